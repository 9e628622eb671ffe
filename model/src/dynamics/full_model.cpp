#include "model/dynamics/full_model.hpp"

#include <Eigen/Eigenvalues>
#include "model/dynamics/eigen_instances.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>

#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/bearing_compliance.hpp"
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
  void spring(const std::vector<std::pair<int, double>>& terms, double k) {
    std::vector<Term> t;
    for (const auto& [dof, c] : terms) t.push_back({dof, c});
    springs_.push_back({std::move(t), k});
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

// ---- effects (model/drivetrain/effects.hpp) as terms of the equations of motion
// ------------------

// A measured bearing's seat: its displacement in the housing frame is Σ dir·x[dof] over
// `dofs` (a seat mass in x and y, or the housing modes along the sensor and one seat DOF
// across it); the sensor reads Σ sensor·ẍ[dof], or the housing resonance's DOF.
struct SeatDof {
  int dof = -1;
  Eigen::Vector2d dir{0.0, 0.0};
  double sensor = 0.0;          // [-] weight in the sensor's reading
  double stiffness = 0.0;       // [N/m] spring to ground (housing modes: m_k ω_k²)
  double damping_ratio = -1.0;  // [-] a housing mode's own ξ_k; < 0: the gearbox's damping
  int param = -1;               // a housing mode's index in DynamicsParameters' housing_*
};
struct SeatRef {
  std::string bearing;
  std::vector<SeatDof> dofs;
  int sensor_dof = -1;  // a housing resonance's DOF, or −1: the sensor reads the seat
  /// Terms (dof, coefficient) of the seat's displacement along `d`, times `sign`.
  std::vector<std::pair<int, double>> along(const Eigen::Vector2d& d, double sign = 1.0) const {
    std::vector<std::pair<int, double>> out;
    for (const SeatDof& sd : dofs) {
      const double c = sd.dir.dot(d);
      if (c != 0.0) out.push_back({sd.dof, sign * c});
    }
    return out;
  }
  /// The seat's displacement in the housing frame at x.
  Eigen::Vector2d displacement(const Eigen::VectorXd& x) const {
    Eigen::Vector2d u(0.0, 0.0);
    for (const SeatDof& sd : dofs) u += sd.dir * x[sd.dof];
    return u;
  }
};

// An element with its own damping ratio (a housing mode's spring, an effect's housing
// resonance): stiffness k along the terms `dir`, ratio ξ (assign_modal_damping()).
struct OwnDamper {
  std::vector<std::pair<int, double>> dir;
  double stiffness = 0.0;
  double damping_ratio = 0.0;
};

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
// ratio and the own ratios of the elements with their own damper by the share of mode i's
// strain energy (ω_i²/2 for a mass-normalised mode) stored in each, k (dᵀφ_i)² / ω_i².
bool assign_modal_damping(FullModel& model, const DynamicsParameters& dp,
                          const std::vector<OwnDamper>& own, std::string* error) {
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
    for (const OwnDamper& o : own) {
      double strain = 0.0;
      for (const auto& [dof, c] : o.dir) strain += c * phi(dof, i);
      const double share = o.stiffness * strain * strain / w2;
      share_total += share;
      xi += share * o.damping_ratio;
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

// What the effects need of the assembled gearbox.
struct EffectSites {
  const std::vector<Node>* sun_shaft = nullptr;
  const std::vector<Node>* ims = nullptr;
  const std::vector<Node>* hss = nullptr;
  const std::vector<Node>* planets = nullptr;
  const std::vector<double>* psi = nullptr;  // planet angles in the carrier frame [rad]
  Node carrier, ring;
  double r_carrier = 0.0, r_ring = 0.0;
  std::array<GearPair, 4> pairs{};  // sun–planet, ring–planet, intermediate, high-speed
  std::array<MeshGeometry, 4> geos{};
  Eigen::Vector2d sensor_dir{0.0, 1.0};
  std::array<double, 4> torque_ratio{};  // rotor, sun shaft, ims, hss torque per N·m input
  std::array<const Node*, 6> bearing_nodes{};
  std::vector<SeatRef> seats;
};

constexpr double kTwoPi = 2.0 * std::numbers::pi;

PeriodicTable table_of(const auto& f) {
  PeriodicTable t;
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i)
    t.values[i] = f(static_cast<double>(i) / static_cast<double>(PeriodicTable::kSize));
  return t;
}
double wrap_half(double x) { return x - std::floor(x + 0.5); }  // to [−½, ½)
double wrap_pi(double a) { return a - kTwoPi * std::floor(a / kTwoPi + 0.5); }

// "planet" → 1, "planet2" → 2 (prefix = the planet gear's id); 0 if not that form.
int planet_index(std::string_view location, std::string_view prefix, int planets) {
  if (location.substr(0, prefix.size()) != prefix) return 0;
  const std::string_view rest = location.substr(prefix.size());
  if (rest.empty()) return 1;
  int n = 0;
  for (char c : rest) {
    if (c < '0' || c > '9') return 0;
    n = 10 * n + (c - '0');
  }
  return n >= 1 && n <= planets ? n : 0;
}

bool add_effects(const Drivetrain& d, const Kinematics& kin, const EffectSites& es,
                 FullModel& model, std::string* error) {
  const int n_dof = model.dofs();
  const GearStage& ps = d.stages[0];
  const GearStage& is = d.stages[1];
  const GearStage& hs = d.stages[2];
  const int planets = ps.planets;
  const int mesh_int = 2 * planets, mesh_hs = 2 * planets + 1;
  const double fo = model.frame_order;
  // Signed speeds per rotor revolution in the housing frame (+: the carrier's sense).
  const double o_sun = kin.stage_ratio(0);
  const double o_ims = -o_sun * kin.stage_ratio(1);
  const double o_hss = -o_ims * kin.stage_ratio(2);
  const Gear* ring_gear = d.gear(ps.gears[2]);
  const Gear* planet_gear = d.gear(ps.gears[1]);
  const double o_planet =
      -static_cast<double>(ring_gear->teeth) / planet_gear->teeth;  // rel. carrier
  auto shaft_order = [&](std::string_view shaft) {
    if (shaft == ps.output_shaft) return o_sun;
    if (shaft == is.output_shaft) return o_ims;
    if (shaft == hs.output_shaft) return o_hss;
    if (shaft == "planet") return o_planet;
    return 0.0;
  };
  const PeriodicTable cos_table = table_of([](double x) { return std::cos(kTwoPi * x); });
  const PeriodicTable sin_table = table_of([](double x) { return std::sin(kTwoPi * x); });
  Eigen::VectorXd x_unit;  // static deflection under 1 N·m: the bearings' load directions
  auto unit_deflection = [&]() -> const Eigen::VectorXd& {
    if (x_unit.size() == 0) x_unit = model.static_deflection(1.0);
    return x_unit;
  };

  // A mesh of a gear: index, signed speed of the gear relative to the frame in which the
  // mesh's contact point is fixed [per rotor revolution], and the angle at which the gear's
  // reference point meets the contact point [rad].
  struct GearMesh {
    int mesh;
    int geo;  // index into es.geos
    double order;
    double contact_angle;
  };
  auto meshes_of_gear = [&](const std::string& g) {
    std::vector<GearMesh> out;
    if (g == ps.gears[0]) {  // sun: meets each planet once per revolution relative to the carrier
      for (int n = 0; n < planets; ++n) out.push_back({n, 0, o_sun - fo, (*es.psi)[n]});
    } else if (const int k = planet_index(g, ps.gears[1], planets); k > 0) {
      // A planet tooth meets the ring on the planet's outer side (angle ψ_k) and the sun on its
      // inner side (ψ_k + π), turning at o_planet relative to the carrier.
      out.push_back({k - 1, 0, o_planet, (*es.psi)[k - 1] + std::numbers::pi});
      out.push_back({planets + k - 1, 1, o_planet, (*es.psi)[k - 1]});
    } else if (g == is.gears[0]) {
      out.push_back({mesh_int, 2, o_sun, 0.0});
    } else if (g == is.gears[1]) {
      out.push_back({mesh_int, 2, o_ims, 0.0});
    } else if (g == hs.gears[0]) {
      out.push_back({mesh_hs, 3, o_ims, 0.0});
    } else if (g == hs.gears[1]) {
      out.push_back({mesh_hs, 3, o_hss, 0.0});
    }
    return out;
  };

  // Force patterns: −F d̂ on the body of a bearing's inner ring, +F d̂ on its outer ring.
  struct BearingBodies {
    int in_x = -1, in_y = -1, in_t = -1;  // inner ring (shaft node, or the planet pin)
    double pin_x = 0.0, pin_y = 0.0;      // the pin's position (planet bearings) [m]
    // Outer ring: (dof, direction in the native frame) terms of its displacement (the
    // planet's x, y, or a seat's DOFs); none: the casing.
    std::vector<std::pair<int, Eigen::Vector2d>> out;
    bool nodes_in_carrier_frame = false;
    bool native_carrier_frame = false;  // the stationary race is fixed in the carrier
  };
  auto pattern_of = [&](const BearingBodies& b, double dx, double dy) {
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n_dof);
    p[b.in_x] -= dx;
    p[b.in_y] -= dy;
    if (b.in_t >= 0) p[b.in_t] -= b.pin_x * dy - b.pin_y * dx;  // moment of −F at the pin
    for (const auto& [dof, dir] : b.out) p[dof] += dir.x() * dx + dir.y() * dy;
    return p;
  };
  // Adds F(t)·(T_x(θ), T_y(θ)) given in the bearing's native frame: tables tx, ty over one
  // revolution of θ (order `o`), the impact train `pulse` (order `po`) as the primary shape.
  auto add_bearing_force = [&](const BearingBodies& b, const std::string& id, double amplitude,
                               const PeriodicTable& pulse, double po, const PeriodicTable& tx,
                               const PeriodicTable& ty, double o, int group) {
    auto term = [&](const Eigen::VectorXd& pattern, const PeriodicTable& t,
                    std::array<double, 3> frame) {
      ForceTerm f;
      f.id = id;
      f.pattern = pattern;
      f.amplitude = amplitude;
      f.shape = pulse;
      f.order = po;
      f.modulations.push_back({t, o, 0.0});
      f.frame = frame;
      f.impact_group = group;
      model.forces.push_back(std::move(f));
    };
    const Eigen::VectorXd px = pattern_of(b, 1.0, 0.0), py = pattern_of(b, 0.0, 1.0);
    if (b.nodes_in_carrier_frame && !b.native_carrier_frame) {
      // Housing components into the carrier's axes: R(−ψ)(F_x, F_y).
      term(px, tx, {0.0, 1.0, 0.0});
      term(px, ty, {0.0, 0.0, 1.0});
      term(py, tx, {0.0, 0.0, -1.0});
      term(py, ty, {0.0, 1.0, 0.0});
    } else {
      term(px, tx, {1.0, 0.0, 0.0});
      term(py, ty, {1.0, 0.0, 0.0});
    }
  };

  int impact_groups = 0;
  for (std::size_t ei = 0; ei < d.effects.size(); ++ei) {
    const Effect& e = d.effects[ei];
    const std::string what =
        "effect '" + std::string(effect_id(e.kind)) + "' at '" + e.location + "'";
    switch (e.kind) {
      case EffectKind::kToothCrack: {
        // The stiffness of every mesh of the gear drops by `stiffness_loss` while the cracked
        // tooth is in contact: a raised-cosine window ε_γ/z of a revolution wide (ε_γ the
        // total contact ratio: how many mesh cycles a tooth stays in contact), once per
        // revolution of the gear relative to the contact point.
        const double loss = *e.parameter("stiffness_loss");
        const double phi0 = *e.parameter("tooth_angle_deg") * std::numbers::pi / 180.0;
        const int k = planet_index(e.location, ps.gears[1], planets);
        const Gear* gear = d.gear(k > 0 ? ps.gears[1] : e.location);
        for (const GearMesh& gm : meshes_of_gear(e.location)) {
          const double width = es.geos[gm.geo].total_contact_ratio() / gear->teeth;  // [rev]
          Modulation m;
          m.table = table_of([&](double x) {
            const double u = wrap_half(x);
            return std::abs(u) < 0.5 * width
                       ? 1.0 - loss * 0.5 * (1.0 + std::cos(kTwoPi * u / width))
                       : 1.0;
          });
          m.order = gm.order;
          m.phase_cycles = (phi0 - gm.contact_angle) / kTwoPi * (gm.order < 0 ? -1.0 : 1.0);
          model.meshes[gm.mesh].modulations.push_back(m);
        }
        break;
      }
      case EffectKind::kGearEccentricity: {
        // Run-out e of the gear's teeth about its axis, turning with the gear: along the
        // mesh normal a transmission error e·(n_xy·ê(θ)); along the line of centres a change
        // of centre distance Δa, which shortens or lengthens the path of contact
        // (dε_α/da = −1/(p_bt·sin α_wt) for an external pair with fixed base circles) and so
        // modulates the mean stiffness c_γα ∝ 0.75ε_α + 0.25 (ISO 6336-1 §9.4).
        const double ecc = *e.parameter("eccentricity_um") * 1e-6;
        const double phi0 = *e.parameter("phase_deg") * std::numbers::pi / 180.0;
        const std::string& g = e.location;
        for (const GearMesh& gm : meshes_of_gear(g)) {
          const MeshInfo& info = model.mesh_info[gm.mesh];
          const MeshGeometry& geo = es.geos[gm.geo];
          // The gear is the mesh's driver A (planet, g1, g3) or its driven B (sun, g2, g4).
          const bool is_a = (g == is.gears[0] || g == hs.gears[0]);
          const Eigen::Vector2d nxy = info.normal.head<2>();
          const Eigen::Vector2d uab = (info.driven_centre_m - info.driver_centre_m).normalized();
          MeshExcitation te;
          // The run-out moves the flank towards the mate (interference, δ grows): e = −that.
          te.amplitude_m = (is_a ? -1.0 : 1.0) * ecc * nxy.norm();
          te.pattern = {cos_table, gm.order, (phi0 - std::atan2(nxy.y(), nxy.x())) / kTwoPi};
          model.meshes[gm.mesh].excitations.push_back(te);
          const double kappa = -0.75 / (0.75 * geo.transverse_contact_ratio + 0.25) /
                               (geo.base_pitch_m * std::sin(geo.transverse_pressure_angle_rad));
          const double c = kappa * (is_a ? -1.0 : 1.0) * ecc;  // Δa = ∓u_AB·ê e
          Modulation m;
          m.table = table_of([&](double x) { return 1.0 + c * std::cos(kTwoPi * x); });
          m.order = gm.order;
          m.phase_cycles = (phi0 - std::atan2(uab.y(), uab.x())) / kTwoPi;
          model.meshes[gm.mesh].modulations.push_back(m);
        }
        break;
      }
      case EffectKind::kBearingOuterRaceDefect:
      case EffectKind::kBearingInnerRaceDefect:
      case EffectKind::kBearingBallDefect: {
        const double force = *e.parameter("impact_force_n");
        const double slip = *e.parameter("slip");
        const double width_m = *e.parameter("defect_width_mm") * 1e-3;
        BearingBodies bodies;
        const Bearing* b = nullptr;
        double o_r = 0.0;  // rotating race, per rotor revolution (native frame)
        bool outer_turns = false;
        Eigen::Vector2d load(0.0, 0.0);  // bearing load direction in the native frame
        const Eigen::VectorXd& x1 = unit_deflection();
        for (const Bearing& cand : d.bearings) {
          if (cand.shaft == "planet" && planet_index(e.location, cand.id, planets) > 0) b = &cand;
        }
        if (b != nullptr) {  // a planet bearing: inner ring = the pin on the carrier
          const int k = planet_index(e.location, b->id, planets) - 1;
          const Node& p = (*es.planets)[k];
          const double psi_k = (*es.psi)[k];
          bodies.in_x = es.carrier.x;
          bodies.in_y = es.carrier.y;
          bodies.in_t = es.carrier.t;
          bodies.pin_x = es.r_carrier * std::cos(psi_k);
          bodies.pin_y = es.r_carrier * std::sin(psi_k);
          bodies.out = {{p.x, Eigen::Vector2d(1.0, 0.0)}, {p.y, Eigen::Vector2d(0.0, 1.0)}};
          bodies.nodes_in_carrier_frame = bodies.native_carrier_frame = true;
          o_r = o_planet;
          outer_turns = true;
          // Force of the pin on the planet ~ planet − pin deflection.
          load = Eigen::Vector2d(
              x1[p.x] - x1[es.carrier.x] + es.r_carrier * std::sin(psi_k) * x1[es.carrier.t],
              x1[p.y] - x1[es.carrier.y] - es.r_carrier * std::cos(psi_k) * x1[es.carrier.t]);
        } else {
          b = d.bearing(e.location);
          static constexpr std::array<const char*, 6> kIds{"b1", "b2", "b3", "b4", "b5", "b6"};
          const int i =
              static_cast<int>(std::find_if(kIds.begin(), kIds.end(),
                                            [&](const char* id) { return e.location == id; }) -
                               kIds.begin());
          if (b == nullptr || i >= 6) {
            fail(error, "drivetrain '" + d.name + "': " + what +
                            ": no such bearing in the dynamics model");
            return false;
          }
          const Node& nd = *es.bearing_nodes[static_cast<std::size_t>(i)];
          bodies.in_x = nd.x;
          bodies.in_y = nd.y;
          Eigen::Vector2d seat_x1(0.0, 0.0);
          for (const SeatRef& seat : es.seats) {
            if (seat.bearing != e.location) continue;
            for (const SeatDof& sd : seat.dofs) bodies.out.push_back({sd.dof, sd.dir});
            seat_x1 = seat.displacement(x1);
          }
          bodies.nodes_in_carrier_frame = (b->shaft == ps.output_shaft);
          o_r = shaft_order(b->shaft);
          load = Eigen::Vector2d(x1[nd.x], x1[nd.y]) - seat_x1;
        }
        const double theta_l = load.squaredNorm() > 0.0 ? std::atan2(load.y(), load.x()) : 0.0;
        const double gamma =
            b->element_diameter_m / b->pitch_diameter_m * std::cos(b->contact_angle_rad);
        const double nb = b->elements;
        // Cage speed relative to the stationary race, slowed by the slip.
        const double o_cage = o_r * 0.5 * (outer_turns ? 1.0 + gamma : 1.0 - gamma) * (1.0 - slip);
        const double d_outer =
            b->pitch_diameter_m + b->element_diameter_m * std::cos(b->contact_angle_rad);
        const double d_inner =
            b->pitch_diameter_m - b->element_diameter_m * std::cos(b->contact_angle_rad);
        // Load zone (Stribeck, ε = ½): q = cos^p of the angle from the load direction within
        // ±90°, p = 10/9 for rollers, 3/2 for balls.
        const double p_exp = b->type == BearingType::kRoller ? 10.0 / 9.0 : 1.5;
        auto load_zone = [&](double angle) {
          const double c = std::cos(wrap_pi(angle - theta_l));
          return c > 0.0 ? std::pow(c, p_exp) : 0.0;
        };
        // An impact: a half sine lasting the time a rolling element takes to cross the
        // defect, as a fraction of the impact period (at least three table samples).
        auto pulse_table = [](double fraction) {
          const double w = std::clamp(fraction, 3.0 / PeriodicTable::kSize, 0.5);
          return table_of(
              [w](double x) { return x < w ? std::sin(std::numbers::pi * x / w) : 0.0; });
        };
        const bool on_outer = e.kind == EffectKind::kBearingOuterRaceDefect;
        const bool on_inner = e.kind == EffectKind::kBearingInnerRaceDefect;
        const bool stationary_race = (on_outer && !outer_turns) || (on_inner && outer_turns);
        const std::string id = e.location + "." + std::string(effect_id(e.kind));
        const int group = impact_groups++;
        if (e.kind == EffectKind::kBearingBallDefect) {
          // A defect on a rolling element strikes both races once per element revolution
          // (2·BSF), carried round by the cage through the load zone.
          const double bsf =
              b->pitch_diameter_m / (2.0 * b->element_diameter_m) * (1.0 - gamma * gamma);
          const double po = 2.0 * bsf * std::abs(o_r) * (1.0 - slip);
          const PeriodicTable pulse =
              pulse_table(2.0 * width_m / (std::numbers::pi * b->element_diameter_m));
          add_bearing_force(
              bodies, id, force, pulse, po,
              table_of([&](double x) { return load_zone(kTwoPi * x) * std::cos(kTwoPi * x); }),
              table_of([&](double x) { return load_zone(kTwoPi * x) * std::sin(kTwoPi * x); }),
              o_cage, group);
        } else if (stationary_race) {
          // A defect on the stationary race sits in the load zone: every element passing it
          // strikes, along the load direction, at Nb × the cage speed.
          const double po = nb * std::abs(o_cage);
          const double race = on_outer ? d_outer : d_inner;
          const PeriodicTable pulse = pulse_table(width_m * nb / (std::numbers::pi * race));
          const double cx = std::cos(theta_l), cy = std::sin(theta_l);
          add_bearing_force(bodies, id, force, pulse, po, PeriodicTable::constant(cx),
                            PeriodicTable::constant(cy), 0.0, group);
        } else {
          // A defect on the turning race: struck at Nb × (race − cage speed), along the
          // defect's own radius, hard inside the load zone, not at all outside it.
          const double po = nb * std::abs(o_r - o_cage);
          const double race = on_outer ? d_outer : d_inner;
          const PeriodicTable pulse = pulse_table(width_m * nb / (std::numbers::pi * race));
          add_bearing_force(
              bodies, id, force, pulse, po,
              table_of([&](double x) { return load_zone(kTwoPi * x) * std::cos(kTwoPi * x); }),
              table_of([&](double x) { return load_zone(kTwoPi * x) * std::sin(kTwoPi * x); }), o_r,
              group);
        }
        break;
      }
      case EffectKind::kShaftUnbalance: {
        // F = U·Ω² turning with the shaft, at the shaft's heaviest gear (g1, g3, g4).
        const double u = *e.parameter("unbalance_kg_m");
        const double phi0 = *e.parameter("phase_deg") / 360.0;
        const double o = shaft_order(e.location);
        const Node* node = nullptr;
        double o_rel = o;
        if (e.location == ps.output_shaft) {
          node = &(*es.sun_shaft)[kG1Node];
          o_rel = o - fo;  // seen from the carrier's axes
        } else if (e.location == is.output_shaft) {
          node = &(*es.ims)[kG3Node];
        } else {
          node = &(*es.hss)[kG4Node];
        }
        for (int c = 0; c < 2; ++c) {
          ForceTerm f;
          f.id = e.location + ".shaft_unbalance";
          f.pattern = Eigen::VectorXd::Zero(n_dof);
          f.pattern[c == 0 ? node->x : node->y] = 1.0;
          f.amplitude = u * std::pow(kTwoPi * o, 2);
          f.per_rotor_hz_squared = true;
          f.shape = c == 0 ? cos_table : sin_table;
          f.order = o_rel;
          f.phase_cycles = phi0;
          model.forces.push_back(std::move(f));
        }
        break;
      }
      case EffectKind::kShaftMisalignment: {
        // An angular misalignment δ makes the coupling carry the torque T with a bending
        // moment T·δ that fluctuates twice per revolution (and once, `ratio_1x` of it),
        // reacted over the lever ℓ to the next bearing: F = T_shaft·δ/ℓ (cos 2θ + r cos θ)
        // along the offset's direction. hss: at the generator coupling, ℓ to b6; ims (no
        // coupling): a bore misalignment, the moment as a couple on b3 and b4, ℓ the span.
        const double delta = *e.parameter("misalignment_mrad") * 1e-3;
        const double r1 = *e.parameter("ratio_1x");
        const double dir = *e.parameter("direction_deg") * std::numbers::pi / 180.0;
        const Eigen::Vector2d dv(std::cos(dir), std::sin(dir));
        ForceTerm f;
        f.id = e.location + ".shaft_misalignment";
        f.pattern = Eigen::VectorXd::Zero(n_dof);
        double lever = 0.0, ratio = 0.0;
        if (e.location == hs.output_shaft) {
          const Node& c = (*es.hss)[kGeneratorNode];
          f.pattern[c.x] = dv.x();
          f.pattern[c.y] = dv.y();
          lever = d.shaft(hs.output_shaft)->length_m * (kGeneratorNode - kB6Node) / kHssElements;
          ratio = es.torque_ratio[3];
        } else {
          const Node& a = (*es.ims)[kB3Node];
          const Node& c = (*es.ims)[kB4Node];
          f.pattern[a.x] = dv.x();
          f.pattern[a.y] = dv.y();
          f.pattern[c.x] = -dv.x();
          f.pattern[c.y] = -dv.y();
          lever = d.shaft(is.output_shaft)->length_m * (kB4Node - kB3Node) / kImsElements;
          ratio = es.torque_ratio[2];
        }
        f.amplitude = ratio * delta / lever;
        f.per_newton_metre = true;
        f.shape = table_of(
            [r1](double x) { return std::cos(2.0 * kTwoPi * x) + r1 * std::cos(kTwoPi * x); });
        f.order = shaft_order(e.location);
        model.forces.push_back(std::move(f));
        break;
      }
      case EffectKind::kPlanetPassModulation: {
        // The ring's reaction reaches a measured seat through the housing the more the
        // nearer a planet stands to that seat's side of the ring: a path from the ring's
        // rim (r_ring·θ_ring) to the seat's radial displacement whose stiffness is k_p times
        // Σ_n h(ψ_n(t) − θ_seat), h a Hann window of half-width W (McFadden & Smith 1985's
        // changing transmission path, here as a stiffness of the equations of motion).
        const double kp = *e.parameter("path_stiffness_mn_m") * 1e6;
        const double w = *e.parameter("window_deg") * std::numbers::pi / 180.0;
        for (const SeatRef& seat : es.seats) {
          static constexpr std::array<const char*, 6> kIds{"b1", "b2", "b3", "b4", "b5", "b6"};
          const auto i = std::find_if(kIds.begin(), kIds.end(),
                                      [&](const char* id) { return seat.bearing == id; }) -
                         kIds.begin();
          const Eigen::Vector2d c = es.bearing_nodes[static_cast<std::size_t>(i)]->centre;
          const double theta_seat = std::atan2(c.y(), c.x());
          const PeriodicTable h = table_of([&](double x) {
            double sum = 0.0;
            for (double psi_n : *es.psi) {
              const double a = wrap_pi(kTwoPi * x + psi_n - theta_seat);
              if (std::abs(a) < w) sum += std::pow(std::cos(0.5 * std::numbers::pi * a / w), 2);
            }
            return sum;
          });
          const double mean = h.mean();
          if (!(mean > 0.0) || kp == 0.0) continue;
          VaryingStiffness v;
          v.id = "planet_pass." + seat.bearing;
          v.directions = Eigen::MatrixXd::Zero(n_dof, 1);
          v.directions(es.ring.t, 0) = es.r_ring;
          for (const auto& [dof, coef] : seat.along(es.sensor_dir, -1.0))
            v.directions(dof, 0) += coef;
          v.mean_n_m = kp * mean;
          v.shape = h;
          for (double& s : v.shape.values) s /= mean;
          v.order = fo;
          v.phase_cycles = 0.0;
          model.stiffness.noalias() +=
              v.mean_n_m * v.directions.col(0) * v.directions.col(0).transpose();
          model.paths.push_back(std::move(v));
        }
        break;
      }
      case EffectKind::kHousingResonance:
        break;  // a DOF of the assembly (build_full_model)
    }
  }
  return true;
}

}  // namespace

