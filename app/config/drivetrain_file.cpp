#include "config/drivetrain_file.hpp"

#include "units.hpp"

#include <toml++/toml.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>
#include <type_traits>
#include <variant>

#include "config/drivetrain_checks.hpp"
#include "data/embedded.hpp"

namespace app::config {
namespace {

using model::Bearing;
using model::BearingType;
using model::CpSurface;
using model::Drivetrain;
using model::DynamicsParameters;
using model::Gear;
using model::GearStage;
using model::Material;
using model::MeasurementPoint;
using model::Shaft;
using model::StageType;
using model::Turbine;
using model::TurbineCorrections;

/// What a numeric value must satisfy (in file units).
enum class Range {
  kAny,
  kPositive,
  kNonNegative,
  kFraction /* (0, 1] */,
  kUnit /* [0, 1] */,
  kAtLeastOne
};

template <class T>
using Member =
    std::variant<double T::*, int T::*, std::string T::*, std::vector<std::string> T::*,
                 std::array<double, 3> T::*, std::array<double, 6> T::*, std::array<double, 9> T::*,
                 std::array<double, 24> T::*, std::array<double, model::kCpTableKnots> T::*,
                 StageType T::*, BearingType T::*>;

/// One key of a table: its TOML name, the field it fills, the factor from file
/// units to stored units (stored = file · scale) and the allowed range.
/// Adding a field to the format is one line in the tables below.
template <class T>
struct Key {
  const char* name = nullptr;
  Member<T> member;
  Range range = Range::kAny;
  double scale = 1.0;
};

// ---- the format: one line per key --------------------------------------------------------------
const std::vector<Key<Turbine>> kTurbineKeys{
    {"rated_power_w", &Turbine::rated_power_w, Range::kPositive},
    {"rated_torque_nm", &Turbine::rated_torque_nm, Range::kPositive},
    {"rated_rotor_speed_rpm", &Turbine::rated_rotor_speed_rpm, Range::kPositive},
    {"min_rotor_speed_rpm", &Turbine::min_rotor_speed_rpm, Range::kNonNegative},
    {"cut_in_wind_mps", &Turbine::cut_in_wind_mps, Range::kNonNegative},
    {"rated_wind_mps", &Turbine::rated_wind_mps, Range::kPositive},
    {"cut_out_wind_mps", &Turbine::cut_out_wind_mps, Range::kPositive},
    {"rotor_radius_m", &Turbine::rotor_radius_m, Range::kPositive},
    {"air_density_kg_m3", &Turbine::air_density_kg_m3, Range::kPositive},
    {"cp_max", &Turbine::cp_max, Range::kNonNegative},
    {"lambda_opt", &Turbine::lambda_opt, Range::kNonNegative},
    {"drivetrain_efficiency", &Turbine::drivetrain_efficiency, Range::kFraction},
    {"site_altitude_m", &Turbine::site_altitude_m},
};
const std::vector<Key<TurbineCorrections>> kCorrectionKeys{
    {"no_load_loss_w", &TurbineCorrections::no_load_loss_w},
    {"nacelle_wind_gain", &TurbineCorrections::nacelle_wind_gain, Range::kPositive},
    {"nacelle_wind_offset_mps", &TurbineCorrections::nacelle_wind_offset_mps},
    {"yaw_loss_exponent", &TurbineCorrections::yaw_loss_exponent, Range::kNonNegative},
    {"tracking_tip_speed_ratio", &TurbineCorrections::tracking_tip_speed_ratio,
     Range::kNonNegative},
    {"tracking_band_margin", &TurbineCorrections::tracking_band_margin, Range::kNonNegative},
    {"turbulence_intensity", &TurbineCorrections::turbulence_intensity, Range::kNonNegative},
};
const std::vector<Key<CpSurface>> kCpKeys{
    {"c", &CpSurface::c},
    {"lambda_i_beta", &CpSurface::lambda_i_beta},
    {"lambda_i_cubic", &CpSurface::lambda_i_cubic},
    {"lambda_scale", &CpSurface::lambda_scale, Range::kPositive},
    {"table_lambda_min", &CpSurface::table_lambda_min, Range::kNonNegative},
    {"table_lambda_max", &CpSurface::table_lambda_max, Range::kNonNegative},
    {"table_cp", &CpSurface::table_cp, Range::kNonNegative},
};
const std::vector<Key<Material>> kMaterialKeys{
    {"id", &Material::id},
    {"youngs_modulus_pa", &Material::youngs_modulus_pa, Range::kPositive},
    {"poisson_ratio", &Material::poisson_ratio, Range::kFraction},
    {"density_kg_m3", &Material::density_kg_m3, Range::kPositive},
    {"sigma_hlim_mpa", &Material::sigma_hlim_mpa, Range::kPositive},
    {"sigma_flim_mpa", &Material::sigma_flim_mpa, Range::kPositive},
    {"sn_contact_m", &Material::sn_contact_m, Range::kPositive},
    {"sn_contact_c_mpa", &Material::sn_contact_c_mpa, Range::kPositive},
    {"sn_bending_m", &Material::sn_bending_m, Range::kPositive},
    {"sn_bending_c_mpa", &Material::sn_bending_c_mpa, Range::kPositive},
    {"sn_contact_knee_cycles", &Material::sn_contact_knee_cycles, Range::kPositive},
    {"sn_bending_knee_cycles", &Material::sn_bending_knee_cycles, Range::kPositive},
    {"reversed_bending_factor", &Material::reversed_bending_factor, Range::kFraction},
};
const std::vector<Key<Shaft>> kShaftKeys{
    {"id", &Shaft::id},
    {"length_m", &Shaft::length_m, Range::kPositive},
    {"diameter_m", &Shaft::diameter_m, Range::kPositive},
    {"material", &Shaft::material},
};
const std::vector<Key<Gear>> kGearKeys{
    {"id", &Gear::id},
    {"shaft", &Gear::shaft},
    {"teeth", &Gear::teeth, Range::kAtLeastOne},
    {"face_width_m", &Gear::face_width_m, Range::kPositive},
    {"mass_kg", &Gear::mass_kg, Range::kNonNegative},
    {"profile_shift", &Gear::profile_shift},
    {"material", &Gear::material},
};
const std::vector<Key<GearStage>> kStageKeys{
    {"id", &GearStage::id},
    {"type", &GearStage::type},
    {"normal_module_m", &GearStage::normal_module_m, Range::kPositive},
    {"pressure_angle_deg", &GearStage::pressure_angle_rad, Range::kPositive, kDeg},
    {"helix_angle_deg", &GearStage::helix_angle_rad, Range::kNonNegative, kDeg},
    {"planets", &GearStage::planets, Range::kNonNegative},
    {"gears", &GearStage::gears},
    {"input_shaft", &GearStage::input_shaft},
    {"output_shaft", &GearStage::output_shaft},
};
const std::vector<Key<Bearing>> kBearingKeys{
    {"id", &Bearing::id},
    {"shaft", &Bearing::shaft},
    {"position", &Bearing::position},
    {"elements", &Bearing::elements, Range::kAtLeastOne},
    {"rows", &Bearing::rows, Range::kAtLeastOne},
    {"element_diameter_m", &Bearing::element_diameter_m, Range::kPositive},
    {"pitch_diameter_m", &Bearing::pitch_diameter_m, Range::kPositive},
    {"contact_angle_deg", &Bearing::contact_angle_rad, Range::kNonNegative, kDeg},
    {"type", &Bearing::type},
    {"dynamic_rating_n", &Bearing::dynamic_rating_n, Range::kNonNegative},
    {"roller_effective_length_m", &Bearing::roller_effective_length_m, Range::kNonNegative},
    {"static_rating_n", &Bearing::static_rating_n, Range::kNonNegative},
    {"fatigue_load_limit_n", &Bearing::fatigue_load_limit_n, Range::kNonNegative},
    {"radial_stiffness_n_m", &Bearing::radial_stiffness_n_m, Range::kNonNegative},
};
const std::vector<Key<MeasurementPoint>> kPointKeys{
    {"channel", &MeasurementPoint::channel},
    {"location", &MeasurementPoint::location},
    {"direction", &MeasurementPoint::direction},
};
const std::vector<Key<DynamicsParameters>> kDynamicsKeys{
    {"rayleigh_eta", &DynamicsParameters::rayleigh_eta, Range::kNonNegative},
    {"rayleigh_zeta", &DynamicsParameters::rayleigh_zeta, Range::kNonNegative},
    {"mesh_stiffness_scale", &DynamicsParameters::mesh_stiffness_scale, Range::kPositive},
    {"mesh_tip_relief", &DynamicsParameters::mesh_tip_relief, Range::kUnit},
    {"bearing_stiffness_scale", &DynamicsParameters::bearing_stiffness_scale, Range::kPositive},
    {"bearing_stiffness_fluctuation", &DynamicsParameters::bearing_stiffness_fluctuation,
     Range::kNonNegative},
    {"bearing_compliance_scale", &DynamicsParameters::bearing_compliance_scale,
     Range::kNonNegative},
    {"bearing_stiffness_factor", &DynamicsParameters::bearing_stiffness_factor, Range::kPositive},
    {"sun_shaft_torsion_scale", &DynamicsParameters::sun_shaft_torsion_scale, Range::kPositive},
    {"damping_band_factor", &DynamicsParameters::damping_band_factor, Range::kPositive},
    {"transmission_error_m", &DynamicsParameters::transmission_error_m},
    {"transmission_error_phase_rad", &DynamicsParameters::transmission_error_phase_rad},
    {"housing_frequency_hz", &DynamicsParameters::housing_frequency_hz, Range::kNonNegative},
    {"housing_damping_ratio", &DynamicsParameters::housing_damping_ratio, Range::kNonNegative},
    {"housing_modal_mass_kg", &DynamicsParameters::housing_modal_mass_kg, Range::kNonNegative},
    {"housing_participation", &DynamicsParameters::housing_participation},
    {"housing_cross_participation", &DynamicsParameters::housing_cross_participation},
    {"housing_seat_participation", &DynamicsParameters::housing_seat_participation},
    {"gearbox_body_mass_kg", &DynamicsParameters::gearbox_body_mass_kg, Range::kNonNegative},
    {"gearbox_mount_stiffness_n_m", &DynamicsParameters::gearbox_mount_stiffness_n_m,
     Range::kNonNegative},
    {"gearbox_mount_damping_ratio", &DynamicsParameters::gearbox_mount_damping_ratio,
     Range::kNonNegative},
};

// ---- enums ------------------------------------------------------------------------------------
const char* enum_name(StageType t) { return t == StageType::kPlanetary ? "planetary" : "parallel"; }
const char* enum_name(BearingType t) { return t == BearingType::kBall ? "ball" : "roller"; }
bool enum_parse(std::string_view s, StageType& out) {
  if (s == "planetary") {
    out = StageType::kPlanetary;
  } else if (s == "parallel") {
    out = StageType::kParallel;
  } else {
    return false;
  }
  return true;
}
bool enum_parse(std::string_view s, BearingType& out) {
  if (s == "ball") {
    out = BearingType::kBall;
  } else if (s == "roller") {
    out = BearingType::kRoller;
  } else {
    return false;
  }
  return true;
}
const char* enum_choices(StageType) { return "\"planetary\" or \"parallel\""; }
const char* enum_choices(BearingType) { return "\"ball\" or \"roller\""; }

// ---- reading ----------------------------------------------------------------------------------
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key,
                         const std::string& what) const {
    std::ostringstream msg;
    msg << source_;
    if (node != nullptr && node->source().begin.line > 0) {
      msg << ':' << node->source().begin.line << ':' << node->source().begin.column;
    }
    msg << ": key '" << key << "': " << what;
    throw DrivetrainFileError(msg.str());
  }

