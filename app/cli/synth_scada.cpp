// `drivetwin synth-scada --years N --out FILE`: a deterministic synthetic SCADA history
// (10-minute rows by default) with given site wind statistics, for history-mode runs
// over years (`drivetwin damage`).
//
// Wind: 10-minute mean wind speeds with a Weibull(k, c) marginal and AR(1) persistence,
// by a Gaussian copula: z_i = φ·z_{i−1} + √(1−φ²)·ε_i, ε ~ N(0,1), v_i = c·(−ln(1 − Φ(z_i)))^(1/k).
// Defaults are fitted to the Kelmarsh turbine 1 10-minute data, January–June 2019
// (shared/data/kelmarsh, Plumley 2022, CC-BY-4.0), by the method of moments: mean 5.98 m/s,
// standard deviation 2.48 m/s → k = (σ/μ)^−1.086 = 2.60, c = μ/Γ(1 + 1/k) = 6.73 m/s;
// lag-1 autocorrelation of the 10-minute means 0.951. These months are windier than the
// annual mean at that site; pass --weibull-k/--weibull-c for other statistics.
// Operating point: the turbine controller's steady state of the wind load model
// (model/wind): rotor speed and rotor torque; power = T·ω·η. Rows carry 10-minute means
// only: no turbulence within the 10 minutes, no stops other than below cut-in / above cut-out.
// Random numbers: std::mt19937_64 (fully specified by the standard) with our own
// Box–Muller transform, so the file is identical on every platform for a given seed.
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"
#include "model/wind/wind_load.hpp"

namespace {

using app::cli::CommandError;
constexpr double kPi = 3.14159265358979323846;

struct SynthArgs {
  std::string out;
  std::string drivetrain;
  double years = 11.0;
  double period_s = 600.0;
  double weibull_k = 2.60;
  double weibull_c = 6.73;
  double lag1 = 0.951;
  unsigned long long seed = 1;
  double start_s = 1420070400.0;  // 2015-01-01T00:00:00Z
};

class Normal {
 public:
  explicit Normal(unsigned long long seed) : rng_(seed) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  std::mt19937_64 rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

void run(const SynthArgs& a) {
  if (!(a.years > 0.0) || !(a.period_s > 0.0))
    throw CommandError("--years and --period must be > 0");
  if (!(a.weibull_k > 0.0) || !(a.weibull_c > 0.0))
    throw CommandError("--weibull-k and --weibull-c must be > 0");
  if (!(a.lag1 >= 0.0 && a.lag1 < 1.0)) throw CommandError("--lag1 must be in [0, 1)");
  const model::Drivetrain d = app::config::load_drivetrain(a.drivetrain);
  const model::wind::WindLoad wind(d.turbine);
  std::FILE* f = std::fopen(a.out.c_str(), "w");
  if (!f) throw CommandError("--out: cannot write '" + a.out + "'");
  std::fprintf(f, "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,torque_nm\n");
  const auto rows = static_cast<long long>(std::llround(a.years * 365.25 * 86400.0 / a.period_s));
  Normal normal(a.seed);
  double z = normal.next();
  const double innov = std::sqrt(1.0 - a.lag1 * a.lag1);
  const double eta = d.turbine.drivetrain_efficiency;
  for (long long i = 0; i < rows; ++i) {
    if (i > 0) z = a.lag1 * z + innov * normal.next();
    const double u = 0.5 * std::erfc(-z / std::sqrt(2.0));
    const double v =
        a.weibull_c * std::pow(-std::log1p(-std::min(u, 1.0 - 1e-16)), 1.0 / a.weibull_k);
    const model::wind::WindLoadOutput o = wind.steady_state(v);
    const double rpm = o.rotor_speed_rad_s * 60.0 / (2.0 * kPi);
    const double p_kw = o.torque_nm * o.rotor_speed_rad_s * eta / 1e3;
    std::fprintf(f, "%.0f,%.3f,%.4f,%.3f,%.1f\n", a.start_s + static_cast<double>(i) * a.period_s,
                 v, rpm, p_kw, o.torque_nm);
  }
  if (std::fclose(f) != 0) throw CommandError("--out: write error on '" + a.out + "'");
  std::printf("wrote %lld rows (%.2f years of %.0f s) to %s\n", rows, a.years, a.period_s,
              a.out.c_str());
}

void setup_synth_scada(CLI::App& sub) {
  auto args = std::make_shared<SynthArgs>();
  sub.add_option("--out", args->out, "Output CSV (bundle scada.csv columns)")->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--years", args->years, "Length [years of 365.25 days]")->capture_default_str();
  sub.add_option("--period", args->period_s, "Row period [s]")->capture_default_str();
  sub.add_option("--weibull-k", args->weibull_k, "Weibull shape k of the 10-min wind")
      ->capture_default_str();
  sub.add_option("--weibull-c", args->weibull_c, "Weibull scale c [m/s]")->capture_default_str();
  sub.add_option("--lag1", args->lag1, "Lag-1 autocorrelation of the Gaussian copula")
      ->capture_default_str();
  sub.add_option("--seed", args->seed, "Random seed")->capture_default_str();
  sub.add_option("--start", args->start_s, "First t_s [s since 1970 UTC]")->capture_default_str();
  sub.callback([args] { run(*args); });
}

const bool kSynthScadaRegistered = app::cli::register_command(
    {"synth-scada",
     "Deterministic synthetic SCADA history (Weibull + AR(1) wind, steady-state turbine)",
     &setup_synth_scada});

}  // namespace
