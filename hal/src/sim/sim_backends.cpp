// Simulation backends with fault injection: see hal/sim_backends.hpp.
#include "hal/sim_backends.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

namespace hal {

const char* to_string(SimFault f) {
  switch (f) {
    case SimFault::kNone:
      return "none";
    case SimFault::kSilent:
      return "silent";
    case SimFault::kStuck:
      return "stuck";
    case SimFault::kNoisy:
      return "noisy";
    case SimFault::kGarbage:
      return "garbage";
    case SimFault::kGaps:
      return "gaps";
    case SimFault::kBusOff:
      return "bus_off";
    case SimFault::kNonFinite:
      return "non_finite";
    case SimFault::kOutOfRange:
      return "out_of_range";
  }
  return "?";
}

bool parse_sim_fault(const char* s, SimFault& out) {
  for (auto f :
       {SimFault::kNone, SimFault::kSilent, SimFault::kStuck, SimFault::kNoisy, SimFault::kGarbage,
        SimFault::kGaps, SimFault::kBusOff, SimFault::kNonFinite, SimFault::kOutOfRange}) {
    if (std::strcmp(s, to_string(f)) == 0) {
      out = f;
      return true;
    }
  }
  return false;
}

// ---- SCADA -------------------------------------------------------------------------

SimScadaConfig sim_scada_paper_point() {
  SimScadaConfig c;
  auto set = [&](ScadaQuantity q, double v) {
    c.base[static_cast<std::size_t>(q)] = v;
    c.present[static_cast<std::size_t>(q)] = true;
  };
  set(ScadaQuantity::kWindSpeed, 6.75);
  set(ScadaQuantity::kRotorSpeed, 8.33);
  set(ScadaQuantity::kGeneratorSpeed, 8.33 * 103.0246);
  set(ScadaQuantity::kRotorTorque, 361747.0);
  // Aerodynamic power P = T·ω = 361 747 N·m × 8.33·2π/60 rad/s = 315.6 kW.
  set(ScadaQuantity::kPower, 361747.0 * 8.33 * 2.0 * std::numbers::pi / 60.0 / 1000.0);
  set(ScadaQuantity::kPitch, 0.0);
  return c;
}

SimScadaSource::SimScadaSource(const SimScadaConfig& config, const Clock& clock)
    : config_(config), clock_(clock), rng_(config.seed) {}

Status SimScadaSource::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (config_.period <= std::chrono::milliseconds(0) ||
      config_.stale_after <= std::chrono::milliseconds(0))
    return Status::kInvalidConfig;
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status SimScadaSource::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  next_update_ = clock_.now();
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status SimScadaSource::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status SimScadaSource::read(Timestamp now, ScadaData& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  const SimFault fault = fault_.load();
  if (next_update_ <= now) {
    // Only the newest due update matters to a "latest value" source: skip the rest.
    const auto behind = (now - next_update_) / config_.period;
    next_update_ += config_.period * behind;
    updates_ += static_cast<std::uint64_t>(behind);
    const Timestamp t = next_update_;
    next_update_ += config_.period;
    const std::uint64_t k = updates_++;
    const bool lost = fault == SimFault::kGaps && k % 4 == 3;
    if (fault == SimFault::kSilent || fault == SimFault::kStuck) {
      // nothing new: silent = no answer, stuck = registers frozen
      if (fault == SimFault::kSilent) ++data_.error_count;
    } else if (lost) {
      ++data_.error_count;
    } else if (fault == SimFault::kGarbage) {
      ++data_.error_count;
      for (auto& m : data_.values) m.valid = false;
      garbage_last_ = true;
    } else {
      const double var = fault == SimFault::kNoisy ? config_.noisy_variation : config_.variation;
      for (std::size_t q = 0; q < kScadaQuantityCount; ++q) {
        Measurement& m = data_.values[q];
        m.valid = config_.present[q];
        m.value = config_.present[q] ? config_.base[q] * (1.0 + var * rng_.uniform()) : 0.0;
        if (fault == SimFault::kNonFinite) m.value = std::numeric_limits<double>::quiet_NaN();
        if (fault == SimFault::kOutOfRange) m.value *= 1000.0;
        m.stamp = t;
      }
      data_.last_update = t;
      ++data_.update_count;
      garbage_last_ = false;
    }
  }
  out = data_;
  if (garbage_last_) return Status::kProtocolError;
  if (data_.update_count == 0) return Status::kNoData;
  if (now - data_.last_update > config_.stale_after) return Status::kStale;
  return Status::kOk;
}

// ---- CMS stream ----------------------------------------------------------------------

namespace {
CmsIngestConfig ingest_config(const SimCmsConfig& c) {
  CmsIngestConfig i;
  i.base_id = c.base_id;
  i.classic_format = c.format;
  i.scale.fill(0.0f);
  for (std::size_t ch = 0; ch < c.channels && ch < kCmsMaxChannels; ++ch) i.scale[ch] = c.scale;
  i.stale_after = c.stale_after;
  i.error_hold = c.error_hold;
  return i;
}
}  // namespace

SimCmsStream::SimCmsStream(const SimCmsConfig& config, const Clock& clock)
    : config_(config), clock_(clock), ingest_(ingest_config(config)), rng_(config.seed) {}

Status SimCmsStream::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (config_.channels < 1 || config_.channels > kCmsMaxChannels ||
      !(config_.sample_rate_hz > 0.0) || config_.samples_per_frame < 1 ||
      config_.samples_per_frame > max_fd_samples(config_.format) || !(config_.scale > 0.0f) ||
      config_.base_id + kCmsMaxChannels - 1 > 0x7FF || config_.max_frames_per_read < 1)
    return Status::kInvalidConfig;
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status SimCmsStream::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  start_ = clock_.now();
  ingest_.start(start_);
  frame_index_ = 0;
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status SimCmsStream::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  size_ = 0;
  return Status::kOk;
}

