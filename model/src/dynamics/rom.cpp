#include "model/dynamics/rom.hpp"

#include "model/dynamics/eigen_instances.hpp"
#include "rom_kernel.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace model::dynamics {

static_assert(detail::kKernelDofs == kRomDofs && detail::kKernelMeshes == kRomMeshes &&
                  detail::kKernelMeshBasis == kRomMeshBasis &&
                  detail::kKernelBearings == kRomBearings &&
                  detail::kKernelBearingRank == kRomBearingRank &&
                  detail::kKernelPaths == kRomPaths && detail::kKernelForces == kRomForces &&
                  detail::kKernelSensors == kRomSensors &&
                  detail::kKernelReadoutRows == kRomReadoutRows &&
                  detail::kKernelLookups == kRomLookups &&
                  detail::kKernelTableSize == static_cast<int>(PeriodicTable::kSize),
              "rom_kernel.hpp's capacities must equal rom.hpp's");
static_assert(kRomSensors == 2, "RomOutputs::acceleration_m_s2 is filled by the kernel");
static_assert(kRomDofs % 8 == 0 && kRomLookups % 8 == 0, "whole SIMD vectors of 8");

namespace {

constexpr int kLookupOne = detail::kKernelLookupOne;
constexpr int kLookupZero = detail::kKernelLookupZero;
constexpr int kRowBearings = detail::kKernelRowBearings;
constexpr int kRowTurning = detail::kKernelRowTurning;
constexpr int kRowPaths = detail::kKernelRowPaths;

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

// A table of the look-ups being laid out (build_rom only).
struct LookupPlan {
  double order = 0.0, phase = 0.0;
  PeriodicTable table = PeriodicTable::constant(1.0);
};

// The product of factors of one order as one table at phase 0: Π_k table_k(x + phase_k).
PeriodicTable product_table(const std::vector<const Modulation*>& factors) {
  PeriodicTable t = PeriodicTable::constant(1.0);
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double x = static_cast<double>(i) / PeriodicTable::kSize;
    for (const Modulation* f : factors) t.values[i] *= f->table.value(x + f->phase_cycles);
  }
  return t;
}

}  // namespace

double RomData::lookup(int t, double revs) const noexcept {
  if (t == kLookupOne) return 1.0;
  if (t == kLookupZero || t < 0 || t >= lookups) return 0.0;
  const double x = term_order[t] * revs + term_phase_cycles[t];
  const double pos = (x - std::floor(x)) * static_cast<double>(PeriodicTable::kSize);
  const int i = std::min(static_cast<int>(pos), static_cast<int>(PeriodicTable::kSize) - 1);
  const double w = pos - i;
  const double* table = term_values.data() + t * static_cast<int>(PeriodicTable::kSize);
  const double v0 = table[i];
  return v0 + w * (table[(i + 1) % static_cast<int>(PeriodicTable::kSize)] - v0);
}

