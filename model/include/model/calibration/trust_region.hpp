#pragma once
// Derivative-free least squares by a trust region around a linear model of a
// vector-valued map, after DFO-GN: C. Cartis, L. Roberts, "A derivative-free
// Gauss–Newton method", Mathematical Programming Computation 11 (2019)
// 631–674 (and POUNDERS, S. M. Wild, 2017: one model evaluation per iteration
// for a whole residual vector).
//
// Problem: find x in the box [lower, upper] minimising
//
//   F(x) = ‖r(x)‖²,   r(x) = w ∘ (φ(x) − φ*)                        (1)
//
// where φ(x) ∈ R^m is what one model evaluation returns (here: the log RMS and
// log mesh-harmonic amplitudes of both measurement points), φ* its target and
// w ≥ 0 weights (0 masks a feature). The method keeps a linear model
// φ(x_k + s) ≈ φ(x_k) + J s of the features themselves (not of F, and not
// weighted, so that J can be reused for another target: the warm start).
//
//  1. Model: J from n probes x_k + Δ·q_i (q_i an orthonormal basis: the
//     coordinate axes, or a random rotation drawn from `seed`), the linear
//     interpolation of DFO-GN (Cartis & Roberts §3, n + 1 points):
//     J·D = [φ(x_k + d_i) − φ(x_k)],  D = [d_1 … d_n]                  (2)
//     — or a previous calibration's J (warm start: no probe at all).
//  2. Step: the Gauss–Newton step within the trust region, as a
//     Levenberg–Marquardt step (Moré 1978): with A = (WJ)ᵀ(WJ) = VΛVᵀ,
//     g = (WJ)ᵀ r,   s(λ) = −V (Λ + λI)⁻¹ Vᵀ g,  λ = 0 when ‖s(0)‖ ≤ Δ,
//     else λ > 0 with ‖s(λ)‖ = Δ (bisection); x_k + s clamped to the box.  (3)
//  3. One evaluation at x_k + s; ratio of actual to predicted reduction
//     ρ = (F(x_k) − F(x_k + s)) / (F(x_k) − ‖r_k + WJs‖²)                 (4)
//     accept when F decreases; Δ ← Δ/2 when ρ < 0.1, Δ ← min(2Δ, Δ_max)
//     when ρ > 0.7 and the step reached the boundary (Cartis & Roberts
//     Alg. 1 with γ_dec = 0.5, γ_inc = 2, η1 = 0.1, η2 = 0.7).
//  4. Model update after every evaluation, successful or not — Broyden's
//     least-change secant update (Broyden 1965), which makes J interpolate the
//     new point as DFO-GN's point replacement does, without storing points:
//     J ← J + ((φ(x_k + s) − φ(x_k)) − J s) sᵀ / (sᵀs)                  (5)
//  5. Model refresh (DFO-GN's geometry/safety step, simplified): after
//     `refresh_after_failures` consecutive unsuccessful steps, J is rebuilt by
//     fresh probes of length Δ around x_k.
//  6. Restart (ours, for the many local minima of vibration features: a mesh
//     harmonic moves across a resonance as a stiffness changes): when Δ falls
//     below min_radius, the run continues from x_best + restart_radius·u (u a
//     random unit vector) with Δ = initial_radius and the current J — unless
//     `restarts` is off, and then the run finishes.
//  Finish: `max_evaluations` reached, or Δ < min_radius without restarts,
//  or finish() from the owner (e.g. "every indicator within its threshold").
//
// Memory: Eigen storage of fixed capacity (≤ kMaxLsqVariables × kMaxLsqFeatures, sized
// to the map at construction), every work matrix a member: nothing allocated after
// construction and nothing large on the stack. Deterministic (own xoshiro256**).
// Thread context: one owning thread (the calibrator's low-priority worker);
// step() makes exactly one evaluation of the map (none once finished).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <cstddef>
#include <cstdint>

