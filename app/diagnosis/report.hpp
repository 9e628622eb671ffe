#pragma once
// The diagnosis report in its two forms:
//  - JSON exactly as shared/reference/diagnosis-report.md (format drivetwin-diagnosis/1),
//    keys in the contract's order;
//  - one self-contained HTML file (no network: inline SVG, inline CSS) that an engineer
//    opens offline: recording vs simulation spectra at each point before calibration,
//    after calibration and after the named physics, the mismatch marked on them, the
//    effect, its location, its fitted parameters and the evidence for it.
// Host / non-real-time code: allocates.

#include <nlohmann/json.hpp>

#include <string>

#include "model/diagnosis/diagnoser.hpp"

namespace app::diagnosis {

/// The contract's JSON of a finished diagnosis of bundle `bundle_name`.
nlohmann::ordered_json report_json(const model::diagnosis::DiagnosisReport& report,
                                   const model::diagnosis::Catalogue& catalogue,
                                   const std::string& bundle_name);

/// The HTML report.
std::string report_html(const model::diagnosis::DiagnosisReport& report,
                        const model::diagnosis::Catalogue& catalogue,
                        const std::string& bundle_name);

}  // namespace app::diagnosis
