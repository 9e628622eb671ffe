// A recording bundle measured for calibration (calibration_measurement.hpp); moved here from
// app/cli/calibrate.cpp unchanged so that host tools measure a bundle as calibrate does.
#include "recording/calibration_measurement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/order_tracking.hpp"
#include "signal/speed_reference.hpp"

namespace app::recording {

namespace {

namespace mc = model::calibration;
namespace dsp = model::dsp;
namespace fs = std::filesystem;
using MeasurementError = BundleCheckError;

std::string describe_channel(const hal::Recording& rec, const fs::path& dir,
                             const std::string& channel) {
  return (dir / rec.samples_file).string() + ": channel '" + channel + "'";
}

// The recording's evidence for the speed reference (app/signal/speed_reference.hpp chooses):
// the hss tacho's pulses, the SCADA rotor speed, point 1 for the mesh line, the operating point.
app::signal::SpeedReference calibration_speed_reference(const hal::Recording& rec,
                                                        const fs::path& dir,
                                                        const model::Kinematics& k,
                                                        const std::vector<double>& point1,
                                                        dsp::FeatureExtractor& fx) {
  app::signal::SpeedEvidence e;
  e.min_pulses = fx.config().revolutions + 1;
  for (std::size_t c = 0; c < rec.channels.size() && e.hss_pulses_s.empty(); ++c) {
    const hal::BundleChannel& ch = rec.channels[c];
    if (ch.kind != "once_per_rev") continue;
    if (ch.location != "hss") {
      std::fprintf(stderr, "calibrate: note: tacho '%s' is on '%s', not the hss; not used\n",
                   ch.name.c_str(), ch.location.c_str());
      continue;
    }
    const std::size_t n = fx.tracker().detect_pulses(rec.samples[c].data(), rec.samples[c].size(),
                                                     rec.sample_rate_hz);
    if (n < e.min_pulses) {
      throw MeasurementError(describe_channel(rec, dir, ch.name) + ": tacho gives " +
                             std::to_string(n) + " pulses; the order resolution needs " +
                             std::to_string(e.min_pulses) +
                             " (a once-per-revolution pulse on the hss)");
    }
    e.hss_pulses_s.assign(fx.tracker().pulse_times(), fx.tracker().pulse_times() + n);
  }
  double sum = 0.0;
  std::size_t rows = 0;
  for (const hal::BundleScadaRow& r : rec.scada) {
    if (r.rotor_speed_rpm) {
      sum += *r.rotor_speed_rpm;
      ++rows;
    }
  }
  if (rows > 0) e.scada_rotor_rpm = sum / static_cast<double>(rows);
  e.point1 = point1.data();
  e.samples = point1.size();
  e.sample_rate_hz = rec.sample_rate_hz;
  e.nominal_rotor_rpm = rec.operating_point.rotor_speed_rpm;
  return app::signal::choose_speed_reference(e, k);
}

}  // namespace

CalibrationMeasurement measure_for_calibration(const fs::path& path, std::size_t max_windows,
                                               dsp::FeatureExtractor& fx,
                                               const std::string& drivetrain_override) {
  CalibrationMeasurement out;
  out.dir = path;
  const fs::path& dir = out.dir;
  out.bundle = load_bundle(dir, {drivetrain_override});
  const hal::Recording& rec = out.bundle.recording;
  const model::Drivetrain& drivetrain = out.bundle.drivetrain;
  const model::Kinematics kinematics(drivetrain);
  std::array<const std::vector<double>*, mc::kMeasurementPoints> wave{};
  std::array<std::string, mc::kMeasurementPoints> channel{};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    if (p >= drivetrain.measurement_points.size()) {
      throw MeasurementError("drivetrain '" + drivetrain.name +
                             "': measurement_points: calibration needs 2, found " +
                             std::to_string(drivetrain.measurement_points.size()));
    }
    channel[p] = drivetrain.measurement_points[p].channel;
    const auto idx = rec.channel_index(channel[p]);
    if (!idx) {
      throw MeasurementError((dir / "recording.json").string() + ": channels: no channel named '" +
                             channel[p] + "' (measurement point at " +
                             drivetrain.measurement_points[p].location + ")");
    }
    wave[p] = &rec.samples[*idx];
    const dsp::DspStatus q =
        dsp::check_waveform(wave[p]->data(), wave[p]->size(), fx.config().flat_threshold);
    if (q != dsp::DspStatus::kOk)
      throw MeasurementError(describe_channel(rec, dir, channel[p]) + ": " + dsp::to_string(q));
  }
  const app::signal::SpeedReference speed =
      calibration_speed_reference(rec, dir, kinematics, *wave[0], fx);
  out.speed_source = speed.source;
  out.hss_hz = speed.mean_hss_hz();
  const double fs_hz = rec.sample_rate_hz;
  const std::size_t revs = fx.config().revolutions;
  const std::size_t lines = fx.config().samples_per_rev * revs / 2 + 1;
  std::array<dsp::PointFeatures, mc::kMeasurementPoints> sum{};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) out.spectrum[p].assign(lines, 0.0);
  for (std::size_t w = 0; w < std::max<std::size_t>(max_windows, 1); ++w) {
    // Window w starts at the first pulse of its revolutions (tacho) or w·revs revolutions in.
    std::size_t first = 0;
    std::vector<double> pulses;
    if (!speed.pulses.empty()) {
      const std::size_t k0 = w * revs;
      if (k0 + revs + 1 > speed.pulses.size()) break;
      // Two samples before the pulse: the tracker's cubic needs the sample before it.
      first = static_cast<std::size_t>(std::max(0.0, std::floor(speed.pulses[k0] * fs_hz) - 2.0));
      const double t0 = static_cast<double>(first) / fs_hz;
      for (std::size_t k = k0; k < speed.pulses.size(); ++k) pulses.push_back(speed.pulses[k] - t0);
    } else {
      first = static_cast<std::size_t>(
          std::floor(static_cast<double>(w * revs) / speed.hss_hz * fs_hz));
    }
    const dsp::SpeedReference ref{pulses.empty() ? nullptr : pulses.data(), pulses.size(),
                                  speed.hss_hz};
    std::array<dsp::PointFeatures, mc::kMeasurementPoints> f{};
    bool ok = true;
    for (std::size_t p = 0; p < mc::kMeasurementPoints && ok; ++p) {
      const std::size_t n = wave[p]->size() > first ? wave[p]->size() - first : 0;
      const dsp::DspStatus s = fx.extract(wave[p]->data() + first, n, fs_hz, ref, f[p]);
      if (s == dsp::DspStatus::kTooShort && w > 0) {
        ok = false;  // no room for another window
        break;
      }
      if (s == dsp::DspStatus::kTooShort) {
        char text[160];
        std::snprintf(text, sizeof text,
                      ": recording of %.2f s is too short: %zu hss revolutions (order resolution "
                      "1/%zu) need %.2f s",
                      static_cast<double>(wave[p]->size()) / fs_hz, revs, revs,
                      fx.required_duration_s(out.hss_hz));
        throw MeasurementError(describe_channel(rec, dir, channel[p]) + text);
      }
      if (s != dsp::DspStatus::kOk)
        throw MeasurementError(describe_channel(rec, dir, channel[p]) + ": " + dsp::to_string(s));
      for (std::size_t k = 0; k < lines; ++k)
        out.spectrum[p][k] += fx.order_spectrum()[k] * fx.order_spectrum()[k];
    }
    if (!ok) break;
    for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
      sum[p].count = f[p].count;
      sum[p].rms += f[p].rms * f[p].rms;
      for (std::size_t i = 0; i < f[p].count; ++i) {
        sum[p].amplitude[i] += f[p].amplitude[i] * f[p].amplitude[i];
        sum[p].noise_floor[i] += f[p].noise_floor[i] * f[p].noise_floor[i];
        sum[p].separable[i] = f[p].separable[i];
      }
    }
    ++out.windows;
  }
  const double nw = static_cast<double>(out.windows);
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    for (double& a : out.spectrum[p]) a = std::sqrt(a / nw);
    dsp::PointFeatures& m = out.measured.measured[p];
    m = sum[p];
    m.rms = std::sqrt(sum[p].rms / nw);
    for (std::size_t i = 0; i < m.count; ++i) {
      m.amplitude[i] = std::sqrt(sum[p].amplitude[i] / nw);
      m.noise_floor[i] = std::sqrt(sum[p].noise_floor[i] / nw);
      m.resolved[i] = m.separable[i] && m.amplitude[i] > 0.0 &&
                      m.amplitude[i] >= fx.config().resolved_ratio * m.noise_floor[i];
    }
    if (m.resolved_count() < mc::kMinTones) {
      throw MeasurementError(describe_channel(rec, dir, channel[p]) + ": only " +
                             std::to_string(m.resolved_count()) + " of " + std::to_string(m.count) +
                             " mesh harmonics stand out of the noise; f2/f3 need at least " +
                             std::to_string(mc::kMinTones));
    }
  }
  out.measured.op.rotor_speed_rpm = out.hss_hz / kinematics.overall_ratio() * 60.0;
  out.measured.op.input_torque_nm = out.bundle.input_torque_nm;
  return out;
}

}  // namespace app::recording
