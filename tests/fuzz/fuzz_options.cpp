// Fuzz the command-option validation layer (app/cli/options.hpp) through CLI11 the way
// the subcommands use it: the input is split at NUL bytes into a command line for an
// app carrying one option of each validator kind. Properties:
//   - parsing never crashes, and fails only with a CLI::Error (no other exception);
//   - a validator's refusal names the option it refused (CLI11 prefixes it);
//   - every value that is accepted satisfies its declared range exactly (finite, bounds
//     open or closed as declared, integers in range, words from the list).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli/options.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args;
  std::string current;
  for (std::size_t i = 0; i < size && args.size() < 32; ++i) {
    if (data[i] == 0) {
      args.push_back(current);
      current.clear();
    } else {
      current += static_cast<char>(data[i]);
    }
  }
  if (args.size() < 32) args.push_back(current);

  using namespace app::cli;  // NOLINT(google-build-using-namespace): the validators under test
  CLI::App app{"fuzz"};
  double period = 600.0, rate = 25600.0, seconds = 10.0, torque = 0.0, factor = 0.0, ratio = 0.0;
  double k_h_beta = 0.0;
  std::string speed = "max";
  int grade = 6;
  std::string spectrum = "quasi-static";
  app.add_option("--period", period)->check(number_in(0.0, 366.0 * 86400.0, "s", true));
  app.add_option("--rate", rate)->check(positive("Hz"));
  app.add_option("--seconds", seconds)->check(number_in(0.0, 600.0, "s"));
  app.add_option("--torque", torque)->check(non_negative("N·m"));
  app.add_option("--factor", factor)->check(number_in(1.0, 10.0));
  app.add_option("--ratio", ratio)->check(number_in(0.0, 0.5, "", false, true));
  app.add_option("--grade", grade)->check(integer_in(1, 12, "ISO 1328 grade"));
  app.add_option("--k-h-beta", k_h_beta)->check(number_in_or(0.0, "method C", 1.0, 10.0));
  app.add_option("--speed", speed)->check(number_in_or_word("max", 0.0, 1e6, "", true));
  app.add_option("--spectrum", spectrum)
      ->check(one_of({"quasi-static", "dynamics", "dynamics-rows"}));

  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 pops from the back
  try {
    app.parse(reversed);
  } catch (const CLI::ValidationError& e) {
    const std::string what = e.what();
    static const char* const kNames[] = {"--period",   "--rate",  "--seconds", "--torque",
                                         "--factor",   "--ratio", "--grade",   "--spectrum",
                                         "--k-h-beta", "--speed"};
    bool named = false;
    for (const char* n : kNames) named = named || what.find(n) != std::string::npos;
    if (!named) std::abort();
    return 0;
  } catch (const CLI::Error&) {
    return 0;  // CLI11's own refusals (unknown option, missing value, ...)
  }
  // Whatever was accepted is in range (the defaults are too).
  if (!(std::isfinite(period) && period > 0.0 && period <= 366.0 * 86400.0)) std::abort();
  if (!(std::isfinite(rate) && rate > 0.0)) std::abort();
  if (!(seconds >= 0.0 && seconds <= 600.0)) std::abort();
  if (!(std::isfinite(torque) && torque >= 0.0)) std::abort();
  if (!(factor == 0.0 || (factor >= 1.0 && factor <= 10.0))) std::abort();  // 0: default
  if (!(ratio >= 0.0 && ratio < 0.5)) std::abort();
  if (!(grade >= 1 && grade <= 12)) std::abort();
  if (spectrum != "quasi-static" && spectrum != "dynamics" && spectrum != "dynamics-rows")
    std::abort();
  if (!(k_h_beta == 0.0 || (k_h_beta >= 1.0 && k_h_beta <= 10.0))) std::abort();
  if (speed != "max") {
    // Accepted as a number: the whole text, finite, in (0, 1e6].
    char* end = nullptr;
    const double v = std::strtod(speed.c_str(), &end);
    if (speed.empty() || end != speed.c_str() + speed.size() || !std::isfinite(v) || !(v > 0.0) ||
        v > 1e6)
      std::abort();
  }
  return 0;
}
