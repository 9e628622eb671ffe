#include "model/dynamics/full_model.hpp"

#include <array>
#include <cmath>
#include <numbers>

#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/mesh_stiffness.hpp"

namespace model::dynamics {
namespace {

// Element counts of the paper (§2.3.1) and where gears and bearings sit on each
// shaft (node index, node 0 = "node 1" of the paper). The sun is node 0 of the
// sun shaft; the generator coupling is the last node of the hss.
constexpr int kSunShaftElements = 11;
constexpr int kImsElements = 8;
constexpr int kHssElements = 8;
constexpr int kSunNode = 0, kB1Node = 3, kG1Node = 7, kB2Node = 11;
constexpr int kB3Node = 0, kG2Node = 2, kG3Node = 6, kB4Node = 8;
constexpr int kB5Node = 0, kG4Node = 2, kB6Node = 5, kGeneratorNode = 8;

struct Node {
  int x = -1, y = -1, z = -1, t = -1;  // DOF indices, −1: absent
  Eigen::Vector2d centre{0.0, 0.0};    // [m] axis position in the housing frame
};

class Assembler {
 public:
  int add_dof(std::string name, double mass) {
    names_.push_back(std::move(name));
    mass_.push_back(mass);
    return static_cast<int>(names_.size()) - 1;
  }
  Node add_node(const std::string& name, bool axial, const Eigen::Vector2d& centre) {
    Node n;
    n.x = add_dof(name + ".x", 0.0);
    n.y = add_dof(name + ".y", 0.0);
    if (axial) n.z = add_dof(name + ".z", 0.0);
    n.t = add_dof(name + ".theta", 0.0);
    n.centre = centre;
    return n;
  }
  void add_mass(const Node& n, double m, double j) {
    mass_[n.x] += m;
    mass_[n.y] += m;
    if (n.z >= 0) mass_[n.z] += m;
    if (n.t >= 0) mass_[n.t] += j;
  }
  void add_mass(int dof, double m) { mass_[dof] += m; }
  int size() const { return static_cast<int>(names_.size()); }

  // A constant spring k along a sparse direction (dof, coefficient).
  struct Term {
    int dof;
    double c;
  };
  void spring(std::initializer_list<Term> terms, double k) {
    springs_.push_back({std::vector<Term>(terms), k});
  }

  FullModel finish() {
    FullModel m;
    m.dof_names = names_;
    const int n = size();
    m.mass = Eigen::Map<const Eigen::VectorXd>(mass_.data(), n);
    m.stiffness = Eigen::MatrixXd::Zero(n, n);
    for (const auto& s : springs_) {
      for (const Term& a : s.terms) {
        for (const Term& b : s.terms) m.stiffness(a.dof, b.dof) += s.k * a.c * b.c;
      }
    }
    return m;
  }

 private:
  struct Spring {
    std::vector<Term> terms;
    double k;
  };
  std::vector<std::string> names_;
  std::vector<double> mass_;
  std::vector<Spring> springs_;
};

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

// A gear's polar inertia as a solid disc at its pitch radius [kg·m²].
double disc_inertia(double mass_kg, double radius_m) { return 0.5 * mass_kg * radius_m * radius_m; }

// Direction of one gear mesh (3D, unit) and the lever arms of the two gears:
// δ = (x_A + lever_A θ_A − x_B − lever_B θ_B)·n + (z terms), force on B = +k δ n.
struct MeshVector {
  Eigen::Vector3d n;
  double lever_a = 0.0;  // (ρ_A × n)_z [m]
  double lever_b = 0.0;  // (ρ_B × n)_z [m]
};

MeshVector mesh_vector(const Eigen::Vector2d& centre_a, const Eigen::Vector2d& centre_b,
                       const Eigen::Vector2d& pitch_point, const Eigen::Vector2d& nt, double beta_b,
                       double axial_sign) {
  MeshVector v;
  v.n = Eigen::Vector3d(std::cos(beta_b) * nt.x(), std::cos(beta_b) * nt.y(),
                        axial_sign * std::sin(beta_b));
  auto lever = [&](const Eigen::Vector2d& centre) {
    // ρ: from the centre to the tangency point on the base circle (foot of the perpendicular).
    const Eigen::Vector2d d = pitch_point - centre;
    const Eigen::Vector2d rho = d - d.dot(nt) * nt;
    return rho.x() * v.n.y() - rho.y() * v.n.x();
  };
  v.lever_a = lever(centre_a);
  v.lever_b = lever(centre_b);
  return v;
}

Eigen::VectorXd mesh_direction(int dofs, const Node& a, const Node& b, const MeshVector& mv) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(dofs);
  u[a.x] += mv.n.x();
  u[a.y] += mv.n.y();
  if (a.z >= 0) u[a.z] += mv.n.z();
  u[a.t] += mv.lever_a;
  u[b.x] -= mv.n.x();
  u[b.y] -= mv.n.y();
  if (b.z >= 0) u[b.z] -= mv.n.z();
  u[b.t] -= mv.lever_b;
  return u;
}

}  // namespace

