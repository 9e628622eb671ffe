// The ROM's step map with the carrier frozen, written from rom.hpp's equations (not from the
// kernel), and its spectral radius at every carrier angle: pure linear algebra on the ROM's
// data (a general eigensolver and 4×4 matrix exponentials, the most expensive code of the
// test suite to compile). It does not depend on the platform, so it runs natively only
// (tests/model/dynamics/CMakeLists.txt); the ROM's own stepping at those rates runs in every
// tier (test_rom.cpp, RomStability).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/rom.hpp"
#include "paper_models.hpp"

namespace {

using namespace model::dynamics;

using test_support::quiet_model;
using test_support::quiet_paper;

// Below 4096 Hz the ROM diverged once the planets turned with the carrier (docs/run.md, known
// problems): the turning mesh's stiffness along its direction at ψ, less its mean along the
// direction at 0, is a large, indefinite change of the modal stiffness, and the first-order
// hold couples it through modes the step cannot resolve (ω·Δt near and above π). Those modes
// are now quasi-static (rom.hpp, "Stability"). These tests run the ROM where it diverged.

// The step's map of (q, v) over one step with the carrier frozen at ψ, written from the
// equations in rom.hpp (not from the kernel): q⁺ = P_qq q + P_qv v + B0q g + B1q g⁺, the same
// for v, g = −D(ψ) q with D(ψ) = k̄_r (W_r(ψ)W_r(ψ)ᵀ − W_r(0)W_r(0)ᵀ) (constant meshes).
// `all_dynamic`: every mode by its first-order-hold exponential propagator, as before the fix.
double frozen_step_radius(const RomData& d, double psi_rev, bool all_dynamic) {
  const int n = d.eigenmodes + d.correction_vectors, r = d.turning_mesh;
  const double psi = 2.0 * std::numbers::pi * psi_rev;
  const Eigen::VectorXd c = d.w_basis.col(r).head(n), a = d.w_basis.col(kRomMeshes).head(n),
                        b = d.w_basis.col(kRomMeshes + 1).head(n);
  const Eigen::VectorXd w_psi = c + std::cos(psi) * a + std::sin(psi) * b, w_0 = c + a;
  const Eigen::MatrixXd dk =
      d.mesh_mean_n_m[r] * (w_psi * w_psi.transpose() - w_0 * w_0.transpose());
  Eigen::VectorXd pqq = d.pqq.head(n), pqv = d.pqv.head(n), pvq = d.pvq.head(n),
                  pvv = d.pvv.head(n), b0q = d.b0q.head(n), b1q = d.b1q.head(n),
                  b0v = d.b0v.head(n), b1v = d.b1v.head(n);
  if (all_dynamic) {
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
      m(0, 1) = 1.0;
      m(1, 0) = -d.omega2[i];
      m(1, 1) = -d.damping_1_s[i];
      m(1, 2) = 1.0;
      m(2, 3) = 1.0;
      const Eigen::Matrix4d e = (m * d.dt_s).exp();
      pqq[i] = e(0, 0), pqv[i] = e(0, 1), pvq[i] = e(1, 0), pvv[i] = e(1, 1);
      b0q[i] = e(0, 2) - e(0, 3) / d.dt_s, b1q[i] = e(0, 3) / d.dt_s;
      b0v[i] = e(1, 2) - e(1, 3) / d.dt_s, b1v[i] = e(1, 3) / d.dt_s;
    }
  }
  const Eigen::MatrixXd lhs = Eigen::MatrixXd::Identity(n, n) + b1q.asDiagonal() * dk;
  const Eigen::MatrixXd mqq =
      lhs.partialPivLu().solve(Eigen::MatrixXd(pqq.asDiagonal()) - b0q.asDiagonal() * dk);
  const Eigen::MatrixXd mqv = lhs.partialPivLu().solve(Eigen::MatrixXd(pqv.asDiagonal()));
  Eigen::MatrixXd map(2 * n, 2 * n);
  map << mqq, mqv,
      Eigen::MatrixXd(pvq.asDiagonal()) - b0v.asDiagonal() * dk - b1v.asDiagonal() * dk * mqq,
      Eigen::MatrixXd(pvv.asDiagonal()) - b1v.asDiagonal() * dk * mqv;
  return Eigen::EigenSolver<Eigen::MatrixXd>(map, false).eigenvalues().cwiseAbs().maxCoeff();
}

TEST(RomStability, TheFrozenStepMapHasNoGrowingModeAtAnyCarrierAngle) {
  // The carrier turns slowly (0.25 Hz at rated speed) against the step rates, so the step's
  // map with ψ frozen decides stability: its spectral radius must stay ≤ 1 at every ψ. With
  // every mode dynamic (before the fix) it exceeds 1 near ψ = π: the cause of the divergence.
  const FullModel m = quiet_model();
  for (const auto& [rate, cutoff] : std::array<std::pair<double, double>, 4>{
           {{512, 60}, {1024, 150}, {2048, 600}, {8192, 2200}}}) {
    std::string error;
    const auto data = build_rom(m, 1.0 / rate, cutoff, &error);
    ASSERT_TRUE(data) << error;
    double worst = 0.0, worst_before = 0.0;
    for (int k = 0; k < 8; ++k) {  // every 45°, π among them
      worst = std::max(worst, frozen_step_radius(*data, k / 8.0, false));
      worst_before = std::max(worst_before, frozen_step_radius(*data, k / 8.0, true));
    }
    EXPECT_LE(worst, 1.0) << rate << " Hz, cut-off " << cutoff << " Hz";
    if (rate <= 2048) {
      EXPECT_GT(worst_before, 1.0) << rate << " Hz, cut-off " << cutoff << " Hz";
    }
  }
}

}  // namespace
