#include "diagnosis/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace app::diagnosis {

namespace md = model::diagnosis;
namespace mc = model::calibration;

namespace {

nlohmann::ordered_json fit_json(const mc::PointIndicators& fit,
                                const std::vector<md::PointSpectra>& spectra) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (std::size_t p = 0; p < fit.size(); ++p) {
    const std::string name =
        p < spectra.size() ? spectra[p].channel : "point" + std::to_string(p + 1);
    j[name] = {{"f1", fit[p].f1}, {"f2", fit[p].f2}, {"f3", fit[p].f3}};
  }
  return j;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string general(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// One spectrum panel: the recording (grey) and a simulation (colour) in dB re the
// recording's largest line, 0..max_hz, with bands and lines marked.
std::string spectrum_svg(const md::SpectrumTrace& rec, const md::SpectrumTrace& sim,
                         const std::string& sim_label, const std::string& colour,
                         const std::vector<const md::MismatchEntry*>& marks,
                         const std::string& title, double max_hz) {
  const double w = 920, h = 230, left = 52, right = 10, top = 22, bottom = 30;
  const double pw = w - left - right, ph = h - top - bottom;
  double peak = 1e-300;
  for (double a : rec.amplitude) peak = std::max(peak, a);
  const double db_lo = -100.0;
  auto x_of = [&](double hz) { return left + pw * std::clamp(hz / max_hz, 0.0, 1.0); };
  auto y_of = [&](double a) {
    const double db = a > 0.0 ? 20.0 * std::log10(a / peak) : db_lo;
    return top + ph * std::clamp(db / db_lo, 0.0, 1.0);
  };
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << w << "' height='" << h
    << "' viewBox='0 0 " << w << ' ' << h << "'>";
  o << "<text x='" << left << "' y='15' font-size='13' font-weight='bold'>" << escape(title)
    << "</text>";
  for (const md::MismatchEntry* m : marks) {
    if (m->domain == md::FeatureDomain::kAverage) continue;
    // A kinematic family's band is shaded; lines no family explains are only marked (grey).
    if (m->kinematic) {
      const double x0 = x_of(std::max(0.0, m->band_lo_hz - 2.0)), x1 = x_of(m->band_hi_hz + 2.0);
      o << "<rect x='" << x0 << "' y='" << top << "' width='" << std::max(2.0, x1 - x0)
        << "' height='" << ph << "' fill='#ffd54f' fill-opacity='0.35'><title>"
        << escape(m->signature) << "</title></rect>";
    }
    for (double f : m->peaks_hz)
      o << "<path d='M" << x_of(f) << ' ' << top << " l-4 -7 h8 z' fill='"
        << (m->kinematic ? "#e65100" : "#9e9e9e") << "'><title>"
        << fixed(f, 2) + " Hz: " << escape(m->signature) << "</title></path>";
  }
  for (int db = 0; db >= -100; db -= 20) {
    const double y = top + ph * db / db_lo;
    o << "<line x1='" << left << "' x2='" << left + pw << "' y1='" << y << "' y2='" << y
      << "' stroke='#ddd'/><text x='" << left - 4 << "' y='" << y + 4
      << "' font-size='10' text-anchor='end'>" << db << "</text>";
  }
  for (int k = 0; k <= 10; ++k) {
    const double hz = max_hz * k / 10.0, x = x_of(hz);
    o << "<text x='" << x << "' y='" << h - 12 << "' font-size='10' text-anchor='middle'>"
      << fixed(hz, 0) << "</text>";
  }
  o << "<text x='" << left + pw << "' y='" << h - 1
    << "' font-size='10' text-anchor='end'>Hz</text>";
  o << "<text x='12' y='" << top + ph / 2 << "' font-size='10' transform='rotate(-90 12 "
    << top + ph / 2 << ")' text-anchor='middle'>dB re max</text>";
  auto poly = [&](const md::SpectrumTrace& t, const std::string& c, double width) {
    o << "<polyline fill='none' stroke='" << c << "' stroke-width='" << width << "' points='";
    for (std::size_t i = 0; i < t.hz.size(); ++i)
      o << fixed(x_of(t.hz[i]), 1) << ',' << fixed(y_of(t.amplitude[i]), 1) << ' ';
    o << "'/>";
  };
  poly(sim, colour, 1.2);
  o << "<g opacity='0.75'>";
  poly(rec, "#333", 0.7);
  o << "</g>";
  o << "<rect x='" << left + pw - 250 << "' y='" << top + 2
    << "' width='248' height='30' fill='white' fill-opacity='0.8'/>";
  o << "<line x1='" << left + pw - 244 << "' x2='" << left + pw - 224 << "' y1='" << top + 11
    << "' y2='" << top + 11 << "' stroke='#333' stroke-width='2'/><text x='" << left + pw - 220
    << "' y='" << top + 15 << "' font-size='11'>recording</text>";
  o << "<line x1='" << left + pw - 244 << "' x2='" << left + pw - 224 << "' y1='" << top + 25
    << "' y2='" << top + 25 << "' stroke='" << colour << "' stroke-width='2'/><text x='"
    << left + pw - 220 << "' y='" << top + 29 << "' font-size='11'>" << escape(sim_label)
    << "</text>";
  o << "</svg>";
  return o.str();
}

std::string fit_table(const char* title, const mc::PointIndicators& fit,
                      const std::vector<md::PointSpectra>& spectra) {
  std::ostringstream o;
  o << "<tr><th>" << title << "</th>";
  for (std::size_t p = 0; p < fit.size(); ++p) {
    auto cell = [&](double v, double t) {
      o << "<td" << (v > t ? " class='bad'" : "") << ">" << fixed(v, 3) << "</td>";
    };
    cell(fit[p].f1, mc::kF1Threshold);
    cell(fit[p].f2, mc::kF2Threshold);
    cell(fit[p].f3, mc::kF3Threshold);
  }
  (void)spectra;
  o << "</tr>";
  return o.str();
}

const char* domain_name(md::FeatureDomain d) {
  switch (d) {
    case md::FeatureDomain::kSpectrum:
      return "spectrum";
    case md::FeatureDomain::kEnvelope:
      return "envelope";
    case md::FeatureDomain::kAverage:
      return "synchronous average";
    case md::FeatureDomain::kBand:
      return "band";
  }
  return "";
}

}  // namespace

nlohmann::ordered_json report_json(const md::DiagnosisReport& r, const md::Catalogue& catalogue,
                                   const std::string& bundle_name) {
  (void)catalogue;
  nlohmann::ordered_json j;
  j["format"] = "drivetwin-diagnosis/1";
  j["bundle"] = bundle_name;
  j["operating_point"] = {{"rotor_speed_rpm", r.rotor_speed_rpm},
                          {"input_torque_nm", r.input_torque_nm}};
  j["fit_before"] = fit_json(r.fit_before, r.spectra);
  j["fit_calibrated"] = fit_json(r.fit_calibrated, r.spectra);
  j["residual_before"] = r.residual_before;
  j["residual_calibrated"] = r.residual_calibrated;
  nlohmann::ordered_json mismatch = nlohmann::ordered_json::array();
  for (const md::MismatchEntry& m : r.mismatch) {
    mismatch.push_back({{"channel", m.channel},
                        {"band_hz", {m.band_lo_hz, m.band_hi_hz}},
                        {"peaks_hz", m.peaks_hz},
                        {"signature", m.signature}});
  }
  j["mismatch"] = mismatch;
  nlohmann::ordered_json missing = nlohmann::ordered_json::array();
  for (std::size_t i : r.missing) {
    const md::CandidateResult& c = r.candidates[i];
    nlohmann::ordered_json params = nlohmann::ordered_json::object();
    for (const auto& [name, value] : c.parameters) params[name] = value;
    missing.push_back({{"effect", md::effect_id(c.effect)},
                       {"location", c.location},
                       {"confidence", c.confidence},
                       {"parameters", params},
                       {"explanation", c.explanation}});
  }
  j["missing_physics"] = missing;
  j["fit_after"] = fit_json(r.fit_after, r.spectra);
  j["residual_after"] = r.residual_after;
  return j;
}

std::string report_html(const md::DiagnosisReport& r, const md::Catalogue& catalogue,
                        const std::string& bundle_name) {
  (void)catalogue;
  std::ostringstream o;
  o << "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>drivetwin diagnosis: "
    << escape(bundle_name)
    << "</title><style>body{font-family:sans-serif;margin:20px;max-width:960px;color:#222}"
       "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px "
       "7px;font-size:13px;text-align:left}"
       "td.bad{background:#ffcdd2}.effect{background:#e8f5e9;border:1px solid "
       "#81c784;padding:8px;margin:8px 0}"
       ".none{background:#eceff1;padding:8px}h2{border-bottom:1px solid "
       "#aaa}small{color:#666}</style></head><body>";
  o << "<h1>Diagnosis of <code>" << escape(bundle_name) << "</code></h1>";
  o << "<p>Drivetrain <b>" << escape(r.drivetrain) << "</b>; rotor " << fixed(r.rotor_speed_rpm, 3)
    << " rpm (" << escape(r.reference_shaft) << " " << fixed(r.reference_hz, 3)
    << " Hz, speed from " << escape(r.speed_source) << ", " << fixed(r.speed_min_hz, 3) << "–"
    << fixed(r.speed_max_hz, 3) << " Hz within the recording); input torque "
    << fixed(r.input_torque_nm, 0) << " N·m; " << r.revolutions
    << " revolutions analysed, halves of " << r.half_revolutions << ".</p>";

  o << "<h2>Missing physics</h2>";
  if (r.missing.empty()) {
    o << "<div class='none'>None: calibration alone explains the recording as well as any modelled "
         "effect "
         "(no candidate passed the hold-out rule, see <i>Candidates</i>).</div>";
  }
  for (std::size_t i : r.missing) {
    const md::CandidateResult& c = r.candidates[i];
    o << "<div class='effect'><b>" << md::effect_id(c.effect) << "</b> at <b>" << escape(c.location)
      << "</b>, confidence " << fixed(c.confidence, 2) << "<br>" << escape(c.explanation)
      << "<br>Parameters: ";
    for (const auto& [name, v] : c.parameters) o << escape(name) << " = " << general(v, 4) << "; ";
    o << "<br>Evidence: " << escape(c.verdict) << "; hold-out residual in its lines "
      << fixed(c.signature_holdout_calibrated, 3) << " (calibrated) → "
      << fixed(c.signature_holdout_effect, 3) << " (with the effect), in all lines "
      << fixed(c.residual_holdout_calibrated, 3) << " → " << fixed(c.residual_holdout_effect, 3)
      << ".</div>";
  }

  o << "<h2>Fit</h2><table><tr><th></th>";
  for (const md::PointSpectra& s : r.spectra)
    o << "<th colspan='3'>" << escape(s.channel) << " (f1 ≤ 0.5, f2 ≤ 0.2, f3 ≤ 0.2)</th>";
  o << "</tr><tr><th></th>";
  for (std::size_t p = 0; p < r.spectra.size(); ++p) o << "<th>f1</th><th>f2</th><th>f3</th>";
  o << "</tr>" << fit_table("before calibration", r.fit_before, r.spectra)
    << fit_table("calibrated", r.fit_calibrated, r.spectra)
    << fit_table("after the named physics", r.fit_after, r.spectra) << "</table>";
  o << "<p>Residual (share of the recording's order-tracked spectral energy 0–5 kHz the simulation "
       "does not explain): before "
    << fixed(r.residual_before, 3) << ", calibrated " << fixed(r.residual_calibrated, 3)
    << ", after " << fixed(r.residual_after, 3) << ". Calibration: " << r.calibration_evaluations
    << " model evaluations.</p>";
  auto params_row = [&](const char* title, const model::DynamicsParameters& p) {
    o << "<tr><th>" << title << "</th><td>" << general(p.rayleigh_eta, 4) << "</td><td>"
      << general(p.rayleigh_zeta, 4) << "</td>";
    for (double v : p.mesh_stiffness_scale) o << "<td>" << fixed(v, 3) << "</td>";
    for (double v : p.bearing_stiffness_scale) o << "<td>" << fixed(v, 3) << "</td>";
    o << "</tr>";
  };
  o << "<table><tr><th>parameters</th><th>η [1/s]</th><th>ζ [s]</th><th colspan='3'>mesh stiffness "
       "scale</th><th "
       "colspan='3'>bearing stiffness scale</th></tr>";
  params_row("before", r.parameters_before);
  params_row("calibrated", r.parameters_calibrated);
  o << "</table>";

  o << "<h2>Mismatch after calibration</h2>";
  if (r.mismatch.empty())
    o << "<p>No significant line of the recording is left unexplained.</p>";
  else {
    o << "<table><tr><th>channel</th><th>domain</th><th>band [Hz]</th><th>strongest lines "
         "[Hz]</th><th>signature</th><th>share</th></tr>";
    for (const md::MismatchEntry& m : r.mismatch) {
      o << "<tr><td>" << escape(m.channel) << "</td><td>" << domain_name(m.domain) << "</td><td>"
        << fixed(m.band_lo_hz, 1) << "–" << fixed(m.band_hi_hz, 1) << "</td><td>";
      for (std::size_t k = 0; k < m.peaks_hz.size() && k < 6; ++k)
        o << fixed(m.peaks_hz[k], 2) << ' ';
      o << "</td><td>" << escape(m.signature) << "</td><td>" << fixed(m.share, 2) << "</td></tr>";
    }
    o << "</table>";
  }

  o << "<h2>Spectra</h2><p><small>Order-tracked amplitude spectra (the recording resampled to the "
    << escape(r.reference_shaft) << " angle, shown in Hz at the mean speed; maxima per "
    << fixed(5000.0 / static_cast<double>(std::max<std::size_t>(
                          r.spectra.empty() ? 1 : r.spectra[0].recorded.hz.size(), 1)),
             1)
    << " Hz bin); a kinematic family's mismatch is shaded and its strongest lines marked ▼ "
       "(orange); lines no family explains are marked grey.</small></p>";
  for (const md::PointSpectra& s : r.spectra) {
    std::vector<const md::MismatchEntry*> marks, env_marks;
    for (const md::MismatchEntry& m : r.mismatch) {
      if (m.channel != s.channel) continue;
      (m.domain == md::FeatureDomain::kEnvelope ? env_marks : marks).push_back(&m);
    }
    const double max_hz =
        s.recorded.hz.empty() ? 5000.0 : s.recorded.hz.back() * (1.0 + 0.5 / s.recorded.hz.size());
    o << "<h3>" << escape(s.channel) << "</h3><p><small>RMS " << general(s.stats.rms, 4)
      << ", crest factor " << fixed(s.stats.crest_factor, 2) << ", kurtosis "
      << fixed(s.stats.kurtosis, 2);
    for (const auto& [shaft, k] : s.shaft_kurtosis)
      o << "; " << escape(shaft) << " difference-signal kurtosis " << fixed(k, 2);
    o << "</small></p>";
    o << spectrum_svg(s.recorded, s.before, "simulation, before calibration", "#1565c0", marks,
                      s.channel + ": before calibration", max_hz);
    o << spectrum_svg(s.recorded, s.calibrated, "simulation, calibrated", "#2e7d32", marks,
                      s.channel + ": calibrated", max_hz);
    o << spectrum_svg(s.recorded, s.after, "simulation with the named physics", "#c62828", marks,
                      s.channel + ": after the named physics", max_hz);
    const double env_max =
        s.envelope_recorded.hz.empty() ? 1.0 : s.envelope_recorded.hz.back() * 1.001;
    o << spectrum_svg(
        s.envelope_recorded, s.envelope_after, "simulation (after)", "#c62828", env_marks,
        s.channel + ": squared-envelope spectrum of " + fixed(s.band.f_lo_hz, 0) + "–" +
            fixed(s.band.f_hi_hz, 0) + " Hz (kurtogram band, spectral kurtosis " +
            fixed(s.band.kurtosis, 2) + ")",
        env_max);
  }

  o << "<h2>Candidates</h2><p><small>The best-ranked hypotheses of the kinematic catalogue, each "
       "fitted on the first "
       "half of the recording and judged on the second. Rule: reported when, on the hold-out half, "
       "the residual in its own "
       "lines with its term is at most 75 % of the calibrated one, its lines are significant "
       "there, it improved the fitted "
       "half and does not raise the hold-out half's total residual "
       "(docs/diagnosis.md).</small></p>";
  o << "<table><tr><th>effect</th><th>location</th><th>ranking "
       "score</th><th>parameters</th><th>its lines, half A: cal → eff</th>"
       "<th>its lines, half B: cal → eff</th><th>all lines, half B: cal → eff</th><th>evidence "
       "B</th><th>confidence</th><th>verdict</th></tr>";
  for (const md::CandidateResult& c : r.candidates) {
    o << "<tr><td>" << md::effect_id(c.effect) << "</td><td>" << escape(c.location) << "</td><td>"
      << fixed(c.prior_score, 3) << "</td><td>";
    for (const auto& [name, v] : c.parameters) o << escape(name) << "=" << general(v, 3) << ' ';
    o << "</td><td>" << fixed(c.signature_fit_calibrated, 3) << " → "
      << fixed(c.signature_fit_effect, 3) << "</td><td>" << fixed(c.signature_holdout_calibrated, 3)
      << " → " << fixed(c.signature_holdout_effect, 3) << "</td><td>"
      << fixed(c.residual_holdout_calibrated, 3) << " → " << fixed(c.residual_holdout_effect, 3)
      << "</td><td>" << fixed(c.holdout_evidence, 0) << "</td><td>" << fixed(c.confidence, 2)
      << "</td><td>" << escape(c.verdict) << "</td></tr>";
  }
  o << "</table><p><small>drivetwin-diagnosis/1 · generated offline by drivetwin "
       "diagnose</small></p></body></html>\n";
  return o.str();
}

}  // namespace app::diagnosis
