#include "fatigue/damage_history.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "model/wind/wind_load.hpp"
#include "wind/scada_limits.hpp"
#include "wind/torque_source.hpp"

namespace app::fatigue {
namespace {
constexpr double kDayS = 86400.0;
constexpr std::size_t kPeriodProbeRows = 64;
using hal::ScadaQuantity;
}  // namespace

HistoryResult run_history(hal::ScadaCsvReader& reader, const model::Drivetrain& drivetrain,
                          const model::fatigue::ChannelSet& channels,
                          const model::fatigue::LoadSpectrum& spectrum,
                          const HistoryOptions& options) {
  HistoryResult r;
  const std::size_t nc = channels.channel_count();
  r.damage.assign(nc, 0.0);
  r.exceeded_at_s.assign(nc, std::numeric_limits<double>::quiet_NaN());
  r.bin_time_s.assign(kTorqueBins, 0.0);
  std::vector<std::vector<double>> bin_damage(nc, std::vector<double>(kTorqueBins, 0.0));
  std::vector<model::fatigue::DamageRateHistory> rates;
  rates.reserve(nc);
  for (std::size_t c = 0; c < nc; ++c) rates.emplace_back(kDayS, options.rul_short_window_days);
  std::vector<double> day_inc(nc, 0.0), d(nc, 0.0);
  long long day = std::numeric_limits<long long>::min();
  bool day_has_data = false;

  const model::wind::WindLoad wind(drivetrain.turbine);
  const double rated_torque =
      drivetrain.turbine.rated_torque_nm > 0 ? drivetrain.turbine.rated_torque_nm : 1.0;
  double prev_t = std::numeric_limits<double>::quiet_NaN();

  auto issue = [&](std::size_t row, std::string field, std::string message) {
    r.note(row, std::move(field), std::move(message));
  };
  auto where = [&](const hal::ScadaRow& row, const std::string& column, std::string_view key) {
    return app::wind::where(reader, row, column, std::string(key));
  };
  const app::wind::ScadaLimits limits(drivetrain);
  DayRecord day_record;
  auto flush_day = [&]() {
    if (!day_has_data) return;
    if (options.per_day) {
      day_record.day = day;
      day_record.damage = day_inc;
      r.days.push_back(day_record);
      day_record = DayRecord{};
    }
    for (std::size_t c = 0; c < nc; ++c) {
      rates[c].add_interval(day_inc[c]);
      day_inc[c] = 0.0;
    }
    day_has_data = false;
  };

  auto process = [&](const hal::ScadaRow& row) {
    if (!row.has_time()) {
      r.bad_time(reader, row, "time missing");
      return;
    }
    const double t = row.time_s();
    if (!std::isnan(prev_t) && !(t > prev_t)) {
      r.bad_time(
          reader, row,
          t == prev_t ? "duplicate timestamp" : "timestamp before the previous row's (unsorted)");
      return;
    }
    // Plausibility (app/wind/scada_rows.hpp): one implausible value rejects the row. The
    // measured speed is ignored when the wind model's steady state gives it.
    const bool steady = options.torque_from == TorqueFrom::kWindSteady;
    if (!r.plausible(limits, reader, row, steady)) return;
    app::wind::ScadaValues values;
    for (std::size_t i = 0; i < hal::kScadaQuantityCount; ++i) {
      const auto q = static_cast<ScadaQuantity>(i);
      if (!row.has(q) || (q == ScadaQuantity::kRotorSpeed && steady)) continue;
      values.set(q, row.get(q));
    }
    // Torque source, in order of preference (app/wind/torque_source.hpp).
    const app::wind::RotorTorque rt =
        app::wind::rotor_torque(drivetrain.turbine, wind, values, options.torque_from);
    const double torque = rt.torque_nm;
    const double rpm = rt.rotor_speed_rpm;
    switch (rt.source) {
      case app::wind::TorqueSource::kMeasuredTorque:
        ++r.torque_rows_measured;
        break;
      case app::wind::TorqueSource::kPower:
        ++r.torque_rows_power;
        break;
      case app::wind::TorqueSource::kWind:
        ++r.torque_rows_wind;
        break;
      case app::wind::TorqueSource::kNone:
      case app::wind::TorqueSource::kHeld:  // the supervisor's, never rotor_torque()'s
      case app::wind::TorqueSource::kSteadyState:
        ++r.rows_no_data;
        return;
    }
    // Beyond the load spectrum: its damage cannot be interpolated (clamping it to the
    // spectrum's edge would hide a torque column in the wrong unit): rejected and counted.
    if (torque > spectrum.grid.torque_max_nm || rpm > spectrum.grid.speed_max_rpm) {
      ++r.rows_rejected;
      ++r.rejected_spectrum;
      r.max_rejected_torque_nm = std::max(r.max_rejected_torque_nm, torque);
      char what[240];
      if (torque > spectrum.grid.torque_max_nm) {
        std::snprintf(what, sizeof what,
                      "rotor torque %.6g N·m (%.2f x rated, from %s) is above the load spectrum "
                      "(<= %.6g N·m = %.1f x rated); row skipped, its damage not counted",
                      torque, torque / rated_torque, app::wind::to_string(rt.source),
                      spectrum.grid.torque_max_nm, spectrum.grid.torque_max_nm / rated_torque);
      } else {
        std::snprintf(what, sizeof what,
                      "rotor speed %.4g rpm is above the load spectrum (<= %.4g rpm); row "
                      "skipped, its damage not counted",
                      rpm, spectrum.grid.speed_max_rpm);
      }
      const bool torque_side = torque > spectrum.grid.torque_max_nm;
      issue(row.row, torque_side ? "torque" : "rotor_speed_rpm",
            reader.path() + ": row " + std::to_string(row.row) + " (line " +
                std::to_string(row.line) + "): " + what);
      return;
    }
    // Damage per rotor revolution at this operating point.
    if (options.at_point) {
      if (!options.at_point(torque, rpm, d.data())) {
        ++r.rows_no_data;
        return;
      }
    } else {
      spectrum.damage_per_rev_at(torque, rpm, d.data());
    }
    // Gap before this row?
    if (!std::isnan(prev_t) && t - prev_t > kGapFactor * r.period_s) {
      ++r.gaps;
      r.gap_s += t - prev_t - r.period_s;
      issue(row.row, "t_s",
            where(row, reader.time_column_name(), hal::kScadaTimeKey) + ": gap of " +
                std::to_string(t - prev_t) + " s before this row (not extrapolated)");
    }
    if (r.rows_used == 0) r.first_t_s = t;
    r.last_t_s = t;
    prev_t = t;
    ++r.rows_used;
    r.covered_s += r.period_s;
    const auto today = static_cast<long long>(std::floor(t / kDayS));
    if (today != day) {
      flush_day();
      day = today;
    }
    day_has_data = true;
    day_record.covered_s += r.period_s;
    if (row.has(ScadaQuantity::kWindSpeed)) {
      day_record.wind_sum_mps += row.get(ScadaQuantity::kWindSpeed);
      ++day_record.wind_rows;
    }
    const double revs = rpm / 60.0 * r.period_s;
    const auto bin =
        std::min(kTorqueBins - 1, static_cast<std::size_t>(torque / (0.1 * rated_torque)));
    r.bin_time_s[bin] += r.period_s;
    for (std::size_t c = 0; c < nc; ++c) {
      const double inc = d[c] * revs;
      const bool alive = r.damage[c] < 1.0;
      r.damage[c] += inc;
      day_inc[c] += inc;
      bin_damage[c][bin] += inc;
      if (alive && r.damage[c] >= 1.0) r.exceeded_at_s[c] = t;  // Miner's D = 1 reached
    }
    if (options.progress && (r.rows_used & 0x3fff) == 0) options.progress(r.rows);
  };

  // Read the first rows to detect the period, then stream.
  std::vector<hal::ScadaRow> probe;
  hal::ScadaRow row;
  bool end = false;
  auto read = [&](hal::ScadaRow& out) -> bool {
    for (;;) {
      if (options.max_rows > 0 && r.rows >= options.max_rows) return false;
      const hal::ScadaReadResult res = reader.next(out);
      if (res == hal::ScadaReadResult::kEnd) return false;
      ++r.rows;
      if (res == hal::ScadaReadResult::kRow) return true;
      r.unreadable(reader, r.rows);  // counted and named; throws on an I/O error
    }
  };
  while (probe.size() < kPeriodProbeRows && (end = !read(row)) == false) probe.push_back(row);
  if (r.rows == 0) {
    throw std::runtime_error(reader.path() +
                             ": no data rows after the header; nothing to accumulate");
  }
  r.period_s = options.period_s;
  if (!(r.period_s > 0.0)) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i < probe.size(); ++i) {
      if (probe[i].has_time() && probe[i - 1].has_time()) {
        const double dt = probe[i].time_s() - probe[i - 1].time_s();
        if (dt > 0.0) best = std::min(best, dt);
      }
    }
    if (!std::isfinite(best)) {
      // Name the rows that left too few to measure the period with.
      std::string rejected;
      for (std::size_t i = 0; i < r.issues.size() && i < 3; ++i)
        rejected += "; " + r.issues[i].message;
      throw std::runtime_error(
          reader.path() + ": cannot detect the SCADA period: of the first " +
          std::to_string(r.rows) + " data rows " + std::to_string(r.rows_rejected) +
          " were rejected and fewer than two of the rest have increasing t_s (pass --period, "
          "or fix the rows)" +
          rejected);
    }
    r.period_s = best;
  }
  for (const hal::ScadaRow& p : probe) process(p);
  if (!end) {
    while (read(row)) process(row);
  }
  flush_day();
  if (r.rows_used == 0) {
    std::string rejected;
    for (std::size_t i = 0; i < r.issues.size() && i < 3; ++i)
      rejected += "; " + r.issues[i].message;
    throw std::runtime_error(reader.path() + ": none of the " + std::to_string(r.rows) +
                             " data rows is usable (" + std::to_string(r.rows_rejected) +
                             " rejected, " + std::to_string(r.rows_no_data) +
                             " without torque, power or wind); nothing accumulated" + rejected);
  }
  // Issues were found in reading order (the period probe reads ahead): list them by row.
  std::stable_sort(r.issues.begin(), r.issues.end(),
                   [](const HistoryIssue& a, const HistoryIssue& b) { return a.row < b.row; });
  r.rul.resize(nc);
  std::size_t worst = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    r.rul[c] = rates[c].estimate(r.damage[c]);
    const bool contact = channels.channel(c).mode == model::fatigue::FailureMode::kContact;
    if (contact && r.damage[c] > r.damage[worst]) worst = c;
  }
  r.breakdown_channel = worst;
  r.bin_damage = nc ? bin_damage[worst] : std::vector<double>(kTorqueBins, 0.0);
  return r;
}

