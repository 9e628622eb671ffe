// Real-time factors of the dynamics models, measured in one run on one core:
//   ROM  : Rom::step() at 25.6 kHz (the CMS rate), outputs of every step read
//   full : the full-order reference at the settings of the 5 % fidelity test
//          (Newmark, 2 steps per 25.6 kHz sample)
// Real-time factor = simulated seconds / elapsed seconds, both for wall-clock time
// and for this thread's CPU time (the CPU figure is the one-core figure when the
// machine is shared). Also prints the bytes of the ROM's data and state.
//
// Usage: dynamics_bench [--rom-steps N] [--full-seconds S] [--rom-only]
//   --rom-only: only N ROM steps (for callgrind: tools/dynamics_bench/run.sh).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>

#include "dynamics_bench_options.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/newmark.hpp"
#include "model/dynamics/rom.hpp"

namespace {

using namespace model::dynamics;
constexpr double kRate = 25600.0;

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
double wall_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Real-time factors of the reduced and full dynamics models"};
  tools::bench::DynamicsBenchOptions o;
  tools::bench::add_options(cli, o);
  CLI11_PARSE(cli, argc, argv);
  const long rom_steps = o.rom_steps;
  const double full_seconds = o.full_seconds;
  const bool rom_only = o.rom_only;
  const model::Drivetrain d = model::paper_2mw();
  std::string error;
  const std::optional<FullModel> m = build_full_model(d, {}, &error);
  if (!m) {
    std::fprintf(stderr, "dynamics_bench: %s\n", error.c_str());
    return 1;
  }
  RomBuildReport report;
  const double b0 = thread_cpu_s();
  const std::unique_ptr<RomData> data =
      build_rom(*m, 1.0 / kRate, kRomDefaultCutoffHz, &error, &report);
  const double build_cpu = thread_cpu_s() - b0;
  if (!data) {
    std::fprintf(stderr, "dynamics_bench: %s\n", error.c_str());
    return 1;
  }
  const RomInputs in{14.8, 1.23e6};  // rated
  auto rom = std::make_unique<Rom>(*data);
  rom->reset(in);
  RomOutputs out;
  double sink = 0.0;
  const double rw0 = wall_s(), rc0 = thread_cpu_s();
  for (long i = 0; i < rom_steps; ++i) {
    rom->step(in, out);
    sink += out.acceleration_m_s2[0] + out.mesh_force_n[7] + out.bearing_force_x_n[4];
  }
  const double rom_wall = wall_s() - rw0, rom_cpu = thread_cpu_s() - rc0;
  const double rom_sim = static_cast<double>(rom_steps) / kRate;
  if (rom_only) {
    std::printf("rom_steps %ld simulated_s %.6f checksum %.6e kernel %s\n", rom_steps, rom_sim,
                sink, rom_step_isa());
    return 0;
  }

  NewmarkIntegrator full(*m, 1.0 / (2 * kRate));
  full.reset_static({14.8, 1.23e6});
  const long full_steps = static_cast<long>(full_seconds * 2 * kRate);
  const double fw0 = wall_s(), fc0 = thread_cpu_s();
  for (long i = 0; i < full_steps; ++i) {
    full.step();
    if (i % 2 == 1) sink += full.sensor_m_s2(0) + full.mesh_force_n(7) + full.bearing_force_n(4, 0);
  }
  const double full_wall = wall_s() - fw0, full_cpu = thread_cpu_s() - fc0;
  const double full_sim = static_cast<double>(full_steps) / (2 * kRate);

  std::printf(
      "drivetwin dynamics benchmark (paper-2mw, rated 14.8 rpm / 1.23e6 N·m, outputs at %.0f Hz)\n",
      kRate);
  std::printf(
      "ROM: %d modes <= %.0f Hz + %d static corrections = %d DOF (capacity %d), built in %.1f ms "
      "CPU\n",
      report.eigenmodes, data->cutoff_hz, report.correction_vectors,
      report.eigenmodes + report.correction_vectors, kRomDofs, 1e3 * build_cpu);
  std::printf("ROM step kernel: %s\n", rom_step_isa());
  std::printf("ROM  real-time factor: %8.1f x (CPU time)  %8.1f x (wall)   [%.2f s simulated]\n",
              rom_sim / rom_cpu, rom_sim / rom_wall, rom_sim);
  std::printf(
      "full real-time factor: %8.3f x (CPU time)  %8.3f x (wall)   [%.2f s simulated, %d DOF, 2 "
      "steps/sample]\n",
      full_sim / full_cpu, full_sim / full_wall, full_sim, m->dofs());
  std::printf("ROM / full speed ratio: %8.1f x (CPU time)  %8.1f x (wall)\n",
              (rom_sim / rom_cpu) / (full_sim / full_cpu),
              (rom_sim / rom_wall) / (full_sim / full_wall));
  std::printf("ROM bytes: data %zu + state %zu = %zu (%.1f KiB)\n", sizeof(RomData), sizeof(Rom),
              sizeof(RomData) + sizeof(Rom),
              static_cast<double>(sizeof(RomData) + sizeof(Rom)) / 1024.0);
  std::printf("(checksum %.6e)\n", sink);
  return 0;
}
