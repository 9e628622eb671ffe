#include "config/drivetrain_checks.hpp"

#include "units.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "model/wind/cp_surface.hpp"

namespace app::config {
namespace {

using model::Drivetrain;
using model::Gear;
using model::GearStage;
using model::StageType;

constexpr double kPi = std::numbers::pi;
constexpr double kBetz = 16.0 / 27.0;
constexpr double kMinPressureAngleDeg = 10.0;
constexpr double kMaxPressureAngleDeg = 35.0;
constexpr double kMaxHelixAngleDeg = 45.0;
constexpr double kMinProfileShift = -1.0;
constexpr double kMaxProfileShift = 2.0;
constexpr double kUndercutAllowance = 5.0 / 6.0;  // [-] practical / theoretical z_min
constexpr double kMinTipThickness = 0.2;          // [-] × m_n
constexpr double kCoaxialTolerance = 0.01;        // [-] × m_n, operating centre distances
constexpr double kMinPlanetGap = 0.5;             // [-] × m_n between planet tips
constexpr int kMaxPlanets = 12;
constexpr double kRatedPowerTolerance = 0.2;  // [-]

std::string num(double v, int digits = 4) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

double involute(double a) { return std::tan(a) - a; }

/// α with inv α = v (Newton from the series start a ≈ (3v)^(1/3)).
double inverse_involute(double v) {
  if (!(v > 0.0)) return 0.0;
  double a = std::cbrt(3.0 * v);
  for (int i = 0; i < 50; ++i) {
    const double t = std::tan(a);
    const double step = (t - a - v) / (t * t);
    a -= step;
    if (a <= 0.0) a = 1e-6;
    if (std::fabs(step) < 1e-14) break;
  }
  return a;
}

struct StageGeometry {
  double mn = 0.0, beta = 0.0, alpha_n = 0.0, alpha_t = 0.0, mt = 0.0;
};

StageGeometry geometry(const GearStage& s) {
  StageGeometry g;
  g.mn = s.normal_module_m;
  g.beta = s.helix_angle_rad;
  g.alpha_n = s.pressure_angle_rad;
  g.alpha_t = std::atan(std::tan(g.alpha_n) / std::cos(g.beta));
  g.mt = g.mn / std::cos(g.beta);
  return g;
}

/// Operating transverse pressure angle and centre distance of a pair; internal: gear 2
/// is the ring (KHK convention), z2 > z1.
struct Mesh {
  double alpha_wt = 0.0;  // [rad]
  double a_w = 0.0;       // [m]
  bool ok = true;
};
Mesh operating(const StageGeometry& g, int z1, double x1, int z2, double x2, bool internal) {
  Mesh m;
  const double zsum = internal ? z2 - z1 : z1 + z2;
  const double xsum = internal ? x2 - x1 : x1 + x2;
  if (!(zsum > 0.0)) {
    m.ok = false;
    return m;
  }
  const double inv_w = involute(g.alpha_t) + 2.0 * std::tan(g.alpha_n) * xsum / zsum;
  if (!(inv_w > 0.0)) {
    m.ok = false;
    return m;
  }
  m.alpha_wt = inverse_involute(inv_w);
  m.a_w = g.mt * zsum / 2.0 * std::cos(g.alpha_t) / std::cos(m.alpha_wt);
  return m;
}

double tip_diameter_external(const StageGeometry& g, int z, double x) {
  return g.mt * z + 2.0 * g.mn * (1.0 + x);
}
double tip_diameter_internal(const StageGeometry& g, int z, double x) {
  return g.mt * z - 2.0 * g.mn * (1.0 - x);
}

/// Total contact ratio ε_α + ε_β; NaN when a tip lies inside its base circle.
double contact_ratio(const StageGeometry& g, const Mesh& m, int z1, double x1, int z2, double x2,
                     bool internal, double face_width_m) {
  const double rb1 = g.mt * z1 / 2.0 * std::cos(g.alpha_t);
  const double rb2 = g.mt * z2 / 2.0 * std::cos(g.alpha_t);
  const double ra1 = tip_diameter_external(g, z1, x1) / 2.0;
  const double ra2 =
      (internal ? tip_diameter_internal(g, z2, x2) : tip_diameter_external(g, z2, x2)) / 2.0;
  if (ra1 < rb1 || ra2 < rb2) return std::nan("");
  const double pbt = kPi * g.mt * std::cos(g.alpha_t);
  const double l1 = std::sqrt(ra1 * ra1 - rb1 * rb1);
  const double l2 = std::sqrt(ra2 * ra2 - rb2 * rb2);
  const double line = m.a_w * std::sin(m.alpha_wt);
  const double eps_alpha = internal ? (l1 - l2 + line) / pbt : (l1 + l2 - line) / pbt;
  const double eps_beta = face_width_m * std::sin(g.beta) / (kPi * g.mn);
  return eps_alpha + eps_beta;
}

/// Normal tip thickness of an external gear [m].
double tip_thickness_normal(const StageGeometry& g, int z, double x) {
  const double d = g.mt * z;
  const double db = d * std::cos(g.alpha_t);
  const double da = tip_diameter_external(g, z, x);
  const double st = g.mt * (kPi / 2.0 + 2.0 * x * std::tan(g.alpha_n));
  const double alpha_at = std::acos(std::min(1.0, db / da));
  const double sat = da * (st / d + involute(g.alpha_t) - involute(alpha_at));
  const double beta_a = std::atan(std::tan(g.beta) * da / d);
  return sat * std::cos(beta_a);
}

class Checker {
 public:
  explicit Checker(const Drivetrain& d) : d_(d) {}

