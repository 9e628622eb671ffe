#include "model/wind/corrections.hpp"

#include <cmath>

namespace model::wind {

double standard_pressure_pa(double altitude_m) {
  // ISO 2533:1975, troposphere: p = p0·(1 − L·h/T0)^(g/(R_d·L))
  const double exponent = kStandardGravityMps2 / (kDryAirGasConstant * kTemperatureLapseKPerM);
  return kSeaLevelPressurePa *
         std::pow(1.0 - kTemperatureLapseKPerM * altitude_m / kSeaLevelTemperatureK, exponent);
}

double air_density_kg_m3(double temperature_c, double altitude_m) {
  const double temperature_k = temperature_c + kZeroCelsiusK;
  if (!(temperature_k > 0.0)) return std::nan("");
  // Ideal gas: ρ = p/(R_d·T) (IEC 61400-12-1:2017 eq. 12 without the humidity term)
  return standard_pressure_pa(altitude_m) / (kDryAirGasConstant * temperature_k);
}

double yaw_power_factor(double yaw_error_rad, double exponent) {
  const double c = std::cos(yaw_error_rad);
  if (!(c > 0.0)) return 0.0;
  return std::pow(c, exponent);
}

double free_stream_wind_mps(double nacelle_wind_mps, double gain, double offset_mps) {
  const double v = gain * nacelle_wind_mps + offset_mps;  // IEC 61400-12-2 NTF, affine
  return v > 0.0 ? v : 0.0;
}

double electrical_power_w(double aerodynamic_power_w, double efficiency, double no_load_loss_w) {
  return efficiency * aerodynamic_power_w - no_load_loss_w;
}

double aerodynamic_power_w(double electrical_power_w, double efficiency, double no_load_loss_w) {
  return efficiency > 0.0 ? (electrical_power_w + no_load_loss_w) / efficiency : std::nan("");
}

}  // namespace model::wind
