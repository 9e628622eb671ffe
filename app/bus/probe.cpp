// `drivetwin bus probe`: see probe.hpp.
#include "bus/probe.hpp"

#include <array>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "hal/memory_backends.hpp"
#include "hal/recording_bundle.hpp"
#include "hal/replay_backends.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "recording/mesh_lines.hpp"
#include "results/register_map.hpp"

namespace app::bus {
namespace {

/// `v` with `precision` decimals, right-aligned in `width` characters.
std::string fixed(double v, int precision, int width = 0) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << std::setw(width) << v;
  return s.str();
}

void check(hal::Status s, const std::string& what) {
  if (s != hal::Status::kOk) throw BusConfigError(what + ": " + hal::to_string(s));
}

std::string num(double v, int digits = 4) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

/// A ratio near a small whole number or its inverse, said as a hint ("" otherwise).
std::string ratio_hint(double ratio) {
  for (int n = 2; n <= 8; ++n) {
    if (std::fabs(ratio * n - 1.0) < 0.03) return " (1/" + std::to_string(n) + ")";
    if (std::fabs(ratio / n - 1.0) < 0.03) return " (" + std::to_string(n) + "x)";
  }
  return "";
}

/// One independent reading of the rotor speed.
struct SpeedReading {
  std::string source;  // "SCADA rotor_speed_rpm", ...
  double rotor_rpm = 0.0;
  std::string look_at;  // what to check when this one is the odd one out
};

}  // namespace

