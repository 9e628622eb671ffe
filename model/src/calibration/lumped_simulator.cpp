#include "model/calibration/lumped_simulator.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace model::calibration {

namespace {
constexpr std::array<const char*, 3> kShafts = {"sun_shaft", "ims", "hss"};

double next_uniform(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return (static_cast<double>(z >> 11) + 0.5) * 0x1.0p-53;  // (0, 1)
}

using Mat3 = Eigen::Matrix3d;

Mat3 stiffness(const std::array<double, 3>& kb, const std::array<double, 3>& km) {
  Mat3 k = Mat3::Zero();
  for (int i = 0; i < 3; ++i) k(i, i) = kb[static_cast<std::size_t>(i)];
  k(0, 0) += km[0];  // sun–planet meshes to the (fixed-ring) planets
  const Eigen::Vector3d di(1.0, -1.0, 0.0), dh(0.0, 1.0, -1.0);
  k.noalias() += km[1] * di * di.transpose();  // intermediate stage: sun_shaft ↔ ims
  k.noalias() += km[2] * dh * dh.transpose();  // high-speed stage: ims ↔ hss
  return k;
}
}  // namespace

LumpedSimulator::LumpedSimulator(const Drivetrain& drivetrain, const LumpedSimulatorConfig& config)
    : kinematics_(drivetrain), config_(config) {
  for (std::size_t s = 0; s < 3; ++s) {
    for (const Gear& g : drivetrain.gears) {
      if (g.shaft == kShafts[s]) mass_kg_[s] += g.mass_kg;
    }
    if (const Shaft* shaft = drivetrain.shaft(kShafts[s])) {
      const double r = 0.5 * shaft->diameter_m;
      mass_kg_[s] += std::numbers::pi * r * r * shaft->length_m * 7850.0;
    }
    for (const Bearing& b : drivetrain.bearings) {
      // Per row, as the full model counts it (a paired or two-row set carries rows × k).
      if (b.shaft == kShafts[s]) bearing_n_m_[s] += b.radial_stiffness_n_m * b.rows;
    }
  }
  for (std::size_t s = 0; s < std::min<std::size_t>(3, drivetrain.stages.size()); ++s) {
    const GearStage& stage = drivetrain.stages[s];
    double width = 0.0;
    for (const std::string& id : stage.gears) {
      if (const Gear* g = drivetrain.gear(id))
        width = width == 0.0 ? g->face_width_m : std::min(width, g->face_width_m);
    }
    const double planets = stage.type == StageType::kPlanetary ? std::max(1, stage.planets) : 1;
    mesh_n_m_[s] = config.mesh_stiffness_per_width_n_m2 * width * planets;
  }
  rated_torque_nm_ =
      drivetrain.turbine.rated_torque_nm > 0.0 ? drivetrain.turbine.rated_torque_nm : 1.0;
  const auto capacity =
      static_cast<std::size_t>(std::ceil(config.sample_rate_hz * config.max_duration_s));
  for (auto& w : wave_) w.assign(capacity, 0.0);
}

std::array<double, 3> LumpedSimulator::natural_frequencies_hz(const DynamicsParameters& p) const {
  std::array<double, 3> kb{}, km{};
  for (std::size_t s = 0; s < 3; ++s) {
    kb[s] = bearing_n_m_[s] * p.bearing_stiffness_scale[s];
    km[s] = mesh_n_m_[s] * p.mesh_stiffness_scale[s];
  }
  const Mat3 k = stiffness(kb, km);
  const Eigen::Vector3d m(mass_kg_[0], mass_kg_[1], mass_kg_[2]);
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> es(k, Mat3(m.asDiagonal()));
  std::array<double, 3> f{};
  for (int i = 0; i < 3; ++i) {
    f[static_cast<std::size_t>(i)] =
        std::sqrt(std::max(0.0, es.eigenvalues()(i))) / (2.0 * std::numbers::pi);
  }
  return f;
}