std::unique_ptr<RomData> build_rom(const FullModel& m, double dt_s, double cutoff_hz,
                                   std::string* error, RomBuildReport* report) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s) || !(cutoff_hz > 0.0) || !std::isfinite(cutoff_hz)) {
    fail(error, "rom: time step and cut-off frequency must be finite and > 0");
    return nullptr;
  }
  if (m.meshes.size() > static_cast<std::size_t>(kRomMeshes) ||
      m.bearings.size() > static_cast<std::size_t>(kRomBearings) ||
      m.paths.size() > static_cast<std::size_t>(kRomPaths) ||
      m.forces.size() > static_cast<std::size_t>(kRomForces) ||
      m.sensors.size() > static_cast<std::size_t>(kRomSensors)) {
    fail(error,
         "rom: the model has more meshes, bearings, paths, forces or sensors than the ROM's "
         "capacity (" +
             std::to_string(kRomMeshes) + ", " + std::to_string(kRomBearings) + ", " +
             std::to_string(kRomPaths) + ", " + std::to_string(kRomForces) + ", " +
             std::to_string(kRomSensors) + ")");
    return nullptr;
  }
  const auto id_too_long = [&](const std::string& id) {
    if (id.size() <= kRomIdChars) return false;
    fail(error, "rom: id '" + id + "' is longer than kRomIdChars = " + std::to_string(kRomIdChars));
    return true;
  };
  for (const auto& v : m.meshes)
    if (id_too_long(v.id)) return nullptr;
  for (const auto& v : m.bearings)
    if (id_too_long(v.id)) return nullptr;
  for (const auto& v : m.sensors)
    if (id_too_long(v.channel)) return nullptr;
  for (const auto& b : m.bearings) {
    if (b.directions.cols() != 2 || b.rotates() || !b.modulations.empty() ||
        !b.excitations.empty()) {
      fail(error,
           "rom: bearing '" + b.id + "' must be a fixed rank-2 (x, y) element with one table");
      return nullptr;
    }
  }
  for (const auto& p : m.paths) {
    if (p.directions.cols() != 1 || p.rotates() || !p.modulations.empty()) {
      fail(error, "rom: path '" + p.id + "' must be a fixed rank-1 element with one table");
      return nullptr;
    }
  }
  int turning = -1;
  for (std::size_t j = 0; j < m.meshes.size(); ++j) {
    const VaryingStiffness& v = m.meshes[j];
    if (v.directions.cols() != 1) {
      fail(error, "rom: mesh '" + v.id + "' must have rank 1");
      return nullptr;
    }
    if (v.rotates()) {
      if (turning >= 0) {
        fail(error, "rom: meshes '" + m.meshes[static_cast<std::size_t>(turning)].id + "' and '" +
                        v.id + "' both turn with the carrier; the ROM takes one turning mesh");
        return nullptr;
      }
      turning = static_cast<int>(j);
    }
  }
  for (const auto& f : m.forces) {
    if (!f.events_revs.empty()) {
      fail(error, "rom: force '" + f.id +
                      "' has random impact times (randomise_impacts): the ROM "
                      "takes the deterministic train");
      return nullptr;
    }
  }
  const int n = m.dofs();
  // Full eigenproblem K φ = ω² M φ with diagonal M: symmetric form M^-½ K M^-½.
  const Eigen::VectorXd inv_sqrt_m = m.mass.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd k_sym = inv_sqrt_m.asDiagonal() * m.stiffness * inv_sqrt_m.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> full(k_sym);
  if (full.info() != Eigen::Success) {
    fail(error, "rom: eigen-decomposition of the full model failed");
    return nullptr;
  }
  const Eigen::VectorXd& lambda = full.eigenvalues();
  if (lambda[0] <= 0.0) {
    fail(
        error,
        "rom: the full model's stiffness is not positive definite (unsupported rigid-body motion)");
    return nullptr;
  }
  const double cutoff_w2 = std::pow(2.0 * std::numbers::pi * cutoff_hz, 2);
  int keep = 0;
  while (keep < n && lambda[keep] <= cutoff_w2) ++keep;
  const Eigen::MatrixXd phi =
      inv_sqrt_m.asDiagonal() * full.eigenvectors().leftCols(keep);  // Φᵀ M Φ = I

  // Static correction vectors: every force pattern, mesh direction (the turning mesh's three
  // parts: its compliance is then exact at every carrier angle) and path.
  std::vector<Eigen::VectorXd> loads;
  for (const auto& f : m.forces) loads.push_back(f.pattern);
  for (const auto& v : m.meshes) {
    loads.push_back(v.directions.col(0));
    // The turning mesh's cos ψ and sin ψ parts need no vectors of their own: the mesh
    // compliance stays exact at every carrier angle without them (test_rom.cpp: 1e-10 of the
    // full model's static mesh forces at four angles), and each would cost 1/64 of a step.
  }
  for (const auto& p : m.paths) loads.push_back(p.directions.col(0));
  const Eigen::LLT<Eigen::MatrixXd> k_llt(m.stiffness);
  // Bearings: their fluctuation acts as Δk_b(t)·(static deflection), a force along the
  // bearing's static load direction (proportional to the torque, so one vector each).
  Eigen::VectorXd unit_torque = Eigen::VectorXd::Zero(n);
  for (const auto& f : m.forces) {
    if (f.per_newton_metre && f.id == "input_torque") unit_torque += f.amplitude * f.pattern;
  }
  if (unit_torque.squaredNorm() > 0.0) {
    const Eigen::VectorXd x1 = k_llt.solve(unit_torque);
    for (const auto& b : m.bearings)
      loads.push_back(b.directions * (b.directions.transpose() * x1));
  }
  // Unit load vectors: the threshold below compares their residuals with each other.
  std::erase_if(loads, [](const Eigen::VectorXd& l) { return !(l.squaredNorm() > 0.0); });
  for (auto& l : loads) l.normalize();
  Eigen::MatrixXd psi(n, static_cast<Eigen::Index>(loads.size()));
  for (std::size_t j = 0; j < loads.size(); ++j) {
    const Eigen::VectorXd modal = phi.transpose() * loads[j];
    psi.col(static_cast<Eigen::Index>(j)) =
        k_llt.solve(loads[j]) - phi * (modal.array() / lambda.head(keep).array()).matrix();
  }
  // The subtraction above cancels most of K̄⁻¹f: restore M-orthogonality to the kept modes
  // explicitly (twice, classical Gram–Schmidt's usual cure), then M-orthonormalise the
  // corrections among themselves, dropping dependent ones.
  for (int pass = 0; pass < 2; ++pass) psi -= phi * (phi.transpose() * (m.mass.asDiagonal() * psi));
  for (Eigen::Index j = 0; j < psi.cols(); ++j) psi.col(j).normalize();
  const Eigen::MatrixXd gram = psi.transpose() * m.mass.asDiagonal() * psi;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ge(gram);
  const double gmax = ge.eigenvalues().maxCoeff();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < gram.rows(); ++j) {
    if (ge.eigenvalues()[j] > 1e-8 * gmax) kept.push_back(j);
  }
  const int n_corr = static_cast<int>(kept.size());
  const int total = keep + n_corr;
  if (total > kRomDofs) {
    fail(error, "rom: " + std::to_string(keep) + " modes up to " + std::to_string(cutoff_hz) +
                    " Hz + " + std::to_string(n_corr) +
                    " correction vectors exceed the capacity kRomDofs = " +
                    std::to_string(kRomDofs) + "; lower the cut-off or raise kRomDofs");
    return nullptr;
  }
  Eigen::MatrixXd basis(n, total);
  basis.leftCols(keep) = phi;
  for (int j = 0; j < n_corr; ++j) {
    basis.col(keep + j) =
        psi * ge.eigenvectors().col(kept[j]) / std::sqrt(ge.eigenvalues()[kept[j]]);
  }
  // Rayleigh–Ritz on the M-orthonormal basis.
  const Eigen::MatrixXd k_red = basis.transpose() * m.stiffness * basis;
  const Eigen::MatrixXd k_red_sym = 0.5 * (k_red + k_red.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> red(k_red_sym);
  const Eigen::MatrixXd phi_r = basis * red.eigenvectors();
  const Eigen::VectorXd& w2 = red.eigenvalues();

  auto data = std::make_unique<RomData>();
  RomData& d = *data;
  d.dt_s = dt_s;
  d.cutoff_hz = cutoff_hz;
  d.eigenmodes = keep;
  d.correction_vectors = n_corr;
  d.dofs = (total + 7) / 8 * 8;
  d.mesh_count = static_cast<int>(m.meshes.size());
  d.bearing_count = static_cast<int>(m.bearings.size());
  d.path_count = static_cast<int>(m.paths.size());
  d.force_count = static_cast<int>(m.forces.size());
  d.sensor_count = static_cast<int>(m.sensors.size());
  d.turning_mesh = turning;
  d.frame_order = m.frame_order;
  const auto set_id = [](RomId& out, const std::string& id) {
    std::copy(id.begin(), id.end(), out.chars.begin());  // length checked above
  };
  for (int j = 0; j < d.mesh_count; ++j) set_id(d.mesh_ids[j], m.meshes[j].id);
  for (int j = 0; j < d.bearing_count; ++j) set_id(d.bearing_ids[j], m.bearings[j].id);
  for (int j = 0; j < d.sensor_count; ++j) set_id(d.sensor_ids[j], m.sensors[j].channel);
  for (int i = 0; i < total; ++i) {
    const double om2 = w2[i];
    const double om = std::sqrt(om2);
    // The model's modal damping (full_model.hpp) projected, φ_iᵀCφ_i: exact for the
    // retained modes (C is modal in the full model's modes), the diagonal of the
    // projection for the correction vectors' Ritz modes.
    const double c = std::max(0.0, phi_r.col(i).dot(m.damping() * phi_r.col(i)));
    d.omega_rad_s[i] = om;
    d.omega2[i] = om2;
    d.damping_1_s[i] = c;
    // State [q, v, f, ḟ]: q' = v, v' = −ω²q − c v + f, f' = ḟ, ḟ' = 0.
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    a(0, 1) = 1.0;
    a(1, 0) = -om2;
    a(1, 1) = -c;
    a(1, 2) = 1.0;
    a(2, 3) = 1.0;
    if (om * dt_s > kRomQuasiStaticOmegaDt) {
      // Too fast for the step: quasi-static, q = f/ω² at t_{n+1} (rom.hpp, "Stability").
      ++d.quasi_static_modes;
      d.b1q[i] = 1.0 / om2;
      continue;  // pqq, pqv, b0q, pvq, pvv, b0v, b1v stay 0
    }
    const Eigen::Matrix4d e = (a * dt_s).exp();
    d.pqq[i] = e(0, 0);
    d.pqv[i] = e(0, 1);
    d.b0q[i] = e(0, 2) - e(0, 3) / dt_s;
    d.b1q[i] = e(0, 3) / dt_s;
    d.pvq[i] = e(1, 0);
    d.pvv[i] = e(1, 1);
    d.b0v[i] = e(1, 2) - e(1, 3) / dt_s;
    d.b1v[i] = e(1, 3) / dt_s;
  }
  const auto modal = [&](const Eigen::VectorXd& x) {
    RomData::Vec out = RomData::Vec::Zero();
    out.head(total) = phi_r.transpose() * x;
    return out;
  };
  for (int j = 0; j < d.mesh_count; ++j) {
    const VaryingStiffness& v = m.meshes[j];
    d.w_mesh.col(j) = modal(v.directions.col(0));
    if (j == turning) {
      d.w_basis.col(j) = modal(v.directions.col(0) - v.rotation_cos.col(0));  // c
      d.w_basis.col(kRomMeshes) = modal(v.rotation_cos.col(0));               // a
      d.w_basis.col(kRomMeshes + 1) = modal(v.rotation_sin.col(0));           // b
    } else {
      d.w_basis.col(j) = d.w_mesh.col(j);
    }
  }
  // G over the basis, then its constant, cos ψ, sin ψ parts for the meshes' system.
  const Eigen::Matrix<double, kRomMeshBasis, kRomMeshBasis> g10 =
      d.w_basis.transpose() * d.b1q.asDiagonal() * d.w_basis;
  d.g_mesh = g10.topLeftCorner<kRomMeshes, kRomMeshes>();
  if (turning >= 0) {
    const int r = turning, ca = kRomMeshes, cb = kRomMeshes + 1;
    for (int j = 0; j < kRomMeshes; ++j) {
      if (j == r) continue;
      d.g_mesh_cos(j, r) = d.g_mesh_cos(r, j) = g10(j, ca);
      d.g_mesh_sin(j, r) = d.g_mesh_sin(r, j) = g10(j, cb);
    }
    // W_r(ψ)ᵀBW_r(ψ) = G_cc + 2cos ψ G_ca + 2 sin ψ G_cb + cos²ψ G_aa + sin²ψ G_bb + 2 sin ψ cos ψ
    // G_ab.
    d.g_mesh(r, r) = g10(r, r) + 0.5 * (g10(ca, ca) + g10(cb, cb));
    d.g_mesh_cos(r, r) = 2.0 * g10(r, ca);
    d.g_mesh_sin(r, r) = 2.0 * g10(r, cb);
    d.g_turning_2psi = {0.5 * (g10(ca, ca) - g10(cb, cb)), g10(ca, cb)};
    // The extra column W_r(0) = c + a.
    for (int j = 0; j < kRomMeshes; ++j) d.g_extra(j, 0) = g10(j, r) + g10(j, ca);
    d.g_extra(r, 0) = g10(r, r) + g10(r, ca);
    d.g_extra(r, 1) = g10(ca, r) + g10(ca, ca);
    d.g_extra(r, 2) = g10(cb, r) + g10(cb, ca);
    d.g_extra_self = g10(r, r) + 2.0 * g10(r, ca) + g10(ca, ca);
  }
  for (int j = 0; j < d.bearing_count; ++j) {
    d.w_bearing.col(2 * j) = modal(m.bearings[j].directions.col(0));
    d.w_bearing.col(2 * j + 1) = modal(m.bearings[j].directions.col(1));
    d.bearing_mean_n_m[j] = m.bearings[j].mean_n_m;
    d.bearing_carrier_frame[j] = m.bearings[j].carrier_frame_xy;
  }
  for (int j = 0; j < d.path_count; ++j) {
    d.w_path.col(j) = modal(m.paths[j].directions.col(0));
    d.path_mean_n_m[j] = m.paths[j].mean_n_m;
  }
  d.readout_by_dof.topRows<kRomMeshes>() = d.w_basis.leftCols<kRomMeshes>().transpose();
  d.readout_by_dof.middleRows<kRomBearingRank>(kRowBearings) = d.w_bearing.transpose();
  d.readout_by_dof.middleRows<2>(kRowTurning) = d.w_basis.rightCols<2>().transpose();
  d.readout_by_dof.middleRows<kRomPaths>(kRowPaths) = d.w_path.transpose();
  d.readout_correction = d.readout_by_dof * d.b1q.asDiagonal() * d.w_basis;
  for (int j = 0; j < d.sensor_count; ++j)
    d.sensor_rows.row(j) = modal(m.sensors[j].row).transpose();

  // ---- look-ups ---------------------------------------------------------------------------
  std::vector<LookupPlan> plan(static_cast<std::size_t>(kRomMeshes + kRomBearings + kRomPaths));
  for (int j = 0; j < d.mesh_count; ++j) {
    const VaryingStiffness& v = m.meshes[j];
    plan[j] = {v.order, v.phase_cycles, v.shape};
    d.mesh_mean_n_m[j] = v.mean_n_m;
  }
  for (int j = 0; j < d.bearing_count; ++j) {
    const VaryingStiffness& v = m.bearings[j];
    plan[kRomMeshes + j] = {v.order, v.phase_cycles, v.shape};
  }
  for (int j = 0; j < d.path_count; ++j) {
    const VaryingStiffness& v = m.paths[j];
    plan[kRomMeshes + kRomBearings + j] = {v.order, v.phase_cycles, v.shape};
  }
  // Factors of one order share a look-up (their product as one table); a constant factor
  // (order 0) folds into the consumer's scale.
  auto add_lookup = [&](const std::vector<const Modulation*>& factors, double& scale) -> int {
    std::vector<const Modulation*> varying;
    for (const Modulation* f : factors) {
      if (f->order == 0.0) {
        scale *= f->value(0.0);
      } else {
        varying.push_back(f);
      }
    }
    if (varying.empty()) return kLookupOne;
    for (const Modulation* f : varying) {
      if (f->order != varying.front()->order) return -1;  // two orders: more than one table
    }
    if (varying.size() == 1) {
      plan.push_back(
          {varying.front()->order, varying.front()->phase_cycles, varying.front()->table});
    } else {
      plan.push_back({varying.front()->order, 0.0, product_table(varying)});
    }
    return static_cast<int>(plan.size()) - 1;
  };
  for (int j = 0; j < kRomMeshes; ++j) {
    d.mesh_shape[j] = j;
    d.mesh_modulation[j] = kLookupOne;
    d.mesh_error0[j] = d.mesh_error1[j] = kLookupZero;
  }
  for (int j = 0; j < d.mesh_count; ++j) {
    const VaryingStiffness& v = m.meshes[j];
    std::vector<const Modulation*> mods;
    for (const Modulation& mo : v.modulations) mods.push_back(&mo);
    double scale = 1.0;
    const int mi = add_lookup(mods, scale);
    if (mi < 0) {
      fail(error, "rom: mesh '" + v.id +
                      "': modulations of more than one order (two gears' "
                      "effects on one mesh); the ROM takes one");
      return nullptr;
    }
    d.mesh_modulation[j] = mi;
    d.mesh_mean_n_m[j] *= scale;
    // Transmission errors: one look-up per order, amplitude in the table, at most two orders.
    // A constant one (order 0: a planet pin's position error) joins the first order's table.
    std::vector<std::pair<double, std::vector<const MeshExcitation*>>> by_order;
    double constant_m = 0.0;
    bool has_constant = false;
    for (const MeshExcitation& x : v.excitations) {
      if (x.pattern.order == 0.0) {
        constant_m += x.amplitude_m * x.pattern.table.value(x.pattern.phase_cycles);
        has_constant = true;
        continue;
      }
      auto it = std::find_if(by_order.begin(), by_order.end(),
                             [&](const auto& g) { return g.first == x.pattern.order; });
      if (it == by_order.end()) {
        by_order.push_back({x.pattern.order, {&x}});
      } else {
        it->second.push_back(&x);
      }
    }
    if (has_constant && by_order.empty()) by_order.push_back({0.0, {}});
    if (by_order.size() > 2) {
      fail(error, "rom: mesh '" + v.id + "': transmission errors of more than two orders");
      return nullptr;
    }
    for (std::size_t g = 0; g < by_order.size(); ++g) {
      PeriodicTable t = PeriodicTable::constant(g == 0 ? constant_m : 0.0);
      for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
        const double x = static_cast<double>(i) / PeriodicTable::kSize;
        for (const MeshExcitation* e : by_order[g].second)
          t.values[i] += e->amplitude_m * e->pattern.table.value(x + e->pattern.phase_cycles);
      }
      plan.push_back({by_order[g].first, 0.0, t});
      (g == 0 ? d.mesh_error0 : d.mesh_error1)[j] = static_cast<int>(plan.size()) - 1;
      d.excitation = true;
    }
  }
  for (int j = 0; j < d.force_count; ++j) {
    const ForceTerm& f = m.forces[j];
    d.w_force.col(j) = modal(f.pattern);
    double scale = f.amplitude;
    const Modulation primary{f.shape, f.order, f.phase_cycles};
    const int i0 = add_lookup({&primary}, scale);
    std::vector<const Modulation*> mods;
    for (const Modulation& mo : f.modulations) mods.push_back(&mo);
    const int i1 = add_lookup(mods, scale);
    if (i1 < 0) {
      fail(error, "rom: force '" + f.id + "': modulations of more than one order");
      return nullptr;
    }
    d.force_index0[j] = i0;
    d.force_index1[j] = i1;
    d.force_scale[j] = f.per_newton_metre || f.per_rotor_hz_squared ? 0.0 : scale;
    d.force_per_nm[j] = f.per_newton_metre ? scale : 0.0;
    d.force_per_hz2[j] = f.per_rotor_hz_squared ? scale : 0.0;
    if (f.per_newton_metre && f.per_rotor_hz_squared) {
      fail(error,
           "rom: force '" + f.id + "': an amplitude both per N·m and per Hz² is not supported");
      return nullptr;
    }
    for (int k = 0; k < 3; ++k) d.force_frame[3 * j + k] = f.frame[k];
  }
  if (plan.size() > static_cast<std::size_t>(kRomLookups)) {
    fail(error, "rom: " + std::to_string(plan.size()) +
                    " table look-ups exceed the capacity kRomLookups = " +
                    std::to_string(kRomLookups) + " (too many effects at once)");
    return nullptr;
  }
  d.lookups = static_cast<int>((plan.size() + 7) / 8 * 8);
  for (int t = 0; t < d.lookups; ++t) {
    const LookupPlan p = t < static_cast<int>(plan.size()) ? plan[t] : LookupPlan{};
    d.term_order[t] = p.order;
    d.term_phase_cycles[t] = p.phase;
    std::copy(p.table.values.begin(), p.table.values.end(),
              d.term_values.begin() + t * static_cast<int>(PeriodicTable::kSize));
  }

  // Explicit bearing and path fluctuation: each mode's share of the fluctuating stiffness
  // must stay below its own stiffness — the exact bound for a quasi-static mode, q⁺ = −δq/ω²
  // (rom.hpp, "Stability"); the step is the reason the fast modes are quasi-static.
  const auto swing = [&](int t, double mean) {
    const double* table = d.term_values.data() + t * static_cast<int>(PeriodicTable::kSize);
    double worst = 0.0;
    for (std::size_t i = 0; i < PeriodicTable::kSize; ++i)
      worst = std::max(worst, std::abs(table[i] - 1.0));
    return worst * mean;
  };
  for (int i = 0; i < total; ++i) {
    double share = 0.0;
    for (int j = 0; j < d.bearing_count; ++j) {
      share += swing(kRomMeshes + j, d.bearing_mean_n_m[j]) *
               (d.w_bearing(i, 2 * j) * d.w_bearing(i, 2 * j) +
                d.w_bearing(i, 2 * j + 1) * d.w_bearing(i, 2 * j + 1));
    }
    for (int j = 0; j < d.path_count; ++j)
      share += swing(kRomMeshes + kRomBearings + j, d.path_mean_n_m[j]) * d.w_path(i, j) *
               d.w_path(i, j);
    if (share >= d.omega2[i]) {
      fail(error, "rom: bearing or path stiffness fluctuation exceeds the stiffness of ROM mode " +
                      std::to_string(i) + " (explicit terms would be unstable)");
      return nullptr;
    }
  }
  if (report) {
    report->full_mode_hz.clear();
    for (Eigen::Index i = 0; i < lambda.size(); ++i)
      report->full_mode_hz.push_back(std::sqrt(lambda[i]) / (2.0 * std::numbers::pi));
    report->rom_mode_hz.clear();
    for (int i = 0; i < total; ++i)
      report->rom_mode_hz.push_back(d.omega_rad_s[i] / (2.0 * std::numbers::pi));
    report->eigenmodes = keep;
    report->correction_vectors = n_corr;
  }
  return data;
}