int FullModel::dof(std::string_view name) const {
  for (std::size_t i = 0; i < dof_names.size(); ++i) {
    if (dof_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

Eigen::MatrixXd FullModel::damping() const {
  Eigen::MatrixXd c = rayleigh_zeta * stiffness;
  c.diagonal() += rayleigh_eta * mass;
  return c;
}

Eigen::VectorXd FullModel::force(double rotor_revolutions, double input_torque_nm) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const ForceTerm& t : forces) f += t.scale(rotor_revolutions, input_torque_nm) * t.pattern;
  return f;
}

Eigen::VectorXd FullModel::static_deflection(double input_torque_nm) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const ForceTerm& t : forces) {
    f += (t.per_newton_metre ? t.amplitude * input_torque_nm : t.amplitude) * t.shape.mean() *
         t.pattern;
  }
  return stiffness.llt().solve(f);
}

std::optional<FullModel> build_full_model(const Drivetrain& d, const StructuralParameters& s,
                                          std::string* error) {
  // ---- topology and data checks -------------------------------------------------------
  if (d.stages.size() != 3 || d.stages[0].type != StageType::kPlanetary ||
      d.stages[1].type != StageType::kParallel || d.stages[2].type != StageType::kParallel) {
    fail(error, "drivetrain '" + d.name +
                    "': stages: the dynamics model needs one planetary stage followed by two "
                    "parallel stages");
    return std::nullopt;
  }
  const GearStage& ps = d.stages[0];
  const GearStage& is = d.stages[1];
  const GearStage& hs = d.stages[2];
  if (ps.gears.size() != 3 || is.gears.size() != 2 || hs.gears.size() != 2) {
    fail(error, "drivetrain '" + d.name +
                    "': stages: gear lists must be {sun, planet, ring}, {wheel, pinion}");
    return std::nullopt;
  }
  if (ps.planets < 1) {
    fail(error, "drivetrain '" + d.name + "': stage '" + ps.id + "': planets must be ≥ 1");
    return std::nullopt;
  }
  std::array<const Gear*, 7> g{};
  const std::array<std::string, 7> gear_ids{ps.gears[0], ps.gears[1], ps.gears[2], is.gears[0],
                                            is.gears[1], hs.gears[0], hs.gears[1]};
  for (std::size_t i = 0; i < g.size(); ++i) {
    g[i] = d.gear(gear_ids[i]);
    if (g[i] == nullptr || g[i]->teeth <= 0 || g[i]->face_width_m <= 0.0 || g[i]->mass_kg <= 0.0) {
      fail(error, "drivetrain '" + d.name + "': gears: '" + gear_ids[i] +
                      "' is missing or has non-positive teeth, face width or mass");
      return std::nullopt;
    }
  }
  const Gear& sun = *g[0];
  const Gear& planet = *g[1];
  const Gear& ring = *g[2];
  const std::array<std::string, 3> shaft_ids{ps.output_shaft, is.output_shaft, hs.output_shaft};
  std::array<const Shaft*, 3> sh{};
  for (std::size_t i = 0; i < 3; ++i) {
    sh[i] = d.shaft(shaft_ids[i]);
    if (sh[i] == nullptr || sh[i]->length_m <= 0.0 || sh[i]->diameter_m <= 0.0) {
      fail(error, "drivetrain '" + d.name + "': shafts: '" + shaft_ids[i] +
                      "' is missing or has a non-positive length or diameter");
      return std::nullopt;
    }
  }
  const std::array<std::string, 7> bearing_ids{"b1", "b2", "b3", "b4", "b5", "b6", "pb"};
  std::array<const Bearing*, 7> br{};
  for (std::size_t i = 0; i < br.size(); ++i) {
    br[i] = d.bearing(bearing_ids[i]);
    if (br[i] == nullptr || br[i]->radial_stiffness_n_m <= 0.0) {
      fail(error, "drivetrain '" + d.name + "': bearings: '" + bearing_ids[i] +
                      "' is missing or has no radial_stiffness_n_m");
      return std::nullopt;
    }
  }
  const DynamicsParameters& dp = d.dynamics;
  if (!(dp.rayleigh_eta >= 0.0) || !(dp.rayleigh_zeta >= 0.0) ||
      !(dp.bearing_stiffness_fluctuation >= 0.0) || !(dp.bearing_stiffness_fluctuation < 1.0)) {
    fail(error, "drivetrain '" + d.name +
                    "': dynamics: rayleigh_eta, rayleigh_zeta must be ≥ 0 and "
                    "bearing_stiffness_fluctuation in [0, 1)");
    return std::nullopt;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(dp.mesh_stiffness_scale[i] > 0.0) || !(dp.bearing_stiffness_scale[i] > 0.0)) {
      fail(error, "drivetrain '" + d.name + "': dynamics: stiffness scales must be > 0 (index " +
                      std::to_string(i) + ")");
      return std::nullopt;
    }
  }

  const Kinematics kin(d);
  Assembler as;

  // ---- planetary stage (Lin & Parker 1999) ------------------------------------------------
  const GearPair sp_pair{sun.teeth,
                         planet.teeth,
                         false,
                         ps.normal_module_m,
                         ps.pressure_angle_rad,
                         0.0,
                         std::min(sun.face_width_m, planet.face_width_m),
                         sun.profile_shift,
                         planet.profile_shift};
  const GearPair rp_pair{planet.teeth,
                         ring.teeth,
                         true,
                         ps.normal_module_m,
                         ps.pressure_angle_rad,
                         0.0,
                         std::min(ring.face_width_m, planet.face_width_m),
                         planet.profile_shift,
                         ring.profile_shift};
  const MeshGeometry sp_geo = mesh_geometry(sp_pair);
  const MeshGeometry rp_geo = mesh_geometry(rp_pair);
  const double r_sun = sp_geo.pitch_radius1_m;
  const double r_planet = sp_geo.pitch_radius2_m;
  const double r_ring = rp_geo.pitch_radius2_m;
  const double r_carrier = r_sun + r_planet;  // standard centre distance
  const double alpha = sp_geo.transverse_pressure_angle_rad;

  Node carrier;
  carrier.x = as.add_dof("carrier.x", s.carrier_mass_kg);
  carrier.y = as.add_dof("carrier.y", s.carrier_mass_kg);
  carrier.t = as.add_dof("carrier.theta", s.carrier_inertia_kg_m2);
  Node ringn;
  ringn.x = as.add_dof("ring.x", ring.mass_kg);
  ringn.y = as.add_dof("ring.y", ring.mass_kg);
  ringn.t = as.add_dof("ring.theta", ring.mass_kg * r_ring * r_ring);  // thin rim
  std::vector<Node> planets;
  std::vector<double> psi;
  for (int n = 0; n < ps.planets; ++n) {
    const double p = 2.0 * std::numbers::pi * n / ps.planets;  // equally spaced
    const std::string name = "planet" + std::to_string(n + 1);
    Node pn;
    pn.x = as.add_dof(name + ".x", planet.mass_kg);
    pn.y = as.add_dof(name + ".y", planet.mass_kg);
    pn.t = as.add_dof(name + ".theta", disc_inertia(planet.mass_kg, r_planet));
    pn.centre = r_carrier * Eigen::Vector2d(std::cos(p), std::sin(p));
    planets.push_back(pn);
    psi.push_back(p);
  }

  // ---- shafts (Timoshenko, 4 DOF per node) --------------------------------------------------
  const GearPair int_pair{g[4]->teeth,
                          g[3]->teeth,
                          false,
                          is.normal_module_m,
                          is.pressure_angle_rad,
                          is.helix_angle_rad,
                          std::min(g[3]->face_width_m, g[4]->face_width_m),
                          g[4]->profile_shift,
                          g[3]->profile_shift};
  const GearPair hs_pair{g[6]->teeth,
                         g[5]->teeth,
                         false,
                         hs.normal_module_m,
                         hs.pressure_angle_rad,
                         hs.helix_angle_rad,
                         std::min(g[5]->face_width_m, g[6]->face_width_m),
                         g[6]->profile_shift,
                         g[5]->profile_shift};
  const MeshGeometry int_geo = mesh_geometry(int_pair);
  const MeshGeometry hs_geo = mesh_geometry(hs_pair);
  const Eigen::Vector2d ims_centre =
      int_geo.centre_distance_m *
      Eigen::Vector2d(std::cos(s.ims_axis_angle_rad), std::sin(s.ims_axis_angle_rad));
  const Eigen::Vector2d hss_centre =
      ims_centre + hs_geo.centre_distance_m * Eigen::Vector2d(std::cos(s.hss_axis_angle_rad),
                                                              std::sin(s.hss_axis_angle_rad));

  auto build_shaft = [&](const Shaft& shaft, int elements,
                         const Eigen::Vector2d& centre) -> std::optional<std::vector<Node>> {
    const Material* mat = d.material(shaft.material);
    if (mat == nullptr) {
      fail(error, "drivetrain '" + d.name + "': shafts: '" + shaft.id + "': unknown material '" +
                      shaft.material + "'");
      return std::nullopt;
    }
    std::vector<Node> nodes;
    for (int i = 0; i <= elements; ++i)
      nodes.push_back(as.add_node(shaft.id + "." + std::to_string(i), true, centre));
    const double le = shaft.length_m / elements;
    const double dia = shaft.diameter_m;
    const double area = std::numbers::pi * dia * dia / 4.0;
    const double i_area = std::numbers::pi * std::pow(dia, 4) / 64.0;
    const double j_polar = 2.0 * i_area;
    const double e = mat->youngs_modulus_pa;
    const double nu = mat->poisson_ratio;
    const double gmod = e / (2.0 * (1.0 + nu));
    const double kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);  // Cowper 1966, solid circle
    const double phi = 12.0 * e * i_area / (kappa * gmod * area * le * le);
    const double k_lat = 12.0 * e * i_area / (le * le * le * (1.0 + phi));
    const double k_ax = e * area / le;
    const double k_tor = gmod * j_polar / le;
    const double m_half = 0.5 * mat->density_kg_m3 * area * le;
    const double j_half = 0.5 * mat->density_kg_m3 * j_polar * le;
    for (int i = 0; i < elements; ++i) {
      const Node& a = nodes[i];
      const Node& b = nodes[i + 1];
      as.spring({{a.x, 1.0}, {b.x, -1.0}}, k_lat);
      as.spring({{a.y, 1.0}, {b.y, -1.0}}, k_lat);
      as.spring({{a.z, 1.0}, {b.z, -1.0}}, k_ax);
      as.spring({{a.t, 1.0}, {b.t, -1.0}}, k_tor);
      as.add_mass(a, m_half, j_half);
      as.add_mass(b, m_half, j_half);
    }
    return nodes;
  };
  const auto sun_shaft = build_shaft(*sh[0], kSunShaftElements, Eigen::Vector2d::Zero());
  if (!sun_shaft) return std::nullopt;
  const auto ims = build_shaft(*sh[1], kImsElements, ims_centre);
  if (!ims) return std::nullopt;
  const auto hss = build_shaft(*sh[2], kHssElements, hss_centre);
  if (!hss) return std::nullopt;
  const Node& sunn = (*sun_shaft)[kSunNode];
  as.add_mass(sunn, sun.mass_kg, disc_inertia(sun.mass_kg, r_sun));
  as.add_mass((*sun_shaft)[kG1Node], g[3]->mass_kg,
              disc_inertia(g[3]->mass_kg, int_geo.pitch_radius2_m));
  as.add_mass((*ims)[kG2Node], g[4]->mass_kg, disc_inertia(g[4]->mass_kg, int_geo.pitch_radius1_m));
  as.add_mass((*ims)[kG3Node], g[5]->mass_kg, disc_inertia(g[5]->mass_kg, hs_geo.pitch_radius2_m));
  as.add_mass((*hss)[kG4Node], g[6]->mass_kg, disc_inertia(g[6]->mass_kg, hs_geo.pitch_radius1_m));

  // ---- supports of the planetary stage ---------------------------------------------------------
  as.spring({{carrier.x, 1.0}}, s.carrier_bearing_stiffness_n_m);
  as.spring({{carrier.y, 1.0}}, s.carrier_bearing_stiffness_n_m);
  as.spring({{ringn.x, 1.0}}, s.ring_support_stiffness_n_m);
  as.spring({{ringn.y, 1.0}}, s.ring_support_stiffness_n_m);
  as.spring({{ringn.t, 1.0}}, s.ring_torsional_stiffness_nm_rad);
  // Planet bearing: planet centre ↔ carrier pin at radius r_c, angle ψ_n. The pin moves
  // with the carrier: (x_c − r_c sinψ θ_c, y_c + r_c cosψ θ_c).
  const double k_pb = br[6]->radial_stiffness_n_m * br[6]->rows;
  for (int n = 0; n < ps.planets; ++n) {
    const Node& p = planets[n];
    as.spring({{p.x, 1.0}, {carrier.x, -1.0}, {carrier.t, r_carrier * std::sin(psi[n])}}, k_pb);
    as.spring({{p.y, 1.0}, {carrier.y, -1.0}, {carrier.t, -r_carrier * std::cos(psi[n])}}, k_pb);
  }

  // ---- housing seats under the measured bearings -----------------------------------------------
  struct Seat {
    std::string bearing;
    int x = -1, y = -1;
  };
  std::vector<Seat> seats;
  for (const MeasurementPoint& mp : d.measurement_points) {
    bool known = false;
    for (int i = 0; i < 6; ++i) known = known || mp.location == bearing_ids[i];
    if (!known) {
      fail(error, "drivetrain '" + d.name + "': measurement_points: '" + mp.channel +
                      "' sits on '" + mp.location +
                      "'; the dynamics model has housing seats under b1..b6 only");
      return std::nullopt;
    }
    Seat seat;
    seat.bearing = mp.location;
    seat.x = as.add_dof("seat." + mp.location + ".x", s.housing_seat_mass_kg);
    seat.y = as.add_dof("seat." + mp.location + ".y", s.housing_seat_mass_kg);
    as.spring({{seat.x, 1.0}}, s.housing_seat_stiffness_n_m);
    as.spring({{seat.y, 1.0}}, s.housing_seat_stiffness_n_m);
    seats.push_back(seat);
  }

  // ---- generator ----------------------------------------------------------------------------
  const int gen = as.add_dof("generator.theta", s.generator_inertia_kg_m2);
  as.spring({{(*hss)[kGeneratorNode].t, 1.0}, {gen, -1.0}}, s.generator_coupling_nm_rad);
  as.spring({{gen, 1.0}}, s.generator_control_nm_rad);

  // Bearing axial stiffness to the casing (takes the helical axial forces).
  struct BearingSite {
    const Node* node;
    int shaft_group;
  };
  const std::array<BearingSite, 6> sites{
      BearingSite{&(*sun_shaft)[kB1Node], 0}, BearingSite{&(*sun_shaft)[kB2Node], 0},
      BearingSite{&(*ims)[kB3Node], 1},       BearingSite{&(*ims)[kB4Node], 1},
      BearingSite{&(*hss)[kB5Node], 2},       BearingSite{&(*hss)[kB6Node], 2}};
  for (int i = 0; i < 6; ++i) {
    const double ka = br[i]->radial_stiffness_n_m * br[i]->rows *
                      dp.bearing_stiffness_scale[sites[i].shaft_group];
    as.spring({{sites[i].node->z, 1.0}}, s.bearing_axial_ratio * ka);
  }

  FullModel model = as.finish();
  const int n_dof = model.dofs();
  model.rayleigh_eta = dp.rayleigh_eta;
  model.rayleigh_zeta = dp.rayleigh_zeta;

  auto add_varying = [&](std::vector<VaryingStiffness>& list, VaryingStiffness v) {
    for (int c = 0; c < v.directions.cols(); ++c) {
      model.stiffness.noalias() +=
          v.mean_n_m * v.directions.col(c) * v.directions.col(c).transpose();
    }
    list.push_back(std::move(v));
  };

  // ---- planetary meshes ----------------------------------------------------------------------
  // Force on the sun from a planet: tangential in the sun's sense of rotation (+θ, the
  // carrier's), separating (−u): n = cos α·w − sin α·u. Force on the ring from a planet:
  // +w (the ring holds the reaction), separating (+u): n = cos α·w + sin α·u.
  const double planetary_order = kin.mesh_hz(0, 60.0);
  const double sun_torque_ratio = 1.0 / kin.stage_ratio(0);  // T_sun / T_in (ring fixed)
  const MeshStiffness k_sp = mesh_stiffness(sp_pair, dp.mesh_stiffness_scale[0]);
  const MeshStiffness k_rp = mesh_stiffness(rp_pair, dp.mesh_stiffness_scale[0]);
  const double gamma_rs = ring_sun_phase(planet.teeth);
  for (int n = 0; n < ps.planets; ++n) {
    const Eigen::Vector2d u(std::cos(psi[n]), std::sin(psi[n]));
    const Eigen::Vector2d w(-u.y(), u.x());
    {
      const Eigen::Vector2d nt = std::cos(alpha) * w - std::sin(alpha) * u;
      const MeshVector mv =
          mesh_vector(planets[n].centre, Eigen::Vector2d::Zero(), r_sun * u, nt, 0.0, 0.0);
      VaryingStiffness v;
      v.id = "sun_planet_" + std::to_string(n + 1);
      v.directions = mesh_direction(n_dof, planets[n], sunn, mv);
      v.mean_n_m = k_sp.mean_n_m;
      v.shape = k_sp.shape;
      v.order = planetary_order;
      v.phase_cycles = sun_planet_phase(sun.teeth, psi[n]);
      model.mesh_info.push_back({planets[n].centre, Eigen::Vector2d::Zero(), r_sun * u, mv.n,
                                 sp_geo.base_radius1_m, sun_torque_ratio, 0.0, ps.planets});
      add_varying(model.meshes, std::move(v));
    }
  }
  for (int n = 0; n < ps.planets; ++n) {
    const Eigen::Vector2d u(std::cos(psi[n]), std::sin(psi[n]));
    const Eigen::Vector2d w(-u.y(), u.x());
    const Eigen::Vector2d nt = std::cos(alpha) * w + std::sin(alpha) * u;
    const MeshVector mv =
        mesh_vector(planets[n].centre, Eigen::Vector2d::Zero(), r_ring * u, nt, 0.0, 0.0);
    VaryingStiffness v;
    v.id = "ring_planet_" + std::to_string(n + 1);
    v.directions = mesh_direction(n_dof, planets[n], ringn, mv);
    v.mean_n_m = k_rp.mean_n_m;
    v.shape = k_rp.shape;
    v.order = planetary_order;
    const double gamma = ring_planet_phase(ring.teeth, psi[n]) + gamma_rs;
    v.phase_cycles = gamma - std::floor(gamma);
    // Ring reaction torque = T_in − T_sun.
    model.mesh_info.push_back({planets[n].centre, Eigen::Vector2d::Zero(), r_ring * u, mv.n,
                               rp_geo.base_radius2_m, 1.0 - sun_torque_ratio, 0.0, ps.planets});
    add_varying(model.meshes, std::move(v));
  }

  // ---- parallel helical meshes -----------------------------------------------------------------
  // Driver A (wheel) turning in sense `spin` (+1: +θ) pushes the pinion B tangentially in
  // A's surface velocity and away from A: n_t = spin·cos α_t·w + sin α_t·u, u from A to B.
  auto parallel_mesh = [&](const char* id, const Node& a, const Node& b, const MeshGeometry& geo,
                           double spin, double order, double scale, const GearPair& pair,
                           double torque_ratio) {
    const Eigen::Vector2d ab = b.centre - a.centre;
    const Eigen::Vector2d u = ab.normalized();
    const Eigen::Vector2d w(-u.y(), u.x());
    const double at = geo.transverse_pressure_angle_rad;
    const Eigen::Vector2d nt = spin * std::cos(at) * w + std::sin(at) * u;
    const Eigen::Vector2d pitch = a.centre + geo.pitch_radius2_m * u;  // wheel = gear 2 of the pair
    const MeshVector mv = mesh_vector(a.centre, b.centre, pitch, nt, geo.base_helix_angle_rad, 1.0);
    const MeshStiffness k = mesh_stiffness(pair, scale);
    VaryingStiffness v;
    v.id = id;
    v.directions = mesh_direction(n_dof, a, b, mv);
    v.mean_n_m = k.mean_n_m;
    v.shape = k.shape;
    v.order = order;
    v.phase_cycles = 0.0;
    model.mesh_info.push_back({a.centre, b.centre, pitch, mv.n, geo.base_radius1_m, torque_ratio,
                               geo.base_helix_angle_rad, 1});
    add_varying(model.meshes, std::move(v));
  };
  // Sun and carrier turn the same way (ring fixed): the sun shaft spins +θ, the ims −θ.
  const double ims_torque_ratio = sun_torque_ratio / kin.stage_ratio(1);
  const double hss_torque_ratio = ims_torque_ratio / kin.stage_ratio(2);
  parallel_mesh("intermediate", (*sun_shaft)[kG1Node], (*ims)[kG2Node], int_geo, +1.0,
                kin.mesh_hz(1, 60.0), dp.mesh_stiffness_scale[1], int_pair, ims_torque_ratio);
  parallel_mesh("high_speed", (*ims)[kG3Node], (*hss)[kG4Node], hs_geo, -1.0, kin.mesh_hz(2, 60.0),
                dp.mesh_stiffness_scale[2], hs_pair, hss_torque_ratio);

  // ---- bearings b1..b6
  // ---------------------------------------------------------------------------
  for (int i = 0; i < 6; ++i) {
    const Bearing& b = *br[i];
    const Node& node = *sites[i].node;
    VaryingStiffness v;
    v.id = b.id;
    v.directions = Eigen::MatrixXd::Zero(n_dof, 2);
    v.directions(node.x, 0) = 1.0;
    v.directions(node.y, 1) = 1.0;
    for (const Seat& seat : seats) {
      if (seat.bearing == b.id) {
        v.directions(seat.x, 0) = -1.0;
        v.directions(seat.y, 1) = -1.0;
      }
    }
    v.mean_n_m = b.radial_stiffness_n_m * b.rows * dp.bearing_stiffness_scale[sites[i].shaft_group];
    v.shape = PeriodicTable::cosine(dp.bearing_stiffness_fluctuation);
    const std::optional<BearingFrequencies> f = kin.bearing_hz(b.id, 60.0);
    if (!f) {
      fail(error, "drivetrain '" + d.name + "': bearings: '" + b.id + "': shaft '" + b.shaft +
                      "' is not a drivetrain shaft");
      return std::nullopt;
    }
    v.order = f->bpfo_hz;  // varying compliance: one period per ball passing the outer race
    v.phase_cycles = 0.0;
    add_varying(model.bearings, std::move(v));
  }

  // ---- input torque, sensors --------------------------------------------------------------------
  ForceTerm torque;
  torque.id = "input_torque";
  torque.pattern = Eigen::VectorXd::Zero(n_dof);
  torque.pattern[carrier.t] = 1.0;
  torque.per_newton_metre = true;
  model.forces.push_back(torque);

  for (std::size_t i = 0; i < seats.size(); ++i) {
    Sensor sensor;
    sensor.channel = d.measurement_points[i].channel;
    sensor.location = seats[i].bearing;
    sensor.row = Eigen::VectorXd::Zero(n_dof);
    sensor.row[seats[i].x] = std::cos(s.sensor_angle_rad);
    sensor.row[seats[i].y] = std::sin(s.sensor_angle_rad);
    model.sensors.push_back(sensor);
  }
  return model;
}

}  // namespace model::dynamics
