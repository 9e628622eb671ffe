// The twin's persistent state as state-record sections: see twin_state.hpp.
#include "persistence/twin_state.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>

namespace app::persistence {
namespace fat = model::fatigue;

namespace {

// ---- little-endian byte writer / reader ----------------------------------------------------

class Writer {
 public:
  void u32(std::uint32_t v) { put(&v, sizeof v); }
  void u64(std::uint64_t v) { put(&v, sizeof v); }
  void f64(double v) { put(&v, sizeof v); }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    put(s.data(), s.size());
  }
  std::vector<unsigned char> take() { return std::move(bytes_); }

 private:
  void put(const void* p, std::size_t n) {
    static_assert(std::endian::native == std::endian::little, "the state format is little-endian");
    const auto* c = static_cast<const unsigned char*>(p);
    bytes_.insert(bytes_.end(), c, c + n);
  }
  std::vector<unsigned char> bytes_;
};

class Reader {
 public:
  Reader(const StateSection& s, const char* name) : b_(s.bytes), name_(name) {}
  bool u32(std::uint32_t& v) { return get(&v, sizeof v); }
  bool u64(std::uint64_t& v) { return get(&v, sizeof v); }
  bool f64(double& v) { return get(&v, sizeof v); }
  bool str(std::string& s) {
    std::uint32_t n = 0;
    if (!u32(n) || n > b_.size() - at_) return fail("a string runs past the end");
    s.assign(reinterpret_cast<const char*>(b_.data() + at_), n);
    at_ += n;
    return true;
  }
  /// A count that must be ≤ limit.
  bool count(std::uint32_t& v, std::size_t limit, const char* what) {
    if (!u32(v)) return false;
    if (v > limit)
      return fail(std::string(what) + " " + std::to_string(v) + " exceeds " +
                  std::to_string(limit));
    return true;
  }
  bool done() {
    if (at_ != b_.size()) return fail(std::to_string(b_.size() - at_) + " bytes left over");
    return true;
  }
  bool fail(const std::string& why) {
    if (error_.empty()) error_ = std::string("section ") + name_ + ": " + why;
    return false;
  }
  const std::string& error() const { return error_; }

 private:
  bool get(void* p, std::size_t n) {
    if (n > b_.size() - at_) return fail("truncated at byte " + std::to_string(at_));
    std::memcpy(p, b_.data() + at_, n);
    at_ += n;
    return true;
  }
  const std::vector<unsigned char>& b_;
  const char* name_;
  std::size_t at_ = 0;
  std::string error_;
};

StateSection section(TwinSection id, std::uint32_t version, Writer& w) {
  return {static_cast<std::uint32_t>(id), version, w.take()};
}

// Distributes `values` (real, ≥ 0) to integers whose sum is `target`: floors, then +1 to the
// largest remainders (Hamilton), so totals stay exact.
std::vector<std::uint64_t> apportion(const std::vector<long double>& values, std::uint64_t target) {
  std::vector<std::uint64_t> out(values.size());
  std::uint64_t sum = 0;
  std::vector<std::pair<long double, std::size_t>> rem;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const long double v = std::max<long double>(0.0L, values[i]);
    out[i] = static_cast<std::uint64_t>(std::floor(v));
    sum += out[i];
    rem.emplace_back(v - std::floor(v), i);
  }
  std::sort(rem.begin(), rem.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; sum < target && k < rem.size(); ++k, ++sum) ++out[rem[k].second];
  // (sum > target only by rounding of the inputs: take back from the smallest remainders)
  for (std::size_t k = rem.size(); sum > target && k > 0; --k)
    if (out[rem[k - 1].second] > 0) {
      --out[rem[k - 1].second];
      --sum;
    }
  return out;
}

