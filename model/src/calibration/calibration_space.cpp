#include "model/calibration/calibration_space.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>

namespace model::calibration {

namespace {
constexpr double kLn2 = 0.6931471805599453;
constexpr double kLn3 = 1.0986122886681098;

void copy_text(std::array<char, 40>& out, const char* text) {
  std::snprintf(out.data(), out.size(), "%s", text);
}
}  // namespace

void CalibrationSpace::add(ParameterField f, std::size_t index, bool logarithmic, double sd,
                           double lower, double upper, const char* name, const char* unit) {
  if (count_ >= kMaxCalibrationVariables) {
    ++overflow_;
    return;
  }
  CalibrationVariable& v = vars_[count_];
  v.field = f;
  v.index = static_cast<std::uint8_t>(index);
  v.logarithmic = logarithmic;
  v.prior_sd = sd;
  v.lower = lower;
  v.upper = upper;
  copy_text(v.name, name);
  std::snprintf(v.unit.data(), v.unit.size(), "%s", unit);
  const double p = get(prior_, v);
  prior_u_[count_] =
      logarithmic ? std::log(std::clamp(p, lower, upper)) : std::clamp(p, lower, upper);
  ++count_;
}

CalibrationSpace CalibrationSpace::with_sun_shaft_torsion() const {
  CalibrationSpace s = *this;
  for (std::size_t i = 0; i < count_; ++i)
    if (vars_[i].field == ParameterField::kSunShaftTorsion) return s;
  const double v = prior_.sun_shaft_torsion_scale;
  s.add(ParameterField::kSunShaftTorsion, 0, true, kLn3, v / 9.0, v * 9.0,
        "sun_shaft_torsion_scale", "-");
  return s;
}

CalibrationSpace CalibrationSpace::paper(const DynamicsParameters& prior) {
  CalibrationSpace s;
  s.prior_ = prior;
  const double eta = prior.rayleigh_eta > 0.0 ? prior.rayleigh_eta : 5.0;
  const double zeta = prior.rayleigh_zeta > 0.0 ? prior.rayleigh_zeta : 1e-5;
  s.prior_.rayleigh_eta = eta;
  s.prior_.rayleigh_zeta = zeta;
  s.add(ParameterField::kRayleighEta, 0, true, kLn2, 0.5, 50.0, "rayleigh_eta", "1/s");
  s.add(ParameterField::kRayleighZeta, 0, true, kLn2, 1e-6, 1e-4, "rayleigh_zeta", "s");
  static constexpr const char* kStage[3] = {
      "mesh_stiffness_scale.stage1", "mesh_stiffness_scale.stage2", "mesh_stiffness_scale.stage3"};
  for (std::size_t i = 0; i < 3; ++i)
    s.add(ParameterField::kMeshScale, i, true, 0.25, 0.5, 2.0, kStage[i], "-");
  static constexpr const char* kShaft[3] = {"bearing_stiffness_scale.sun_shaft",
                                            "bearing_stiffness_scale.ims",
                                            "bearing_stiffness_scale.hss"};
  for (std::size_t i = 0; i < 3; ++i)
    s.add(ParameterField::kBearingShaftScale, i, true, 0.25, 0.5, 2.0, kShaft[i], "-");
  return s;
}

CalibrationSpace CalibrationSpace::standard(
    const DynamicsParameters& prior,
    const std::array<bool, kHousingSeatBearings>& unmeasured_seats) {
  CalibrationSpace s;
  s.prior_ = prior;
  const double eta = prior.rayleigh_eta > 0.0 ? prior.rayleigh_eta : 5.0;
  const double zeta = prior.rayleigh_zeta > 0.0 ? prior.rayleigh_zeta : 1e-5;
  s.prior_.rayleigh_eta = eta;
  s.prior_.rayleigh_zeta = zeta;
  char name[40];
  s.add(ParameterField::kRayleighEta, 0, true, kLn2, eta / 10.0, eta * 10.0, "rayleigh_eta", "1/s");
  s.add(ParameterField::kRayleighZeta, 0, true, kLn2, zeta / 10.0, zeta * 10.0, "rayleigh_zeta",
        "s");
  for (std::size_t k = 0; k < kDampingKnots; ++k) {
    const double f = prior.damping_band_factor[k];
    std::snprintf(name, sizeof name, "damping_band_factor.%.0fHz", kDampingKnotsHz[k]);
    s.add(ParameterField::kDampingBand, k, true, kLn2, f / 5.0, f * 5.0, name, "-");
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const double v = prior.mesh_stiffness_scale[i];
    std::snprintf(name, sizeof name, "mesh_stiffness_scale.stage%zu", i + 1);
    s.add(ParameterField::kMeshScale, i, true, 0.25, v / 2.0, v * 2.0, name, "-");
  }
  for (std::size_t i = 0; i < 3; ++i) {
    std::snprintf(name, sizeof name, "mesh_tip_relief.stage%zu", i + 1);
    s.add(ParameterField::kMeshTipRelief, i, false, 0.35, 0.0, 1.0, name, "-");
  }
  for (std::size_t i = 0; i < 6; ++i) {
    const double v = prior.bearing_stiffness_factor[i];
    std::snprintf(name, sizeof name, "bearing_stiffness.b%zu", i + 1);
    s.add(ParameterField::kBearingFactor, i, true, kLn2, v / 4.0, v * 4.0, name, "-");
  }
  // The derived varying compliance (model/dynamics/bearing_compliance.hpp): its amplitude at
  // zero operating clearance is ~1e-4 of the stiffness for 14–22 rollers; an unknown clearance
  // narrows the load zone and raises it — clearance/2 at 0.5 of the load deflection ×10–100,
  // at 0.75 ×100 (1–3 %) — so σ = ln 10 and bounds ×/÷ 100 (2 σ, as every variable here);
  // ÷ 100 is "no fluctuation" (a preloaded bearing), not a bound.
  if (const double v = prior.bearing_compliance_scale; v > 0.0) {
    s.add(ParameterField::kBearingComplianceScale, 0, true, std::log(10.0), v / 100.0, v * 100.0,
          "bearing_compliance_scale", "-");
    s.vars_[s.count_ - 1].lower_is_zero = true;
  }
  if (const double v = prior.bearing_stiffness_fluctuation; v > 0.0) {
    s.add(ParameterField::kBearingFluctuation, 0, true, kLn2, v / 10.0, std::min(1.0, v * 10.0),
          "bearing_stiffness_fluctuation", "-");
  }
  for (std::size_t st = 0; st < kTransmissionErrorStages; ++st) {
    for (std::size_t h = 1; h <= kTransmissionErrorHarmonics; ++h) {
      const std::size_t i = st * kTransmissionErrorHarmonics + h - 1;
      const double v = prior.transmission_error_m[i];
      if (!(v > 0.0)) continue;  // no prior error on this harmonic: not calibrated
      std::snprintf(name, sizeof name, "transmission_error.stage%zu.h%zu", st + 1, h);
      s.add(ParameterField::kTransmissionError, i, true, kLn3, v / 50.0, v * 50.0, name, "m");
      s.vars_[s.count_ - 1].lower_is_zero = true;
    }
  }
  for (std::size_t st = 0; st < kTransmissionErrorStages; ++st) {
    for (std::size_t h = 1; h <= kTransmissionErrorHarmonics; ++h) {
      const std::size_t i = st * kTransmissionErrorHarmonics + h - 1;
      if (!(prior.transmission_error_m[i] > 0.0)) continue;
      std::snprintf(name, sizeof name, "transmission_error.stage%zu.h%zu.phase", st + 1, h);
      // Bounds two turns wide: the phase is periodic, so a bound is never a physical limit.
      s.add(ParameterField::kTransmissionErrorPhase, i, false, std::numbers::pi / std::sqrt(3.0),
            -2.0 * std::numbers::pi, 2.0 * std::numbers::pi, name, "rad");
    }
  }
  for (std::size_t p = 0; p < kHousingPoints; ++p) {
    for (std::size_t k = 0; k < kHousingModesPerPoint; ++k) {
      const std::size_t i = p * kHousingModesPerPoint + k;
      const double f = prior.housing_frequency_hz[i];
      if (!(f > 0.0)) continue;
      const double m = prior.housing_modal_mass_kg[i];
      const double xi =
          prior.housing_damping_ratio[i] > 0.0 ? prior.housing_damping_ratio[i] : 0.03;
      s.prior_.housing_damping_ratio[i] = xi;
      const double pp = prior.housing_participation[i] > 0.0 ? prior.housing_participation[i] : 1.0;
      s.prior_.housing_participation[i] = pp;
      std::snprintf(name, sizeof name, "housing.point%zu.mode%zu.frequency", p + 1, k + 1);
      s.add(ParameterField::kHousingFrequency, i, true, 0.35, f / 2.0, f * 2.0, name, "Hz");
      std::snprintf(name, sizeof name, "housing.point%zu.mode%zu.damping", p + 1, k + 1);
      s.add(ParameterField::kHousingDamping, i, true, kLn2, 0.005, 0.2, name, "-");
      std::snprintf(name, sizeof name, "housing.point%zu.mode%zu.mass", p + 1, k + 1);
      s.add(ParameterField::kHousingMass, i, true, kLn2, m / 4.0, m * 4.0, name, "kg");
      std::snprintf(name, sizeof name, "housing.point%zu.mode%zu.participation", p + 1, k + 1);
      s.add(ParameterField::kHousingParticipation, i, true, 0.5, pp / 4.0, pp * 4.0, name, "-");
      std::snprintf(name, sizeof name, "housing.point%zu.mode%zu.cross", p + 1, k + 1);
      s.add(ParameterField::kHousingCross, i, false, 0.5, -1.0, 1.0, name, "-");
    }
  }
  // One variable per (unmeasured seat, point): the three modes of a point share the seat's
  // participation (the quasi-static picture of a seat on the same wall as the point's own; a
  // point's 7–9 resolved tones do not determine three per seat and point — 12 free per-mode
  // variables calibrated 2 of Table 3's 5 recordings, these 4 calibrate 4, docs/calibration.md).
  constexpr std::size_t kModes = kHousingPoints * kHousingModesPerPoint;
  for (std::size_t b = 0; b < kHousingSeatBearings; ++b) {
    if (!unmeasured_seats[b]) continue;
    for (std::size_t p = 0; p < kHousingPoints; ++p) {
      if (!(prior.housing_frequency_hz[p * kHousingModesPerPoint] > 0.0)) continue;
      std::snprintf(name, sizeof name, "housing.b%zu.point%zu", b + kHousingSeatFirstBearing + 1,
                    p + 1);
      s.add(ParameterField::kHousingSeat, b * kModes + p * kHousingModesPerPoint, false, 0.5, -1.0,
            1.0, name, "-");
    }
  }
  // The gearbox body on its mounts (DynamicsParameters::gearbox_body_mass_kg): what the
  // housing's low-frequency path from every bearing to both sensors is made of. Wide priors:
  // neither the box's mass at the seats nor its supports are published for a real turbine.
  if (const double m = prior.gearbox_body_mass_kg; m > 0.0) {
    const double k = prior.gearbox_mount_stiffness_n_m;
    const double xi =
        prior.gearbox_mount_damping_ratio > 0.0 ? prior.gearbox_mount_damping_ratio : 0.05;
    s.prior_.gearbox_mount_damping_ratio = xi;
    s.add(ParameterField::kGearboxBodyMass, 0, true, kLn2, m / 4.0, m * 4.0, "gearbox_body.mass",
          "kg");
    s.add(ParameterField::kGearboxMountStiffness, 0, true, kLn3, k / 20.0, k * 20.0,
          "gearbox_body.mount_stiffness", "N/m");
    s.add(ParameterField::kGearboxMountDamping, 0, true, kLn2, 0.01, 0.3,
          "gearbox_body.mount_damping", "-");
  }
  return s;
}

double CalibrationSpace::get(const DynamicsParameters& p, const CalibrationVariable& v) {
  const std::size_t i = v.index;
  switch (v.field) {
    case ParameterField::kRayleighEta:
      return p.rayleigh_eta;
    case ParameterField::kRayleighZeta:
      return p.rayleigh_zeta;
    case ParameterField::kDampingBand:
      return p.damping_band_factor[i];
    case ParameterField::kMeshScale:
      return p.mesh_stiffness_scale[i];
    case ParameterField::kMeshTipRelief:
      return p.mesh_tip_relief[i];
    case ParameterField::kBearingFluctuation:
      return p.bearing_stiffness_fluctuation;
    case ParameterField::kSunShaftTorsion:
      return p.sun_shaft_torsion_scale;
    case ParameterField::kBearingComplianceScale:
      return p.bearing_compliance_scale;
    case ParameterField::kBearingShaftScale:
      return p.bearing_stiffness_scale[i];
    case ParameterField::kBearingFactor:
      return p.bearing_stiffness_factor[i];
    case ParameterField::kTransmissionError:
      return p.transmission_error_m[i];
    case ParameterField::kTransmissionErrorPhase:
      return p.transmission_error_phase_rad[i];
    case ParameterField::kHousingFrequency:
      return p.housing_frequency_hz[i];
    case ParameterField::kHousingDamping:
      return p.housing_damping_ratio[i];
    case ParameterField::kHousingMass:
      return p.housing_modal_mass_kg[i];
    case ParameterField::kHousingParticipation:
      return p.housing_participation[i];
    case ParameterField::kHousingCross:
      return p.housing_cross_participation[i];
    case ParameterField::kHousingSeat: {  // the mean over the point's modes (set() ties them)
      double sum = 0.0;
      for (std::size_t k = 0; k < kHousingModesPerPoint; ++k)
        sum += p.housing_seat_participation[i + k];
      return sum / static_cast<double>(kHousingModesPerPoint);
    }
    case ParameterField::kGearboxBodyMass:
      return p.gearbox_body_mass_kg;
    case ParameterField::kGearboxMountStiffness:
      return p.gearbox_mount_stiffness_n_m;
    case ParameterField::kGearboxMountDamping:
      return p.gearbox_mount_damping_ratio;
  }
  return 0.0;
}

void CalibrationSpace::set(DynamicsParameters& p, const CalibrationVariable& v, double value) {
  const std::size_t i = v.index;
  switch (v.field) {
    case ParameterField::kRayleighEta:
      p.rayleigh_eta = value;
      break;
    case ParameterField::kRayleighZeta:
      p.rayleigh_zeta = value;
      break;
    case ParameterField::kDampingBand:
      p.damping_band_factor[i] = value;
      break;
    case ParameterField::kMeshScale:
      p.mesh_stiffness_scale[i] = value;
      break;
    case ParameterField::kMeshTipRelief:
      p.mesh_tip_relief[i] = value;
      break;
    case ParameterField::kBearingFluctuation:
      p.bearing_stiffness_fluctuation = value;
      break;
    case ParameterField::kBearingComplianceScale:
      p.bearing_compliance_scale = value;
      break;
    case ParameterField::kSunShaftTorsion:
      p.sun_shaft_torsion_scale = value;
      break;
    case ParameterField::kBearingShaftScale:
      p.bearing_stiffness_scale[i] = value;
      break;
    case ParameterField::kBearingFactor:
      p.bearing_stiffness_factor[i] = value;
      break;
    case ParameterField::kTransmissionError:
      p.transmission_error_m[i] = value;
      break;
    case ParameterField::kTransmissionErrorPhase:
      p.transmission_error_phase_rad[i] = value;
      break;
    case ParameterField::kHousingFrequency:
      p.housing_frequency_hz[i] = value;
      break;
    case ParameterField::kHousingDamping:
      p.housing_damping_ratio[i] = value;
      break;
    case ParameterField::kHousingMass:
      p.housing_modal_mass_kg[i] = value;
      break;
    case ParameterField::kHousingParticipation:
      p.housing_participation[i] = value;
      break;
    case ParameterField::kHousingCross:
      p.housing_cross_participation[i] = value;
      break;
    case ParameterField::kHousingSeat:
      for (std::size_t k = 0; k < kHousingModesPerPoint; ++k)
        p.housing_seat_participation[i + k] = value;
      break;
    case ParameterField::kGearboxBodyMass:
      p.gearbox_body_mass_kg = value;
      break;
    case ParameterField::kGearboxMountStiffness:
      p.gearbox_mount_stiffness_n_m = value;
      break;
    case ParameterField::kGearboxMountDamping:
      p.gearbox_mount_damping_ratio = value;
      break;
  }
}

double CalibrationSpace::whiten(std::size_t i, double v) const {
  const CalibrationVariable& var = vars_[i];
  const double u = var.logarithmic ? std::log(std::max(v, 1e-300)) : v;
  return (u - prior_u_[i]) / var.prior_sd;
}

double CalibrationSpace::value(std::size_t i, double z) const {
  const CalibrationVariable& var = vars_[i];
  const double u = prior_u_[i] + z * var.prior_sd;
  return std::clamp(var.logarithmic ? std::exp(u) : u, var.lower, var.upper);
}

double CalibrationSpace::lower(std::size_t i) const { return whiten(i, vars_[i].lower); }
double CalibrationSpace::upper(std::size_t i) const { return whiten(i, vars_[i].upper); }

DynamicsParameters CalibrationSpace::to_parameters(const double* z) const {
  return to_parameters(z, prior_);
}

DynamicsParameters CalibrationSpace::to_parameters(const double* z,
                                                   const DynamicsParameters& base) const {
  DynamicsParameters p = base;
  for (std::size_t i = 0; i < count_; ++i) set(p, vars_[i], value(i, z[i]));
  return p;
}

void CalibrationSpace::to_variables(const DynamicsParameters& p, double* z) const {
  for (std::size_t i = 0; i < count_; ++i) {
    const double v = get(p, vars_[i]);
    const bool usable = vars_[i].logarithmic ? v > 0.0 : std::isfinite(v);
    z[i] = std::clamp(usable ? whiten(i, v) : 0.0, lower(i), upper(i));
  }
}

}  // namespace model::calibration
