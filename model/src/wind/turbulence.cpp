#include "model/wind/turbulence.hpp"

#include <kissfft/kissfft.hh>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace model::wind {

namespace {
constexpr double kNtmOffsetMps = 5.6;        // [m/s] b of IEC 61400-1 ed. 3 eq. (11)
constexpr double kLambda1HighM = 42.0;       // [m] Λ1 for hub heights ≥ 60 m
constexpr double kLambda1HeightM = 60.0;     // [m]
constexpr double kLambda1Slope = 0.7;        // [-] Λ1 = 0.7·z below 60 m
constexpr double kKaimalLengthFactor = 8.1;  // [-] L = 8.1·Λ1 (Annex B, longitudinal)
constexpr std::size_t kMaxSamples = std::size_t{1} << 22;  // bound on one segment's FFT

bool is_valid_mean(double v) { return v > 0.0 && std::isfinite(v); }
}  // namespace

struct TurbulentWind::Fft {
  explicit Fft(std::size_t n) : plan(n, /*inverse=*/true) {}
  kissfft<double> plan;
};

double reference_turbulence_intensity(TurbulenceClass turbulence_class) {
  switch (turbulence_class) {
    case TurbulenceClass::kA:
      return 0.16;
    case TurbulenceClass::kB:
      return 0.14;
    case TurbulenceClass::kC:
      return 0.12;
  }
  return 0.16;
}

double ntm_sigma_mps(TurbulenceClass turbulence_class, double mean_wind_mps) {
  // IEC 61400-1:2005 §6.3.1.3 eq. (11): σ1 = I_ref·(0.75·V_hub + b), b = 5.6 m/s
  return reference_turbulence_intensity(turbulence_class) * (0.75 * mean_wind_mps + kNtmOffsetMps);
}

double kaimal_length_scale_m(double hub_height_m) {
  const double lambda1 =
      hub_height_m < kLambda1HeightM ? kLambda1Slope * hub_height_m : kLambda1HighM;
  return kKaimalLengthFactor * lambda1;
}

double kaimal_psd(double f_hz, double sigma_mps, double length_scale_m, double mean_wind_mps) {
  if (!(mean_wind_mps > 0.0)) return 0.0;
  const double time_scale = length_scale_m / mean_wind_mps;  // L/V [s]
  // IEC 61400-1:2005 Annex B eq. (B.14)
  return 4.0 * sigma_mps * sigma_mps * time_scale /
         std::pow(1.0 + 6.0 * f_hz * time_scale, 5.0 / 3.0);
}

double iec_coherence(double separation_m, double f_hz, double mean_wind_mps,
                     double coherence_scale_m) {
  // IEC 61400-1:2005 Annex B eq. (B.16)
  const double a = f_hz * separation_m / mean_wind_mps;
  const double b = 0.12 * separation_m / coherence_scale_m;
  return std::exp(-12.0 * std::sqrt(a * a + b * b));
}

double disc_distance_density(double distance_m, double radius_m) {
  if (!(distance_m > 0.0) || !(distance_m < 2.0 * radius_m)) return 0.0;
  const double x = distance_m / (2.0 * radius_m);
  return 4.0 * distance_m / (std::numbers::pi * radius_m * radius_m) *
         (std::acos(x) - x * std::sqrt(1.0 - x * x));
}

double rotor_admittance(double f_hz, double mean_wind_mps, double radius_m,
                        double coherence_scale_m) {
  if (!(radius_m > 0.0) || !(mean_wind_mps > 0.0)) return 1.0;
  // Composite Simpson over d ∈ [0, 2R]; p vanishes at both ends, as d at 0 and as
  // (2R − d)^(3/2) at 2R, so 256 intervals are ample (the tests check 1e-5).
  constexpr int kIntervals = 256;
  const double h = 2.0 * radius_m / kIntervals;
  double sum = 0.0;
  for (int i = 0; i <= kIntervals; ++i) {
    const double d = h * i;
    const double w = (i == 0 || i == kIntervals) ? 1.0 : (i % 2 != 0 ? 4.0 : 2.0);
    sum += w * disc_distance_density(d, radius_m) *
           iec_coherence(d, f_hz, mean_wind_mps, coherence_scale_m);
  }
  return sum * h / 3.0;
}

bool valid_turbulence_settings(const TurbulenceSettings& s, const char** what) {
  const char* problem = nullptr;
  if (!(s.hub_height_m > 0.0) || !std::isfinite(s.hub_height_m)) {
    problem = "hub height must be > 0";
  } else if (!(s.sample_period_s > 0.0) || !std::isfinite(s.sample_period_s)) {
    problem = "sample period must be > 0";
  } else if (!(s.segment_s >= 4.0 * s.sample_period_s) || !std::isfinite(s.segment_s)) {
    problem = "segment must be at least 4 sample periods";
  } else {
    const double n = s.segment_s / s.sample_period_s;
    const double rounded = std::round(n);
    if (std::abs(n - rounded) > 1e-9 * n || static_cast<std::size_t>(rounded) % 2 != 0) {
      problem = "segment / sample period must be an even whole number";
    } else if (rounded > static_cast<double>(kMaxSamples)) {
      problem = "segment / sample period is too large (more than 2^22 samples)";
    } else if (!(s.crossfade_s >= 0.0) || !(s.crossfade_s <= s.segment_s)) {
      problem = "cross-fade must be in [0, segment]";
    } else if (!(s.rotor_radius_m >= 0.0) || !std::isfinite(s.rotor_radius_m)) {
      problem = "rotor radius must be >= 0";
    }
  }
  if (what != nullptr) *what = problem;
  return problem == nullptr;
}

