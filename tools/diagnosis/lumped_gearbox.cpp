#include "lumped_gearbox.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "model/drivetrain/kinematics.hpp"

namespace tools::diagnosis {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kDofs = 12;
using Mat = Eigen::Matrix<double, kDofs, kDofs>;
using Vec = Eigen::Matrix<double, kDofs, 1>;
enum Dof { kThC, kThS, kThI, kThH, kThG, kYs, kYi, kYh, kYr, kSeat3, kSeat5, kRes };

double frac(double x) { return x - std::floor(x); }

// Base radius of a gear of a stage [m].
double base_radius(const model::GearStage& st, const model::Gear& g) {
  const double pitch = st.normal_module_m * g.teeth / (2.0 * std::cos(st.helix_angle_rad));
  const double alpha_t = std::atan(std::tan(st.pressure_angle_rad) / std::cos(st.helix_angle_rad));
  return pitch * std::cos(alpha_t);
}

// Raised-cosine window of half-width h centred on 0.5 (x in [0, 1)).
double window(double x, double h) {
  const double d = std::abs(x - 0.5);
  return d < h ? 0.5 * (1.0 + std::cos(kPi * d / h)) : 0.0;
}

struct Mesh {
  Vec g = Vec::Zero();               // deflection gradient
  double k = 0.0;                    // [N/m] mean
  double fluct[3] = {0, 0, 0};       // stiffness harmonics (relative)
  double te = 0.0;                   // [m] static transmission error amplitude
  double teeth_per_rotor_rev = 0.0;  // mesh cycles per rotor revolution
  double crack_loss = 0.0, crack_half = 0.0;
  double crack_rate = 0.0;  // cracked-gear revolutions per rotor revolution
  int crack_windows = 1;    // windows per cracked-gear revolution
  double ecc = 0.0, ecc_rate = 0.0;
  double base_pitch = 0.0;  // [m] p_b = 2π·r_b/z of the eccentric gear
  double tan_alpha = 0.0;
};

struct Impacts {
  std::vector<double> times;       // [s]
  std::vector<double> amplitude;   // [N]
  int dof = -1, counter_dof = -1;  // force on dof, reaction on counter_dof (−1: ground)
};

}  // namespace

