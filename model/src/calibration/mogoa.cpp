#include "model/calibration/mogoa.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace model::calibration {

double MultiObjectiveProblem::preference(const double* f) const {
  double sum = 0.0;
  for (std::size_t k = 0; k < objectives(); ++k) sum += f[k];
  return sum;
}

namespace {
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

// Pareto dominance for minimisation: a is no worse in every objective and better in one.
template <class A, class B>
bool dominates(const A& a, const B& b, std::size_t n) {
  bool better = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (a(static_cast<Eigen::Index>(k)) > b(static_cast<Eigen::Index>(k))) return false;
    if (a(static_cast<Eigen::Index>(k)) < b(static_cast<Eigen::Index>(k))) better = true;
  }
  return better;
}
}  // namespace

Mogoa::Mogoa(MultiObjectiveProblem& problem, const MogoaConfig& config)
    : problem_(problem), config_(config) {
  dims_ = problem.variables();
  objs_ = problem.objectives();
  config_ok_ = dims_ >= 1 && dims_ <= kMaxVariables && objs_ >= 1 && objs_ <= kMaxObjectives &&
               config.population >= 2 && config.population <= kMaxPopulation &&
               config.archive_size >= 1 && config.archive_size <= kMaxArchive &&
               config.max_iterations >= 1;
  if (!config_ok_) return;
  std::uint64_t s = config.seed;
  for (auto& r : rng_) r = splitmix64(s);
  const auto d = static_cast<Eigen::Index>(dims_);
  const auto n = static_cast<Eigen::Index>(config.population);
  lower_.resize(d);
  span_.resize(d);
  for (Eigen::Index i = 0; i < d; ++i) {
    lower_(i) = problem.lower(static_cast<std::size_t>(i));
    span_(i) = problem.upper(static_cast<std::size_t>(i)) - lower_(i);
  }
  x_.resize(n, d);
  x_next_.resize(n, d);
  f_.resize(n, static_cast<Eigen::Index>(objs_));
  archive_x_.resize(static_cast<Eigen::Index>(kMaxArchive + kMaxPopulation), d);
  archive_f_.resize(static_cast<Eigen::Index>(kMaxArchive + kMaxPopulation),
                    static_cast<Eigen::Index>(objs_));
  ranks_.resize(static_cast<Eigen::Index>(kMaxArchive + kMaxPopulation));
  weights_.resize(static_cast<Eigen::Index>(kMaxArchive + kMaxPopulation));
  x_work_.resize(d);
  f_work_.resize(static_cast<Eigen::Index>(objs_));
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < d; ++j) x_(i, j) = uniform();
  }
}

double Mogoa::uniform() {
  // xoshiro256** (Blackman & Vigna 2018); 53 random bits → [0, 1).
  const std::uint64_t result = rotl(rng_[1] * 5, 7) * 9;
  const std::uint64_t t = rng_[1] << 17;
  rng_[2] ^= rng_[0];
  rng_[3] ^= rng_[1];
  rng_[1] ^= rng_[2];
  rng_[0] ^= rng_[3];
  rng_[2] ^= t;
  rng_[3] = rotl(rng_[3], 45);
  return static_cast<double>(result >> 11) * 0x1.0p-53;
}

std::size_t Mogoa::roulette(const double* weights, std::size_t n) {
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) total += weights[i];
  if (!(total > 0.0)) return 0;
  const double pick = uniform() * total;
  double acc = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    acc += weights[i];
    if (pick < acc) return i;
  }
  return n - 1;
}

double Mogoa::social_force(double r, double f, double l) {
  return f * std::exp(-r / l) - std::exp(-r);
}

void Mogoa::seed_position(const double* x) {
  if (!config_ok_ || initialised_ || seeded_ >= config_.population) return;
  const auto row = static_cast<Eigen::Index>(seeded_++);
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(dims_); ++j) {
    const double u = span_(j) > 0.0 ? (x[j] - lower_(j)) / span_(j) : 0.0;
    x_(row, j) = std::clamp(u, 0.0, 1.0);
  }
}

void Mogoa::evaluate_population() {
  const auto d = static_cast<Eigen::Index>(dims_);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(config_.population); ++i) {
    for (Eigen::Index j = 0; j < d; ++j) x_work_(j) = lower_(j) + span_(j) * x_(i, j);
    problem_.evaluate(x_work_.data(), f_work_.data());
    ++evaluations_;
    for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(objs_); ++k) {
      f_(i, k) = std::isfinite(f_work_(k)) ? f_work_(k) : std::numeric_limits<double>::max();
    }
    add_to_archive(static_cast<std::size_t>(i));
  }
  trim_archive();
}

