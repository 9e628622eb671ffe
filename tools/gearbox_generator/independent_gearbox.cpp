#include "independent_gearbox.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace tools::generator {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// ---- the reference gearbox (shared/reference/drivetrain-2mw.md), copied here on purpose -----
constexpr int kZSun = 21, kZPlanet = 39, kZRing = 99, kZg1 = 92, kZg2 = 21, kZg3 = 107, kZg4 = 26;
constexpr double kModulePlanetary = 0.017, kModuleParallel = 0.014;  // [m] normal modules
constexpr double kPressureAngle = 20.0 * kDeg, kHelix = 10.0 * kDeg;
constexpr double kMassPlanet = 994, kMassSun = 286, kMassG1 = 2724, kMassG2 = 102, kMassG3 = 2096,
                 kMassG4 = 101;  // [kg]
constexpr int kPlanets = 3;

struct Vec2 {
  double x = 0, y = 0;
};
Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
Vec2 unit(double angle) { return {std::cos(angle), std::sin(angle)}; }
Vec2 perp(Vec2 a) { return {-a.y, a.x}; }  // ẑ × a

// A gear (or shaft node) in the plane: its DOFs (−1: none, i.e. held) and centre.
struct Body {
  int x = -1, y = -1, t = -1;
  Vec2 centre;
};

// Geometry of one mesh at an instant: line-of-action direction n (force on the driven
// gear = +k·δ·n) and the two gears' lever arms λ = (ρ × n)_z.
struct MeshLine {
  Vec2 n;
  double lever_driver = 0, lever_driven = 0;
};
MeshLine mesh_line(Vec2 driver_centre, Vec2 driven_centre, Vec2 pitch_point, Vec2 n) {
  auto lever = [&](Vec2 centre) {
    const Vec2 d = pitch_point - centre;
    const Vec2 rho = d - dot(d, n) * n;  // foot of the perpendicular onto the line
    return cross(rho, n);
  };
  return {n, lever(driver_centre), lever(driven_centre)};
}

double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}
double uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return u(rng);
}

// Spur mesh stiffness over one cycle, mean 1: double contact for a fraction ε − 1 of the
// cycle at `ratio` × the single-contact stiffness, raised-cosine transitions of 4 %.
double spur_shape(double phase, double contact_ratio, double ratio) {
  const double f = phase - std::floor(phase);
  const double dbl = contact_ratio - 1.0;  // fraction of the cycle in double contact
  const double ramp = 0.04;
  double w;  // 0 single, 1 double
  if (f < dbl) {
    w = 1.0;
  } else if (f < dbl + ramp) {
    w = 0.5 * (1.0 + std::cos(kPi * (f - dbl) / ramp));
  } else if (f > 1.0 - ramp) {
    w = 0.5 * (1.0 - std::cos(kPi * (f - (1.0 - ramp)) / ramp));
  } else {
    w = 0.0;
  }
  const double mean = (1.0 - dbl) + dbl * ratio;  // single = 1 (transitions nearly symmetric)
  return (1.0 + w * (ratio - 1.0)) / mean;
}

}  // namespace

