#include "truth.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "hal/recording_bundle.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/spectrum.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/newmark.hpp"

namespace truth {
namespace {

namespace md = model::dynamics;

double rms_of(const std::vector<double>& x) { return model::dsp::rms(x.data(), x.size()); }

// The effect's severity parameter, scaled to conceal it; nullptr: not scalable.
const char* severity_parameter(model::EffectKind kind) {
  switch (kind) {
    case model::EffectKind::kToothCrack:
      return "stiffness_loss";
    case model::EffectKind::kGearEccentricity:
      return "eccentricity_um";
    case model::EffectKind::kBearingOuterRaceDefect:
    case model::EffectKind::kBearingInnerRaceDefect:
    case model::EffectKind::kBearingBallDefect:
      return "impact_force_n";
    case model::EffectKind::kShaftUnbalance:
      return "unbalance_kg_m";
    case model::EffectKind::kShaftMisalignment:
      return "misalignment_mrad";
    case model::EffectKind::kPlanetPassModulation:
      return "path_stiffness_mn_m";
    case model::EffectKind::kHousingResonance:
      return nullptr;
  }
  return nullptr;
}

bool is_bearing_defect(model::EffectKind kind) {
  return kind == model::EffectKind::kBearingOuterRaceDefect ||
         kind == model::EffectKind::kBearingInnerRaceDefect ||
         kind == model::EffectKind::kBearingBallDefect;
}

struct Waves {
  std::vector<std::vector<double>> sensors;  // [channel][sample] [m/s²]
  std::vector<double> hss_revolutions;       // [sample]
  double mean_rpm = 0.0;
};

double rpm_at(const CaseSpec& s, double t) {
  const Measurement& m = s.measurement;
  return s.rotor_rpm * (1.0 + m.drift * std::sin(2.0 * std::numbers::pi * t / m.drift_period_s +
                                                 m.drift_phase_rad));
}

// The full-order model, carrier turning, speed drifting, from its static deflection; the
// first settle_s discarded.
Waves simulate(const model::Drivetrain& d, const CaseSpec& s, double seconds) {
  md::StructuralParameters structure;
  structure.carrier_turns = true;
  std::string error;
  std::optional<md::FullModel> m = md::build_full_model(d, structure, &error);
  if (!m) throw std::runtime_error("case '" + s.id + "': " + error);
  const double total_s = s.settle_s + seconds;
  if (s.measurement.jitter > 0.0 && s.effect && is_bearing_defect(s.effect->kind)) {
    md::randomise_impacts(*m, s.measurement.jitter, total_s,
                          s.rotor_rpm / 60.0 * (1.0 + std::abs(s.measurement.drift)), s.seed + 7);
  }
  const double hss_ratio = model::Kinematics(d).overall_ratio();
  md::NewmarkIntegrator integ(*m, 1.0 / (s.sample_rate_hz * s.substeps));
  md::OperatingPoint op{rpm_at(s, 0.0), s.torque_nm};
  integ.reset_static(op);
  const auto settle = static_cast<std::size_t>(std::llround(s.settle_s * s.sample_rate_hz));
  const auto samples = static_cast<std::size_t>(std::llround(seconds * s.sample_rate_hz));
  Waves w;
  w.sensors.assign(m->sensors.size(), std::vector<double>(samples));
  w.hss_revolutions.resize(samples);
  double rpm_sum = 0.0;
  const double sub_dt = 1.0 / (s.sample_rate_hz * s.substeps);
  for (std::size_t i = 0; i < settle + samples; ++i) {
    for (int k = 0; k < s.substeps; ++k) {
      // The speed over the coming step (held over it).
      op.rotor_speed_rpm = rpm_at(s, integ.time_s() + 0.5 * sub_dt);
      integ.set_operating_point(op);
      integ.step();
    }
    if (i < settle) continue;
    const std::size_t j = i - settle;
    for (std::size_t c = 0; c < w.sensors.size(); ++c) w.sensors[c][j] = integ.sensor_m_s2(c);
    w.hss_revolutions[j] = integ.rotor_revolutions() * hss_ratio;
    rpm_sum += op.rotor_speed_rpm;
  }
  w.mean_rpm = rpm_sum / static_cast<double>(samples);
  return w;
}

// What the sensor adds: gain, then white noise scaled to the healthy channel's RMS.
std::vector<std::vector<double>> measure(const Waves& w, const Waves& healthy, const CaseSpec& s) {
  std::mt19937_64 rng(s.seed);
  std::vector<std::vector<double>> out = w.sensors;
  for (std::size_t c = 0; c < out.size(); ++c) {
    const double gain = c < s.measurement.gain.size() ? s.measurement.gain[c] : 1.0;
    std::normal_distribution<double> gauss(0.0, s.measurement.noise * rms_of(healthy.sensors[c]));
    for (double& v : out[c]) v = gain * v + gauss(rng);
  }
  return out;
}

model::Drivetrain with_effect(model::Drivetrain d, const std::optional<model::Effect>& e) {
  d.effects.clear();
  if (e) d.effects.push_back(*e);
  return d;
}

}  // namespace

std::vector<double> welch_amplitude(const std::vector<double>& x, std::size_t nfft) {
  model::dsp::SpectrumAnalyzer fft(nfft);
  if (!fft.valid() || x.size() < nfft)
    throw std::runtime_error("welch_amplitude: record shorter than the block");
  std::vector<double> sum(fft.lines(), 0.0), line(fft.lines());
  int blocks = 0;
  for (std::size_t start = 0; start + nfft <= x.size(); start += nfft / 2, ++blocks) {
    fft.amplitude_spectrum(x.data() + start, line.data());
    for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += line[k];
  }
  for (double& v : sum) v /= blocks;
  return sum;
}

double tenth_highest_peak(const std::vector<double>& a) {
  std::vector<double> peaks;
  for (std::size_t k = 2; k + 1 < a.size(); ++k) {  // lines 0, 1: the mean's leakage
    if (a[k] > a[k - 1] && a[k] >= a[k + 1]) peaks.push_back(a[k]);
  }
  if (peaks.size() < 10) return peaks.empty() ? 0.0 : *std::min_element(peaks.begin(), peaks.end());
  std::nth_element(peaks.begin(), peaks.begin() + 9, peaks.end(), std::greater<>());
  return peaks[9];
}

ChannelConcealment concealment(const std::string& channel, const std::vector<double>& raw,
                               const std::vector<double>& without, double fs) {
  ChannelConcealment c;
  c.channel = channel;
  std::size_t nfft = 16;
  while (nfft * 2 <= std::min<std::size_t>(raw.size(), std::size_t{1} << 15)) nfft *= 2;
  std::vector<double> diff(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) diff[i] = raw[i] - without[i];
  const std::vector<double> spec_raw = welch_amplitude(raw, nfft);
  const std::vector<double> spec_eff = welch_amplitude(diff, nfft);
  std::size_t best = 2;
  for (std::size_t k = 2; k < spec_eff.size(); ++k) {
    if (spec_eff[k] > spec_eff[best]) best = k;
  }
  c.effect_line_hz = static_cast<double>(best) * fs / static_cast<double>(nfft);
  c.effect_line = spec_eff[best];
  c.tenth_peak = tenth_highest_peak(spec_raw);
  c.margin_db = c.effect_line > 0.0 && c.tenth_peak > 0.0
                    ? 20.0 * std::log10(c.effect_line / c.tenth_peak)
                    : -300.0;
  const double r0 = rms_of(without);
  c.rms_change = r0 > 0.0 ? rms_of(raw) / r0 - 1.0 : 0.0;
  c.concealed = std::abs(c.rms_change) < kConcealedRmsChange && c.margin_db <= -kConcealedMarginDb;
  return c;
}

model::DynamicsParameters off_nominal(const model::DynamicsParameters& nominal, double spread,
                                      std::uint64_t seed) {
  std::mt19937_64 rng(seed * 2654435761ULL + 12345);
  auto factor = [&](double half_width) {
    std::uniform_real_distribution<double> u(-half_width * spread, half_width * spread);
    return 1.0 + u(rng);
  };
  model::DynamicsParameters p = nominal;
  for (double& k : p.mesh_stiffness_scale) k *= factor(0.10);
  for (double& k : p.bearing_stiffness_scale) k *= factor(0.15);
  p.rayleigh_eta *= factor(0.30);
  p.rayleigh_zeta *= factor(0.30);
  return p;
}

CaseResult run_case(const model::Drivetrain& drivetrain, const CaseSpec& spec) {
  CaseResult r;
  r.spec = spec;
  model::Drivetrain d = drivetrain;
  d.dynamics = off_nominal(drivetrain.dynamics, spec.offset_spread, spec.seed);
  r.parameters = d.dynamics;
  if (spec.effect) {
    std::string error;
    if (!model::check_effect(d, *spec.effect, &error))
      throw std::runtime_error("case '" + spec.id + "': " + error);
  }
  const model::Drivetrain healthy_d = with_effect(d, std::nullopt);
  const Waves healthy = simulate(healthy_d, spec, spec.seconds);
  r.mean_rotor_rpm = healthy.mean_rpm;
  const std::vector<std::vector<double>> healthy_measured = measure(healthy, healthy, spec);
  std::vector<std::vector<double>> measured = healthy_measured;
  Waves final_waves = healthy;

  if (spec.effect) {
    model::Effect effect = *spec.effect;
    const char* knob = severity_parameter(effect.kind);
    // Concealment figures of the effect against a healthy run of the same length.
    auto figures = [&](const Waves& w, const Waves& base,
                       const std::vector<std::vector<double>>& base_measured,
                       std::vector<ChannelConcealment>& out) {
      const std::vector<std::vector<double>> m = measure(w, base, spec);
      out.clear();
      for (std::size_t c = 0; c < m.size(); ++c)
        out.push_back(concealment(d.measurement_points[c].channel, m[c], base_measured[c],
                                  spec.sample_rate_hz));
      return m;
    };
    auto all_concealed = [](const std::vector<ChannelConcealment>& cs) {
      return std::all_of(cs.begin(), cs.end(),
                         [](const ChannelConcealment& c) { return c.concealed; });
    };
    if (spec.conceal && knob != nullptr) {
      // Find the severity on short probes first: aim 2 dB inside the line criterion and at
      // 6 % RMS change, both about linear in the severity parameter for these small effects.
      CaseSpec probe_spec = spec;
      probe_spec.seconds = std::min(spec.seconds, 4.0);
      const Waves probe_healthy = simulate(healthy_d, probe_spec, probe_spec.seconds);
      const auto probe_measured = measure(probe_healthy, probe_healthy, probe_spec);
      double upper = 0.0;
      for (const auto& p : model::effect_parameters(effect.kind)) {
        if (std::string(p.name) == knob) upper = p.upper;
      }
      for (int t = 0; t < 4; ++t) {
        std::vector<ChannelConcealment> probe;
        figures(simulate(with_effect(d, effect), probe_spec, probe_spec.seconds), probe_healthy,
                probe_measured, probe);
        double worst_margin = -300.0, worst_rms = 0.0;
        for (const auto& c : probe) {
          worst_margin = std::max(worst_margin, c.margin_db);
          worst_rms = std::max(worst_rms, std::abs(c.rms_change));
        }
        double scale = std::pow(10.0, (-(kConcealedMarginDb + 2.0) - worst_margin) / 20.0);
        if (worst_rms > 0.0) scale = std::min(scale, 0.06 / worst_rms);
        const double current = *effect.parameter(knob);
        const double next = std::min(current * scale, upper);
        if (std::abs(next / current - 1.0) < 0.15) break;  // near the aim
        effect.set_parameter(knob, next);
        if (next >= upper && all_concealed(probe)) break;  // at its bound and still hidden
      }
    }
    // The recording at that severity; if the full length shows it, back off and redo.
    for (int t = 0; t < 3; ++t) {
      r.severity_tries = t + 1;
      final_waves = simulate(with_effect(d, effect), spec, spec.seconds);
      measured = figures(final_waves, healthy, healthy_measured, r.concealment);
      r.concealed = all_concealed(r.concealment);
      if (r.concealed || !spec.conceal || knob == nullptr) break;
      double worst_margin = -300.0, worst_rms = 0.0;
      for (const auto& c : r.concealment) {
        worst_margin = std::max(worst_margin, c.margin_db);
        worst_rms = std::max(worst_rms, std::abs(c.rms_change));
      }
      double scale = std::pow(10.0, (-(kConcealedMarginDb + 2.0) - worst_margin) / 20.0);
      if (worst_rms > 0.0) scale = std::min(scale, 0.06 / worst_rms);
      effect.set_parameter(knob, *effect.parameter(knob) * std::min(scale, 0.8));
    }
    r.spec.effect = effect;
  }

  r.samples = measured;
  if (spec.measurement.tacho) {
    std::vector<double> pulse(final_waves.hss_revolutions.size());
    for (std::size_t i = 0; i < pulse.size(); ++i) {
      const double rev = final_waves.hss_revolutions[i];
      pulse[i] = rev - std::floor(rev) < 0.05 ? 5.0 : 0.0;  // 5 V over 5 % of a revolution
    }
    r.samples.push_back(std::move(pulse));
  }
  return r;
}

void write_case_bundle(const CaseResult& r, const std::string& dir) {
  hal::Recording rec;
  rec.drivetrain = "paper-2mw";
  rec.sample_rate_hz = r.spec.sample_rate_hz;
  rec.samples_file = "cms.wav";
  const model::Drivetrain d = model::paper_2mw();
  for (const auto& mp : d.measurement_points)
    rec.channels.push_back({mp.channel, mp.location, "radial", "", "m/s^2"});
  if (r.spec.measurement.tacho) rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
  rec.samples = r.samples;
  rec.operating_point.rotor_speed_rpm = r.mean_rotor_rpm;
  rec.operating_point.input_torque_nm = r.spec.torque_nm;
  rec.notes = "drivetwin truth synthesizer, case " + r.spec.id;
  if (const auto err = hal::write_bundle(dir, rec)) throw std::runtime_error(err->to_string());
}

std::string truth_json(const CaseResult& r) {
  nlohmann::ordered_json j;
  j["format"] = "drivetwin-truth/1";
  j["case"] = r.spec.id;
  j["note"] = r.spec.note;
  if (r.spec.effect) {
    const model::Effect& e = *r.spec.effect;
    j["effect"] = std::string(model::effect_id(e.kind));
    j["location"] = e.location;
    nlohmann::ordered_json p;
    const auto params = model::effect_parameters(e.kind);
    for (std::size_t i = 0; i < params.size(); ++i) p[params[i].name] = e.parameters[i];
    j["parameters"] = p;
  } else {
    j["effect"] = nullptr;
  }
  j["operating_point"] = {{"rotor_speed_rpm_nominal", r.spec.rotor_rpm},
                          {"rotor_speed_rpm_mean", r.mean_rotor_rpm},
                          {"input_torque_nm", r.spec.torque_nm}};
  const Measurement& m = r.spec.measurement;
  j["measurement"] = {{"seconds", r.spec.seconds},
                      {"sample_rate_hz", r.spec.sample_rate_hz},
                      {"noise_relative", m.noise},
                      {"speed_drift", m.drift},
                      {"speed_drift_period_s", m.drift_period_s},
                      {"gain", m.gain},
                      {"tacho", m.tacho},
                      {"impact_jitter", m.jitter},
                      {"seed", r.spec.seed}};
  const model::DynamicsParameters& p = r.parameters;
  j["dynamics_parameters"] = {{"rayleigh_eta", p.rayleigh_eta},
                              {"rayleigh_zeta", p.rayleigh_zeta},
                              {"mesh_stiffness_scale", p.mesh_stiffness_scale},
                              {"bearing_stiffness_scale", p.bearing_stiffness_scale}};
  nlohmann::ordered_json c = nlohmann::ordered_json::object();
  for (const auto& ch : r.concealment) {
    c[ch.channel] = {{"rms_change", ch.rms_change},        {"effect_line_hz", ch.effect_line_hz},
                     {"effect_line_m_s2", ch.effect_line}, {"tenth_peak_m_s2", ch.tenth_peak},
                     {"margin_db", ch.margin_db},          {"concealed", ch.concealed}};
  }
  j["concealment"] = c;
  j["concealed"] = r.concealed;
  j["severity_tries"] = r.severity_tries;
  return j.dump(2) + "\n";
}

}  // namespace truth
