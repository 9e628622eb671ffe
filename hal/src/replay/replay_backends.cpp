// Replay backends: see hal/replay_backends.hpp.
#include "hal/replay_backends.hpp"

#include <algorithm>
#include <cmath>

namespace hal {
namespace {

Timestamp seconds(double s) {
  return std::chrono::duration_cast<Timestamp>(std::chrono::duration<double>(s));
}

}  // namespace

Timestamp ReplayClock::now() const {
  if (speed_ <= 0.0) return stepped_;
  const double wall_s = std::chrono::duration<double>(wall_.now() - wall_start_).count();
  return seconds(wall_s * speed_);
}

// ---- SCADA -------------------------------------------------------------------------------

ReplayScadaSource::ReplayScadaSource(const std::vector<BundleScadaRow>& rows,
                                     const ReplayScadaConfig& config)
    : config_(config), bundle_rows_(rows) {}

ReplayScadaSource::ReplayScadaSource(std::string csv_path, const ScadaColumns& columns,
                                     const ReplayScadaConfig& config)
    : config_(config), csv_path_(std::move(csv_path)), columns_(columns), from_csv_(true) {}

Status ReplayScadaSource::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  rows_.clear();
  if (from_csv_) {
    ScadaCsvReader reader;
    if (!reader.open(csv_path_, columns_)) {
      error_ = reader.error();
      return Status::kInvalidConfig;
    }
    ScadaRow r;
    std::optional<double> t0;
    while (true) {
      const ScadaReadResult res = reader.next(r);
      if (res == ScadaReadResult::kEnd) break;
      if (res == ScadaReadResult::kError) {
        error_ = reader.error();
        return Status::kInvalidConfig;
      }
      if (!r.has_time() || !r.has(ScadaQuantity::kWindSpeed)) {
        ++skipped_;
        continue;
      }
      if (!t0) t0 = r.time_s();
      Row row;
      row.t = seconds(r.time_s() - *t0);
      if (!rows_.empty() && row.t <= rows_.back().t) {
        error_ = csv_path_ + ": row " + std::to_string(r.row) + " (line " + std::to_string(r.line) +
                 "): time does not increase; expected rows in time order";
        return Status::kInvalidConfig;
      }
      // The CSV reader and the SCADA source share hal::ScadaQuantity: every quantity the
      // file has is replayed.
      for (std::size_t q = 0; q < kScadaQuantityCount; ++q) {
        row.present[q] = r.present[q];
        row.v[q] = r.present[q] ? r.value[q] : 0.0;
      }
      rows_.push_back(row);
    }
  } else {
    for (const BundleScadaRow& b : bundle_rows_) {
      Row row;
      row.t = seconds(b.t_s);
      auto put = [&](ScadaQuantity q, const std::optional<double>& v) {
        row.present[static_cast<std::size_t>(q)] = v.has_value();
        row.v[static_cast<std::size_t>(q)] = v.value_or(0.0);
      };
      put(ScadaQuantity::kWindSpeed, b.wind_speed_mps);
      put(ScadaQuantity::kRotorSpeed, b.rotor_speed_rpm);
      put(ScadaQuantity::kPower, b.power_kw);
      put(ScadaQuantity::kPitch, b.pitch_deg);
      put(ScadaQuantity::kRotorTorque, b.torque_nm);
      rows_.push_back(row);
    }
    // Bundle rows count from the start of the recording: keep their times.
  }
  if (rows_.empty()) {
    error_ = (from_csv_ ? csv_path_ : std::string("scada.csv")) +
             ": no usable rows; expected at least one with time and wind speed";
    return Status::kInvalidConfig;
  }
  if (config_.stale_after.count() > 0) {
    stale_after_ = config_.stale_after;
  } else if (rows_.size() >= 2) {
    std::vector<Timestamp> d;
    for (std::size_t i = 1; i < rows_.size(); ++i) d.push_back(rows_[i].t - rows_[i - 1].t);
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    stale_after_ = 2 * d[d.size() / 2];
  } else {
    stale_after_ = std::chrono::seconds(1);
  }
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayScadaSource::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  cursor_ = 0;
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status ReplayScadaSource::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayScadaSource::read(Timestamp now, ScadaData& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  // Time moved backwards (a replay restarted): find the place again.
  if (cursor_ > 0 && rows_[cursor_ - 1].t > now) {
    cursor_ = static_cast<std::size_t>(
        std::upper_bound(rows_.begin(), rows_.end(), now,
                         [](Timestamp t, const Row& r) { return t < r.t; }) -
        rows_.begin());
  }
  while (cursor_ < rows_.size() && rows_[cursor_].t <= now) ++cursor_;
  if (cursor_ == 0) return Status::kNoData;
  const Row& r = rows_[cursor_ - 1];
  out = ScadaData{};
  for (std::size_t q = 0; q < kScadaQuantityCount; ++q) {
    out.values[q].value = r.v[q];
    out.values[q].valid = r.present[q];
    out.values[q].stamp = r.t;
  }
  out.last_update = r.t;
  out.update_count = static_cast<std::uint32_t>(cursor_);
  if (now - r.t > stale_after_)
    return cursor_ == rows_.size() ? Status::kEndOfData : Status::kStale;
  return Status::kOk;
}

// ---- CMS stream ------------------------------------------------------------------------------

ReplayCmsStream::ReplayCmsStream(const Recording& rec, const Clock& clock,
                                 const ReplayCmsConfig& config)
    : rec_(&rec), clock_(clock), config_(config) {}

Status ReplayCmsStream::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (config_.samples_per_block < 1 || config_.samples_per_block > kCmsMaxSamplesPerBlock ||
      rec_->samples.empty() || !(rec_->sample_rate_hz > 0.0))
    return Status::kInvalidConfig;
  channel_count_ = 0;
  for (std::size_t c = 0; c < rec_->channels.size() && channel_count_ < kCmsMaxChannels; ++c) {
    if (!config_.include_tacho && rec_->channels[c].kind == "once_per_rev") continue;
    map_[channel_count_++] = c;
  }
  if (channel_count_ == 0) return Status::kInvalidConfig;
  samples_.assign(channel_count_, {});
  for (std::size_t k = 0; k < channel_count_; ++k) {
    const auto& src = rec_->samples[map_[k]];
    samples_[k].assign(src.size(), 0.0f);
    std::transform(src.begin(), src.end(), samples_[k].begin(),
                   [](double v) { return static_cast<float>(v); });
  }
  fs_ = rec_->sample_rate_hz;
  blocks_per_channel_ =
      samples_[0].size() / config_.samples_per_block;  // a partial last block is not sent
  rec_ = nullptr;                                      // everything needed is copied
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayCmsStream::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  start_ = clock_.now();
  next_block_ = 0;
  next_channel_ = 0;
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status ReplayCmsStream::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayCmsStream::read(CmsBlock& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  if (next_block_ >= blocks_per_channel_) return Status::kEndOfData;
  const std::size_t n = config_.samples_per_block;
  const std::size_t first = next_block_ * n;
  // A block is due when its last sample has been "measured": t(first + n − 1) ≤ now.
  const Timestamp due = start_ + seconds(static_cast<double>(first + n - 1) / fs_);
  if (clock_.now() < due) return Status::kNoData;
  out.channel = next_channel_;
  out.sequence = static_cast<std::uint16_t>(next_block_);
  out.count = static_cast<std::uint8_t>(n);
  out.stamp = start_ + seconds(static_cast<double>(first) / fs_);
  out.received = clock_.now();
  std::copy_n(samples_[next_channel_].begin() + static_cast<std::ptrdiff_t>(first), n,
              out.samples.begin());
  std::fill(out.samples.begin() + static_cast<std::ptrdiff_t>(n), out.samples.end(), 0.0f);
  ++stats_.blocks;
  if (++next_channel_ == channel_count_) {
    next_channel_ = 0;
    ++next_block_;
  }
  return Status::kOk;
}

Status ReplayCmsStream::health(Timestamp) const {
  if (lifecycle_ == LifecycleState::kActive && next_block_ >= blocks_per_channel_)
    return Status::kEndOfData;
  return Status::kOk;
}

// ---- keyphasor
// -----------------------------------------------------------------------------------

std::vector<double> tacho_edges_s(const std::vector<double>& x, double fs) {
  std::vector<double> edges;
  if (x.size() < 2 || !(fs > 0.0)) return edges;
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  const double range = *hi - *lo;
  if (!(range > 0.0)) return edges;
  const double threshold = *lo + 0.5 * range;
  const double rearm = *lo + 0.25 * range;
  bool armed = x[0] < threshold;
  for (std::size_t i = 1; i < x.size(); ++i) {
    if (!armed) {
      if (x[i] < rearm) armed = true;
      continue;
    }
    if (x[i - 1] < threshold && x[i] >= threshold) {
      const double frac = (threshold - x[i - 1]) / (x[i] - x[i - 1]);
      edges.push_back((static_cast<double>(i - 1) + frac) / fs);
      armed = false;
    }
  }
  return edges;
}

ReplayKeyphasor::ReplayKeyphasor(const Recording& rec, const Clock& clock, std::string channel)
    : rec_(&rec), clock_(clock), channel_(std::move(channel)) {}

Status ReplayKeyphasor::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  std::optional<std::size_t> idx;
  for (std::size_t c = 0; c < rec_->channels.size(); ++c) {
    const auto& ch = rec_->channels[c];
    if (channel_.empty() ? ch.kind == "once_per_rev" : ch.name == channel_) {
      idx = c;
      break;
    }
  }
  if (!idx || *idx >= rec_->samples.size()) return Status::kInvalidConfig;
  for (double t : tacho_edges_s(rec_->samples[*idx], rec_->sample_rate_hz))
    edges_.push_back(seconds(t));
  rec_ = nullptr;
  if (edges_.empty()) return Status::kInvalidConfig;
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayKeyphasor::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  start_ = clock_.now();
  next_ = 0;
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status ReplayKeyphasor::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status ReplayKeyphasor::read(KeyphasorEdge& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  if (next_ >= edges_.size()) return Status::kEndOfData;
  const Timestamp t = start_ + edges_[next_];
  if (t > clock_.now()) return Status::kNoData;
  out.stamp = t;
  out.rising = true;
  out.sequence = static_cast<std::uint32_t>(next_++);
  return Status::kOk;
}

}  // namespace hal