Rom::Rom(const RomData& data) noexcept : data_(&data) { bind_kernel(); }

Rom::Rom(const Rom& other) noexcept : data_(other.data_) { *this = other; }

Rom& Rom::operator=(const Rom& other) noexcept {
  if (this == &other) return *this;
  data_ = other.data_;
  q_ = other.q_;
  v_ = other.v_;
  g_ = other.g_;
  z_ = other.z_;
  t0_ = other.t0_;
  steps_ = other.steps_;
  whole_revs_ = other.whole_revs_;
  frac_revs_ = other.frac_revs_;
  phase_base_ = other.phase_base_;
  cos_psi_ = other.cos_psi_;
  sin_psi_ = other.sin_psi_;
  psi_base_ = other.psi_base_;
  steps_since_exact_ = other.steps_since_exact_;
  bind_kernel();
  return *this;
}

void Rom::bind_kernel() noexcept {
  const RomData& d = *data_;
  kernel_ = detail::RomKernelModel{d.dofs,
                                   d.lookups,
                                   d.force_count,
                                   d.path_count,
                                   d.turning_mesh,
                                   d.excitation,
                                   d.pqq.data(),
                                   d.pqv.data(),
                                   d.b0q.data(),
                                   d.b1q.data(),
                                   d.pvq.data(),
                                   d.pvv.data(),
                                   d.b0v.data(),
                                   d.b1v.data(),
                                   d.damping_1_s.data(),
                                   d.omega2.data(),
                                   d.w_force.data(),
                                   d.w_bearing.data(),
                                   d.w_path.data(),
                                   d.w_basis.data(),
                                   d.readout_by_dof.data(),
                                   d.g_mesh.data(),
                                   d.g_mesh_cos.data(),
                                   d.g_mesh_sin.data(),
                                   d.g_turning_2psi.data(),
                                   d.g_extra.data(),
                                   d.g_extra_self,
                                   d.readout_correction.data(),
                                   d.sensor_rows.data(),
                                   d.term_order.data(),
                                   phase_base_.data(),
                                   d.term_values.data(),
                                   d.mesh_mean_n_m.data(),
                                   d.mesh_shape.data(),
                                   d.mesh_modulation.data(),
                                   d.mesh_error0.data(),
                                   d.mesh_error1.data(),
                                   d.bearing_mean_n_m.data(),
                                   d.path_mean_n_m.data(),
                                   d.force_scale.data(),
                                   d.force_per_nm.data(),
                                   d.force_per_hz2.data(),
                                   d.force_index0.data(),
                                   d.force_index1.data(),
                                   d.force_frame.data()};
}