void SimCmsStream::generate(Timestamp now) {
  const double frame_s = static_cast<double>(config_.samples_per_frame) / config_.sample_rate_hz;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  if (elapsed_s < 0.0) return;
  const auto due = static_cast<std::uint64_t>(elapsed_s / frame_s) + 1;  // frames with t0 <= now
  // Far behind (the reader stalled): the front end kept sending, this reader
  // lost those frames. Skip ahead with the sequence numbers advancing, so the
  // decoder reports the loss as a gap.
  const std::uint64_t bound = 4 * config_.max_frames_per_read;
  if (due > frame_index_ + bound) {
    const std::uint64_t skip = due - frame_index_ - bound;
    for (std::size_t ch = 0; ch < config_.channels; ++ch)
      sequence_[ch] = static_cast<std::uint16_t>(sequence_[ch] + skip);
    frame_index_ += skip;
  }
  const SimFault fault = fault_.load();
  if (fault != SimFault::kBusOff && bus_off_sent_) {
    CanFrame restarted;
    restarted.error = true;
    restarted.id = kCanErrRestarted;
    CmsBlock unused;
    (void)ingest_.ingest(restarted, now, unused);
    bus_off_sent_ = false;
  }
  std::size_t produced = 0;
  const double ts = 1.0 / config_.sample_rate_hz;
  const double noise = fault == SimFault::kNoisy ? config_.noisy_noise : config_.noise;
  const std::int32_t lim = config_.format == CmsSampleFormat::kInt16 ? 32767 : 8388607;
  while (frame_index_ < due && produced < config_.max_frames_per_read) {
    const std::uint64_t k = frame_index_++;
    ++produced;
    const double t0 = static_cast<double>(k) * frame_s;
    for (std::uint8_t ch = 0; ch < config_.channels; ++ch) {
      CmsFrame f;
      f.channel = ch;
      f.format = config_.format;
      f.count = config_.samples_per_frame;
      f.sequence = fault == SimFault::kStuck ? static_cast<std::uint16_t>(sequence_[ch] - 1)
                                             : sequence_[ch]++;
      f.t0_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(t0 * 1e6)) &
                                           0xFFFFFFFFu);
      for (std::size_t i = 0; i < f.count; ++i) {
        const double t = t0 + static_cast<double>(i) * ts;
        const double phase = static_cast<double>(ch) * 0.5;
        const double x =
            config_.amplitude * std::sin(2.0 * std::numbers::pi * config_.tone_hz * t + phase) +
            noise * rng_.uniform();
        f.raw[i] = static_cast<std::int32_t>(
            std::clamp<long>(std::lround(x / static_cast<double>(config_.scale)), -lim - 1, lim));
      }
      if (fault == SimFault::kSilent) continue;
      if (fault == SimFault::kGaps && k % 4 == 3) continue;
      CanFrame frame;
      if (fault == SimFault::kBusOff) {
        if (!bus_off_sent_) {
          frame.error = true;
          frame.id = kCanErrBusOff;
          bus_off_sent_ = true;
        } else {
          continue;  // the controller is off the bus: nothing arrives
        }
      } else if (!encode_cms_fd_frame(f, config_.base_id, frame)) {
        continue;
      }
      if (fault == SimFault::kGarbage) {
        constexpr std::uint8_t kLens[] = {8, 12, 16, 20, 24, 32, 48, 64};
        frame.len = kLens[rng_.next() % 8];
        for (std::size_t i = 0; i < frame.len; ++i)
          frame.data[i] = static_cast<std::uint8_t>(rng_.next());
      }
      CmsBlock b;
      const Status s = ingest_.ingest(frame, now, b);
      if (s != Status::kOk && s != Status::kGap) continue;
      if (size_ == ring_.size()) {
        ingest_.count_overflow();
        continue;
      }
      ring_[(head_ + size_) % ring_.size()] = b;
      ++size_;
      ingest_.count_delivered();
    }
  }
}

