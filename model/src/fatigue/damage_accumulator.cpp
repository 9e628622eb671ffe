#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "model/fatigue/damage_accumulator.hpp"

namespace model::fatigue {
namespace {
constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;
std::uint64_t fnv(std::uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * kFnvPrime;
  return h;
}
}  // namespace

DamageAccumulator::DamageAccumulator(const ChannelSet& channels, const AccumulatorConfig& config)
    : channels_(&channels), config_(config), state_(std::make_unique<AccumulatorState>()) {
  config_.bins = std::clamp<std::uint32_t>(config_.bins, 1, kMaxBins);
  std::uint64_t h = kFnvOffset;
  h = fnv(h, &config_.bins, sizeof config_.bins);
  h = fnv(h, &config_.tick_s, sizeof config_.tick_s);
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    double fs = config_.full_scale[c];
    if (!(fs > 0.0) || !std::isfinite(fs)) fs = channels.channel(c).stress_full_scale;
    config_.full_scale[c] = fs;
    width_[c] = fs / config_.bins;
    inv_width_[c] = 1.0 / width_[c];
    const Channel& ch = channels.channel(c);
    h = fnv(h, ch.component.data(), ch.component.size());
    h = fnv(h, ch.detail.data(), ch.detail.size());
    h = fnv(h, &ch.mode, sizeof ch.mode);
    h = fnv(h, &fs, sizeof fs);
  }
  const Lubrication& lub = channels.options().lubrication;
  const double lub_values[] = {lub.enabled ? 1.0 : 0.0, lub.viscosity_40c_mm2_s,
                               lub.viscosity_100c_mm2_s, lub.temperature_c,
                               lub.contamination_factor};
  h = fnv(h, lub_values, sizeof lub_values);
  config_hash_ = h;
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    const SnCurve& sn = channels.channel(c).curve;
    CurveConstants& k = curve_[c];
    // SnCurve::cycles_to_failure: N = n_ref·(C/σ)^m, beyond the knee N0·(σ_k/σ)^k2.
    k.k1 = sn.m;
    k.ln_n1 = std::log(sn.n_ref) + sn.m * std::log(sn.c);
    const bool knee = sn.branch != KneeBranch::kNone && std::isfinite(sn.knee_cycles);
    k.ln_knee = knee ? std::log(sn.knee_cycles) : std::numeric_limits<double>::infinity();
    k.k2 = knee ? sn.exponent_beyond_knee() : sn.m;
    k.ln_n2 = knee ? k.ln_knee + k.k2 * std::log(sn.knee_stress()) : k.ln_n1;
  }
  for (std::size_t b = 0; b < channels.bearing_count(); ++b) {
    const Bearing& br = channels.bearing(b);
    BearingConstants& k = bearing_[b];
    // equivalent_load_n()'s constants, computed the same way.
    k.radial_only = br.type == BearingType::kBall || br.contact_angle_rad <= 0.0;
    k.single_row = br.rows <= 1;
    if (!k.radial_only) {
      k.e = 1.5 * std::tan(br.contact_angle_rad);
      k.cot = 1.0 / std::tan(br.contact_angle_rad);
    }
  }
  reset();
}

void DamageAccumulator::reset() {
  *state_ = AccumulatorState{};
  state_->channel_count = static_cast<std::uint32_t>(channels_->channel_count());
  state_->bins = config_.bins;
  state_->config_hash = config_hash_;
}

bool DamageAccumulator::restore(const AccumulatorState& saved) {
  if (saved.version != kAccumulatorStateVersion || saved.channel_count != state_->channel_count ||
      saved.bins != state_->bins || saved.config_hash != config_hash_) {
    return false;
  }
  std::memcpy(state_.get(), &saved, sizeof saved);
  return true;
}

