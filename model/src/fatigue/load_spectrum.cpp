#include "model/fatigue/load_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace model::fatigue {

const char* spectrum_source_name(SpectrumSource source) {
  return source == SpectrumSource::kDynamics ? "dynamics" : "quasi-static fallback";
}

double SpectrumGrid::torque_at(std::uint32_t i) const {
  return torque_max_nm * static_cast<double>(i) / static_cast<double>(torque_points - 1);
}
double SpectrumGrid::speed_at(std::uint32_t j) const {
  return speed_min_rpm + (speed_max_rpm - speed_min_rpm) * static_cast<double>(j) /
                             static_cast<double>(speed_points - 1);
}

bool damage_per_rev_at_point(const ChannelSet& channels, const LoadSimulator& simulator, double t,
                             double n, double* out, std::string* error) {
  LoadSeries series;
  if (!simulator(t, n, series) || series.samples.empty() ||
      series.samples.size() != series.rotor_rpm.size() || !(series.dt_s > 0.0)) {
    if (error)
      *error = "load spectrum: simulator failed at torque " + std::to_string(t) + " N·m, speed " +
               std::to_string(n) + " rpm";
    return false;
  }
  AccumulatorConfig cfg;
  cfg.tick_s = series.dt_s;
  DamageAccumulator acc(channels, cfg);
  for (std::size_t k = 0; k < series.samples.size(); ++k)
    acc.step(series.samples[k], series.rotor_rpm[k], 1);
  const double revs = acc.rotor_revolutions();
  if (!(revs > 0.0)) {
    if (error)
      *error = "load spectrum: no rotor revolutions at speed " + std::to_string(n) + " rpm";
    return false;
  }
  for (std::size_t c = 0; c < channels.channel_count(); ++c) out[c] = acc.damage(c) / revs;
  return true;
}

LoadSpectrum build_load_spectrum(const ChannelSet& channels, const SpectrumGrid& grid,
                                 SpectrumSource source, const LoadSimulator& simulator,
                                 std::string* error) {
  LoadSpectrum s;
  auto fail = [&](std::string what) {
    if (error) *error = std::move(what);
    return LoadSpectrum{};
  };
  if (grid.torque_points < 2 || grid.speed_points < 2 || !(grid.torque_max_nm > 0.0) ||
      !(grid.speed_min_rpm > 0.0) || !(grid.speed_max_rpm > grid.speed_min_rpm)) {
    return fail(
        "load spectrum grid: need ≥ 2 points per axis, torque_max > 0, 0 < speed_min < speed_max");
  }
  s.grid = grid;
  s.source = source;
  s.channel_count = channels.channel_count();
  s.damage_per_rev.assign(
      static_cast<std::size_t>(grid.torque_points) * grid.speed_points * s.channel_count, 0.0);
  std::vector<double> point(s.channel_count);
  for (std::uint32_t i = 0; i < grid.torque_points; ++i) {
    for (std::uint32_t j = 0; j < grid.speed_points; ++j) {
      std::string why;
      if (!damage_per_rev_at_point(channels, simulator, grid.torque_at(i), grid.speed_at(j),
                                   point.data(), &why))
        return fail(why);
      for (std::size_t c = 0; c < s.channel_count; ++c) {
        s.damage_per_rev[(static_cast<std::size_t>(i) * grid.speed_points + j) * s.channel_count +
                         c] = point[c];
      }
    }
  }
  s.prepare();
  return s;
}

void LoadSpectrum::prepare() {
  log_damage_per_rev.resize(damage_per_rev.size());
  for (std::size_t k = 0; k < damage_per_rev.size(); ++k) {
    log_damage_per_rev[k] = damage_per_rev[k] > 0.0 ? std::log(damage_per_rev[k])
                                                    : -std::numeric_limits<double>::infinity();
  }
}

void LoadSpectrum::damage_per_rev_at(double torque_nm, double rotor_rpm, double* out) const {
  const double tq = std::clamp(std::abs(torque_nm), 0.0, grid.torque_max_nm);
  const double sp = std::clamp(rotor_rpm, grid.speed_min_rpm, grid.speed_max_rpm);
  const double fi = tq / grid.torque_max_nm * (grid.torque_points - 1);
  const double fj = (sp - grid.speed_min_rpm) / (grid.speed_max_rpm - grid.speed_min_rpm) *
                    (grid.speed_points - 1);
  const auto i0 = std::min<std::size_t>(static_cast<std::size_t>(fi), grid.torque_points - 2);
  const auto j0 = std::min<std::size_t>(static_cast<std::size_t>(fj), grid.speed_points - 2);
  const double wi = fi - static_cast<double>(i0), wj = fj - static_cast<double>(j0);
  const double w00 = (1 - wi) * (1 - wj), w01 = (1 - wi) * wj, w10 = wi * (1 - wj), w11 = wi * wj;
  const std::size_t n = channel_count, sp_pts = grid.speed_points;
  const std::size_t k00 = (i0 * sp_pts + j0) * n, k01 = (i0 * sp_pts + j0 + 1) * n;
  const std::size_t k10 = ((i0 + 1) * sp_pts + j0) * n, k11 = ((i0 + 1) * sp_pts + j0 + 1) * n;
  const bool have_log = log_damage_per_rev.size() == damage_per_rev.size();
  for (std::size_t c = 0; c < n; ++c) {
    const double d00 = damage_per_rev[k00 + c], d01 = damage_per_rev[k01 + c];
    const double d10 = damage_per_rev[k10 + c], d11 = damage_per_rev[k11 + c];
    if (have_log && d00 > 0.0 && d01 > 0.0 && d10 > 0.0 && d11 > 0.0) {
      out[c] = std::exp(w00 * log_damage_per_rev[k00 + c] + w01 * log_damage_per_rev[k01 + c] +
                        w10 * log_damage_per_rev[k10 + c] + w11 * log_damage_per_rev[k11 + c]);
    } else {
      out[c] = w00 * d00 + w01 * d01 + w10 * d10 + w11 * d11;
    }
  }
}

LoadSimulator quasi_static_simulator(const ChannelSet& channels) {
  return [&channels](double torque_nm, double rotor_rpm, LoadSeries& out) {
    out.dt_s = 1.0;
    out.samples.push_back(channels.quasi_static_loads(torque_nm));
    out.rotor_rpm.push_back(rotor_rpm);
    return true;
  };
}

}  // namespace model::fatigue
