#include "model/dynamics/full_model.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

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

// Gearbox damping-ratio factor at f: damping_band_factor at the knots kDampingKnotsHz,
// linear in log f between them, constant outside.
double band_factor(const DynamicsParameters& dp, double f_hz) {
  const auto& knots = kDampingKnotsHz;
  const auto& factor = dp.damping_band_factor;
  if (!(f_hz > knots.front())) return factor.front();
  if (f_hz >= knots.back()) return factor.back();
  std::size_t k = 0;
  while (k + 2 < knots.size() && f_hz >= knots[k + 1]) ++k;
  const double u = std::log(f_hz / knots[k]) / std::log(knots[k + 1] / knots[k]);
  return factor[k] + u * (factor[k + 1] - factor[k]);
}

// C = MΦ diag(2ξ_iω_i) ΦᵀM over every mode (header comment): ξ_i mixes the gearbox's
// ratio and the housing modes' own by the share of mode i's strain energy (ω_i²/2 for a
// mass-normalised mode) stored in each housing spring, k_h φ_ih² / ω_i².
bool assign_modal_damping(FullModel& model, const DynamicsParameters& dp,
                          const std::vector<std::pair<int, std::pair<double, double>>>& housing,
                          std::string* error) {
  const Eigen::VectorXd inv_sqrt_m = model.mass.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd k_sym = inv_sqrt_m.asDiagonal() * model.stiffness * inv_sqrt_m.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(k_sym);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()[0] > 0.0)) {
    return fail(error, "dynamics: the model's stiffness is not positive definite");
  }
  const Eigen::MatrixXd phi = inv_sqrt_m.asDiagonal() * eig.eigenvectors();  // ΦᵀMΦ = I
  const Eigen::Index n = phi.cols();
  Eigen::VectorXd c_modal(n);
  model.modal_damping_ratio.assign(static_cast<std::size_t>(n), 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w2 = eig.eigenvalues()[i];
    const double w = std::sqrt(w2);
    const double gearbox = (model.rayleigh_eta / (2.0 * w) + 0.5 * model.rayleigh_zeta * w) *
                           band_factor(dp, w / (2.0 * std::numbers::pi));
    double share_total = 0.0;
    double xi = 0.0;
    for (const auto& [dof, kx] : housing) {
      const double share = kx.first * phi(dof, i) * phi(dof, i) / w2;
      share_total += share;
      xi += share * kx.second;
    }
    xi += std::max(0.0, 1.0 - share_total) * gearbox;
    model.modal_damping_ratio[static_cast<std::size_t>(i)] = xi;
    c_modal[i] = 2.0 * xi * w;
  }
  const Eigen::MatrixXd mphi = model.mass.asDiagonal() * phi;
  model.damping_matrix = mphi * c_modal.asDiagonal() * mphi.transpose();
  model.damping_matrix = 0.5 * (model.damping_matrix + model.damping_matrix.transpose());
  return true;
}

}  // namespace

