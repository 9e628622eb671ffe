#include "model/calibration/trust_region.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace model::calibration {

namespace {
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

constexpr double kShrink = 0.5;     // γ_dec
constexpr double kGrow = 2.0;       // γ_inc
constexpr double kRatioPoor = 0.1;  // η1
constexpr double kRatioGood = 0.7;  // η2
constexpr double kEigenFloor =
    1e-12;  // relative: smaller curvatures are treated as flat (pseudo-inverse)
constexpr int kBisections = 60;
constexpr double kPi = 3.14159265358979323846;
}  // namespace

TrustRegionLeastSquares::TrustRegionLeastSquares(FeatureMap& map, const TrustRegionConfig& config)
    : map_(map), config_(config) {
  n_ = map.variables();
  m_ = map.features();
  config_ok_ = n_ > 0 && n_ <= kMaxLsqVariables && m_ > 0 && m_ <= kMaxLsqFeatures &&
               config.initial_radius > 0.0 && config.min_radius > 0.0 &&
               config.max_radius >= config.initial_radius && config.max_evaluations > 0;
  if (!config_ok_) return;
  const auto n = static_cast<Eigen::Index>(n_);
  const auto m = static_cast<Eigen::Index>(m_);
  for (Vector* v : {&lower_, &upper_, &x_k_, &best_x_, &x_last_, &probe_best_x_, &g_work_, &b_work_,
                    &c_work_, &lambda_work_, &s_work_, &u_work_})
    v->setZero(n);
  for (Features* f : {&target_, &weight_, &phi_k_, &probe_best_phi_, &phi_work_, &r_work_})
    f->setZero(m);
  for (Jacobian* j : {&jacobian_, &probe_dphi_, &wj_}) j->setZero(m, n);
  for (Square* q : {&basis_, &probe_d_, &normal_, &inverse_d_}) q->setZero(n, n);
  basis_.setIdentity(n, n);
  for (std::size_t i = 0; i < n_; ++i) {
    lower_(static_cast<Eigen::Index>(i)) = map.lower(i);
    upper_(static_cast<Eigen::Index>(i)) = map.upper(i);
  }
  std::uint64_t s = config.seed;
  for (auto& r : rng_) r = splitmix64(s);
  make_basis();
}

double TrustRegionLeastSquares::uniform() {
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

void TrustRegionLeastSquares::make_basis() {
  const auto n = static_cast<Eigen::Index>(n_);
  basis_.setIdentity(n, n);
  if (config_.seed == 0) return;
  // Gaussian columns (Box–Muller), orthonormalised by modified Gram–Schmidt: a
  // uniformly random rotation of the probe directions.
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const double u1 = std::max(uniform(), 1e-300);
      const double u2 = uniform();
      basis_(i, j) = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index k = 0; k < j; ++k) {
      const double p = basis_.col(j).head(n).dot(basis_.col(k).head(n));
      basis_.col(j).head(n) -= p * basis_.col(k).head(n);
    }
    const double norm = basis_.col(j).head(n).norm();
    if (norm > 1e-12) {
      basis_.col(j).head(n) /= norm;
    } else {  // degenerate draw (probability 0): fall back to the axes
      basis_.setIdentity(n, n);
      return;
    }
  }
}

void TrustRegionLeastSquares::set_target(const double* target, const double* weights) {
  if (!config_ok_) return;
  target_.setZero();
  weight_.setZero();
  for (std::size_t i = 0; i < m_ && i < kMaxLsqFeatures; ++i) {
    target_(static_cast<Eigen::Index>(i)) = target[i];
    weight_(static_cast<Eigen::Index>(i)) = weights[i];
  }
}

double TrustRegionLeastSquares::cost(const Features& phi) const {
  return (weight_.array() * (phi - target_).array()).matrix().squaredNorm();
}

void TrustRegionLeastSquares::clamp(Vector& x) const {
  for (std::size_t i = 0; i < n_; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    x(k) = std::clamp(x(k), lower_(k), upper_(k));
  }
}

bool TrustRegionLeastSquares::evaluate(const Vector& x, Features& phi) {
  ++evaluations_;
  x_last_ = x;
  phi.setZero();
  if (!map_.evaluate(x.data(), phi.data())) return false;
  for (std::size_t i = 0; i < m_; ++i) {
    if (!std::isfinite(phi(static_cast<Eigen::Index>(i)))) return false;
  }
  const double c = cost(phi);
  if (c < best_cost_) {
    best_cost_ = c;
    best_x_ = x;
  }
  return true;
}