  std::string describe(const toml::node& node) const {
    std::ostringstream out;
    if (node.is_table()) return "a table";
    if (node.is_array()) return "an array";
    if (node.is_string()) return "\"" + std::string(*node.value<std::string_view>()) + "\"";
    node.visit([&](auto&& v) {
      if constexpr (toml::is_value<decltype(v)>) out << v;
    });
    return out.str();
  }

  double number(const toml::node& node, const std::string& key, Range range) const {
    std::optional<double> v;
    if (node.is_floating_point() || node.is_integer()) v = node.value<double>();
    if (!v) fail(&node, key, "expected a number" + range_text(range) + ", got " + describe(node));
    if (!std::isfinite(*v) || !in_range(*v, range)) {
      fail(&node, key, "expected a finite number" + range_text(range) + ", got " + describe(node));
    }
    return *v;
  }

  template <class T>
  void read(const toml::table& table, T& object, const std::vector<Key<T>>& keys,
            const std::string& path, const std::set<std::string>& sub_tables = {}) const {
    for (const auto& [name, node] : table) {
      const std::string key =
          path.empty() ? std::string(name.str()) : path + "." + std::string(name.str());
      if (sub_tables.count(std::string(name.str())) != 0) continue;
      const Key<T>* found = nullptr;
      for (const auto& k : keys) {
        if (name.str() == k.name) found = &k;
      }
      if (found == nullptr) fail(&node, key, "unknown key (" + known_keys(keys) + ")");
      read_value(node, object, *found, key);
    }
  }

