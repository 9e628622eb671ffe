#pragma once
// What lies between a SCADA row and the rotor's aerodynamic power, and between
// that power and the electrical power the SCADA records (the description's
// Turbine::site_altitude_m and TurbineCorrections). Each is a textbook relation
// whose one free parameter `drivetwin fit-cp` fits to SCADA:
//
//   air density     ρ = p(h) / (R_d·T),  p(h) = p0·(1 − L·h/T0)^(g/(R_d·L))
//                   (ideal gas; pressure of the ISO 2533 standard atmosphere at
//                   the site altitude h, temperature measured; IEC 61400-12-1:2017
//                   eq. (12) uses the same ideal-gas density with measured pressure,
//                   which SCADA rarely has)
//   yaw error       P(γ) = P(0)·cos^x(γ)  (momentum theory of a yawed actuator disc
//                   gives x = 3; measured x is nearer 2: Burton et al., Wind Energy
//                   Handbook, 2nd ed., 2011, §3.10; x is fitted)
//   nacelle wind    v_free = a·v_nacelle + b  (nacelle transfer function,
//                   IEC 61400-12-2:2013 §6: the anemometer sits behind the rotor)
//   losses          P_el = η·P_aero − P_0  (a constant efficiency for the load-
//                   dependent gear and generator losses plus a no-load loss P_0:
//                   gear churning, bearings, magnetising, converter and auxiliaries)
//
// Thread context: pure functions of their arguments, no allocation, no
// exceptions, no blocking; safe on the real-time thread.

namespace model::wind {

inline constexpr double kSeaLevelPressurePa = 101325.0;   // [Pa] ISO 2533 p0
inline constexpr double kSeaLevelTemperatureK = 288.15;   // [K] ISO 2533 T0
inline constexpr double kTemperatureLapseKPerM = 0.0065;  // [K/m] ISO 2533 L (troposphere)
inline constexpr double kStandardGravityMps2 = 9.80665;   // [m/s²] g
inline constexpr double kDryAirGasConstant = 287.05287;   // [J/(kg·K)] R_d (ISO 2533)
inline constexpr double kZeroCelsiusK = 273.15;           // [K]

/// Pressure of the ISO 2533 standard atmosphere at an altitude [Pa].
/// @param altitude_m  above sea level [m], troposphere (< 11 km)
double standard_pressure_pa(double altitude_m);

/// Air density of dry air at a measured temperature and the standard pressure
/// of the site altitude [kg/m³]; NaN when the temperature is at or below 0 K.
/// @param temperature_c  ambient temperature [°C]
/// @param altitude_m     site altitude above sea level [m]
double air_density_kg_m3(double temperature_c, double altitude_m);

/// cos^x(γ) for |γ| < 90°, else 0 (a rotor turned edge-on or beyond extracts nothing).
/// @param yaw_error_rad  wind direction − rotor axis [rad]
/// @param exponent       x [-]; 0 gives 1 for every |γ| < 90°
double yaw_power_factor(double yaw_error_rad, double exponent);

/// Free-stream wind speed from the nacelle anemometer, v_free = a·v + b, never below 0 [m/s].
double free_stream_wind_mps(double nacelle_wind_mps, double gain, double offset_mps);

/// Electrical power from aerodynamic power, η·P_aero − P_0 [W] (negative when the
/// no-load loss exceeds what the rotor gives: the turbine would draw from the grid).
double electrical_power_w(double aerodynamic_power_w, double efficiency, double no_load_loss_w);

/// The inverse: aerodynamic power that yields an electrical power, (P_el + P_0)/η [W].
double aerodynamic_power_w(double electrical_power_w, double efficiency, double no_load_loss_w);

}  // namespace model::wind
