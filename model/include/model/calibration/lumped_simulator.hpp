#pragma once
// A lumped stand-in for the dynamics ROM: the lateral (line-of-action)
// vibration of the three parallel shafts of a planetary + two-parallel-stage
// gearbox, excited by the transmission error of every mesh.
//
// Degrees of freedom y = (y_sun_shaft, y_ims, y_hss) [m], each shaft a rigid
// mass on its bearings (Σ k_a of its bearings × bearing_stiffness_scale), the
// meshes springs along their lines of action (k_mesh × mesh_stiffness_scale):
//
//   M ÿ + C ẏ + K y = F(t),    C = η M + ζ K          (Rayleigh damping)
//   K = diag(k_b) + k_p e1e1ᵀ + k_i (e1 − e2)(e1 − e2)ᵀ + k_h (e2 − e3)(e2 − e3)ᵀ
//   F(t) = Σ_stages k_s · e_s(t) · d_s,  d_p = e1, d_i = e1 − e2, d_h = e2 − e3
//   e_s(t) = Σ_h E_s,h · cos(h·ω_s·t + φ_s,h)      (static transmission error,
//            E_s,h = TE amplitude × torque / rated torque, decaying 1/h)
//
// Mean mesh stiffness per unit face width c_γ = 20 N/(mm·µm) (ISO 6336-1,
// §9, the single-stiffness value for steel spur/helical gears), k_s = c_γ·b
// (× number of planets for the sun–planet meshes). The steady state is solved
// per excitation line in the frequency domain, Y(ω) = (K − ω²M + iωC)⁻¹ F,
// and the sensors read the radial accelerations −ω²Y of the hss (point1, b5)
// and the ims (point2, b3), synthesised into waveforms at `sample_rate_hz`.
// Time-varying mesh stiffness (parametric excitation), the planet DOFs and
// the housing are left out: this is the cheap model for developing and
// testing the calibrator, not the twin's dynamics.
//
// Thread context: construct at start-up (allocates the waveform buffers for
// max_duration_s); simulate() is allocation-free; one owning thread.

#include <array>
#include <cstdint>
#include <vector>

#include "model/calibration/simulator.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"

namespace model::calibration {

/// Rayleigh damping the stand-in starts from when a description carries none
/// (paper-2mw publishes no damping): modal damping ratios of 1–3 % between
/// the first mode (~270 Hz) and the third harmonic of the high-speed mesh.
inline constexpr double kNominalRayleighEta_1_s = 2.0;  // [1/s]
inline constexpr double kNominalRayleighZeta_s = 2e-5;  // [s]

/// `p` with the nominal damping above when both of its Rayleigh coefficients are zero.
inline DynamicsParameters with_nominal_damping(DynamicsParameters p) {
  if (p.rayleigh_eta == 0.0 && p.rayleigh_zeta == 0.0) {
    p.rayleigh_eta = kNominalRayleighEta_1_s;
    p.rayleigh_zeta = kNominalRayleighZeta_s;
  }
  return p;
}

struct LumpedSimulatorConfig {
  double sample_rate_hz = 8192.0;                 // [Hz]
  double max_duration_s = 16.0;                   // [s] buffer capacity
  std::size_t harmonics = 3;                      // [-] TE harmonics per mesh
  double te_amplitude_m = 5e-6;                   // [m] fundamental TE at rated torque
  double mesh_stiffness_per_width_n_m2 = 2.0e10;  // [N/m per m face width] c_γ
  double noise_relative = 0.0;   // [-] white noise added, RMS as a fraction of each
                                 //     point's noise-free RMS (synthetic recordings only)
  std::uint64_t noise_seed = 1;  // the same noise sequence on every simulate() call
};

class LumpedSimulator : public VibrationSimulator {
 public:
  /// @param drivetrain must outlive the simulator (the kinematics refer to it)
  LumpedSimulator(const Drivetrain& drivetrain, const LumpedSimulatorConfig& config);

  bool simulate(const DynamicsParameters& params, const OperatingPoint& op, double duration_s,
                std::array<WaveformView, kMeasurementPoints>& out) override;

  /// Undamped natural frequencies of the nominal system [Hz], ascending.
  std::array<double, 3> natural_frequencies_hz(const DynamicsParameters& params) const;

 private:
  Kinematics kinematics_;
  LumpedSimulatorConfig config_;
  std::array<double, 3> mass_kg_{};
  std::array<double, 3> bearing_n_m_{};
  std::array<double, 3> mesh_n_m_{};
  double rated_torque_nm_ = 1.0;
  std::array<std::vector<double>, kMeasurementPoints> wave_;
};

}  // namespace model::calibration