  std::vector<DrivetrainIssue> run() {
    turbine();
    materials();
    for (std::size_t i = 0; i < d_.stages.size(); ++i) stage(i);
    return std::move(issues_);
  }

 private:
  void add(std::string list, std::string id, std::string field, std::string key,
           std::string message) {
    issues_.push_back(
        {std::move(list), std::move(id), std::move(field), std::move(key), std::move(message)});
  }
  std::string gear_key(const Gear& gear, const char* field) const {
    for (std::size_t i = 0; i < d_.gears.size(); ++i) {
      if (&d_.gears[i] == &gear) return "gears[" + std::to_string(i) + "]." + field;
    }
    return std::string("gears.") + field;
  }

  void turbine() {
    const model::Turbine& t = d_.turbine;
    if (t.cp_max > kBetz) {
      add("turbine", "", "cp_max", "turbine.cp_max",
          num(t.cp_max) + "; expected at most the Betz limit 16/27 = 0.5926");
    }
    const model::wind::CpPeak peak = model::wind::find_cp_peak(t.cp);
    if (peak.cp_max > kBetz) {
      add("turbine", "", "cp", "turbine.cp",
          "the surface's maximum Cp is " + num(peak.cp_max) + " (at lambda " +
              num(peak.lambda_opt, 3) +
              "); expected at most the Betz limit 16/27 = 0.5926 (no rotor extracts more)");
    }
    const double omega = t.rated_rotor_speed_rpm * 2.0 * kPi / 60.0;
    const double p_mech = t.rated_torque_nm * omega;
    if (t.rated_power_w > 0.0 && p_mech > 0.0) {
      const double p_el = t.drivetrain_efficiency * p_mech;
      if (std::fabs(p_el / t.rated_power_w - 1.0) > kRatedPowerTolerance) {
        add("turbine", "", "rated_power_w", "turbine.rated_power_w",
            num(t.rated_power_w) +
                " W, but drivetrain_efficiency x rated_torque_nm x rated speed = " +
                num(t.drivetrain_efficiency, 3) + " x " + num(t.rated_torque_nm) + " N·m x " +
                num(omega) + " rad/s = " + num(p_el) +
                " W; expected within 20 % (an inconsistent rated point: a unit or a digit?)");
      }
    }
    const double area = kPi * t.rotor_radius_m * t.rotor_radius_m;
    const double p_wind = 0.5 * t.air_density_kg_m3 * area * std::pow(t.rated_wind_mps, 3);
    if (p_wind > 0.0 && p_mech / p_wind > kBetz) {
      add("turbine", "", "rated_wind_mps", "turbine.rated_wind_mps",
          num(t.rated_wind_mps) + " m/s: rated torque at rated speed (" + num(p_mech) +
              " W) needs Cp " + num(p_mech / p_wind, 3) + " from that wind over a " +
              num(t.rotor_radius_m) +
              " m rotor; expected at most the Betz limit 0.5926 (rated wind, radius or the "
              "rated point is wrong)");
    }
  }

  void materials() {
    for (std::size_t i = 0; i < d_.materials.size(); ++i) {
      const model::Material& m = d_.materials[i];
      const std::string k = "materials[" + std::to_string(i) + "].";
      auto range = [&](const char* field, double v, double lo, double hi, const char* what) {
        if (!(v >= lo && v <= hi)) {
          add("materials", m.id, field, k + field,
              num(v) + "; expected " + num(lo) + " to " + num(hi) + " " + what);
        }
      };
      range("poisson_ratio", m.poisson_ratio, 0.0, 0.4999, "(below 0.5 for any solid)");
      range("sigma_hlim_mpa", m.sigma_hlim_mpa, 200.0, 2000.0,
            "MPa (ISO 6336-5: grey iron to case-hardened steel)");
      range("sigma_flim_mpa", m.sigma_flim_mpa, 100.0, 1000.0, "MPa (ISO 6336-5)");
      range("youngs_modulus_pa", m.youngs_modulus_pa, 50e9, 400e9, "Pa (cast iron to carbide)");
      range("sn_contact_m", m.sn_contact_m, 1.0, 100.0, "(an S-N exponent)");
      range("sn_bending_m", m.sn_bending_m, 1.0, 100.0, "(an S-N exponent)");
    }
  }

