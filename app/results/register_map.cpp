#include "results/register_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

namespace app::results {
namespace {

using hal::RegisterType;

struct HeaderEntry {
  std::uint16_t address;
  RegisterType type;
  Quantity quantity;
  const char* name;
  const char* unit;
  const char* description;
};

// The fixed part of the map: its addresses are those of map version 1 and never move.
constexpr std::array<HeaderEntry, 12> kHeader{{
    {0, RegisterType::kUInt16, Quantity::kMapVersion, "map_version", "-",
     "register map version (2)"},
    {1, RegisterType::kUInt16, Quantity::kStatusWord, "status_word", "-",
     "bit 0 running, 1 degraded, 2 SCADA stale, 3 CMS fault, 4 keyphasor fault, 5 calibrated, "
     "6 alarm, 7 overrun"},
    {2, RegisterType::kUInt16, Quantity::kFaultWord, "fault_word", "-",
     "supervisor faults, one bit each"},
    {3, RegisterType::kUInt16, Quantity::kCalibrationGeneration, "calibration_generation", "-",
     "increments with every calibration the loop adopts"},
    {4, RegisterType::kUInt32, Quantity::kSequence, "sequence", "-", "results publish counter"},
    {6, RegisterType::kUInt32, Quantity::kStampS, "stamp_s", "s", "loop time of the results"},
    {8, RegisterType::kFloat32, Quantity::kRotorTorque, "rotor_torque_nm", "N·m",
     "rotor (gearbox input) torque driving the model"},
    {10, RegisterType::kFloat32, Quantity::kRotorSpeed, "rotor_speed_rpm", "rpm",
     "rotor speed driving the model"},
    {12, RegisterType::kFloat32, Quantity::kWindSpeed, "wind_speed_mps", "m/s", "wind speed used"},
    {14, RegisterType::kFloat32, Quantity::kHssSpeed, "hss_speed_rpm", "rpm",
     "high-speed shaft speed from the keyphasor"},
    {16, RegisterType::kFloat32, Quantity::kCalibrationResidual, "calibration_residual", "-",
     "residual of the last calibration"},
    {18, RegisterType::kUInt16, Quantity::kChannelCount, "channel_count", "-",
     "damage channels mapped from address 200 (8 registers each)"},
}};

// "reversed (Y_M)" → "reversed-y_m": lower case, [a-z0-9_] kept, runs of anything else → '-'.
std::string slug(const std::string& s) {
  std::string out;
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || ch == '_') {
      out += static_cast<char>(std::tolower(c));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out;
}

const char* load_unit(model::fatigue::FailureMode mode) {
  return mode == model::fatigue::FailureMode::kBearing ? "N" : "MPa";
}

void put_float(hal::RegisterImage& image, std::uint16_t address, float v, hal::WordOrder order) {
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  const auto hi = static_cast<std::uint16_t>(u >> 16);
  const auto lo = static_cast<std::uint16_t>(u & 0xFFFFu);
  const bool high_first = order == hal::WordOrder::kHighWordFirst;
  image.words[address] = high_first ? hi : lo;
  image.words[address + 1u] = high_first ? lo : hi;
}

}  // namespace

RegisterMap::RegisterMap(const model::fatigue::ChannelSet& channels, hal::WordOrder order)
    : order_(order) {
  build(&channels);
}

RegisterMap::RegisterMap(hal::WordOrder order) : order_(order) { build(nullptr); }

void RegisterMap::build(const model::fatigue::ChannelSet* channels) {
  for (const HeaderEntry& h : kHeader) {
    entries_.push_back({h.address, h.type, h.quantity, 0, h.name, h.unit, h.description});
  }
  for (std::uint16_t k = 0; k < kIndicatorCount; ++k) {
    entries_.push_back({static_cast<std::uint16_t>(kIndicatorBase + 2 * k), RegisterType::kFloat32,
                        Quantity::kIndicator, k, std::string("indicator.") + kIndicatorNames[k],
                        "-", "condition indicator"});
  }
  for (std::uint16_t k = 0; k < kCommandCount; ++k) {
    entries_.push_back({static_cast<std::uint16_t>(kCommandStart + k), RegisterType::kUInt16,
                        Quantity::kCommand, k, "command." + std::to_string(k), "-",
                        "command register: written by clients if listed in results.writable"});
  }
  channel_count_ = channels ? channels->channel_count() : 0;
  for (std::size_t c = 0; c < channel_count_; ++c) {
    const model::fatigue::Channel& ch = channels->channel(c);
    std::string id = "channel." + ch.component + "." + model::fatigue::failure_mode_name(ch.mode);
    if (!ch.detail.empty()) id += "." + slug(ch.detail);
    std::string what = ch.component + " " + model::fatigue::failure_mode_name(ch.mode);
    if (!ch.detail.empty()) what += " (" + ch.detail + ")";
    const auto base = static_cast<std::uint16_t>(kChannelBase + kChannelStride * c);
    const auto index = static_cast<std::uint16_t>(c);
    entries_.push_back({base, RegisterType::kFloat32, Quantity::kChannelDamage, index,
                        id + ".damage", "-", what + ": Palmgren–Miner damage"});
    entries_.push_back({static_cast<std::uint16_t>(base + 2), RegisterType::kFloat32,
                        Quantity::kChannelRul, index, id + ".rul_h", "h",
                        what + ": remaining useful life at the long-term damage rate"});
    entries_.push_back({static_cast<std::uint16_t>(base + 4), RegisterType::kFloat32,
                        Quantity::kChannelRulLow, index, id + ".rul_low_h", "h",
                        what + ": remaining useful life at the p90 damage rate"});
    entries_.push_back({static_cast<std::uint16_t>(base + 6), RegisterType::kFloat32,
                        Quantity::kChannelLoad, index, id + ".load", load_unit(ch.mode),
                        what + ": stress (gears) or equivalent load (bearings), last cycle"});
  }
  std::uint32_t end = 0;
  for (const RegisterEntry& e : entries_) {
    end = std::max<std::uint32_t>(end, e.address + hal::register_count(e.type));
  }
  register_count_ = static_cast<std::uint16_t>(std::min<std::uint32_t>(end, 0xFFFF));
}

void RegisterMap::encode(const ResultsValues& v, hal::RegisterImage& image) const {
  image.count = register_count_;
  for (std::uint16_t a = 0; a < register_count_; ++a) {
    if (a < kCommandStart || a >= kCommandStart + kCommandCount) image.words[a] = 0;
  }
  for (const RegisterEntry& e : entries_) {
    if (e.type == RegisterType::kFloat32) {
      float f = 0.0f;
      switch (e.quantity) {
        case Quantity::kRotorTorque:
          f = v.rotor_torque_nm;
          break;
        case Quantity::kRotorSpeed:
          f = v.rotor_speed_rpm;
          break;
        case Quantity::kWindSpeed:
          f = v.wind_speed_mps;
          break;
        case Quantity::kHssSpeed:
          f = v.hss_speed_rpm;
          break;
        case Quantity::kCalibrationResidual:
          f = v.calibration_residual;
          break;
        case Quantity::kIndicator:
          f = v.indicators[e.index];
          break;
        case Quantity::kChannelDamage:
          f = v.channels[e.index].damage;
          break;
        case Quantity::kChannelRul:
          f = v.channels[e.index].rul_h;
          break;
        case Quantity::kChannelRulLow:
          f = v.channels[e.index].rul_low_h;
          break;
        case Quantity::kChannelLoad:
          f = v.channels[e.index].load;
          break;
        default:
          break;
      }
      put_float(image, e.address, f, order_);
      continue;
    }
    double x = 0.0;
    switch (e.quantity) {
      case Quantity::kMapVersion:
        x = kResultsMapVersion;
        break;
      case Quantity::kStatusWord:
        x = v.status_word;
        break;
      case Quantity::kFaultWord:
        x = v.fault_word;
        break;
      case Quantity::kCalibrationGeneration:
        x = v.calibration_generation;
        break;
      case Quantity::kSequence:
        x = v.sequence;
        break;
      case Quantity::kStampS:
        x = static_cast<double>(std::clamp<std::int64_t>(v.stamp_ns / 1000000000, 0, 0xFFFFFFFF));
        break;
      case Quantity::kChannelCount:
        x = static_cast<double>(channel_count_);
        break;
      case Quantity::kCommand:
        continue;  // the clients' registers
      default:
        break;
    }
    // Cannot fail: every integer quantity fits its type by construction.
    (void)hal::put_register(image, e.address, e.type, order_, x);
  }
}

std::string RegisterMap::markdown() const {
  std::string out = "| address | type | name | unit | description |\n|---|---|---|---|---|\n";
  std::vector<const RegisterEntry*> sorted;
  for (const RegisterEntry& e : entries_) sorted.push_back(&e);
  std::stable_sort(
      sorted.begin(), sorted.end(),
      [](const RegisterEntry* a, const RegisterEntry* b) { return a->address < b->address; });
  auto row = [&](const std::string& addr, const std::string& type, const std::string& name,
                 const std::string& unit, const std::string& description) {
    out += "| " + addr + " | " + type + " | " + name + " | " + unit + " | " + description + " |\n";
  };
  bool retired_listed = false;
  for (const RegisterEntry* e : sorted) {
    if (!retired_listed && e->address > 20) {
      row("20–133", "—", "(retired)", "—",
          "map v1's fixed reference-gearbox components; read as 0");
      retired_listed = true;
    }
    const std::size_t n = hal::register_count(e->type);
    const std::string addr =
        n == 1 ? std::to_string(e->address)
               : std::to_string(e->address) + "–" + std::to_string(e->address + n - 1);
    row(addr, hal::to_string(e->type), e->name, e->unit, e->description);
  }
  return out;
}

}  // namespace app::results