int FullModel::dof(std::string_view name) const {
  for (std::size_t i = 0; i < dof_names.size(); ++i) {
    if (dof_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

Eigen::VectorXd VaryingStiffness::direction(int c, double psi_rad) const {
  if (!rotates()) return directions.col(c);
  return directions.col(c) + (std::cos(psi_rad) - 1.0) * rotation_cos.col(c) +
         std::sin(psi_rad) * rotation_sin.col(c);
}

double ForceTerm::scale(double revs, double input_torque_nm, double rotor_hz,
                        double psi_rad) const {
  double a = amplitude;
  if (per_newton_metre) a *= input_torque_nm;
  if (per_rotor_hz_squared) a *= rotor_hz * rotor_hz;
  if (events_revs.empty()) {
    a *= shape.value(order * revs + phase_cycles);
  } else {
    // The latest impact at or before `revs`; its shape in the local coordinate, 0 once a
    // whole nominal period has passed without the next one (the table wraps otherwise).
    const auto it = std::upper_bound(events_revs.begin(), events_revs.end(), revs);
    if (it == events_revs.begin()) return 0.0;
    const double local = (revs - *(it - 1)) * std::abs(order);
    if (local >= 1.0) return 0.0;
    a *= shape.value(local);
  }
  for (const Modulation& m : modulations) a *= m.value(revs);
  if (frame[1] != 0.0 || frame[2] != 0.0) {
    a *= frame[0] + frame[1] * std::cos(psi_rad) + frame[2] * std::sin(psi_rad);
  } else {
    a *= frame[0];
  }
  return a;
}

double ForceTerm::mean_scale(double input_torque_nm, double rotor_hz) const {
  double a = amplitude * frame[0];
  if (per_newton_metre) a *= input_torque_nm;
  if (per_rotor_hz_squared) a *= rotor_hz * rotor_hz;
  a *= order == 0.0 ? shape.value(phase_cycles) : shape.mean();
  for (const Modulation& m : modulations) a *= m.order == 0.0 ? m.value(0.0) : m.table.mean();
  return a;
}

double FullModel::carrier_angle_rad(double rotor_revolutions) const {
  return 2.0 * std::numbers::pi * frame_order * rotor_revolutions;
}

Eigen::VectorXd FullModel::force(double rotor_revolutions, double input_torque_nm,
                                 double rotor_hz) const {
  const double psi = carrier_angle_rad(rotor_revolutions);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const ForceTerm& t : forces)
    f += t.scale(rotor_revolutions, input_torque_nm, rotor_hz, psi) * t.pattern;
  return f;
}

Eigen::VectorXd FullModel::mesh_excitation_force(double rotor_revolutions) const {
  const double psi = carrier_angle_rad(rotor_revolutions);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const VaryingStiffness& v : meshes) {
    if (v.excitations.empty()) continue;
    f += v.stiffness_n_m(rotor_revolutions) * v.excitation_m(rotor_revolutions) *
         v.direction(0, psi);
  }
  return f;
}

Eigen::MatrixXd FullModel::stiffness_at(double rotor_revolutions) const {
  Eigen::MatrixXd k = stiffness;
  const double psi = carrier_angle_rad(rotor_revolutions);
  for (const auto* list : {&meshes, &bearings, &paths}) {
    for (const VaryingStiffness& v : *list) {
      if (!v.rotates()) continue;
      for (int c = 0; c < v.directions.cols(); ++c) {
        const Eigen::VectorXd u = v.direction(c, psi);
        k.noalias() += v.mean_n_m *
                       (u * u.transpose() - v.directions.col(c) * v.directions.col(c).transpose());
      }
    }
  }
  return k;
}

Eigen::VectorXd FullModel::static_deflection(double input_torque_nm) const {
  return static_deflection_at(input_torque_nm, 0.0);
}

Eigen::VectorXd FullModel::static_deflection_at(double input_torque_nm,
                                                double rotor_revolutions) const {
  const double psi = carrier_angle_rad(rotor_revolutions);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs());
  for (const ForceTerm& t : forces) f += t.mean_scale(input_torque_nm) * t.pattern;
  // The mean transmission error pushes like a force: +u·k̄·ē.
  for (const VaryingStiffness& v : meshes) {
    double e = 0.0;
    for (const MeshExcitation& x : v.excitations)
      e += x.amplitude_m * (x.pattern.order == 0.0 ? x.pattern.value(0.0) : x.pattern.table.mean());
    if (e != 0.0) f += v.mean_n_m * e * v.direction(0, psi);
  }
  if (rotor_revolutions == 0.0) return stiffness.llt().solve(f);
  return stiffness_at(rotor_revolutions).llt().solve(f);
}