void Mogoa::add_to_archive(std::size_t row) {
  const auto r = static_cast<Eigen::Index>(row);
  const auto candidate = f_.row(r);
  for (std::size_t a = 0; a < archive_count_; ++a) {
    const auto member = archive_f_.row(static_cast<Eigen::Index>(a));
    if (dominates(member, candidate, objs_) || member == candidate) return;
  }
  // Remove the members the candidate dominates (swap with the last).
  for (std::size_t a = 0; a < archive_count_;) {
    if (dominates(candidate, archive_f_.row(static_cast<Eigen::Index>(a)), objs_)) {
      const auto last = static_cast<Eigen::Index>(--archive_count_);
      archive_x_.row(static_cast<Eigen::Index>(a)) = archive_x_.row(last);
      archive_f_.row(static_cast<Eigen::Index>(a)) = archive_f_.row(last);
    } else {
      ++a;
    }
  }
  // Capacity kMaxArchive + kMaxPopulation ≥ archive_size + population: a
  // population's worth of additions always fits before trim_archive().
  const auto slot = static_cast<Eigen::Index>(archive_count_++);
  archive_x_.row(slot) = x_.row(r);
  archive_f_.row(slot) = candidate;
}

void Mogoa::rank_archive() {
  // N_i: members within (max_k − min_k)/20 of member i in every objective (self included).
  const auto n = static_cast<Eigen::Index>(archive_count_);
  const auto m = static_cast<Eigen::Index>(objs_);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxObjectives, 1> radius(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    radius(k) =
        (archive_f_.col(k).head(n).maxCoeff() - archive_f_.col(k).head(n).minCoeff()) / 20.0;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    int count = 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      bool near = true;
      for (Eigen::Index k = 0; k < m && near; ++k) {
        // A zero radius (all members equal in k) counts every member as near in k.
        near = radius(k) == 0.0 || std::abs(archive_f_(j, k) - archive_f_(i, k)) < radius(k);
      }
      count += near ? 1 : 0;
    }
    ranks_(i) = count;
  }
}

void Mogoa::trim_archive() {
  while (archive_count_ > config_.archive_size) {
    rank_archive();
    const std::size_t victim = roulette(ranks_.data(), archive_count_);
    const auto last = static_cast<Eigen::Index>(--archive_count_);
    archive_x_.row(static_cast<Eigen::Index>(victim)) = archive_x_.row(last);
    archive_f_.row(static_cast<Eigen::Index>(victim)) = archive_f_.row(last);
  }
}

std::size_t Mogoa::choose_target() {
  if (config_.preference_target_share > 0.0 && uniform() < config_.preference_target_share) {
    std::size_t best = 0;
    double best_value = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < archive_count_; ++a) {
      for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(objs_); ++k)
        f_work_(k) = archive_f_(static_cast<Eigen::Index>(a), k);
      const double v = problem_.preference(f_work_.data());
      if (v < best_value) {
        best_value = v;
        best = a;
      }
    }
    return best;
  }
  rank_archive();
  for (std::size_t a = 0; a < archive_count_; ++a)
    weights_(static_cast<Eigen::Index>(a)) = 1.0 / ranks_(static_cast<Eigen::Index>(a));
  return roulette(weights_.data(), archive_count_);
}

bool Mogoa::step() {
  if (!config_ok_) return false;
  if (!initialised_) {
    evaluate_population();
    initialised_ = true;
    return true;
  }
  if (iteration_ >= config_.max_iterations) return false;
  ++iteration_;
  // c decreases linearly over the iterations (GOA eq. 2.8).
  const double c = config_.c_max - static_cast<double>(iteration_) *
                                       (config_.c_max - config_.c_min) /
                                       static_cast<double>(config_.max_iterations);
  const auto target = static_cast<Eigen::Index>(choose_target());
  const auto n = static_cast<Eigen::Index>(config_.population);
  const auto d = static_cast<Eigen::Index>(dims_);
  for (Eigen::Index i = 0; i < n; ++i) {
    x_work_.setZero();
    for (Eigen::Index j = 0; j < n; ++j) {
      if (j == i) continue;
      const double dist = (x_.row(j) - x_.row(i)).norm();
      const double mapped = 1.0 + std::fmod(dist, 3.0);  // distances mapped into [1, 4)
      // (ub − lb)/2 = 1/2 in the normalised box.
      const double gain = c * 0.5 *
                          social_force(mapped, config_.attraction_f, config_.length_scale_l) /
                          (dist + std::numeric_limits<double>::epsilon());
      x_work_.noalias() += gain * (x_.row(j) - x_.row(i)).transpose();
    }
    for (Eigen::Index k = 0; k < d; ++k) {
      x_next_(i, k) = std::clamp(c * x_work_(k) + archive_x_(target, k), 0.0, 1.0);
    }
  }
  x_ = x_next_;
  evaluate_population();
  return true;
}

void Mogoa::archive_member(std::size_t i, double* x, double* f) const {
  const auto r = static_cast<Eigen::Index>(i);
  if (x != nullptr) {
    for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(dims_); ++j)
      x[j] = lower_(j) + span_(j) * archive_x_(r, j);
  }
  if (f != nullptr) {
    for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(objs_); ++k) f[k] = archive_f_(r, k);
  }
}

}  // namespace model::calibration
