// truth_synth: recordings with known missing physics for the diagnosis (issue 14), from the
// full-order dynamics model (tools/truth/README.md).
//
//   truth_synth one --out DIR --id crack-g4 --effect tooth_crack --location g4
//       [--param stiffness_loss=0.3 ...] [--conceal] [--rpm 8.33] [--torque 361747]
//       [--seconds 16] [--noise 0.05] [--drift 0.02] [--gain 1.05,0.94] [--no-tacho]
//       [--jitter 0.01] [--seed 1]
//   truth_synth list tools/truth/cases.toml --out DIR [--only ID,ID] [--seconds S]
//
// Each case: DIR/<id>/ (a drivetwin-recording/1 bundle), DIR/truth/<id>.json (what is in
// it and its concealment figures); `list` also writes DIR/cases.md and DIR/cases.json.
// The truth is kept out of the bundle directory so a diagnosis cannot read it.
#include <toml++/toml.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "truth.hpp"
#include "truth_synth_options.hpp"

namespace {

namespace fs = std::filesystem;

struct OperatingPoint {
  double rpm, torque;
};
constexpr OperatingPoint kPaper{8.33, 361747.0};
constexpr OperatingPoint kRated{14.8, 1.23e6};

model::Effect parse_effect(const std::string& id, const std::string& location,
                           const std::vector<std::pair<std::string, double>>& params) {
  const std::optional<model::EffectKind> kind = model::effect_kind(id);
  if (!kind) throw std::runtime_error("unknown effect '" + id + "'");
  model::Effect e = model::make_effect(*kind, location);
  for (const auto& [name, value] : params) {
    if (!e.set_parameter(name, value))
      throw std::runtime_error("effect '" + id + "' has no parameter '" + name + "'");
  }
  return e;
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + p.string());
}

std::string summary_row(const truth::CaseResult& r, double cpu_s) {
  char buf[512];
  std::string margins, rms;
  for (const auto& c : r.concealment) {
    char m[64];
    std::snprintf(m, sizeof m, "%s%.1f", margins.empty() ? "" : " / ", c.margin_db);
    margins += m;
    std::snprintf(m, sizeof m, "%s%.1f", rms.empty() ? "" : " / ", 100.0 * c.rms_change);
    rms += m;
  }
  std::string effect = "— (control)", where = "—", severity = "—";
  if (r.spec.effect) {
    effect = std::string(model::effect_id(r.spec.effect->kind));
    where = r.spec.effect->location;
    const auto params = model::effect_parameters(r.spec.effect->kind);
    severity.clear();
    for (std::size_t i = 0; i < params.size(); ++i) {
      if (!params[i].fitted) continue;
      char p[96];
      std::snprintf(p, sizeof p, "%s%s %.4g", severity.empty() ? "" : ", ", params[i].name,
                    r.spec.effect->parameters[i]);
      severity += p;
    }
  }
  std::snprintf(buf, sizeof buf, "| %s | %s | %s | %s | %.2f | %s | %s | %s | %s | %.0f |\n",
                r.spec.id.c_str(), effect.c_str(), where.c_str(), severity.c_str(),
                r.spec.rotor_rpm, r.spec.measurement.tacho ? "yes" : "no",
                margins.empty() ? "—" : margins.c_str(), rms.empty() ? "—" : rms.c_str(),
                r.spec.effect ? (r.concealed ? "yes" : "**no**") : "—", cpu_s);
  return buf;
}

const char* kSummaryHeader =
    "| case | effect | location | severity | rotor rpm | tacho | line vs 10th peak [dB] "
    "point1 / point2 | RMS change [%] point1 / point2 | concealed | CPU [s] |\n"
    "|---|---|---|---|---|---|---|---|---|---|\n";

truth::CaseResult run_and_write(const model::Drivetrain& d, const truth::CaseSpec& spec,
                                const fs::path& out, double& cpu_s) {
  const auto t0 = std::clock();
  truth::CaseResult r = truth::run_case(d, spec);
  cpu_s = static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
  fs::create_directories(out / "truth");
  truth::write_case_bundle(r, (out / spec.id).string());
  write_text(out / "truth" / (spec.id + ".json"), truth::truth_json(r));
  return r;
}

