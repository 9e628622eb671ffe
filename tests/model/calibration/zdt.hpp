#pragma once
// ZDT1–3 (Zitzler, Deb, Thiele 2000, "Comparison of multiobjective
// evolutionary algorithms: empirical results", Evol. Comput. 8(2)) with their
// analytic Pareto fronts, and the inverted generational distance.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>
#include <vector>

#include "model/calibration/mogoa.hpp"

namespace zdt {

enum class Kind { kZdt1, kZdt2, kZdt3 };

class Problem : public model::calibration::MultiObjectiveProblem {
 public:
  explicit Problem(Kind kind, std::size_t n = 30) : kind_(kind), n_(n) {}
  std::size_t variables() const override { return n_; }
  std::size_t objectives() const override { return 2; }
  double lower(std::size_t) const override { return 0.0; }
  double upper(std::size_t) const override { return 1.0; }
  void evaluate(const double* x, double* f) override {
    double sum = 0.0;
    for (std::size_t i = 1; i < n_; ++i) sum += x[i];
    const double g = 1.0 + 9.0 * sum / static_cast<double>(n_ - 1);
    const double f1 = x[0];
    const double q = f1 / g;
    double h = 0.0;
    switch (kind_) {
      case Kind::kZdt1:
        h = 1.0 - std::sqrt(q);
        break;
      case Kind::kZdt2:
        h = 1.0 - q * q;
        break;
      case Kind::kZdt3:
        h = 1.0 - std::sqrt(q) - q * std::sin(10.0 * std::numbers::pi * f1);
        break;
    }
    f[0] = f1;
    f[1] = g * h;
  }

 private:
  Kind kind_;
  std::size_t n_;
};

/// Points of the analytic front (g = 1), uniformly in f1.
inline std::vector<std::pair<double, double>> true_front(Kind kind, std::size_t points = 500) {
  // ZDT3: the non-dominated pieces of f2 = 1 − √f1 − f1·sin(10πf1).
  static constexpr double kZdt3Pieces[5][2] = {{0.0, 0.0830015349},
                                               {0.1822287280, 0.2577623634},
                                               {0.4093136748, 0.4538821041},
                                               {0.6183967944, 0.6525117038},
                                               {0.8233317983, 0.8518328654}};
  std::vector<std::pair<double, double>> front;
  for (std::size_t i = 0; i < points; ++i) {
    double f1 = static_cast<double>(i) / static_cast<double>(points - 1);
    double f2 = 0.0;
    switch (kind) {
      case Kind::kZdt1:
        f2 = 1.0 - std::sqrt(f1);
        break;
      case Kind::kZdt2:
        f2 = 1.0 - f1 * f1;
        break;
      case Kind::kZdt3: {
        // Spread the points over the total length of the pieces.
        double total = 0.0;
        for (const auto& p : kZdt3Pieces) total += p[1] - p[0];
        double s = f1 * total;
        for (const auto& p : kZdt3Pieces) {
          if (s <= p[1] - p[0]) {
            f1 = p[0] + s;
            break;
          }
          s -= p[1] - p[0];
        }
        f2 = 1.0 - std::sqrt(f1) - f1 * std::sin(10.0 * std::numbers::pi * f1);
        break;
      }
    }
    front.emplace_back(f1, f2);
  }
  return front;
}

/// IGD: mean over the true front's points of the distance to the nearest archive member.
inline double igd(const model::calibration::Mogoa& mogoa,
                  const std::vector<std::pair<double, double>>& front) {
  double sum = 0.0;
  for (const auto& [a, b] : front) {
    double best = 1e300;
    for (std::size_t i = 0; i < mogoa.archive_count(); ++i) {
      const double d1 = mogoa.archive_objective(i, 0) - a;
      const double d2 = mogoa.archive_objective(i, 1) - b;
      best = std::min(best, std::sqrt(d1 * d1 + d2 * d2));
    }
    sum += best;
  }
  return sum / static_cast<double>(front.size());
}

}  // namespace zdt
