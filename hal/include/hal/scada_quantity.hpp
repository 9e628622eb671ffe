#pragma once
// The SCADA quantities: the one list of what the turbine controller reports, with one
// unit each, used by the live SCADA source (scada_source.hpp, Modbus register maps), the
// CSV reader (scada_csv.hpp) and the replay backends alike.
//
// Thread context: constexpr data; any thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace hal {

/// The operating quantities the twin uses. Each has one fixed SI-ish unit;
/// a register map converts the controller's raw registers into it.
enum class ScadaQuantity : std::uint8_t {
  kWindSpeed,           // [m/s] nacelle anemometer
  kRotorSpeed,          // [rpm] rotor (low-speed shaft)
  kGeneratorSpeed,      // [rpm] generator (high-speed shaft)
  kPower,               // [kW] electrical active power
  kPitch,               // [deg] blade pitch angle
  kRotorTorque,         // [N·m] rotor torque as reported by the controller
  kYawError,            // [deg]
  kAmbientTemperature,  // [degC]
  kCount
};
inline constexpr std::size_t kScadaQuantityCount = static_cast<std::size_t>(ScadaQuantity::kCount);

/// Key as written in config files, and unit, of each quantity.
struct ScadaQuantityInfo {
  ScadaQuantity quantity;
  std::string_view key;
  std::string_view unit;
};
inline constexpr std::array<ScadaQuantityInfo, kScadaQuantityCount> kScadaQuantities{{
    {ScadaQuantity::kWindSpeed, "wind_speed_mps", "m/s"},
    {ScadaQuantity::kRotorSpeed, "rotor_speed_rpm", "rpm"},
    {ScadaQuantity::kGeneratorSpeed, "generator_speed_rpm", "rpm"},
    {ScadaQuantity::kPower, "power_kw", "kW"},
    {ScadaQuantity::kPitch, "pitch_deg", "deg"},
    {ScadaQuantity::kRotorTorque, "torque_nm", "N·m"},
    {ScadaQuantity::kYawError, "yaw_error_deg", "deg"},
    {ScadaQuantity::kAmbientTemperature, "ambient_temperature_c", "degC"},
}};

/// Looks a quantity up by its config key. @return false if unknown.
constexpr bool scada_quantity_from_key(std::string_view key, ScadaQuantity& out) {
  for (const auto& q : kScadaQuantities) {
    if (q.key == key) {
      out = q.quantity;
      return true;
    }
  }
  return false;
}

/// The quantity's key (config files, bundle column names): "wind_speed_mps", ...
constexpr std::string_view scada_quantity_key(ScadaQuantity q) {
  return kScadaQuantities[static_cast<std::size_t>(q)].key;
}

/// The quantity's unit: "m/s", "rpm", ...
constexpr std::string_view scada_quantity_unit(ScadaQuantity q) {
  return kScadaQuantities[static_cast<std::size_t>(q)].unit;
}

}  // namespace hal
