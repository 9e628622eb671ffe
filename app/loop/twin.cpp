// One cycle of the twin: see twin.hpp.
#include "loop/twin.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "fatigue/dynamics_spectrum.hpp"
#include "model/drivetrain/kinematics.hpp"

namespace app::loop {
namespace {

constexpr float kInfHours = std::numeric_limits<float>::infinity();

hal::Timestamp from_seconds(double s) {
  return std::chrono::duration_cast<hal::Timestamp>(std::chrono::duration<double>(s));
}

model::fatigue::AccumulatorConfig accumulator_config(double dt_s, std::uint32_t bins) {
  model::fatigue::AccumulatorConfig c;
  c.tick_s = dt_s;
  c.bins = bins;
  return c;
}

}  // namespace

Twin::Twin(const model::Drivetrain& drivetrain, const model::fatigue::ChannelSet& channels,
           const model::dynamics::RomData& rom, const TwinSettings& settings, Mailboxes& mailboxes,
           const TwinDevices& devices)
    : channels_(channels),
      settings_(settings),
      mail_(mailboxes),
      dev_(devices),
      rom_data_(&rom),
      rom_(rom),
      shadow_(rom),
      converter_(drivetrain, channels, rom),
      shaper_(rom, static_cast<double>(settings.period_ns) * 1e-9, settings.scada_period_s),
      accumulator_(std::make_unique<model::fatigue::DamageAccumulator>(
          channels, accumulator_config(rom.dt_s, settings.accumulator_bins))),
      supervisor_(drivetrain, settings.supervisor),
      register_map_(channels) {
  if (dev_.scada == nullptr) throw std::runtime_error("twin: a SCADA source is required");
  if (!converter_.valid()) throw std::runtime_error("twin: " + converter_.error());
  const double dt_expected =
      static_cast<double>(settings_.period_ns) * 1e-9 / settings_.rom_steps_per_cycle;
  if (std::abs(rom.dt_s - dt_expected) > 1e-12 * dt_expected)
    throw std::runtime_error("twin: the ROM's step does not match period / steps per cycle");
  hss_ratio_ = model::Kinematics(drivetrain).overall_ratio();
  point_of_channel_.fill(-1);
  for (std::size_t p = 0; p < kSnapshotPoints; ++p) {
    const int ch = settings_.point_channel[p];
    if (ch < 0 || ch >= static_cast<int>(hal::kCmsMaxChannels))
      throw std::runtime_error("twin: point channel out of range");
    point_of_channel_[static_cast<std::size_t>(ch)] = static_cast<int>(p);
    zones_[p] = supervisor::VibrationZones(settings_.zones, settings_.cms_sample_rate_hz);
  }
  window_capacity_ =
      static_cast<std::size_t>(std::ceil(settings_.window_s * settings_.cms_sample_rate_hz));
  next_window_ = hal::Timestamp{0};
  next_interval_ = from_seconds(settings_.rul_interval_s);
  next_checkpoint_ = from_seconds(settings_.checkpoint_interval_s);
  rul_.rul_low_h.fill(kNoValue);
  snapshot_.channel_count = static_cast<std::uint32_t>(channels.channel_count());
}

bool Twin::restore(const model::fatigue::AccumulatorState& state) {
  return accumulator_->restore(state);
}

void Twin::emit(hal::Timestamp now, EventCode code, std::int32_t a, double b) {
  if (!mail_.events.push(Event{now.count(), code, a, b})) {
    ++counters_.events_dropped;
    queue_full_since_publish_ = true;
  }
}

void Twin::drain_keyphasor(hal::Timestamp now) {
  if (dev_.keyphasor == nullptr) {
    keyphasor_state_ = {};
    return;
  }
  hal::KeyphasorEdge edge;
  for (std::size_t i = 0; i < kMaxEdgesPerCycle; ++i) {
    const hal::Status s = dev_.keyphasor->read(edge);
    if (s != hal::Status::kOk && s != hal::Status::kOverflow) break;
    keyphasor_.on_edge(edge);
    ++counters_.keyphasor_edges;
    // Edge stamps while a window is open (converted to the window's base when it completes).
    if (window_ != nullptr && window_edges_ < window_->pulses_s.size())
      window_->pulses_s[window_edges_++] = static_cast<double>(edge.stamp.count());
  }
  keyphasor_state_ = keyphasor_.state(now);
}

void Twin::drain_cms(hal::Timestamp now) {
  lost_blocks_cycle_ = 0;
  if (dev_.cms == nullptr) {
    cms_fault_ = false;
    return;
  }
  hal::CmsBlock block;
  bool bus_off = false;
  for (std::size_t i = 0; i < kMaxBlocksPerCycle; ++i) {
    const hal::Status s = dev_.cms->read(block);
    if (s == hal::Status::kBusOff) bus_off = true;
    if (s != hal::Status::kOk) break;
    ++counters_.cms_blocks;
    clock_map_.add(block.stamp.count(), block.received.count());
    const std::size_t ch = block.channel;
    if (ch >= hal::kCmsMaxChannels) continue;
    std::size_t lost = 0;
    if (have_sequence_[ch]) {
      const auto d = static_cast<std::uint16_t>(block.sequence - last_sequence_[ch]);
      if (d > 1 && d < 0x8000) lost = static_cast<std::size_t>(d - 1);
    }
    have_sequence_[ch] = true;
    last_sequence_[ch] = block.sequence;
    samples_per_block_[ch] = block.count;
    lost_blocks_cycle_ += lost;
    const int p = point_of_channel_[ch];
    if (p < 0) continue;
    const auto point = static_cast<std::size_t>(p);
    zones_[point].add(block.samples.data(), block.count, lost * block.count);
    if (lost > 0) abort_window(1);
    window_samples(point, block);
  }
  counters_.cms_gaps += lost_blocks_cycle_ > 0 ? 1 : 0;
  const hal::Status h = dev_.cms->health(now);
  cms_fault_ = bus_off || (h != hal::Status::kOk && h != hal::Status::kNoData);
}

void Twin::window_samples(std::size_t point, const hal::CmsBlock& block) {
  if (window_ == nullptr) return;
  const float* x = block.samples.data();
  const std::size_t n = block.count;
  std::size_t& fill = window_fill_[point];
  if (point == 0 && fill == 0) window_device_start_ns_ = block.stamp.count();
  const std::size_t take = std::min(n, window_capacity_ - fill);
  double* out = window_->samples[point].data() + fill;
  for (std::size_t i = 0; i < take; ++i) out[i] = static_cast<double>(x[i]);
  fill += take;
}

void Twin::abort_window(int reason) {
  if (window_ == nullptr) return;
  // Keep the buffer and start over at once (the next gap-free stretch).
  window_fill_.fill(0);
  window_cycles_ = window_hss_cycles_ = 0;
  window_edges_ = 0;
  window_rpm_sum_ = window_torque_sum_ = window_hss_sum_ = 0.0;
  emit(hal::Timestamp{snapshot_.stamp_ns}, EventCode::kCalibrationSkipped, reason);
}

void Twin::collect_window(hal::Timestamp now, const supervisor::SupervisorDecision& d) {
  if (!settings_.calibration_enabled || dev_.cms == nullptr) return;
  if (window_ == nullptr) {
    if (now < next_window_) return;
    CmsWindow* w = nullptr;
    if (!mail_.windows_free.pop(w)) return;  // the calibration thread still has them all
    window_ = w;
    window_->start_ns = now.count();
    window_fill_.fill(0);
    window_cycles_ = window_hss_cycles_ = 0;
    window_edges_ = 0;
    window_rpm_sum_ = window_torque_sum_ = window_hss_sum_ = 0.0;
    return;  // samples from the next cycle's blocks on
  }
  // The operating point of the window: only measured (not held) inputs count.
  const bool measured =
      d.rom_valid && (d.source == TorqueSource::kMeasuredTorque ||
                      d.source == TorqueSource::kPower || d.source == TorqueSource::kWind);
  if (!measured) {
    abort_window(3);
    return;
  }
  const double rpm = d.rom.rotor_speed_rpm, nm = d.rom.input_torque_nm;
  if (window_cycles_ == 0) {
    window_rpm_min_ = window_rpm_max_ = rpm;
    window_torque_min_ = window_torque_max_ = nm;
  }
  window_rpm_min_ = std::min(window_rpm_min_, rpm);
  window_rpm_max_ = std::max(window_rpm_max_, rpm);
  window_torque_min_ = std::min(window_torque_min_, nm);
  window_torque_max_ = std::max(window_torque_max_, nm);
  window_rpm_sum_ += rpm;
  window_torque_sum_ += nm;
  ++window_cycles_;
  if (keyphasor_state_.valid) {
    window_hss_sum_ += keyphasor_state_.speed_hz;
    ++window_hss_cycles_;
  }
  if (window_fill_[0] < window_capacity_ || window_fill_[1] < window_capacity_) return;
  // Complete: steady enough to stand for one operating point?
  const double n = static_cast<double>(window_cycles_);
  const double rpm_mean = window_rpm_sum_ / n, nm_mean = window_torque_sum_ / n;
  const bool steady =
      rpm_mean > 0.0 && nm_mean > 0.0 &&
      (window_rpm_max_ - window_rpm_min_) <= 2.0 * settings_.steady_speed_tolerance * rpm_mean &&
      (window_torque_max_ - window_torque_min_) <=
          2.0 * settings_.steady_torque_tolerance * nm_mean;
  if (!steady) {
    abort_window(2);
    return;
  }
  window_->count = window_capacity_;
  window_->sample_rate_hz = settings_.cms_sample_rate_hz;
  window_->rotor_speed_rpm = rpm_mean;
  window_->input_torque_nm = nm_mean;
  window_pulses();
  window_->hss_hz = window_hss_cycles_ * 2 > window_cycles_
                        ? window_hss_sum_ / static_cast<double>(window_hss_cycles_)
                        : rpm_mean / 60.0 * hss_ratio_;
  if (mail_.windows_full.push(window_)) {
    window_ = nullptr;
    next_window_ = now + from_seconds(settings_.check_interval_s);
  } else {
    abort_window(4);  // cannot happen with kWindows buffers; counted all the same
  }
}

void Twin::window_pulses() {
  // Edge stamps (host clock) → seconds from the window's first sample, keeping those inside
  // it; none until the clock mapping has two buckets (a live box's first seconds).
  window_->pulse_count = 0;
  if (!clock_map_.valid()) return;
  const std::int64_t start = clock_map_.to_host(window_device_start_ns_);
  const double span_s = static_cast<double>(window_->count) / settings_.cms_sample_rate_hz;
  std::size_t n = 0;
  for (std::size_t i = 0; i < window_edges_; ++i) {
    const double t = (window_->pulses_s[i] - static_cast<double>(start)) * 1e-9;
    if (t >= 0.0 && t <= span_s) window_->pulses_s[n++] = t;
  }
  window_->pulse_count = n;
}

void Twin::adopt_calibrated(const supervisor::SupervisorDecision& d) {
  // Hand back what the return path refused last time.
  if (pending_return_ != nullptr &&
      mail_.rom.give_back(const_cast<model::dynamics::RomData*>(pending_return_)))
    pending_return_ = nullptr;
  if (shadow_data_ == nullptr && pending_return_ == nullptr && rom_started_) {
    if (model::dynamics::RomData* next = mail_.rom.take()) {
      if (next->dt_s != rom_data_->dt_s || next->mesh_count != rom_data_->mesh_count ||
          next->bearing_count != rom_data_->bearing_count) {
        // A model for another step or topology would corrupt the counting: refuse it.
        emit(hal::Timestamp{snapshot_.stamp_ns}, EventCode::kCalibrationFailed, 90);
        if (!mail_.rom.give_back(next)) pending_return_ = next;
      } else {
        shadow_data_ = next;
        shadow_ = model::dynamics::Rom(*next);
        shadow_.reset(d.rom, rom_);  // at the running ROM's exact time and angle
        shadow_settle_s_ = model::dynamics::rom_settle_time_s(*next);
        shadow_steps_left_ = static_cast<std::int64_t>(std::ceil(shadow_settle_s_ / next->dt_s));
      }
    }
  }
  if (shadow_data_ != nullptr && shadow_steps_left_ <= 0) {
    // Settled: the calibrated model takes over; the old one goes back to the builder.
    std::swap(rom_, shadow_);
    const model::dynamics::RomData* old = rom_data_;
    rom_data_ = shadow_data_;
    shadow_data_ = nullptr;
    if (!mail_.rom.give_back(const_cast<model::dynamics::RomData*>(old))) pending_return_ = old;
    ++calibration_generation_;
    ++counters_.rom_adoptions;
    emit(hal::Timestamp{snapshot_.stamp_ns}, EventCode::kRomAdopted, calibration_generation_,
         shadow_settle_s_);
  }
}

namespace {
// The mesh forces are bounded by RomLoadConverter::within; a bearing force is only checked
// for being finite (a NaN there would reach the damage through its channel).
bool bearings_finite(const model::dynamics::RomOutputs& o) noexcept {
  for (std::size_t j = 0; j < o.bearing_force_x_n.size(); ++j)
    if (!std::isfinite(o.bearing_force_x_n[j]) || !std::isfinite(o.bearing_force_y_n[j]))
      return false;
  return true;
}
}  // namespace

void Twin::step_model(hal::Timestamp now, const supervisor::SupervisorDecision& d) {
  if (!d.rom_valid) return;
  // The inputs per step between SCADA samples (signal/rom_input_shaper.hpp): a held value
  // that steps would ring the drivetrain's first mode and be counted as damage.
  const bool new_sample =
      scada_.update_count != last_scada_update_ || d.source != last_decision_.source;
  last_scada_update_ = scada_.update_count;
  if (!rom_started_) {
    rom_.reset(d.rom);
    shaper_.reset(now, d.rom);
    rom_started_ = true;
  } else {
    shaper_.cycle(now, d.rom, new_sample);
  }
  // 10 × the quasi-static mesh forces at this torque (at least a tenth of rated): the bound
  // `drivetwin damage` refuses a diverged simulation at (app/fatigue/dynamics_spectrum.hpp).
  const fatigue::RomLoadConverter::DivergenceLimits limits =
      converter_.divergence_limits(d.rom.input_torque_nm);
  const int steps = settings_.rom_steps_per_cycle;
  for (int i = 0; i < steps; ++i) {
    const model::dynamics::RomInputs u = shaper_.at_step(i, steps);
    rom_.step(u, rom_out_);
    converter_.convert(rom_out_.mesh_force_n.data(), rom_out_.bearing_force_x_n.data(),
                       rom_out_.bearing_force_y_n.data(), u.input_torque_nm, loads_);
    if (!converter_.within(limits, rom_out_.mesh_force_n.data()) || !bearings_finite(rom_out_)) {
      // A diverging ROM (none is known since the fast modes are quasi-static, rom.hpp
      // "Stability"; this guards the lifetime damage against one nonetheless) must not put
      // NaN or absurd loads into the lifetime damage: the cycle's remaining steps are not
      // counted and the ROM restarts from equilibrium next cycle.
      rom_diverged_since_publish_ = true;
      rom_started_ = false;
      counters_.rom_steps += static_cast<std::uint64_t>(i + 1);
      return;
    }
    accumulator_->step(loads_, u.rotor_speed_rpm, 1);
    if (shadow_data_ != nullptr) {
      shadow_.step(u, shadow_out_);  // settling: its loads are not counted
      --shadow_steps_left_;
    }
  }
  counters_.rom_steps += static_cast<std::uint64_t>(steps);
}

void Twin::events_on_change(hal::Timestamp now, const supervisor::SupervisorDecision& d) {
  const supervisor::SupervisorDecision& p = last_decision_;
  if (d.rejected_this_cycle > 0) emit(now, EventCode::kInputRejected, d.rejected_this_cycle);
  if (d.source != p.source) {
    switch (d.source) {
      case TorqueSource::kHeld:
        emit(now, EventCode::kHoldingInputs, 0, d.rom.input_torque_nm);
        break;
      case TorqueSource::kSteadyState:
        emit(now, EventCode::kSteadyState, 0, d.rom.input_torque_nm);
        break;
      case TorqueSource::kNone:
        emit(now, EventCode::kNoInputs);
        break;
      default:
        if (p.source == TorqueSource::kHeld || p.source == TorqueSource::kSteadyState ||
            p.source == TorqueSource::kNone)
          emit(now, EventCode::kInputsRecovered, static_cast<std::int32_t>(d.source));
        break;
    }
  }
  const bool stale = (d.fault_word & supervisor::kFaultScadaStale) != 0;
  const bool was_stale = (p.fault_word & supervisor::kFaultScadaStale) != 0;
  if (stale && !was_stale) emit(now, EventCode::kScadaStale, static_cast<int>(last_scada_status_));
  if (!stale && was_stale) emit(now, EventCode::kScadaRecovered);
  if (lost_blocks_cycle_ > 0) emit(now, EventCode::kCmsGap, static_cast<int>(lost_blocks_cycle_));
  const bool cms = (d.fault_word & supervisor::kFaultCmsBusOff) != 0;
  const bool was_cms = (p.fault_word & supervisor::kFaultCmsBusOff) != 0;
  if (cms && !was_cms && dev_.cms != nullptr)
    emit(now, EventCode::kCmsFault, static_cast<int>(dev_.cms->health(now)));
  if (!cms && was_cms) emit(now, EventCode::kCmsRecovered);
  const bool kp = (d.fault_word & supervisor::kFaultKeyphasor) != 0;
  const bool was_kp = (p.fault_word & supervisor::kFaultKeyphasor) != 0;
  if (dev_.keyphasor != nullptr && kp != was_kp)
    emit(now, kp ? EventCode::kKeyphasorLost : EventCode::kKeyphasorRecovered);
  for (std::size_t i = 0; i < kSnapshotPoints; ++i) {
    const VibrationZone z = zones_[i].zone();
    if (z != zone_[i]) {
      emit(now, EventCode::kZoneChanged, static_cast<int>(i), static_cast<double>(z));
      zone_[i] = z;
    }
  }
  if (d.alarm && !alarm_) {
    int worst = 0;
    for (const VibrationZone z : zone_) worst = std::max(worst, static_cast<int>(z));
    emit(now, EventCode::kAlarmRaised, worst);
  }
  if (!d.alarm && alarm_) emit(now, EventCode::kAlarmCleared);
  alarm_ = d.alarm;
}

void Twin::cycle(hal::Timestamp now) {
  if (cycle_index_ == 0)
    emit(now, EventCode::kStarted, static_cast<int>(settings_.period_ns / 1000), rom_data_->dt_s);
  // 1 read
  last_scada_status_ = dev_.scada->read(now, scada_);
  drain_keyphasor(now);
  drain_cms(now);
  CalibrationStatus cs;
  if (mail_.calibration.read(cs)) calibration_ = cs;

  // 2 decide
  supervisor::CycleObservations seen;
  seen.scada_status = last_scada_status_;
  seen.cms_gap = lost_blocks_cycle_ > 0;
  seen.cms_fault = cms_fault_;
  seen.keyphasor_valid = dev_.keyphasor == nullptr || keyphasor_state_.valid;
  seen.overrun = overrun_since_publish_;
  seen.calibrated = calibration_generation_ > 0;
  seen.calibration_unfit = calibration_.unfit_after_calibration;
  seen.queue_full = queue_full_since_publish_;
  seen.rom_diverged = rom_diverged_since_publish_;
  seen.persistence_failed = mail_.persistence_failed.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < kSnapshotPoints; ++i) seen.zones[i] = zones_[i].zone();
  const supervisor::SupervisorDecision d = supervisor_.update(now, scada_, seen);