// ---- choices ----------------------------------------------------------------------------------
GearboxChoices GearboxChoices::draw(std::uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 12345);
  GearboxChoices c;
  c.rotor_inertia_kg_m2 = log_uniform(rng, 3e6, 6e6);
  c.carrier_inertia_kg_m2 = log_uniform(rng, 600, 1500);
  c.generator_inertia_kg_m2 = log_uniform(rng, 60, 120);
  c.shaft_node_mass_kg = log_uniform(rng, 40, 120);
  c.main_shaft_nm_rad = log_uniform(rng, 5e7, 2e8);
  c.sun_shaft_torsion_nm_rad = log_uniform(rng, 2e8, 6e8);
  c.ims_torsion_nm_rad = log_uniform(rng, 1e8, 3e8);
  c.coupling_nm_rad = log_uniform(rng, 3e6, 1e7);
  c.converter_nm_rad = log_uniform(rng, 1e4, 5e4);
  c.converter_damping_nms_rad = log_uniform(rng, 50, 300);
  c.bending_n_m = log_uniform(rng, 2e9, 8e9);
  const std::array<std::array<double, 2>, 7> bearing_range{{{1e9, 4e9},
                                                            {1e9, 4e9},
                                                            {0.6e9, 2.5e9},
                                                            {0.6e9, 2.5e9},
                                                            {0.4e9, 1.6e9},
                                                            {0.4e9, 1.6e9},
                                                            {1e9, 3e9}}};
  for (std::size_t i = 0; i < 7; ++i)
    c.bearing_n_m[i] = log_uniform(rng, bearing_range[i][0], bearing_range[i][1]);
  c.bearing_damping_ratio = uniform(rng, 0.02, 0.05);
  // Transverse mesh stiffness c_γ·b with c_γ 13–22 N/(mm·µm) and the reference's face widths.
  const std::array<double, 3> face_mm{370, 300, 170};
  for (std::size_t s = 0; s < 3; ++s) {
    c.mesh_stiffness_n_m[s] = uniform(rng, 13, 22) * face_mm[s] * 1e6;
    c.mesh_damping_ratio[s] = uniform(rng, 0.03, 0.10);
  }
  c.spur_double_single_ratio = uniform(rng, 1.5, 1.9);
  c.helical_ripple = uniform(rng, 0.02, 0.08);
  // Transmission error: first harmonic log-uniform (spur larger), a geometric decay with
  // ±30 % scatter per harmonic, random phases.
  for (std::size_t s = 0; s < 3; ++s) {
    const double a1 = s == 0 ? log_uniform(rng, 2e-6, 8e-6) : log_uniform(rng, 0.7e-6, 4e-6);
    const double decay = uniform(rng, 0.25, 0.6);
    for (std::size_t h = 0; h < 5; ++h) {
      c.te_m[s][h] = a1 * std::pow(decay, static_cast<double>(h)) * uniform(rng, 0.7, 1.3);
      c.te_phase[s][h] = uniform(rng, -kPi, kPi);
    }
  }
  for (std::size_t p = 0; p < 2; ++p) {
    c.seat_mass_kg[p] = log_uniform(rng, 80, 300);
    c.wall_mass_kg[p] = log_uniform(rng, 200, 800);
    c.seat_n_m[p] = log_uniform(rng, 5e9, 3e10);
    c.wall_n_m[p] = log_uniform(rng, 1e10, 5e10);
    c.sensor_gain[p] = uniform(rng, 0.95, 1.05);
    c.sensor_tilt_rad[p] = uniform(rng, -5.0, 5.0) * kDeg;
  }
  c.body_mass_kg = log_uniform(rng, 3000, 8000);
  c.body_n_m = log_uniform(rng, 2e9, 8e9);
  c.housing_damping_ratio = uniform(rng, 0.02, 0.05);
  c.mass_damping_1_s = uniform(rng, 0.5, 3.0);
  c.noise_relative = uniform(rng, 0.02, 0.05);
  c.turbulence_relative = uniform(rng, 0.03, 0.08);
  c.turbulence_corner_hz = log_uniform(rng, 0.05, 0.3);
  c.ripple_3p_relative = uniform(rng, 0.005, 0.02);
  c.drift_relative = uniform(rng, 0.005, 0.01);
  c.drift_period_s = {uniform(rng, 8, 25), uniform(rng, 2, 6)};
  c.drift_phase = {uniform(rng, -kPi, kPi), uniform(rng, -kPi, kPi)};
  // Residual unbalance of the hss for balance grade G 2.5 at rated speed (25.4 Hz):
  // U = m·e = m·G/ω, m ≈ g4 + shaft ≈ 250 kg.
  c.hss_unbalance_kg_m = 250.0 * 2.5e-3 / (2 * kPi * 25.4);
  return c;
}

std::string GearboxChoices::describe() const {
  std::ostringstream o;
  o.precision(3);
  o << "bearings b1..b6, pb [N/m]:";
  for (double k : bearing_n_m) o << ' ' << k;
  o << "; mesh k [N/m]:";
  for (double k : mesh_stiffness_n_m) o << ' ' << k;
  o << "; TE [um] stage x harmonic:";
  for (const auto& s : te_m) {
    o << " (";
    for (double a : s) o << ' ' << a * 1e6;
    o << " )";
  }
  o << "; seat/wall mass [kg] " << seat_mass_kg[0] << '/' << wall_mass_kg[0] << ", "
    << seat_mass_kg[1] << '/' << wall_mass_kg[1] << "; seat/wall k [N/m] " << seat_n_m[0] << '/'
    << wall_n_m[0] << ", " << seat_n_m[1] << '/' << wall_n_m[1] << "; body " << body_mass_kg
    << " kg on " << body_n_m << " N/m; housing zeta " << housing_damping_ratio << "; mesh zeta "
    << mesh_damping_ratio[0] << ' ' << mesh_damping_ratio[1] << ' ' << mesh_damping_ratio[2]
    << "; sensor gains " << sensor_gain[0] << ' ' << sensor_gain[1] << ", tilts [deg] "
    << sensor_tilt_rad[0] / kDeg << ' ' << sensor_tilt_rad[1] / kDeg << "; noise " << noise_relative
    << "; turbulence " << turbulence_relative << " (corner " << turbulence_corner_hz
    << " Hz); speed drift " << drift_relative;
  return o.str();
}

// ---- the model --------------------------------------------------------------------------------
struct IndependentGearbox::Impl {
  GearboxChoices c;
  std::vector<std::string> names;
  Eigen::VectorXd mass;
  std::map<std::string, int> index;

