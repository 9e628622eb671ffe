// `drivetwin bus probe`: see probe.hpp.
#include "bus/probe.hpp"

#include <array>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "hal/memory_backends.hpp"
#include "hal/recording_bundle.hpp"
#include "hal/replay_backends.hpp"
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

  std::optional<hal::Recording> rec;
  if (!c.bundle.empty() && any_replay) {
    hal::OperatingRange range;  // bus probe checks wiring, not the operating point
    auto r = hal::read_bundle(c.bundle, range);
    if (!r) throw BusConfigError(c.file.string() + ": replay.bundle: " + r.error.to_string());
    rec = std::move(*r.recording);
  }

  // ---- construct (no I/O) ----
  std::unique_ptr<hal::ScadaSource> scada;
  switch (c.scada) {
    case Backend::kLinux:
      scada = std::make_unique<hal::ModbusScadaSource>(c.modbus_client, clock);
      break;
    case Backend::kReplay:
      if (!c.scada_csv.empty()) {
        std::string err;
        const auto cols = hal::parse_scada_columns(c.scada_columns, &err);
        if (!cols) throw BusConfigError(c.file.string() + ": scada.columns: " + err);
        scada = std::make_unique<hal::ReplayScadaSource>(c.scada_csv, *cols);
      } else {
        if (rec->scada.empty())
          throw BusConfigError(c.bundle + ": no scada.csv to replay (scada.backend = \"replay\")");
        scada = std::make_unique<hal::ReplayScadaSource>(rec->scada);
      }
      break;
    case Backend::kSim: {
      auto s = std::make_unique<hal::SimScadaSource>(hal::sim_scada_paper_point(), clock);
      s->inject(c.scada_fault);
      scada = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  std::unique_ptr<hal::CmsStream> cms;
  std::array<std::string, hal::kCmsMaxChannels> ch_name{}, ch_unit{};
  for (std::size_t i = 0; i < hal::kCmsMaxChannels; ++i) {
    ch_name[i] = i < c.cms_channels.size() && !c.cms_channels[i].name.empty()
                     ? c.cms_channels[i].name
                     : "ch" + std::to_string(i);
    ch_unit[i] = i < c.cms_channels.size() ? c.cms_channels[i].unit : "";
  }
  switch (c.cms) {
    case Backend::kLinux:
      cms = std::make_unique<hal::SocketCanCmsStream>(c.socketcan, clock);
      break;
    case Backend::kReplay: {
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
      auto s = std::make_unique<hal::SimCmsStream>(sc, clock);
      s->inject(c.cms_fault);
      for (std::size_t k = 0; k < sc.channels; ++k) ch_unit[k] = "m/s^2";
      cms = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  std::unique_ptr<hal::Keyphasor> kp;
  switch (c.keyphasor) {
    case Backend::kLinux:
      kp = std::make_unique<hal::GpiodKeyphasor>(c.gpio_keyphasor);
      break;
    case Backend::kReplay:
      kp = std::make_unique<hal::ReplayKeyphasor>(*rec, clock);
      break;
    case Backend::kSim: {
      auto s = std::make_unique<hal::SimKeyphasor>(hal::SimKeyphasorConfig{}, clock);
      s->inject(c.keyphasor_fault);
      kp = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  std::unique_ptr<hal::DigitalOutputs> outputs;
  if (c.outputs == Backend::kLinux)
    outputs = std::make_unique<hal::GpiodDigitalOutputs>(c.gpio_outputs);
  if (c.outputs == Backend::kSim) outputs = std::make_unique<hal::MemoryDigitalOutputs>();
  std::unique_ptr<hal::ModbusResultsServer> results;
  // The probe does not run the twin: it serves the map's header (status word 0).
  const app::results::RegisterMap results_map(c.modbus_server.word_order);
  if (c.results == Backend::kLinux) {
    hal::ModbusServerConfig sc = c.modbus_server;
    sc.register_count = results_map.register_count();
    results = std::make_unique<hal::ModbusResultsServer>(sc);
  }

  // ---- configure + activate ----
  const std::string f = c.file.string();
  if (scada) {
    check(scada->configure(), f + ": scada (" +
                                  (c.scada == Backend::kLinux ? c.modbus_client.host
                                                              : std::string(to_string(c.scada))) +
                                  ")");
  }
  if (cms && cms->state() == hal::LifecycleState::kUnconfigured)
    check(cms->configure(), f + ": cms (interface " + c.socketcan.interface + ")");
  if (kp) {
    check(kp->configure(), f + ": keyphasor (" + c.gpio_keyphasor.chip.chip + " line " +
                               std::to_string(c.gpio_keyphasor.line) + ")");
  }
  if (outputs) check(outputs->configure(), f + ": outputs (" + c.gpio_outputs.chip.chip + ")");
  if (results) {
    check(results->configure(), f + ": results (" + c.modbus_server.bind_address + ":" +
                                    std::to_string(c.modbus_server.port) + ")");
  }
  clock.start();
  if (scada) check(scada->activate(), "scada");
  if (cms) check(cms->activate(), "cms");
  if (kp) check(kp->activate(), "keyphasor");
  if (results) {
    check(results->activate(), "results");
    hal::RegisterImage image;
    results_map.encode(app::results::ResultsValues{}, image);
    (void)results->publish(image);
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
      }
    }
    if (kp) {
      hal::KeyphasorEdge e;
      for (int i = 0; i < 1024; ++i) {
        const hal::Status s = kp->read(e);
        if (s != hal::Status::kOk && s != hal::Status::kOverflow) break;
        tracker.on_edge(e);
        ++kp_edges;
      }
    }
    if (now < next_report && now < end) continue;
    const double dt_s = std::chrono::duration<double>(now - last_report).count();
    out << "[" << fixed(std::chrono::duration<double>(now).count(), 1, 7) << " s]\n";
    if (scada) {
      hal::ScadaData d;
      const hal::Status s = scada->read(now, d);
      scada_seen |= d.update_count > 0;
      out << "  scada: " << hal::to_string(s) << "  (updates " << d.update_count << ", errors "
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
    }
    if (cms) {
      const hal::CmsStreamStats st = cms->stats();
      out << "  cms: " << hal::to_string(cms->health(now)) << "  blocks/s";
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
      const auto s = tracker.state(now);
      out << "  keyphasor: ";
      if (s.valid) {
        out << c.keyphasor_shaft << " " << fixed(s.speed_hz, 4)
            << " Hz = " << fixed(s.speed_hz * 60.0, 1) << " rpm";
      } else {
        out << "no valid speed";
      }
      out << "  (edges " << kp_edges << ", glitches " << s.glitches << ", lost " << s.lost << ")\n";
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

  std::string silent;
  if (scada && !scada_seen) silent += " scada";
  if (cms && cms_total == 0) silent += " cms";
  if (kp && kp_edges == 0) silent += " keyphasor";
  if (!silent.empty()) {
    out << "no data from:" << silent << "\n";
    return 3;
  }
  return 0;
}

}  // namespace app::bus
