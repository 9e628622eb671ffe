// The supervisor (app/supervisor/supervisor.hpp): the torque source chain against hand
// values, rejection of non-finite and implausible inputs, the degraded modes in time, the
// alarm from the vibration zones, and the status/fault words that say so.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "model/wind/wind_load.hpp"
#include "results/register_map.hpp"
#include "supervisor/supervisor.hpp"

namespace {

using namespace app::supervisor;
using app::loop::TorqueSource;
using app::loop::VibrationZone;
using hal::ScadaQuantity;
using std::chrono::seconds;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

hal::ScadaData scada(double wind, double rpm, double power_kw, double torque = kNaN) {
  hal::ScadaData d;
  const auto set = [&](ScadaQuantity q, double v) {
    if (std::isnan(v)) return;
    d[q].value = v;
    d[q].valid = true;
  };
  set(ScadaQuantity::kWindSpeed, wind);
  set(ScadaQuantity::kRotorSpeed, rpm);
  set(ScadaQuantity::kPower, power_kw);
  set(ScadaQuantity::kRotorTorque, torque);
  return d;
}

CycleObservations ok() {
  CycleObservations o;
  o.scada_status = hal::Status::kOk;
  o.keyphasor_valid = true;
  return o;
}

class SupervisorTest : public ::testing::Test {
 protected:
  model::Drivetrain d_ = model::paper_2mw();
  SupervisorConfig cfg_{};
};

TEST_F(SupervisorTest, MeasuredTorqueComesFirstThenPowerThenWind) {
  Supervisor s(d_, cfg_);
  // Measured torque (its magnitude) with the measured speed.
  SupervisorDecision r = s.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0, -600000.0), ok());
  EXPECT_EQ(r.source, TorqueSource::kMeasuredTorque);
  EXPECT_DOUBLE_EQ(r.rom.input_torque_nm, 600000.0);
  EXPECT_DOUBLE_EQ(r.rom.rotor_speed_rpm, 12.0);
  // Power: T = P / (η ω), paper-2mw's η = 1: 900 kW at 12 rpm = 716 197 N·m.
  r = s.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), ok());
  EXPECT_EQ(r.source, TorqueSource::kPower);
  EXPECT_NEAR(r.rom.input_torque_nm, 900e3 / (12.0 * 2.0 * std::numbers::pi / 60.0), 1e-6);
  // Wind at the measured speed: the wind load model's own value.
  r = s.update(hal::Timestamp{0}, scada(8.0, 12.0, kNaN), ok());
  EXPECT_EQ(r.source, TorqueSource::kWind);
  const model::wind::WindLoad wind(d_.turbine);
  EXPECT_DOUBLE_EQ(
      r.rom.input_torque_nm,
      std::abs(
          wind.with_rotor_speed(8.0, 12.0 * 2.0 * std::numbers::pi / 60.0, 0.0, false).torque_nm));
  EXPECT_TRUE(r.rom_valid);
  EXPECT_EQ(r.status_word, app::results::kStatusRunning);
  EXPECT_EQ(r.fault_word, 0);
}

TEST_F(SupervisorTest, NonFiniteAndImplausibleValuesAreRejectedCountedAndSkipped) {
  Supervisor s(d_, cfg_);
  // NaN torque and a power beyond 1.5 × rated: both rejected, the wind model takes over.
  hal::ScadaData d = scada(8.0, 12.0, 5000.0);
  d[ScadaQuantity::kRotorTorque].value = std::numeric_limits<double>::quiet_NaN();
  d[ScadaQuantity::kRotorTorque].valid = true;
  const SupervisorDecision r = s.update(hal::Timestamp{0}, d, ok());
  EXPECT_EQ(r.rejected_this_cycle, 2u);
  EXPECT_EQ(s.rejected_total(), 2u);
  EXPECT_EQ(r.source, TorqueSource::kWind);
  EXPECT_TRUE(r.fault_word & kFaultInputRejected);
  // A rotor speed of 100 rpm (6.8 × rated) and a wind of 300 m/s: nothing usable is left.
  const SupervisorDecision r2 = s.update(hal::Timestamp{0}, scada(300.0, 100.0, kNaN), ok());
  EXPECT_EQ(r2.rejected_this_cycle, 2u);
  EXPECT_EQ(r2.source, TorqueSource::kHeld);  // the previous cycle's inputs, held
}