namespace {
// frac(order·whole) without the rounding of the product: whole is exact in a double
// (|whole| < 2^53), p + e = order·whole exactly (fma), and p − floor(p) is exact.
double frac_of_product(double order, std::int64_t whole) noexcept {
  const auto w = static_cast<double>(whole);
  const double p = order * w;
  const double e = std::fma(order, w, -p);
  double f = (p - std::floor(p)) + e;
  f -= std::floor(f);
  return f;
}
double wrap_cycles(double x) noexcept { return x - std::floor(x); }
}  // namespace

void Rom::adopt(const RomData& next, const RomInputs& in) noexcept {
  const double t = time_s();  // the old model's step
  data_ = &next;
  bind_kernel();
  reset_at(in, whole_revs_, frac_revs_, t, 0);
}

void Rom::reset(const RomInputs& in, double rotor_revolutions, double time_s) noexcept {
  const double whole = std::floor(rotor_revolutions);
  reset_at(in, static_cast<std::int64_t>(whole), rotor_revolutions - whole, time_s, 0);
}

void Rom::reset(const RomInputs& in, const Rom& at) noexcept {
  reset_at(in, at.whole_revs_, at.frac_revs_, at.time_s(), 0);
}

void Rom::set_angle(std::int64_t whole, double fraction) noexcept {
  if (!std::isfinite(fraction)) fraction = 0.0;  // a non-finite speed: keep the whole count
  const double carry = std::floor(fraction);
  whole_revs_ = whole + static_cast<std::int64_t>(carry);
  frac_revs_ = fraction - carry;
  if (frac_revs_ >= 1.0) {  // fraction just below an integer rounded up
    frac_revs_ = 0.0;
    ++whole_revs_;
  }
  const RomData& d = *data_;
  for (int t = 0; t < kRomLookups; ++t)
    phase_base_[t] = wrap_cycles(frac_of_product(d.term_order[t], whole_revs_) +
                                 wrap_cycles(d.term_phase_cycles[t]));
  psi_base_ = frac_of_product(d.frame_order, whole_revs_);
  const double psi = 2.0 * std::numbers::pi * wrap_cycles(psi_base_ + d.frame_order * frac_revs_);
  cos_psi_ = std::cos(psi);
  sin_psi_ = std::sin(psi);
  steps_since_exact_ = 0;
}

