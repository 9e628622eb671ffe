// The calibration thread: see calibration_worker.hpp.
#include "loop/calibration_worker.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <boost/crc.hpp>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "config/drivetrain_file.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "signal/speed_reference.hpp"

namespace app::loop {
namespace mc = model::calibration;
namespace {

double worst_ratio(const mc::PointIndicators& ind) {
  double w = 0.0;
  for (const mc::Indicators& i : ind)
    w = std::max(w, i.valid ? mc::worst_threshold_ratio(i) : mc::kIndicatorPenalty);
  return w;
}

}  // namespace

CalibrationWorker::CalibrationWorker(const model::Drivetrain& drivetrain,
                                     const model::DynamicsParameters& parameters,
                                     const CalibrationWorkerSettings& settings,
                                     Mailboxes& mailboxes, std::uint32_t generation)
    : drivetrain_(drivetrain),
      kinematics_(drivetrain_),
      parameters_(parameters),
      settings_(settings),
      mail_(mailboxes) {
  // The model's waveforms at ≥ 6 × the highest compared mesh harmonic at rated speed
  // (dynamics_simulator.hpp), settled for 0.5 s from the static deflection.
  const model::Kinematics k(drivetrain_);
  mc::CalibratorConfig cc;
  cc.method = settings_.method;
  cc.trust_region.max_evaluations = settings_.max_evaluations;
  // The standard space's priors are the description's values (not the last calibration's:
  // a prior that followed each calibration would regularise towards nothing); the fit
  // starts from the parameters the loop runs (start()). The paper's 8 centre on those.
  cc.space = settings_.space == WorkerSpace::kPaper ? mc::CalibrationSpace::paper(parameters_)
                                                    : mc::default_space(drivetrain_);
  model::dsp::FeatureConfig fc;
  const double rated_rpm = drivetrain_.turbine.rated_rotor_speed_rpm > 0
                               ? drivetrain_.turbine.rated_rotor_speed_rpm
                               : 20.0;
  const double top_hz =
      k.mesh_hz(k.stage_count() - 1, rated_rpm) * static_cast<double>(fc.harmonics);
  simulator_ = std::make_unique<mc::DynamicsSimulator>(drivetrain_, mc::DynamicsModel::kRom,
                                                       mc::rom_sample_rate_hz(top_hz), 0.5);
  calibrator_ = std::make_unique<mc::Calibrator>(*simulator_, drivetrain_, fc, cc);
  if (calibrator_->status() != model::dsp::DspStatus::kOk)
    throw std::runtime_error(std::string("calibration: feature configuration: ") +
                             model::dsp::to_string(calibrator_->status()));
  features_ = std::make_unique<model::dsp::FeatureExtractor>(calibrator_->feature_config());
  status_.generation = generation;
  mail_.calibration.write(status_);
}

void CalibrationWorker::emit(const CmsWindow& w, EventCode code, std::int32_t a, double b) {
  (void)events_.push(Event{w.start_ns, code, a, b});
}

void CalibrationWorker::reclaim_roms() {
  while (std::unique_ptr<model::dynamics::RomData> old = mail_.rom.reclaim()) {
    // Freed here, off the RT thread.
  }
}

void CalibrationWorker::run() {
  while (!stop_.load(std::memory_order_relaxed)) {
    reclaim_roms();
    CmsWindow* w = nullptr;
    if (!mail_.windows_full.pop(w)) {
      std::this_thread::sleep_for(std::chrono::nanoseconds(settings_.idle_poll_ns));
      continue;
    }
    process(*w);
    (void)mail_.windows_free.push(w);
  }
  reclaim_roms();
}

void CalibrationWorker::process(CmsWindow& w) {
  std::array<model::dsp::PointFeatures, kSnapshotPoints> measured{};
  // The one choice of speed reference (app/signal/speed_reference.hpp): the keyphasor's
  // pulses in the window's time base when there are enough, else SCADA speed × ratio, ...
  signal::SpeedEvidence e;
  e.hss_pulses_s.assign(w.pulses_s.begin(),
                        w.pulses_s.begin() + static_cast<std::ptrdiff_t>(w.pulse_count));
  e.min_pulses = features_->config().revolutions + 1;
  e.scada_rotor_rpm = w.rotor_speed_rpm;
  e.point1 = w.samples[0].data();
  e.samples = w.count;
  e.sample_rate_hz = w.sample_rate_hz;
  e.nominal_rotor_rpm = w.rotor_speed_rpm;
  const signal::SpeedReference speed = signal::choose_speed_reference(e, kinematics_);
  const model::dsp::SpeedReference ref{speed.pulses.empty() ? nullptr : speed.pulses.data(),
                                       speed.pulses.size(), speed.hss_hz};
  for (std::size_t p = 0; p < kSnapshotPoints; ++p) {
    const model::dsp::DspStatus s =
        features_->extract(w.samples[p].data(), w.count, w.sample_rate_hz, ref, measured[p]);
    if (s != model::dsp::DspStatus::kOk) {
      emit(w, EventCode::kCalibrationFailed, 10 + static_cast<int>(s));
      return;
    }
  }
  const mc::OperatingPoint op{w.rotor_speed_rpm, w.input_torque_nm};
  calibrator_->set_measurement(measured, op);
  mc::PointIndicators ind{};
  if (!calibrator_->evaluate(parameters_, ind)) {
    emit(w, EventCode::kCalibrationFailed, 2);
    return;
  }
  ++status_.checks;
  status_.worst_ratio = worst_ratio(ind);
  status_.fits = !mc::needs_calibration(ind);
  for (std::size_t p = 0; p < kSnapshotPoints; ++p)
    status_.f[p] = {ind[p].f1, ind[p].f2, ind[p].f3};
  mail_.calibration.write(status_);
  emit(w, EventCode::kCalibrationCheck, status_.fits ? 0 : 1, status_.worst_ratio);
  if (!status_.fits) (void)calibrate(w, measured, speed.pulses);
}

bool CalibrationWorker::calibrate(
    const CmsWindow& w, const std::array<model::dsp::PointFeatures, kSnapshotPoints>& measured,
    const std::vector<double>& pulses_s) {
  if (!calibrator_->start(parameters_, previous_)) {
    emit(w, EventCode::kCalibrationFailed, 3);
    return false;
  }
  mc::StepStatus s = mc::StepStatus::kRunning;
  while (s == mc::StepStatus::kRunning) {
    if (stop_.load(std::memory_order_relaxed)) calibrator_->cancel();
    s = calibrator_->step();
  }
  mc::CalibrationResult r;
  if (s != mc::StepStatus::kFinished || !calibrator_->read_result(r)) return false;
  ++status_.calibrations;
  const double before = status_.worst_ratio;
  const double after = worst_ratio(r.indicators);
  emit(w, EventCode::kCalibrationDone, r.fits ? 1 : 0, after);
  status_.unfit_after_calibration = !r.fits;
  bool improved = false;
  if (after < before) {
    // Build the loop's model with the new parameters here, off the RT thread.
    std::string error;
    std::unique_ptr<model::dynamics::RomData> rom =
        model::dynamics::build_rom(drivetrain_, r.parameters, settings_.rom, &error);
    if (rom) {
      previous_ = parameters_;
      parameters_ = r.parameters;
      ++status_.generation;
      // An earlier offer the loop has not taken yet comes back and is freed: the newest wins.
      (void)mail_.rom.offer(std::move(rom));
      if (!settings_.state_file.empty() &&
          !save_calibration(settings_.state_file, parameters_, status_.generation, &error))
        emit(w, EventCode::kCalibrationFailed, 5);
      status_.worst_ratio = after;
      for (std::size_t p = 0; p < kSnapshotPoints; ++p)
        status_.f[p] = {r.indicators[p].f1, r.indicators[p].f2, r.indicators[p].f3};
      improved = true;
    } else {
      emit(w, EventCode::kCalibrationFailed, 4);
    }
  }
  mail_.calibration.write(status_);
  if (!r.fits) {
    // The parameters cannot explain the mismatch: the missing-physics diagnosis's place.
    emit(w, EventCode::kUnexplainedMismatch, static_cast<int>(status_.generation), after);
    if (hook_) {
      (void)hook_(Mismatch{w, measured, r, status_.generation});
    } else if (settings_.diagnosis &&
               (!diagnosed_ || static_cast<double>(w.start_ns - last_diagnosis_ns_) * 1e-9 >=
                                   settings_.diagnosis_interval_s)) {
      diagnose(w, pulses_s);
    }
  }
  return improved;
}

void CalibrationWorker::diagnose(const CmsWindow& w, const std::vector<double>& pulses_s) {
  namespace md = model::diagnosis;
  diagnosed_ = true;
  last_diagnosis_ns_ = w.start_ns;
  if (!diagnoser_) {
    effects_ = std::make_unique<md::RomEffectSimulator>(drivetrain_, 0.5);
    diagnoser_ = std::make_unique<md::Diagnoser>(drivetrain_, *effects_);
  }
  md::DiagnosisInput in;
  in.sample_rate_hz = w.sample_rate_hz;
  for (std::size_t p = 0; p < kSnapshotPoints; ++p) in.points[p] = w.samples[p].data();
  in.samples = w.count;
  in.tacho_pulses_s = pulses_s;
  in.tacho_shaft = pulses_s.empty() ? "" : "hss";
  in.rotor_speed_rpm = w.rotor_speed_rpm;
  in.input_torque_nm = w.input_torque_nm;
  diagnoser_->start(in);
  md::DiagnosisStep s = md::DiagnosisStep::kRunning;
  md::DiagnosisSummary summary;
  while (s == md::DiagnosisStep::kRunning) {
    if (stop_.load(std::memory_order_relaxed)) diagnoser_->cancel();
    s = diagnoser_->step();
    if (diagnoser_->read_result(summary)) mail_.diagnosis.write(summary);
  }
  emit(w, EventCode::kDiagnosis, static_cast<int>(summary.reported),
       summary.reported > 0 ? summary.effects[0].confidence : 0.0);
  if (!note_) return;
  const md::DiagnosisReport& rep = diagnoser_->report();
  char line[256];
  if (s != md::DiagnosisStep::kFinished) {
    std::snprintf(line, sizeof line, "diagnosis of the window at %.3f s: %s (%s)",
                  static_cast<double>(w.start_ns) * 1e-9, md::to_string(rep.status),
                  rep.message.c_str());
    note_(line);
    return;
  }
  std::string found;
  for (std::size_t i = 0; i < summary.reported && i < summary.effects.size(); ++i) {
    const auto& e = summary.effects[i];
    char one[96];
    std::snprintf(one, sizeof one, "%s%s at %s (confidence %.2f)", found.empty() ? "" : ", ",
                  md::effect_id(e.effect), e.location.data(), e.confidence);
    found += one;
  }
  std::snprintf(line, sizeof line,
                "diagnosis of the window at %.3f s: residual %.3f before, %.3f calibrated, %.3f "
                "after; ",
                static_cast<double>(w.start_ns) * 1e-9, summary.residual_before,
                summary.residual_calibrated, summary.residual_after);
  note_(std::string(line) + (found.empty() ? "no effect of the contract explains the mismatch"
                                           : "missing physics: " + found));
}

// ---- calibrated parameters on disk --------------------------------------------------------

namespace {

// Version 2: TOML comments carry the format and the generation, then the description's own
// [dynamics] table with every calibrated quantity (the standard space moves the transmission
// errors, housing modes, per-bearing stiffnesses, damping bands… not only the paper's 8), so
// the body is valid TOML whose line numbers are the file's, and pastes into a description.
constexpr const char* kCalibrationFormat = "# drivetwin-calibration 2";

std::string serialise(const model::DynamicsParameters& p, std::uint32_t generation) {
  return std::string(kCalibrationFormat) + "\n# generation " + std::to_string(generation) + "\n" +
         app::config::dynamics_to_toml(p);
}

// Version 1 (the paper's 8 variables, "key value…" lines), read over `base`.
bool parse_version1(std::istringstream& b, model::DynamicsParameters& p, std::uint32_t& g,
                    std::string& why) {
  std::string key;
  while (b >> key) {
    if (key == "generation")
      b >> g;
    else if (key == "rayleigh_eta")
      b >> p.rayleigh_eta;
    else if (key == "rayleigh_zeta")
      b >> p.rayleigh_zeta;
    else if (key == "mesh_stiffness_scale")
      b >> p.mesh_stiffness_scale[0] >> p.mesh_stiffness_scale[1] >> p.mesh_stiffness_scale[2];
    else if (key == "bearing_stiffness_scale")
      b >> p.bearing_stiffness_scale[0] >> p.bearing_stiffness_scale[1] >>
          p.bearing_stiffness_scale[2];
    else if (key == "bearing_stiffness_fluctuation")
      b >> p.bearing_stiffness_fluctuation;
    else {
      why = "unknown key '" + key + "'";
      return false;
    }
    if (!b) {
      why = "bad value of '" + key + "'";
      return false;
    }
  }
  return true;
}

std::uint32_t crc32_of(const std::string& s) {
  boost::crc_32_type crc;
  crc.process_bytes(s.data(), s.size());
  return crc.checksum();
}

bool fail(std::string* error, std::string m) {
  if (error) *error = std::move(m);
  return false;
}

}  // namespace

bool save_calibration(const std::string& file, const model::DynamicsParameters& p,
                      std::uint32_t generation, std::string* error) {
  const std::string body = serialise(p, generation);
  char tail[32];
  std::snprintf(tail, sizeof tail, "crc %08" PRIx32 "\n", crc32_of(body));
  const std::string text = body + tail;
  const std::string tmp = file + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(error, tmp + ": cannot create");
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!written || !synced) return fail(error, tmp + ": cannot write");
  if (std::rename(tmp.c_str(), file.c_str()) != 0) return fail(error, file + ": cannot rename");
  const std::string dir = std::filesystem::path(file).parent_path().string();
  const int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return true;
}

