// ISO 10816-21 broadband evaluation: see vibration_zones.hpp.
#include "supervisor/vibration_zones.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace app::supervisor {

loop::VibrationZone zone_of(double value, double bc, double cd) {
  if (!(value >= 0.0)) return loop::VibrationZone::kUnknown;
  if (value < bc) return loop::VibrationZone::kAB;
  if (value < cd) return loop::VibrationZone::kC;
  return loop::VibrationZone::kD;
}

namespace {
// Bilinear transform of the analogue Butterworth prototype, corner pre-warped:
// K = tan(π fc / fs), Q = 1/√2 (RBJ audio-EQ cookbook form).
Biquad butterworth(double fc, double fs, bool high) {
  const double k = std::tan(std::numbers::pi * std::min(fc, 0.49 * fs) / fs);
  const double q = std::numbers::sqrt2 / 2.0;
  const double norm = 1.0 / (1.0 + k / q + k * k);
  Biquad b;
  if (high) {
    b.b0 = norm;
    b.b1 = -2.0 * norm;
    b.b2 = norm;
  } else {
    b.b0 = k * k * norm;
    b.b1 = 2.0 * b.b0;
    b.b2 = b.b0;
  }
  b.a1 = 2.0 * (k * k - 1.0) * norm;
  b.a2 = (1.0 - k / q + k * k) * norm;
  return b;
}
}  // namespace

Biquad butterworth_lowpass(double fc_hz, double fs_hz) { return butterworth(fc_hz, fs_hz, false); }
Biquad butterworth_highpass(double fc_hz, double fs_hz) { return butterworth(fc_hz, fs_hz, true); }

VibrationZones::VibrationZones(const ZoneLimits& limits, double sample_rate_hz)
    : limits_(limits), fs_(sample_rate_hz) {
  hf_hp_ = butterworth_highpass(10.0, fs_);
  hf_lp_ = butterworth_lowpass(2000.0, fs_);
  v_hp1_ = butterworth_highpass(10.0, fs_);
  v_hp2_ = butterworth_highpass(10.0, fs_);
  v_lp_ = butterworth_lowpass(1000.0, fs_);
  // 0.1–10 Hz on block means at about 100 Hz (the mean's first null is at 100 Hz, its
  // response at 10 Hz 0.98: enough ahead of a 10 Hz low-pass).
  lf_decimation_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::floor(fs_ / 100.0)));
  lf_fs_ = fs_ / static_cast<double>(lf_decimation_);
  lf_hp_ = butterworth_highpass(0.1, lf_fs_);
  lf_lp_ = butterworth_lowpass(10.0, lf_fs_);
  hf_expected_ = static_cast<std::size_t>(std::llround(limits_.hf_interval_s * fs_));
  lf_expected_ = static_cast<std::size_t>(std::llround(limits_.lf_interval_s * fs_));
}

void VibrationZones::end_hf_interval() {
  const double n = static_cast<double>(hf_n_);
  if (hf_n_ > 0 && n >= kMinCoverage * static_cast<double>(hf_expected_)) {
    accel_hf_ = std::sqrt(hf_sum2_ / n);
    velocity_mmps_ = 1e3 * std::sqrt(v_sum2_ / n);
    const double mean = raw_sum1_ / n;
    // Central moments from the raw sums.
    const double m2 = raw_sum2_ / n - mean * mean;
    const double m4 = raw_sum4_ / n - 4.0 * mean * raw_sum3_ / n +
                      6.0 * mean * mean * raw_sum2_ / n - 3.0 * mean * mean * mean * mean;
    rms_ = std::sqrt(std::max(m2, 0.0));
    kurtosis_ = m2 > 0.0 ? m4 / (m2 * m2) : -1.0;
  } else {
    accel_hf_ = velocity_mmps_ = rms_ = kurtosis_ = -1.0;
  }
  ++hf_intervals_;
  hf_sum2_ = v_sum2_ = raw_sum1_ = raw_sum2_ = raw_sum3_ = raw_sum4_ = 0.0;
  hf_n_ = 0;
  hf_clock_ = 0;
}