  // Constant springs: f = −(k·δ + c·δ̇)·coef_j on dof_j, δ = Σ coef_j x_j.
  struct Spring {
    std::vector<std::pair<int, double>> terms;
    double k = 0, c = 0;
  };
  std::vector<Spring> springs;

  // Bodies.
  Body rotor, carrier, sun, g1, g2, g3, g4, generator;
  std::array<Body, kPlanets> planet{};
  Body b1, b2, b3, b4, b5, b6;
  std::array<Body, 2> seat{}, wall{};
  Body body;
  // Geometry.
  double r_sun = 0, r_planet = 0, r_ring = 0, r_carrier = 0, alpha_t = 0;
  double rb_sun = 0, rb_planet = 0;
  double r_g1 = 0, r_g2 = 0, r_g3 = 0, r_g4 = 0;
  Vec2 ims_centre, hss_centre;
  double contact_ratio_spur = 1.65;
  // Kinematics: revolutions of each shaft per rotor revolution.
  double sun_ratio = 0, ims_ratio = 0, hss_ratio = 0;
  // Meshes: damping per stage [N·s/m] (on the line of action).
  std::array<double, 3> mesh_c{};
  std::vector<std::shared_ptr<const Effect>> effects;

  int add(const std::string& name, double m) {
    index[name] = static_cast<int>(names.size());
    names.push_back(name);
    mass.conservativeResize(static_cast<Eigen::Index>(names.size()));
    mass[mass.size() - 1] = m;
    return static_cast<int>(names.size()) - 1;
  }
  Body add_body(const std::string& name, double m, double j, Vec2 centre, bool rotates) {
    Body b;
    b.x = add(name + ".x", m);
    b.y = add(name + ".y", m);
    if (rotates) b.t = add(name + ".theta", j);
    b.centre = centre;
    return b;
  }
  // A spring with damping ratio ζ on the lighter side's mass.
  void spring(std::vector<std::pair<int, double>> terms, double k, double zeta, double m_ref) {
    springs.push_back({std::move(terms), k, 2.0 * zeta * std::sqrt(k * m_ref)});
  }
  void lateral(const Body& a, const Body& b, double k, double zeta, double m_ref) {
    if (b.x >= 0) {
      spring({{a.x, 1.0}, {b.x, -1.0}}, k, zeta, m_ref);
      spring({{a.y, 1.0}, {b.y, -1.0}}, k, zeta, m_ref);
    } else {
      spring({{a.x, 1.0}}, k, zeta, m_ref);
      spring({{a.y, 1.0}}, k, zeta, m_ref);
    }
  }