LumpedOutput simulate_lumped(const model::Drivetrain& d,
                             const std::function<double(double)>& rotor_revs, double torque_nm,
                             double fs_hz, double seconds, double settle_s,
                             const std::vector<LumpedEffect>& effects, double stiffness_scale,
                             double damping_scale, unsigned seed) {
  const model::Kinematics kin(d);
  if (d.stages.size() != 3 || d.stages[0].type != model::StageType::kPlanetary)
    throw std::runtime_error("lumped gearbox: needs one planetary and two parallel stages");
  const model::GearStage& ps = d.stages[0];
  const model::GearStage& is = d.stages[1];
  const model::GearStage& hs = d.stages[2];
  const model::Gear& sun = *d.gear(ps.gears[0]);
  const model::Gear& planet = *d.gear(ps.gears[1]);
  const model::Gear& ring = *d.gear(ps.gears[2]);
  const model::Gear& g1 = *d.gear(is.gears[0]);
  const model::Gear& g2 = *d.gear(is.gears[1]);
  const model::Gear& g3 = *d.gear(hs.gears[0]);
  const model::Gear& g4 = *d.gear(hs.gears[1]);
  const double ratio_p = 1.0 + static_cast<double>(ring.teeth) / sun.teeth;
  const double ratio_total = kin.overall_ratio();
  const double rate_sun = ratio_p;                     // sun shaft per rotor rev
  const double rate_ims = *kin.shaft_hz("ims", 60.0);  // per rotor rev
  const double rate_hss = *kin.shaft_hz("hss", 60.0);
  const double rate_planet = *kin.shaft_hz("planet", 60.0);
  const double sin_a = std::sin(is.pressure_angle_rad);

  // Masses and inertias: gears as discs on their pitch radii, shafts lumped.
  auto disc = [](const model::GearStage& st, const model::Gear& g) {
    const double r = st.normal_module_m * g.teeth / (2.0 * std::cos(st.helix_angle_rad));
    return 0.5 * g.mass_kg * r * r;
  };
  Vec m = Vec::Zero();
  m[kThC] = 900.0 + ps.planets * planet.mass_kg *
                        std::pow(0.5 * ps.normal_module_m * (sun.teeth + planet.teeth), 2);
  m[kThS] = disc(ps, sun) + disc(is, g1) + 5.0;
  m[kThI] = disc(is, g2) + disc(hs, g3) + 3.0;
  m[kThH] = disc(hs, g4) + 0.8;
  m[kThG] = 80.0;
  m[kYs] = sun.mass_kg + g1.mass_kg + 600.0;
  m[kYi] = g2.mass_kg + g3.mass_kg + 350.0;
  m[kYh] = g4.mass_kg + 180.0;
  m[kYr] = ring.mass_kg;
  m[kSeat3] = 250.0;
  m[kSeat5] = 250.0;
  m[kRes] = 1.0;

  // Constant stiffness (bearings, supports, coupling, converter).
  Mat k0 = Mat::Zero();
  auto spring = [&](int a, int b, double k) {
    k0(a, a) += k;
    if (b >= 0) {
      k0(b, b) += k;
      k0(a, b) -= k;
      k0(b, a) -= k;
    }
  };
  const double s = stiffness_scale;
  spring(kYs, -1, 2 * 2.0e9 * s);  // b1, b2
  spring(kYi, kSeat3, 1.5e9 * s);  // b3
  spring(kYi, -1, 1.5e9 * s);      // b4
  spring(kYh, kSeat5, 1.0e9 * s);  // b5
  spring(kYh, -1, 1.0e9 * s);      // b6
  spring(kSeat3, -1, 1.5e10);
  spring(kSeat5, -1, 1.5e10);
  spring(kYr, -1, 5.0e9);
  spring(kYr, kSeat3, 2.0e8);  // housing path ring → intermediate seat
  spring(kThH, kThG, 5.0e6);   // generator coupling
  spring(kThG, -1, 2.0e4);     // converter speed loop
  spring(kRes, -1, 1.0);       // the resonator, decoupled unless switched on

  // Meshes.
  std::vector<Mesh> meshes(3);
  const double rs = base_radius(ps, sun);
  meshes[0].g[kThC] = rs * ratio_p;
  meshes[0].g[kThS] = -rs;
  meshes[0].k = 1.5e10 * s;
  meshes[0].fluct[0] = 0.20;
  meshes[0].fluct[1] = 0.07;
  meshes[0].fluct[2] = 0.03;
  meshes[0].te = 2.0e-6;
  meshes[0].teeth_per_rotor_rev = ring.teeth;
  meshes[1].g[kThS] = base_radius(is, g1);
  meshes[1].g[kThI] = -base_radius(is, g2);
  meshes[1].g[kYs] = sin_a;
  meshes[1].g[kYi] = -sin_a;
  meshes[1].k = 6.0e9 * s;
  meshes[1].fluct[0] = 0.04;
  meshes[1].fluct[1] = 0.015;
  meshes[1].te = 1.0e-6;
  meshes[1].teeth_per_rotor_rev = g1.teeth * rate_sun;
  meshes[2].g[kThI] = base_radius(hs, g3);
  meshes[2].g[kThH] = -base_radius(hs, g4);
  meshes[2].g[kYi] = sin_a;
  meshes[2].g[kYh] = -sin_a;
  meshes[2].k = 3.5e9 * s;
  meshes[2].fluct[0] = 0.05;
  meshes[2].fluct[1] = 0.02;
  meshes[2].te = 1.0e-6;
  meshes[2].teeth_per_rotor_rev = g3.teeth * rate_ims;

  // Effects.
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Impacts> impacts;
  double ppm_depth = 0.0;
  struct ShaftForce {
    int dof, tdof;
    double rate, unbalance, misalignment;
  };
  std::vector<ShaftForce> shaft_forces;
  int resonance_seat = -1;
  double duration = settle_s + seconds;
  const double dt = 1.0 / (2.0 * fs_hz);
  auto shaft_rate = [&](const std::string& shaft) -> double {
    if (shaft == "planet") return rate_planet;
    const auto f = kin.shaft_hz(shaft, 60.0);
    if (!f) throw std::runtime_error("lumped gearbox: unknown shaft '" + shaft + "'");
    return *f;
  };
  for (const LumpedEffect& e : effects) {
    if (e.effect.empty()) continue;
    if (e.effect == "tooth_crack") {
      int mi = -1;
      double rate = 0.0, eps = 2.5;
      int windows = 1;
      int teeth = 0;
      if (e.location == "sun") {
        mi = 0;
        rate = ratio_p - 1.0;
        windows = ps.planets;
        eps = 1.6;
        teeth = sun.teeth;
      } else if (e.location == "planet") {
        mi = 0;
        rate = rate_planet;
        windows = 2;
        eps = 1.6;
        teeth = planet.teeth;
      } else if (e.location == "g1") {
        mi = 1;
        rate = rate_sun;
        teeth = g1.teeth;
      } else if (e.location == "g2") {
        mi = 1;
        rate = rate_ims;
        teeth = g2.teeth;
      } else if (e.location == "g3") {
        mi = 2;
        rate = rate_ims;
        teeth = g3.teeth;
      } else if (e.location == "g4") {
        mi = 2;
        rate = rate_hss;
        teeth = g4.teeth;
      } else
        throw std::runtime_error("lumped gearbox: tooth_crack at unknown gear '" + e.location +
                                 "'");
      meshes[mi].crack_loss = e.severity;
      meshes[mi].crack_half = 0.5 * eps / teeth;
      meshes[mi].crack_rate = rate;
      meshes[mi].crack_windows = windows;
    } else if (e.effect == "gear_eccentricity") {
      int mi = -1;
      double rate = 0.0;
      if (e.location == "sun") {
        mi = 0;
        rate = ratio_p - 1.0;
      } else if (e.location == "g1") {
        mi = 1;
        rate = rate_sun;
      } else if (e.location == "g2") {
        mi = 1;
        rate = rate_ims;
      } else if (e.location == "g3") {
        mi = 2;
        rate = rate_ims;
      } else if (e.location == "g4") {
        mi = 2;
        rate = rate_hss;
      } else
        throw std::runtime_error("lumped gearbox: gear_eccentricity at unknown gear '" +
                                 e.location + "'");
      meshes[mi].ecc = e.severity;
      meshes[mi].ecc_rate = rate;
      const model::GearStage& st = d.stages[static_cast<std::size_t>(mi)];
      const model::Gear* g = d.gear(e.location == "sun" ? ps.gears[0] : e.location);
      meshes[mi].base_pitch = 2.0 * kPi * base_radius(st, *g) / g->teeth;
      meshes[mi].tan_alpha = std::tan(st.pressure_angle_rad);
    } else if (e.effect.rfind("bearing_", 0) == 0) {
      const model::Bearing* b = d.bearing(e.location);
      if (b == nullptr)
        throw std::runtime_error("lumped gearbox: unknown bearing '" + e.location + "'");
      const model::BearingFrequencies o = model::bearing_orders(*b);
      const double fr = shaft_rate(b->shaft);  // shaft revs per rotor rev
      double defect = 0.0;
      int kind = 0;
      if (e.effect == "bearing_outer_race_defect")
        defect = o.bpfo_hz;
      else if (e.effect == "bearing_inner_race_defect") {
        defect = o.bpfi_hz;
        kind = 1;
      } else if (e.effect == "bearing_ball_defect") {
        defect = 2.0 * o.bsf_hz;
        kind = 2;
      } else
        throw std::runtime_error("lumped gearbox: unknown effect '" + e.effect + "'");
      Impacts im;
      const std::string& id = b->id;
      if (id == "b1" || id == "b2")
        im.dof = kYs;
      else if (id == "b3") {
        im.dof = kYi;
        im.counter_dof = kSeat3;
      } else if (id == "b4")
        im.dof = kYi;
      else if (id == "b5") {
        im.dof = kYh;
        im.counter_dof = kSeat5;
      } else if (id == "b6")
        im.dof = kYh;
      else
        im.dof = kYr;  // planet bearings: through the ring
      // Impact instants: the defect angle advances at defect·(1 − slip)·shaft speed.
      double t = 0.0;
      const double h = 1e-4;
      double phase = 0.0;
      double next = 1.0 + 0.005 * gauss(rng);
      while (t < duration) {
        const double rev0 = rotor_revs(t), rev1 = rotor_revs(t + h);
        const double dphase = defect * (1.0 - e.slip) * fr * (rev1 - rev0);
        while (phase + dphase >= next) {
          const double tt = t + (next - phase) / dphase * h;
          double w = 1.0;
          const double shaft_angle = fr * rotor_revs(tt);
          if (kind == 1) w = std::max(0.0, std::cos(2 * kPi * shaft_angle));
          if (kind == 2) w = std::max(0.0, std::cos(2 * kPi * o.ftf_hz * shaft_angle));
          im.times.push_back(tt);
          im.amplitude.push_back(e.severity * w);
          next += 1.0 + 0.005 * gauss(rng);
        }
        phase += dphase;
        t += h;
      }
      impacts.push_back(std::move(im));
    } else if (e.effect == "shaft_unbalance" || e.effect == "shaft_misalignment") {
      ShaftForce f{};
      if (e.location == "sun_shaft") {
        f.dof = kYs;
        f.tdof = kThS;
      } else if (e.location == "ims") {
        f.dof = kYi;
        f.tdof = kThI;
      } else if (e.location == "hss") {
        f.dof = kYh;
        f.tdof = kThH;
      } else
        throw std::runtime_error("lumped gearbox: " + e.effect + " at unknown shaft '" +
                                 e.location + "'");
      f.rate = shaft_rate(e.location);
      (e.effect == "shaft_unbalance" ? f.unbalance : f.misalignment) = e.severity;
      shaft_forces.push_back(f);
    } else if (e.effect == "planet_pass_modulation") {
      ppm_depth = e.severity;
    } else if (e.effect == "housing_resonance") {
      if (e.location == "b5")
        resonance_seat = kSeat5;
      else if (e.location == "b3")
        resonance_seat = kSeat3;
      else
        throw std::runtime_error(
            "lumped gearbox: housing_resonance needs a measured bearing (b5, b3)");
      // the resonator's spring and damper are added below
    } else {
      throw std::runtime_error("lumped gearbox: unknown effect '" + e.effect + "'");
    }
  }

  // Rayleigh damping on the mean stiffness of the gearbox; a resonator has its own viscous
  // damper only (its spring must not add stiffness-proportional damping to the seat).
  Mat kmean = k0;
  for (const Mesh& me : meshes) kmean += me.k * me.g * me.g.transpose();
  Mat c = (5.0 * damping_scale) * Mat(m.asDiagonal()) + (1.0e-5 * damping_scale) * kmean;
  if (resonance_seat >= 0) {
    double zeta = 0.02, fr = 1000.0;
    for (const LumpedEffect& e : effects)
      if (e.effect == "housing_resonance") {
        zeta = e.damping;
        fr = e.severity;
      }
    // A light bracket between the seat and the sensor: base-excited by the seat, too light
    // to load it (no reaction on the seat), so only what the sensor reads changes:
    // ẍ_r = −ω²(x_r − x_s) − 2ζω(ẋ_r − ẋ_s).
    const double w = 2 * kPi * fr;
    m[kRes] = 1.0;
    k0.row(kRes).setZero();
    k0(kRes, kRes) = w * w;
    k0(kRes, resonance_seat) = -w * w;
    c.row(kRes).setZero();
    c.col(kRes).setZero();
    c(kRes, kRes) = 2.0 * zeta * w;
    c(kRes, resonance_seat) = -2.0 * zeta * w;
  }

  // Planet-pass path gain p(ψ): Σ_n max(0, cos(ψ_n))⁸, its mean removed.
  auto pass_gain = [&](double carrier_revs) {
    double p = 0.0;
    for (int n = 0; n < ps.planets; ++n) {
      const double cosv = std::cos(2 * kPi * (carrier_revs + static_cast<double>(n) / ps.planets));
      p += cosv > 0.0 ? std::pow(cosv, 8) : 0.0;
    }
    return p;
  };
  double p_mean = 0.0;
  for (int i = 0; i < 1000; ++i) p_mean += pass_gain(i / 1000.0);
  p_mean /= 1000.0;

  auto mesh_state = [&](const Mesh& me, double rotor, double& k, double& e) {
    double phi = me.teeth_per_rotor_rev * rotor;
    // Run-out moves the teeth along the line of action by e·tan α·sin(gear angle): the
    // mesh cycle's phase is modulated by that over the base pitch.
    const double runout = me.ecc > 0.0 ? me.ecc * std::sin(2 * kPi * me.ecc_rate * rotor) : 0.0;
    if (me.ecc > 0.0) phi += runout * me.tan_alpha / me.base_pitch;
    k = me.k *
        (1.0 + me.fluct[0] * std::cos(2 * kPi * phi) + me.fluct[1] * std::cos(4 * kPi * phi + 0.5) +
         me.fluct[2] * std::cos(6 * kPi * phi + 1.0));
    if (me.crack_loss > 0.0) {
      const double x = frac(me.crack_rate * rotor * me.crack_windows);
      k *= 1.0 - me.crack_loss * window(x, me.crack_half * me.crack_windows);
    }
    e = me.te * (std::sin(2 * kPi * phi) + 0.3 * std::sin(4 * kPi * phi + 0.4) +
                 0.1 * std::sin(6 * kPi * phi + 1.1));
    e += runout * me.tan_alpha;
  };

  std::vector<std::size_t> next_impact(impacts.size(), 0);
  const double tau = 2.5e-4;  // [s] impact duration
  auto forces = [&](double t, const Mat& k_t, Vec& f, double& pmesh_dynamic) {
    (void)k_t;
    f.setZero();
    const double rotor = rotor_revs(t);
    const double rotor_hz = (rotor_revs(t + 1e-4) - rotor_revs(t - 1e-4)) / 2e-4;
    f[kThC] += torque_nm;
    f[kThG] -= torque_nm / ratio_total;
    for (const Mesh& me : meshes) {
      double k, e;
      mesh_state(me, rotor, k, e);
      f -= k * e * me.g;
    }
    // Planetary mesh's dynamic force to the ring (sin α of it), through the planet-pass path.
    const double gain = 1.0 + ppm_depth * (pass_gain(rotor) - p_mean);
    f[kYr] += 0.3 * sin_a * pmesh_dynamic * gain;
    for (const ShaftForce& sf : shaft_forces) {
      const double ang = 2 * kPi * sf.rate * rotor;
      const double w = 2 * kPi * sf.rate * rotor_hz;
      f[sf.dof] += sf.unbalance * w * w * std::cos(ang) +
                   sf.misalignment * (std::cos(2 * ang) + 0.4 * std::cos(ang));
      f[sf.tdof] += 0.05 * sf.misalignment * std::cos(2 * ang);
    }
    for (std::size_t i = 0; i < impacts.size(); ++i) {
      const Impacts& im = impacts[i];
      std::size_t& j = next_impact[i];
      while (j < im.times.size() && im.times[j] + tau < t) ++j;
      double v = 0.0;
      for (std::size_t q = j; q < im.times.size() && im.times[q] <= t; ++q) {
        const double sdt = t - im.times[q];
        if (sdt < tau) v += im.amplitude[q] * std::sin(kPi * sdt / tau);
      }
      f[im.dof] += v;
      if (im.counter_dof >= 0) f[im.counter_dof] -= v;
    }
  };
  auto stiffness = [&](double t, Mat& k, double& pmesh_k, double& pmesh_e) {
    k = k0;
    const double rotor = rotor_revs(t);
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      double km, e;
      mesh_state(meshes[i], rotor, km, e);
      k += km * meshes[i].g * meshes[i].g.transpose();
      if (i == 0) {
        pmesh_k = km;
        pmesh_e = e;
      }
    }
  };

  // Static start.
  Mat kt;
  double pk = 0.0, pe = 0.0;
  stiffness(0.0, kt, pk, pe);
  Vec f;
  forces(0.0, kt, f, pe);
  Vec q = kt.partialPivLu().solve(f);
  const double pmesh_static = meshes[0].k * meshes[0].g.dot(q);
  Vec v = Vec::Zero(), a = Vec::Zero();
  const auto total_steps = static_cast<std::size_t>(std::llround(duration / dt));
  const auto skip_steps = static_cast<std::size_t>(std::llround(settle_s / dt));
  LumpedOutput out;
  const std::size_t samples = (total_steps - skip_steps) / 2;
  out.point1.reserve(samples);
  out.point2.reserve(samples);
  out.hss_revolutions.reserve(samples);
  const int p1 = resonance_seat == kSeat5 ? kRes : kSeat5;
  const int p2 = resonance_seat == kSeat3 ? kRes : kSeat3;
  const Mat mm = m.asDiagonal();
  double pmesh_dynamic = 0.0;
  for (std::size_t n = 1; n <= total_steps; ++n) {
    const double t = static_cast<double>(n) * dt;
    stiffness(t, kt, pk, pe);
    forces(t, kt, f, pmesh_dynamic);
    const Mat lhs = mm + 0.5 * dt * c + 0.25 * dt * dt * kt;
    const Vec rhs = f - c * (v + 0.5 * dt * a) - kt * (q + dt * v + 0.25 * dt * dt * a);
    const Vec a1 = lhs.partialPivLu().solve(rhs);
    q += dt * v + 0.25 * dt * dt * (a + a1);
    v += 0.5 * dt * (a + a1);
    a = a1;
    pmesh_dynamic = pk * (meshes[0].g.dot(q) + pe) - pmesh_static;
    if (n > skip_steps && (n - skip_steps) % 2 == 0) {
      out.point1.push_back(a[p1]);
      out.point2.push_back(a[p2]);
      out.hss_revolutions.push_back(rate_hss * rotor_revs(t));
    }
  }
  return out;
}

}  // namespace tools::diagnosis
