// `drivetwin results-map [--drivetrain NAME|FILE] [--word-order high_first|low_first]`:
// prints the results register map of a drivetrain as a Markdown table, generated from
// the one declaration (app/results/register_map.hpp); docs/results-map.md is its output
// for the built-in paper-2mw (a test keeps the two equal).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "results/register_map.hpp"

namespace {

struct ResultsMapArgs {
  std::string drivetrain;
  std::string word_order = "high_first";
};

void setup_results_map(CLI::App& sub) {
  auto args = std::make_shared<ResultsMapArgs>();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--word-order", args->word_order,
                 "32-bit values: high_first (ABCD, default) or low_first (CDAB)");
  sub.callback([args] {
    hal::WordOrder order;
    if (!hal::parse_word_order(args->word_order, order)) {
      throw app::cli::CommandError("--word-order: expected high_first or low_first, got '" +
                                   args->word_order + "'");
    }
    const model::Drivetrain d = app::config::load_drivetrain(args->drivetrain);
    const model::fatigue::ChannelSet channels(d, model::fatigue::ChannelOptions{});
    if (!channels.valid()) {
      throw app::cli::CommandError("drivetrain '" + d.name + "': " + channels.error());
    }
    const app::results::RegisterMap map(channels, order);
    std::printf(
        "Results register map v%u of drivetrain '%s': %zu damage channels, %u registers, "
        "32-bit values %s.\n\n",
        static_cast<unsigned>(app::results::kResultsMapVersion), d.name.c_str(),
        map.channel_count(), static_cast<unsigned>(map.register_count()), hal::to_string(order));
    std::fputs(map.markdown().c_str(), stdout);
  });
}

const bool kResultsMapRegistered = app::cli::register_command(
    {"results-map", "Print the results register map (Modbus) of a drivetrain as a table",
     &setup_results_map});

}  // namespace