  explicit Impl(const GearboxChoices& ch) : c(ch) {
    // Gear geometry: pitch radii from the transverse module, transverse pressure angle.
    r_sun = 0.5 * kZSun * kModulePlanetary;
    r_planet = 0.5 * kZPlanet * kModulePlanetary;
    r_ring = 0.5 * kZRing * kModulePlanetary;
    r_carrier = r_sun + r_planet;
    rb_sun = r_sun * std::cos(kPressureAngle);
    rb_planet = r_planet * std::cos(kPressureAngle);
    const double mt = kModuleParallel / std::cos(kHelix);
    alpha_t = std::atan(std::tan(kPressureAngle) / std::cos(kHelix));
    r_g1 = 0.5 * kZg1 * mt;
    r_g2 = 0.5 * kZg2 * mt;
    r_g3 = 0.5 * kZg3 * mt;
    r_g4 = 0.5 * kZg4 * mt;
    sun_ratio = 1.0 + static_cast<double>(kZRing) / kZSun;
    ims_ratio = sun_ratio * kZg1 / kZg2;
    hss_ratio = ims_ratio * kZg3 / kZg4;
    // Layout (this generator's own): the ims below-left of the sun shaft, the hss above it.
    ims_centre = (r_g1 + r_g2) * unit(200.0 * kDeg);
    hss_centre = ims_centre + (r_g3 + r_g4) * unit(95.0 * kDeg);
    // Spur contact ratio from the tip circles (addendum = module).
    auto path = [](double r, double rb) { return std::sqrt(std::pow(r, 2) - rb * rb); };
    const double ra_s = r_sun + kModulePlanetary;
    const double ra_p = r_planet + kModulePlanetary;
    const double g_alpha =
        path(ra_s, rb_sun) + path(ra_p, rb_planet) - r_carrier * std::sin(kPressureAngle);
    contact_ratio_spur = g_alpha / (kPi * kModulePlanetary * std::cos(kPressureAngle));

    // Inertias: a gear as a disc with a web, 0.45·m·r².
    auto disc = [](double m, double r) { return 0.45 * m * r * r; };
    rotor.t = add("rotor.theta", c.rotor_inertia_kg_m2);
    carrier.t = add("carrier.theta", c.carrier_inertia_kg_m2);
    for (int i = 0; i < kPlanets; ++i) {
      planet[static_cast<std::size_t>(i)] = add_body("planet" + std::to_string(i + 1), kMassPlanet,
                                                     disc(kMassPlanet, r_planet), {}, true);
    }
    const double m_node = c.shaft_node_mass_kg;
    sun = add_body("sun", kMassSun + 0.5 * m_node, disc(kMassSun, r_sun), {}, true);
    b1 = add_body("sun_shaft.b1", m_node, 0, {}, false);
    g1 = add_body("g1", kMassG1, disc(kMassG1, r_g1), {}, true);
    b2 = add_body("sun_shaft.b2", m_node, 0, {}, false);
    b3 = add_body("ims.b3", m_node, 0, ims_centre, false);
    g2 = add_body("g2", kMassG2 + 0.5 * m_node, disc(kMassG2, r_g2), ims_centre, true);
    g3 = add_body("g3", kMassG3, disc(kMassG3, r_g3), ims_centre, true);
    b4 = add_body("ims.b4", m_node, 0, ims_centre, false);
    b5 = add_body("hss.b5", m_node, 0, hss_centre, false);
    g4 = add_body("g4", kMassG4 + 0.5 * m_node, disc(kMassG4, r_g4), hss_centre, true);
    b6 = add_body("hss.b6", m_node, 0, hss_centre, false);
    generator.t = add("generator.theta", c.generator_inertia_kg_m2);
    for (std::size_t p = 0; p < 2; ++p) {
      const std::string bearing = p == 0 ? "b5" : "b3";
      seat[p] = add_body("seat." + bearing, c.seat_mass_kg[p], 0, {}, false);
      wall[p] = add_body("wall." + bearing, c.wall_mass_kg[p], 0, {}, false);
    }
    body = add_body("housing", c.body_mass_kg, 0, {}, false);

    const double zb = c.bearing_damping_ratio;
    const double zh = c.housing_damping_ratio;
    // Torsion.
    spring({{rotor.t, 1.0}, {carrier.t, -1.0}}, c.main_shaft_nm_rad, 0.02, c.carrier_inertia_kg_m2);
    spring({{sun.t, 1.0}, {g1.t, -1.0}}, c.sun_shaft_torsion_nm_rad, 0.02, disc(kMassSun, r_sun));
    spring({{g2.t, 1.0}, {g3.t, -1.0}}, c.ims_torsion_nm_rad, 0.02, disc(kMassG2, r_g2));
    spring({{g4.t, 1.0}, {generator.t, -1.0}}, c.coupling_nm_rad, 0.02, disc(kMassG4, r_g4));
    springs.push_back({{{generator.t, 1.0}}, c.converter_nm_rad, c.converter_damping_nms_rad});
    // Shaft bending between neighbouring nodes.
    lateral(sun, b1, c.bending_n_m, 0.02, m_node);
    lateral(b1, g1, c.bending_n_m, 0.02, m_node);
    lateral(g1, b2, c.bending_n_m, 0.02, m_node);
    lateral(b3, g2, c.bending_n_m, 0.02, m_node);
    lateral(g2, g3, c.bending_n_m, 0.02, m_node);
    lateral(g3, b4, c.bending_n_m, 0.02, m_node);
    lateral(b5, g4, c.bending_n_m, 0.02, m_node);
    lateral(g4, b6, c.bending_n_m, 0.02, m_node);
    // Bearings: b1, b2 to ground; b4, b6 to the housing body; b3, b5 to their seats.
    lateral(b1, Body{}, c.bearing_n_m[0], zb, m_node);
    lateral(b2, Body{}, c.bearing_n_m[1], zb, m_node);
    lateral(b3, seat[1], c.bearing_n_m[2], zb, m_node);
    lateral(b4, body, c.bearing_n_m[3], zb, m_node);
    lateral(b5, seat[0], c.bearing_n_m[4], zb, m_node);
    lateral(b6, body, c.bearing_n_m[5], zb, m_node);
    // Housing: seat → wall → body → ground.
    for (std::size_t p = 0; p < 2; ++p) {
      lateral(seat[p], wall[p], c.seat_n_m[p], zh, c.seat_mass_kg[p]);
      lateral(wall[p], body, c.wall_n_m[p], zh, c.wall_mass_kg[p]);
    }
    lateral(body, Body{}, c.body_n_m, zh, c.body_mass_kg);

    // Mesh damping on the line of action: c = 2ζ·√(k·m_eq), m_eq of the two gears' inertias.
    auto m_eq = [](double j_a, double rb_a, double j_b, double rb_b) {
      return 1.0 / (rb_a * rb_a / j_a + (j_b > 0 ? rb_b * rb_b / j_b : 0.0));
    };
    mesh_c[0] = 2.0 * c.mesh_damping_ratio[0] *
                std::sqrt(c.mesh_stiffness_n_m[0] * m_eq(disc(kMassPlanet, r_planet), rb_planet,
                                                         disc(kMassSun, r_sun), rb_sun));
    mesh_c[1] =
        2.0 * c.mesh_damping_ratio[1] *
        std::sqrt(c.mesh_stiffness_n_m[1] * m_eq(disc(kMassG1, r_g1), r_g1 * std::cos(alpha_t),
                                                 disc(kMassG2, r_g2), r_g2 * std::cos(alpha_t)));
    mesh_c[2] =
        2.0 * c.mesh_damping_ratio[2] *
        std::sqrt(c.mesh_stiffness_n_m[2] * m_eq(disc(kMassG3, r_g3), r_g3 * std::cos(alpha_t),
                                                 disc(kMassG4, r_g4), r_g4 * std::cos(alpha_t)));
  }

