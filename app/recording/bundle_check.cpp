#include "recording/bundle_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "config/drivetrain_file.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"
#include "model/wind/wind_load.hpp"

namespace app::recording {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMinPulses = 3;  // tacho pulses needed for a speed

std::string num(double v, int digits = 4) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string hz(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

[[noreturn]] void fail(const fs::path& file, const std::string& field, const std::string& what) {
  throw BundleCheckError(file.string() + (field.empty() ? "" : ": " + field) + ": " + what);
}

std::string component_ids(const model::Drivetrain& d) {
  std::string ids;
  auto add = [&](const std::string& id) {
    if (!id.empty() && (" " + ids + " ").find(" " + id + " ") == std::string::npos)
      ids += (ids.empty() ? "" : " ") + id;
  };
  for (const auto& b : d.bearings) add(b.id);
  for (const auto& s : d.shafts) add(s.id);
  for (const auto& g : d.gears) add(g.id);
  return ids;
}

bool is_component(const model::Drivetrain& d, const std::string& id) {
  return d.bearing(id) != nullptr || d.shaft(id) != nullptr || d.gear(id) != nullptr;
}

}  // namespace

hal::OperatingRange operating_range(const model::Drivetrain& d) {
  hal::OperatingRange range;
  range.max_rotor_speed_rpm = kOverspeedFactor * d.turbine.rated_rotor_speed_rpm;
  range.max_input_torque_nm = kPeakTorqueFactor * d.turbine.rated_torque_nm;
  range.max_wind_speed_mps = kCutOutWindFactor * d.turbine.cut_out_wind_mps;
  return range;
}

void check_against_drivetrain(CheckedBundle& b, const fs::path& dir) {
  hal::Recording& rec = b.recording;
  const model::Drivetrain& d = b.drivetrain;
  const fs::path meta = dir / "recording.json";
  const model::Kinematics kin(d);
  const double rpm = rec.operating_point.rotor_speed_rpm;

  // Locations: component ids of this drivetrain.
  for (std::size_t c = 0; c < rec.channels.size(); ++c) {
    const hal::BundleChannel& ch = rec.channels[c];
    if (!is_component(d, ch.location)) {
      fail(meta, "channels[" + std::to_string(c) + "].location",
           "'" + ch.location + "' is not a component of drivetrain '" + d.name +
               "'; expected one of " + component_ids(d));
    }
  }

  // Tacho: mean pulse rate through the drivetrain's ratios.
  std::optional<std::size_t> tacho_channel;
  for (std::size_t c = 0; c < rec.channels.size() && !tacho_channel; ++c) {
    if (rec.channels[c].kind == "once_per_rev") tacho_channel = c;
  }
  const double duration_s = static_cast<double>(rec.sample_count()) / rec.sample_rate_hz;
  if (tacho_channel) {
    const hal::BundleChannel& ch = rec.channels[*tacho_channel];
    const std::string field = "channels[" + std::to_string(*tacho_channel) + "]";
    const auto per_rpm = kin.shaft_hz(ch.location, 1.0);  // [Hz per rotor rpm]
    if (!per_rpm || ch.location == "planet") {
      fail(meta, field + ".location",
           "'" + ch.location + "' for a once_per_rev channel; expected a shaft of drivetrain '" +
               d.name + "' (lss, sun_shaft, ims, hss)");
    }
    const std::vector<double>& x = rec.samples[*tacho_channel];
    model::dsp::OrderTracker tracker(2, 1, x.size() / 2 + 1);
    const std::size_t pulses = tracker.detect_pulses(x.data(), x.size(), rec.sample_rate_hz);
    const double expected_pulses = duration_s * rpm * *per_rpm;
    if (pulses >= kMinPulses) {
      const double* t = tracker.pulse_times();
      const double f_hz = static_cast<double>(pulses - 1) / (t[pulses - 1] - t[0]);
      b.tacho_rotor_rpm = f_hz / *per_rpm;
    } else if (expected_pulses >= 2.0 * kMinPulses) {
      fail(dir / rec.samples_file, "channel '" + ch.name + "'",
           std::to_string(pulses) + " tacho pulses in " + num(duration_s) +
               " s; at rotor_speed_rpm " + num(rpm) + " the " + ch.location + " turns " +
               num(expected_pulses, 3) +
               " times: expected one pulse per revolution (is the tacho connected?)");
    } else {
      b.notes.push_back("tacho '" + ch.name + "': the recording is too short for a speed (" +
                        std::to_string(pulses) +
                        " pulses); rotor_speed_rpm not checked against it");
    }
  }

  // Gear-mesh lines of the acceleration channels.
  std::vector<double> expected;
  for (std::size_t s = 0; s < kin.stage_count(); ++s) expected.push_back(kin.mesh_hz(s, rpm));
  std::vector<const std::vector<double>*> accel;
  std::string mesh_channel;  // "point1, point2": the channels the lines were looked for in
  for (std::size_t c = 0; c < rec.channels.size(); ++c) {
    const hal::BundleChannel& ch = rec.channels[c];
    if (!ch.kind.empty() || ch.unit != "m/s^2") continue;
    accel.push_back(&rec.samples[c]);
    mesh_channel += (mesh_channel.empty() ? "" : ", ") + ch.name;
  }
  const MeshLineScale mesh =
      rpm > 0.0 ? find_mesh_line_scale(accel, rec.sample_rate_hz, expected,
                                       b.tacho_rotor_rpm ? *b.tacho_rotor_rpm / rpm : 0.0)
                : MeshLineScale{};
  if (mesh.lines > 0) {
    b.mesh_line_scale = mesh.scale;
  } else if (rpm > 0.0) {
    b.notes.push_back(
        "no gear-mesh line stands out in the acceleration channels (or the recording is "
        "shorter than " +
        std::to_string(kMinMeshSamples) +
        " samples): sample_rate_hz and rotor_speed_rpm not checked "
        "against the vibration");
  }

  // Metadata against the signal.
  const auto agree = [](double x, double y) { return std::fabs(x / y - 1.0) <= kSpeedTolerance; };
  const bool mesh_ok = !b.mesh_line_scale || agree(*b.mesh_line_scale, 1.0);
  const bool tacho_ok = !b.tacho_rotor_rpm || agree(*b.tacho_rotor_rpm, rpm);
  const std::string rate = hz(rec.sample_rate_hz);
  if (!tacho_ok) {
    const double t_rpm = *b.tacho_rotor_rpm;
    const std::string tacho = rec.channels[*tacho_channel].name;
    if (b.mesh_line_scale && agree(*b.mesh_line_scale * rpm, t_rpm)) {
      fail(meta, "operating_point.rotor_speed_rpm",
           num(rpm) + " rpm, but the tacho '" + tacho + "' and the gear-mesh lines of " +
               mesh_channel + " both say " + num(t_rpm) +
               " rpm (expected within 3 %): the recorded speed is wrong, or sample_rate_hz is (" +
               hz(rec.sample_rate_hz * rpm / t_rpm) + " Hz would make them agree, not " + rate +
               ")");
    }
    if (b.mesh_line_scale && mesh_ok && mesh.hint_fundamentals > 0) {
      fail(meta, "operating_point.rotor_speed_rpm",
           num(rpm) + " rpm, but the tacho '" + tacho + "' says " + num(t_rpm) +
               " rpm (expected within 3 %), and gear-mesh lines of " + mesh_channel +
               " stand out at both speeds (one set holds the other's harmonics): the recorded "
               "speed, the tacho, or sample_rate_hz is wrong (" +
               hz(rec.sample_rate_hz * rpm / t_rpm) + " Hz would make them agree, not " + rate +
               ")");
    }
    if (b.mesh_line_scale && mesh_ok) {
      fail(meta, "channels[" + std::to_string(*tacho_channel) + "]",
           "tacho '" + tacho + "' gives " + num(t_rpm) +
               " rpm, but operating_point.rotor_speed_rpm " + num(rpm) +
               " and the gear-mesh lines of " + mesh_channel +
               " agree with each other: check the tacho's shaft (location '" +
               rec.channels[*tacho_channel].location + "') and that it pulses once per revolution");
    }
    fail(meta, "operating_point.rotor_speed_rpm",
         num(rpm) + " rpm, but the tacho '" + tacho + "' says " + num(t_rpm) +
             " rpm (expected within 3 %): the recorded speed, the tacho (one pulse per "
             "revolution of '" +
             rec.channels[*tacho_channel].location + "'?) or sample_rate_hz is wrong");
  }
  if (!mesh_ok && b.tacho_rotor_rpm) {
    // Tacho and metadata agree (a wrong sample rate would move the tacho too): the lines
    // are not where this description's tooth counts put them. Said, not refused: the
    // search cannot tell a family from its harmonics with certainty.
    b.notes.push_back("the gear-mesh fundamentals of " + mesh_channel + " stand out at " +
                      num(*b.mesh_line_scale, 3) + " x the frequencies of drivetrain '" + d.name +
                      "', not where the tacho and rotor_speed_rpm " + num(rpm) +
                      " put them: check that the description's tooth counts are the recorded "
                      "gearbox's");
  } else if (!mesh_ok) {
    const double s = *b.mesh_line_scale;
    fail(meta, "sample_rate_hz",
         "no gear-mesh line of " + mesh_channel + " stands out where rotor_speed_rpm " + num(rpm) +
             " and sample_rate_hz " + rate + " put them (drivetrain '" + d.name +
             "'); the strongest family sits at " + num(s, 3) +
             " x those frequencies (a sample rate of " + hz(rec.sample_rate_hz / s) +
             " Hz, or a rotor speed of " + num(rpm * s) +
             " rpm, would put it there; a family's lines are also the harmonics of lower "
             "ones): sample_rate_hz or rotor_speed_rpm is wrong");
  }
  if (b.tacho_rotor_rpm && b.mesh_line_scale && mesh_ok) {
    b.notes.push_back("rotor speed: recording.json " + num(rpm) + " rpm, tacho " +
                      num(*b.tacho_rotor_rpm) + " rpm, gear-mesh lines of " + mesh_channel + " " +
                      num(rpm * *b.mesh_line_scale) + " rpm: consistent");
  }

  // Input torque: recorded, else the wind load model (the contract's rule).
  const hal::BundleOperatingPoint& op = rec.operating_point;
  if (op.input_torque_nm) {
    b.input_torque_nm = *op.input_torque_nm;
  } else {
    const model::wind::WindLoad wind(d.turbine);
    const double omega = rpm * 2.0 * std::numbers::pi / 60.0;
    const model::wind::WindLoadOutput w = wind.with_rotor_speed(*op.wind_speed_mps, omega, 0.0,
                                                                /*has_pitch=*/false);
    b.input_torque_nm = w.torque_nm;
    b.torque_estimated = true;
    b.notes.push_back("operating_point has no input_torque_nm: " + num(w.torque_nm, 6) +
                      " N·m estimated from wind_speed_mps " + num(*op.wind_speed_mps) + " m/s at " +
                      num(rpm) + " rpm with the wind load model (region " +
                      model::wind::region_name(w.region) + ", effective Cp " +
                      num(w.power_coefficient, 3) + ", pitch 0 assumed)");
  }
}

CheckedBundle load_bundle(const fs::path& dir, const BundleCheckOptions& options) {
  const fs::path meta = dir / "recording.json";
  // The drivetrain first: its range is part of reading the bundle.
  hal::Recording head;
  {
    std::ifstream in(meta, std::ios::binary);
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
      fail(dir, "", "not a directory; expected a recording bundle directory");
    if (!in) fail(meta, "", "missing or unreadable; every bundle needs recording.json");
    std::stringstream text;
    text << in.rdbuf();
    if (auto e = hal::parse_recording_json(text.str(), meta.string(), head))
      throw BundleCheckError(e->to_string());
  }
  CheckedBundle b;
  if (!options.drivetrain.empty()) {
    try {
      b.drivetrain = config::load_drivetrain(options.drivetrain);
    } catch (const std::exception& e) {
      throw BundleCheckError(std::string("--drivetrain: ") + e.what());
    }
    b.drivetrain_source = options.drivetrain;
  } else {
    const auto names = config::builtin_drivetrain_names();
    const bool builtin = std::find(names.begin(), names.end(), head.drivetrain) != names.end();
    const fs::path file = dir / head.drivetrain;
    std::error_code ec;
    if (!builtin && !fs::is_regular_file(file, ec)) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      fail(meta, "drivetrain",
           "'" + head.drivetrain + "' is neither a built-in drivetrain (" + known +
               ") nor a file in the bundle");
    }
    b.drivetrain_source = builtin ? head.drivetrain : file.string();
    try {
      b.drivetrain = config::load_drivetrain(b.drivetrain_source);
    } catch (const std::exception& e) {
      fail(meta, "drivetrain", e.what());
    }
  }
  hal::BundleReadResult read = hal::read_bundle(dir, operating_range(b.drivetrain));
  if (!read) throw BundleCheckError(read.error.to_string());
  b.recording = std::move(*read.recording);
  b.notes = std::move(read.notes);
  check_against_drivetrain(b, dir);
  return b;
}

}  // namespace app::recording