TEST_F(SupervisorTest, StaleScadaHoldsTheLastInputsForTheHoldTimeThenSteadyState) {
  cfg_.hold_s = 30.0;
  Supervisor s(d_, cfg_);
  const SupervisorDecision fresh = s.update(hal::Timestamp{0}, scada(9.0, 13.0, 1200.0), ok());
  ASSERT_EQ(fresh.source, TorqueSource::kPower);
  CycleObservations stale = ok();
  stale.scada_status = hal::Status::kStale;
  // Within the hold time: the last valid inputs, flagged.
  SupervisorDecision r = s.update(seconds(30), scada(9.0, 13.0, 1200.0), stale);
  EXPECT_EQ(r.source, TorqueSource::kHeld);
  EXPECT_DOUBLE_EQ(r.rom.input_torque_nm, fresh.rom.input_torque_nm);
  EXPECT_TRUE(r.status_word & app::results::kStatusDegraded);
  EXPECT_TRUE(r.status_word & app::results::kStatusScadaStale);
  EXPECT_TRUE(r.fault_word & kFaultHoldingInputs);
  // Beyond it: the controller's steady state at the last valid wind.
  r = s.update(seconds(31), hal::ScadaData{}, stale);
  EXPECT_EQ(r.source, TorqueSource::kSteadyState);
  const model::wind::WindLoad wind(d_.turbine);
  const model::wind::WindLoadOutput st = wind.steady_state(9.0);
  EXPECT_DOUBLE_EQ(r.rom.input_torque_nm, std::abs(st.torque_nm));
  EXPECT_NEAR(r.rom.rotor_speed_rpm, st.rotor_speed_rad_s * 60.0 / (2.0 * std::numbers::pi), 1e-9);
  EXPECT_TRUE(r.fault_word & kFaultSteadyState);
  // Fresh again: back to the measurement, no degraded bit.
  r = s.update(seconds(32), scada(9.0, 13.0, 1200.0), ok());
  EXPECT_EQ(r.source, TorqueSource::kPower);
  EXPECT_FALSE(r.status_word & app::results::kStatusDegraded);
}

TEST_F(SupervisorTest, WithoutAnyValidInputTheRomIsNotSteppedAndTheWordsSaySo) {
  Supervisor s(d_, cfg_);
  CycleObservations silent = ok();
  silent.scada_status = hal::Status::kNoData;
  const SupervisorDecision r = s.update(hal::Timestamp{0}, hal::ScadaData{}, silent);
  EXPECT_FALSE(r.rom_valid);
  EXPECT_EQ(r.source, TorqueSource::kNone);
  EXPECT_TRUE(r.fault_word & kFaultNoInputs);
  EXPECT_TRUE(r.fault_word & kFaultScadaStale);
  EXPECT_TRUE(r.status_word & app::results::kStatusRunning);
}

TEST_F(SupervisorTest, TheAlarmFollowsTheWorstZoneFromTheConfiguredOne) {
  Supervisor d_zone(d_, cfg_);
  CycleObservations o = ok();
  o.zones = {VibrationZone::kC, VibrationZone::kAB};
  SupervisorDecision r = d_zone.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), o);
  EXPECT_FALSE(r.alarm);
  EXPECT_TRUE(r.fault_word & kFaultZoneAlert);
  o.zones = {VibrationZone::kC, VibrationZone::kD};
  r = d_zone.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), o);
  EXPECT_TRUE(r.alarm);
  EXPECT_TRUE(r.status_word & app::results::kStatusAlarm);
  EXPECT_TRUE(r.fault_word & kFaultZoneAlarm);
  // Alarm from zone C when configured so; unknown zones never raise it.
  cfg_.alarm_zone = VibrationZone::kC;
  Supervisor c_zone(d_, cfg_);
  o.zones = {VibrationZone::kC, VibrationZone::kUnknown};
  EXPECT_TRUE(c_zone.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), o).alarm);
  o.zones = {VibrationZone::kUnknown, VibrationZone::kUnknown};
  EXPECT_FALSE(c_zone.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), o).alarm);
}

TEST_F(SupervisorTest, CmsAndKeyphasorFaultsSetTheirBits) {
  Supervisor s(d_, cfg_);
  CycleObservations o = ok();
  o.cms_gap = true;
  o.keyphasor_valid = false;
  const SupervisorDecision r = s.update(hal::Timestamp{0}, scada(8.0, 12.0, 900.0), o);
  EXPECT_TRUE(r.fault_word & kFaultCmsGap);
  EXPECT_TRUE(r.status_word & app::results::kStatusCmsFault);
  EXPECT_TRUE(r.fault_word & kFaultKeyphasor);
  EXPECT_TRUE(r.status_word & app::results::kStatusKeyphasorFault);
  EXPECT_TRUE(r.rom_valid);  // the loop carries on
}

}  // namespace