// One saved channel's histogram onto a new bin layout (bins + overflow each). @return the
// largest stress that went into the new overflow bin (0: none), for its overflow maximum.
double rebin(const std::uint64_t* src, std::uint32_t src_bins, double src_fs, double overflow_max,
             long double scale, std::uint64_t* dst, std::uint32_t dst_bins, double dst_fs) {
  double into_overflow = 0.0;
  std::vector<long double> acc(dst_bins + 1, 0.0L);
  const long double ws = static_cast<long double>(src_fs) / src_bins;
  const long double wd = static_cast<long double>(dst_fs) / dst_bins;
  long double total = 0.0L;
  for (std::uint32_t i = 0; i < src_bins; ++i) {
    if (src[i] == 0) continue;
    const long double v = static_cast<long double>(src[i]) * scale;
    total += v;
    const long double lo = i * ws, hi = (i + 1) * ws;
    // Overlap with each destination bin; beyond dst_fs into the overflow.
    auto j = static_cast<std::uint32_t>(std::min<long double>(dst_bins, std::floor(lo / wd)));
    for (; j < dst_bins; ++j) {
      const long double a = std::max(lo, j * wd), b = std::min(hi, (j + 1) * wd);
      if (b <= a) {
        if (j * wd >= hi) break;
        continue;
      }
      acc[j] += v * (b - a) / ws;
    }
    if (hi > dst_bins * wd) {
      acc[dst_bins] += v * (hi - std::max(lo, dst_bins * wd)) / ws;
      into_overflow = std::max(into_overflow, static_cast<double>(hi));
    }
  }
  if (src[src_bins] > 0) {
    const long double v = static_cast<long double>(src[src_bins]) * scale;
    total += v;
    const bool inside = overflow_max < dst_fs;
    const auto j = inside ? std::min<std::uint32_t>(
                                dst_bins - 1,
                                static_cast<std::uint32_t>(overflow_max / static_cast<double>(wd)))
                          : dst_bins;
    acc[j] += v;
    if (!inside) into_overflow = std::max(into_overflow, overflow_max);
  }
  const auto out = apportion(acc, static_cast<std::uint64_t>(std::llround(total)));
  std::copy(out.begin(), out.end(), dst);
  return into_overflow;
}

}  // namespace

std::string channel_key(const fat::Channel& c) {
  std::string k = c.component;
  if (!c.detail.empty()) k += "/" + c.detail;
  return k + "/" + fat::failure_mode_name(c.mode);
}

AccumulatorLayout layout_of(const fat::DamageAccumulator& acc) {
  AccumulatorLayout l;
  l.tick_s = acc.config().tick_s;
  l.bins = acc.config().bins;
  const fat::ChannelSet& cs = acc.channels();
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    l.keys.push_back(channel_key(cs.channel(c)));
    l.full_scale.push_back(acc.config().full_scale[c]);
    l.source_count.push_back(static_cast<std::uint32_t>(cs.channel(c).source_count));
  }
  return l;
}

RateHistoryRecord record_of(const std::vector<fat::DamageRateHistory>& histories,
                            const std::vector<double>& boundary) {
  RateHistoryRecord r;
  if (!histories.empty()) {
    r.interval_s = histories.front().interval_s();
    r.short_window = histories.front().short_window();
  }
  for (std::size_t c = 0; c < histories.size(); ++c) {
    const fat::DamageRateHistory& h = histories[c];
    RateHistoryRecord::Channel ch;
    for (std::size_t i = 0; i < h.size(); ++i) ch.increments.push_back(h.increment(i));
    ch.total_increment = h.total_increment();
    ch.total_intervals = h.total_intervals();
    ch.damage_at_boundary = c < boundary.size() ? boundary[c] : 0.0;
    r.channels.push_back(std::move(ch));
  }
  return r;
}