truth::CaseSpec case_from_toml(const toml::table& t, const toml::table& defaults,
                               const std::string& where) {
  auto get = [&](const char* key) -> const toml::node* {
    if (const toml::node* n = t.get(key)) return n;
    return defaults.get(key);
  };
  auto number = [&](const char* key, double fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    if (auto v = n->value<double>()) return *v;
    throw std::runtime_error(where + ": '" + key + "' must be a number");
  };
  auto boolean = [&](const char* key, bool fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    if (auto v = n->value<bool>()) return *v;
    throw std::runtime_error(where + ": '" + key + "' must be true or false");
  };
  auto text = [&](const char* key) -> std::string {
    const toml::node* n = get(key);
    if (!n) return "";
    if (auto v = n->value<std::string>()) return *v;
    throw std::runtime_error(where + ": '" + key + "' must be a string");
  };
  truth::CaseSpec s;
  s.id = text("id");
  if (s.id.empty()) throw std::runtime_error(where + ": 'id' is required");
  s.note = text("note");
  const std::string op = text("op");
  if (op == "paper" || op.empty()) {
    s.rotor_rpm = kPaper.rpm;
    s.torque_nm = kPaper.torque;
  } else if (op == "rated") {
    s.rotor_rpm = kRated.rpm;
    s.torque_nm = kRated.torque;
  } else {
    throw std::runtime_error(where +
                             ": 'op' must be \"paper\" or \"rated\" (or give rpm and torque)");
  }
  s.rotor_rpm = number("rpm", s.rotor_rpm);
  s.torque_nm = number("torque", s.torque_nm);
  s.seconds = number("seconds", s.seconds);
  s.settle_s = number("settle", s.settle_s);
  s.measurement.noise = number("noise", s.measurement.noise);
  s.measurement.drift = number("drift", s.measurement.drift);
  s.measurement.drift_period_s = number("drift_period", s.measurement.drift_period_s);
  s.measurement.drift_phase_rad = number("drift_phase", s.measurement.drift_phase_rad);
  s.measurement.jitter = number("jitter", s.measurement.jitter);
  s.measurement.tacho = boolean("tacho", s.measurement.tacho);
  s.offset_spread = number("offset_spread", s.offset_spread);
  s.conceal = boolean("conceal", s.conceal);
  s.seed = static_cast<std::uint64_t>(number("seed", 1.0));
  if (const toml::node* g = get("gain")) {
    const toml::array* a = g->as_array();
    if (!a || a->size() != 2 || !(*a)[0].value<double>() || !(*a)[1].value<double>())
      throw std::runtime_error(where + ": 'gain' must be [point1, point2]");
    s.measurement.gain = {*(*a)[0].value<double>(), *(*a)[1].value<double>()};
  }
  const std::string effect = text("effect");
  if (!effect.empty()) {
    std::vector<std::pair<std::string, double>> params;
    if (const toml::table* p = t.get_as<toml::table>("parameters")) {
      for (const auto& [k, v] : *p) {
        const auto x = v.value<double>();
        if (!x)
          throw std::runtime_error(where + ": parameters." + std::string(k.str()) +
                                   " must be a number");
        params.emplace_back(std::string(k.str()), *x);
      }
    }
    s.effect = parse_effect(effect, text("location"), params);
  }
  return s;
}

int run(int argc, char** argv) {
  CLI::App cli{"Recordings with known missing physics from the full-order dynamics model"};
  tools::truth_synth::OneCaseOptions one_o;
  tools::truth_synth::ListOptions list_o;
  tools::truth_synth::add_options(cli, one_o, list_o,
                                  tools::options::operating_range(model::paper_2mw()));
  CLI11_PARSE(cli, argc, argv);
  CLI::App* one = cli.get_subcommand("one");
  std::string out = *one ? one_o.out : list_o.out;
  const std::string &id = one_o.id, &effect = one_o.effect, &location = one_o.location;
  const std::vector<std::string>& params = one_o.params;
  const bool conceal = one_o.conceal, no_tacho = one_o.no_tacho;
  truth::CaseSpec spec;
  spec.rotor_rpm = one_o.rpm;
  spec.torque_nm = one_o.torque;
  spec.seconds = one_o.seconds;
  spec.measurement.noise = one_o.noise;
  spec.measurement.drift = one_o.drift;
  spec.measurement.jitter = one_o.jitter;
  spec.seed = one_o.seed;
  spec.offset_spread = one_o.offset_spread;
  const std::vector<double>& gain = one_o.gain;
  const std::string &list_file = list_o.file, &only = list_o.only;
  const double seconds_override = list_o.seconds;

  const model::Drivetrain d = model::paper_2mw();
  if (*one) {
    spec.id = id;
    spec.conceal = conceal;
    spec.measurement.tacho = !no_tacho;
    if (gain.size() == 2) spec.measurement.gain = {gain[0], gain[1]};
    if (!effect.empty()) {
      std::vector<std::pair<std::string, double>> kv;
      for (const auto& p : params) {
        const auto eq = p.find('=');
        if (eq == std::string::npos)
          throw std::runtime_error("--param: expected name=value, got '" + p + "'");
        kv.emplace_back(p.substr(0, eq), std::stod(p.substr(eq + 1)));
      }
      spec.effect = parse_effect(effect, location, kv);
    }
    double cpu = 0.0;
    const truth::CaseResult r = run_and_write(d, spec, out, cpu);
    std::printf("%s%s", kSummaryHeader, summary_row(r, cpu).c_str());
    return 0;
  }

  toml::table doc;
  try {
    doc = toml::parse_file(list_file);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << list_file << ":" << e.source().begin.line << ": " << e.description();
    throw std::runtime_error(os.str());
  }
  const toml::table empty;
  const toml::table* defaults = doc.get_as<toml::table>("defaults");
  const toml::array* cases = doc.get_as<toml::array>("case");
  if (!cases) throw std::runtime_error(list_file + ": no [[case]] tables");
  std::vector<std::string> wanted;
  for (std::size_t p = 0; p < only.size();) {
    const std::size_t q = std::min(only.find(',', p), only.size());
    wanted.push_back(only.substr(p, q - p));
    p = q + 1;
  }
  std::string table = kSummaryHeader;
  nlohmann::ordered_json index = nlohmann::ordered_json::array();
  std::size_t i = 0;
  for (const toml::node& n : *cases) {
    ++i;
    const toml::table* t = n.as_table();
    const std::string where = list_file + ": case " + std::to_string(i);
    if (!t) throw std::runtime_error(where + ": not a table");
    truth::CaseSpec s = case_from_toml(*t, defaults ? *defaults : empty, where);
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), s.id) == wanted.end()) continue;
    if (seconds_override > 0.0) s.seconds = seconds_override;
    double cpu = 0.0;
    const truth::CaseResult r = run_and_write(d, s, out, cpu);
    const std::string row = summary_row(r, cpu);
    std::printf("%s", row.c_str());
    std::fflush(stdout);
    table += row;
    index.push_back(nlohmann::ordered_json::parse(truth::truth_json(r)));
    write_text(fs::path(out) / "cases.md", table);
    write_text(fs::path(out) / "cases.json", index.dump(2) + "\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "truth_synth: %s\n", e.what());
    return 1;
  }
}
