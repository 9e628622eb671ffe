#pragma once
// Reference integrator of the full-order model: Newmark's average-acceleration
// scheme (γ = 1/2, β = 1/4; Newmark, J. Eng. Mech. Div. 85 (1959); unconditionally
// stable, no numerical damping, period error ≈ (ωΔt)²/12), implicit in the whole
// time-varying stiffness K(t) = K̄ + U·diag(Δk(t))·Uᵀ.
//
// Each step solves (M + Δt/2·C + Δt²/4·K(t_{n+1}))·a_{n+1} = r exactly: the constant
// part S̄ = M + Δt/2·C + Δt²/4·K̄ is factored once (Cholesky), the low-rank part is
// added by the Sherman–Morrison–Woodbury identity (one R×R solve per step, R = the
// total rank of the meshes and bearings). The damping C is the model's (modal, built
// on the mean stiffness; full_model.hpp); the meshes' transmission-error forces
// k(t)·e(t) enter the right-hand side.
//
// Thread context: allocates at construction only; host / non-RT threads.

#include <Eigen/Dense>

#include "model/dynamics/full_model.hpp"

namespace model::dynamics {

class NewmarkIntegrator {
 public:
  /// @param model the model (must outlive the integrator)
  /// @param dt_s time step [s]
  NewmarkIntegrator(const FullModel& model, double dt_s);

  /// Sets the state at rotor position `rotor_revolutions` and computes the
  /// consistent acceleration. Speed and torque are held until the next call of
  /// set_operating_point().
  void reset(const Eigen::VectorXd& x, const Eigen::VectorXd& v, const OperatingPoint& op,
             double rotor_revolutions = 0.0);
  /// Starts from the static deflection under the mean stiffness and torque.
  void reset_static(const OperatingPoint& op);
  void set_operating_point(const OperatingPoint& op) { op_ = op; }

  /// Advances one step Δt.
  void step();

  double time_s() const { return t_; }
  double rotor_revolutions() const { return revs_; }
  const Eigen::VectorXd& displacement() const { return x_; }
  const Eigen::VectorXd& velocity() const { return v_; }
  const Eigen::VectorXd& acceleration() const { return a_; }

  /// Elastic force k(t)·(δ − e(t)) of mesh i along its line of action [N] (compression > 0).
  double mesh_force_n(std::size_t i) const;
  /// Reaction of bearing i in x (c = 0) or y (c = 1) [N].
  double bearing_force_n(std::size_t i, int c) const;
  /// Acceleration read by sensor i [m/s²].
  double sensor_m_s2(std::size_t i) const;

 private:
  void accelerations_from_equilibrium();
  void fill_delta_k(double revs);

  const FullModel& m_;
  double dt_;
  OperatingPoint op_;
  double t_ = 0.0;
  double revs_ = 0.0;
  Eigen::VectorXd x_, v_, a_;
  Eigen::LLT<Eigen::MatrixXd> s_bar_;  // M + Δt/2 C + Δt²/4 K̄
  Eigen::MatrixXd u_;                  // dofs × R varying directions
  Eigen::MatrixXd z_;                  // S̄⁻¹ U
  Eigen::MatrixXd g_;                  // Uᵀ S̄⁻¹ U
  Eigen::VectorXd dk_;                 // R: Δk(t) per column
  Eigen::MatrixXd small_;              // R×R workspace
  Eigen::VectorXd rhs_, tmp_;
};

}  // namespace model::dynamics