int run_probe(const BusConfig& c, const ProbeOptions& o, std::ostream& out) {
  const bool any_replay =
      c.scada == Backend::kReplay || c.cms == Backend::kReplay || c.keyphasor == Backend::kReplay;
  const bool stepped = o.fast && (c.scada != Backend::kLinux && c.cms != Backend::kLinux &&
                                  c.keyphasor != Backend::kLinux);
  if (o.fast && !stepped) {
    throw BusConfigError(
        "--fast works only when no bus is live hardware (modbus, socketcan, gpio)");
  }
  hal::ReplayClock clock(stepped ? 0.0 : (any_replay ? c.replay_speed : 1.0));
  const std::string f = c.file.string();

  // Every bus is opened on its own: one that fails is reported and the others are still
  // probed (a missing CAN interface must not hide the state of the SCADA link).
  std::vector<std::string> problems;  // "<bus>: <what>; look at: <what>"
  const auto open = [&](const char* bus, const std::string& look_at,
                        const std::function<void()>& step) {
    try {
      step();
      return true;
    } catch (const std::exception& e) {
      problems.push_back(std::string(bus) + ": cannot be opened: " + e.what() +
                         "; look at: " + look_at);
      out << bus << ": FAILED to open: " << e.what() << "\n";
      return false;
    }
  };

  std::optional<hal::Recording> rec;
  if (!c.bundle.empty() && any_replay) {
    (void)open("replay", "replay.bundle in " + f, [&] {
      hal::OperatingRange range;  // bus probe checks wiring, not the operating point
      auto r = hal::read_bundle(c.bundle, range);
      if (!r) throw BusConfigError(f + ": replay.bundle: " + r.error.to_string());
      rec = std::move(*r.recording);
    });
  }
  const auto need_bundle = [&] {
    if (!rec) throw BusConfigError("no readable replay.bundle");
  };

  // ---- construct and configure (no outputs live yet) ----
  std::unique_ptr<hal::ScadaSource> scada;
  if (c.scada != Backend::kNone) {
    const std::string what =
        c.scada == Backend::kLinux
            ? "the Modbus link to " + c.modbus_client.host + " ([scada] in " + f + ")"
            : "[scada] in " + f;
    if (!open("scada", what, [&] {
          switch (c.scada) {
            case Backend::kLinux:
              scada = std::make_unique<hal::ModbusScadaSource>(c.modbus_client, clock);
              break;
            case Backend::kReplay:
              if (!c.scada_csv.empty()) {
                std::string err;
                const auto cols = hal::parse_scada_columns(c.scada_columns, &err);
                if (!cols) throw BusConfigError(f + ": scada.columns: " + err);
                scada = std::make_unique<hal::ReplayScadaSource>(c.scada_csv, *cols);
              } else {
                need_bundle();
                if (rec->scada.empty())
                  throw BusConfigError(c.bundle +
                                       ": no scada.csv to replay (scada.backend = \"replay\")");
                scada = std::make_unique<hal::ReplayScadaSource>(rec->scada);
              }
              break;
            case Backend::kSim: {
              auto sim = std::make_unique<hal::SimScadaSource>(hal::sim_scada_paper_point(), clock);
              sim->inject(c.scada_fault);
              scada = std::move(sim);
              break;
            }
            case Backend::kNone:
              break;
          }
          check(scada->configure(),
                f + ": scada (" +
                    (c.scada == Backend::kLinux ? c.modbus_client.host
                                                : std::string(to_string(c.scada))) +
                    ")");
        })) {
      scada.reset();
    }
  }
  std::unique_ptr<hal::CmsStream> cms;
  std::array<std::string, hal::kCmsMaxChannels> ch_name{}, ch_unit{};
  for (std::size_t i = 0; i < hal::kCmsMaxChannels; ++i) {
    ch_name[i] = i < c.cms_channels.size() && !c.cms_channels[i].name.empty()
                     ? c.cms_channels[i].name
                     : "ch" + std::to_string(i);
    ch_unit[i] = i < c.cms_channels.size() ? c.cms_channels[i].unit : "";
  }
  if (c.cms != Backend::kNone) {
    const std::string what = c.cms == Backend::kLinux
                                 ? "the CAN interface " + c.socketcan.interface +
                                       " (ip link show " + c.socketcan.interface + ")"
                                 : "[cms] in " + f;
    if (!open("cms", what, [&] {
          switch (c.cms) {
            case Backend::kLinux:
              cms = std::make_unique<hal::SocketCanCmsStream>(c.socketcan, clock);
              break;
            case Backend::kReplay: {
              need_bundle();
              auto r = std::make_unique<hal::ReplayCmsStream>(*rec, clock);
              check(r->configure(), c.bundle + ": cms replay");
              for (std::size_t k = 0; k < r->channels(); ++k) {
                ch_name[k] = rec->channels[r->source_channel(static_cast<std::uint8_t>(k))].name;
                ch_unit[k] = rec->channels[r->source_channel(static_cast<std::uint8_t>(k))].unit;
              }
              cms = std::move(r);
              break;
            }
            case Backend::kSim: {
              hal::SimCmsConfig sc;
              auto sim = std::make_unique<hal::SimCmsStream>(sc, clock);
              sim->inject(c.cms_fault);
              for (std::size_t k = 0; k < sc.channels; ++k) ch_unit[k] = "m/s^2";
              cms = std::move(sim);
              break;
            }
            case Backend::kNone:
              break;
          }
          if (cms->state() == hal::LifecycleState::kUnconfigured)
            check(cms->configure(), f + ": cms (interface " + c.socketcan.interface + ")");
        })) {
      cms.reset();
    }
  }
  std::unique_ptr<hal::Keyphasor> kp;
  if (c.keyphasor != Backend::kNone) {
    const std::string what = c.keyphasor == Backend::kLinux
                                 ? "GPIO " + c.gpio_keyphasor.chip.chip + " line " +
                                       std::to_string(c.gpio_keyphasor.line)
                                 : "[keyphasor] in " + f;
    if (!open("keyphasor", what, [&] {
          switch (c.keyphasor) {
            case Backend::kLinux:
              kp = std::make_unique<hal::GpiodKeyphasor>(c.gpio_keyphasor);
              break;
            case Backend::kReplay:
              need_bundle();
              kp = std::make_unique<hal::ReplayKeyphasor>(*rec, clock);
              break;
            case Backend::kSim: {
              auto sim = std::make_unique<hal::SimKeyphasor>(hal::SimKeyphasorConfig{}, clock);
              sim->inject(c.keyphasor_fault);
              kp = std::move(sim);
              break;
            }
            case Backend::kNone:
              break;
          }
          check(kp->configure(), f + ": keyphasor (" + c.gpio_keyphasor.chip.chip + " line " +
                                     std::to_string(c.gpio_keyphasor.line) + ")");
        })) {
      kp.reset();
    }
  }
  std::unique_ptr<hal::DigitalOutputs> outputs;
  if (c.outputs != Backend::kNone) {
    if (!open("outputs", "GPIO " + c.gpio_outputs.chip.chip, [&] {
          if (c.outputs == Backend::kLinux)
            outputs = std::make_unique<hal::GpiodDigitalOutputs>(c.gpio_outputs);
          if (c.outputs == Backend::kSim) outputs = std::make_unique<hal::MemoryDigitalOutputs>();
          if (outputs)
            check(outputs->configure(), f + ": outputs (" + c.gpio_outputs.chip.chip + ")");
        })) {
      outputs.reset();
    }
  }
  std::unique_ptr<hal::ModbusResultsServer> results;
  // The probe does not run the twin: it serves the map's header (status word 0).
  const app::results::RegisterMap results_map(c.modbus_server.word_order);
  if (c.results == Backend::kLinux) {
    if (!open("results",
              "[results] in " + f + " (" + c.modbus_server.bind_address + ":" +
                  std::to_string(c.modbus_server.port) + " free?)",
              [&] {
                hal::ModbusServerConfig sc = c.modbus_server;
                sc.register_count = results_map.register_count();
                results = std::make_unique<hal::ModbusResultsServer>(sc);
                check(results->configure(), f + ": results (" + c.modbus_server.bind_address + ":" +
                                                std::to_string(c.modbus_server.port) + ")");
              })) {
      results.reset();
    }
  }

  // ---- activate ----
  clock.start();
  if (scada && !open("scada", "the SCADA link", [&] { check(scada->activate(), "scada"); }))
    scada.reset();
  if (cms && !open("cms", "the CMS front end", [&] { check(cms->activate(), "cms"); })) cms.reset();
  if (kp && !open("keyphasor", "the keyphasor line", [&] { check(kp->activate(), "keyphasor"); }))
    kp.reset();
  if (results && !open("results", "the results server", [&] {
        check(results->activate(), "results");
        hal::RegisterImage image;
        results_map.encode(app::results::ResultsValues{}, image);
        (void)results->publish(image);
      })) {
    results.reset();
  }
  if (results) {
    out << "results: Modbus server on " << c.modbus_server.bind_address << ":"
        << results->bound_port() << ", register map v" << app::results::kResultsMapVersion
        << " (status word 0: twin not running)\n";
  }
  if (outputs)
    out << "outputs: held in their safe states (watchdog low, alarm relay de-energised)\n";

  // ---- listen ----
  hal::KeyphasorTracker::Config kc;
  kc.pulses_per_rev = c.pulses_per_rev;
  hal::KeyphasorTracker tracker(kc);
  std::array<std::uint64_t, hal::kCmsMaxChannels> per_channel{};
  hal::CmsStreamStats last_stats{};
  std::uint64_t kp_edges = 0;
  bool scada_seen = false;
  std::uint64_t cms_total = 0;
  // What the end of the probe checks: SCADA values that never change, the CMS signal
  // (for its mesh lines and its sample rate, from the source's time stamps), speeds.
  constexpr std::size_t kMeshSamples = 65536;
  std::array<std::vector<double>, hal::kCmsMaxChannels> wave;
  std::array<hal::Timestamp, hal::kCmsMaxChannels> first_stamp{}, last_stamp{};
  std::array<std::uint64_t, hal::kCmsMaxChannels> samples_between{};
  std::array<bool, hal::kCmsMaxChannels> seen{};
  hal::ScadaData last_scada{};
  std::size_t scada_reads = 0, scada_unchanged = 0;
  double rotor_sum = 0.0, generator_sum = 0.0;
  std::size_t rotor_n = 0, generator_n = 0;
  hal::Status scada_status = hal::Status::kOk, cms_health = hal::Status::kOk;
  hal::KeyphasorTracker::State kp_state{};
  const hal::Timestamp end =
      std::chrono::duration_cast<hal::Timestamp>(std::chrono::duration<double>(o.seconds));
  hal::Timestamp next_report = o.report_every;
  hal::Timestamp last_report{0};
  const auto wall_start = std::chrono::steady_clock::now();
  std::uint64_t ticks = 0;
  while (true) {
    if (stepped) {
      clock.advance(o.tick);
    } else {
      std::this_thread::sleep_until(wall_start + o.tick * (++ticks));
    }
    const hal::Timestamp now = clock.now();
    if (cms) {
      hal::CmsBlock b;
      for (int i = 0; i < 4096 && cms->read(b) == hal::Status::kOk; ++i) {
        ++per_channel[b.channel];
        ++cms_total;
        if (!seen[b.channel]) {
          seen[b.channel] = true;
          first_stamp[b.channel] = b.stamp;
        } else {
          samples_between[b.channel] += b.count;  // samples from the first block's start
          last_stamp[b.channel] = b.stamp;
        }
        std::vector<double>& w = wave[b.channel];
        if (w.size() < kMeshSamples) {
          for (std::size_t k = 0; k < b.count && w.size() < kMeshSamples; ++k)
            w.push_back(static_cast<double>(b.samples[k]));
        }
      }
    }
    if (kp) {
      hal::KeyphasorEdge e;
      for (int i = 0; i < 1024; ++i) {
        const hal::Status st = kp->read(e);
        if (st != hal::Status::kOk && st != hal::Status::kOverflow) break;
        tracker.on_edge(e);
        ++kp_edges;
      }
    }
    if (now < next_report && now < end) continue;
    const double dt_s = std::chrono::duration<double>(now - last_report).count();
    out << "[" << fixed(std::chrono::duration<double>(now).count(), 1, 7) << " s]\n";
    if (scada) {
      hal::ScadaData d;
      const hal::Status st = scada->read(now, d);
      scada_status = st;
      scada_seen |= d.update_count > 0;
      out << "  scada: " << hal::to_string(st) << "  (updates " << d.update_count << ", errors "
          << d.error_count << ", reconnects " << d.reconnect_count << ")\n";
      for (const auto& q : hal::kScadaQuantities) {
        const hal::Measurement& m = d[q.quantity];
        if (m.stamp.count() == 0 && !m.valid) continue;
        out << "    " << std::string(q.key)
            << std::string(q.key.size() < 24 ? 24 - q.key.size() : 1, ' ') << fixed(m.value, 3, 12)
            << " " << std::string(q.unit)
            << std::string(q.unit.size() < 6 ? 6 - q.unit.size() : 1, ' ') << "age "
            << fixed(std::chrono::duration<double>(now - m.stamp).count(), 2) << " s"
            << (m.valid ? "" : "  INVALID") << "\n";
      }
      // Stuck: wind and rotor speed (quantities that always move) identical read after read.
      if (d.update_count > last_scada.update_count) {
        bool same = scada_reads > 0;
        bool any = false;
        for (const hal::ScadaQuantity q :
             {hal::ScadaQuantity::kWindSpeed, hal::ScadaQuantity::kRotorSpeed}) {
          if (!d[q].valid) continue;
          any = true;
          same &= last_scada[q].valid && d[q].value == last_scada[q].value;
        }
        if (any) {
          scada_unchanged += same ? 1 : 0;
          ++scada_reads;
        }
        last_scada = d;
      }
      if (d[hal::ScadaQuantity::kRotorSpeed].valid) {
        rotor_sum += d[hal::ScadaQuantity::kRotorSpeed].value;
        ++rotor_n;
      }
      if (d[hal::ScadaQuantity::kGeneratorSpeed].valid) {
        generator_sum += d[hal::ScadaQuantity::kGeneratorSpeed].value;
        ++generator_n;
      }
    }
    if (cms) {
      const hal::CmsStreamStats st = cms->stats();
      cms_health = cms->health(now);
      out << "  cms: " << hal::to_string(cms_health) << "  blocks/s";
      bool any = false;
      for (std::size_t ch = 0; ch < hal::kCmsMaxChannels; ++ch) {
        if (per_channel[ch] == 0) continue;
        any = true;
        out << " " << ch_name[ch] << "=" << fixed(static_cast<double>(per_channel[ch]) / dt_s, 0);
        if (!ch_unit[ch].empty()) out << " [" << ch_unit[ch] << "]";
      }
      if (!any) out << " none";
      out << "\n    gaps " << st.gaps - last_stats.gaps << " (lost "
          << st.lost_blocks - last_stats.lost_blocks << "), duplicates "
          << st.duplicates - last_stats.duplicates << ", late "
          << st.reordered - last_stats.reordered << ", malformed "
          << st.malformed - last_stats.malformed << ", error frames "
          << st.error_frames - last_stats.error_frames << ", bus-off "
          << st.bus_off - last_stats.bus_off << ", overflows "
          << st.overflows - last_stats.overflows << "\n";
      last_stats = st;
      per_channel.fill(0);
    }
    if (kp) {
      const auto st = tracker.state(now);
      kp_state = st;
      out << "  keyphasor: ";
      if (st.valid) {
        out << c.keyphasor_shaft << " " << fixed(st.speed_hz, 4)
            << " Hz = " << fixed(st.speed_hz * 60.0, 1) << " rpm";
      } else {
        out << "no valid speed";
      }
      out << "  (edges " << kp_edges << ", glitches " << st.glitches << ", lost " << st.lost
          << ")\n";
    }
    out.flush();
    last_report = now;
    next_report = now + o.report_every;
    if (now >= end) break;
  }

  // ---- deactivate (safe outputs) ----
  if (scada) (void)scada->deactivate();
  if (cms) (void)cms->deactivate();
  if (kp) (void)kp->deactivate();
  if (outputs) (void)outputs->deactivate();
  if (results) (void)results->deactivate();

  // ---- verdict: stale, stuck, inconsistent ----
  std::string silent;
  if (scada && !scada_seen) silent += " scada";
  if (cms && cms_total == 0) silent += " cms";
  if (kp && kp_edges == 0) silent += " keyphasor";
  // At the end of the probe: stale or dead is a problem; lost data is a warning (shown,
  // counted, not failing); no new value since the last read, or a replay at its end, is fine.
  const auto failing = [](hal::Status st) {
    return st == hal::Status::kStale || st == hal::Status::kTimeout ||
           st == hal::Status::kDisconnected || st == hal::Status::kBusOff ||
           st == hal::Status::kIoError || st == hal::Status::kWrongState ||
           st == hal::Status::kInvalidConfig || st == hal::Status::kProtocolError;
  };
  const auto fine = [](hal::Status st) {
    return st == hal::Status::kOk || st == hal::Status::kNoData || st == hal::Status::kEndOfData;
  };
  std::vector<std::string> warnings;
  if (scada && scada_seen && failing(scada_status)) {
    problems.push_back(std::string("scada: ") + hal::to_string(scada_status) +
                       " at the end of the probe; look at: the Modbus link and the "
                       "controller's update rate (register map in " +
                       f + ")");
  } else if (scada && scada_seen && !fine(scada_status)) {
    warnings.push_back(std::string("scada: ") + hal::to_string(scada_status) +
                       " at the end of the probe");
  }
  if (scada && scada_reads >= 3 && scada_unchanged + 1 >= scada_reads) {
    problems.push_back("scada: stuck: wind and rotor speed identical in " +
                       std::to_string(scada_reads) +
                       " updates in a row; look at: the controller's register refresh (a frozen "
                       "SCADA value block) or the register addresses");
  }
  const hal::CmsStreamStats cst = cms ? cms->stats() : hal::CmsStreamStats{};
  if (cms && cms_total > 0 && failing(cms_health)) {
    problems.push_back(std::string("cms: ") + hal::to_string(cms_health) +
                       " at the end of the probe" +
                       (cst.duplicates > 0 ? " after " + std::to_string(cst.duplicates) +
                                                 " duplicate blocks (the front end repeats one "
                                                 "frame: a stuck sequence counter)"
                                           : std::string()) +
                       "; look at: the CMS front end's streaming and the CAN link");
  } else if (cms && cst.duplicates > 0) {
    problems.push_back("cms: " + std::to_string(cst.duplicates) +
                       " duplicate blocks; look at: the CMS front end (repeated frames)");
  } else if (cms && cms_total > 0 && !fine(cms_health)) {
    warnings.push_back(std::string("cms: ") + hal::to_string(cms_health) +
                       " at the end of the probe");
  }
  if (cms && cst.lost_blocks > 0) {
    warnings.push_back("cms: " + std::to_string(cst.lost_blocks) + " blocks lost in " +
                       std::to_string(cst.gaps) +
                       " gaps (bus load, termination, the front end's buffer)");
  }
  if (kp && kp_edges > 0 && !kp_state.valid) {
    problems.push_back("keyphasor: edges arrive but give no valid speed (glitches " +
                       std::to_string(kp_state.glitches) +
                       "); look at: the sensor gap and the line's debounce");
  }

  // Redundant speeds, as rotor speed through the drivetrain's ratios.
  const model::Kinematics kin(o.drivetrain);
  std::vector<SpeedReading> speeds;
  if (rotor_n > 0) {
    speeds.push_back({"SCADA rotor_speed_rpm", rotor_sum / static_cast<double>(rotor_n),
                      "the rotor speed register (scaling, unit)"});
  }
  if (generator_n > 0) {
    speeds.push_back({"SCADA generator_speed_rpm / " + num(kin.overall_ratio(), 6),
                      generator_sum / static_cast<double>(generator_n) / kin.overall_ratio(),
                      "the generator speed register (scaling, unit) or the drivetrain's ratio"});
  }
  if (kp && kp_state.valid) {
    const auto per_rpm = kin.shaft_hz(c.keyphasor_shaft, 1.0);
    if (per_rpm && *per_rpm > 0.0) {
      speeds.push_back({"keyphasor on " + c.keyphasor_shaft + " (pulses_per_rev " +
                            std::to_string(c.pulses_per_rev) + ")",
                        kp_state.speed_hz / *per_rpm,
                        "keyphasor.pulses_per_rev and keyphasor.shaft in " + f});
    }
  }
  // CMS mesh lines, at the rate the source's time stamps give, against the median so far.
  if (cms && !speeds.empty()) {
    std::vector<double> v;
    for (const auto& r : speeds) v.push_back(r.rotor_rpm);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    const double ref_rpm = v[v.size() / 2];
    std::vector<const std::vector<double>*> accel;
    std::string names;
    double fs = 0.0;
    for (std::size_t ch = 0; ch < hal::kCmsMaxChannels; ++ch) {
      if (wave[ch].size() < 4096 || samples_between[ch] == 0) continue;
      const auto unit = hal::parse_unit(ch_unit[ch].empty() ? "m/s^2" : ch_unit[ch]);
      if (!unit || unit->quantity != hal::UnitQuantity::kAcceleration) continue;
      const double span_s = std::chrono::duration<double>(last_stamp[ch] - first_stamp[ch]).count();
      if (!(span_s > 0.0)) continue;
      fs = static_cast<double>(samples_between[ch]) / span_s;
      accel.push_back(&wave[ch]);
      names += (names.empty() ? "" : ", ") + ch_name[ch];
    }
    if (!accel.empty() && ref_rpm > 0.0) {
      std::vector<double> expected;
      for (std::size_t st = 0; st < kin.stage_count(); ++st)
        expected.push_back(kin.mesh_hz(st, ref_rpm));
      const recording::MeshLineScale m = recording::find_mesh_line_scale(accel, fs, expected);
      if (m.lines > 0) {
        speeds.push_back(
            {"CMS mesh lines of " + names + " (" + num(fs, 6) + " Hz)", m.scale * ref_rpm,
             "the CMS sample rate and channel scaling, or the drivetrain description"});
      }
    }
  }
  if (!speeds.empty()) {
    std::vector<double> v;
    for (const auto& r : speeds) v.push_back(r.rotor_rpm);
    std::sort(v.begin(), v.end());
    const double median = v[(v.size() - 1) / 2];
    out << "speeds (as rotor rpm, drivetrain '" << o.drivetrain.name << "'):";
    for (const auto& r : speeds) out << " " << r.source << " " << num(r.rotor_rpm) << ";";
    out << "\n";
    for (const auto& r : speeds) {
      if (speeds.size() < 2 || !(median > 0.0)) break;
      const double ratio = r.rotor_rpm / median;
      if (std::fabs(ratio - 1.0) <= recording::kSpeedTolerance) continue;
      problems.push_back("speeds disagree: " + r.source + " gives " + num(r.rotor_rpm) +
                         " rotor rpm, " + num(ratio, 3) + ratio_hint(ratio) + " x the " +
                         num(median) + " of the others" +
                         (speeds.size() == 2 ? " (two readings: either may be wrong)" : "") +
                         "; look at: " + r.look_at);
    }
  }

  if (!warnings.empty()) {
    out << "warnings (" << warnings.size() << "):\n";
    for (const auto& w : warnings) out << "  " << w << "\n";
  }
  if (!problems.empty()) {
    out << "PROBLEMS (" << problems.size() << "):\n";
    for (const auto& p : problems) out << "  " << p << "\n";
  }
  if (!silent.empty()) out << "no data from:" << silent << "\n";
  if (!problems.empty()) return 4;
  if (!silent.empty()) return 3;
  out << "every bus delivered data; nothing stale, stuck or inconsistent\n";
  return 0;
}

}  // namespace app::bus
