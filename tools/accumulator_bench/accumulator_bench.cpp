// Cost of the online fatigue accumulator (model/fatigue/damage_accumulator.hpp) per model
// step, measured in one run on one core, as ratios:
//   ROM        : Rom::step() of paper-2mw at 25.6 kHz (the baseline: the step it follows)
//   former     : the accumulator's per-step arithmetic before its stress and S-N constants
//                were hoisted (reimplemented here from the public ChannelSet::stress() and
//                SnCurve::damage_per_cycle(): per source two face-load pow()s, the S-N
//                curve's log/exp and, past the knee, its knee pow and logs again)
//   accumulator: DamageAccumulator::step() as the loop runs it
// and how far the two damages differ (relative, worst channel): the tolerance of the change.
// Loads: paper-2mw's quasi-static loads at a torque sweeping 20–110 % of rated, each mesh
// and bearing load modulated ±15 % at its own frequency (stresses on both sides of every
// S-N knee), 4096 samples precomputed and cycled.
// CPU time of this thread (the machine is shared); each figure is the best of 5 rounds.
//
// Usage: accumulator_bench [--steps N] [--only rom|former|accumulator]
//   --only: that part alone, for callgrind (tools/accumulator_bench/run.sh).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "accumulator_bench_options.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace {

using namespace model::fatigue;
constexpr double kRate = 25600.0;  // [Hz]
constexpr std::size_t kSamples = 4096;

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The former DamageAccumulator::step() arithmetic (damage only; the binning is unchanged
// and costs the same in both).
struct FormerAccumulator {
  const ChannelSet* cs;
  std::array<double, kMaxChannels> damage{}, comp{};
  std::array<double, kMaxChannels> full_scale{}, inv_width{};
  std::array<std::array<std::uint64_t, kMaxBins + 1>, kMaxChannels> bin_ticks{}, bin_rev_q{};
  std::uint32_t bins = 200;
  [[gnu::noinline]] void step(const LoadSample& loads, double rpm, double dt_s) {
    const double revs = rpm / 60.0 * dt_s;
    const auto rev_q = static_cast<std::uint64_t>(std::llround(revs / kRevQuantum));
    for (std::size_t c = 0; c < cs->channel_count(); ++c) {
      const Channel& ch = cs->channel(c);
      for (std::size_t k = 0; k < ch.source_count; ++k) {
        const double sigma = cs->stress(c, k, loads);
        std::size_t bin = bins;
        if (sigma < full_scale[c])
          bin = std::min<std::size_t>(
              bins - 1, static_cast<std::size_t>(std::max(0.0, sigma) * inv_width[c]));
        bin_ticks[c][bin] += 1;
        bin_rev_q[c][bin] += rev_q;
        const double inc =
            revs * ch.sources[k].cycles_per_rotor_rev * ch.curve.damage_per_cycle(sigma);
        const double sum = damage[c];
        const double t = sum + inc;
        comp[c] += std::abs(sum) >= std::abs(inc) ? (sum - t) + inc : (inc - t) + sum;
        damage[c] = t;
      }
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Cost of the online fatigue accumulator per model step"};
  tools::bench::AccumulatorBenchOptions o;
  tools::bench::add_options(cli, o);
  CLI11_PARSE(cli, argc, argv);
  const long steps = o.steps;
  const std::string& only = o.only;
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  if (!cs.valid()) {
    std::fprintf(stderr, "accumulator_bench: %s\n", cs.error().c_str());
    return 1;
  }
  AccumulatorConfig cfg;
  cfg.tick_s = 1.0 / kRate;
  auto acc = std::make_unique<DamageAccumulator>(cs, cfg);
  auto former = std::make_unique<FormerAccumulator>();
  former->cs = &cs;
  former->bins = acc->config().bins;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    former->full_scale[c] = acc->config().full_scale[c];
    former->inv_width[c] = 1.0 / acc->bin_width(c);
  }
  std::size_t sources = 0;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) sources += cs.channel(c).source_count;

  // Loads.
  const double rated_nm = 1.23e6, rpm = 14.8;
  std::vector<LoadSample> loads(kSamples);
  for (std::size_t i = 0; i < kSamples; ++i) {
    const double t = static_cast<double>(i) / kRate;
    const double sweep = 0.2 + 0.9 * 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * i / kSamples));
    LoadSample l = cs.quasi_static_loads(sweep * rated_nm);
    for (std::size_t m = 0; m < cs.mesh_count(); ++m)
      l.mesh_force_n[m] *= 1.0 + 0.15 * std::sin(2.0 * std::numbers::pi * (97.0 + 53.0 * m) * t);
    for (std::size_t b = 0; b < cs.bearing_count(); ++b) {
      const double f = 1.0 + 0.15 * std::sin(2.0 * std::numbers::pi * (31.0 + 17.0 * b) * t);
      l.bearing_radial_n[b] *= f;
      l.bearing_axial_n[b] *= f;
    }
    loads[i] = l;
  }

  // ROM (the baseline).
  std::string error;
  model::dynamics::RomSettings rs;
  rs.dt_s = 1.0 / kRate;
  const auto data = model::dynamics::build_rom(d, d.dynamics, rs, &error);
  if (!data) {
    std::fprintf(stderr, "accumulator_bench: %s\n", error.c_str());
    return 1;
  }
  auto rom = std::make_unique<model::dynamics::Rom>(*data);
  const model::dynamics::RomInputs in{rpm, rated_nm};
  rom->reset(in);
  model::dynamics::RomOutputs out;
  double sink = 0.0;

  const auto run_rom = [&] {
    for (long i = 0; i < steps; ++i) {
      rom->step(in, out);
      sink += out.mesh_force_n[7];
    }
  };
  const auto run_former = [&] {
    for (long i = 0; i < steps; ++i)
      former->step(loads[static_cast<std::size_t>(i) % kSamples], rpm, cfg.tick_s);
  };
  const auto run_acc = [&] {
    for (long i = 0; i < steps; ++i)
      (void)acc->step(loads[static_cast<std::size_t>(i) % kSamples], rpm, 1);
  };
  if (!only.empty()) {
    if (only == "rom") run_rom();
    if (only == "former") run_former();
    if (only == "accumulator") run_acc();
    std::printf("(sink %g)\n", sink);
    return 0;
  }

  double best_rom = 1e300, best_former = 1e300, best_acc = 1e300;
  for (int round = 0; round < 5; ++round) {
    acc->reset();
    *former =
        FormerAccumulator{&cs, {}, {}, former->full_scale, former->inv_width, {}, {}, former->bins};
    double t0 = thread_cpu_s();
    run_rom();
    double t1 = thread_cpu_s();
    best_rom = std::min(best_rom, t1 - t0);
    t0 = thread_cpu_s();
    run_former();
    t1 = thread_cpu_s();
    best_former = std::min(best_former, t1 - t0);
    t0 = thread_cpu_s();
    run_acc();
    t1 = thread_cpu_s();
    best_acc = std::min(best_acc, t1 - t0);
  }
  double worst_rel = 0.0;
  std::size_t worst_c = 0;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    const double a = acc->damage(c), f = former->damage[c] + former->comp[c];
    const double rel = f > 0.0 ? std::abs(a - f) / f : std::abs(a);
    if (rel > worst_rel) {
      worst_rel = rel;
      worst_c = c;
    }
  }
  const double n = static_cast<double>(steps);
  std::printf(
      "drivetwin accumulator benchmark (paper-2mw: %zu channels, %zu channel sources, %u bins; %ld "
      "steps at %.0f Hz)\n",
      cs.channel_count(), sources, acc->config().bins, steps, kRate);
  std::printf("ROM step (baseline)       : %8.1f ns/step  (%s kernel)\n", 1e9 * best_rom / n,
              model::dynamics::rom_step_isa());
  std::printf("accumulator, former       : %8.1f ns/step  = %6.2f x ROM\n", 1e9 * best_former / n,
              best_former / best_rom);
  std::printf("accumulator, now          : %8.1f ns/step  = %6.2f x ROM\n", 1e9 * best_acc / n,
              best_acc / best_rom);
  std::printf("speed-up former / now     : %8.2f x\n", best_former / best_acc);
  std::printf("damage now vs former      : %.2e relative (worst channel: %s %s)\n", worst_rel,
              cs.channel(worst_c).component.c_str(), failure_mode_name(cs.channel(worst_c).mode));
  std::printf("(sink %g)\n", sink);
  return 0;
}