  void gear_ranges(const Gear& gear, const StageGeometry& g, bool external,
                   const std::string& stage_id) {
    if (gear.profile_shift < kMinProfileShift || gear.profile_shift > kMaxProfileShift) {
      add("gears", gear.id, "profile_shift", gear_key(gear, "profile_shift"),
          num(gear.profile_shift) + " on gear '" + gear.id + "'; expected " +
              num(kMinProfileShift) + " to " + num(kMaxProfileShift) +
              " (a profile shift of a few tenths is usual)");
      return;
    }
    if (!external) return;
    const double s2 = std::sin(g.alpha_t) * std::sin(g.alpha_t);
    const double z_min = 2.0 * (1.0 - gear.profile_shift) * std::cos(g.beta) / s2;
    const double z_practical = std::round(kUndercutAllowance * z_min);
    if (gear.teeth < z_practical) {
      add("gears", gear.id, "teeth", gear_key(gear, "teeth"),
          std::to_string(gear.teeth) + " teeth on gear '" + gear.id + "' (stage '" + stage_id +
              "', profile shift " + num(gear.profile_shift) + ") are undercut: expected at least " +
              num(z_practical, 3) + " (5/6 of 2(1 - x)cos(beta)/sin^2(alpha_t) = " + num(z_min, 3) +
              "), or a larger profile shift");
      return;
    }
    const double s_an = tip_thickness_normal(g, gear.teeth, gear.profile_shift);
    if (s_an < kMinTipThickness * g.mn) {
      add("gears", gear.id, "profile_shift", gear_key(gear, "profile_shift"),
          num(gear.profile_shift) + " on gear '" + gear.id + "' (" + std::to_string(gear.teeth) +
              " teeth) leaves a tip " + num(s_an * 1e3, 3) + " mm thick" +
              (s_an <= 0.0 ? " (pointed)" : "") +
              "; expected at least 0.2 x m_n = " + num(kMinTipThickness * g.mn * 1e3, 3) + " mm");
    }
  }

  void mesh_contact(const StageGeometry& g, const Mesh& m, const Gear& a, const Gear& b,
                    bool internal, const std::string& sk, const GearStage& s) {
    const double face = std::min(a.face_width_m, b.face_width_m);
    const double eps =
        contact_ratio(g, m, a.teeth, a.profile_shift, b.teeth, b.profile_shift, internal, face);
    if (!(eps >= 1.0)) {
      add("stages", s.id, "gears", sk + ".gears",
          "'" + a.id + "' and '" + b.id + "' have a total contact ratio " +
              (std::isnan(eps) ? std::string("undefined (a tip inside its base circle)")
                               : num(eps, 3)) +
              "; expected at least 1 (the mesh would not transmit continuously)");
    }
  }

