#pragma once
// Multi-objective grasshopper optimisation algorithm (MOGOA) as published:
// S. Z. Mirjalili, S. Mirjalili, S. Saremi, H. Faris, I. Aljarah,
// "Grasshopper optimization algorithm for multi-objective optimization
// problems", Applied Intelligence 48 (2018) 805–820 (online 2017), built on
// GOA (Saremi, Mirjalili, Lewis, Adv. Eng. Softw. 105 (2017) 30–47).
//
// Position update (GOA eq. 2.7, MOGOA eq. 10), per grasshopper i and dimension d:
//
//   X_i^d = c · Σ_{j≠i} c · (ub_d − lb_d)/2 · s(r̃_ij) · (x_j^d − x_i^d)/d_ij  +  T̂^d
//
//   s(r) = f·e^(−r/l) − e^(−r),  f = 0.5, l = 1.5     (social force, GOA eq. 2.3)
//   d_ij = |x_j − x_i| (Euclidean), r̃_ij = 1 + (d_ij mod 3) ∈ [1, 4)  (the paper
//          maps distances into [1, 4]; the authors' MATLAB code uses 2 + (d mod 2))
//   c    = c_max − t·(c_max − c_min)/t_max,  c_max = 1, c_min = 0.00004  (eq. 2.8)
//   T̂    = target: an archive member chosen by roulette wheel with probability
//          ∝ 1/N_i, N_i = the number of archive members within the
//          neighbourhood (|F_j,k − F_i,k| < (max_k − min_k)/20 for every
//          objective k, self included): less crowded regions are favoured.
//
// Archive: the non-dominated solutions found so far (Pareto dominance for
// minimisation). When it exceeds its capacity, members are removed one at a
// time by roulette wheel with probability ∝ N_i (crowded regions lose first).
//
// Differences from the reference code, each deliberate: the search runs in
// coordinates normalised to the unit box (ub − lb = 1 for every variable, so
// a variable's unit does not decide its step); positions leaving the box are
// clamped to it; a new solution whose objectives equal an archive member's is
// not added twice. Deterministic under `seed` (own xoshiro256** generator,
// identical on every platform).
//
// Improvements for calibration (off by default = published MOGOA):
//  - warm start: positions given with seed_position() replace random ones in
//    the initial population (e.g. the current parameters and the last
//    calibration's result);
//  - preference-guided target: with probability `preference_target_share`, T̂
//    is the archive member with the smallest MultiObjectiveProblem::preference()
//    instead of the roulette choice.
//
// Memory: all storage is inline Eigen matrices with compile-time maxima
// (the object is ~100 kB: create it once, at start-up, on the heap or as a
// static). step() performs `population` problem evaluations and never
// allocates. Thread context: one owning thread (a low-priority worker); not
// thread-safe.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

namespace model::calibration {

// The largest calibration space (calibration_space.hpp kMaxCalibrationVariables: the standard
// 66, with --space seats 70, with the released sun shaft 71); ZDT1–3 use 30. At 64 the standard
// space had outgrown it and the MOGOA methods refused it.
inline constexpr std::size_t kMaxVariables = 72;
inline constexpr std::size_t kMaxObjectives = 6;   // 3 indicators × 2 measurement points
inline constexpr std::size_t kMaxPopulation = 64;  // grasshoppers
inline constexpr std::size_t kMaxArchive = 128;    // Pareto archive capacity

/// A box-bounded problem with objectives to minimise.
class MultiObjectiveProblem {
 public:
  virtual ~MultiObjectiveProblem() = default;
  virtual std::size_t variables() const = 0;   // ≤ kMaxVariables
  virtual std::size_t objectives() const = 0;  // ≤ kMaxObjectives
  virtual double lower(std::size_t i) const = 0;
  virtual double upper(std::size_t i) const = 0;
  /// @param x variables() values within the bounds
  /// @param f objectives() values written (finite; large for failures)
  virtual void evaluate(const double* x, double* f) = 0;
  /// Scalar preference of an objective vector (smaller = better); used only by
  /// the preference-guided target. Default: the sum of the objectives.
  virtual double preference(const double* f) const;
};

struct MogoaConfig {
  std::size_t population = 20;      // [-] grasshoppers, ≤ kMaxPopulation
  std::size_t max_iterations = 50;  // [-] t_max of the c schedule
  std::size_t archive_size = 100;   // [-] ≤ kMaxArchive
  double c_max = 1.0;
  double c_min = 0.00004;
  double attraction_f = 0.5;    // f of s(r)
  double length_scale_l = 1.5;  // l of s(r)
  std::uint64_t seed = 1;
  double preference_target_share = 0.0;  // [0, 1]; 0 = published roulette target
};

class Mogoa {
 public:
  using PopulationX =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxPopulation, kMaxVariables>;
  using PopulationF =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxPopulation, kMaxObjectives>;
  using ArchiveX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0,
                                 kMaxArchive + kMaxPopulation, kMaxVariables>;
  using ArchiveF = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0,
                                 kMaxArchive + kMaxPopulation, kMaxObjectives>;

  /// Sizes are checked here; config_ok() is false (and step() does nothing)
  /// when a size exceeds its maximum or is zero.
  Mogoa(MultiObjectiveProblem& problem, const MogoaConfig& config);

  bool config_ok() const { return config_ok_; }

  /// Puts x (in the problem's units, clamped to the bounds) into the initial
  /// population in place of a random grasshopper. Call before the first step();
  /// at most `population` positions are kept.
  void seed_position(const double* x);

  /// One iteration. The first call evaluates the initial population; each
  /// later call moves every grasshopper once and evaluates it. Returns false
  /// (and does nothing) once max_iterations moves have been made.
  bool step();

  std::size_t iteration() const { return iteration_; }
  std::size_t evaluations() const { return evaluations_; }
  std::size_t archive_count() const { return archive_count_; }
  /// Archive member i in the problem's units / its objectives.
  void archive_member(std::size_t i, double* x, double* f) const;
  double archive_objective(std::size_t i, std::size_t k) const {
    return archive_f_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k));
  }

  /// Social force s(r) = f·e^(−r/l) − e^(−r) (GOA eq. 2.3).
  static double social_force(double r, double f, double l);

 private:
  double uniform();  // [0, 1)
  std::size_t roulette(const double* weights, std::size_t n);
  void evaluate_population();
  void add_to_archive(std::size_t row);
  void rank_archive();
  void trim_archive();
  std::size_t choose_target();

  MultiObjectiveProblem& problem_;
  MogoaConfig config_;
  bool config_ok_ = false;
  std::size_t dims_ = 0;
  std::size_t objs_ = 0;
  std::uint64_t rng_[4]{};
  std::size_t iteration_ = 0;
  std::size_t evaluations_ = 0;
  bool initialised_ = false;
  std::size_t seeded_ = 0;

  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxVariables, 1> lower_, span_;
  PopulationX x_;  // normalised positions in [0, 1]
  PopulationX x_next_;
  PopulationF f_;
  ArchiveX archive_x_;  // normalised
  ArchiveF archive_f_;
  std::size_t archive_count_ = 0;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxArchive + kMaxPopulation, 1> ranks_;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxArchive + kMaxPopulation, 1> weights_;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxVariables, 1> x_work_;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxObjectives, 1> f_work_;
};

}  // namespace model::calibration
