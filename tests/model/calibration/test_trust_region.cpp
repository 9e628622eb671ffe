// The derivative-free least-squares trust region (trust_region.hpp) on maps
// whose least-squares solution is known independently: a linear map (normal
// equations solved here by QR), Rosenbrock's function as a residual vector
// (Moré, Garbow & Hillstrom 1981, problem 1: minimum at (1, 1)).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <vector>

#include "model/calibration/trust_region.hpp"

namespace {

using model::calibration::FeatureMap;
using model::calibration::TrustRegionConfig;
using model::calibration::TrustRegionLeastSquares;

// φ(x) = A x + c with 5 features of 3 variables, box [−2, 2]³.
struct LinearMap : FeatureMap {
  Eigen::Matrix<double, 5, 3> a;
  Eigen::Matrix<double, 5, 1> c;
  std::vector<Eigen::Vector3d> visited;
  LinearMap() {
    a << 1.0, 0.2, -0.3,  //
        0.4, 1.5, 0.1,    //
        -0.2, 0.3, 0.9,   //
        0.7, -0.5, 0.2,   //
        0.1, 0.1, 0.1;
    c << 0.3, -0.1, 0.2, 0.0, 0.5;
  }
  std::size_t variables() const override { return 3; }
  std::size_t features() const override { return 5; }
  double lower(std::size_t) const override { return -2.0; }
  double upper(std::size_t) const override { return 2.0; }
  bool evaluate(const double* x, double* phi) override {
    const Eigen::Vector3d v(x[0], x[1], x[2]);
    visited.push_back(v);
    Eigen::Map<Eigen::Matrix<double, 5, 1>> out(phi);
    out = a * v + c;
    return true;
  }
};

// Rosenbrock as least squares: φ = (10·(x2 − x1²), x1), target (0, 1).
struct RosenbrockMap : FeatureMap {
  std::size_t variables() const override { return 2; }
  std::size_t features() const override { return 2; }
  double lower(std::size_t) const override { return -5.0; }
  double upper(std::size_t) const override { return 5.0; }
  bool evaluate(const double* x, double* phi) override {
    phi[0] = 10.0 * (x[1] - x[0] * x[0]);
    phi[1] = x[0];
    return true;
  }
};

TEST(TrustRegionLeastSquares, LandsOnTheLeastSquaresSolutionOfALinearMapRightAfterItsProbes) {
  // Arrange: target φ* = A x_t + c + e, with e outside A's range so the fit is not exact;
  // the least-squares solution x* = argmin ‖A x + c − φ*‖ from the normal equations (QR here).
  LinearMap map;
  const Eigen::Vector3d x_t(0.2, -0.1, 0.15);
  Eigen::Matrix<double, 5, 1> e;
  e << 0.01, -0.02, 0.0, 0.015, -0.01;
  const Eigen::Matrix<double, 5, 1> target = map.a * x_t + map.c + e;
  const Eigen::Vector3d x_star = map.a.colPivHouseholderQr().solve(target - map.c);
  const std::array<double, 5> w{1.0, 1.0, 1.0, 1.0, 1.0};
  TrustRegionConfig cfg;
  cfg.initial_radius =
      0.5;  // x* is within 0.5 of the start: the first step is the full Gauss–Newton step
  cfg.restarts = false;
  TrustRegionLeastSquares tr(map, cfg);
  ASSERT_TRUE(tr.config_ok());
  tr.set_target(target.data(), w.data());
  const std::array<double, 3> x0{0.0, 0.0, 0.0};
  // Act: the base point, 3 probes, one step.
  tr.start(x0.data());
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(tr.step());
  // Assert: probes of a linear map give its exact Jacobian, so the 5th evaluation is x*.
  ASSERT_EQ(map.visited.size(), 5u);
  EXPECT_NEAR((map.visited[4] - x_star).norm(), 0.0, 1e-9);
  for (int r = 0; r < 5; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(tr.jacobian()(r, c), map.a(r, c), 1e-9);
  }
}

TEST(TrustRegionLeastSquares, FindsTheMinimumOfRosenbrocksFunctionFromTheClassicStart) {
  // Arrange: start (−1.2, 1) (Moré, Garbow & Hillstrom 1981); minimum F = 0 at (1, 1).
  RosenbrockMap map;
  const std::array<double, 2> target{0.0, 1.0};
  const std::array<double, 2> w{1.0, 1.0};
  TrustRegionConfig cfg;
  cfg.max_evaluations = 200;
  cfg.min_radius = 1e-7;
  cfg.restarts = false;
  TrustRegionLeastSquares tr(map, cfg);
  tr.set_target(target.data(), w.data());
  const std::array<double, 2> x0{-1.2, 1.0};
  // Act
  tr.start(x0.data());
  while (tr.step()) {
  }
  // Assert
  EXPECT_TRUE(tr.finished());
  EXPECT_NEAR(tr.best_x()(0), 1.0, 1e-4);
  EXPECT_NEAR(tr.best_x()(1), 1.0, 2e-4);
  EXPECT_LT(tr.best_cost(), 1e-8);
  EXPECT_LT(tr.evaluations(), 200u);
}

TEST(TrustRegionLeastSquares, AGivenJacobianSkipsTheProbesAndTheFirstStepIsAlreadyTheSolution) {
  // Arrange: the linear map's exact Jacobian, as a previous calibration would hand over.
  LinearMap map;
  const Eigen::Matrix<double, 5, 1> target = map.a * Eigen::Vector3d(0.1, 0.2, -0.1) + map.c;
  const std::array<double, 5> w{1.0, 1.0, 1.0, 1.0, 1.0};
  TrustRegionLeastSquares::Jacobian j = map.a;  // features() × variables()
  TrustRegionLeastSquares tr(map, TrustRegionConfig{});
  tr.set_target(target.data(), w.data());
  const std::array<double, 3> x0{0.0, 0.0, 0.0};
  // Act
  tr.start(x0.data(), &j);
  ASSERT_TRUE(tr.step());  // x0
  ASSERT_TRUE(tr.step());  // the Gauss–Newton step
  // Assert
  ASSERT_EQ(map.visited.size(), 2u);
  EXPECT_NEAR((map.visited[1] - Eigen::Vector3d(0.1, 0.2, -0.1)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(tr.best_cost(), 0.0, 1e-18);
}

TEST(TrustRegionLeastSquares, IsDeterministicUnderASeedAndTheSeedRotatesTheProbes) {
  auto run = [](std::uint64_t seed) {
    RosenbrockMap rosen;
    struct Recording : FeatureMap {
      FeatureMap* inner = nullptr;
      std::vector<std::array<double, 2>> visited;
      std::size_t variables() const override { return 2; }
      std::size_t features() const override { return 2; }
      double lower(std::size_t i) const override { return inner->lower(i); }
      double upper(std::size_t i) const override { return inner->upper(i); }
      bool evaluate(const double* x, double* phi) override {
        visited.push_back({x[0], x[1]});
        return inner->evaluate(x, phi);
      }
    } map;
    map.inner = &rosen;
    const std::array<double, 2> target{0.0, 1.0};
    const std::array<double, 2> w{1.0, 1.0};
    TrustRegionConfig cfg;
    cfg.seed = seed;
    cfg.max_evaluations = 30;
    TrustRegionLeastSquares tr(map, cfg);
    tr.set_target(target.data(), w.data());
    const std::array<double, 2> x0{-1.2, 1.0};
    tr.start(x0.data());
    while (tr.step()) {
    }
    return map.visited;
  };
  const auto a = run(3);
  const auto b = run(3);
  const auto c = run(4);
  const auto axes = run(0);
  EXPECT_EQ(a, b);
  ASSERT_GE(a.size(), 2u);
  ASSERT_GE(c.size(), 2u);
  EXPECT_NE(a[1], c[1]);
  // Seed 0 probes along the first axis by the initial radius.
  EXPECT_DOUBLE_EQ(axes[1][0], -1.2 + TrustRegionConfig{}.initial_radius);
  EXPECT_DOUBLE_EQ(axes[1][1], 1.0);
}

}  // namespace