void VibrationZones::end_lf_interval() {
  // Coverage counted in input samples: lf_n_ block means of lf_decimation_ samples each.
  const double n_in = static_cast<double>(lf_n_ * lf_decimation_);
  accel_lf_ = lf_n_ > 0 && n_in >= kMinCoverage * static_cast<double>(lf_expected_)
                  ? std::sqrt(lf_sum2_ / static_cast<double>(lf_n_))
                  : -1.0;
  lf_sum2_ = 0.0;
  lf_n_ = 0;
  lf_clock_ = 0;
}

void VibrationZones::add(const float* samples, std::size_t n, std::size_t lost_before) {
  if (fs_ <= 0.0) return;
  if (lost_before > 0) {
    // Time passes without samples; interval ends inside the gap still happen.
    for (std::size_t left = lost_before; left > 0;) {
      const std::size_t to_hf = hf_expected_ - hf_clock_, to_lf = lf_expected_ - lf_clock_;
      const std::size_t step = std::min({left, to_hf, to_lf});
      hf_clock_ += step;
      lf_clock_ += step;
      left -= step;
      if (hf_clock_ >= hf_expected_) end_hf_interval();
      if (lf_clock_ >= lf_expected_) end_lf_interval();
    }
    hf_hp_.reset();
    hf_lp_.reset();
    v_hp1_.reset();
    v_hp2_.reset();
    v_lp_.reset();
    v_prev_in_ = v_integral_ = 0.0;
    lf_hp_.reset();
    lf_lp_.reset();
    lf_block_sum_ = 0.0;
    lf_block_n_ = 0;
  }
  const double dt2 = 0.5 / fs_;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(samples[i]);
    // Broadband moments (mean removed at the interval's end).
    const double x2 = x * x;
    raw_sum1_ += x;
    raw_sum2_ += x2;
    raw_sum3_ += x2 * x;
    raw_sum4_ += x2 * x2;
    const double a = hf_lp_.step(hf_hp_.step(x));
    hf_sum2_ += a * a;
    const double h = v_hp1_.step(x);
    v_integral_ += dt2 * (h + v_prev_in_);
    v_prev_in_ = h;
    const double v = v_lp_.step(v_hp2_.step(v_integral_));
    v_sum2_ += v * v;
    ++hf_n_;
    lf_block_sum_ += x;
    if (++lf_block_n_ == lf_decimation_) {
      const double m =
          lf_lp_.step(lf_hp_.step(lf_block_sum_ / static_cast<double>(lf_decimation_)));
      lf_sum2_ += m * m;
      ++lf_n_;
      lf_block_sum_ = 0.0;
      lf_block_n_ = 0;
    }
    if (++hf_clock_ >= hf_expected_) end_hf_interval();
    if (++lf_clock_ >= lf_expected_) end_lf_interval();
  }
}

namespace {
float value_or_nan(double v) { return v >= 0.0 ? static_cast<float>(v) : loop::kNoValue; }
}  // namespace

void VibrationZones::fill(loop::PointSnapshot& out) const {
  out.accel_rms_10_2000_mps2 = value_or_nan(accel_hf_);
  out.velocity_rms_10_1000_mmps = value_or_nan(velocity_mmps_);
  out.accel_rms_01_10_mps2 = value_or_nan(accel_lf_);
  out.rms_mps2 = value_or_nan(rms_);
  out.kurtosis = value_or_nan(kurtosis_);
  out.zone = zone();
}

loop::VibrationZone VibrationZones::zone() const {
  const loop::VibrationZone zones[3] = {
      zone_of(accel_hf_, limits_.accel_hf_bc_mps2, limits_.accel_hf_cd_mps2),
      zone_of(velocity_mmps_, limits_.velocity_bc_mmps, limits_.velocity_cd_mmps),
      zone_of(accel_lf_, limits_.accel_lf_bc_mps2, limits_.accel_lf_cd_mps2)};
  // The worst evaluated band; unknown only when no band has a value yet.
  loop::VibrationZone worst = loop::VibrationZone::kUnknown;
  for (const loop::VibrationZone z : zones)
    if (static_cast<int>(z) > static_cast<int>(worst)) worst = z;
  return worst;
}

}  // namespace app::supervisor
