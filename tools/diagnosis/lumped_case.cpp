#include "lumped_case.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace tools::diagnosis {

LumpedCase make_lumped_case(const model::Drivetrain& d, const LumpedCaseSpec& spec_in) {
  LumpedCase out;
  out.spec = spec_in;
  LumpedCaseSpec& spec = out.spec;
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const double phase = std::numbers::pi * uni(rng);
  const std::array<double, 2> gains{1.0 + spec.gain_error * uni(rng),
                                    1.0 + spec.gain_error * uni(rng)};
  const double f0 = spec.rpm / 60.0, drift = spec.drift;
  const double w = 2.0 * std::numbers::pi / spec.drift_period_s;
  auto revs = [=](double t) {
    return f0 * (t - drift / w * (std::cos(w * t + phase) - std::cos(phase)));
  };
  const double settle = 0.5;
  const bool control = spec.effect.effect.empty();
  std::vector<LumpedEffect> none;
  const LumpedOutput without =
      simulate_lumped(d, revs, spec.torque_nm, spec.fs_hz, spec.seconds, settle, none,
                      spec.stiffness_scale, spec.damping_scale, spec.seed);
  LumpedOutput with = without;
  // Noise: a fixed realisation per case (the same with and without the effect).
  std::array<std::vector<double>, 2> noise;
  for (std::size_t c = 0; c < 2; ++c) {
    const std::vector<double>& x = c == 0 ? without.point1 : without.point2;
    double mean = 0.0, ss = 0.0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (double v : x) ss += (v - mean) * (v - mean);
    std::normal_distribution<double> g(0.0,
                                       spec.noise * std::sqrt(ss / static_cast<double>(x.size())));
    noise[c].resize(x.size());
    for (double& v : noise[c]) v = g(rng);
  }
  auto record = [&](const LumpedOutput& o) {
    std::vector<std::vector<double>> r = {o.point1, o.point2};
    for (std::size_t c = 0; c < 2; ++c)
      for (std::size_t i = 0; i < r[c].size(); ++i) r[c][i] = gains[c] * r[c][i] + noise[c][i];
    return r;
  };
  std::vector<std::vector<double>> recorded = record(without);
  if (!control) {
    // Concealment: the strongest effect line 8–20 dB below the tenth peak and the RMS
    // within 10 %. The knob is the severity (a resonance: its damping, inversely), moved
    // geometrically and then bisected between a known too-hidden and a known too-visible
    // value.
    const bool resonance = spec.effect.effect == "housing_resonance";
    double& knob = resonance ? spec.effect.damping : spec.effect.severity;
    const double knob_max = spec.effect.effect == "tooth_crack" ? 0.95 : (resonance ? 0.5 : 1e300);
    const double knob_min = resonance ? 0.005 : 0.0;
    double too_hidden = 0.0, too_visible = 0.0;  // 0: not known yet
    for (int attempt = 0; attempt < 10; ++attempt) {
      with = simulate_lumped(d, revs, spec.torque_nm, spec.fs_hz, spec.seconds, settle,
                             {spec.effect}, spec.stiffness_scale, spec.damping_scale, spec.seed);
      recorded = record(with);
      out.concealment =
          concealment({with.point1, with.point2}, {without.point1, without.point2}, recorded);
      out.concealed = out.concealment.concealed();
      if (!spec.conceal) break;
      const double margin = out.concealment.line_margin_db;
      const bool visible = !out.concealed || margin < 8.0;
      if (!visible && margin <= 20.0) break;
      // "stronger" means a larger severity, or a smaller damping of a resonance.
      const bool stronger_needed = !visible;
      if (visible)
        too_visible = knob;
      else
        too_hidden = knob;
      double next;
      if (too_hidden > 0.0 && too_visible > 0.0) {
        next = std::sqrt(too_hidden * too_visible);
      } else {
        double factor = std::clamp(std::pow(10.0, (margin - 12.0) / 20.0), 0.05, 20.0);
        if (!out.concealed && out.concealment.rms_change >= 0.10) factor = std::min(factor, 0.3);
        next = resonance ? knob / factor : knob * factor;
      }
      next = std::clamp(next, knob_min, knob_max);
      if (next == knob || (stronger_needed && knob == (resonance ? knob_min : knob_max))) break;
      knob = next;
    }
  }
  hal::Recording& rec = out.recording;
  rec.drivetrain = d.name;
  rec.sample_rate_hz = spec.fs_hz;
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  rec.samples = std::move(recorded);
  if (spec.tacho) {
    std::vector<double> t(with.hss_revolutions.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double r = with.hss_revolutions[i];
      t[i] = r - std::floor(r) < 0.05 ? 5.0 : 0.0;
    }
    rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
    rec.samples.push_back(std::move(t));
  }
  rec.operating_point.rotor_speed_rpm = spec.rpm;
  rec.operating_point.input_torque_nm = spec.torque_nm;
  rec.notes = "lumped gearbox (tools/diagnosis), case " + spec.id;
  return out;
}

std::string lumped_truth_json(const LumpedCase& c) {
  nlohmann::ordered_json j;
  j["generator"] = "lumped";
  j["case"] = c.spec.id;
  j["effect"] = c.spec.effect.effect.empty() ? nlohmann::ordered_json(nullptr)
                                             : nlohmann::ordered_json(c.spec.effect.effect);
  j["location"] = c.spec.effect.location.empty() ? nlohmann::ordered_json(nullptr)
                                                 : nlohmann::ordered_json(c.spec.effect.location);
  j["severity"] = c.spec.effect.severity;
  if (c.spec.effect.effect == "housing_resonance") j["damping_ratio"] = c.spec.effect.damping;
  j["rotor_speed_rpm"] = c.spec.rpm;
  j["input_torque_nm"] = c.spec.torque_nm;
  j["tacho"] = c.spec.tacho;
  j["drift"] = c.spec.drift;
  j["noise"] = c.spec.noise;
  j["stiffness_scale"] = c.spec.stiffness_scale;
  j["damping_scale"] = c.spec.damping_scale;
  j["concealed"] = c.concealed;
  j["rms_change"] = c.concealment.rms_change;
  j["line_margin_db"] = c.concealment.line_margin_db;
  return j.dump(2) + "\n";
}

}  // namespace tools::diagnosis