void TrustRegionLeastSquares::start(const double* x0, const Jacobian* jacobian,
                                    const double* phi0) {
  if (!config_ok_) return;
  if (jacobian && (jacobian->rows() != static_cast<Eigen::Index>(m_) ||
                   jacobian->cols() != static_cast<Eigen::Index>(n_)))
    jacobian = nullptr;  // not a model of this map: probe
  x_k_.setZero();
  for (std::size_t i = 0; i < n_; ++i) x_k_(static_cast<Eigen::Index>(i)) = x0[i];
  clamp(x_k_);
  evaluations_ = 0;
  failures_ = 0;
  probe_ = 0;
  radius_ = config_.initial_radius;
  cost_k_ = std::numeric_limits<double>::infinity();
  best_x_ = x_k_;
  best_cost_ = cost_k_;
  restarts_ = 0;
  jacobian_valid_ = jacobian != nullptr;
  if (jacobian) jacobian_ = *jacobian;
  phase_ = Phase::kBase;
  finished_ = false;
  if (phi0) {
    // The base is known: as Phase::kBase would have left it, without the evaluation.
    for (std::size_t i = 0; i < m_; ++i) phi_k_(static_cast<Eigen::Index>(i)) = phi0[i];
    cost_k_ = cost(phi_k_);
    best_x_ = x_k_;
    best_cost_ = cost_k_;
    phase_ = jacobian_valid_ ? Phase::kIterate : Phase::kProbe;
    probe_ = 0;
  }
}

bool TrustRegionLeastSquares::step() {
  if (finished_ || !config_ok_) return false;
  const std::size_t before = evaluations_;
  // Phases may end without an evaluation (a probe direction the box blocks, a
  // step the model predicts useless): go on until one evaluation is made.
  while (evaluations_ == before && !finished_) {
    switch (phase_) {
      case Phase::kBase:
        if (!evaluate(x_k_, phi_k_)) {
          if (restarts_ == 0) {
            finished_ = true;  // nothing to build a model around
            return true;
          }
          restart();  // a failed restart point: draw another
          break;
        }
        cost_k_ = cost(phi_k_);
        phase_ = jacobian_valid_ ? Phase::kIterate : Phase::kProbe;
        probe_ = 0;
        break;
      case Phase::kProbe:
        probe_step();
        break;
      case Phase::kIterate:
        iterate_step();
        break;
    }
    if (evaluations_ >= config_.max_evaluations) finished_ = true;
    if (!finished_ && radius_ < config_.min_radius) {
      if (config_.restarts && jacobian_valid_) {
        restart();
      } else {
        finished_ = true;
      }
    }
  }
  return evaluations_ != before;
}

void TrustRegionLeastSquares::restart() {
  // 6: a random unit direction (Gaussian components, normalised) from the best point.
  const auto n = static_cast<Eigen::Index>(n_);
  Vector& u = u_work_;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double u1 = std::max(uniform(), 1e-300);
    u(i) = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * uniform());
  }
  const double norm = u.norm();
  if (norm > 0.0) u /= norm;
  x_k_ = best_x_;
  x_k_ += config_.restart_radius * u;
  clamp(x_k_);
  cost_k_ = std::numeric_limits<double>::infinity();
  radius_ = config_.initial_radius;
  failures_ = 0;
  ++restarts_;
  phase_ = Phase::kBase;
}

void TrustRegionLeastSquares::probe_step() {
  const auto n = static_cast<Eigen::Index>(n_);
  const auto i = static_cast<Eigen::Index>(probe_);
  if (probe_ == 0) {
    probe_best_x_ = x_k_;
    probe_best_phi_ = phi_k_;
    probe_best_cost_ = cost_k_;
    probe_d_.setIdentity(n, n);
    probe_dphi_.setZero();
  }
  // x_k + Δ·q_i; the opposite direction when that leaves the box; clamped as a last resort.
  Vector& x = s_work_;
  x = x_k_;
  x += radius_ * basis_.col(i);
  bool inside = true;
  for (Eigen::Index k = 0; k < n; ++k) inside = inside && x(k) >= lower_(k) && x(k) <= upper_(k);
  if (!inside) {
    x = x_k_;
    x -= radius_ * basis_.col(i);
  }
  clamp(x);
  probe_d_.col(i) = x - x_k_;
  if (probe_d_.col(i).norm() < 1e-3 * radius_) {
    // Box too thin in this direction: no information, keep J's column at 0.
    probe_d_.col(i).setZero();
    probe_d_(i, i) = 1.0;
  } else if (evaluate(x, phi_work_)) {
    probe_dphi_.col(i) = phi_work_ - phi_k_;
    const double c = cost(phi_work_);
    if (c < probe_best_cost_) {
      probe_best_cost_ = c;
      probe_best_x_ = x;
      probe_best_phi_ = phi_work_;
    }
  } else {
    probe_dphi_.col(i).setZero();  // failed model: treat the direction as insensitive
  }
  if (++probe_ == n_) {
    // (2): J·D = ΔΦ  →  J = ΔΦ·D⁻¹.
    inverse_d_ = probe_d_.inverse();
    jacobian_.noalias() = probe_dphi_ * inverse_d_;
    jacobian_valid_ = true;
    if (probe_best_cost_ < cost_k_) {
      x_k_ = probe_best_x_;
      phi_k_ = probe_best_phi_;
      cost_k_ = probe_best_cost_;
    }
    failures_ = 0;
    phase_ = Phase::kIterate;
  }
}

