#pragma once
// Reference integrator of the full-order model: Newmark's average-acceleration
// scheme (γ = 1/2, β = 1/4; Newmark, J. Eng. Mech. Div. 85 (1959); unconditionally
// stable, no numerical damping, period error ≈ (ωΔt)²/12), implicit in the whole
// time-varying stiffness K(t) = K̄ + U·diag(Δk(t))·Uᵀ.
//
// Each step solves (M + Δt/2·C + Δt²/4·K(t_{n+1}))·a_{n+1} = r exactly: the constant
// part S̄ = M + Δt/2·C + Δt²/4·K̄ is factored once (Cholesky), the low-rank part is
// added by the Sherman–Morrison–Woodbury identity (one R×R solve per step, R = the
// total rank of the meshes, bearings and paths, + 2 for each element that turns with the
// carrier: its direction u(ψ) spans three fixed vectors c + cos ψ·a + sin ψ·b, and what
// it adds to K̄ is the 3×3 block k(t)·vvᵀ − k̄·v₀v₀ᵀ in them, v = (1, cos ψ, sin ψ),
// v₀ = (1, 1, 0)). The damping C is the model's (modal, built on the mean stiffness at
// the reference angle; full_model.hpp). The meshes' transmission error is a known force
// +u·k(t)·e(t) at t_{n+1} (the mesh force is k·(δ − e)); the carrier frame's Coriolis and
// centripetal forces on its translations (full_model.hpp) are explicit, at the predicted velocity
// and displacement (2Ω·Δt ≈ 1e-4: far inside the stability limit).
//
// Thread context: allocates at construction only; host / non-RT threads.

#include <Eigen/Dense>

#include <vector>

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

  /// Elastic force of mesh i along its line of action [N] (compression > 0).
  double mesh_force_n(std::size_t i) const;
  /// Reaction of bearing i in the housing frame's x (c = 0) or y (c = 1) [N].
  double bearing_force_n(std::size_t i, int c) const;
  /// Acceleration read by sensor i [m/s²].
  double sensor_m_s2(std::size_t i) const;

 private:
  void accelerations_from_equilibrium();
  void fill_delta_k(double revs);
  // r += the external forces, the transmission error's and the turning frame's at (revs, x, v).
  void add_forces(double revs, const Eigen::VectorXd& x, const Eigen::VectorXd& v);
  // r = −K̄ x − C v.
  void subtract_mean_stiffness_and_damping(const Eigen::VectorXd& x, const Eigen::VectorXd& v);
  // r −= U·D·Uᵀ x.
  void subtract_low_rank(const Eigen::VectorXd& x);

  // The low-rank part: a group of columns of U per element.
  struct Group {
    const VaryingStiffness* element = nullptr;
    int first = 0;  // first column in U
    int size = 0;   // rank, or 3 for a turning element
    bool turning = false;
  };

  const FullModel& m_;
  double dt_;
  OperatingPoint op_;
  double t_ = 0.0;
  double revs_ = 0.0;
  Eigen::VectorXd x_, v_, a_;
  Eigen::LLT<Eigen::MatrixXd> s_bar_;  // M + Δt/2 C + Δt²/4 K̄
  std::vector<Group> groups_;
  Eigen::MatrixXd u_;      // dofs × R varying directions
  Eigen::MatrixXd z_;      // S̄⁻¹ U
  Eigen::MatrixXd g_;      // Uᵀ S̄⁻¹ U
  Eigen::MatrixXd dk_;     // R×R: the stiffness added to K̄ at t, in U's columns
  Eigen::MatrixXd c_;      // C
  Eigen::MatrixXd small_;  // R×R workspace
  Eigen::VectorXd rhs_, tmp_;
};

}  // namespace model::dynamics
