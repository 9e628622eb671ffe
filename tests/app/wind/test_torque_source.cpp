// The one torque source and the one set of SCADA plausibility limits, checked by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/scada_limits.hpp"
#include "wind/torque_source.hpp"

namespace {

using app::wind::TorquePreference;
using app::wind::TorqueSource;
using Q = hal::ScadaQuantity;

// A turbine with the losses of kelmarsh-mm92's fit: η = 0.94, P_0 = 47 356.126 W.
model::Drivetrain lossy_turbine() {
  model::Drivetrain d = model::paper_2mw();
  d.turbine.drivetrain_efficiency = 0.94;
  d.turbine.corrections.no_load_loss_w = 47356.12631710944;
  return d;
}

TEST(TorqueSource, PowerGivesTheRotorTorqueWithEfficiencyAndNoLoadLoss) {
  // By hand: ω = 14·2π/60 = 1.4660766 rad/s; P_aero = (1 000 000 + 47 356.126)/0.94
  //   = 1 114 208.645 W; T = P_aero/ω = 759 993.49 N·m (P/(η·ω) without P_0 would give
  //   725 630.44 N·m, 4.5 % less).
  const model::Drivetrain d = lossy_turbine();
  EXPECT_NEAR(app::wind::rotor_torque_from_power_nm(d.turbine, 1000.0, 14.0), 759993.49, 0.01);
  // Below the minimum speed power says nothing; negative power cannot make T negative.
  EXPECT_EQ(app::wind::rotor_torque_from_power_nm(d.turbine, 1000.0, 0.05), 0.0);
  EXPECT_EQ(app::wind::rotor_torque_from_power_nm(d.turbine, -100.0, 14.0), 0.0);
}

TEST(TorqueSource, PowerIsTheExactInverseOfTheWindModelsElectricalPower) {
  // The estimate is compared on the electrical side with (η·T·ω − P_0)/ω
  // (torque_estimate.hpp); the power source must undo exactly that.
  const model::Drivetrain d = lossy_turbine();
  const model::wind::WindLoad wind(d.turbine);
  const double omega = 12.0 * 2.0 * std::numbers::pi / 60.0;
  const double p_w = wind.electrical_power_w(800000.0, omega);
  EXPECT_NEAR(app::wind::rotor_torque_from_power_nm(d.turbine, p_w / 1e3, 12.0), 800000.0, 1e-6);
}

TEST(TorqueSource, PrefersMeasuredTorqueThenPowerThenWind) {
  // Arrange
  const model::Drivetrain d = lossy_turbine();
  const model::wind::WindLoad wind(d.turbine);
  app::wind::ScadaValues v;
  v.set(Q::kWindSpeed, 8.0);
  v.set(Q::kRotorSpeed, 14.0);
  v.set(Q::kPower, 1000.0);
  v.set(Q::kRotorTorque, -500000.0);  // sign convention of the controller: magnitude counts
  // Act / Assert: all present → measured torque
  auto r = app::wind::rotor_torque(d.turbine, wind, v);
  EXPECT_EQ(r.source, TorqueSource::kMeasuredTorque);
  EXPECT_EQ(r.torque_nm, 500000.0);
  EXPECT_EQ(r.rotor_speed_rpm, 14.0);
  // without torque → power
  v.present[static_cast<std::size_t>(Q::kRotorTorque)] = false;
  r = app::wind::rotor_torque(d.turbine, wind, v);
  EXPECT_EQ(r.source, TorqueSource::kPower);
  EXPECT_NEAR(r.torque_nm, 759993.49, 0.01);
  // without power → the wind model at the measured speed
  v.present[static_cast<std::size_t>(Q::kPower)] = false;
  r = app::wind::rotor_torque(d.turbine, wind, v);
  EXPECT_EQ(r.source, TorqueSource::kWind);
  const double omega = 14.0 * 2.0 * std::numbers::pi / 60.0;
  EXPECT_NEAR(r.torque_nm, std::abs(wind.with_rotor_speed(8.0, omega, 0.0, false).torque_nm), 1e-9);
  // without speed → the steady state, which also gives the speed
  v.present[static_cast<std::size_t>(Q::kRotorSpeed)] = false;
  r = app::wind::rotor_torque(d.turbine, wind, v);
  const auto steady = wind.steady_state(8.0);
  EXPECT_EQ(r.source, TorqueSource::kWind);
  EXPECT_NEAR(r.rotor_speed_rpm, steady.rotor_speed_rad_s * 60.0 / (2.0 * std::numbers::pi), 1e-12);
  // nothing → none
  v.present[static_cast<std::size_t>(Q::kWindSpeed)] = false;
  EXPECT_EQ(app::wind::rotor_torque(d.turbine, wind, v).source, TorqueSource::kNone);
}

TEST(TorqueSource, AForcedSourceWithoutItsInputGivesNone) {
  const model::Drivetrain d = lossy_turbine();
  const model::wind::WindLoad wind(d.turbine);
  app::wind::ScadaValues v;
  v.set(Q::kWindSpeed, 8.0);
  v.set(Q::kRotorSpeed, 14.0);
  EXPECT_EQ(app::wind::rotor_torque(d.turbine, wind, v, TorquePreference::kPower).source,
            TorqueSource::kNone);
  EXPECT_EQ(app::wind::rotor_torque(d.turbine, wind, v, TorquePreference::kTorque).source,
            TorqueSource::kNone);
  // kWindSteady ignores the measured speed.
  const auto r = app::wind::rotor_torque(d.turbine, wind, v, TorquePreference::kWindSteady);
  EXPECT_EQ(r.source, TorqueSource::kWind);
  EXPECT_NE(r.rotor_speed_rpm, 14.0);
}

TEST(ScadaLimits, EachQuantityHasTheLimitsOfItsTurbine) {
  // paper-2mw: rated 14.8 rpm, 2 MW, 1.23 MN·m.
  const model::Drivetrain d = model::paper_2mw();
  const app::wind::ScadaLimits l(d);
  EXPECT_TRUE(l.plausible(Q::kRotorSpeed, 22.2));  // 1.5 × 14.8
  EXPECT_FALSE(l.plausible(Q::kRotorSpeed, 22.21));
  EXPECT_TRUE(l.plausible(Q::kRotorSpeed, -1.0));
  EXPECT_FALSE(l.plausible(Q::kRotorSpeed, -1.01));
  EXPECT_TRUE(l.plausible(Q::kPower, -4000.0));
  EXPECT_FALSE(l.plausible(Q::kPower, 4000.1));
  EXPECT_FALSE(l.plausible(Q::kRotorTorque, 3.69e6 + 1.0));  // 3 × 1.23e6
  EXPECT_FALSE(l.plausible(Q::kWindSpeed, -0.1));
  EXPECT_FALSE(l.plausible(Q::kWindSpeed, std::nan("")));
  EXPECT_FALSE(l.plausible(Q::kYawError, 180.5));
  EXPECT_FALSE(l.plausible(Q::kAmbientTemperature, 61.0));
  EXPECT_FALSE(l.plausible(Q::kPitch, -16.0));
  // The generator speed scales with the gearbox ratio.
  EXPECT_GT(l.range(Q::kGeneratorSpeed).max, 50.0 * 22.2);
  EXPECT_NE(l.why_implausible(Q::kRotorSpeed, 1480.0)
                .find("1480 rpm is beyond any plausible rotor speed for this turbine"),
            std::string::npos);
  EXPECT_TRUE(l.why_implausible(Q::kRotorSpeed, 10.0).empty());
}

}  // namespace