int FullModel::dof(std::string_view name) const {
  for (std::size_t i = 0; i < dof_names.size(); ++i) {
    if (dof_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

Eigen::VectorXd FullModel::transmission_error_force(double rotor_revolutions) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const VaryingStiffness& v : meshes) {
    const double e = v.transmission_error_m(rotor_revolutions);
    if (e != 0.0) f += (v.stiffness_n_m(rotor_revolutions) * e) * v.directions.col(0);
  }
  return f;
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
  for (std::size_t i = 0; i < dp.bearing_stiffness_factor.size(); ++i) {
    if (!(dp.bearing_stiffness_factor[i] > 0.0) || !std::isfinite(dp.bearing_stiffness_factor[i])) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: bearing_stiffness_factor must be finite and > 0 (index " +
                      std::to_string(i) + ")");
      return std::nullopt;
    }
  }
  for (std::size_t i = 0; i < dp.damping_band_factor.size(); ++i) {
    if (!(dp.damping_band_factor[i] > 0.0) || !std::isfinite(dp.damping_band_factor[i])) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: damping_band_factor must be finite and > 0 (index " +
                      std::to_string(i) + ")");
      return std::nullopt;
    }
  }
  for (std::size_t i = 0; i < dp.transmission_error_m.size(); ++i) {
    if (!std::isfinite(dp.transmission_error_m[i]) || std::abs(dp.transmission_error_m[i]) > 1e-3) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: transmission_error_m must be finite and within ±1 mm (index " +
                      std::to_string(i) + ")");
      return std::nullopt;
    }
  }
  for (std::size_t i = 0; i < dp.housing_frequency_hz.size(); ++i) {
    const double f = dp.housing_frequency_hz[i];
    if (f == 0.0) continue;  // no mode in this slot
    if (!(f > 0.0) || !std::isfinite(f) || !(dp.housing_modal_mass_kg[i] > 0.0) ||
        !std::isfinite(dp.housing_modal_mass_kg[i]) || !(dp.housing_damping_ratio[i] >= 0.0) ||
        !(dp.housing_damping_ratio[i] < 1.0) || !std::isfinite(dp.housing_participation[i]) ||
        !std::isfinite(dp.housing_cross_participation[i])) {
      fail(error, "drivetrain '" + d.name + "': dynamics: housing mode " + std::to_string(i) +
                      ": frequency and modal mass must be finite and > 0, damping ratio in "
                      "[0, 1), participations finite");
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
  // A seat's displacement in the housing frame is Σ_d dir_d · x[dof_d]: the legacy seat
  // has seat.x along x and seat.y along y; a modal housing has each mode's DOF along the
  // sensor direction s and one seat DOF across it (t). The sensor reads Σ sensor_d·ẍ[dof_d].
  struct SeatDof {
    int dof = -1;
    Eigen::Vector2d dir{0.0, 0.0};
    double sensor = 0.0;          // [-] weight in the sensor's reading
    double stiffness = 0.0;       // [N/m] spring to ground (housing modes: m_k ω_k²)
    double damping_ratio = -1.0;  // [-] a housing mode's own ξ_k; < 0: the gearbox's damping
    int param = -1;               // a housing mode's index in DynamicsParameters' housing_*
  };
  struct Seat {
    std::string bearing;
    std::vector<SeatDof> dofs;
  };
  std::vector<Seat> seats;
  const Eigen::Vector2d sensor_dir(std::cos(s.sensor_angle_rad), std::sin(s.sensor_angle_rad));
  const Eigen::Vector2d across_dir(-sensor_dir.y(), sensor_dir.x());
  for (std::size_t p = 0; p < d.measurement_points.size(); ++p) {
    const MeasurementPoint& mp = d.measurement_points[p];
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
    const std::string base = "seat." + mp.location;
    bool modal = false;
    if (p < kHousingPoints) {
      for (std::size_t k = 0; k < kHousingModesPerPoint; ++k) {
        const std::size_t i = p * kHousingModesPerPoint + k;
        const double f = dp.housing_frequency_hz[i];
        if (f <= 0.0) continue;
        modal = true;
        const double m = dp.housing_modal_mass_kg[i];
        const double w = 2.0 * std::numbers::pi * f;
        SeatDof h;
        h.dof = as.add_dof(base + ".mode" + std::to_string(k + 1), m);
        h.dir = sensor_dir;
        h.sensor = dp.housing_participation[i];
        h.stiffness = m * w * w;
        h.damping_ratio = dp.housing_damping_ratio[i];
        h.param = static_cast<int>(i);
        as.spring({{h.dof, 1.0}}, h.stiffness);
        seat.dofs.push_back(h);
      }
    }
    if (modal) {
      SeatDof t;
      t.dof = as.add_dof(base + ".across", s.housing_seat_mass_kg);
      t.dir = across_dir;
      t.stiffness = s.housing_seat_stiffness_n_m;
      as.spring({{t.dof, 1.0}}, t.stiffness);
      seat.dofs.push_back(t);
    } else {
      SeatDof x;
      x.dof = as.add_dof(base + ".x", s.housing_seat_mass_kg);
      x.dir = Eigen::Vector2d(1.0, 0.0);
      x.sensor = sensor_dir.x();
      x.stiffness = s.housing_seat_stiffness_n_m;
      SeatDof y;
      y.dof = as.add_dof(base + ".y", s.housing_seat_mass_kg);
      y.dir = Eigen::Vector2d(0.0, 1.0);
      y.sensor = sensor_dir.y();
      y.stiffness = s.housing_seat_stiffness_n_m;
      as.spring({{x.dof, 1.0}}, x.stiffness);
      as.spring({{y.dof, 1.0}}, y.stiffness);
      seat.dofs.push_back(x);
      seat.dofs.push_back(y);
    }
    seats.push_back(seat);
  }
  // Housing modes are the housing's, not one seat's: mode k of point p also moves the other
  // measured point's seat, by c_k·h_k along its sensor direction (housing_cross_participation,
  // the mode's seat participation there relative to its own seat). Reciprocally that seat's
  // bearing force drives h_k with c_k, and that point's sensor reads c_k·ḧ_k.
  if (seats.size() == kHousingPoints) {
    for (std::size_t p = 0; p < kHousingPoints; ++p) {
      Seat& other = seats[1 - p];
      for (const SeatDof& sd : std::vector<SeatDof>(seats[p].dofs)) {
        if (sd.param < 0) continue;  // not a housing mode
        const double c = dp.housing_cross_participation[static_cast<std::size_t>(sd.param)];
        if (c == 0.0) continue;
        SeatDof cross;
        cross.dof = sd.dof;
        cross.dir = c * sensor_dir;
        cross.sensor = c;
        other.dofs.push_back(cross);  // stiffness 0, damping_ratio < 0: not a spring of its own
      }
    }
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
                      dp.bearing_stiffness_scale[sites[i].shaft_group] *
                      dp.bearing_stiffness_factor[i];
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
      v.transmission_error =
          transmission_error_table(&dp.transmission_error_m[0], kTransmissionErrorHarmonics);
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
    v.transmission_error =
        transmission_error_table(&dp.transmission_error_m[0], kTransmissionErrorHarmonics);
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
                           double torque_ratio, std::size_t stage) {
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
    v.transmission_error = transmission_error_table(
        &dp.transmission_error_m[stage * kTransmissionErrorHarmonics], kTransmissionErrorHarmonics);
    model.mesh_info.push_back({a.centre, b.centre, pitch, mv.n, geo.base_radius1_m, torque_ratio,
                               geo.base_helix_angle_rad, 1});
    add_varying(model.meshes, std::move(v));
  };
  // Sun and carrier turn the same way (ring fixed): the sun shaft spins +θ, the ims −θ.
  const double ims_torque_ratio = sun_torque_ratio / kin.stage_ratio(1);
  const double hss_torque_ratio = ims_torque_ratio / kin.stage_ratio(2);
  parallel_mesh("intermediate", (*sun_shaft)[kG1Node], (*ims)[kG2Node], int_geo, +1.0,
                kin.mesh_hz(1, 60.0), dp.mesh_stiffness_scale[1], int_pair, ims_torque_ratio, 1);
  parallel_mesh("high_speed", (*ims)[kG3Node], (*hss)[kG4Node], hs_geo, -1.0, kin.mesh_hz(2, 60.0),
                dp.mesh_stiffness_scale[2], hs_pair, hss_torque_ratio, 2);

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
      if (seat.bearing != b.id) continue;
      for (const SeatDof& sd : seat.dofs) {
        v.directions(sd.dof, 0) -= sd.dir.x();
        v.directions(sd.dof, 1) -= sd.dir.y();
      }
    }
    v.mean_n_m = b.radial_stiffness_n_m * b.rows *
                 dp.bearing_stiffness_scale[sites[i].shaft_group] * dp.bearing_stiffness_factor[i];
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
    for (const SeatDof& sd : seats[i].dofs) sensor.row[sd.dof] = sd.sensor;
    model.sensors.push_back(sensor);
  }

  // ---- damping: modal, strain-energy mix of the gearbox's and the housing modes' ratios -------
  std::vector<std::pair<int, std::pair<double, double>>> housing_springs;  // dof, (k, ξ)
  for (const Seat& seat : seats) {
    for (const SeatDof& sd : seat.dofs) {
      if (sd.damping_ratio >= 0.0)
        housing_springs.push_back({sd.dof, {sd.stiffness, sd.damping_ratio}});
    }
  }
  if (!assign_modal_damping(model, dp, housing_springs, error)) return std::nullopt;
  return model;
}

}  // namespace model::dynamics