  // 3 step (a calibrated model is adopted at this cycle boundary)
  if (d.rom_valid) adopt_calibrated(d);
  step_model(now, d);
  collect_window(now, d);
  for (std::size_t c = 0; c < channels_.channel_count(); ++c) {
    // The channel's highest source stress of the cycle's last step (what the register shows).
    double worst = 0.0;
    for (std::size_t s = 0; s < channels_.channel(c).source_count; ++s)
      worst = std::max(worst, channels_.stress(c, s, loads_));
    last_load_[c] = d.rom_valid ? worst : 0.0;
  }

  // 4 write. SAFETY-CRITICAL: the watchdog toggles only while cycles complete; the alarm
  // follows the supervisor.
  watchdog_level_ = !watchdog_level_;
  if (dev_.outputs != nullptr) {
    (void)dev_.outputs->set_watchdog(watchdog_level_);
    (void)dev_.outputs->set_alarm(d.alarm);
  }

  // 5 publish, events, slow work
  events_on_change(now, d);
  last_decision_ = d;
  ++cycle_index_;
  ++counters_.cycles;
  snapshot_.stamp_ns = now.count();
  if (now >= next_interval_) {
    IntervalRecord r;
    r.stamp_ns = now.count();
    r.elapsed_s = accumulator_->elapsed_s();
    r.channel_count = static_cast<std::uint32_t>(channels_.channel_count());
    for (std::size_t c = 0; c < r.channel_count; ++c) r.damage[c] = accumulator_->damage(c);
    (void)mail_.intervals.push(r);
    next_interval_ += from_seconds(settings_.rul_interval_s);
  }
  if (now >= next_checkpoint_) {
    checkpoint();
    next_checkpoint_ += from_seconds(settings_.checkpoint_interval_s);
  }
  if (cycle_index_ % static_cast<std::uint64_t>(settings_.publish_divisor) == 0) publish(now);
}