Quantiles quantiles(std::vector<double> v) {
  Quantiles out;
  out.count = v.size();
  if (v.empty()) return out;
  std::sort(v.begin(), v.end());
  auto quantile = [&v](double p) {
    const double rank = p * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(rank));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (rank - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  out.min = v.front();
  out.max = v.back();
  out.q1 = quantile(0.25);
  out.median = quantile(0.5);
  out.q3 = quantile(0.75);
  double sum = 0.0;
  for (double x : v) sum += x;
  out.mean = sum / static_cast<double>(v.size());
  return out;
}

DayDistribution day_distribution(const std::vector<DayRecord>& days, std::size_t channel,
                                 double full_day_s, double wind_ref_mps, std::size_t nearest_count,
                                 double band_mps) {
  DayDistribution out;
  std::vector<double> v, in_band;
  std::vector<std::size_t> full;
  for (std::size_t i = 0; i < days.size(); ++i) {
    if (days[i].covered_s >= full_day_s && channel < days[i].damage.size()) {
      v.push_back(days[i].damage[channel]);
      full.push_back(i);
      if (days[i].wind_rows > 0 && std::abs(days[i].mean_wind_mps() - wind_ref_mps) <= band_mps)
        in_band.push_back(days[i].damage[channel]);
    } else {
      ++out.partial_days;
    }
  }
  out.full_days = v.size();
  if (v.empty()) return out;
  out.all = quantiles(std::move(v));
  out.band = quantiles(std::move(in_band));
  std::stable_sort(full.begin(), full.end(), [&](std::size_t a, std::size_t b) {
    return std::abs(days[a].mean_wind_mps() - wind_ref_mps) <
           std::abs(days[b].mean_wind_mps() - wind_ref_mps);
  });
  full.resize(std::min(full.size(), nearest_count));
  out.nearest = full;
  return out;
}

model::fatigue::SpectrumGrid quasi_static_grid(const model::Drivetrain& drivetrain) {
  model::fatigue::SpectrumGrid grid;
  grid.torque_max_nm = 1.5 * drivetrain.turbine.rated_torque_nm;
  grid.speed_min_rpm = 0.5;
  grid.speed_max_rpm = std::max(1.0, 1.2 * drivetrain.turbine.rated_rotor_speed_rpm);
  return grid;
}

}  // namespace app::fatigue
