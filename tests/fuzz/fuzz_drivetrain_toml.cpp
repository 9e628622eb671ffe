// Fuzz the drivetrain description reader (app/config/drivetrain_file.hpp) and its
// physics checks (drivetrain_checks.hpp) on TOML text in memory. Properties:
//   - a rejection is a DrivetrainFileError whose message starts with the source name
//     (never another exception, a crash or UB);
//   - a description that is accepted is written back by to_toml() as a description
//     that is accepted again (what `fit-cp --update` and `drivetwin drivetrain` rely on).
// `base` names built-ins only, so no input reaches the file system.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "config/drivetrain_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz.toml";
  model::Drivetrain d;
  try {
    d = app::config::parse_drivetrain(text, source);
  } catch (const app::config::DrivetrainFileError& e) {
    if (std::string(e.what()).rfind(source, 0) != 0) std::abort();
    return 0;
  }
  const std::string written = app::config::to_toml(d);
  try {
    (void)app::config::parse_drivetrain(written, "written.toml");
  } catch (const app::config::DrivetrainFileError&) {
    std::abort();  // accepted once, refused after writing back
  }
  return 0;
}
