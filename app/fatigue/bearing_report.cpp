#include "fatigue/bearing_report.hpp"

#include <cmath>
#include <cstdio>

#include "model/fatigue/bearing_life.hpp"
#include "model/fatigue/bearing_rating.hpp"

namespace app::fatigue {
namespace mf = model::fatigue;

std::vector<BearingRatingRow> bearing_rating_rows(const model::Drivetrain& drivetrain,
                                                  const mf::ChannelSet& channels) {
  std::vector<BearingRatingRow> rows;
  const mf::LoadSample rated = channels.quasi_static_loads(drivetrain.turbine.rated_torque_nm);
  const double rated_rpm = drivetrain.turbine.rated_rotor_speed_rpm;
  for (std::size_t s = 0; s < channels.bearing_count(); ++s) {
    const model::Bearing& b = channels.bearing(s);
    const model::Bearing* desc = drivetrain.bearing(b.id);
    const mf::BearingLifeTerms& life = channels.bearing_life(s);
    BearingRatingRow r;
    r.id = channels.bearing_id(s);
    r.c_n = b.dynamic_rating_n;
    r.c_from_catalogue = desc != nullptr && desc->dynamic_rating_n > 0.0;
    const mf::BearingRating geometry = mf::iso281_dynamic_rating(desc ? *desc : b);
    r.c_geometry_n = geometry.c_n;
    r.geometry_error = geometry.error;
    r.c0_n = life.c0_n;
    r.cu_n = life.cu_n;
    r.rated_load_n = mf::equivalent_load_n(b, rated.bearing_radial_n[s], rated.bearing_axial_n[s]);
    r.rated_speed_rpm = rated_rpm * life.rev_per_rotor_rev;
    const double nu1 = mf::rated_viscosity_mm2_s(r.rated_speed_rpm, life.pitch_diameter_mm);
    r.kappa = nu1 > 0.0 ? life.viscosity_mm2_s / nu1 : 0.0;
    r.a_iso = channels.life_modification(s, r.rated_load_n, rated_rpm);
    rows.push_back(r);
  }
  return rows;
}

std::string bearing_rating_text(const mf::ChannelSet& channels,
                                const std::vector<BearingRatingRow>& rows) {
  char buf[256];
  std::string out =
      "# bearing ratings C [kN] in use (* from the geometry: the description gives none) and "
      "ISO 281:2007's C from the geometry as a check:";
  bool assumed = false;
  for (const BearingRatingRow& r : rows) {
    assumed |= !r.c_from_catalogue;
    if (r.c_geometry_n > 0.0) {
      std::snprintf(buf, sizeof buf, " %s %.0f%s (%.0f)", r.id.c_str(), r.c_n / 1e3,
                    r.c_from_catalogue ? "" : "*", r.c_geometry_n / 1e3);
    } else {
      std::snprintf(buf, sizeof buf, " %s %.0f%s (-)", r.id.c_str(), r.c_n / 1e3,
                    r.c_from_catalogue ? "" : "*");
    }
    out += buf;
  }
  out += "\n";
  if (assumed) {
    out +=
        "# * assumed: no dynamic_rating_n in the description, C computed from the bearing's "
        "geometry (ISO 281 formula); a catalogue rating is often higher: these lives rest on "
        "that assumption\n";
  }
  const mf::Lubrication& lub = channels.options().lubrication;
  if (!lub.enabled) {
    return out + "# life modification: none (--basic-life): bearing lives are ISO 281 L10\n";
  }
  const double nu =
      rows.empty() ? 0.0 : channels.bearing_life(0).viscosity_mm2_s;  // same oil for all
  std::snprintf(buf, sizeof buf,
                "# ISO 281:2007 life modification a_ISO: oil nu40 %.0f / nu100 %.1f mm2/s at %.0f "
                "degC -> nu %.1f mm2/s, contamination factor e_C %.2f; C0, C_u [kN]:",
                lub.viscosity_40c_mm2_s, lub.viscosity_100c_mm2_s, lub.temperature_c, nu,
                lub.contamination_factor);
  out += buf;
  for (const BearingRatingRow& r : rows) {
    std::snprintf(buf, sizeof buf, " %s %.0f, %.0f", r.id.c_str(), r.c0_n / 1e3, r.cu_n / 1e3);
    out += buf;
  }
  out += "\n# at rated torque and speed (quasi-static loads): kappa, a_ISO:";
  for (const BearingRatingRow& r : rows) {
    std::snprintf(buf, sizeof buf, " %s %.2f, %.2f", r.id.c_str(), r.kappa, r.a_iso);
    out += buf;
  }
  out += "\n";
  if (!channels.life_note().empty()) out += "# a_ISO not applied: " + channels.life_note() + "\n";
  return out;
}

nlohmann::json bearing_rating_json(const mf::ChannelSet& channels,
                                   const std::vector<BearingRatingRow>& rows) {
  nlohmann::json j = {{"bearings", nlohmann::json::object()}};
  for (const BearingRatingRow& r : rows) {
    j["bearings"][r.id] = {
        {"c_n", r.c_n},
        {"c_source", r.c_from_catalogue ? "description" : "iso281-geometry"},
        {"c_iso281_geometry_n",
         r.c_geometry_n > 0.0 ? nlohmann::json(r.c_geometry_n) : nlohmann::json()},
        {"c0_n", r.c0_n},
        {"cu_n", r.cu_n},
        {"rated_equivalent_load_n", r.rated_load_n},
        {"rated_ring_speed_rpm", r.rated_speed_rpm},
        {"kappa_at_rated", r.kappa},
        {"a_iso_at_rated", r.a_iso}};
  }
  const mf::Lubrication& lub = channels.options().lubrication;
  j["life_modification"] = {{"enabled", lub.enabled},
                            {"viscosity_40c_mm2_s", lub.viscosity_40c_mm2_s},
                            {"viscosity_100c_mm2_s", lub.viscosity_100c_mm2_s},
                            {"temperature_c", lub.temperature_c},
                            {"contamination_factor", lub.contamination_factor}};
  return j;
}

}  // namespace app::fatigue
