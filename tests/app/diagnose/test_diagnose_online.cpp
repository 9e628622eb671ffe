// The diagnosis online, as the running application will use it: a low-priority worker
// thread owns the Diagnoser and steps it, publishing its fixed-size summary after every
// step through the application's mailbox (app/loop/mailbox.hpp, Latest<T>); another thread
// reads the summaries and asks for a cancel, which the worker relays at its next step.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "loop/mailbox.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/diagnosis/diagnoser.hpp"
#include "model/dynamics/simulate.hpp"

namespace {

namespace md = model::diagnosis;

TEST(DiagnoseOnline, AWorkerPublishesEveryStepAndACancelFromAnotherThreadEndsTheRun) {
  // A recording: the ROM at rated with drifted stiffness, 3 % noise, 8 s.
  model::Drivetrain d = model::paper_2mw();
  d.dynamics = model::calibration::with_nominal_damping(d.dynamics);
  model::Drivetrain truth = d;
  truth.dynamics.mesh_stiffness_scale = {0.9, 0.9, 0.85};
  model::dynamics::SimulationOutputs out;
  std::string error;
  ASSERT_TRUE(model::dynamics::simulate_rom(truth, {14.8, 1.23e6}, {8.5, 25600.0}, out, &error))
      << error;
  std::array<std::vector<double>, 2> points;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 0.01);
  for (std::size_t p = 0; p < 2; ++p) {
    points[p].assign(out.acceleration_m_s2[p].begin() + 12800, out.acceleration_m_s2[p].end());
    for (double& v : points[p]) v += g(rng);
  }
  md::DiagnosisInput in;
  in.sample_rate_hz = 25600.0;
  in.points = {points[0].data(), points[1].data()};
  in.samples = points[0].size();
  in.rotor_speed_rpm = 14.8;
  in.input_torque_nm = 1.23e6;

  md::RomEffectSimulator sim(d, 0.5);
  md::Diagnoser diagnoser(d, sim);
  app::loop::Latest<md::DiagnosisSummary> latest;
  std::atomic<bool> cancel_request{false};
  std::atomic<int> final_step{-1};

  // Act: the worker steps and publishes; this thread watches and cancels mid-calibration.
  std::thread worker([&] {
    diagnoser.start(in);
    md::DiagnosisStep st;
    do {
      if (cancel_request.load(std::memory_order_relaxed)) diagnoser.cancel();
      st = diagnoser.step();
      md::DiagnosisSummary s;
      if (diagnoser.read_result(s)) {
        latest.write(s);
        // Mid-calibration, hold until the watcher has seen it and asked for the cancel: the
        // calibration stage can be over in a few steps, before a watcher slowed by load or a
        // sanitizer is scheduled (the cancel then arrived after the run had ended).
        if (s.stage == md::DiagnosisStage::kCalibrate && !s.finished) {
          while (!cancel_request.load()) std::this_thread::yield();
        }
      }
    } while (st == md::DiagnosisStep::kRunning);
    final_step.store(static_cast<int>(st));
  });
  std::uint32_t last_generation = 0;
  md::DiagnosisSummary seen;
  while (final_step.load() < 0) {
    if (latest.read(seen)) {
      EXPECT_GE(seen.generation, last_generation);  // never a torn or older summary
      last_generation = seen.generation;
      if (seen.stage == md::DiagnosisStage::kCalibrate) cancel_request.store(true);
    }
    std::this_thread::yield();
  }
  worker.join();

  // Assert: the run ended cancelled, and the last published summary says so.
  EXPECT_EQ(final_step.load(), static_cast<int>(md::DiagnosisStep::kCancelled));
  ASSERT_TRUE(latest.read(seen));
  EXPECT_TRUE(seen.finished);
  EXPECT_TRUE(seen.cancelled);
  EXPECT_EQ(seen.status, md::DiagnosisStatus::kCancelled);
}

}  // namespace