  template <class T>
  void read_value(const toml::node& node, T& object, const Key<T>& k,
                  const std::string& key) const {
    std::visit(
        [&](auto member) {
          using Field = std::remove_reference_t<decltype(object.*member)>;
          Field& field = object.*member;
          if constexpr (std::is_same_v<Field, double>) {
            field = number(node, key, k.range) * k.scale;
          } else if constexpr (std::is_same_v<Field, int>) {
            const auto v = node.value_exact<std::int64_t>();
            const std::int64_t min = k.range == Range::kAtLeastOne ? 1
                                     : k.range == Range::kAny      ? std::numeric_limits<int>::min()
                                                                   : 0;
            if (!v || *v < min || *v > std::numeric_limits<int>::max()) {
              fail(&node, key,
                   std::string("expected an integer") +
                       (min == 1   ? " >= 1"
                        : min == 0 ? " >= 0"
                                   : "") +
                       ", got " + describe(node));
            }
            field = static_cast<int>(*v);
          } else if constexpr (std::is_same_v<Field, std::string>) {
            const auto v = node.value_exact<std::string>();
            if (!v) fail(&node, key, "expected a string, got " + describe(node));
            field = *v;
          } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
            const toml::array* array = node.as_array();
            if (array == nullptr)
              fail(&node, key, "expected an array of strings, got " + describe(node));
            field.clear();
            for (std::size_t i = 0; i < array->size(); ++i) {
              const auto v = (*array)[i].value_exact<std::string>();
              if (!v) {
                fail(&(*array)[i], key + "[" + std::to_string(i) + "]",
                     "expected a string, got " + describe((*array)[i]));
              }
              field.push_back(*v);
            }
          } else if constexpr (std::is_same_v<Field, std::array<double, 3>> ||
                               std::is_same_v<Field, std::array<double, 6>> ||
                               std::is_same_v<Field, std::array<double, 9>> ||
                               std::is_same_v<Field, std::array<double, 24>> ||
                               std::is_same_v<Field, std::array<double, model::kCpTableKnots>>) {
            const toml::array* array = node.as_array();
            if (array == nullptr || array->size() != field.size()) {
              fail(&node, key,
                   "expected an array of " + std::to_string(field.size()) + " numbers, got " +
                       describe(node));
            }
            for (std::size_t i = 0; i < field.size(); ++i) {
              field[i] =
                  number((*array)[i], key + "[" + std::to_string(i) + "]", k.range) * k.scale;
            }
          } else {  // enums
            const auto v = node.value_exact<std::string>();
            if (!v || !enum_parse(*v, field)) {
              fail(&node, key,
                   std::string("expected ") + enum_choices(field) + ", got " + describe(node));
            }
          }
        },
        k.member);
  }

  /// [[list]] of tables, entries matched on `id_key` to existing ones (from a base).
  template <class T>
  void read_list(const toml::node& node, std::vector<T>& items, const std::vector<Key<T>>& keys,
                 const std::string& path, std::string T::*id_member, const char* id_key) const {
    const toml::array* array = node.as_array();
    if (array == nullptr) fail(&node, path, "expected an array of tables ([[" + path + "]])");
    for (std::size_t i = 0; i < array->size(); ++i) {
      const std::string item_path = path + "[" + std::to_string(i) + "]";
      const toml::table* table = (*array)[i].as_table();
      if (table == nullptr) fail(&(*array)[i], item_path, "expected a table");
      const auto id = (*table)[id_key].value_exact<std::string>();
      if (!id || id->empty()) {
        fail(&(*array)[i], item_path + "." + id_key,
             "expected a non-empty string (every entry needs one)");
      }
      T* target = nullptr;
      for (auto& item : items) {
        if (item.*id_member == *id) target = &item;
      }
      const bool added = target == nullptr;
      if (added) {
        items.emplace_back();
        target = &items.back();
      }
      read(*table, *target, keys, item_path);
      if (added) require_in_range(*table, *target, keys, item_path);
    }
  }

  /// A new entry starts from the struct's defaults: a key it does not give must have a
  /// default in its range, else the entry is refused as missing that key (it would be
  /// written back by to_toml() as a value the reader refuses).
  template <class T>
  void require_in_range(const toml::table& table, const T& object, const std::vector<Key<T>>& keys,
                        const std::string& path, const char* why = "a new entry needs it") const {
    for (const auto& k : keys) {
      if (table.contains(k.name)) continue;
      bool ok = true;
      std::visit(
          [&](auto member) {
            using Field = std::remove_cv_t<std::remove_reference_t<decltype(object.*member)>>;
            if constexpr (std::is_same_v<Field, double> || std::is_same_v<Field, int>) {
              ok = in_range(static_cast<double>(object.*member) / k.scale, k.range);
            }
          },
          k.member);
      if (!ok)
        fail(&table, path + "." + k.name, std::string("missing: ") + why + range_text(k.range));
    }
  }

 private:
  static bool in_range(double v, Range range) {
    switch (range) {
      case Range::kAny:
        return true;
      case Range::kPositive:
        return v > 0.0;
      case Range::kNonNegative:
        return v >= 0.0;
      case Range::kFraction:
        return v > 0.0 && v <= 1.0;
      case Range::kUnit:
        return v >= 0.0 && v <= 1.0;
      case Range::kAtLeastOne:
        return v >= 1.0;
    }
    return true;
  }
  static std::string range_text(Range range) {
    switch (range) {
      case Range::kAny:
        return "";
      case Range::kPositive:
        return " > 0";
      case Range::kNonNegative:
        return " >= 0";
      case Range::kFraction:
        return " in (0, 1]";
      case Range::kUnit:
        return " in [0, 1]";
      case Range::kAtLeastOne:
        return " >= 1";
    }
    return "";
  }
  template <class T>
  static std::string known_keys(const std::vector<Key<T>>& keys) {
    std::string out = "expected one of";
    for (const auto& k : keys) out += std::string(" ") + k.name;
    return out;
  }

  std::string source_;
};

