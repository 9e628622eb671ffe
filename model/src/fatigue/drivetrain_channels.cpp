#include "model/fatigue/drivetrain_channels.hpp"

#include <algorithm>
#include <cmath>

#include "model/drivetrain/kinematics.hpp"
#include "model/fatigue/bearing_rating.hpp"

namespace model::fatigue {
namespace {

// Quasi-static bearing reactions (FALLBACK only; the dynamics model supplies real ones):
// every gear sits at mid-span between the two bearings of its shaft, so each bearing
// takes half of the transverse gear force F_t/cos α_wt; where a shaft carries two gear
// meshes their forces are taken as collinear and added (an upper bound: the layout
// angles are not in the description). Helical axial forces F_t·tan β: on a shaft with a
// driven and a driving helical gear (the intermediate shaft) the two are assumed of the
// same hand, as is usual so that their thrusts oppose, and subtract; the net thrust is
// taken by the shaft's angular-contact bearing (contact angle > 0), or ignored when the
// shaft has none. The sun's planet meshes cancel (equal load sharing).
constexpr double kMidSpanShare = 0.5;

}  // namespace

const char* failure_mode_name(FailureMode mode) {
  switch (mode) {
    case FailureMode::kContact:
      return "contact";
    case FailureMode::kBending:
      return "bending";
    case FailureMode::kBearing:
      return "bearing";
  }
  return "?";
}

double planet_load_sharing_factor(int planets) {
  // IEC 61400-4:2012 (gearbox design requirements for wind turbines), planet load sharing
  // factor K_γ by the number of planets.
  constexpr double kTable[] = {1.10, 1.25, 1.35, 1.44, 1.47};  // 3, 4, 5, 6, 7 planets
  if (planets <= 2) return 1.0;
  return kTable[std::min(planets, 7) - 3];
}

double iso281_exponent(BearingType type) { return type == BearingType::kBall ? 3.0 : 10.0 / 3.0; }

double l10_million_revs(double c_n, double p_n, BearingType type) {
  if (!(p_n > 0.0)) return std::numeric_limits<double>::infinity();
  return std::pow(c_n / p_n, iso281_exponent(type));
}

double equivalent_load_n(const Bearing& b, double radial_n, double axial_n) {
  const double fr = std::abs(radial_n), fa = std::abs(axial_n);
  if (b.type == BearingType::kBall || b.contact_angle_rad <= 0.0) return fr;
  const double e = 1.5 * std::tan(b.contact_angle_rad);
  const double cot = 1.0 / std::tan(b.contact_angle_rad);
  const bool low_axial = fa <= e * fr;
  if (b.rows <= 1) return low_axial ? fr : 0.4 * fr + 0.4 * cot * fa;
  return low_axial ? fr + 0.45 * cot * fa : 0.67 * fr + 0.67 * cot * fa;
}

ChannelSet::ChannelSet(const Drivetrain& d, const ChannelOptions& options) : options_(options) {
  const Kinematics kin(d);
  const double rpm = 60.0;  // 1 rotor rev/s: speeds in Hz are then ratios to the rotor speed
  auto fail = [this](std::string what) { error_ = std::move(what); };
  auto add_channel = [&](Channel c) -> Channel* {
    if (channel_count_ >= kMaxChannels) {
      fail("too many damage channels (capacity kMaxChannels)");
      return nullptr;
    }
    channels_[channel_count_] = std::move(c);
    return &channels_[channel_count_++];
  };
  auto material_of = [&](const Gear& g) -> const Material* {
    const Material* m = d.material(g.material);
    if (!m) fail("gear '" + g.id + "': unknown material '" + g.material + "'");
    return m;
  };
  auto contact_curve = [&](const Material& m) {
    SnCurve c;
    c.m = m.sn_contact_m;
    c.c = m.sn_contact_c_mpa;
    c.knee_cycles = m.sn_contact_knee_cycles;
    c.branch = options.branch;
    return c;
  };
  auto bending_curve = [&](const Material& m, bool reversed) {
    SnCurve c;
    c.m = m.sn_bending_m;
    c.c = m.sn_bending_c_mpa * (reversed ? m.reversed_bending_factor : 1.0);
    c.knee_cycles = m.sn_bending_knee_cycles;
    c.branch = options.branch;
    return c;
  };
  auto add_mesh = [&](std::string id, const MeshRating& r, double ft_per_nm) -> int {
    if (mesh_count_ >= kMaxMeshes) {
      fail("too many gear meshes (capacity kMaxMeshes)");
      return -1;
    }
    mesh_ids_[mesh_count_] = std::move(id);
    meshes_[mesh_count_] = r;
    torque_to_ft_per_nm_[mesh_count_] = ft_per_nm;
    quasi_static_factor_[mesh_count_] = 1.0;
    return static_cast<int>(mesh_count_++);
  };
  // Transverse gear forces (per rotor torque) acting on each shaft, for the fallback.
  struct ShaftForce {
    std::string shaft;
    double radial_per_nm = 0.0, axial_per_nm = 0.0;
  };
  std::array<ShaftForce, kMaxMeshes * 2> shaft_forces{};
  std::size_t shaft_force_count = 0;
  auto add_shaft_force = [&](const std::string& shaft, double radial, double axial) {
    for (std::size_t i = 0; i < shaft_force_count; ++i) {
      if (shaft_forces[i].shaft == shaft) {
        shaft_forces[i].radial_per_nm += radial;
        shaft_forces[i].axial_per_nm += axial;
        return;
      }
    }
    if (shaft_force_count < shaft_forces.size())
      shaft_forces[shaft_force_count++] = {shaft, radial, axial};
  };
  double planet_ft_per_nm = 0.0;
  int planets = 0;
  double planet_rev_per_rotor_rev = 0.0;

  for (std::size_t si = 0; si < d.stages.size() && valid(); ++si) {
    const GearStage& st = d.stages[si];
    // Torque on the stage's input shaft per rotor torque (lossless).
    const double in_ratio = kin.stage_input_hz(si, rpm);
    const double t_in_per_nm = 1.0 / in_ratio;
    if (st.type == StageType::kPlanetary) {
      if (st.gears.size() != 3 || st.planets <= 0) {
        fail("stage '" + st.id +
             "': planetary stage needs gears {sun, planet, ring} and planets > 0");
        break;
      }
      const Gear* sun = d.gear(st.gears[0]);
      const Gear* planet = d.gear(st.gears[1]);
      const Gear* ring = d.gear(st.gears[2]);
      if (!sun || !planet || !ring) {
        fail("stage '" + st.id + "': unknown gear id");
        break;
      }
      const Material* ms = material_of(*sun);
      const Material* mp = material_of(*planet);
      const Material* mr = material_of(*ring);
      if (!ms || !mp || !mr) break;
      const double zs = sun->teeth, zp = planet->teeth, zr = ring->teeth;
      const double b_sp = std::min(sun->face_width_m, planet->face_width_m);
      const double b_pr = std::min(planet->face_width_m, ring->face_width_m);
      const PairGeometry g_sp =
          pair_geometry(zs, zp, sun->profile_shift, planet->profile_shift, st.normal_module_m,
                        st.pressure_angle_rad, st.helix_angle_rad, b_sp, options.rating.rack);
      const PairGeometry g_pr =
          pair_geometry(zp, -zr, planet->profile_shift, ring->profile_shift, st.normal_module_m,
                        st.pressure_angle_rad, st.helix_angle_rad, b_pr, options.rating.rack);
      // K_Hβ (ISO 6336-1 method C, gear_rating.hpp): the sun's body carries the torque of all
      // P planet meshes over its face width and its radial forces balance (no shaft bending);
      // a planet is an idler (no torque through its body); its pin's bending is not in the
      // description, so it is left out.
      PinionShaft sun_body;
      sun_body.torsion_meshes = static_cast<double>(st.planets);
      PinionShaft planet_body;
      planet_body.torsion_meshes = 0.0;
      const MeshRating r_sp = mesh_rating(g_sp, *ms, *mp, options.k_a, options.rating, sun_body);
      const MeshRating r_pr = mesh_rating(g_pr, *mp, *mr, options.k_a, options.rating, planet_body);
      // Carrier torque T_c = P·F_t·(d_s/2)·(1 + z_r/z_s) (ring fixed): F_t per planet mesh.
      const double ft_per_nm =
          t_in_per_nm / (st.planets * 0.5 * std::abs(g_sp.d_m[0]) * (1.0 + zr / zs));
      planets = st.planets;
      planet_ft_per_nm = ft_per_nm;
      planet_load_sharing_ = options.planet_load_sharing > 0.0
                                 ? options.planet_load_sharing
                                 : planet_load_sharing_factor(st.planets);
      planet_rev_per_rotor_rev = zr / zp;
      std::array<int, kMaxMeshes> sp{}, pr{};
      for (int k = 0; k < st.planets && valid(); ++k) {
        sp[k] = add_mesh(sun->id + "-" + planet->id + std::to_string(k + 1), r_sp, ft_per_nm);
      }
      for (int k = 0; k < st.planets && valid(); ++k) {
        pr[k] = add_mesh(planet->id + std::to_string(k + 1) + "-" + ring->id, r_pr, ft_per_nm);
      }
      if (!valid()) break;
      for (int k = 0; k < st.planets; ++k) {
        quasi_static_factor_[static_cast<std::size_t>(sp[k])] = planet_load_sharing_;
        quasi_static_factor_[static_cast<std::size_t>(pr[k])] = planet_load_sharing_;
      }
      Channel sun_c{sun->id, "", FailureMode::kContact, contact_curve(*ms), {}, 0, 0.0};
      Channel sun_b{sun->id, "", FailureMode::kBending, bending_curve(*ms, false), {}, 0, 0.0};
      Channel ring_c{ring->id, "", FailureMode::kContact, contact_curve(*mr), {}, 0, 0.0};
      for (int k = 0; k < st.planets; ++k) {
        if (static_cast<std::size_t>(k) >= kMaxSources) {
          fail("stage '" + st.id + "': more planets than kMaxSources");
          break;
        }
        sun_c.sources[k] = {static_cast<std::uint8_t>(sp[k]), 0, zr / zs};
        sun_b.sources[k] = {static_cast<std::uint8_t>(sp[k]), 0, zr / zs};
        ring_c.sources[k] = {static_cast<std::uint8_t>(pr[k]), 1, 1.0};
      }
      sun_c.source_count = sun_b.source_count = ring_c.source_count =
          static_cast<std::size_t>(st.planets);
      add_channel(sun_c);
      add_channel(sun_b);
      for (int k = 0; k < st.planets && valid(); ++k) {
        const std::string pid = planet->id + std::to_string(k + 1);
        Channel c1{pid, "sun-side flank", FailureMode::kContact, contact_curve(*mp), {}, 1, 0.0};
        c1.sources[0] = {static_cast<std::uint8_t>(sp[k]), 1, zr / zp};
        Channel c2{pid, "ring-side flank", FailureMode::kContact, contact_curve(*mp), {}, 1, 0.0};
        c2.sources[0] = {static_cast<std::uint8_t>(pr[k]), 0, zr / zp};
        Channel c3{pid, "reversed (Y_M)", FailureMode::kBending, bending_curve(*mp, true), {}, 1,
                   0.0};
        c3.sources[0] = {static_cast<std::uint8_t>(sp[k]), 1, zr / zp};
        add_channel(c1);
        add_channel(c2);
        add_channel(c3);
      }
      add_channel(ring_c);
    } else {
      if (st.gears.size() != 2) {
        fail("stage '" + st.id + "': parallel stage needs gears {wheel, pinion}");
        break;
      }
      const Gear* wheel = d.gear(st.gears[0]);
      const Gear* pinion = d.gear(st.gears[1]);
      if (!wheel || !pinion) {
        fail("stage '" + st.id + "': unknown gear id");
        break;
      }
      const Material* mw = material_of(*wheel);
      const Material* mpn = material_of(*pinion);
      if (!mw || !mpn) break;
      const PairGeometry g =
          pair_geometry(pinion->teeth, wheel->teeth, pinion->profile_shift, wheel->profile_shift,
                        st.normal_module_m, st.pressure_angle_rad, st.helix_angle_rad,
                        std::min(pinion->face_width_m, wheel->face_width_m), options.rating.rack);
      // K_Hβ: the pinion shaft bends between its bearings (ISO 6336-1 method C, gear_rating.hpp):
      // l = the shaft's length between the bearings, d_sh its diameter, s = pinion_offset_ratio·l;
      // K' of ISO 6336-1 Figure 13 arrangement (a), where bending adds to torsion (the layout is
      // not in the description; the adding case is the conservative one): 0.48 with the pinion
      // stiffening its shaft (d1/d_sh ≥ 1.15), else 0.8.
      const Shaft* pinion_shaft = d.shaft(pinion->shaft);
      if (!pinion_shaft || !(pinion_shaft->length_m > 0.0) || !(pinion_shaft->diameter_m > 0.0)) {
        fail("stage '" + st.id + "': pinion '" + pinion->id + "' sits on shaft '" + pinion->shaft +
             "', which is missing or has a non-positive length or diameter (needed for K_Hβ)");
        break;
      }
      PinionShaft body;
      body.torsion_meshes = 1.0;
      body.bearing_span_m = pinion_shaft->length_m;
      body.offset_m = options.rating.face_load.pinion_offset_ratio * pinion_shaft->length_m;
      body.shaft_diameter_m = pinion_shaft->diameter_m;
      body.k_prime = std::abs(g.d_m[0]) / pinion_shaft->diameter_m >= 1.15 ? 0.48 : 0.8;
      const MeshRating r = mesh_rating(g, *mpn, *mw, options.k_a, options.rating, body);
      const double ft_per_nm = t_in_per_nm / (0.5 * std::abs(g.d_m[1]));
      const int slot = add_mesh(wheel->id + "-" + pinion->id, r, ft_per_nm);
      if (slot < 0) break;
      const double wheel_rev = in_ratio;
      const double pinion_rev = in_ratio * kin.stage_ratio(si);
      const Gear* gears[2] = {pinion, wheel};
      const Material* mats[2] = {mpn, mw};
      const double revs[2] = {pinion_rev, wheel_rev};
      for (int i : {1, 0}) {  // wheel first: the description's order
        Channel c{gears[i]->id, "", FailureMode::kContact, contact_curve(*mats[i]), {}, 1, 0.0};
        c.sources[0] = {static_cast<std::uint8_t>(slot), static_cast<std::uint8_t>(i), revs[i]};
        Channel bnd{gears[i]->id, "", FailureMode::kBending, bending_curve(*mats[i], false), {}, 1,
                    0.0};
        bnd.sources[0] = c.sources[0];
        add_channel(c);
        add_channel(bnd);
      }
      const double radial = ft_per_nm / std::cos(g.alpha_wt_rad);
      const double axial = ft_per_nm * std::tan(st.helix_angle_rad);
      add_shaft_force(wheel->shaft, radial, -axial);  // driving gear: thrust one way
      add_shaft_force(pinion->shaft, radial, axial);  // driven gear: the other
    }
  }
  // Bearings.
  for (const Bearing& b : d.bearings) {
    if (!valid()) break;
    const bool on_planet = b.shaft == "planet";
    const int copies = on_planet ? std::max(planets, 0) : 1;
    double rev = 0.0;
    if (on_planet) {
      rev = planet_rev_per_rotor_rev;
    } else if (auto hz = kin.shaft_hz(b.shaft, rpm)) {
      rev = std::abs(*hz);
    } else {
      fail("bearing '" + b.id + "': unknown shaft '" + b.shaft + "'");
      break;
    }
    double radial = 0.0, axial = 0.0;
    if (on_planet) {
      radial = 2.0 * planet_ft_per_nm;  // sun and ring tangential forces add on the pin
    } else {
      for (std::size_t i = 0; i < shaft_force_count; ++i) {
        if (shaft_forces[i].shaft == b.shaft) {
          radial = kMidSpanShare * shaft_forces[i].radial_per_nm;
          if (b.contact_angle_rad > 0.0) axial = std::abs(shaft_forces[i].axial_per_nm);
        }
      }
    }
    for (int k = 0; k < copies; ++k) {
      if (bearing_count_ >= kMaxBearings) {
        fail("too many bearings (capacity kMaxBearings)");
        break;
      }
      const std::size_t slot = bearing_count_++;
      bearing_ids_[slot] = on_planet ? b.id + std::to_string(k + 1) : b.id;
      bearings_[slot] = b;
      torque_to_radial_per_nm_[slot] = radial;
      torque_to_axial_per_nm_[slot] = axial;
      bearing_quasi_static_factor_[slot] = on_planet ? planet_load_sharing_ : 1.0;
      // C from the description, else from the geometry (ISO 281:2007, bearing_rating.hpp).
      const BearingRating rating = effective_dynamic_rating(b);
      if (!(rating.c_n > 0.0)) {
        fail("bearing '" + b.id +
             "': no dynamic_rating_n given and none from geometry: " + rating.error);
        break;
      }
      bearings_[slot].dynamic_rating_n = rating.c_n;
      // ISO 281:2007 a_ISO inputs (bearing_life.hpp).
      BearingLifeTerms& life = life_[slot];
      life.type = b.type;
      life.c0_n = effective_static_rating_n(b);
      life.cu_n = effective_fatigue_load_limit_n(b);
      life.pitch_diameter_mm = b.pitch_diameter_m * 1e3;
      life.rev_per_rotor_rev = rev;
      const Lubrication& lub = options.lubrication;
      life.viscosity_mm2_s = kinematic_viscosity_mm2_s(lub.viscosity_40c_mm2_s,
                                                       lub.viscosity_100c_mm2_s, lub.temperature_c);
      life.ec_cu_n = lub.contamination_factor * life.cu_n;
      life.applied = lub.enabled && life.cu_n > 0.0 && life.viscosity_mm2_s > 0.0;
      if (lub.enabled && !life.applied && k == 0) {
        life_note_ += (life_note_.empty() ? "" : "; ") + b.id +
                      ": no C_u (give static_rating_n or fatigue_load_limit_n), a_ISO = 1";
      }
      Channel c{bearing_ids_[slot], "", FailureMode::kBearing, {}, {}, 1, 0.0};
      c.curve.m = iso281_exponent(b.type);
      c.curve.c = rating.c_n;
      c.curve.n_ref = 1e6;
      c.curve.branch = KneeBranch::kNone;
      c.sources[0] = {static_cast<std::uint8_t>(slot), 0, rev};
      add_channel(c);
    }
  }
  if (valid() && channel_count_ == 0) fail("drivetrain has no gear stages or bearings to rate");
  // Suggested histogram ranges: the quasi-static stress at twice the rated torque.
  if (valid()) {
    const double t2 = 2.0 * std::max(d.turbine.rated_torque_nm, 1.0);
    const LoadSample l = quasi_static_loads(t2);
    for (std::size_t c = 0; c < channel_count_; ++c) {
      double s = 0.0;
      for (std::size_t k = 0; k < channels_[c].source_count; ++k) s = std::max(s, stress(c, k, l));
      channels_[c].stress_full_scale = s > 0.0 ? s : 1.0;
    }
  }
}

double ChannelSet::life_modification(std::size_t slot, double p_n, double rotor_rpm) const {
  const BearingLifeTerms& t = life_[slot];
  if (!t.applied || !(p_n > 0.0)) return 1.0;
  const double nu1 =
      rated_viscosity_mm2_s(std::abs(rotor_rpm) * t.rev_per_rotor_rev, t.pitch_diameter_mm);
  // At standstill no film forms: the lowest curve (κ = 0.1) of the standard.
  const double kappa = nu1 > 0.0 ? t.viscosity_mm2_s / nu1 : 0.0;
  return life_modification_factor(t.type, kappa, t.ec_cu_n / p_n);
}

double ChannelSet::stress(std::size_t c, std::size_t s, const LoadSample& loads) const {
  const Channel& ch = channels_[c];
  const Source& src = ch.sources[s];
  switch (ch.mode) {
    case FailureMode::kContact:
      return meshes_[src.slot].contact_stress_mpa(loads.mesh_force_n[src.slot], src.gear);
    case FailureMode::kBending:
      return meshes_[src.slot].bending_stress_mpa(loads.mesh_force_n[src.slot], src.gear);
    case FailureMode::kBearing:
      return equivalent_load_n(bearings_[src.slot], loads.bearing_radial_n[src.slot],
                               loads.bearing_axial_n[src.slot]);
  }
  return 0.0;
}

LoadSample ChannelSet::quasi_static_loads(double rotor_torque_nm) const {
  LoadSample l;
  const double t = std::abs(rotor_torque_nm);
  for (std::size_t i = 0; i < mesh_count_; ++i)
    l.mesh_force_n[i] = quasi_static_factor_[i] * torque_to_ft_per_nm_[i] * t;
  for (std::size_t i = 0; i < bearing_count_; ++i) {
    l.bearing_radial_n[i] = bearing_quasi_static_factor_[i] * torque_to_radial_per_nm_[i] * t;
    l.bearing_axial_n[i] = torque_to_axial_per_nm_[i] * t;
  }
  return l;
}

}  // namespace model::fatigue
