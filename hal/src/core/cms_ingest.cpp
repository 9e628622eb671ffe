// CAN frames → CMS blocks with sequence tracking and link state: see hal/cms_ingest.hpp.
#include "hal/cms_ingest.hpp"

namespace hal {

Status CmsIngest::ingest(const CanFrame& frame, Timestamp now, CmsBlock& out) {
  if (frame.error) {
    ++error_frames_;
    last_error_ns_ = now.count();
    const CanErrorInfo info = classify_error_frame(frame.id, frame.data);
    if (info.bus_off && !bus_off_.exchange(true)) ++bus_off_events_;
    if (info.restarted && bus_off_.exchange(false)) ++recoveries_;
    return bus_off_ ? Status::kBusOff : Status::kBusError;
  }
  CmsFrame f;
  if (decode_cms_frame(frame, config_.base_id, config_.classic_format, f) !=
          CmsDecodeError::kNone ||
      config_.scale[f.channel] == 0.0f) {
    ++malformed_;
    last_malformed_ns_ = now.count();
    return Status::kProtocolError;
  }
  if (bus_off_.exchange(false)) ++recoveries_;  // a decodable frame: the bus is back
  const auto verdict = trackers_[f.channel].on_sequence(f.sequence);
  using V = SequenceTracker::Verdict;
  if (verdict.verdict == V::kDuplicate) {
    ++duplicates_;
    return Status::kNoData;
  }
  if (verdict.verdict == V::kReordered) {
    ++reordered_;
    return Status::kNoData;
  }
  last_frame_ns_ = now.count();  // new data (repeats do not count: a stuck sender goes stale)
  out.channel = f.channel;
  out.sequence = f.sequence;
  out.count = f.count;
  out.received = now;
  out.stamp = f.t0_us ? unwrappers_[f.channel].unwrap(*f.t0_us) : now;
  const float scale = config_.scale[f.channel];
  for (std::size_t i = 0; i < f.count; ++i) out.samples[i] = static_cast<float>(f.raw[i]) * scale;
  for (std::size_t i = f.count; i < out.samples.size(); ++i) out.samples[i] = 0.0f;
  if (verdict.verdict == V::kGap) {
    ++gaps_;
    lost_ += verdict.lost;
    last_gap_ns_ = now.count();
    return Status::kGap;
  }
  return Status::kOk;
}

CmsStreamStats CmsIngest::stats() const {
  CmsStreamStats s;
  s.blocks = blocks_;
  s.gaps = gaps_;
  s.lost_blocks = lost_;
  s.duplicates = duplicates_;
  s.reordered = reordered_;
  s.malformed = malformed_;
  s.error_frames = error_frames_;
  s.bus_off = bus_off_events_;
  s.recoveries = recoveries_;
  s.overflows = overflows_;
  return s;
}

Status CmsIngest::health(Timestamp now) const {
  if (bus_off_) return Status::kBusOff;
  if (link_down_) return Status::kDisconnected;
  if (now - Timestamp{last_error_ns_.load()} < config_.error_hold) return Status::kBusError;
  if (now - Timestamp{last_malformed_ns_.load()} < config_.error_hold)
    return Status::kProtocolError;
  if (now - Timestamp{last_gap_ns_.load()} < config_.error_hold) return Status::kGap;
  if (now - Timestamp{last_frame_ns_.load()} > config_.stale_after) return Status::kStale;
  return Status::kOk;
}

}  // namespace hal