std::optional<Drivetrain> builtin(std::string_view name, int depth);

/// The node of the file that an issue is about: its key, else its entry, else its table;
/// nullptr when the entry comes from the base.
const toml::node* locate(const toml::table& root, const DrivetrainIssue& issue) {
  const toml::node* list = root.get(issue.list);
  if (list == nullptr) return nullptr;
  const toml::table* entry = nullptr;
  if (const toml::table* t = list->as_table(); t != nullptr && issue.id.empty()) {
    entry = t;
  } else if (const toml::array* a = list->as_array()) {
    for (const toml::node& e : *a) {
      const toml::table* t2 = e.as_table();
      if (t2 != nullptr && (*t2)["id"].value_exact<std::string>() == issue.id) entry = t2;
    }
  }
  if (entry == nullptr) return nullptr;
  if (const toml::node* field = entry->get(issue.field)) return field;
  return entry;
}

/// TOML text → its root table; a syntax error → DrivetrainFileError naming source:line:column.
toml::table parse_toml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source << ':' << e.source().begin.line << ':' << e.source().begin.column
        << ": malformed TOML: " << e.description();
    throw DrivetrainFileError(msg.str());
  }
}

Drivetrain parse(std::string_view text, const std::string& source, int depth) {
  const toml::table root = parse_toml(text, source);
  const Reader reader(source);

  if (const toml::node* format = root.get("format")) {
    if (format->value_exact<std::string>() != std::string(kDrivetrainFormat)) {
      reader.fail(
          format, "format",
          std::string("expected \"") + kDrivetrainFormat + "\", got " + reader.describe(*format));
    }
  }
  Drivetrain d;
  if (const toml::node* base = root.get("base")) {
    const auto name = base->value_exact<std::string>();
    if (!name) reader.fail(base, "base", "expected the name of a built-in drivetrain");
    auto found = depth < 4 ? builtin(*name, depth + 1) : std::nullopt;
    if (!found) {
      std::string names;
      for (const auto& n : builtin_drivetrain_names()) names += " " + n;
      reader.fail(base, "base",
                  "unknown built-in drivetrain \"" + *name + "\" (known:" + names + ")");
    }
    d = std::move(*found);
  }
  if (const toml::node* name = root.get("name")) {
    const auto v = name->value_exact<std::string>();
    if (!v || v->empty()) reader.fail(name, "name", "expected a non-empty string");
    d.name = *v;
  } else if (!root.contains("base")) {
    reader.fail(nullptr, "name", "missing (a description without `base` needs a name)");
  }

  static const std::set<std::string> kTopLevel{
      "format",   "name",   "base",   "turbine",  "materials",
      "shafts",   "gears",  "stages", "bearings", "measurement_points",
      "dynamics", "effects"};
  for (const auto& [key, node] : root) {
    if (kTopLevel.count(std::string(key.str())) == 0) {
      reader.fail(&node, std::string(key.str()),
                  "unknown key (expected format, name, base, turbine, materials, shafts, gears, "
                  "stages, bearings, measurement_points, dynamics, effects)");
    }
  }
  // Without a base, the single tables start from the structs' defaults like a new list
  // entry does: a key the file leaves out must have a default in its range (else to_toml()
  // would write back a value the reader refuses).
  const bool from_scratch = !root.contains("base");
  constexpr const char* kNoBase = "a description without `base` needs it";
  const toml::table no_keys;
  const toml::table* turbine_table = &no_keys;
  if (const toml::node* node = root.get("turbine")) {
    const toml::table* table = node->as_table();
    if (table == nullptr) reader.fail(node, "turbine", "expected a table [turbine]");
    turbine_table = table;
    reader.read(*table, d.turbine, kTurbineKeys, "turbine", {"cp", "corrections"});
  }
  if (from_scratch)
    reader.require_in_range(*turbine_table, d.turbine, kTurbineKeys, "turbine", kNoBase);
  const toml::table* cp_table = &no_keys;
  if (const toml::node* cp = turbine_table->get("cp")) {
    if (!cp->is_table()) reader.fail(cp, "turbine.cp", "expected a table [turbine.cp]");
    cp_table = cp->as_table();
    reader.read(*cp_table, d.turbine.cp, kCpKeys, "turbine.cp");
  }
  if (from_scratch)
    reader.require_in_range(*cp_table, d.turbine.cp, kCpKeys, "turbine.cp", kNoBase);
  const toml::table* corrections_table = &no_keys;
  if (const toml::node* c = turbine_table->get("corrections")) {
    if (!c->is_table()) {
      reader.fail(c, "turbine.corrections", "expected a table [turbine.corrections]");
    }
    corrections_table = c->as_table();
    reader.read(*corrections_table, d.turbine.corrections, kCorrectionKeys, "turbine.corrections");
  }
  if (from_scratch) {
    reader.require_in_range(*corrections_table, d.turbine.corrections, kCorrectionKeys,
                            "turbine.corrections", kNoBase);
  }
  if (const toml::node* n = root.get("materials")) {
    reader.read_list(*n, d.materials, kMaterialKeys, "materials", &Material::id, "id");
  }
  if (const toml::node* n = root.get("shafts")) {
    reader.read_list(*n, d.shafts, kShaftKeys, "shafts", &Shaft::id, "id");
  }
  if (const toml::node* n = root.get("gears")) {
    reader.read_list(*n, d.gears, kGearKeys, "gears", &Gear::id, "id");
  }
  if (const toml::node* n = root.get("stages")) {
    reader.read_list(*n, d.stages, kStageKeys, "stages", &GearStage::id, "id");
  }
  if (const toml::node* n = root.get("bearings")) {
    reader.read_list(*n, d.bearings, kBearingKeys, "bearings", &Bearing::id, "id");
  }
  if (const toml::node* n = root.get("measurement_points")) {
    reader.read_list(*n, d.measurement_points, kPointKeys, "measurement_points",
                     &MeasurementPoint::channel, "channel");
  }
  if (const toml::node* node = root.get("dynamics")) {
    const toml::table* table = node->as_table();
    if (table == nullptr) reader.fail(node, "dynamics", "expected a table [dynamics]");
    reader.read(*table, d.dynamics, kDynamicsKeys, "dynamics");
    if (from_scratch)
      reader.require_in_range(*table, d.dynamics, kDynamicsKeys, "dynamics", kNoBase);
  } else if (from_scratch) {
    reader.require_in_range(no_keys, d.dynamics, kDynamicsKeys, "dynamics", kNoBase);
  }

  // Physics beyond the healthy gearbox (model/drivetrain/effects.hpp): [[effects]] tables,
  // kind = "<contract id>", location = "<component id>", then parameters by name.
  if (const toml::node* node = root.get("effects")) {
    const toml::array* list = node->as_array();
    if (list == nullptr) reader.fail(node, "effects", "expected an array of tables [[effects]]");
    d.effects.clear();  // a file's list replaces its base's
    for (std::size_t i = 0; i < list->size(); ++i) {
      const std::string where = "effects[" + std::to_string(i) + "]";
      const toml::table* t = (*list)[i].as_table();
      if (t == nullptr) reader.fail(&(*list)[i], where, "expected a table");
      const toml::node* kind_node = t->get("kind");
      const auto kind_id = kind_node ? kind_node->value_exact<std::string>() : std::nullopt;
      const auto kind = kind_id ? model::effect_kind(*kind_id) : std::nullopt;
      if (!kind) {
        std::string ids;
        for (model::EffectKind k : model::effect_kinds())
          ids += std::string(ids.empty() ? "" : ", ") + std::string(model::effect_id(k));
        reader.fail(kind_node ? kind_node : &(*list)[i], where + ".kind", "expected one of " + ids);
      }
      const toml::node* loc_node = t->get("location");
      const auto location = loc_node ? loc_node->value_exact<std::string>() : std::nullopt;
      if (!location)
        reader.fail(loc_node ? loc_node : &(*list)[i], where + ".location",
                    "expected a component id");
      model::Effect e = model::make_effect(*kind, *location);
      for (const auto& [key, value] : *t) {
        const std::string k(key.str());
        if (k == "kind" || k == "location") continue;
        const auto v = value.value<double>();
        if (!e.parameter(k)) {
          std::string names;
          for (const auto& p : model::effect_parameters(*kind))
            names += std::string(names.empty() ? "" : ", ") + p.name;
          reader.fail(&value, where + "." + k,
                      "unknown parameter of " + *kind_id + " (expected " + names + ")");
        }
        if (!v)
          reader.fail(&value, where + "." + k, "expected a number, got " + reader.describe(value));
        e.set_parameter(k, *v);
      }
      d.effects.push_back(std::move(e));
    }
  }

  // Cross-field checks (the whole description, after the base is merged).
  const Turbine& t = d.turbine;
  const toml::node* turbine_node = root.get("turbine");
  if (!(t.cut_in_wind_mps < t.rated_wind_mps && t.rated_wind_mps < t.cut_out_wind_mps)) {
    reader.fail(turbine_node, "turbine.rated_wind_mps",
                "expected cut_in_wind_mps < rated_wind_mps < cut_out_wind_mps");
  }
  if (t.min_rotor_speed_rpm > t.rated_rotor_speed_rpm) {
    reader.fail(turbine_node, "turbine.min_rotor_speed_rpm",
                "expected at most turbine.rated_rotor_speed_rpm");
  }
  if (t.cp.table_lambda_max > t.cp.table_lambda_min) {
    for (std::size_t i = 0; i < t.cp.table_cp.size(); ++i) {
      if (t.cp.table_cp[i] > 16.0 / 27.0) {  // Betz limit
        reader.fail(turbine_node, "turbine.cp.table_cp[" + std::to_string(i) + "]",
                    "expected at most the Betz limit 16/27 = 0.5926");
      }
    }
  }
  auto check_ref = [&](const std::string& key, const std::string& id, bool ok, const char* what) {
    if (!id.empty() && !ok)
      reader.fail(nullptr, key, "\"" + id + "\" is not the id of any " + what);
  };
  for (std::size_t i = 0; i < d.gears.size(); ++i) {
    check_ref("gears[" + std::to_string(i) + "].material", d.gears[i].material,
              d.material(d.gears[i].material) != nullptr, "material");
  }
  for (std::size_t i = 0; i < d.stages.size(); ++i) {
    for (std::size_t g = 0; g < d.stages[i].gears.size(); ++g) {
      check_ref("stages[" + std::to_string(i) + "].gears[" + std::to_string(g) + "]",
                d.stages[i].gears[g], d.gear(d.stages[i].gears[g]) != nullptr, "gear");
    }
  }
  for (std::size_t i = 0; i < d.bearings.size(); ++i) {
    const auto& b = d.bearings[i];
    if (b.element_diameter_m >= b.pitch_diameter_m) {
      reader.fail(nullptr, "bearings[" + std::to_string(i) + "].element_diameter_m",
                  "expected less than pitch_diameter_m");
    }
  }
  for (std::size_t i = 0; i < d.effects.size(); ++i) {
    std::string why;
    if (!model::check_effect(d, d.effects[i], &why)) {
      const toml::array* list = root.get("effects") ? root.get("effects")->as_array() : nullptr;
      const toml::node* at = list != nullptr && i < list->size() ? &(*list)[i] : nullptr;
      reader.fail(at, "effects[" + std::to_string(i) + "]", why);
    }
  }
  // Physics of the whole description (config/drivetrain_checks.hpp): the first violated
  // rule, at the line of the key (or of its entry) when the file names it.
  const std::vector<DrivetrainIssue> issues = check_drivetrain(d);
  if (!issues.empty()) {
    const DrivetrainIssue& issue = issues.front();
    reader.fail(locate(root, issue), issue.key, issue.message);
  }
  return d;
}