Status SimCmsStream::read(CmsBlock& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  generate(clock_.now());
  if (size_ > 0) {
    out = ring_[head_];
    head_ = (head_ + 1) % ring_.size();
    --size_;
    return Status::kOk;
  }
  if (ingest_.bus_off()) return Status::kBusOff;
  return Status::kNoData;
}

// ---- keyphasor ---------------------------------------------------------------------------

SimKeyphasor::SimKeyphasor(const SimKeyphasorConfig& config, const Clock& clock)
    : config_(config), clock_(clock), rng_(config.seed) {}

Status SimKeyphasor::configure() {
  if (lifecycle_ != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (!(config_.speed_hz > 0.0)) return Status::kInvalidConfig;
  lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status SimKeyphasor::activate() {
  if (lifecycle_ == LifecycleState::kUnconfigured) return Status::kWrongState;
  start_ = clock_.now();
  index_ = 0;
  lifecycle_ = LifecycleState::kActive;
  return Status::kOk;
}

Status SimKeyphasor::deactivate() {
  if (lifecycle_ == LifecycleState::kActive) lifecycle_ = LifecycleState::kInactive;
  return Status::kOk;
}

Status SimKeyphasor::read(KeyphasorEdge& out) {
  if (lifecycle_ != LifecycleState::kActive) return Status::kWrongState;
  const Timestamp now = clock_.now();
  const double period_s = 1.0 / config_.speed_hz;
  constexpr std::uint64_t kMaxBehind = 64;  // edges older than this many periods are dropped
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const auto due = static_cast<std::uint64_t>(std::max(0.0, elapsed_s / period_s)) + 1;
  if (due > index_ + kMaxBehind) {
    sequence_ +=
        static_cast<std::uint32_t>(due - index_ - kMaxBehind);  // lost, visible to the tracker
    index_ = due - kMaxBehind;
  }
  while (index_ < due) {
    const std::uint64_t k = index_++;
    const SimFault fault = fault_.load();
    if (fault == SimFault::kSilent || fault == SimFault::kStuck) continue;  // no pulses at all
    if (fault == SimFault::kGaps && k % 4 == 3) {
      ++sequence_;  // edge lost between sensor and box
      continue;
    }
    double t_s = static_cast<double>(k) * period_s;
    if (fault == SimFault::kNoisy) t_s += config_.noisy_jitter * period_s * rng_.uniform();
    out.stamp = start_ + std::chrono::duration_cast<Timestamp>(std::chrono::duration<double>(t_s));
    out.rising = true;
    out.sequence = sequence_++;
    return Status::kOk;
  }
  return Status::kNoData;
}

}  // namespace hal
