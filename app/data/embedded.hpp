#pragma once
// Data files compiled into the drivetwin binary (app/data/*.csv, *.toml), so the
// box needs no data directory: the built-in Kelmarsh day of the demo and the
// built-in drivetrain descriptions beyond paper-2mw. The .cpp holding the bytes
// is generated at build time by app/data/embed.cmake.
// Thread context: immutable static data; safe from any thread.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace app::data {

/// The content of an embedded file by its name in app/data/ (e.g. "kelmarsh-day.csv").
std::optional<std::string_view> embedded_file(std::string_view name);

/// Names of all embedded files, sorted.
std::vector<std::string> embedded_file_names();

}  // namespace app::data