std::optional<Drivetrain> builtin(std::string_view name, int depth) {
  if (auto d = model::builtin_drivetrain(name)) {
    const std::vector<DrivetrainIssue> issues = check_drivetrain(*d);
    if (!issues.empty()) {
      throw DrivetrainFileError("<built-in " + std::string(name) + ">: key '" + issues.front().key +
                                "': " + issues.front().message);
    }
    return d;
  }
  const std::string file = std::string(name) + ".toml";
  if (const auto text = app::data::embedded_file(file)) {
    return parse(*text, "<built-in " + file + ">", depth);
  }
  return std::nullopt;
}

// ---- writing ----------------------------------------------------------------------------------
std::string format_double(double v) {
  std::array<char, 64> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  std::string s(buf.data(), r.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a TOML float
  return s;
}

/// A TOML basic string: quotes, backslashes and control characters escaped (TOML 1.0
/// allows none of them raw), so every string read back is the string written.
std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04X", static_cast<unsigned>(u));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

template <class T>
void write(std::ostream& out, const T& object, const std::vector<Key<T>>& keys) {
  for (const auto& k : keys) {
    out << k.name << " = ";
    std::visit(
        [&](auto member) {
          using Field = std::remove_cv_t<std::remove_reference_t<decltype(object.*member)>>;
          const Field& field = object.*member;
          if constexpr (std::is_same_v<Field, double>) {
            out << format_double(field / k.scale);
          } else if constexpr (std::is_same_v<Field, int>) {
            out << field;
          } else if constexpr (std::is_same_v<Field, std::string>) {
            out << quote(field);
          } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
            out << '[';
            for (std::size_t i = 0; i < field.size(); ++i)
              out << (i ? ", " : "") << quote(field[i]);
            out << ']';
          } else if constexpr (std::is_same_v<Field, std::array<double, 3>> ||
                               std::is_same_v<Field, std::array<double, 6>> ||
                               std::is_same_v<Field, std::array<double, 9>> ||
                               std::is_same_v<Field, std::array<double, 24>> ||
                               std::is_same_v<Field, std::array<double, model::kCpTableKnots>>) {
            out << '[';
            for (std::size_t i = 0; i < field.size(); ++i) {
              out << (i ? ", " : "") << format_double(field[i] / k.scale);
            }
            out << ']';
          } else {
            out << quote(enum_name(field));
          }
        },
        k.member);
    out << '\n';
  }
}