namespace model::calibration {

inline constexpr std::size_t kMaxLsqVariables = 70;  // the calibration's decision variables
/// 4 operating points × 2 points × (RMS + 18 tones + the spectral residual) + one prior row per
/// variable: 230 × 70 doubles, under Eigen's 128 kB fixed-size limit for the Jacobian's
/// storage. 18 tones: 3 meshes × 5 harmonics or 4 × 4 (the default is 3 × 3); more fit fewer
/// operating points (Calibrator::set_measurements() refuses).
inline constexpr std::size_t kMaxLsqFeatures = 4 * 2 * 20 + kMaxLsqVariables;

/// A box-bounded map x → φ(x) (the model's feature vector).
class FeatureMap {
 public:
  virtual ~FeatureMap() = default;
  virtual std::size_t variables() const = 0;  // ≤ kMaxLsqVariables
  virtual std::size_t features() const = 0;   // ≤ kMaxLsqFeatures
  virtual double lower(std::size_t i) const = 0;
  virtual double upper(std::size_t i) const = 0;
  /// φ(x) into phi[0..features()); false when the model cannot be evaluated at x.
  virtual bool evaluate(const double* x, double* phi) = 0;
};

struct TrustRegionConfig {
  std::size_t max_evaluations = 60;  // [-] budget, probes included
  double initial_radius = 0.5;       // [units of x] Δ_0 and the probe length
  double min_radius = 1e-2;          // [units of x] converged below (restart or finish)
  bool restarts = true;              // restart from a random point near the best after converging
  double restart_radius = 0.5;       // [units of x]
  double max_radius = 2.0;           // [units of x]
  std::size_t refresh_after_failures = 3;  // [-] consecutive unsuccessful steps before re-probing
  std::uint64_t seed = 0;  // 0: probe along the coordinate axes; else a random orthonormal basis
};

class TrustRegionLeastSquares {
 public:
  // Sized to the map (variables() × features()) at construction, capacity fixed.
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxLsqVariables, 1>;
  using Features = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxLsqFeatures, 1>;
  using Jacobian =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxLsqFeatures, kMaxLsqVariables>;
  using Square =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxLsqVariables, kMaxLsqVariables>;

  /// config_ok() is false (and step() does nothing) when the map's sizes exceed the
  /// capacities or are zero, or a radius is not positive.
  TrustRegionLeastSquares(FeatureMap& map, const TrustRegionConfig& config);
  bool config_ok() const { return config_ok_; }

  /// φ* and w of (1), features() values each (copied).
  void set_target(const double* target, const double* weights);

  /// Begins at x0 (clamped to the box). With `jacobian` (a previous model of φ for
  /// the same map, features() × variables()), the first step evaluates x0 and the next
  /// ones already move.
  /// With `phi0` as well (φ at x0, features() values, already evaluated by the owner), x0 is
  /// not evaluated again: the first step already moves (or probes).
  void start(const double* x0, const Jacobian* jacobian = nullptr, const double* phi0 = nullptr);

  /// One evaluation of the map. false (nothing evaluated) once finished.
  bool step();
  /// Ends the run now (e.g. the owner's stopping rule).
  void finish() { finished_ = true; }
  bool finished() const { return finished_; }

  std::size_t evaluations() const { return evaluations_; }
  /// Best point so far (lowest F) and its cost; cost is +inf before the first success.
  const Vector& best_x() const { return best_x_; }
  double best_cost() const { return best_cost_; }
  std::size_t restarts() const { return restarts_; }
  /// The last evaluated point and whether its evaluation succeeded.
  const Vector& last_x() const { return x_last_; }
  double radius() const { return radius_; }
  /// The current model of φ (valid once the probes are done or a J was given).
  const Jacobian& jacobian() const { return jacobian_; }
  bool jacobian_valid() const { return jacobian_valid_; }

 private:
  enum class Phase : std::uint8_t { kBase, kProbe, kIterate };
  double uniform();
  void make_basis();
  double cost(const Features& phi) const;
  void clamp(Vector& x) const;
  bool evaluate(const Vector& x, Features& phi);
  void probe_step();
  void restart();
  void iterate_step();
  void compute_step(Vector& s, double& predicted);

  FeatureMap& map_;
  TrustRegionConfig config_;
  bool config_ok_ = false;
  std::size_t n_ = 0;
  std::size_t m_ = 0;
  std::uint64_t rng_[4]{};
  Vector lower_;
  Vector upper_;
  Features target_;
  Features weight_;
  Square basis_;

  Phase phase_ = Phase::kBase;
  bool finished_ = true;
  std::size_t evaluations_ = 0;
  std::size_t probe_ = 0;
  std::size_t failures_ = 0;
  double radius_ = 0.0;
  Vector x_k_;
  Features phi_k_;
  double cost_k_ = 0.0;
  Vector best_x_;
  double best_cost_ = 0.0;
  std::size_t restarts_ = 0;
  Vector x_last_;
  Jacobian jacobian_;
  bool jacobian_valid_ = false;
  // Probe bookkeeping of (2).
  Square probe_d_;
  Jacobian probe_dphi_;
  Vector probe_best_x_;
  Features probe_best_phi_;
  double probe_best_cost_ = 0.0;
  Features phi_work_;
  // Work storage of compute_step() and the updates.
  Jacobian wj_;
  Square normal_;
  Square inverse_d_;
  Eigen::SelfAdjointEigenSolver<Square> eigen_;
  Features r_work_;
  Vector g_work_, b_work_, c_work_, lambda_work_, s_work_, u_work_;
};

}  // namespace model::calibration