std::vector<StateSection> encode_twin_state(const TwinState& s) {
  std::vector<StateSection> out;
  const AccumulatorLayout& l = s.layout;
  const auto n = static_cast<std::uint32_t>(l.keys.size());
  {
    Writer w;
    w.f64(l.tick_s);
    w.u32(l.bins);
    w.u32(n);
    for (std::uint32_t c = 0; c < n; ++c) {
      w.str(l.keys[c]);
      w.f64(l.full_scale[c]);
      w.u32(l.source_count[c]);
    }
    out.push_back(section(TwinSection::kLayout, kLayoutVersion, w));
  }
  {
    const fat::AccumulatorState& a = *s.accumulator;
    Writer w;
    w.u32(a.version);
    w.u64(a.config_hash);
    for (const std::uint64_t v : {a.elapsed_ticks, a.rotor_rev_q, a.valid_steps, a.bad_load_steps,
                                  a.bad_speed_steps, a.zero_dt_steps})
      w.u64(v);
    for (std::uint32_t c = 0; c < n; ++c) {
      w.f64(a.damage[c]);
      w.f64(a.damage_comp[c]);
      w.f64(a.overflow_max[c]);
      for (std::uint32_t i = 0; i <= l.bins; ++i) w.u64(a.bin_ticks[c][i]);
      for (std::uint32_t i = 0; i <= l.bins; ++i) w.u64(a.bin_rev_q[c][i]);
    }
    out.push_back(section(TwinSection::kAccumulator, kAccumulatorSectionVersion, w));
  }
  if (s.rate) {
    Writer w;
    w.f64(s.rate->interval_s);
    w.u64(s.rate->short_window);
    w.u32(static_cast<std::uint32_t>(s.rate->channels.size()));
    for (const auto& ch : s.rate->channels) {
      w.f64(ch.damage_at_boundary);
      w.f64(ch.total_increment);
      w.u64(ch.total_intervals);
      w.u32(static_cast<std::uint32_t>(ch.increments.size()));
      for (const double v : ch.increments) w.f64(v);
    }
    out.push_back(section(TwinSection::kRateHistory, kRateHistoryVersion, w));
  }
  if (s.calibration) {
    Writer w;
    w.u32(s.calibration->generation);
    w.str(s.calibration->format);
    w.str(s.calibration->text);
    out.push_back(section(TwinSection::kCalibration, kCalibrationVersion, w));
  }
  {
    Writer w;
    w.u32(static_cast<std::uint32_t>(s.retired.size()));
    for (const RetiredChannel& r : s.retired) {
      w.str(r.key);
      w.f64(r.damage);
      w.f64(r.elapsed_s);
    }
    out.push_back(section(TwinSection::kRetired, kRetiredVersion, w));
  }
  return out;
}