template <class T>
void write_list(std::ostream& out, const std::vector<T>& items, const std::vector<Key<T>>& keys,
                const char* name) {
  for (const auto& item : items) {
    out << "\n[[" << name << "]]\n";
    write(out, item, keys);
  }
}

}  // namespace

std::vector<std::string> builtin_drivetrain_names() {
  std::vector<std::string> names = model::builtin_drivetrain_names();
  for (const auto& file : app::data::embedded_file_names()) {
    const std::string_view f = file;
    if (f.size() > 5 && f.substr(f.size() - 5) == ".toml") {
      names.emplace_back(f.substr(0, f.size() - 5));
    }
  }
  return names;
}

std::string dynamics_to_toml(const model::DynamicsParameters& parameters) {
  std::ostringstream out;
  out << "[dynamics]\n";
  write(out, parameters, kDynamicsKeys);
  return out.str();
}

model::DynamicsParameters parse_dynamics(std::string_view toml_text, const std::string& source,
                                         const model::DynamicsParameters& base) {
  const toml::table root = parse_toml(toml_text, source);
  const Reader reader(source);
  for (const auto& [name, node] : root)
    if (name.str() != "dynamics")
      reader.fail(&node, std::string(name.str()), "unknown key (only a [dynamics] table)");
  model::DynamicsParameters p = base;
  const toml::node* node = root.get("dynamics");
  if (node == nullptr) reader.fail(nullptr, "dynamics", "missing: the [dynamics] table");
  const toml::table* table = node->as_table();
  if (table == nullptr) reader.fail(node, "dynamics", "expected a table [dynamics]");
  reader.read(*table, p, kDynamicsKeys, "dynamics");
  return p;
}

