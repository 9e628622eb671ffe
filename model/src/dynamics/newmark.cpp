#include "model/dynamics/newmark.hpp"
#include "model/dynamics/eigen_instances.hpp"

#include <cmath>
#include <numbers>

namespace model::dynamics {

NewmarkIntegrator::NewmarkIntegrator(const FullModel& model, double dt_s) : m_(model), dt_(dt_s) {
  const int n = m_.dofs();
  int rank = 0;
  for (const auto* list : {&m_.meshes, &m_.bearings, &m_.paths}) {
    for (const auto& v : *list) {
      Group g;
      g.element = &v;
      g.first = rank;
      g.turning = v.rotates();
      g.size = g.turning ? 3 * static_cast<int>(v.directions.cols())
                         : static_cast<int>(v.directions.cols());
      rank += g.size;
      groups_.push_back(g);
    }
  }
  u_.resize(n, rank);
  for (const Group& g : groups_) {
    const VaryingStiffness& v = *g.element;
    if (!g.turning) {
      for (int k = 0; k < g.size; ++k) u_.col(g.first + k) = v.directions.col(k);
    } else {
      // u(ψ) = (D − A) + cos ψ·A + sin ψ·B (rank-1 elements only turn).
      u_.col(g.first) = v.directions.col(0) - v.rotation_cos.col(0);
      u_.col(g.first + 1) = v.rotation_cos.col(0);
      u_.col(g.first + 2) = v.rotation_sin.col(0);
    }
  }
  c_ = m_.damping();
  Eigen::MatrixXd s = (0.25 * dt_ * dt_) * m_.stiffness + (0.5 * dt_) * c_;
  s.diagonal() += m_.mass;
  s_bar_.compute(s);
  z_ = s_bar_.solve(u_);
  g_ = u_.transpose() * z_;
  dk_ = Eigen::MatrixXd::Zero(rank, rank);
  small_.resize(rank, rank);
  x_ = v_ = a_ = rhs_ = tmp_ = Eigen::VectorXd::Zero(n);
}

void NewmarkIntegrator::fill_delta_k(double revs) {
  const double psi = m_.carrier_angle_rad(revs);
  for (const Group& g : groups_) {
    const VaryingStiffness& v = *g.element;
    const double k = v.stiffness_n_m(revs);
    if (!g.turning) {
      for (int c = 0; c < g.size; ++c) dk_(g.first + c, g.first + c) = k - v.mean_n_m;
    } else {
      const double w[3] = {1.0, std::cos(psi), std::sin(psi)};
      const double w0[3] = {1.0, 1.0, 0.0};
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
          dk_(g.first + i, g.first + j) = k * w[i] * w[j] - v.mean_n_m * w0[i] * w0[j];
      }
    }
  }
}

void NewmarkIntegrator::add_forces(double revs, const Eigen::VectorXd& x,
                                   const Eigen::VectorXd& v) {
  const double rotor_hz = op_.rotor_speed_rpm / 60.0;
  rhs_ += m_.force(revs, op_.input_torque_nm, rotor_hz);
  rhs_ += m_.mesh_excitation_force(revs);
  // Coriolis −2Ωm J ẋ and centripetal +Ω²m x on the carrier frame's translations.
  const double omega = m_.frame_inertia ? 2.0 * std::numbers::pi * m_.frame_order * rotor_hz : 0.0;
  for (const auto& p : m_.carrier_frame_xy) {
    const double mass = m_.mass[p[0]];
    rhs_[p[0]] += mass * (2.0 * omega * v[p[1]] + omega * omega * x[p[0]]);
    rhs_[p[1]] += mass * (-2.0 * omega * v[p[0]] + omega * omega * x[p[1]]);
  }
}

void NewmarkIntegrator::subtract_mean_stiffness_and_damping(const Eigen::VectorXd& x,
                                                            const Eigen::VectorXd& v) {
  // C is modal (full_model.hpp): a dense product like K̄'s.
  rhs_.noalias() = -(m_.stiffness * x);
  rhs_.noalias() -= c_ * v;
}