void Rom::reset_at(const RomInputs& in, std::int64_t whole, double fraction, double t0,
                   std::int64_t steps) noexcept {
  const RomData& d = *data_;
  t0_ = t0;
  steps_ = steps;
  set_angle(whole, fraction);
  const double cpsi = cos_psi_, spsi = sin_psi_;
  const double hz = in.rotor_speed_rpm / 60.0;
  const int r = d.turning_mesh;
  // Value of look-up t at the current angle (RomData::lookup's arithmetic on the split angle).
  const auto now = [&](int t) {
    if (t == kLookupOne) return 1.0;
    if (t == kLookupZero || t < 0 || t >= d.lookups) return 0.0;
    const double x = d.term_order[t] * frac_revs_ + phase_base_[t];
    const double pos = (x - std::floor(x)) * static_cast<double>(PeriodicTable::kSize);
    const int i = std::min(static_cast<int>(pos), static_cast<int>(PeriodicTable::kSize) - 1);
    const double w = pos - i;
    const double* table = d.term_values.data() + t * static_cast<int>(PeriodicTable::kSize);
    return table[i] + w * (table[(i + 1) % static_cast<int>(PeriodicTable::kSize)] - table[i]);
  };
  // Mean of a look-up over time (its table's mean; a constant's value).
  const auto mean_of = [&](int t) {
    if (t == kLookupOne) return 1.0;
    if (t == kLookupZero || t < 0 || t >= d.lookups) return 0.0;
    if (d.term_order[t] == 0.0) return now(t);
    double s = 0.0;
    for (std::size_t i = 0; i < PeriodicTable::kSize; ++i)
      s += d.term_values[static_cast<std::size_t>(t) * PeriodicTable::kSize + i];
    return s / PeriodicTable::kSize;
  };
  // Static equilibrium under the mean stiffness at this carrier angle and the mean forces:
  // (Λ + k̄_r[W_r(ψ)W_r(ψ)ᵀ − W_r(0)W_r(0)ᵀ]) q = Φᵀf̄ + Σ W_j k̄_j ē_j, by Woodbury (rank 2).
  RomData::Vec f = RomData::Vec::Zero();
  RomData::Vec f_now = RomData::Vec::Zero();
  for (int j = 0; j < d.force_count; ++j) {
    const double a =
        d.force_scale[j] + d.force_per_nm[j] * in.input_torque_nm + d.force_per_hz2[j] * hz * hz;
    const double* fr = d.force_frame.data() + 3 * j;
    f.noalias() +=
        (a * mean_of(d.force_index0[j]) * mean_of(d.force_index1[j]) * fr[0]) * d.w_force.col(j);
    f_now.noalias() += (a * now(d.force_index0[j]) * now(d.force_index1[j]) *
                        (fr[0] + fr[1] * cpsi + fr[2] * spsi)) *
                       d.w_force.col(j);
  }
  RomData::Vec w_r = RomData::Vec::Zero(), w_0 = RomData::Vec::Zero();
  if (r >= 0) {
    w_0 = d.w_mesh.col(r);
    w_r =
        d.w_basis.col(r) + cpsi * d.w_basis.col(kRomMeshes) + spsi * d.w_basis.col(kRomMeshes + 1);
  }
  for (int j = 0; j < d.mesh_count; ++j) {
    const double e = mean_of(d.mesh_error0[j]) + mean_of(d.mesh_error1[j]);
    if (e != 0.0)
      f.noalias() += (d.mesh_mean_n_m[j] * e) * (j == r ? w_r : RomData::Vec(d.w_basis.col(j)));
  }
  RomData::Vec inv_l = RomData::Vec::Zero();
  for (int i = 0; i < kRomDofs; ++i) inv_l[i] = d.omega2[i] > 0.0 ? 1.0 / d.omega2[i] : 0.0;
  q_ = inv_l.cwiseProduct(f);
  if (r >= 0) {
    // (Λ + U D Uᵀ)⁻¹f = Λ⁻¹f − Λ⁻¹U (D⁻¹ + UᵀΛ⁻¹U)⁻¹ UᵀΛ⁻¹f, U = [W_r(ψ), W_r(0)], D = k̄(1, −1).
    const double k = d.mesh_mean_n_m[r];
    const RomData::Vec lu0 = inv_l.cwiseProduct(w_r), lu1 = inv_l.cwiseProduct(w_0);
    Eigen::Matrix2d s;
    s << 1.0 / k + w_r.dot(lu0), w_r.dot(lu1), w_0.dot(lu0), -1.0 / k + w_0.dot(lu1);
    const Eigen::Vector2d rhs(w_r.dot(q_), w_0.dot(q_));
    const Eigen::Vector2d c = s.inverse() * rhs;
    q_ -= lu0 * c[0] + lu1 * c[1];
  }
  v_.setZero();
  // The modal force now, with the actual (not mean) stiffness at this rotor angle.
  for (int k = 0; k < kRomReadoutRows; ++k) z_[k] = d.readout_by_dof.row(k).dot(q_);
  g_ = f_now;
  for (int j = 0; j < d.bearing_count; ++j) {
    const double dk = d.bearing_mean_n_m[j] * (now(kRomMeshes + j) - 1.0);
    g_.noalias() -= (dk * z_[kRowBearings + 2 * j]) * d.w_bearing.col(2 * j);
    g_.noalias() -= (dk * z_[kRowBearings + 2 * j + 1]) * d.w_bearing.col(2 * j + 1);
  }
  for (int j = 0; j < d.path_count; ++j) {
    const double dk = d.path_mean_n_m[j] * (now(kRomMeshes + kRomBearings + j) - 1.0);
    g_.noalias() -= (dk * z_[kRowPaths + j]) * d.w_path.col(j);
  }
  for (int j = 0; j < d.mesh_count; ++j) {
    const double k = d.mesh_mean_n_m[j] * now(d.mesh_shape[j]) * now(d.mesh_modulation[j]);
    const double e = now(d.mesh_error0[j]) + now(d.mesh_error1[j]);
    if (j == r) {
      // k(z(ψ) − e) along W_r(ψ), less the diagonal's k̄ z(0) along W_r(0).
      const double z_psi = w_r.dot(q_), z_0 = w_0.dot(q_);
      g_.noalias() -= (k * (z_psi - e)) * w_r;
      g_.noalias() += (d.mesh_mean_n_m[j] * z_0) * w_0;
    } else {
      g_.noalias() -= ((k - d.mesh_mean_n_m[j]) * z_[j] - k * e) * d.w_basis.col(j);
    }
  }
}