  int n() const { return static_cast<int>(names.size()); }

  // One mesh element at an instant: coefficients of δ on the DOFs, stiffness, error, damping.
  struct MeshState {
    std::array<std::pair<int, double>, 6> terms{};
    int count = 0;
    double k = 0, e = 0, c = 0;
    void add(int dof, double coef) {
      if (dof >= 0) terms[static_cast<std::size_t>(count++)] = {dof, coef};
    }
  };

  // The eight meshes at nominal angles `a` (revolutions). Order: sun_planet_1..3,
  // ring_planet_1..3, intermediate, high_speed. `mean`: mean stiffness, no error.
  void meshes(const Angles& a, bool mean, std::array<MeshState, 8>& out) const {
    const double carrier_angle = 2 * kPi * a.carrier;
    const double phase_planetary = kZRing * a.carrier;  // mesh cycles (ring fixed)
    for (int i = 0; i < kPlanets; ++i) {
      const double psi0 = 2 * kPi * i / kPlanets;
      const Vec2 u = unit(psi0 + carrier_angle);
      const Vec2 w = perp(u);
      const Body& p = planet[static_cast<std::size_t>(i)];
      // Sun–planet: force on the sun along +w (it drives the sun), separating (−u).
      {
        const Vec2 n = std::cos(kPressureAngle) * w - std::sin(kPressureAngle) * u;
        const Vec2 pc = r_carrier * u;
        const MeshLine l = mesh_line(pc, {0, 0}, r_sun * u, n);
        MeshState& m = out[static_cast<std::size_t>(i)];
        m = {};
        m.add(p.x, n.x);
        m.add(p.y, n.y);
        m.add(p.t, l.lever_driver);
        m.add(sun.x, -n.x);
        m.add(sun.y, -n.y);
        m.add(sun.t, -l.lever_driven);
        const double phase = phase_planetary + kZSun * psi0 / (2 * kPi);
        fill(m, 0, phase, a, i, mean);
      }
      // Ring–planet: force on the (fixed) ring along +w (reaction), separating (+u).
      {
        const Vec2 n = std::cos(kPressureAngle) * w + std::sin(kPressureAngle) * u;
        const Vec2 pc = r_carrier * u;
        const MeshLine l = mesh_line(pc, {0, 0}, r_ring * u, n);
        MeshState& m = out[static_cast<std::size_t>(kPlanets + i)];
        m = {};
        m.add(p.x, n.x);
        m.add(p.y, n.y);
        m.add(p.t, l.lever_driver);
        const double phase = phase_planetary - kZRing * psi0 / (2 * kPi) + 0.5;
        fill(m, 0, phase, a, kPlanets + i, mean);
      }
    }
    // Intermediate: g1 (CCW) drives g2; hss: g3 (CW) drives g4.
    auto parallel = [&](const Body& drv, const Body& drn, double r_drv, double spin, int stage,
                        double phase, int index_) {
      const Vec2 u = (1.0 / std::sqrt(dot(drn.centre - drv.centre, drn.centre - drv.centre))) *
                     (drn.centre - drv.centre);
      const Vec2 w = perp(u);
      const Vec2 n = spin * std::cos(alpha_t) * w + std::sin(alpha_t) * u;
      const MeshLine l = mesh_line(drv.centre, drn.centre, drv.centre + r_drv * u, n);
      MeshState& m = out[static_cast<std::size_t>(index_)];
      m = {};
      m.add(drv.x, n.x);
      m.add(drv.y, n.y);
      m.add(drv.t, l.lever_driver);
      m.add(drn.x, -n.x);
      m.add(drn.y, -n.y);
      m.add(drn.t, -l.lever_driven);
      fill(m, stage, phase, a, index_, mean);
    };
    parallel(g1, g2, r_g1, +1.0, 1, kZg1 * a.sun_shaft, 6);
    parallel(g3, g4, r_g3, -1.0, 2, kZg3 * std::abs(a.ims), 7);
  }