std::optional<TwinState> decode_twin_state(const StateRecord& record, std::string* error) {
  const auto fail = [&](const std::string& why) -> std::optional<TwinState> {
    if (error) *error = why;
    return std::nullopt;
  };
  const auto need = [&](TwinSection id, std::uint32_t version, const char* name,
                        const StateSection*& out) -> std::string {
    out = record.find(static_cast<std::uint32_t>(id));
    if (out == nullptr) return "";
    if (out->version != version)
      return std::string("section ") + name + ": layout version " + std::to_string(out->version) +
             " (this build reads " + std::to_string(version) + ")";
    return "";
  };
  TwinState s;
  const StateSection* sec = nullptr;
  if (auto e = need(TwinSection::kLayout, kLayoutVersion, "layout", sec); !e.empty())
    return fail(e);
  if (sec == nullptr) return fail("no layout section");
  std::uint32_t n = 0;
  {
    Reader r(*sec, "layout");
    bool ok = r.f64(s.layout.tick_s) && r.u32(s.layout.bins) &&
              r.count(n, fat::kMaxChannels, "channel count");
    if (ok && (s.layout.bins == 0 || s.layout.bins > fat::kMaxBins))
      ok = r.fail("bins " + std::to_string(s.layout.bins) + " out of range");
    if (ok && !(s.layout.tick_s > 0.0 && std::isfinite(s.layout.tick_s)))
      ok = r.fail("tick is not a positive number");
    for (std::uint32_t c = 0; ok && c < n; ++c) {
      std::string key;
      double fs = 0.0;
      std::uint32_t src = 0;
      ok = r.str(key) && r.f64(fs) && r.u32(src);
      if (ok && !(fs > 0.0 && std::isfinite(fs)))
        ok = r.fail("channel " + key + ": full scale is not a positive number");
      s.layout.keys.push_back(key);
      s.layout.full_scale.push_back(fs);
      s.layout.source_count.push_back(src);
    }
    if (!ok || !r.done()) return fail(r.error());
  }
  if (auto e = need(TwinSection::kAccumulator, kAccumulatorSectionVersion, "accumulator", sec);
      !e.empty())
    return fail(e);
  if (sec == nullptr) return fail("no accumulator section");
  {
    s.accumulator = std::make_unique<fat::AccumulatorState>();
    fat::AccumulatorState& a = *s.accumulator;
    Reader r(*sec, "accumulator");
    bool ok = r.u32(a.version) && r.u64(a.config_hash) && r.u64(a.elapsed_ticks) &&
              r.u64(a.rotor_rev_q) && r.u64(a.valid_steps) && r.u64(a.bad_load_steps) &&
              r.u64(a.bad_speed_steps) && r.u64(a.zero_dt_steps);
    a.channel_count = n;
    a.bins = s.layout.bins;
    for (std::uint32_t c = 0; ok && c < n; ++c) {
      ok = r.f64(a.damage[c]) && r.f64(a.damage_comp[c]) && r.f64(a.overflow_max[c]);
      for (std::uint32_t i = 0; ok && i <= s.layout.bins; ++i) ok = r.u64(a.bin_ticks[c][i]);
      for (std::uint32_t i = 0; ok && i <= s.layout.bins; ++i) ok = r.u64(a.bin_rev_q[c][i]);
      if (ok && !(std::isfinite(a.damage[c]) && a.damage[c] >= 0.0))
        ok = r.fail("channel " + s.layout.keys[c] + ": damage is not a finite non-negative number");
    }
    if (!ok || !r.done()) return fail(r.error());
  }
  if (auto e = need(TwinSection::kRateHistory, kRateHistoryVersion, "rate history", sec);
      !e.empty())
    return fail(e);
  if (sec != nullptr) {
    RateHistoryRecord rh;
    Reader r(*sec, "rate history");
    std::uint32_t m = 0;
    bool ok = r.f64(rh.interval_s) && r.u64(rh.short_window) &&
              r.count(m, fat::kMaxChannels, "channel count");
    for (std::uint32_t c = 0; ok && c < m; ++c) {
      RateHistoryRecord::Channel ch;
      std::uint32_t k = 0;
      ok = r.f64(ch.damage_at_boundary) && r.f64(ch.total_increment) && r.u64(ch.total_intervals) &&
           r.count(k, fat::kMaxRateIntervals, "interval count");
      for (std::uint32_t i = 0; ok && i < k; ++i) {
        double v = 0.0;
        ok = r.f64(v);
        ch.increments.push_back(v);
      }
      rh.channels.push_back(std::move(ch));
    }
    if (!ok || !r.done()) return fail(r.error());
    s.rate = std::move(rh);
  }
  if (auto e = need(TwinSection::kCalibration, kCalibrationVersion, "calibration", sec); !e.empty())
    return fail(e);
  if (sec != nullptr) {
    CalibrationRecord cr;
    Reader r(*sec, "calibration");
    if (!(r.u32(cr.generation) && r.str(cr.format) && r.str(cr.text)) || !r.done())
      return fail(r.error());
    s.calibration = std::move(cr);
  }
  if (auto e = need(TwinSection::kRetired, kRetiredVersion, "retired", sec); !e.empty())
    return fail(e);
  if (sec != nullptr) {
    Reader r(*sec, "retired");
    std::uint32_t m = 0;
    bool ok = r.count(m, 4096, "retired channel count");
    for (std::uint32_t i = 0; ok && i < m; ++i) {
      RetiredChannel rc;
      ok = r.str(rc.key) && r.f64(rc.damage) && r.f64(rc.elapsed_s);
      s.retired.push_back(rc);
    }
    if (!ok || !r.done()) return fail(r.error());
  }
  return s;
}

