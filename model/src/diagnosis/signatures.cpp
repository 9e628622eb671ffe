#include "model/diagnosis/signatures.hpp"

#include <algorithm>
#include <cmath>

namespace model::diagnosis {

namespace {
constexpr const char* kEffectIds[kEffectCount] = {"tooth_crack",
                                                  "gear_eccentricity",
                                                  "bearing_outer_race_defect",
                                                  "bearing_inner_race_defect",
                                                  "bearing_ball_defect",
                                                  "shaft_unbalance",
                                                  "shaft_misalignment",
                                                  "planet_pass_modulation",
                                                  "housing_resonance"};

std::string pretty(std::string id) {
  std::replace(id.begin(), id.end(), '_', '-');
  return id;
}
}  // namespace

const char* effect_id(Effect effect) { return kEffectIds[static_cast<std::size_t>(effect)]; }

std::optional<Effect> effect_from_id(std::string_view id) {
  for (std::size_t i = 0; i < kEffectCount; ++i)
    if (id == kEffectIds[i]) return static_cast<Effect>(i);
  return std::nullopt;
}

const PartRate* Catalogue::shaft(std::string_view id) const {
  for (const PartRate& s : shafts)
    if (s.id == id) return &s;
  return nullptr;
}

namespace {

struct Builder {
  const Drivetrain& d;
  const CatalogueConfig& cfg;
  Catalogue& cat;

  std::size_t family(Domain domain, std::string text, double spacing, std::vector<double> orders,
                     std::vector<double> weights, double tolerance) {
    for (std::size_t i = 0; i < cat.families.size(); ++i)
      if (cat.families[i].text == text) return i;
    Family f;
    f.domain = domain;
    f.text = std::move(text);
    f.spacing_order = spacing;
    for (std::size_t i = 0; i < orders.size(); ++i) {
      if (orders[i] > 0.0 && orders[i] <= cfg.max_order) {
        f.orders.push_back(orders[i]);
        f.weights.push_back(weights[i]);
      }
    }
    f.tolerance = tolerance;
    cat.families.push_back(std::move(f));
    return cat.families.size() - 1;
  }

  void add(Hypothesis h, const std::vector<SignatureLine>& lines) {
    for (const SignatureLine& l : lines)
      if (l.order > 0.0 && l.order <= cfg.max_order) h.lines.push_back(l);
    if (h.lines.empty() && h.effect != Effect::kHousingResonance) return;
    cat.hypotheses.push_back(std::move(h));
  }

  // h·mesh ± k·rate for h = 1..H, k = 1..K, plus k·rate for k = 1..K_low (weight w_low).
  std::vector<SignatureLine> sidebands(double mesh, double rate, int k_max, int low, double w_low) {
    std::vector<SignatureLine> out;
    for (int h = 1; h <= cfg.mesh_harmonics; ++h)
      for (int k = 1; k <= k_max; ++k) {
        out.push_back({h * mesh - k * rate, 1.0});
        out.push_back({h * mesh + k * rate, 1.0});
      }
    for (int k = 1; k <= low; ++k) out.push_back({k * rate, w_low});
    return out;
  }

  std::size_t sideband_family(const std::string& stage, double mesh, double rate,
                              const std::string& rate_text) {
    std::vector<double> o, w;
    for (const SignatureLine& l : sidebands(mesh, rate, cfg.crack_sidebands, 0, 0.0)) {
      o.push_back(l.order);
      w.push_back(l.weight);
    }
    return family(Domain::kSpectrum,
                  "sidebands of the " + pretty(stage) + " mesh spaced at " + rate_text, rate, o, w,
                  0.0);
  }