std::size_t Twin::windows_outstanding() const {
  const std::size_t held = window_ != nullptr ? 1 : 0;
  const std::size_t free = mail_.windows_free.size();
  return Mailboxes::kWindows > free + held ? Mailboxes::kWindows - free - held : 0;
}

void Twin::checkpoint() {
  model::fatigue::AccumulatorState* s = nullptr;
  if (!mail_.checkpoints_free.pop(s)) {  // the persistence thread is still writing
    ++checkpoints_skipped_;
    return;
  }
  *s = accumulator_->state();
  if (!mail_.checkpoints_full.push(s)) {
    (void)mail_.checkpoints_free.push(s);
    ++checkpoints_skipped_;
    return;
  }
  ++checkpoints_handed_over_;
  last_checkpoint_elapsed_s_ = accumulator_->elapsed_s();
}

void Twin::record_timing(double wakeup_latency_us, double cycle_time_us, bool overran,
                         std::uint64_t skipped) {
  LoopCounters& c = counters_;
  c.wakeup_latency_us = static_cast<float>(wakeup_latency_us);
  c.cycle_time_us = static_cast<float>(cycle_time_us);
  if (std::isnan(c.cycle_time_max_us) || cycle_time_us > static_cast<double>(c.cycle_time_max_us))
    c.cycle_time_max_us = static_cast<float>(cycle_time_us);
  if (std::isnan(c.wakeup_latency_max_us) ||
      wakeup_latency_us > static_cast<double>(c.wakeup_latency_max_us))
    c.wakeup_latency_max_us = static_cast<float>(wakeup_latency_us);
  if (overran) {
    ++c.overruns;
    c.skipped_periods += skipped;
    overrun_since_publish_ = true;
    emit(hal::Timestamp{snapshot_.stamp_ns}, EventCode::kOverrun, static_cast<int>(skipped),
         wakeup_latency_us);
  }
}

