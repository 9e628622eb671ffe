#pragma once
// The steady-state answer of a linear time-invariant model to one harmonic force, solved in
// the frequency domain: the independent expectation the time integrators (Newmark, ROM) are
// checked against when the meshes carry only a transmission error (constant stiffness).
#include <Eigen/Dense>

#include <complex>

#include "model/dynamics/full_model.hpp"

namespace model::dynamics::frequency_response {

/// Acceleration amplitude [m/s²] read by sensor `sensor` when the force
/// amplitude·cos(2πft)·pattern acts on the model: ω²·|rowᵀ(K̄ − ω²M + iωC)⁻¹ pattern|·amplitude.
inline double sensor_response(const FullModel& m, const Eigen::VectorXd& pattern, double amplitude,
                              double frequency_hz, int sensor) {
  const double w = 2.0 * 3.14159265358979323846 * frequency_hz;
  Eigen::MatrixXcd a = m.stiffness.cast<std::complex<double>>();
  a.diagonal() -= (w * w * m.mass).cast<std::complex<double>>();
  a += std::complex<double>(0.0, w) * m.damping().cast<std::complex<double>>();
  const Eigen::VectorXcd x = a.partialPivLu().solve(pattern.cast<std::complex<double>>());
  const std::complex<double> reading =
      m.sensors[static_cast<std::size_t>(sensor)].row.cast<std::complex<double>>().dot(x);
  return w * w * std::abs(reading) * amplitude;
}

}  // namespace model::dynamics::frequency_response
