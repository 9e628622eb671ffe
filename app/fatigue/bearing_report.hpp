#pragma once
// The bearing ratings a damage run uses, reported the same way by `drivetwin damage` and the
// demo's fatigue stage: the rating C in use (the description's catalogue figure, or ISO 281
// from the geometry) beside ISO 281:2007's rating from the geometry as a check, C0 and C_u,
// and the ISO 281 life modification a_ISO with its lubrication and contamination inputs, at
// the rated operating point (model/fatigue/bearing_life.hpp).
//
// Thread context: command code (allocates).

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace app::fatigue {

/// One bearing slot's ratings and its life modification at rated torque and speed.
struct BearingRatingRow {
  std::string id;
  double c_n = 0.0;               // [N] in use
  bool c_from_catalogue = false;  // the description gives C
  double c_geometry_n = 0.0;      // [N] ISO 281:2007 from the geometry (0: not computable)
  std::string geometry_error;     // why not
  double c0_n = 0.0, cu_n = 0.0;  // [N]
  double rated_load_n = 0.0;      // [N] P at rated torque (quasi-static)
  double rated_speed_rpm = 0.0;   // [rpm] ring speed at rated rotor speed
  double kappa = 0.0;             // [-] ν/ν1 at rated speed
  double a_iso = 1.0;             // [-] at rated load and speed
};

std::vector<BearingRatingRow> bearing_rating_rows(const model::Drivetrain& drivetrain,
                                                  const model::fatigue::ChannelSet& channels);

/// Comment lines ("# ...") for a text report.
std::string bearing_rating_text(const model::fatigue::ChannelSet& channels,
                                const std::vector<BearingRatingRow>& rows);

/// The same as JSON: {"bearings": {id: {...}}, "life_modification": {...}}.
nlohmann::json bearing_rating_json(const model::fatigue::ChannelSet& channels,
                                   const std::vector<BearingRatingRow>& rows);

}  // namespace app::fatigue