model::Drivetrain parse_drivetrain(std::string_view toml_text, const std::string& source) {
  return parse(toml_text, source, 0);
}

model::Drivetrain load_drivetrain(const std::string& name_or_path) {
  if (auto d = builtin(name_or_path, 0)) return std::move(*d);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(name_or_path, ec)) {
    std::string names;
    for (const auto& n : builtin_drivetrain_names()) names += " " + n;
    throw DrivetrainFileError("drivetrain '" + name_or_path + "': neither a built-in (" +
                              names.substr(1) + ") nor a readable file");
  }
  std::ifstream in(name_or_path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw DrivetrainFileError(name_or_path + ": cannot read");
  return parse(text.str(), name_or_path, 0);
}

std::string to_toml(const model::Drivetrain& d) {
  std::ostringstream out;
  out << "# drivetwin drivetrain description (app/config/README.md)\n"
      << "format = " << quote(kDrivetrainFormat) << '\n'
      << "name = " << quote(d.name) << "\n\n[turbine]\n";
  write(out, d.turbine, kTurbineKeys);
  out << "\n[turbine.cp]\n";
  write(out, d.turbine.cp, kCpKeys);
  out << "\n[turbine.corrections]\n";
  write(out, d.turbine.corrections, kCorrectionKeys);
  write_list(out, d.materials, kMaterialKeys, "materials");
  write_list(out, d.shafts, kShaftKeys, "shafts");
  write_list(out, d.gears, kGearKeys, "gears");
  write_list(out, d.stages, kStageKeys, "stages");
  write_list(out, d.bearings, kBearingKeys, "bearings");
  write_list(out, d.measurement_points, kPointKeys, "measurement_points");
  out << "\n[dynamics]\n";
  write(out, d.dynamics, kDynamicsKeys);
  for (const model::Effect& e : d.effects) {
    out << "\n[[effects]]\nkind = " << quote(std::string(model::effect_id(e.kind)))
        << "\nlocation = " << quote(e.location) << '\n';
    const auto params = model::effect_parameters(e.kind);
    for (std::size_t i = 0; i < params.size(); ++i)
      out << params[i].name << " = " << format_double(e.parameters[i]) << '\n';
  }
  return out.str();
}

}  // namespace app::config
