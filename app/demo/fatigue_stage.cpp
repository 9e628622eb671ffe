// Demo stage "fatigue": how much life the reference drivetrain (paper-2mw) uses on the
// built-in day. The day's 10-minute wind speeds (Kelmarsh 2019-12-05, the wind stage's
// day) drive paper-2mw's wind load model (controller steady state per row); history mode
// (app/fatigue/damage_history.hpp) turns each row into ISO 6336 contact and root stresses
// and ISO 281 bearing loads through the quasi-static load spectrum, counts cycles per ISO
// 6336-6 and sums Palmgren–Miner damage per gear, failure mode and bearing. It prints the
// sun gear's contact damage against the paper's one-day figure, where in the torque range
// that damage comes from, and the components whose life goes fastest, with the remaining
// life at this day's rate, and the bearings' catalogue ratings beside ISO 281's from the
// geometry with the life modification a_ISO's inputs. `drivetwin damage builtin:kelmarsh-day.csv
// --torque-from wind-steady` prints the full table (and `--spectrum dynamics` the dynamics-model
// spectrum). Host / command code: allocates, throws CommandError.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/run.hpp"
#include "config/drivetrain_file.hpp"
#include "data/embedded.hpp"
#include "demo/demo.hpp"
#include "fatigue/bearing_report.hpp"
#include "fatigue/damage_history.hpp"
#include "hal/scada_csv.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"

namespace {

namespace mf = model::fatigue;

constexpr double kPaperDayDamage = 1.023e-5;  // [-] the paper's sun contact damage of one day
constexpr double kDayS = 86400.0;             // [s]
constexpr double kYearS = 365.25 * kDayS;     // [s]
constexpr std::size_t kShown = 3;             // gear channels and bearings listed

void run_fatigue_stage(const app::demo::DemoContext& ctx) {
  constexpr const char* kFile = "kelmarsh-day.csv";
  const auto text = app::data::embedded_file(kFile);
  if (!text) throw app::cli::CommandError(std::string("demo: built-in data ") + kFile + " missing");
  const model::Drivetrain drivetrain = app::config::load_drivetrain("paper-2mw");
  const mf::ChannelSet channels(drivetrain, mf::ChannelOptions{});
  if (!channels.valid()) throw app::cli::CommandError("demo: paper-2mw: " + channels.error());
  std::string error;
  mf::LoadSpectrum spectrum = mf::build_load_spectrum(
      channels, app::fatigue::quasi_static_grid(drivetrain), mf::SpectrumSource::kQuasiStatic,
      mf::quasi_static_simulator(channels), &error);
  if (spectrum.channel_count == 0) throw app::cli::CommandError("demo: load spectrum: " + error);
  spectrum.prepare();

  hal::ScadaCsvReader reader;
  if (!reader.open_text(*text, std::string("<built-in ") + kFile + ">",
                        hal::kelmarsh_scada_columns())) {
    throw app::cli::CommandError(reader.error());
  }
  app::fatigue::HistoryOptions options;
  options.torque_from = app::fatigue::TorqueFrom::kWindSteady;
  options.per_day = true;
  const app::fatigue::HistoryResult h =
      app::fatigue::run_history(reader, drivetrain, channels, spectrum, options);
  if (h.rows_used == 0 || h.covered_s <= 0.0 || h.days.empty()) {
    throw app::cli::CommandError("demo: no usable rows in the built-in day");
  }
  const double days = h.covered_s / kDayS;
  double wind_sum = 0.0;
  std::size_t wind_rows = 0;
  for (const auto& day : h.days) {
    wind_sum += day.wind_sum_mps;
    wind_rows += day.wind_rows;
  }
  const double mean_wind = wind_rows > 0 ? wind_sum / static_cast<double>(wind_rows) : 0.0;

  std::fprintf(ctx.out,
               "paper-2mw driven by the built-in day's wind (%zu 10-min rows, mean %.2f m/s; "
               "controller steady state per row); quasi-static load spectrum, ISO 6336-2/-3 "
               "method B, K_Hβ ISO 6336-1 method C, ISO 6336-6 cycles, paper's dual-slope S-N\n",
               h.rows_used, mean_wind);

  // The sun gear's contact damage against the paper's one day, and where it comes from.
  std::size_t sun = channels.channel_count();
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    if (channels.channel(c).component == "sun" &&
        channels.channel(c).mode == mf::FailureMode::kContact) {
      sun = c;
    }
  }
  if (sun == channels.channel_count()) throw app::cli::CommandError("demo: no sun contact channel");
  std::fprintf(ctx.out,
               "sun contact damage: %.3e in %.2f days (paper, its one day at a 6.75 m/s mean: "
               "%.3e)\n",
               h.damage[sun], days, kPaperDayDamage);
  if (h.breakdown_channel == sun && h.damage[sun] > 0.0) {
    double time_near_rated = 0.0, damage_near_rated = 0.0;
    for (std::size_t b = 9; b < app::fatigue::kTorqueBins; ++b) {  // ≥ 0.9 × rated torque
      time_near_rated += h.bin_time_s[b];
      damage_near_rated += h.bin_damage[b];
    }
    std::fprintf(ctx.out, "  at ≥ 0.9 × rated torque: %.0f %% of the time, %.0f %% of the damage\n",
                 100.0 * time_near_rated / h.covered_s, 100.0 * damage_near_rated / h.damage[sun]);
  }

  // The bearings' ratings: catalogue C beside ISO 281's from the geometry, and a_ISO's inputs.
  std::string ratings = app::fatigue::bearing_rating_text(
      channels, app::fatigue::bearing_rating_rows(drivetrain, channels));
  for (std::size_t at = ratings.find("# "); at != std::string::npos; at = ratings.find("# ", at)) {
    if (at == 0 || ratings[at - 1] == '\n') ratings.replace(at, 2, "");
    ++at;
  }
  std::fprintf(ctx.out, "%s", ratings.c_str());

  // The gear channels and the bearings whose damage grows fastest.
  std::vector<std::size_t> gears, bearings;
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    (channels.channel(c).mode == mf::FailureMode::kBearing ? bearings : gears).push_back(c);
  }
  auto by_damage = [&](std::size_t a, std::size_t b) { return h.damage[a] > h.damage[b]; };
  std::fprintf(ctx.out, "fastest-ageing (damage this day; remaining life at this day's rate):\n");
  for (auto* list : {&gears, &bearings}) {
    std::stable_sort(list->begin(), list->end(), by_damage);
    for (std::size_t i = 0; i < std::min(kShown, list->size()); ++i) {
      const std::size_t c = (*list)[i];
      const mf::Channel& ch = channels.channel(c);
      const std::string name = ch.component + (ch.detail.empty() ? "" : " " + ch.detail) + " " +
                               mf::failure_mode_name(ch.mode);
      std::fprintf(ctx.out, "  %-32s %.3e   %.3g years\n", name.c_str(), h.damage[c],
                   h.rul[c].rul_s / kYearS);
    }
  }
}

const bool kFatigueStageRegistered = app::demo::register_stage({30, "fatigue", &run_fatigue_stage});

}  // namespace