std::optional<model::DynamicsParameters> load_calibration(const std::string& file,
                                                          const model::DynamicsParameters& base,
                                                          std::uint32_t* generation,
                                                          std::string* error) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::size_t crc_at = text.rfind("crc ");
  const auto bad = [&](const std::string& why) {
    if (error) *error = file + ": " + why + "; the description's parameters are used";
    return std::nullopt;
  };
  if (crc_at == std::string::npos) return bad("no CRC line (truncated?)");
  const std::string body = text.substr(0, crc_at);
  unsigned long stored = 0;
  if (std::sscanf(text.c_str() + crc_at, "crc %lx", &stored) != 1 ||
      static_cast<std::uint32_t>(stored) != crc32_of(body))
    return bad("CRC mismatch (corrupt)");
  model::DynamicsParameters p = base;
  std::uint32_t g = 0;
  if (body.rfind(kCalibrationFormat, 0) == 0) {
    std::istringstream b(body);
    std::string line;
    std::getline(b, line);
    std::getline(b, line);
    unsigned long gen = 0;
    if (std::sscanf(line.c_str(), "# generation %lu", &gen) != 1)
      return bad("line 2: expected '# generation N'");
    g = static_cast<std::uint32_t>(gen);
    try {
      p = app::config::parse_dynamics(body, file, base);
    } catch (const app::config::DrivetrainFileError& e) {
      return bad(e.what());
    }
  } else {
    std::istringstream b(body);
    std::string magic;
    int version = 0;
    b >> magic >> version;
    if (magic != "drivetwin-calibration" || version != 1) return bad("not a calibration file");
    std::string why;
    if (!parse_version1(b, p, g, why)) return bad(why);
  }
  if (generation) *generation = g;
  return p;
}

}  // namespace app::loop