void Rom::step(const RomInputs& in, RomOutputs& out) noexcept {
  const RomData& d = *data_;
  // The angle within the current revolution (may pass 1 in this step; the phases stay
  // continuous: order·(f − 1) + frac(order·(w + 1)) = order·f + frac(order·w) mod 1).
  const double revs_next = frac_revs_ + in.rotor_speed_rpm * (1.0 / 60.0) * d.dt_s;
  // The carrier angle's cosine and sine, turned by this step's small angle (Taylor terms to
  // Δψ⁴, Δψ ≤ 1e-4 rad: exact to rounding) and recomputed exactly every 4096 steps and at
  // every revolution (set_angle).
  if (d.frame_order != 0.0) {
    if (++steps_since_exact_ >= 4096) {
      const double psi =
          2.0 * std::numbers::pi * wrap_cycles(psi_base_ + d.frame_order * revs_next);
      cos_psi_ = std::cos(psi);
      sin_psi_ = std::sin(psi);
      steps_since_exact_ = 0;
    } else {
      const double dpsi = 2.0 * std::numbers::pi * d.frame_order * (revs_next - frac_revs_);
      const double d2 = dpsi * dpsi;
      const double cd = 1.0 - 0.5 * d2 * (1.0 - d2 * (1.0 / 12.0));
      const double sd = dpsi * (1.0 - d2 * (1.0 / 6.0));
      const double c = cos_psi_ * cd - sin_psi_ * sd;
      sin_psi_ = sin_psi_ * cd + cos_psi_ * sd;
      cos_psi_ = c;
    }
  }
  const double cpsi = cos_psi_, spsi = sin_psi_;

  // Look-ups, predictor, Woodbury mesh solve, corrector, read-outs (rom_kernel.cpp).
  const detail::RomKernelInputs kin{revs_next, in.input_torque_nm, in.rotor_speed_rpm / 60.0, cpsi,
                                    spsi};
  const detail::RomKernelState state{q_.data(), v_.data(), g_.data(), z_.data()};
  const detail::RomKernelOutputs outputs{out.mesh_force_n.data(), out.bearing_force_x_n.data(),
                                         out.bearing_force_y_n.data(),
                                         out.acceleration_m_s2.data()};
  detail::rom_step_kernel(kernel_, kin, state, outputs);
  // Bearings described in the carrier's axes: their forces turned into the housing's.
  for (int j = 0; j < d.bearing_count; ++j) {
    if (!d.bearing_carrier_frame[j]) continue;
    const double fx = out.bearing_force_x_n[j], fy = out.bearing_force_y_n[j];
    out.bearing_force_x_n[j] = fx * cpsi - fy * spsi;
    out.bearing_force_y_n[j] = fx * spsi + fy * cpsi;
  }
  ++steps_;
  if (revs_next >= 0.0 && revs_next < 1.0) {
    frac_revs_ = revs_next;
  } else {
    set_angle(whole_revs_, revs_next);  // a revolution completed (or reversed): once per rev
  }
}