  void fill(MeshState& m, int stage, double phase, const Angles& a, int index_, bool mean) const {
    const auto s = static_cast<std::size_t>(stage);
    double shape = 1.0;
    double e = 0.0;
    if (!mean) {
      shape = stage == 0 ? spur_shape(phase, contact_ratio_spur, c.spur_double_single_ratio)
                         : 1.0 + c.helical_ripple * std::cos(2 * kPi * phase) +
                               0.3 * c.helical_ripple * std::cos(4 * kPi * phase + 0.7);
      for (std::size_t h = 0; h < 5; ++h)
        e += c.te_m[s][h] *
             std::cos(2 * kPi * static_cast<double>(h + 1) * phase + c.te_phase[s][h]);
      for (const auto& eff : effects) {
        shape *= eff->mesh_stiffness_factor(index_, a);
        e += eff->mesh_error_m(index_, a);
      }
    }
    m.k = c.mesh_stiffness_n_m[s] * shape;
    m.e = e;
    m.c = mesh_c[s];
  }

  // Carrier pin of planet i moves with the carrier's vibratory rotation: planet bearing
  // springs (planet − pin) in x and y with the pin at θ_c·ẑ × R_i.
  struct PinSpring {
    std::array<std::pair<int, double>, 2> terms{};
    double k = 0, c = 0;
  };
  void planet_bearings(const Angles& a, std::array<PinSpring, 2 * kPlanets>& out) const {
    const double carrier_angle = 2 * kPi * a.carrier;
    const double k = c.bearing_n_m[6];
    const double cc = 2.0 * c.bearing_damping_ratio * std::sqrt(k * kMassPlanet);
    for (int i = 0; i < kPlanets; ++i) {
      const Vec2 r = r_carrier * unit(2 * kPi * i / kPlanets + carrier_angle);
      const Body& p = planet[static_cast<std::size_t>(i)];
      out[static_cast<std::size_t>(2 * i)] = {
          {{{p.x, 1.0}, {carrier.t, r.y}}}, k, cc};  // x − (−R_y θ_c)
      out[static_cast<std::size_t>(2 * i + 1)] = {
          {{{p.y, 1.0}, {carrier.t, -r.x}}}, k, cc};  // y − R_x θ_c
    }
  }

  Angles angles(double t, double rotor_revs, double rotor_hz) const {
    Angles a;
    a.time_s = t;
    a.carrier = rotor_revs;
    a.sun_shaft = sun_ratio * rotor_revs;
    a.ims = -ims_ratio * rotor_revs;
    a.hss = hss_ratio * rotor_revs;
    a.rotor_hz = rotor_hz;
    return a;
  }

  // Forces f = F_ext − Σ elements, at state (x, v).
  struct Work {
    std::array<PinSpring, 2 * kPlanets> pins{};
    std::array<MeshState, 8> meshes{};
    std::vector<double> ext;
  };
  template <class Terms>
  static void apply(const Terms& terms, std::size_t count, double k, double cd, double e,
                    const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& f) {
    double d = -e;
    double dd = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      d += terms[i].second * x[terms[i].first];
      dd += terms[i].second * v[terms[i].first];
    }
    const double force = k * d + cd * dd;
    for (std::size_t i = 0; i < count; ++i) f[terms[i].first] -= force * terms[i].second;
  }
  void forces(const Angles& a, double torque_rotor, double torque_generator,
              const Eigen::VectorXd& x, const Eigen::VectorXd& v, bool mean, Work& w,
              Eigen::VectorXd& f) const {
    f.setZero();
    for (const Spring& s : springs) apply(s.terms, s.terms.size(), s.k, s.c, 0.0, x, v, f);
    planet_bearings(a, w.pins);
    for (const PinSpring& s : w.pins) apply(s.terms, 2, s.k, s.c, 0.0, x, v, f);
    meshes(a, mean, w.meshes);
    for (const MeshState& m : w.meshes)
      apply(m.terms, static_cast<std::size_t>(m.count), m.k, mean ? 0.0 : m.c, m.e, x, v, f);
    f[rotor.t] += torque_rotor;
    f[generator.t] -= torque_generator;
    if (!mean) {
      w.ext.assign(static_cast<std::size_t>(n()), 0.0);
      for (const auto& eff : effects) eff->add_forces(a, w.ext);
      for (int j = 0; j < n(); ++j) f[j] += w.ext[static_cast<std::size_t>(j)];
      // Mass-proportional damping on every DOF.
      f.array() -= c.mass_damping_1_s * mass.array() * v.array();
    }
  }

  // Static deflection under the mean torque and the mean stiffness (angle 0).
  Eigen::VectorXd static_state(double torque) const {
    const int nn = n();
    Eigen::MatrixXd k(nn, nn);
    Eigen::VectorXd f0(nn), f1(nn);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(nn), v = Eigen::VectorXd::Zero(nn);
    Work w;
    const Angles a0 = angles(0, 0, 0);
    const double t_gen = torque / hss_ratio;
    forces(a0, torque, t_gen, x, v, true, w, f0);  // external only at x = 0
    for (int j = 0; j < nn; ++j) {
      x.setZero();
      x[j] = 1.0;
      forces(a0, 0.0, 0.0, x, v, true, w, f1);
      k.col(j) = -f1;
    }
    return k.partialPivLu().solve(f0);
  }
};

