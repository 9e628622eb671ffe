#include "model/dynamics/rom.hpp"

#include "rom_kernel.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace model::dynamics {

static_assert(detail::kKernelDofs == kRomDofs && detail::kKernelMeshes == kRomMeshes &&
                  detail::kKernelBearings == kRomBearings &&
                  detail::kKernelBearingRank == kRomBearingRank &&
                  detail::kKernelForces == kRomForces && detail::kKernelSensors == kRomSensors &&
                  detail::kKernelReadoutRows == kRomReadoutRows &&
                  detail::kKernelTerms == kRomTerms &&
                  detail::kKernelTableSize == static_cast<int>(PeriodicTable::kSize),
              "rom_kernel.hpp's capacities must equal rom.hpp's");
static_assert(kRomSensors == 2, "RomOutputs::acceleration_m_s2 is filled by the kernel");

namespace {

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

RomStiffnessTerm to_rom(const VaryingStiffness& v) {
  return {v.mean_n_m, v.order, v.phase_cycles, v.shape, v.transmission_error};
}

}  // namespace

std::unique_ptr<RomData> build_rom(const FullModel& m, double dt_s, double cutoff_hz,
                                   std::string* error, RomBuildReport* report) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s) || !(cutoff_hz > 0.0) || !std::isfinite(cutoff_hz)) {
    fail(error, "rom: time step and cut-off frequency must be finite and > 0");
    return nullptr;
  }
  if (m.meshes.size() > static_cast<std::size_t>(kRomMeshes) ||
      m.bearings.size() > static_cast<std::size_t>(kRomBearings) ||
      m.forces.size() > static_cast<std::size_t>(kRomForces) ||
      m.sensors.size() > static_cast<std::size_t>(kRomSensors)) {
    fail(error,
         "rom: the model has more meshes, bearings, forces or sensors than the ROM's capacity (" +
             std::to_string(kRomMeshes) + ", " + std::to_string(kRomBearings) + ", " +
             std::to_string(kRomForces) + ", " + std::to_string(kRomSensors) + ")");
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
    if (b.directions.cols() != 2) {
      fail(error, "rom: bearing '" + b.id + "' must have rank 2 (x, y)");
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

  // Static correction vectors: input torque and each mesh direction.
  std::vector<Eigen::VectorXd> loads;
  for (const auto& f : m.forces) loads.push_back(f.pattern);
  for (const auto& v : m.meshes) loads.push_back(v.directions.col(0));
  const Eigen::LLT<Eigen::MatrixXd> k_llt(m.stiffness);
  // Bearings: their fluctuation acts as Δk_b(t)·(static deflection), a force along the
  // bearing's static load direction (proportional to the torque, so one vector each).
  Eigen::VectorXd unit_torque = Eigen::VectorXd::Zero(n);
  for (const auto& f : m.forces) {
    if (f.per_newton_metre) unit_torque += f.amplitude * f.pattern;
  }
  if (unit_torque.squaredNorm() > 0.0) {
    const Eigen::VectorXd x1 = k_llt.solve(unit_torque);
    for (const auto& b : m.bearings)
      loads.push_back(b.directions * (b.directions.transpose() * x1));
  }
  // Unit load vectors: the threshold below compares their residuals with each other.
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
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> red(0.5 * (k_red + k_red.transpose()));
  const Eigen::MatrixXd phi_r = basis * red.eigenvectors();
  const Eigen::VectorXd& w2 = red.eigenvalues();

  auto data = std::make_unique<RomData>();
  RomData& d = *data;
  d.dt_s = dt_s;
  d.cutoff_hz = cutoff_hz;
  d.eigenmodes = keep;
  d.correction_vectors = n_corr;
  d.mesh_count = static_cast<int>(m.meshes.size());
  d.bearing_count = static_cast<int>(m.bearings.size());
  d.force_count = static_cast<int>(m.forces.size());
  d.sensor_count = static_cast<int>(m.sensors.size());
  const auto set_id = [](RomId& out, const std::string& id) {
    std::copy(id.begin(), id.end(), out.chars.begin());  // length checked above
  };
  for (int j = 0; j < d.mesh_count; ++j) set_id(d.mesh_ids[j], m.meshes[j].id);
  for (int j = 0; j < d.bearing_count; ++j) set_id(d.bearing_ids[j], m.bearings[j].id);
  for (int j = 0; j < d.sensor_count; ++j) set_id(d.sensor_ids[j], m.sensors[j].channel);
  // Modal damping φ_iᵀCφ_i: exact for the retained modes (C is modal in the full model's
  // modes), the diagonal of the projection for the correction vectors' Ritz modes.
  const Eigen::VectorXd c_modal =
      (phi_r.transpose() * m.damping() * phi_r).diagonal().cwiseMax(0.0);
  for (int i = 0; i < total; ++i) {
    const double om2 = w2[i];
    const double om = std::sqrt(om2);
    const double c = c_modal[i];
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
  for (int j = 0; j < d.mesh_count; ++j) {
    d.w_mesh.col(j).head(total) = phi_r.transpose() * m.meshes[j].directions.col(0);
    d.meshes[j] = to_rom(m.meshes[j]);
  }
  d.g_mesh = d.w_mesh.transpose() * d.b1q.asDiagonal() * d.w_mesh;
  for (int j = 0; j < d.bearing_count; ++j) {
    d.w_bearing.col(2 * j).head(total) = phi_r.transpose() * m.bearings[j].directions.col(0);
    d.w_bearing.col(2 * j + 1).head(total) = phi_r.transpose() * m.bearings[j].directions.col(1);
    d.bearings[j] = to_rom(m.bearings[j]);
  }
  d.readout.topRows(kRomMeshes) = d.w_mesh.transpose();
  d.readout.bottomRows(kRomBearingRank) = d.w_bearing.transpose();
  d.readout_by_dof.topRows(kRomMeshes + kRomBearingRank) = d.readout;
  d.h_bearing_mesh = d.w_bearing.transpose() * d.b1q.asDiagonal() * d.w_mesh;
  d.readout_correction.topRows(kRomMeshes) = d.g_mesh;
  d.readout_correction.middleRows(kRomMeshes, kRomBearingRank) = d.h_bearing_mesh;
  for (int j = 0; j < d.force_count; ++j) {
    const ForceTerm& f = m.forces[j];
    d.w_force.col(j).head(total) = phi_r.transpose() * f.pattern;
    d.forces[j] = {f.per_newton_metre, f.amplitude, f.order, f.phase_cycles, f.shape};
  }
  for (int j = 0; j < d.sensor_count; ++j) {
    d.sensor_rows.row(j).head(total) = (phi_r.transpose() * m.sensors[j].row).transpose();
  }
  // The look-up layout of the same terms (unused slots too: inert, scale 0).
  const auto set_term = [&d](int t, double order, double phase_cycles, double scale,
                             double scale_per_nm, const PeriodicTable& shape) {
    d.term_order[t] = order;
    d.term_phase_cycles[t] = phase_cycles;
    d.term_scale[t] = scale;
    d.term_scale_per_nm[t] = scale_per_nm;
    std::copy(shape.values.begin(), shape.values.end(),
              d.term_values.begin() + t * static_cast<int>(PeriodicTable::kSize));
  };
  for (int j = 0; j < kRomMeshes; ++j) {
    const RomStiffnessTerm& t = d.meshes[j];
    set_term(j, t.order, t.phase_cycles, t.mean_n_m, 0.0, t.shape);
  }
  for (int j = 0; j < kRomBearings; ++j) {
    const RomStiffnessTerm& t = d.bearings[j];
    set_term(kRomMeshes + j, t.order, t.phase_cycles, t.mean_n_m, 0.0, t.shape);
  }
  for (int j = 0; j < kRomForces; ++j) {
    const RomForceTerm& f = d.forces[j];
    set_term(kRomMeshes + kRomBearings + j, f.order, f.phase_cycles,
             f.per_newton_metre ? 0.0 : f.amplitude, f.per_newton_metre ? f.amplitude : 0.0,
             f.shape);
  }
  for (int j = 0; j < kRomMeshes; ++j) {
    const RomStiffnessTerm& t = d.meshes[j];
    set_term(kRomMeshes + kRomBearings + kRomForces + j, t.order, t.phase_cycles, 1.0, 0.0,
             t.transmission_error);
  }
  // Explicit bearing fluctuation: each mode's share of the fluctuating stiffness must stay
  // below its own stiffness (see the stability note in rom.hpp).
  for (int i = 0; i < total; ++i) {
    double share = 0.0;
    for (int j = 0; j < d.bearing_count; ++j) {
      const double amp =
          (*std::max_element(d.bearings[j].shape.values.begin(), d.bearings[j].shape.values.end()) -
           1.0) *
          d.bearings[j].mean_n_m;
      share += amp * (d.w_bearing(i, 2 * j) * d.w_bearing(i, 2 * j) +
                      d.w_bearing(i, 2 * j + 1) * d.w_bearing(i, 2 * j + 1));
    }
    if (share >= d.omega2[i]) {
      fail(error, "rom: bearing stiffness fluctuation exceeds the stiffness of ROM mode " +
                      std::to_string(i) + " (explicit bearing terms would be unstable)");
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

Rom::Rom(const RomData& data) noexcept : data_(&data) {}

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
  for (int t = 0; t < kRomTerms; ++t)
    phase_base_[t] = wrap_cycles(frac_of_product(d.term_order[t], whole_revs_) +
                                 wrap_cycles(d.term_phase_cycles[t]));
}

void Rom::reset_at(const RomInputs& in, std::int64_t whole, double fraction, double t0,
                   std::int64_t steps) noexcept {
  const RomData& d = *data_;
  t0_ = t0;
  steps_ = steps;
  set_angle(whole, fraction);
  // Phase of term t at the current angle [cycles] (unwrapped: value() wraps).
  const auto phase = [this](int t, double order) { return order * frac_revs_ + phase_base_[t]; };
  constexpr int kFirstBearingTerm = kRomMeshes;
  constexpr int kFirstForceTerm = kRomMeshes + kRomBearings;
  // Static equilibrium under the mean stiffness and the mean force: ω² q = Φᵀ f̄.
  RomData::Vec f = RomData::Vec::Zero();
  RomData::Vec f_now = RomData::Vec::Zero();  // the force at this angle
  for (int j = 0; j < d.force_count; ++j) {
    const RomForceTerm& ft = d.forces[j];
    const double a = ft.per_newton_metre ? ft.amplitude * in.input_torque_nm : ft.amplitude;
    f.noalias() += (a * ft.shape.mean()) * d.w_force.col(j);
    f_now.noalias() +=
        (a * ft.shape.value(phase(kFirstForceTerm + j, ft.order))) * d.w_force.col(j);
  }
  for (int i = 0; i < kRomDofs; ++i) q_[i] = d.omega2[i] > 0.0 ? f[i] / d.omega2[i] : 0.0;
  v_.setZero();
  // Modal force now with the actual (not mean) stiffness at this rotor angle.
  z_bearing_.noalias() = d.w_bearing.transpose() * q_;
  z_mesh_.noalias() = d.w_mesh.transpose() * q_;
  Eigen::Matrix<double, kRomBearingRank, 1> fb;
  for (int j = 0; j < kRomBearings; ++j) {
    const RomStiffnessTerm& b = d.bearings[j];
    const double dk = b.mean_n_m * (b.shape.value(phase(kFirstBearingTerm + j, b.order)) - 1.0);
    fb[2 * j] = dk * z_bearing_[2 * j];
    fb[2 * j + 1] = dk * z_bearing_[2 * j + 1];
  }
  // Mesh terms at this angle: −Δk·δ + k·e (the transmission-error force).
  Eigen::Matrix<double, kRomMeshes, 1> fm;
  for (int j = 0; j < kRomMeshes; ++j) {
    const RomStiffnessTerm& mt = d.meshes[j];
    const double x = phase(j, mt.order);
    const double k = mt.mean_n_m * mt.shape.value(x);
    fm[j] = (k - mt.mean_n_m) * z_mesh_[j] - k * mt.transmission_error.value(x);
  }
  g_ = f_now;
  g_.noalias() -= d.w_bearing * fb;
  g_.noalias() -= d.w_mesh * fm;
}

void Rom::step(const RomInputs& in, RomOutputs& out) noexcept {
  const RomData& d = *data_;
  // The angle within the current revolution (may pass 1 in this step; the phases stay
  // continuous: order·(f − 1) + frac(order·(w + 1)) = order·f + frac(order·w) mod 1).
  const double revs_next = frac_revs_ + in.rotor_speed_rpm * (1.0 / 60.0) * d.dt_s;

  // Look-ups, predictor, Woodbury mesh solve, corrector, read-outs (rom_kernel.cpp).
  const detail::RomKernelModel model{d.pqq.data(),
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
                                     d.w_mesh.data(),
                                     d.readout_by_dof.data(),
                                     d.g_mesh.data(),
                                     d.readout_correction.data(),
                                     d.sensor_rows.data(),
                                     d.term_order.data(),
                                     phase_base_.data(),
                                     d.term_scale.data(),
                                     d.term_scale_per_nm.data(),
                                     d.term_values.data()};
  const detail::RomKernelState state{q_.data(), v_.data(), g_.data(), z_bearing_.data(),
                                     z_mesh_.data()};
  const detail::RomKernelOutputs outputs{out.mesh_force_n.data(), out.bearing_force_x_n.data(),
                                         out.bearing_force_y_n.data(),
                                         out.acceleration_m_s2.data()};
  detail::rom_step_kernel(model, revs_next, in.input_torque_nm, state, outputs);
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
