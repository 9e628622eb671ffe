#pragma once
// Helpers of the `drivetwin run` integration tests: run files written into a temporary
// folder, the built-in day's first rows as a file of their own.
#include <filesystem>
#include <fstream>
#include <string>

#include "data/embedded.hpp"

namespace run_test {

namespace fs = std::filesystem;

/// A fresh temporary folder, removed with the object.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) {
    path = fs::temp_directory_path() /
           (name + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  static int& counter() {
    static int c = 0;
    return c;
  }
};

inline void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

/// The built-in Kelmarsh day's header and its first `rows` rows.
inline std::string builtin_day_rows(std::size_t rows) {
  const auto text = app::data::embedded_file("kelmarsh-day.csv");
  std::string out;
  std::size_t line = 0, start = 0;
  while (start < text->size() && line <= rows) {
    const std::size_t end = text->find('\n', start);
    const std::size_t stop = end == std::string_view::npos ? text->size() : end + 1;
    out.append(text->substr(start, stop - start));
    start = stop;
    ++line;
  }
  return out;
}

}  // namespace run_test