IndependentGearbox::IndependentGearbox(const GearboxChoices& choices)
    : impl_(std::make_unique<Impl>(choices)) {}
IndependentGearbox::~IndependentGearbox() = default;

int IndependentGearbox::dof(const std::string& name) const {
  const auto it = impl_->index.find(name);
  return it == impl_->index.end() ? -1 : it->second;
}
int IndependentGearbox::dofs() const { return impl_->n(); }
void IndependentGearbox::add_effect(std::shared_ptr<const Effect> effect) {
  impl_->effects.push_back(std::move(effect));
}

std::vector<double> IndependentGearbox::static_mesh_forces(double input_torque_nm) const {
  const Eigen::VectorXd x = impl_->static_state(input_torque_nm);
  std::array<Impl::MeshState, 8> ms{};
  impl_->meshes(impl_->angles(0, 0, 0), true, ms);
  std::vector<double> out;
  for (const auto& m : ms) {
    double d = 0.0;
    for (int k = 0; k < m.count; ++k)
      d += m.terms[static_cast<std::size_t>(k)].second *
           x[m.terms[static_cast<std::size_t>(k)].first];
    out.push_back(m.k * d);
  }
  return out;
}

std::vector<double> IndependentGearbox::driven_base_radius_m() const {
  const Impl& m = *impl_;
  const double ca = std::cos(m.alpha_t);
  return {m.rb_sun,
          m.rb_sun,
          m.rb_sun,
          m.r_ring * std::cos(kPressureAngle),
          m.r_ring * std::cos(kPressureAngle),
          m.r_ring * std::cos(kPressureAngle),
          m.r_g2 * ca,
          m.r_g4 * ca};
}

std::vector<double> IndependentGearbox::driven_torque_ratio() const {
  const Impl& m = *impl_;
  const double sun = 1.0 / m.sun_ratio;
  const double ims = sun * kZg2 / kZg1;
  const double hss = ims * kZg4 / kZg3;
  return {sun / kPlanets,
          sun / kPlanets,
          sun / kPlanets,
          (1 - sun) / kPlanets,
          (1 - sun) / kPlanets,
          (1 - sun) / kPlanets,
          ims,
          hss};
}