void TrustRegionLeastSquares::compute_step(Vector& s, double& predicted) {
  // (3): Levenberg–Marquardt form of the trust-region Gauss–Newton step.
  const auto n = static_cast<Eigen::Index>(n_);
  Features& r = r_work_;
  r = (weight_.array() * (phi_k_ - target_).array()).matrix();
  wj_.noalias() = weight_.asDiagonal() * jacobian_;
  normal_.noalias() = wj_.transpose() * wj_;
  Vector& g = g_work_;
  g.noalias() = wj_.transpose() * r;
  eigen_.compute(normal_);
  Vector& lambda = lambda_work_;
  lambda = eigen_.eigenvalues().cwiseMax(0.0);
  Vector& b = b_work_;
  b.noalias() = eigen_.eigenvectors().transpose() * g;
  const double floor = kEigenFloor * std::max(lambda.maxCoeff(), 1e-300);
  Vector& c = c_work_;
  auto step_for = [&](double mu, Vector& out) {
    for (Eigen::Index k = 0; k < n; ++k) {
      const double denom = lambda(k) + mu;
      c(k) = (mu > 0.0 || lambda(k) > floor) && denom > 0.0 ? -b(k) / denom : 0.0;
    }
    out.noalias() = eigen_.eigenvectors() * c;
  };
  step_for(0.0, s);
  if (s.norm() > radius_) {
    double lo = 0.0;
    double hi = g.norm() / radius_;  // ‖s(μ)‖ ≤ ‖g‖/μ = Δ
    for (int it = 0; it < kBisections; ++it) {
      const double mid = 0.5 * (lo + hi);
      step_for(mid, s);
      if (s.norm() > radius_) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    step_for(hi, s);
  }
  s += x_k_;
  clamp(s);
  s -= x_k_;
  r.noalias() += wj_ * s;
  predicted = r.squaredNorm();
}

void TrustRegionLeastSquares::iterate_step() {
  Vector& s = u_work_;
  double predicted = 0.0;
  compute_step(s, predicted);
  const double step_norm = s.norm();
  if (!(cost_k_ - predicted > 1e-14 * std::max(cost_k_, 1e-300)) ||
      step_norm < 1e-3 * config_.min_radius) {
    // The model predicts no progress within Δ (stationary for the model, or the
    // box blocks it): shrink towards the finishing radius without evaluating.
    radius_ *= kShrink * kShrink;
    return;
  }
  Vector& x = s_work_;
  x = x_k_ + s;
  const bool ok = evaluate(x, phi_work_);
  const double c = ok ? cost(phi_work_) : std::numeric_limits<double>::infinity();
  const double rho = ok ? (cost_k_ - c) / (cost_k_ - predicted) : -1.0;
  if (ok) {
    // (5) Broyden's update along s.
    Features& residual = r_work_;
    residual = phi_work_ - phi_k_;
    residual.noalias() -= jacobian_ * s;
    jacobian_.noalias() += residual * (s.transpose() / s.squaredNorm());
  }
  if (rho < kRatioPoor) {
    radius_ = std::max(kShrink * std::min(radius_, step_norm), 0.5 * config_.min_radius);
    ++failures_;
  } else {
    if (rho > kRatioGood && step_norm >= 0.9 * radius_)
      radius_ = std::min(kGrow * radius_, config_.max_radius);
    failures_ = 0;
  }
  if (ok && c < cost_k_) {
    x_k_ = x;
    phi_k_ = phi_work_;
    cost_k_ = c;
  }
  if (failures_ >= config_.refresh_after_failures && radius_ >= config_.min_radius) {
    phase_ = Phase::kProbe;  // 5: rebuild J around x_k at the current radius
    probe_ = 0;
  }
}

}  // namespace model::calibration
