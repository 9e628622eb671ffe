// The twin's persistence in `drivetwin run`: see twin_persistence.hpp.
#include "persistence/twin_persistence.hpp"

#include <fstream>
#include <limits>
#include <sstream>

#include "persistence/accumulator_store.hpp"

namespace app::persistence {
namespace fat = model::fatigue;

TwinPersistence::TwinPersistence(const TwinPersistenceSettings& settings,
                                 const fat::ChannelSet& channels,
                                 const fat::AccumulatorConfig& config)
    : settings_(settings),
      channels_(channels),
      config_(config),
      store_(settings.state_dir, "twin-state"),
      histories_(channels.channel_count(),
                 fat::DamageRateHistory(settings.rul_interval_s, settings.rul_short_window)),
      boundary_(channels.channel_count(), 0.0) {
  const fat::DamageAccumulator probe(channels_, config_);
  layout_ = layout_of(probe);
}

TwinLoad TwinPersistence::load() {
  TwinLoad out;
  auto acc = std::make_unique<fat::DamageAccumulator>(channels_, config_);
  StateLoad l = store_.load();
  for (const std::string& p : l.problems) out.lines.push_back("WARN: state: " + p);
  if (l.record) {
    std::string error;
    std::optional<TwinState> s = decode_twin_state(*l.record, &error);
    if (!s) {
      out.lines.push_back("WARN: state: " + l.copy + ": " + error + "; not used (kept on disk)");
    } else {
      std::vector<RetiredChannel> retired;
      const CarryOver co = restore_accumulator(*s, *acc, retired);
      out.restored = true;
      out.lines.push_back("state: " + l.copy + " (generation " +
                          std::to_string(l.record->generation) +
                          "): " + (co.exact ? "restored" : "carried over to this configuration") +
                          ", " + std::to_string(acc->elapsed_s() / 3600.0) + " h accumulated");
      for (const std::string& n : co.notes) out.lines.push_back("state: " + n);
      std::string note;
      const std::lock_guard<std::mutex> lock(mutex_);
      retired_ = retired;
      for (std::size_t c = 0; c < boundary_.size(); ++c) boundary_[c] = acc->damage(c);
      if (s->rate && !restore_rate_histories(*s->rate, s->layout.keys, layout_.keys, histories_,
                                             boundary_, &note))
        out.lines.push_back("WARN: state: " + note);
      out.calibration = s->calibration;
    }
  } else if (l.first_start) {
    // The former single-file store, if this configuration wrote it.
    const AccumulatorStore old(settings_.state_dir / "accumulators.state");
    auto st = std::make_unique<fat::AccumulatorState>();
    const LoadResult r = old.load(*st);
    if (r.ok() && acc->restore(*st)) {
      out.restored = true;
      out.lines.push_back("state: taken over from " + old.path().string() + ", " +
                          std::to_string(acc->elapsed_s() / 3600.0) + " h accumulated");
      const std::lock_guard<std::mutex> lock(mutex_);
      for (std::size_t c = 0; c < boundary_.size(); ++c) boundary_[c] = acc->damage(c);
    } else if (r.status != LoadStatus::kNoState) {
      out.lines.push_back(
          "WARN: state: " + old.path().string() + ": " +
          (r.ok() ? std::string("another configuration's damage (no channel keys to carry it by)")
                  : r.message) +
          "; kept on disk, not used");
    } else {
      out.lines.push_back("state: none in " + settings_.state_dir.string() + " (a first start)");
    }
  } else {
    out.lines.push_back(
        "WARN: state: no valid copy in " + settings_.state_dir.string() +
        ": the damage starts from zero; the bad copies are overwritten by the next saves");
  }
  out.accumulator = std::make_unique<fat::AccumulatorState>(acc->state());
  return out;
}

std::vector<double> TwinPersistence::add_interval(const std::vector<double>& damage) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<double> rul_low_h(histories_.size(), std::numeric_limits<double>::infinity());
  for (std::size_t c = 0; c < histories_.size() && c < damage.size(); ++c) {
    histories_[c].add_interval(damage[c] - boundary_[c]);
    boundary_[c] = damage[c];
    rul_low_h[c] = histories_[c].estimate(damage[c]).rul_low_s / 3600.0;
  }
  return rul_low_h;
}

bool TwinPersistence::save(const fat::AccumulatorState& checkpoint, std::int64_t now_ns,
                           std::string* error) {
  TwinState s;
  s.layout = layout_;
  s.accumulator = std::make_unique<fat::AccumulatorState>(checkpoint);
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    s.rate = record_of(histories_, boundary_);
    s.retired = retired_;
  }
  if (!settings_.calibration_file.empty()) {
    std::ifstream in(settings_.calibration_file, std::ios::binary);
    if (in) {
      std::ostringstream text;
      text << in.rdbuf();
      const std::string t = text.str();
      CalibrationRecord c;
      c.format = t.substr(0, t.find('\n'));
      c.text = t;
      s.calibration = std::move(c);
    }
  }
  const bool ok = store_.save(encode_twin_state(s), now_ns, error);
  if (ok) ++saves_;
  return ok;
}

}  // namespace app::persistence
