#pragma once
// Replay backends: play a recording bundle (recording-bundle.md) or a SCADA CSV
// export through the same interfaces as the live buses, with the recording
// supplying the clock — stepped by the loop (as fast as it runs) or paced
// against the wall clock at real time or a multiple of it.
//
// Everything is loaded and allocated at configure(); read() walks arrays with a
// cursor (no allocation, no I/O, bounded work), so a replay exercises the RT
// path exactly as the nacelle box would.
//
// Thread context: read()/health()/stats() from the RT thread; construction and
// configure() from the control thread.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hal/clock.hpp"
#include "hal/cms_stream.hpp"
#include "hal/keyphasor.hpp"
#include "hal/recording_bundle.hpp"
#include "hal/scada_csv.hpp"
#include "hal/scada_source.hpp"

namespace hal {

/// Recording time. speed 0: stepped — advance() moves it (the loop adds its period
/// each cycle, as fast as it can); speed s > 0: paced — recording time =
/// s × wall time elapsed since start() (1 = real time), read from CLOCK_MONOTONIC.
class ReplayClock final : public Clock {
 public:
  explicit ReplayClock(double speed = 0.0) : speed_(speed) {}
  void start() { wall_start_ = wall_.now(); }
  void advance(Timestamp dt) { stepped_ += dt; }
  Timestamp now() const override;
  double speed() const { return speed_; }

 private:
  double speed_;
  MonotonicClock wall_;
  Timestamp wall_start_{0};
  Timestamp stepped_{0};
};

// ---- SCADA ---------------------------------------------------------------------------

struct ReplayScadaConfig {
  /// Data older than this is stale; 0 = automatic: twice the median row spacing.
  std::chrono::milliseconds stale_after{0};
};

class ReplayScadaSource final : public ScadaSource {
 public:
  /// From a bundle's scada.csv rows (times: t_s since the start of the recording).
  ReplayScadaSource(const std::vector<BundleScadaRow>& rows, const ReplayScadaConfig& config = {});
  /// From a SCADA CSV file read with the given column mapping (bundle or e.g.
  /// kelmarsh); replay time 0 is the first row's time. Rows without a time or
  /// wind speed are skipped (counted in skipped_rows()).
  ReplayScadaSource(std::string csv_path, const ScadaColumns& columns,
                    const ReplayScadaConfig& config = {});

  /// Loads the rows (file I/O for the CSV form). kInvalidConfig with error() set
  /// when the file cannot be read or holds no usable row.
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  /// @return kNoData before the first row, kOk, kStale (older than stale_after),
  ///         kEndOfData after the last row has gone stale.
  Status read(Timestamp now, ScadaData& out) override;

  const std::string& error() const { return error_; }
  std::size_t rows() const { return rows_.size(); }
  std::size_t skipped_rows() const { return skipped_; }
  Timestamp duration() const { return rows_.empty() ? Timestamp{0} : rows_.back().t; }

 private:
  struct Row {
    Timestamp t{0};
    std::array<double, kScadaQuantityCount> v{};
    std::array<bool, kScadaQuantityCount> present{};
  };
  ReplayScadaConfig config_;
  std::vector<BundleScadaRow> bundle_rows_;
  std::string csv_path_;
  ScadaColumns columns_;
  bool from_csv_ = false;
  std::vector<Row> rows_;
  std::size_t cursor_ = 0;  // rows_[0..cursor_) are at or before the last `now`
  std::size_t skipped_ = 0;
  Timestamp stale_after_{0};
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::string error_;
};

// ---- CMS stream ------------------------------------------------------------------------

struct ReplayCmsConfig {
  std::uint8_t samples_per_block = static_cast<std::uint8_t>(kCmsMaxSamplesPerBlock);
  bool include_tacho = false;  // channels of kind once_per_rev are left out unless true
};

class ReplayCmsStream final : public CmsStream {
 public:
  /// Copies the channels' samples at configure(); `rec` need not outlive it after that.
  ReplayCmsStream(const Recording& rec, const Clock& clock, const ReplayCmsConfig& config = {});
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  /// The next block (channels interleaved) complete by clock.now();
  /// kNoData if none is due yet; kEndOfData once all were delivered.
  Status read(CmsBlock& out) override;
  CmsStreamStats stats() const override { return stats_; }
  Status health(Timestamp now) const override;
  /// Recording channel index of stream channel c.
  std::size_t source_channel(std::uint8_t c) const { return map_[c]; }
  std::size_t channels() const { return channel_count_; }

 private:
  const Recording* rec_;
  const Clock& clock_;
  ReplayCmsConfig config_;
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::vector<std::vector<float>> samples_;  // [stream channel][i]
  std::array<std::size_t, kCmsMaxChannels> map_{};
  std::size_t channel_count_ = 0;
  double fs_ = 0.0;
  std::size_t next_block_ = 0;  // block index (per channel)
  std::uint8_t next_channel_ = 0;
  std::size_t blocks_per_channel_ = 0;
  CmsStreamStats stats_{};
  Timestamp start_{0};
};

// ---- keyphasor ----------------------------------------------------------------------------

/// Rising edges of a once-per-rev channel: threshold halfway between the
/// channel's minimum and maximum, re-armed when the signal falls below a
/// quarter of the range; edge times interpolated linearly between samples.
/// @return edge times [s since the first sample], empty if the channel is flat.
std::vector<double> tacho_edges_s(const std::vector<double>& x, double sample_rate_hz);

class ReplayKeyphasor final : public Keyphasor {
 public:
  /// @param channel  name of the tacho channel; "" = the first of kind once_per_rev
  ReplayKeyphasor(const Recording& rec, const Clock& clock, std::string channel = "");
  /// kInvalidConfig when the recording has no such channel or it has no edges.
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  /// The next edge at or before clock.now(); kNoData / kEndOfData.
  Status read(KeyphasorEdge& out) override;
  std::size_t edges() const { return edges_.size(); }

 private:
  const Recording* rec_;
  const Clock& clock_;
  std::string channel_;
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::vector<Timestamp> edges_;
  std::size_t next_ = 0;
  Timestamp start_{0};
};

}  // namespace hal