GeneratedRecording IndependentGearbox::run(const GeneratorSettings& s) const {
  const Impl& m = *impl_;
  const GearboxChoices& c = m.c;
  if (!(s.rotor_speed_rpm > 0) || !(s.input_torque_nm >= 0) || !(s.duration_s > 0) ||
      !(s.sample_rate_hz >= 4096) || !(s.settle_s >= 0)) {
    throw std::runtime_error(
        "generator: speed > 0, torque >= 0, duration > 0, rate >= 4096 Hz, settle >= 0 needed");
  }
  const int nn = m.n();
  const double dt = 1.0 / (2.0 * s.sample_rate_hz);  // two RK4 steps per sample
  const auto samples = static_cast<std::size_t>(std::llround(s.duration_s * s.sample_rate_hz));
  const auto settle = static_cast<std::size_t>(std::llround(s.settle_s * s.sample_rate_hz));
  const double f0 = s.rotor_speed_rpm / 60.0;
  std::mt19937_64 rng(s.noise_seed * 0x2545F4914F6CDD1DULL + 7);
  std::normal_distribution<double> gauss(0.0, 1.0);

  // Speed: f(t) = f0·(1 + drift·d(t)), d in [−1, 1]; angle integrated exactly.
  const double w1 = 2 * kPi / c.drift_period_s[0], w2 = 2 * kPi / c.drift_period_s[1];
  auto drift = [&](double t) {
    return (std::sin(w1 * t + c.drift_phase[0]) + 0.5 * std::sin(w2 * t + c.drift_phase[1])) / 1.5;
  };
  auto drift_integral = [&](double t) {
    return (-(std::cos(w1 * t + c.drift_phase[0]) - std::cos(c.drift_phase[0])) / w1 -
            0.5 * (std::cos(w2 * t + c.drift_phase[1]) - std::cos(c.drift_phase[1])) / w2) /
           1.5;
  };
  auto rotor_revs = [&](double t) { return f0 * (t + c.drift_relative * drift_integral(t)); };
  auto rotor_hz = [&](double t) { return f0 * (1.0 + c.drift_relative * drift(t)); };

  // Torque: mean + Ornstein–Uhlenbeck turbulence (updated per output sample) + 3P ripple.
  double ou = 0.0;
  const double ou_decay = std::exp(-2 * kPi * c.turbulence_corner_hz / s.sample_rate_hz);
  const double ou_kick = std::sqrt(1.0 - ou_decay * ou_decay);
  const double t_gen = s.input_torque_nm / m.hss_ratio;

  Eigen::VectorXd x = m.static_state(s.input_torque_nm);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(nn);
  Eigen::VectorXd k1x(nn), k1v(nn), k2x(nn), k2v(nn), k3x(nn), k3v(nn), k4x(nn), k4v(nn), f(nn),
      xt(nn), vt(nn);
  Impl::Work work;
  const Eigen::VectorXd inv_m = m.mass.cwiseInverse();

  auto accel = [&](double t, const Eigen::VectorXd& xs, const Eigen::VectorXd& vs, double torque,
                   Eigen::VectorXd& a_out) {
    const Angles a = m.angles(t, rotor_revs(t), rotor_hz(t));
    // The residual hss unbalance: U·ω²·(cos, sin) of the hss angle on the g4 node.
    m.forces(a, torque, t_gen, xs, vs, false, work, f);
    const double w = 2 * kPi * m.hss_ratio * a.rotor_hz;
    const double phi = 2 * kPi * a.hss;
    f[m.g4.x] += c.hss_unbalance_kg_m * w * w * std::cos(phi);
    f[m.g4.y] += c.hss_unbalance_kg_m * w * w * std::sin(phi);
    a_out = f.cwiseProduct(inv_m);
  };

  GeneratedRecording out;
  out.sample_rate_hz = s.sample_rate_hz;
  out.point1.reserve(samples);
  out.point2.reserve(samples);
  out.tacho.reserve(samples);
  double t = 0.0;
  double speed_sum = 0.0;
  Eigen::VectorXd acc(nn);
  for (std::size_t i = 0; i < settle + samples; ++i) {
    ou = ou_decay * ou + ou_kick * gauss(rng);
    const double torque =
        s.input_torque_nm * (1.0 + c.turbulence_relative * ou +
                             c.ripple_3p_relative * std::cos(2 * kPi * 3.0 * rotor_revs(t)));
    for (int sub = 0; sub < 2; ++sub) {
      accel(t, x, v, torque, k1v);
      k1x = v;
      xt = x + 0.5 * dt * k1x;
      vt = v + 0.5 * dt * k1v;
      accel(t + 0.5 * dt, xt, vt, torque, k2v);
      k2x = vt;
      xt = x + 0.5 * dt * k2x;
      vt = v + 0.5 * dt * k2v;
      accel(t + 0.5 * dt, xt, vt, torque, k3v);
      k3x = vt;
      xt = x + dt * k3x;
      vt = v + dt * k3v;
      accel(t + dt, xt, vt, torque, k4v);
      k4x = vt;
      x += dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
      t += dt;
    }
    if (!std::isfinite(x[0])) throw std::runtime_error("generator: integration diverged");
    if (i < settle) continue;
    accel(t, x, v, torque, acc);
    for (std::size_t p = 0; p < 2; ++p) {
      const Body& seat = m.seat[p];
      const double tilt = c.sensor_tilt_rad[p];
      // Radial (vertical, +y) through a sensor tilted by `tilt`, gain from the choices.
      const double a =
          c.sensor_gain[p] * (std::cos(tilt) * acc[seat.y] + std::sin(tilt) * acc[seat.x]);
      (p == 0 ? out.point1 : out.point2).push_back(a);
    }
    const double hss = m.hss_ratio * rotor_revs(t);
    out.tacho.push_back(hss - std::floor(hss) < 0.05 ? 5.0 : 0.0);
    speed_sum += rotor_hz(t) * 60.0;
  }
  // Sensor noise: white, RMS = noise_relative × the channel's RMS.
  for (std::vector<double>* ch : {&out.point1, &out.point2}) {
    double mean = 0.0;
    for (double a : *ch) mean += a;
    mean /= static_cast<double>(ch->size());
    double ss = 0.0;
    for (double a : *ch) ss += (a - mean) * (a - mean);
    const double sigma = c.noise_relative * std::sqrt(ss / static_cast<double>(ch->size()));
    for (double& a : *ch) a += sigma * gauss(rng);
  }
  out.mean_rotor_speed_rpm = speed_sum / static_cast<double>(samples);
  out.mean_input_torque_nm = s.input_torque_nm;
  return out;
}

}  // namespace tools::generator
