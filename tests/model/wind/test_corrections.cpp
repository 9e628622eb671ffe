// SCADA corrections of the wind load model (model/wind/corrections.hpp) and the
// tabulated Cp(λ) (model/wind/cp_surface.hpp): each against a hand calculation
// or a property the formula guarantees.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "model/drivetrain/description.hpp"
#include "model/wind/corrections.hpp"
#include "model/wind/cp_surface.hpp"
#include "model/wind/wind_load.hpp"

namespace {

using namespace model::wind;
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

TEST(AirDensity, AtSeaLevelAndFifteenDegreesIsTheStandardAtmospheres) {
  // ISO 2533: 101 325 Pa / (287.05287 J/(kg·K) · 288.15 K) = 1.2250 kg/m³
  EXPECT_NEAR(air_density_kg_m3(15.0, 0.0), 1.2250, 5e-5);
}

TEST(AirDensity, AtAltitudeUsesTheStandardPressureAndTheMeasuredTemperature) {
  // Hand calculation, h = 130 m, T = 5 °C:
  //   exponent g/(R_d·L) = 9.80665 / (287.05287 · 0.0065) = 5.25588
  //   p = 101 325 · (1 − 0.0065·130/288.15)^5.25588 = 101 325 · 0.984683 = 99 773 Pa
  //   ρ = 99 773 / (287.05287 · 278.15) = 1.24960 kg/m³
  EXPECT_NEAR(standard_pressure_pa(130.0), 99773.0, 1.0);
  EXPECT_NEAR(air_density_kg_m3(5.0, 130.0), 1.24960, 2e-5);
}

TEST(AirDensity, ColderAirIsDenserInInverseProportionToAbsoluteTemperature) {
  // Ideal gas at the same pressure: ρ(−10 °C)/ρ(30 °C) = 303.15/263.15
  EXPECT_NEAR(air_density_kg_m3(-10.0, 200.0) / air_density_kg_m3(30.0, 200.0), 303.15 / 263.15,
              1e-12);
  EXPECT_TRUE(std::isnan(air_density_kg_m3(-300.0, 0.0)));
}

TEST(YawPowerFactor, IsCosineToTheExponentAndZeroBeyondNinetyDegrees) {
  EXPECT_NEAR(yaw_power_factor(30.0 * kRadPerDeg, 2.0), 0.75, 1e-12);    // cos²30° = 3/4
  EXPECT_NEAR(yaw_power_factor(-60.0 * kRadPerDeg, 3.0), 0.125, 1e-12);  // cos³60° = 1/8
  EXPECT_DOUBLE_EQ(yaw_power_factor(0.0, 2.5), 1.0);
  EXPECT_DOUBLE_EQ(yaw_power_factor(20.0 * kRadPerDeg, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(yaw_power_factor(120.0 * kRadPerDeg, 2.0), 0.0);
}

TEST(NacelleTransferFunction, IsAffineAndNeverNegative) {
  EXPECT_NEAR(free_stream_wind_mps(5.0, 1.1, -0.4), 5.1, 1e-12);  // 1.1·5 − 0.4
  EXPECT_DOUBLE_EQ(free_stream_wind_mps(0.2, 1.0, -0.5), 0.0);
}

TEST(DrivetrainLosses, ElectricalPowerIsEfficiencyTimesAeroMinusNoLoadLossAndInverts) {
  // 0.94 · 1 000 kW − 50 kW = 890 kW
  EXPECT_NEAR(electrical_power_w(1.0e6, 0.94, 50e3), 890e3, 1e-6);
  EXPECT_NEAR(aerodynamic_power_w(890e3, 0.94, 50e3), 1.0e6, 1e-6);
  for (double p_w : {0.0, 12e3, 250e3, 2.05e6}) {
    EXPECT_NEAR(electrical_power_w(aerodynamic_power_w(p_w, 0.9, 30e3), 0.9, 30e3), p_w, 1e-6);
  }
  // Below the no-load loss the turbine would draw from the grid.
  EXPECT_LT(electrical_power_w(20e3, 0.94, 50e3), 0.0);
}

model::Turbine corrected_turbine() {
  model::Turbine t = model::paper_2mw().turbine;
  t.drivetrain_efficiency = 0.9;
  return t;
}

TEST(WindLoadCorrections, DefaultsLeaveTheMeasuredSpeedEstimateUnchanged) {
  const model::Turbine t = corrected_turbine();
  const WindLoad load(t);
  const double speed = 8.33 * 2.0 * std::numbers::pi / 60.0;
  EXPECT_DOUBLE_EQ(load.with_rotor_speed(6.75, speed, 0.0, false, Inflow{}).torque_nm,
                   load.with_rotor_speed(6.75, speed, 0.0, false).torque_nm);
}

TEST(WindLoadCorrections, DensityScalesAndYawReducesTheAerodynamicTorque) {
  model::Turbine t = corrected_turbine();
  t.corrections.yaw_loss_exponent = 2.0;
  const WindLoad load(t);
  const double speed = 8.33 * 2.0 * std::numbers::pi / 60.0;
  const double base = load.with_rotor_speed(6.75, speed, 0.0, false).torque_nm;
  Inflow half_density;
  half_density.air_density_kg_m3 = 0.5 * t.air_density_kg_m3;
  Inflow yawed;
  yawed.yaw_error_rad = 60.0 * kRadPerDeg;  // cos²60° = 1/4
  EXPECT_NEAR(load.with_rotor_speed(6.75, speed, 0.0, false, half_density).torque_nm, 0.5 * base,
              1e-9 * base);
  EXPECT_NEAR(load.with_rotor_speed(6.75, speed, 0.0, false, yawed).torque_nm, 0.25 * base,
              1e-9 * base);
}

TEST(WindLoadCorrections, NacelleTransferFunctionFeedsTheFreeStreamWindToTheAerodynamics) {
  model::Turbine t = corrected_turbine();
  t.corrections.nacelle_wind_gain = 1.1;
  t.corrections.nacelle_wind_offset_mps = -0.3;
  const WindLoad corrected(t);
  const WindLoad plain(corrected_turbine());
  const double speed = 9.0 * 2.0 * std::numbers::pi / 60.0;
  // 1.1 · 6.5 − 0.3 = 6.85 m/s free stream
  EXPECT_DOUBLE_EQ(corrected.with_rotor_speed(6.5, speed, 0.0, false).torque_nm,
                   plain.aerodynamic_torque_nm(6.85, speed, 0.0));
  // The region is what the controller sees: the measured wind.
  EXPECT_EQ(corrected.with_rotor_speed(3.9, speed, 0.0, false).region,
            OperatingRegion::kBelowCutIn);
}

TEST(WindLoadCorrections, ElectricalPowerSubtractsTheNoLoadLoss) {
  model::Turbine t = corrected_turbine();
  t.corrections.no_load_loss_w = 40e3;
  const WindLoad load(t);
  // 0.9 · 500 kN·m · 1.2 rad/s − 40 kW = 500 kW
  EXPECT_NEAR(load.electrical_power_w(500e3, 1.2), 500e3, 1e-6);
}

model::CpSurface table_surface() {
  model::CpSurface s = model::paper_2mw().turbine.cp;
  s.lambda_scale = 1.0;  // the table is looked up at s·λ
  s.table_lambda_min = 4.0;
  s.table_lambda_max = 15.0;  // knots every 1.0
  s.table_cp = {0.10, 0.20, 0.30, 0.40, 0.46, 0.50, 0.48, 0.44, 0.38, 0.30, 0.22, 0.15};
  return s;
}

TEST(CpTable, PassesThroughItsKnotsAndHoldsTheEndValuesOutside) {
  const model::CpSurface s = table_surface();
  ASSERT_TRUE(has_cp_table(s));
  for (std::size_t k = 0; k < model::kCpTableKnots; ++k) {
    EXPECT_NEAR(power_coefficient(s, 4.0 + static_cast<double>(k), 0.0), s.table_cp[k], 1e-12) << k;
  }
  EXPECT_DOUBLE_EQ(power_coefficient(s, 2.0, 0.0), 0.10);
  EXPECT_DOUBLE_EQ(power_coefficient(s, 19.0, 0.0), 0.15);
}

TEST(CpTable, NeverExceedsItsLargestKnotAndIsContinuouslyDifferentiable) {
  const model::CpSurface s = table_surface();
  double max_cp = 0.0;
  for (double lambda = 3.0; lambda < 16.0; lambda += 0.001) {
    max_cp = std::max(max_cp, power_coefficient(s, lambda, 0.0));
  }
  EXPECT_LE(max_cp, 0.50 + 1e-12);  // monotone interpolant: no overshoot of the peak knot
  EXPECT_LE(max_cp, kBetzLimit);
  // C¹: one-sided slopes at an interior knot agree.
  const double h = 1e-6;
  for (double knot : {6.0, 9.0, 12.0}) {
    const double left = (power_coefficient(s, knot, 0.0) - power_coefficient(s, knot - h, 0.0)) / h;
    const double right =
        (power_coefficient(s, knot + h, 0.0) - power_coefficient(s, knot, 0.0)) / h;
    EXPECT_NEAR(left, right, 1e-4) << knot;
  }
}

TEST(CpTable, PitchScalesTheTableByHeiersRelativePitchFactor) {
  const model::CpSurface s = table_surface();
  model::CpSurface heier = s;
  heier.table_lambda_max = heier.table_lambda_min = 0.0;
  const double beta = 2.0 * kRadPerDeg;
  const double expected = power_coefficient(s, 9.0, 0.0) * power_coefficient(heier, 9.0, beta) /
                          power_coefficient(heier, 9.0, 0.0);
  EXPECT_NEAR(power_coefficient(s, 9.0, beta), expected, 1e-12);
  EXPECT_LT(power_coefficient(s, 9.0, beta), power_coefficient(s, 9.0, 0.0));
}

}  // namespace
