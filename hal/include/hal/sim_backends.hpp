#pragma once
// Simulation backends with fault injection: a synthetic turbine bus for the
// loop's integration tests, `drivetwin bus probe --sim`, and demos without
// hardware. They run on the caller's thread, driven by the Clock they are
// given (a ManualClock makes them deterministic): every read() produces what
// would have arrived up to clock.now(), bounded per call, and never blocks.
//
// Faults (inject() at any time, from any thread; kNone recovers without restart):
//   kSilent   nothing arrives                       → kNoData / kStale, health kStale
//   kStuck    the source freezes: SCADA snapshot and its time stamp stop
//             changing (→ kStale); CMS frames repeat the same sequence number
//             (→ duplicates dropped, health kStale); keyphasor edges stop
//   kNoisy    heavy noise on values / samples / edge times (data stays "valid":
//             plausibility is the supervisor's job)
//   kGarbage  CMS frames with random bytes (→ malformed, health kProtocolError);
//             SCADA registers that do not decode (→ values invalid, kProtocolError)
//   kGaps     every 4th CMS frame / SCADA update / keyphasor edge is lost (→ gaps counted, kGap)
//   kBusOff   CMS: error frames announcing bus-off (→ kBusOff) until the fault is cleared,
//             then a "restarted" error frame
//   kNonFinite SCADA: every value NaN, flagged valid (a controller's float register with no
//             value behind it): the supervisor must reject it
//   kOutOfRange SCADA: every value ×1000, flagged valid (a scaling or unit error)
//
// Thread context: read()/health()/stats() from the RT thread; inject() from any thread.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>

#include "hal/clock.hpp"
#include "hal/cms_ingest.hpp"
#include "hal/cms_stream.hpp"
#include "hal/keyphasor.hpp"
#include "hal/scada_source.hpp"

namespace hal {

enum class SimFault : std::uint8_t {
  kNone,
  kSilent,
  kStuck,
  kNoisy,
  kGarbage,
  kGaps,
  kBusOff,
  kNonFinite,
  kOutOfRange
};
const char* to_string(SimFault f);
bool parse_sim_fault(const char* s, SimFault& out);

/// Small deterministic PRNG (xorshift64*), so simulations replay bit for bit.
class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed) : s_(seed ? seed : 0x9E3779B97F4A7C15ull) {}
  std::uint64_t next() {
    s_ ^= s_ >> 12;
    s_ ^= s_ << 25;
    s_ ^= s_ >> 27;
    return s_ * 0x2545F4914F6CDD1Dull;
  }
  /// Uniform in [-1, 1).
  double uniform() { return static_cast<double>(next() >> 11) * (2.0 / 9007199254740992.0) - 1.0; }

 private:
  std::uint64_t s_;
};

// ---- SCADA -------------------------------------------------------------------

struct SimScadaConfig {
  std::chrono::milliseconds period{1000};  // controller update period
  std::chrono::milliseconds stale_after{3000};
  std::array<double, kScadaQuantityCount>
      base{};  // mean value per quantity (unit of kScadaQuantities)
  std::array<bool, kScadaQuantityCount> present{};
  double variation = 0.02;       // [-] relative random variation per update
  double noisy_variation = 0.5;  // [-] with kNoisy
  std::uint64_t seed = 1;
};
/// Operating data of the paper's check point (drivetrain-2mw.md): wind 6.75 m/s,
/// rotor 8.33 rpm (hss 858 rpm at ratio 103.0246), torque 361 747 N·m.
SimScadaConfig sim_scada_paper_point();

class SimScadaSource final : public ScadaSource {
 public:
  SimScadaSource(const SimScadaConfig& config, const Clock& clock);
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  Status read(Timestamp now, ScadaData& out) override;
  void inject(SimFault f) { fault_ = f; }

 private:
  SimScadaConfig config_;
  const Clock& clock_;
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::atomic<SimFault> fault_{SimFault::kNone};
  SimRandom rng_;
  ScadaData data_{};
  Timestamp next_update_{0};
  std::uint64_t updates_ = 0;
  bool garbage_last_ = false;
};

// ---- CMS stream ----------------------------------------------------------------

struct SimCmsConfig {
  double sample_rate_hz = 25600.0;  // [Hz] per channel
  std::uint8_t channels = 2;
  CmsSampleFormat format = CmsSampleFormat::kInt16;
  std::uint8_t samples_per_frame = 28;
  float scale = 0.001f;       // [m/s² per LSB]
  double tone_hz = 371.884;   // [Hz] a sine at the paper point's high-speed mesh
  double amplitude = 2.0;     // [m/s²]
  double noise = 0.05;        // [m/s²] rms-ish uniform noise
  double noisy_noise = 10.0;  // [m/s²] with kNoisy
  std::uint32_t base_id = 0x180;
  std::chrono::milliseconds stale_after{500};
  std::chrono::milliseconds error_hold{500};
  std::size_t max_frames_per_read = 64;  // bound on work per read() call
  std::uint64_t seed = 2;
};

/// Blocks buffered between generation and read(); full → dropped, counted.
inline constexpr std::size_t kSimCmsQueueBlocks = 256;

class SimCmsStream final : public CmsStream {
 public:
  SimCmsStream(const SimCmsConfig& config, const Clock& clock);
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  /// Generates the frames due up to clock.now() (at most max_frames_per_read),
  /// passes them through the CAN decoder, and pops the oldest block.
  Status read(CmsBlock& out) override;
  CmsStreamStats stats() const override { return ingest_.stats(); }
  Status health(Timestamp now) const override { return ingest_.health(now); }
  void inject(SimFault f) { fault_ = f; }

 private:
  void generate(Timestamp now);
  SimCmsConfig config_;
  const Clock& clock_;
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::atomic<SimFault> fault_{SimFault::kNone};
  CmsIngest ingest_;
  SimRandom rng_;
  std::array<CmsBlock, kSimCmsQueueBlocks> ring_{};
  std::size_t head_ = 0, size_ = 0;
  std::uint64_t frame_index_ = 0;  // frames generated per channel so far
  std::array<std::uint16_t, kCmsMaxChannels> sequence_{};
  Timestamp start_{0};
  bool bus_off_sent_ = false;
};

// ---- keyphasor -------------------------------------------------------------------

struct SimKeyphasorConfig {
  double speed_hz = 14.3032;  // [Hz] hss at the paper point (drivetrain-2mw.md)
  double noisy_jitter = 0.2;  // [-] edge time jitter as a fraction of the period (kNoisy)
  std::uint64_t seed = 3;
};

class SimKeyphasor final : public Keyphasor {
 public:
  SimKeyphasor(const SimKeyphasorConfig& config, const Clock& clock);
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override { return lifecycle_; }
  Status read(KeyphasorEdge& out) override;
  void inject(SimFault f) { fault_ = f; }

 private:
  SimKeyphasorConfig config_;
  const Clock& clock_;
  LifecycleState lifecycle_ = LifecycleState::kUnconfigured;
  std::atomic<SimFault> fault_{SimFault::kNone};
  SimRandom rng_;
  std::uint64_t index_ = 0;  // next edge number
  std::uint32_t sequence_ = 0;
  Timestamp start_{0};
};

}  // namespace hal