void Twin::fill_snapshot(hal::Timestamp now) {
  Snapshot& s = snapshot_;
  const supervisor::SupervisorDecision& d = last_decision_;
  s.sequence = ++sequence_;
  s.stamp_ns = now.count();
  const auto f = [](double v) { return std::isfinite(v) ? static_cast<float>(v) : kNoValue; };
  s.rotor_speed_rpm = d.rom_valid ? f(d.rom.rotor_speed_rpm) : kNoValue;
  s.rotor_torque_nm = d.rom_valid ? f(d.rom.input_torque_nm) : kNoValue;
  s.wind_speed_mps = f(d.wind_speed_mps);
  s.power_kw = f(d.power_kw);
  s.hss_speed_rpm = keyphasor_state_.valid ? f(keyphasor_state_.speed_hz * 60.0) : kNoValue;
  s.scada_age_s = f(d.scada_age_s);
  s.torque_source = d.source;
  s.status_word = d.status_word;
  s.fault_word = d.fault_word;
  s.calibration_generation = calibration_generation_;
  if (calibration_.worst_ratio >= 0.0) {
    s.calibration_residual = static_cast<float>(calibration_.worst_ratio);
    for (std::size_t p = 0; p < kSnapshotPoints; ++p)
      for (std::size_t k = 0; k < 3; ++k) s.fit[p][k] = f(calibration_.f[p][k]);
  }
  for (std::size_t p = 0; p < kSnapshotPoints; ++p) zones_[p].fill(s.points[p]);
  RulTable rul;
  if (mail_.rul.read(rul)) rul_ = rul;
  const model::fatigue::DamageAccumulator& acc = *accumulator_;
  s.elapsed_s = acc.elapsed_s();
  s.rotor_revolutions = acc.rotor_revolutions();
  s.channel_count = static_cast<std::uint32_t>(channels_.channel_count());
  for (std::size_t c = 0; c < s.channel_count; ++c) {
    results::ChannelResult& r = s.channels[c];
    const double dmg = acc.damage(c);
    r.damage = static_cast<float>(dmg);
    // Long-term rate = accumulated damage / accumulated time (O(1) here); the p90 rate's
    // RUL comes from the service thread's rate history.
    r.rul_h = dmg > 0.0 && s.elapsed_s > 0.0
                  ? static_cast<float>(std::max(0.0, 1.0 - dmg) / (dmg / s.elapsed_s) / 3600.0)
                  : kInfHours;
    r.rul_low_h = rul_.rul_low_h[c];
    r.load = static_cast<float>(last_load_[c]);
  }
  counters_.rejected_inputs = supervisor_.rejected_total();
  s.counters = counters_;
}

void Twin::publish(hal::Timestamp now) {
  fill_snapshot(now);
  mail_.latest.write(snapshot_);
  if (!mail_.snapshots.push(snapshot_)) {
    ++counters_.snapshots_dropped;
    queue_full_since_publish_ = true;
  } else {
    queue_full_since_publish_ = false;
  }
  overrun_since_publish_ = false;
  rom_diverged_since_publish_ = false;
  if (dev_.results != nullptr) {
    register_map_.encode(to_results_values(snapshot_), image_);
    (void)dev_.results->publish(image_);
  }
}

}  // namespace app::loop
