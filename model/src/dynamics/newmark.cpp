#include "model/dynamics/newmark.hpp"

#include <cmath>

namespace model::dynamics {

NewmarkIntegrator::NewmarkIntegrator(const FullModel& model, double dt_s) : m_(model), dt_(dt_s) {
  const int n = m_.dofs();
  int rank = 0;
  for (const auto& v : m_.meshes) rank += static_cast<int>(v.directions.cols());
  for (const auto& v : m_.bearings) rank += static_cast<int>(v.directions.cols());
  u_.resize(n, rank);
  int c = 0;
  for (const auto* list : {&m_.meshes, &m_.bearings}) {
    for (const auto& v : *list) {
      for (int k = 0; k < v.directions.cols(); ++k) u_.col(c++) = v.directions.col(k);
    }
  }
  Eigen::MatrixXd s = (0.25 * dt_ * dt_) * m_.stiffness + (0.5 * dt_) * m_.damping();
  s.diagonal() += m_.mass;
  s_bar_.compute(s);
  z_ = s_bar_.solve(u_);
  g_ = u_.transpose() * z_;
  dk_ = Eigen::VectorXd::Zero(rank);
  small_.resize(rank, rank);
  x_ = v_ = a_ = rhs_ = tmp_ = Eigen::VectorXd::Zero(n);
}

void NewmarkIntegrator::fill_delta_k(double revs) {
  int c = 0;
  for (const auto* list : {&m_.meshes, &m_.bearings}) {
    for (const auto& v : *list) {
      const double dk = v.stiffness_n_m(revs) - v.mean_n_m;
      for (int k = 0; k < v.directions.cols(); ++k) dk_[c++] = dk;
    }
  }
}

void NewmarkIntegrator::accelerations_from_equilibrium() {
  // M a = f + f_TE − C v − K(t) x
  fill_delta_k(revs_);
  rhs_ = m_.force(revs_, op_.input_torque_nm) + m_.transmission_error_force(revs_);
  rhs_.noalias() -= m_.stiffness * x_;
  rhs_.noalias() -= m_.damping() * v_;
  rhs_.noalias() -= u_ * (dk_.asDiagonal() * (u_.transpose() * x_));
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
  // r = f + f_TE − C ṽ − K(t) x̃ = f + f_TE − C ṽ − K̄ x̃ − U Δk Uᵀ x̃; f_TE = Σ k(t)e(t)u, the
  // meshes' transmission-error forces (known at t_{n+1}: e and k are tables of the angle).
  rhs_ = m_.force(revs_next, op_.input_torque_nm) + m_.transmission_error_force(revs_next);
  rhs_.noalias() -= m_.stiffness * tmp_;
  rhs_.noalias() -= m_.damping() * v_pred;
  rhs_.noalias() -= u_ * (dk_.asDiagonal() * (u_.transpose() * tmp_));
  // (S̄ + U A Uᵀ) a = r, A = Δt²/4 Δk: a = y − Z (I + A G)⁻¹ A Uᵀ y, y = S̄⁻¹ r.
  const Eigen::VectorXd y = s_bar_.solve(rhs_);
  const Eigen::VectorXd a_diag = (0.25 * dt_ * dt_) * dk_;
  small_ = a_diag.asDiagonal() * g_;
  small_.diagonal().array() += 1.0;
  const Eigen::VectorXd corr =
      small_.partialPivLu().solve(a_diag.asDiagonal() * (u_.transpose() * y));
  const Eigen::VectorXd a_next = y - z_ * corr;
  x_ = tmp_ + (0.25 * dt_ * dt_) * a_next;
  v_ = v_pred + (0.5 * dt_) * a_next;
  a_ = a_next;
  revs_ = revs_next;
  t_ += dt_;
}

double NewmarkIntegrator::mesh_force_n(std::size_t i) const {
  const VaryingStiffness& v = m_.meshes[i];
  return v.stiffness_n_m(revs_) * (v.directions.col(0).dot(x_) - v.transmission_error_m(revs_));
}

double NewmarkIntegrator::bearing_force_n(std::size_t i, int c) const {
  const VaryingStiffness& v = m_.bearings[i];
  return v.stiffness_n_m(revs_) * v.directions.col(c).dot(x_);
}

double NewmarkIntegrator::sensor_m_s2(std::size_t i) const { return m_.sensors[i].row.dot(a_); }

}  // namespace model::dynamics