double rom_settle_time_s(const RomData& d, double fraction) noexcept {
  if (!(fraction > 0.0 && fraction < 1.0)) return 0.0;
  double slowest = 0.0;  // [1/s] smallest decay rate of an active mode
  bool any = false;
  for (int i = 0; i < kRomDofs; ++i) {
    const double w2 = d.omega2[i], c = d.damping_1_s[i];
    if (!(w2 > 0.0)) continue;
    // Roots of s² + c s + ω² = 0: underdamped → Re = −c/2; overdamped → the slow root.
    const double disc = c * c - 4.0 * w2;
    const double rate = disc <= 0.0 ? 0.5 * c : 0.5 * (c - std::sqrt(disc));
    if (!any || rate < slowest) slowest = rate;
    any = true;
  }
  if (!any || !(slowest > 0.0)) return 0.0;
  return std::log(1.0 / fraction) / slowest;
}

std::unique_ptr<RomData> build_rom(const Drivetrain& drivetrain,
                                   const DynamicsParameters& parameters,
                                   const RomSettings& settings, std::string* error,
                                   RomBuildReport* report) {
  Drivetrain d = drivetrain;
  d.dynamics = parameters;
  const std::optional<FullModel> m = build_full_model(d, settings.structure, error);
  if (!m) return nullptr;
  return build_rom(*m, settings.dt_s, settings.cutoff_hz, error, report);
}

const char* rom_step_isa() noexcept { return detail::rom_step_kernel_isa(); }

}  // namespace model::dynamics