  std::size_t harmonic_family(const std::string& shaft, double rate) {
    return family(Domain::kSpectrum, "harmonics of the " + shaft + " speed", rate,
                  {rate, 2 * rate, 3 * rate}, {1.0, 1.0, 0.5}, 0.0);
  }
};

}  // namespace

Catalogue build_catalogue(const Drivetrain& d, const std::vector<std::string>& sensor_locations,
                          const CatalogueConfig& cfg) {
  Catalogue cat;
  const Kinematics k(d);
  constexpr double kRpm = 60.0;  // rotor at 1 Hz: shaft_hz is then the ratio to the rotor
  // Reference: the fastest shaft of the description.
  double ref = 0.0;
  for (const Shaft& s : d.shafts) {
    const auto f = k.shaft_hz(s.id, kRpm);
    if (f && *f > ref) {
      ref = *f;
      cat.reference_shaft = s.id;
    }
  }
  if (!(ref > 0.0)) return cat;
  cat.reference_per_rotor = ref;
  for (const Shaft& s : d.shafts) {
    if (const auto f = k.shaft_hz(s.id, kRpm)) cat.shafts.push_back({s.id, *f / ref});
  }
  const bool has_planetary = std::any_of(d.stages.begin(), d.stages.end(), [](const GearStage& s) {
    return s.type == StageType::kPlanetary;
  });
  if (has_planetary) cat.shafts.push_back({"planet", *k.shaft_hz("planet", kRpm) / ref});

  Builder b{d, cfg, cat};
  for (std::size_t i = 0; i < k.stage_count() && i < d.stages.size(); ++i) {
    const GearStage& stage = d.stages[i];
    const double mesh = k.mesh_hz(i, kRpm) / ref;
    cat.meshes.push_back({stage.id, mesh});
    const double f_in = k.stage_input_hz(i, kRpm) / ref;
    if (stage.type == StageType::kPlanetary) {
      const double carrier = f_in;
      const double sun_abs = f_in * k.stage_ratio(i);
      const double sun_rel = sun_abs - carrier;
      const double planet_rel = *k.shaft_hz("planet", kRpm) / ref;
      const double pass = k.planet_pass_hz(i, kRpm) / ref;
      const int n_planets = std::max(1, stage.planets);
      const std::string sun_id = stage.gears.size() > 0 ? stage.gears[0] : "sun";
      const std::string planet_id = stage.gears.size() > 1 ? stage.gears[1] : "planet";
      const std::string ring_id = stage.gears.size() > 2 ? stage.gears[2] : "ring";
      // Sun: a tooth meets the planets N times per revolution relative to the carrier.
      const std::size_t f_sun =
          b.sideband_family(stage.id, mesh, sun_rel, "the sun's speed relative to the carrier");
      b.sideband_family(stage.id, mesh, n_planets * sun_rel,
                        "the sun's tooth-meets-planet rate (" + std::to_string(n_planets) +
                            " × its speed relative to the carrier)");
      {
        Hypothesis h{
            Effect::kToothCrack,
            sun_id,
            Domain::kSpectrum,
            {},
            0.0,
            sun_rel,
            f_sun,
            stage.output_shaft,
            "loss of mesh stiffness while the cracked sun tooth meets a planet: an impulsive "
            "modulation of the " +
                pretty(stage.id) + " mesh once per sun revolution relative to the carrier"};
        auto lines = b.sidebands(mesh, sun_rel, cfg.crack_sidebands, 3, 0.5);
        for (int hh = 1; hh <= cfg.mesh_harmonics; ++hh)
          for (int kk = 1; kk <= 2; ++kk) {
            lines.push_back({hh * mesh - kk * n_planets * sun_rel, 1.0});
            lines.push_back({hh * mesh + kk * n_planets * sun_rel, 1.0});
          }
        b.add(h, lines);
        Hypothesis e{Effect::kGearEccentricity,
                     sun_id,
                     Domain::kSpectrum,
                     {},
                     0.0,
                     sun_rel,
                     f_sun,
                     stage.output_shaft,
                     "run-out of the sun: transmission error and centre distance of the " +
                         pretty(stage.id) +
                         " mesh modulated once per sun revolution relative to the carrier"};
        b.add(e, b.sidebands(mesh, sun_rel, cfg.eccentricity_sidebands, 1, 1.0));
      }
      {
        const std::size_t f_planet = b.sideband_family(
            stage.id, mesh, planet_rel, "the planets' speed relative to the carrier");
        Hypothesis h{
            Effect::kToothCrack,
            planet_id,
            Domain::kSpectrum,
            {},
            0.0,
            planet_rel,
            f_planet,
            "",
            "loss of mesh stiffness while the cracked planet tooth is in contact with the sun or "
            "the ring: an impulsive modulation of the " +
                pretty(stage.id) + " mesh once per planet revolution"};
        b.add(h, b.sidebands(mesh, planet_rel, cfg.crack_sidebands, 2, 0.5));
      }
      {
        std::vector<double> o, w;
        for (int hh = 1; hh <= cfg.mesh_harmonics; ++hh)
          for (int kk = 1; kk <= 3; ++kk) {
            o.push_back(hh * mesh - kk * pass);
            o.push_back(hh * mesh + kk * pass);
            w.push_back(1.0);
            w.push_back(1.0);
          }
        const std::size_t f_pp = b.family(
            Domain::kSpectrum,
            "sidebands of the " + pretty(stage.id) + " mesh spaced at the planet-pass frequency",
            pass, o, w, 0.0);
        Hypothesis h{
            Effect::kPlanetPassModulation,
            ring_id,
            Domain::kSpectrum,
            {},
            0.0,
            pass,
            f_pp,
            "",
            "the path from each planet's mesh to the sensor changes as the carrier turns: the " +
                pretty(stage.id) + " mesh modulated at the planet-pass frequency"};
        std::vector<SignatureLine> lines;
        for (std::size_t j = 0; j < o.size(); ++j) lines.push_back({o[j], w[j]});
        for (int kk = 1; kk <= 2; ++kk) lines.push_back({kk * pass, 0.5});
        b.add(h, lines);
      }
    } else {
      for (const std::string& gear_id : stage.gears) {
        const Gear* g = d.gear(gear_id);
        if (g == nullptr) continue;
        const auto f = k.shaft_hz(g->shaft, kRpm);
        if (!f) continue;
        const double rate = *f / ref;
        const std::size_t fam =
            b.sideband_family(stage.id, mesh, rate, "the " + g->shaft + " speed");
        Hypothesis h{Effect::kToothCrack,
                     gear_id,
                     Domain::kSpectrum,
                     {},
                     0.0,
                     rate,
                     fam,
                     g->shaft,
                     "loss of mesh stiffness while the cracked tooth of " + gear_id +
                         " is in contact: an "
                         "impulsive modulation of the " +
                         pretty(stage.id) + " mesh once per " + g->shaft + " revolution"};
        b.add(h, b.sidebands(mesh, rate, cfg.crack_sidebands, 3, 0.5));
        Hypothesis e{Effect::kGearEccentricity,
                     gear_id,
                     Domain::kSpectrum,
                     {},
                     0.0,
                     rate,
                     fam,
                     g->shaft,
                     "run-out of " + gear_id + ": transmission error and centre distance of the " +
                         pretty(stage.id) + " mesh modulated once per " + g->shaft + " revolution"};
        b.add(e, b.sidebands(mesh, rate, cfg.eccentricity_sidebands, 1, 1.0));
      }
    }
  }

  // Envelope lines at a shaft's harmonics: an impact once per revolution (a cracked tooth,
  // a rub), named so in the envelope; no hypothesis of their own (the crack's evidence is
  // its sidebands and its shaft's synchronous average).
  for (const PartRate& s : std::vector<PartRate>(cat.shafts)) {
    if (s.id == "planet") continue;
    std::vector<double> o, w;
    for (int n = 1; n <= 10; ++n) {
      o.push_back(n * s.order);
      w.push_back(1.0);
    }
    b.family(Domain::kEnvelope,
             "harmonics of the " + s.id + " speed: an impact once per " + s.id + " revolution",
             s.order, o, w, 0.0);
  }

  // Shafts: unbalance and misalignment on every shaft but the rotor's (the input of the
  // first stage), where a once-per-revolution force is lost in the rotor's own loads.
  const std::string rotor_shaft = d.stages.empty() ? "" : d.stages.front().input_shaft;
  for (const PartRate& s : std::vector<PartRate>(cat.shafts)) {
    if (s.id == "planet" || s.id == rotor_shaft) continue;
    const std::size_t fam = b.harmonic_family(s.id, s.order);
    b.add({Effect::kShaftUnbalance,
           s.id,
           Domain::kSpectrum,
           {},
           0.0,
           s.order,
           fam,
           s.id,
           "a rotating force once per " + s.id + " revolution from a mass off the axis"},
          {{s.order, 1.0}});
    b.add({Effect::kShaftMisalignment,
           s.id,
           Domain::kSpectrum,
           {},
           0.0,
           s.order,
           fam,
           s.id,
           "coupling forces at twice (and once) the " + s.id + " speed from misaligned shafts"},
          {{2 * s.order, 1.0}, {s.order, 0.5}, {3 * s.order, 0.3}});
  }

  // Bearings: defect frequencies (with slip) in the envelope.
  for (const Bearing& br : d.bearings) {
    const auto f = k.bearing_hz(br.id, kRpm);
    if (!f) continue;
    const double fr = f->shaft_hz / ref, bpfo = f->bpfo_hz / ref, bpfi = f->bpfi_hz / ref;
    const double bsf2 = 2.0 * f->bsf_hz / ref, ftf = f->ftf_hz / ref;
    const int kmax = cfg.bearing_harmonics;
    {
      std::vector<double> o, w;
      std::vector<SignatureLine> lines;
      for (int kk = 1; kk <= kmax; ++kk) {
        o.push_back(kk * bpfo);
        w.push_back(1.0);
        lines.push_back({kk * bpfo, 1.0});
      }
      const std::size_t fam =
          b.family(Domain::kEnvelope, br.id + " outer-race defect frequency (BPFO) and harmonics",
                   bpfo, o, w, cfg.slip);
      b.add({Effect::kBearingOuterRaceDefect,
             br.id,
             Domain::kEnvelope,
             {},
             cfg.slip,
             bpfo,
             fam,
             "",
             "impacts as each rolling element passes a defect on the outer race of " + br.id +
                 ", ringing the housing"},
            lines);
    }
    {
      std::vector<double> o, w;
      std::vector<SignatureLine> lines;
      for (int kk = 1; kk <= kmax; ++kk)
        for (int j = -2; j <= 2; ++j) {
          const double wt = j == 0 ? 1.0 : (std::abs(j) == 1 ? 0.7 : 0.4);
          o.push_back(kk * bpfi + j * fr);
          w.push_back(wt);
          lines.push_back({kk * bpfi + j * fr, wt});
        }
      const std::size_t fam =
          b.family(Domain::kEnvelope,
                   br.id + " inner-race defect frequency (BPFI) with sidebands at the shaft speed",
                   bpfi, o, w, cfg.slip);
      b.add({Effect::kBearingInnerRaceDefect,
             br.id,
             Domain::kEnvelope,
             {},
             cfg.slip,
             bpfi,
             fam,
             "",
             "impacts as each rolling element passes a defect on the inner race of " + br.id +
                 ", modulated by the load zone once per shaft revolution"},
            lines);
    }
    {
      std::vector<double> o, w;
      std::vector<SignatureLine> lines;
      for (int kk = 1; kk <= std::min(kmax, 2); ++kk)
        for (int j = -1; j <= 1; ++j) {
          const double wt = j == 0 ? 1.0 : 0.6;
          o.push_back(kk * bsf2 + j * ftf);
          w.push_back(wt);
          lines.push_back({kk * bsf2 + j * ftf, wt});
        }
      const std::size_t fam = b.family(
          Domain::kEnvelope,
          br.id + " rolling-element defect frequency (2 × BSF) with sidebands at the cage speed",
          bsf2, o, w, cfg.slip);
      b.add({Effect::kBearingBallDefect,
             br.id,
             Domain::kEnvelope,
             {},
             cfg.slip,
             bsf2,
             fam,
             "",
             "impacts twice per spin of a rolling element of " + br.id +
                 " with a defect, modulated as the cage carries it through the load zone"},
            lines);
    }
  }

  // The same defect frequencies in the waveform's own order spectrum. An impact lasting a
  // large part of its period (a slow shaft, a wide defect: a half sine of several
  // milliseconds) puts its energy in the defect lines themselves, below the band where a
  // short impact rings the housing; cepstral prewhitening flattens such lines with the
  // noise, and the kurtogram finds nothing impulsive (Randall & Antoni, MSSP 25 (2011) §2:
  // the raw spectrum shows the harmonics of a defect when they are not masked). Read off
  // every gear and shaft line (spectrum_exclusions()).
  const std::size_t envelope_end = cat.hypotheses.size();
  for (std::size_t i = 0; i < envelope_end; ++i) {
    if (!is_bearing(cat.hypotheses[i].effect)) continue;
    // Only on a shaft turning at least cfg.bearing_spectrum_min_shaft_order: the lines of a
    // slower one's defect fall among the planetary stage's dense comb (carrier, planet and
    // sun-shaft harmonics a few lines apart), where no line can be told from it.
    const Bearing* br = d.bearing(cat.hypotheses[i].location);
    const PartRate* sh = br != nullptr ? cat.shaft(br->shaft) : nullptr;
    if (sh == nullptr || sh->order < cfg.bearing_spectrum_min_shaft_order) continue;
    Hypothesis h = cat.hypotheses[i];
    h.domain = Domain::kSpectrum;
    // Its first group of lines (the defect rate and its modulation sidebands), repeated at
    // every harmonic of the rate up to the top of the synchronous comb: where the impacts'
    // energy lies in the raw spectrum depends on the pulse's length and on the structure's
    // response, not on the first three harmonics the envelope reads.
    const double rate = h.rate_order;
    std::vector<SignatureLine> first, lines;
    for (const SignatureLine& l : h.lines)
      if (std::abs(l.order - rate) < 0.5 * rate) first.push_back(l);
    const int k_top =
        std::clamp(static_cast<int>(std::floor(cfg.bearing_spectrum_top_order / rate)),
                   cfg.bearing_harmonics, cfg.bearing_spectrum_harmonics);
    for (int kk = 1; kk <= k_top; ++kk)
      for (const SignatureLine& l : first) lines.push_back({l.order + (kk - 1) * rate, l.weight});
    h.lines.clear();
    b.add(std::move(h), lines);
  }

  // Housing resonances between a measured bearing and its sensor.
  for (const std::string& loc : sensor_locations) {
    if (d.bearing(loc) == nullptr) continue;
    const std::size_t fam = b.family(
        Domain::kSpectrum, "lines amplified in one band at the sensor on " + loc, 0.0, {}, {}, 0.0);
    b.add({Effect::kHousingResonance,
           loc,
           Domain::kSpectrum,
           {},
           0.0,
           0.0,
           fam,
           "",
           "a structural resonance of the housing between " + loc +
               " and its sensor amplifying every line in its band"},
          {});
  }
  return cat;
}

}  // namespace model::diagnosis