void NewmarkIntegrator::subtract_low_rank(const Eigen::VectorXd& x) {
  rhs_.noalias() -= u_ * (dk_ * (u_.transpose() * x));
}

void NewmarkIntegrator::accelerations_from_equilibrium() {
  // M a = f − C v − K(t) x
  fill_delta_k(revs_);
  subtract_mean_stiffness_and_damping(x_, v_);
  add_forces(revs_, x_, v_);
  subtract_low_rank(x_);
  a_ = rhs_.array() / m_.mass.array();
}

void NewmarkIntegrator::reset(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                              const OperatingPoint& op, double rotor_revolutions) {
  x_ = x;
  v_ = v;
  op_ = op;
  t_ = 0.0;
  revs_ = rotor_revolutions;
  accelerations_from_equilibrium();
}

void NewmarkIntegrator::reset_static(const OperatingPoint& op) {
  reset(m_.static_deflection(op.input_torque_nm), Eigen::VectorXd::Zero(m_.dofs()), op, 0.0);
}

void NewmarkIntegrator::step() {
  const double revs_next = revs_ + op_.rotor_speed_rpm / 60.0 * dt_;
  fill_delta_k(revs_next);
  // Predictors (Newmark, γ = 1/2, β = 1/4).
  tmp_ = x_ + dt_ * v_ + (0.25 * dt_ * dt_) * a_;  // x̃
  const Eigen::VectorXd v_pred = v_ + (0.5 * dt_) * a_;
  // r = f − C ṽ − K(t) x̃ = f − C ṽ − K̄ x̃ − U D Uᵀ x̃
  subtract_mean_stiffness_and_damping(tmp_, v_pred);
  add_forces(revs_next, tmp_, v_pred);
  subtract_low_rank(tmp_);
  // (S̄ + U A Uᵀ) a = r, A = Δt²/4 D: a = y − Z (I + A G)⁻¹ A Uᵀ y, y = S̄⁻¹ r.
  const Eigen::VectorXd y = s_bar_.solve(rhs_);
  const Eigen::MatrixXd a_mat = (0.25 * dt_ * dt_) * dk_;
  small_ = a_mat * g_;
  small_.diagonal().array() += 1.0;
  const Eigen::VectorXd corr = small_.partialPivLu().solve(a_mat * (u_.transpose() * y));
  const Eigen::VectorXd a_next = y - z_ * corr;
  x_ = tmp_ + (0.25 * dt_ * dt_) * a_next;
  v_ = v_pred + (0.5 * dt_) * a_next;
  a_ = a_next;
  revs_ = revs_next;
  t_ += dt_;
}

double NewmarkIntegrator::mesh_force_n(std::size_t i) const {
  const VaryingStiffness& v = m_.meshes[i];
  return v.stiffness_n_m(revs_) *
         (v.direction(0, m_.carrier_angle_rad(revs_)).dot(x_) - v.excitation_m(revs_));
}

double NewmarkIntegrator::bearing_force_n(std::size_t i, int c) const {
  const VaryingStiffness& v = m_.bearings[i];
  const double k = v.stiffness_n_m(revs_);
  if (!v.carrier_frame_xy) return k * v.directions.col(c).dot(x_);
  // Carrier-frame components turned into the housing frame.
  const double fx = k * v.directions.col(0).dot(x_);
  const double fy = k * v.directions.col(1).dot(x_);
  const double psi = m_.carrier_angle_rad(revs_);
  return c == 0 ? fx * std::cos(psi) - fy * std::sin(psi) : fx * std::sin(psi) + fy * std::cos(psi);
}

double NewmarkIntegrator::sensor_m_s2(std::size_t i) const { return m_.sensors[i].row.dot(a_); }

}  // namespace model::dynamics