StepResult DamageAccumulator::step(const LoadSample& loads, double rotor_speed_rpm,
                                   std::uint32_t dt_ticks) {
  AccumulatorState& s = *state_;
  if (dt_ticks == 0) {
    ++s.zero_dt_steps;
    return StepResult::kZeroDt;
  }
  if (!std::isfinite(rotor_speed_rpm) || rotor_speed_rpm < 0.0) {
    ++s.bad_speed_steps;
    return StepResult::kBadSpeed;
  }
  const ChannelSet& cs = *channels_;
  for (std::size_t i = 0; i < cs.mesh_count(); ++i) {
    if (!std::isfinite(loads.mesh_force_n[i])) {
      ++s.bad_load_steps;
      return StepResult::kBadLoad;
    }
  }
  for (std::size_t i = 0; i < cs.bearing_count(); ++i) {
    if (!std::isfinite(loads.bearing_radial_n[i]) || !std::isfinite(loads.bearing_axial_n[i])) {
      ++s.bad_load_steps;
      return StepResult::kBadLoad;
    }
  }
  const double revs = rotor_speed_rpm / 60.0 * static_cast<double>(dt_ticks) * config_.tick_s;
  const auto rev_q = static_cast<std::uint64_t>(std::llround(revs / kRevQuantum));
  ++s.valid_steps;
  s.elapsed_ticks += dt_ticks;
  s.rotor_rev_q += rev_q;
  // Every slot's stresses once (a mesh feeds up to four channels).
  std::array<MeshStresses, kMaxMeshes> mesh;
  for (std::size_t i = 0; i < cs.mesh_count(); ++i)
    mesh[i] = cs.mesh(i).stresses(loads.mesh_force_n[i]);
  std::array<double, kMaxBearings> bearing_p;
  for (std::size_t i = 0; i < cs.bearing_count(); ++i) {
    // equivalent_load_n() with e and cot α from construction.
    const BearingConstants& b = bearing_[i];
    const double fr = std::abs(loads.bearing_radial_n[i]), fa = std::abs(loads.bearing_axial_n[i]);
    if (b.radial_only) {
      bearing_p[i] = fr;
    } else {
      const bool low_axial = fa <= b.e * fr;
      bearing_p[i] = b.single_row
                         ? (low_axial ? fr : 0.4 * fr + 0.4 * b.cot * fa)
                         : (low_axial ? fr + 0.45 * b.cot * fa : 0.67 * fr + 0.67 * b.cot * fa);
    }
  }
  const std::size_t overflow = config_.bins;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    const Channel& ch = cs.channel(c);
    const CurveConstants& k = curve_[c];
    for (std::size_t j = 0; j < ch.source_count; ++j) {
      const Source& src = ch.sources[j];
      double sigma = 0.0;
      switch (ch.mode) {
        case FailureMode::kContact:
          sigma = mesh[src.slot].contact_mpa[src.gear];
          break;
        case FailureMode::kBending:
          sigma = mesh[src.slot].bending_mpa[src.gear];
          break;
        case FailureMode::kBearing:
          sigma = bearing_p[src.slot];
          break;
      }
      std::size_t bin = overflow;
      if (sigma < config_.full_scale[c]) {
        bin =
            std::min(overflow - 1, static_cast<std::size_t>(std::max(0.0, sigma) * inv_width_[c]));
      } else {
        s.overflow_max[c] = std::max(s.overflow_max[c], sigma);
      }
      s.bin_ticks[c][bin] += dt_ticks;
      s.bin_rev_q[c][bin] += rev_q;
      if (!(sigma > 0.0)) continue;  // no load, no damage
      // Palmgren–Miner increment n/N(σ), n = revs·cycles per rotor rev (ISO 6336-6 §5).
      const double ln_sigma = std::log(sigma);
      double ln_n = k.ln_n1 - k.k1 * ln_sigma;
      if (ln_n > k.ln_knee) ln_n = k.ln_n2 - k.k2 * ln_sigma;
      double inc = revs * src.cycles_per_rotor_rev * std::exp(-ln_n);
      // ISO 281: L_nm = a_ISO·L10 (a1 = 1), so each revolution costs 1/a_ISO of the basic damage.
      if (ch.mode == FailureMode::kBearing) {
        inc /= cs.life_modification(src.slot, sigma, rotor_speed_rpm);
      }
      // Neumaier compensated summation.
      const double sum = s.damage[c];
      const double t = sum + inc;
      if (std::abs(sum) >= std::abs(inc)) {
        s.damage_comp[c] += (sum - t) + inc;
      } else {
        s.damage_comp[c] += (inc - t) + sum;
      }
      s.damage[c] = t;
    }
  }
  return StepResult::kAccumulated;
}

double DamageAccumulator::histogram_damage(std::size_t c) const {
  const Channel& ch = channels_->channel(c);
  if (ch.source_count == 0) return 0.0;
  // All sources of a channel share cycles per rotor revolution (ChannelSet builds them so).
  const double cycles = ch.sources[0].cycles_per_rotor_rev;
  double d = 0.0;
  for (std::size_t i = 0; i < config_.bins; ++i) {
    const double revs = static_cast<double>(state_->bin_rev_q[c][i]) * kRevQuantum;
    if (revs > 0.0)
      d += revs * cycles * ch.curve.damage_per_cycle((static_cast<double>(i) + 0.5) * width_[c]);
  }
  const double over = static_cast<double>(state_->bin_rev_q[c][config_.bins]) * kRevQuantum;
  if (over > 0.0) d += over * cycles * ch.curve.damage_per_cycle(state_->overflow_max[c]);
  return d;
}

}  // namespace model::fatigue