bool LumpedSimulator::simulate(const DynamicsParameters& p, const OperatingPoint& op,
                               double duration_s,
                               std::array<WaveformView, kMeasurementPoints>& out) {
  const auto n = static_cast<std::size_t>(std::ceil(duration_s * config_.sample_rate_hz));
  if (n == 0 || n > wave_[0].size() || !(op.rotor_speed_rpm > 0.0) || !(p.rayleigh_eta >= 0.0) ||
      !(p.rayleigh_zeta >= 0.0) || kinematics_.stage_count() < 3) {
    return false;
  }
  std::array<double, 3> kb{}, km{};
  for (std::size_t s = 0; s < 3; ++s) {
    kb[s] = bearing_n_m_[s] * p.bearing_stiffness_scale[s];
    km[s] = mesh_n_m_[s] * p.mesh_stiffness_scale[s];
    if (!(kb[s] > 0.0) || !(km[s] > 0.0)) return false;
  }
  const Mat3 k = stiffness(kb, km);
  const Mat3 m = Eigen::Vector3d(mass_kg_[0], mass_kg_[1], mass_kg_[2]).asDiagonal();
  const Mat3 c = p.rayleigh_eta * m + p.rayleigh_zeta * k;
  const std::array<Eigen::Vector3d, 3> direction = {Eigen::Vector3d(1.0, 0.0, 0.0),
                                                    Eigen::Vector3d(1.0, -1.0, 0.0),
                                                    Eigen::Vector3d(0.0, 1.0, -1.0)};
  const double load = std::abs(op.input_torque_nm) / rated_torque_nm_;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) std::fill_n(wave_[pt].begin(), n, 0.0);
  const double dt = 1.0 / config_.sample_rate_hz;
  for (std::size_t s = 0; s < 3; ++s) {
    const double mesh_hz = kinematics_.mesh_hz(s, op.rotor_speed_rpm);
    for (std::size_t h = 1; h <= config_.harmonics; ++h) {
      const double w = 2.0 * std::numbers::pi * mesh_hz * static_cast<double>(h);
      if (w * dt >= std::numbers::pi) continue;  // above Nyquist: not representable
      const double te = config_.te_amplitude_m * load / static_cast<double>(h);
      const Eigen::Vector3cd f = (km[s] * te * direction[s]).cast<std::complex<double>>();
      const Eigen::Matrix3cd dyn = k.cast<std::complex<double>>() -
                                   w * w * m.cast<std::complex<double>>() +
                                   std::complex<double>(0.0, w) * c.cast<std::complex<double>>();
      const Eigen::Vector3cd y = dyn.partialPivLu().solve(f);
      const double phase = 0.7 * static_cast<double>(s) + 1.3 * static_cast<double>(h);
      // Sensors: point1 = hss (index 2), point2 = ims (index 1); acceleration = −ω²·y.
      const std::array<std::complex<double>, kMeasurementPoints> accel = {-w * w * y(2),
                                                                          -w * w * y(1)};
      const std::complex<double> step = std::polar(1.0, w * dt);
      for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
        const double amplitude = std::abs(accel[pt]);
        if (!std::isfinite(amplitude)) return false;
        if (amplitude == 0.0) continue;
        std::complex<double> rot = accel[pt] * std::polar(1.0, phase);
        double* dst = wave_[pt].data();
        for (std::size_t i = 0; i < n; ++i) {
          dst[i] += rot.real();
          rot *= step;
          if ((i & 1023) == 1023) rot *= amplitude / std::abs(rot);  // keep |rot| from drifting
        }
      }
    }
  }
  if (config_.noise_relative > 0.0) {
    std::uint64_t noise_state =
        config_.noise_seed;  // the same noise on every call: reproducible recordings
    for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) sum += wave_[pt][i] * wave_[pt][i];
      const double sigma = config_.noise_relative * std::sqrt(sum / static_cast<double>(n));
      for (std::size_t i = 0; i < n; ++i) {
        // Box–Muller.
        const double u1 = next_uniform(noise_state);
        const double u2 = next_uniform(noise_state);
        wave_[pt][i] +=
            sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
      }
    }
  }
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    out[pt] = {wave_[pt].data(), n, config_.sample_rate_hz};
  }
  return true;
}

}  // namespace model::calibration