  void stage(std::size_t i) {
    const GearStage& s = d_.stages[i];
    const std::string sk = "stages[" + std::to_string(i) + "]";
    const double alpha_deg = s.pressure_angle_rad / kDeg;
    const double beta_deg = s.helix_angle_rad / kDeg;
    if (alpha_deg < kMinPressureAngleDeg || alpha_deg > kMaxPressureAngleDeg) {
      add("stages", s.id, "pressure_angle_deg", sk + ".pressure_angle_deg",
          num(alpha_deg) + " deg; expected 10 to 35 deg (ISO 53's basic rack is 20 deg)");
      return;
    }
    if (beta_deg > kMaxHelixAngleDeg) {
      add("stages", s.id, "helix_angle_deg", sk + ".helix_angle_deg",
          num(beta_deg) +
              " deg; expected 0 to 45 deg (single helical gears run at 8-20 deg, "
              "double helical up to 45 deg)");
      return;
    }
    std::vector<const Gear*> gears;
    for (const auto& id : s.gears) gears.push_back(d_.gear(id));
    for (const Gear* gear : gears) {
      if (gear == nullptr) return;  // a reference error, reported by the parser
    }
    const StageGeometry g = geometry(s);
    if (s.type == StageType::kParallel) {
      if (gears.size() != 2) {
        add("stages", s.id, "gears", sk + ".gears",
            std::to_string(gears.size()) +
                " gears; expected 2 for a parallel stage (wheel on the input shaft, pinion)");
        return;
      }
      const std::size_t before = issues_.size();
      gear_ranges(*gears[0], g, true, s.id);
      gear_ranges(*gears[1], g, true, s.id);
      if (issues_.size() != before) return;
      const Mesh m = operating(g, gears[1]->teeth, gears[1]->profile_shift, gears[0]->teeth,
                               gears[0]->profile_shift, false);
      if (!m.ok) {
        add("stages", s.id, "gears", sk + ".gears",
            "profile shifts leave no operating pressure angle; expected a realisable pair");
        return;
      }
      mesh_contact(g, m, *gears[1], *gears[0], false, sk, s);
      return;
    }
    // Planetary: sun, planet, ring.
    if (gears.size() != 3) {
      add("stages", s.id, "gears", sk + ".gears",
          std::to_string(gears.size()) +
              " gears; expected 3 for a planetary stage (sun, planet, "
              "ring)");
      return;
    }
    const Gear& sun = *gears[0];
    const Gear& planet = *gears[1];
    const Gear& ring = *gears[2];
    if (s.planets < 1 || s.planets > kMaxPlanets) {
      add("stages", s.id, "planets", sk + ".planets",
          std::to_string(s.planets) + "; expected 1 to " + std::to_string(kMaxPlanets));
      return;
    }
    if (ring.teeth <= planet.teeth) {
      add("gears", ring.id, "teeth", gear_key(ring, "teeth"),
          std::to_string(ring.teeth) + " ring teeth; expected more than the planet's " +
              std::to_string(planet.teeth));
      return;
    }
    const std::size_t before = issues_.size();
    gear_ranges(sun, g, true, s.id);
    gear_ranges(planet, g, true, s.id);
    gear_ranges(ring, g, false, s.id);
    if (issues_.size() != before) return;
    const Mesh sp =
        operating(g, sun.teeth, sun.profile_shift, planet.teeth, planet.profile_shift, false);
    const Mesh rp =
        operating(g, planet.teeth, planet.profile_shift, ring.teeth, ring.profile_shift, true);
    const std::string teeth = "sun " + std::to_string(sun.teeth) + ", planet " +
                              std::to_string(planet.teeth) + ", ring " + std::to_string(ring.teeth);
    if (!sp.ok || !rp.ok || std::fabs(sp.a_w - rp.a_w) > kCoaxialTolerance * g.mn) {
      const bool unshifted =
          sun.profile_shift == 0.0 && planet.profile_shift == 0.0 && ring.profile_shift == 0.0;
      std::string why = unshifted ? "z_ring - z_sun = " + std::to_string(ring.teeth - sun.teeth) +
                                        " but 2 x z_planet = " + std::to_string(2 * planet.teeth)
                                  : "with the profile shifts";
      add("stages", s.id, "gears", sk + ".gears",
          "the planets cannot mesh with sun and ring at one centre distance (" + teeth +
              "): " + why + "; operating centre distance sun-planet " + num(sp.a_w * 1e3, 5) +
              " mm, ring-planet " + num(rp.a_w * 1e3, 5) + " mm; expected equal within 0.01 x m_n");
      return;
    }
    const double spacing = 2.0 * sp.a_w * std::sin(kPi / s.planets);
    const double tip = tip_diameter_external(g, planet.teeth, planet.profile_shift);
    if (s.planets > 1 && spacing - tip < kMinPlanetGap * g.mn) {
      add("stages", s.id, "planets", sk + ".planets",
          std::to_string(s.planets) + " planets overlap: neighbouring planet centres are " +
              num(spacing * 1e3, 4) + " mm apart, a planet's tip diameter is " + num(tip * 1e3, 4) +
              " mm; expected a gap of at least 0.5 x m_n = " + num(kMinPlanetGap * g.mn * 1e3, 3) +
              " mm");
      return;
    }
    if ((ring.teeth + sun.teeth) % s.planets != 0) {
      add("stages", s.id, "planets", sk + ".planets",
          std::to_string(s.planets) + " planets cannot be equally spaced (" + teeth +
              "): (z_ring + z_sun) / N = " + std::to_string(ring.teeth + sun.teeth) + " / " +
              std::to_string(s.planets) + " is not an integer");
      return;
    }
    mesh_contact(g, sp, sun, planet, false, sk, s);
    mesh_contact(g, rp, planet, ring, true, sk, s);
  }

  const Drivetrain& d_;
  std::vector<DrivetrainIssue> issues_;
};

}  // namespace

std::vector<DrivetrainIssue> check_drivetrain(const model::Drivetrain& drivetrain) {
  return Checker(drivetrain).run();
}

}  // namespace app::config