TurbulentWind::TurbulentWind(const TurbulenceSettings& settings, std::uint64_t seed)
    : settings_(settings), rng_(seed) {
  if (!valid_turbulence_settings(settings_, nullptr)) {
    // Unusable settings: one sample per segment at the mean (documented in the header).
    n_ = 1;
    previous_.u.assign(1, 0.0);
    current_.u.assign(1, 0.0);
    next_.u.assign(1, 0.0);
    return;
  }
  n_ = static_cast<std::size_t>(std::llround(settings_.segment_s / settings_.sample_period_s));
  fade_ = static_cast<std::size_t>(
      std::llround(0.5 * settings_.crossfade_s / settings_.sample_period_s));
  fade_ = std::min(fade_, n_ / 2);
  length_scale_m_ = kaimal_length_scale_m(settings_.hub_height_m);
  fft_ = std::make_unique<Fft>(n_);
  spectrum_.assign(n_, {0.0, 0.0});
  series_.assign(n_, {0.0, 0.0});
  previous_.u.assign(n_, 0.0);
  current_.u.assign(n_, 0.0);
  next_.u.assign(n_, 0.0);
}

TurbulentWind::~TurbulentWind() = default;

double TurbulentWind::uniform() {
  // 53 random bits → [0, 1), exact and identical on every platform.
  return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

void TurbulentWind::generate(Segment& segment, double mean_mps) {
  segment.mean_mps = is_valid_mean(mean_mps) ? mean_mps : 0.0;
  std::fill(segment.u.begin(), segment.u.end(), 0.0);
  if (!fft_ || segment.mean_mps <= 0.0) return;
  const double sigma = ntm_sigma_mps(settings_.turbulence_class, segment.mean_mps);
  const double df = 1.0 / settings_.segment_s;  // Δf = 1/T
  const std::size_t half = n_ / 2;
  // Variance of the discrete harmonic sum before scaling: Σ a_k²/2 = Σ S(f_k)·Δf.
  double variance = 0.0;
  for (std::size_t k = 1; k < half; ++k) {
    variance +=
        kaimal_psd(static_cast<double>(k) * df, sigma, length_scale_m_, segment.mean_mps) * df;
  }
  const double gain = variance > 0.0 ? sigma / std::sqrt(variance) : 0.0;
  std::fill(spectrum_.begin(), spectrum_.end(), std::complex<double>(0.0, 0.0));
  for (std::size_t k = 1; k < half; ++k) {
    const double f = static_cast<double>(k) * df;
    // Rotor-effective wind: the point spectrum times the disc admittance χ(f) (header).
    const double chi =
        settings_.rotor_radius_m > 0.0
            ? rotor_admittance(f, segment.mean_mps, settings_.rotor_radius_m, length_scale_m_)
            : 1.0;
    const double amplitude =
        gain * std::sqrt(2.0 * kaimal_psd(f, sigma, length_scale_m_, segment.mean_mps) * chi * df);
    const double phase = 2.0 * std::numbers::pi * uniform();
    // x_j = Σ_k X_k·e^{+2πijk/n} (kissfft inverse, unnormalised); with X_k = (a_k/2)·e^{iφ_k}
    // and X_{n−k} = conj(X_k): x_j = Σ_k a_k·cos(2πjk/n + φ_k).
    const std::complex<double> x = std::polar(0.5 * amplitude, phase);
    spectrum_[k] = x;
    spectrum_[n_ - k] = std::conj(x);
  }
  fft_->plan.transform(spectrum_.data(), series_.data());
  for (std::size_t j = 0; j < n_; ++j) segment.u[j] = series_[j].real();
}

void TurbulentWind::reset_neighbours() {
  current_.mean_mps = 0.0;
  have_next_ = false;
}

void TurbulentWind::advance(double current_mean_mps, double next_mean_mps) {
  const double cur = is_valid_mean(current_mean_mps) ? current_mean_mps : 0.0;
  std::swap(previous_, current_);
  if (have_next_ && next_.mean_mps == cur) {
    std::swap(current_, next_);
  } else {
    // First row, or after a gap: the previous row is not a neighbour.
    previous_.mean_mps = 0.0;
    generate(current_, cur);
  }
  generate(next_, next_mean_mps);
  have_next_ = true;
}

double TurbulentWind::wind_mps(std::size_t j) const {
  if (j >= n_) j = n_ - 1;
  const double own = current_.mean_mps;
  if (own <= 0.0) return 0.0;
  double mean = own;
  double u = current_.u[j];
  // Cross-fade windows of 2·fade_ samples centred on each boundary; x ∈ (0, 1).
  if (fade_ > 0 && j < fade_ && previous_.mean_mps > 0.0) {
    const double x = (static_cast<double>(j + fade_) + 0.5) / static_cast<double>(2 * fade_);
    const double angle = 0.5 * std::numbers::pi * x;
    mean = (1.0 - x) * previous_.mean_mps + x * own;
    u = std::cos(angle) * previous_.u[j] + std::sin(angle) * current_.u[j];
  } else if (fade_ > 0 && j >= n_ - fade_ && next_.mean_mps > 0.0) {
    const double x = (static_cast<double>(j - (n_ - fade_)) + 0.5) / static_cast<double>(2 * fade_);
    const double angle = 0.5 * std::numbers::pi * x;
    mean = (1.0 - x) * own + x * next_.mean_mps;
    u = std::cos(angle) * current_.u[j] + std::sin(angle) * next_.u[j];
  }
  return std::max(0.0, mean + u);
}

}  // namespace model::wind