double FullModel::static_mesh_force(std::size_t i, const Eigen::VectorXd& x,
                                    double rotor_revolutions) const {
  const VaryingStiffness& v = meshes[i];
  double e = 0.0;
  for (const MeshExcitation& m : v.excitations)
    e += m.amplitude_m * (m.pattern.order == 0.0 ? m.pattern.value(0.0) : m.pattern.table.mean());
  return v.mean_n_m * (v.direction(0, carrier_angle_rad(rotor_revolutions)).dot(x) - e);
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
      !(dp.bearing_stiffness_fluctuation >= 0.0) || !(dp.bearing_stiffness_fluctuation < 1.0) ||
      !(dp.bearing_compliance_scale >= 0.0) || !std::isfinite(dp.bearing_compliance_scale)) {
    fail(error, "drivetrain '" + d.name +
                    "': dynamics: rayleigh_eta, rayleigh_zeta must be ≥ 0, "
                    "bearing_stiffness_fluctuation in [0, 1) and bearing_compliance_scale a "
                    "finite value ≥ 0");
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
  if (!(dp.sun_shaft_torsion_scale > 0.0) || !std::isfinite(dp.sun_shaft_torsion_scale)) {
    fail(error,
         "drivetrain '" + d.name + "': dynamics: sun_shaft_torsion_scale must be finite and > 0");
    return std::nullopt;
  }
  for (std::size_t i = 0; i < dp.mesh_tip_relief.size(); ++i) {
    if (!(dp.mesh_tip_relief[i] >= 0.0 && dp.mesh_tip_relief[i] <= 1.0)) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: mesh_tip_relief must be in [0, 1] (index " + std::to_string(i) +
                      ")");
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
    if (!std::isfinite(dp.transmission_error_phase_rad[i])) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: transmission_error_phase_rad must be finite (index " +
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
  if (dp.gearbox_body_mass_kg != 0.0) {
    const double m = dp.gearbox_body_mass_kg, k = dp.gearbox_mount_stiffness_n_m,
                 xi = dp.gearbox_mount_damping_ratio;
    if (!(m > 0.0) || !std::isfinite(m) || !(k > 0.0) || !std::isfinite(k) || !(xi >= 0.0) ||
        !(xi < 1.0)) {
      fail(error, "drivetrain '" + d.name +
                      "': dynamics: gearbox body: gearbox_body_mass_kg and "
                      "gearbox_mount_stiffness_n_m must be finite and > 0 (mass 0: no body), "
                      "gearbox_mount_damping_ratio in [0, 1)");
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
    const double p =
        s.carrier_angle_rad + 2.0 * std::numbers::pi * n / ps.planets;  // equally spaced
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

  auto build_shaft = [&](const Shaft& shaft, int elements, const Eigen::Vector2d& centre,
                         double torsion_scale) -> std::optional<std::vector<Node>> {
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
    const double k_tor = torsion_scale * gmod * j_polar / le;
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
  const auto sun_shaft = build_shaft(*sh[0], kSunShaftElements, Eigen::Vector2d::Zero(),
                                     d.dynamics.sun_shaft_torsion_scale);
  if (!sun_shaft) return std::nullopt;
  const auto ims = build_shaft(*sh[1], kImsElements, ims_centre, 1.0);
  if (!ims) return std::nullopt;
  const auto hss = build_shaft(*sh[2], kHssElements, hss_centre, 1.0);
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

  // ---- effects: validated first (effects.hpp) ------------------------------------------------
  for (const Effect& e : d.effects) {
    std::string why;
    if (!check_effect(d, e, &why)) {
      fail(error, "drivetrain '" + d.name + "': effects: " + why);
      return std::nullopt;
    }
  }

  // ---- housing seats under the measured bearings -----------------------------------------------
  // The sun shaft turns in the carrier frame; a seat under b1/b2 would join the two frames
  // through the bearing's full stiffness, so seats sit under the parallel-stage bearings.
  // A seat's displacement in the housing frame is Σ_d dir_d · x[dof_d] (SeatRef): the plain
  // seat has seat.x along x and seat.y along y; a modal housing has each mode's DOF along the
  // sensor direction s and one seat DOF across it (t).
  using Seat = SeatRef;
  const Eigen::Vector2d sensor_dir(std::cos(s.sensor_angle_rad), std::sin(s.sensor_angle_rad));
  const Eigen::Vector2d across_dir(-sensor_dir.y(), sensor_dir.x());
  std::vector<Seat> seats;
  std::vector<OwnDamper> own_dampers;  // housing modes, housing resonances, the mounts
  // The gearbox body on its mounts (DynamicsParameters::gearbox_body_mass_kg): one DOF u_b
  // along the sensor direction, mass M_b on the mounts' stiffness K_b to the nacelle frame,
  // with the mounts' own damping ratio. It is one more term of every parallel-stage seat's
  // displacement (the measured seats' and, below, the unmeasured ones'), each with
  // participation 1 — the rigid body moves every seat alike — so every such bearing's force
  // drives it (the bearing's direction vector carries −s at u_b: K stays symmetric) and both
  // sensors read its acceleration. The planetary stage (b1, b2, ring, carrier) is described in
  // the turning carrier frame and stays on ground: the body is the parallel-stage end of the
  // box moving on its supports about the planetary stage held by the main shaft and the
  // torque arms (docs/dynamics.md).
  SeatDof body;
  if (dp.gearbox_body_mass_kg > 0.0) {
    body.dof = as.add_dof("gearbox_body", dp.gearbox_body_mass_kg);
    body.dir = sensor_dir;
    body.sensor = 1.0;
    body.stiffness = dp.gearbox_mount_stiffness_n_m;
    body.damping_ratio = dp.gearbox_mount_damping_ratio;
    as.spring({{body.dof, 1.0}}, body.stiffness);
    own_dampers.push_back({{{body.dof, 1.0}}, body.stiffness, body.damping_ratio});
  }
  for (std::size_t p = 0; p < d.measurement_points.size(); ++p) {
    const MeasurementPoint& mp = d.measurement_points[p];
    bool known = false;
    for (int i = 2; i < 6; ++i) known = known || mp.location == bearing_ids[i];
    if (!known) {
      fail(error, "drivetrain '" + d.name + "': measurement_points: '" + mp.channel +
                      "' sits on '" + mp.location +
                      "'; the dynamics model has housing seats under b3..b6 only (the sun "
                      "shaft's b1, b2 turn with the carrier frame)");
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
        own_dampers.push_back({{{h.dof, 1.0}}, h.stiffness, h.damping_ratio});
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
    if (body.dof >= 0) seat.dofs.push_back(body);
    // housing_resonance: the sensor sits on a housing mass m on a spring k = m(2πf)² to the
    // seat, along the sensor's direction, with its own damper (assign_modal_damping()).
    const Effect* resonance = nullptr;
    for (const Effect& e : d.effects) {
      if (e.kind == EffectKind::kHousingResonance && e.location == mp.location) resonance = &e;
    }
    if (resonance != nullptr) {
      const double f = *resonance->parameter("frequency_hz");
      const double m = *resonance->parameter("mass_kg");
      seat.sensor_dof = as.add_dof("housing." + mp.location, m);
      std::vector<std::pair<int, double>> dir = seat.along(sensor_dir, -1.0);
      dir.insert(dir.begin(), {seat.sensor_dof, 1.0});
      const double k = m * std::pow(2.0 * std::numbers::pi * f, 2);
      as.spring(dir, k);
      own_dampers.push_back({dir, k, *resonance->parameter("damping_ratio")});
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
  // Every other parallel-stage bearing's seat is in the same housing: mode k moves it by
  // c·h_k along the sensor direction (housing_seat_participation; 0: the seat on ground, the
  // model before the parameter). Reciprocally its bearing's force drives h_k with c: one
  // term of the bearing's direction, so K stays symmetric and the coupling stores no energy
  // of its own. The sensors do not read these seats.
  std::array<std::vector<SeatDof>, kHousingSeatBearings> seat_couplings;
  {
    std::array<int, kHousingPoints * kHousingModesPerPoint> mode_dof{};
    mode_dof.fill(-1);
    for (const Seat& seat : seats) {
      for (const SeatDof& sd : seat.dofs) {
        if (sd.param >= 0) mode_dof[static_cast<std::size_t>(sd.param)] = sd.dof;
      }
    }
    for (std::size_t b = 0; b < kHousingSeatBearings; ++b) {
      const std::string& id = bearing_ids[kHousingSeatFirstBearing + b];
      const bool measured = std::any_of(seats.begin(), seats.end(),
                                        [&](const Seat& seat) { return seat.bearing == id; });
      for (std::size_t k = 0; k < mode_dof.size(); ++k) {
        const std::size_t i = b * mode_dof.size() + k;
        const double c = dp.housing_seat_participation[i];
        if (c == 0.0) continue;
        std::string why;
        if (!std::isfinite(c)) {
          why = "is not finite";
        } else if (measured) {
          why = "is on measured bearing '" + id +
                "' (its seat's participations are housing_participation and "
                "housing_cross_participation)";
        } else if (mode_dof[k] < 0) {
          why = "names point " + std::to_string(k / kHousingModesPerPoint + 1) + "'s mode " +
                std::to_string(k % kHousingModesPerPoint + 1) +
                ", which is not modelled (housing_frequency_hz 0 or no such point)";
        }
        if (!why.empty()) {
          fail(error, "drivetrain '" + d.name + "': dynamics: housing_seat_participation[" +
                          std::to_string(i) + "] " + why);
          return std::nullopt;
        }
        SeatDof sd;
        sd.dof = mode_dof[k];
        sd.dir = c * sensor_dir;
        seat_couplings[b].push_back(sd);
      }
      if (body.dof >= 0 && !measured) {
        SeatDof sd;
        sd.dof = body.dof;
        sd.dir = sensor_dir;  // the body moves this seat as it moves the measured ones
        seat_couplings[b].push_back(sd);
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
  // The carrier is the rotor shaft (the input of the planetary stage).
  model.frame_order = s.carrier_turns ? 1.0 : 0.0;
  model.frame_inertia = s.frame_inertia;
  model.carrier_frame_xy.push_back({carrier.x, carrier.y});
  model.carrier_frame_xy.push_back({ringn.x, ringn.y});
  for (const Node& p : planets) model.carrier_frame_xy.push_back({p.x, p.y});
  for (const Node& nd : *sun_shaft) model.carrier_frame_xy.push_back({nd.x, nd.y});

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
  const MeshStiffness k_sp =
      mesh_stiffness(sp_pair, dp.mesh_stiffness_scale[0], dp.mesh_tip_relief[0]);
  const MeshStiffness k_rp =
      mesh_stiffness(rp_pair, dp.mesh_stiffness_scale[0], dp.mesh_tip_relief[0]);
  const double gamma_rs = ring_sun_phase(planet.teeth);
  // Static transmission error of stage `stage` (DynamicsParameters::transmission_error_m):
  // e(t) = Σ_h a_h cos(2π h (order·N_rotor + phase) + φ_h), the mesh's own cycle; none when 0.
  const auto add_transmission_error = [&](VaryingStiffness& v, std::size_t stage) {
    const double* a = &dp.transmission_error_m[stage * kTransmissionErrorHarmonics];
    if (std::all_of(a, a + kTransmissionErrorHarmonics, [](double x) { return x == 0.0; })) return;
    MeshExcitation x;
    x.amplitude_m = 1.0;
    const double* phase = &dp.transmission_error_phase_rad[stage * kTransmissionErrorHarmonics];
    x.pattern = {transmission_error_table(a, kTransmissionErrorHarmonics, phase), v.order,
                 v.phase_cycles};
    v.excitations.push_back(x);
  };
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
      add_transmission_error(v, 0);
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
    add_transmission_error(v, 0);
    // Ring reaction torque = T_in − T_sun.
    model.mesh_info.push_back({planets[n].centre, Eigen::Vector2d::Zero(), r_ring * u, mv.n,
                               rp_geo.base_radius2_m, 1.0 - sun_torque_ratio, 0.0, ps.planets});
    add_varying(model.meshes, std::move(v));
  }

  // Pin position errors (StructuralParameters::planet_pin_error_m): both meshes of the planet
  // close by e·(n·w) = e·cos α_t.
  if (s.planet_pin_error_m.size() > static_cast<std::size_t>(ps.planets)) {
    fail(error, "structure: planet_pin_error_m has " + std::to_string(s.planet_pin_error_m.size()) +
                    " entries for " + std::to_string(ps.planets) + " planets");
    return std::nullopt;
  }
  for (std::size_t n = 0; n < s.planet_pin_error_m.size(); ++n) {
    const double e = s.planet_pin_error_m[n];
    if (!std::isfinite(e)) {
      fail(error, "structure: planet_pin_error_m[" + std::to_string(n) + "] must be finite");
      return std::nullopt;
    }
    if (e == 0.0) continue;
    for (std::size_t j : {n, n + static_cast<std::size_t>(ps.planets)}) {
      MeshExcitation x;
      x.amplitude_m = -e * std::cos(alpha);
      x.pattern = {PeriodicTable::constant(1.0), 0.0, 0.0};
      model.meshes[j].excitations.push_back(x);
    }
  }

  // ---- parallel helical meshes -----------------------------------------------------------------
  // Driver A (wheel) turning in sense `spin` (+1: +θ) pushes the pinion B tangentially in
  // A's surface velocity and away from A: n_t = spin·cos α_t·w + sin α_t·u, u from A to B.
  // A wheel on the sun shaft (`a_turns`: the intermediate stage's g1) is described in the
  // carrier frame, its pinion in the housing's: the housing-fixed normal n seen from the
  // carrier's axes turns backwards, R(−ψ)n, so its g1 part is n cos ψ + Jᵀn sin ψ.
  auto parallel_mesh = [&](const char* id, const Node& a, const Node& b, const MeshGeometry& geo,
                           double spin, double order, double scale, const GearPair& pair,
                           double torque_ratio, bool a_turns, std::size_t stage) {
    const Eigen::Vector2d ab = b.centre - a.centre;
    const Eigen::Vector2d u = ab.normalized();
    const Eigen::Vector2d w(-u.y(), u.x());
    const double at = geo.transverse_pressure_angle_rad;
    const Eigen::Vector2d nt = spin * std::cos(at) * w + std::sin(at) * u;
    const Eigen::Vector2d pitch = a.centre + geo.pitch_radius2_m * u;  // wheel = gear 2 of the pair
    const MeshVector mv = mesh_vector(a.centre, b.centre, pitch, nt, geo.base_helix_angle_rad, 1.0);
    const MeshStiffness k = mesh_stiffness(pair, scale, dp.mesh_tip_relief[stage]);
    VaryingStiffness v;
    v.id = id;
    v.directions = mesh_direction(n_dof, a, b, mv);
    v.mean_n_m = k.mean_n_m;
    v.shape = k.shape;
    v.order = order;
    v.phase_cycles = 0.0;
    add_transmission_error(v, stage);
    if (a_turns) {
      v.rotation_cos = Eigen::MatrixXd::Zero(n_dof, 1);
      v.rotation_sin = Eigen::MatrixXd::Zero(n_dof, 1);
      v.rotation_cos(a.x, 0) = mv.n.x();
      v.rotation_cos(a.y, 0) = mv.n.y();
      v.rotation_sin(a.x, 0) = mv.n.y();
      v.rotation_sin(a.y, 0) = -mv.n.x();
    }
    model.mesh_info.push_back({a.centre, b.centre, pitch, mv.n, geo.base_radius1_m, torque_ratio,
                               geo.base_helix_angle_rad, 1});
    add_varying(model.meshes, std::move(v));
  };
  // Sun and carrier turn the same way (ring fixed): the sun shaft spins +θ, the ims −θ.
  const double ims_torque_ratio = sun_torque_ratio / kin.stage_ratio(1);
  const double hss_torque_ratio = ims_torque_ratio / kin.stage_ratio(2);
  parallel_mesh("intermediate", (*sun_shaft)[kG1Node], (*ims)[kG2Node], int_geo, +1.0,
                kin.mesh_hz(1, 60.0), dp.mesh_stiffness_scale[1], int_pair, ims_torque_ratio,
                s.carrier_turns, 1);
  parallel_mesh("high_speed", (*ims)[kG3Node], (*hss)[kG4Node], hs_geo, -1.0, kin.mesh_hz(2, 60.0),
                dp.mesh_stiffness_scale[2], hs_pair, hss_torque_ratio, false, 2);

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
    if (i >= static_cast<int>(kHousingSeatFirstBearing)) {
      for (const SeatDof& sd :
           seat_couplings[static_cast<std::size_t>(i) - kHousingSeatFirstBearing]) {
        v.directions(sd.dof, 0) -= sd.dir.x();
        v.directions(sd.dof, 1) -= sd.dir.y();
      }
    }
    v.mean_n_m = b.radial_stiffness_n_m * b.rows *
                 dp.bearing_stiffness_scale[sites[i].shaft_group] * dp.bearing_stiffness_factor[i];
    // Varying compliance: the elements passing through the load zone (bearing_compliance.hpp),
    // derived from the bearing's element count and contact law, scaled, plus the explicit cosine.
    v.shape = bearing_stiffness_shape(b.elements, b.type, dp.bearing_compliance_scale,
                                      dp.bearing_stiffness_fluctuation);
    {
      double lo = v.shape.values[0];
      for (double x : v.shape.values) lo = std::min(lo, x);
      if (!(lo > 0.0)) {
        fail(error, "drivetrain '" + d.name + "': dynamics: bearing '" + b.id +
                        "': bearing_compliance_scale and bearing_stiffness_fluctuation make its "
                        "stiffness reach zero within a ball pass");
        return std::nullopt;
      }
    }
    const std::optional<BearingFrequencies> f = kin.bearing_hz(b.id, 60.0);
    if (!f) {
      fail(error, "drivetrain '" + d.name + "': bearings: '" + b.id + "': shaft '" + b.shaft +
                      "' is not a drivetrain shaft");
      return std::nullopt;
    }
    v.order = f->bpfo_hz;  // varying compliance: one period per ball passing the outer race
    v.phase_cycles = 0.0;
    // Isotropic (the same k(t) in x and y), so the sun shaft's b1, b2 are the same in the
    // carrier's axes; their forces are turned into the housing frame when reported.
    v.carrier_frame_xy = sites[i].shaft_group == 0;
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
    if (seats[i].sensor_dof >= 0) {
      sensor.row[seats[i].sensor_dof] = 1.0;
    } else {
      for (const SeatDof& sd : seats[i].dofs) sensor.row[sd.dof] = sd.sensor;
    }
    model.sensors.push_back(sensor);
  }

  // ---- effects (effects.hpp)
  // ---------------------------------------------------------------------
  if (!d.effects.empty()) {
    EffectSites es;
    es.sun_shaft = &*sun_shaft;
    es.ims = &*ims;
    es.hss = &*hss;
    es.planets = &planets;
    es.psi = &psi;
    es.carrier = carrier;
    es.ring = ringn;
    es.r_carrier = r_carrier;
    es.r_ring = r_ring;
    es.pairs = {sp_pair, rp_pair, int_pair, hs_pair};
    es.geos = {sp_geo, rp_geo, int_geo, hs_geo};
    es.sensor_dir = sensor_dir;
    es.torque_ratio = {1.0, sun_torque_ratio, ims_torque_ratio, hss_torque_ratio};
    for (int i = 0; i < 6; ++i) es.bearing_nodes[i] = sites[i].node;
    for (const Seat& seat : seats) es.seats.push_back(seat);
    if (!add_effects(d, kin, es, model, error)) return std::nullopt;
  }

  // ---- damping: modal, strain-energy mix of the gearbox's and the own dampers' ratios -------
  if (!assign_modal_damping(model, dp, own_dampers, error)) return std::nullopt;
  return model;
}

}  // namespace model::dynamics

namespace model::dynamics {

void randomise_impacts(FullModel& model, double jitter, double seconds, double rotor_hz,
                       unsigned long long seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double last_rev = seconds * rotor_hz + 1.0;
  for (int group = 0;; ++group) {
    std::vector<ForceTerm*> terms;
    for (ForceTerm& f : model.forces) {
      if (f.impact_group == group) terms.push_back(&f);
    }
    if (terms.empty()) break;
    const double order = std::abs(terms.front()->order);
    if (!(order > 0.0)) continue;
    const double period = 1.0 / order;  // [rotor revolutions]
    // The deterministic train's first impact (shape(order·N + phase) starts at x = 0), one
    // period early so that the record opens inside a train.
    const double phase =
        terms.front()->order > 0.0 ? terms.front()->phase_cycles : -terms.front()->phase_cycles;
    std::vector<double> events;
    for (double n = -period - (phase - std::floor(phase)) * period; n <= last_rev;) {
      events.push_back(n);
      n += period * std::max(0.5, 1.0 + jitter * normal(rng));
    }
    for (ForceTerm* f : terms) f->events_revs = events;
  }
}

}  // namespace model::dynamics