CarryOver restore_accumulator(const TwinState& saved, fat::DamageAccumulator& acc,
                              std::vector<RetiredChannel>& retired) {
  CarryOver co;
  acc.reset();
  retired = saved.retired;
  const AccumulatorLayout now = layout_of(acc);
  const AccumulatorLayout& was = saved.layout;
  const fat::AccumulatorState& old = *saved.accumulator;
  const bool same = now.tick_s == was.tick_s && now.bins == was.bins && now.keys == was.keys &&
                    now.full_scale == was.full_scale && now.source_count == was.source_count;
  if (same && acc.restore(old)) {
    co.exact = true;
    co.matched = now.keys.size();
    return co;
  }
  // Carry over by key.
  auto st = std::make_unique<fat::AccumulatorState>(acc.state());  // zero, the new hash
  const long double tick_scale =
      static_cast<long double>(was.tick_s) / static_cast<long double>(now.tick_s);
  st->elapsed_ticks = static_cast<std::uint64_t>(std::llround(old.elapsed_ticks * tick_scale));
  st->rotor_rev_q = old.rotor_rev_q;
  st->valid_steps = old.valid_steps;
  st->bad_load_steps = old.bad_load_steps;
  st->bad_speed_steps = old.bad_speed_steps;
  st->zero_dt_steps = old.zero_dt_steps;
  if (now.tick_s != was.tick_s)
    co.notes.push_back("tick " + std::to_string(was.tick_s) + " s → " + std::to_string(now.tick_s) +
                       " s (ROM rate changed): histogram times converted");
  std::map<std::string, std::size_t> saved_index;
  for (std::size_t c = 0; c < was.keys.size(); ++c) saved_index[was.keys[c]] = c;
  std::vector<bool> used(was.keys.size(), false);
  for (std::size_t c = 0; c < now.keys.size(); ++c) {
    const auto it = saved_index.find(now.keys[c]);
    if (it == saved_index.end()) {
      const auto r = std::find_if(retired.begin(), retired.end(),
                                  [&](const RetiredChannel& x) { return x.key == now.keys[c]; });
      if (r != retired.end()) {
        st->damage[c] = r->damage;
        co.notes.push_back(now.keys[c] + ": retired damage " + std::to_string(r->damage) +
                           " taken back");
        retired.erase(r);
        ++co.returned;
      } else {
        co.notes.push_back(now.keys[c] + ": new channel, starts at zero damage");
        ++co.added;
      }
      continue;
    }
    const std::size_t o = it->second;
    used[o] = true;
    ++co.matched;
    st->damage[c] = old.damage[o];
    st->damage_comp[c] = old.damage_comp[o];
    st->overflow_max[c] = old.overflow_max[o];
    const double over =
        rebin(old.bin_ticks[o].data(), was.bins, was.full_scale[o], old.overflow_max[o], tick_scale,
              st->bin_ticks[c].data(), now.bins, now.full_scale[c]);
    st->overflow_max[c] = std::max(st->overflow_max[c], over);
    rebin(old.bin_rev_q[o].data(), was.bins, was.full_scale[o], old.overflow_max[o], 1.0L,
          st->bin_rev_q[c].data(), now.bins, now.full_scale[c]);
    if (was.bins != now.bins || was.full_scale[o] != now.full_scale[c])
      co.notes.push_back(now.keys[c] + ": histogram re-binned (" + std::to_string(was.bins) +
                         " bins to " + std::to_string(was.full_scale[o]) + " → " +
                         std::to_string(now.bins) + " to " + std::to_string(now.full_scale[c]) +
                         ")");
  }
  for (std::size_t o = 0; o < was.keys.size(); ++o) {
    if (used[o]) continue;
    const double d = old.damage[o] + old.damage_comp[o];
    retired.push_back({was.keys[o], d, static_cast<double>(old.elapsed_ticks) * was.tick_s});
    co.notes.push_back(was.keys[o] + ": not in this configuration; its damage " +
                       std::to_string(d) + " is kept as retired");
    ++co.retired;
  }
  const bool ok = acc.restore(*st);
  if (!ok) co.notes.push_back("internal: the carried state was refused");
  return co;
}

bool restore_rate_histories(const RateHistoryRecord& rec,
                            const std::vector<std::string>& saved_keys,
                            const std::vector<std::string>& keys,
                            std::vector<fat::DamageRateHistory>& histories,
                            std::vector<double>& boundary, std::string* note) {
  if (histories.empty()) return true;
  if (rec.interval_s != histories.front().interval_s()) {
    if (note)
      *note = "rate history of " + std::to_string(rec.interval_s) +
              " s intervals not used (configured " +
              std::to_string(histories.front().interval_s()) + " s): the RUL rates start afresh";
    return false;
  }
  for (std::size_t c = 0; c < keys.size() && c < histories.size(); ++c) {
    const auto it = std::find(saved_keys.begin(), saved_keys.end(), keys[c]);
    if (it == saved_keys.end()) continue;
    const auto o = static_cast<std::size_t>(it - saved_keys.begin());
    if (o >= rec.channels.size()) continue;
    const RateHistoryRecord::Channel& ch = rec.channels[o];
    if (histories[c].restore(ch.increments.data(), ch.increments.size(), ch.total_increment,
                             ch.total_intervals) &&
        c < boundary.size())
      boundary[c] = ch.damage_at_boundary;
  }
  return true;
}

}  // namespace app::persistence
