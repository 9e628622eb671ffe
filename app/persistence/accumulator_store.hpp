#pragma once
// Persistence of the online fatigue accumulator (model/fatigue/damage_accumulator.hpp):
// the state survives restarts, written so that a crash or power loss at any moment leaves
// a good copy on disk, and read so that a damaged file is reported, never silently
// replaced by zero damage.
//
// File format "drivetwin-accumulator", version kAccumulatorFileVersion (little-endian, as
// the box and the host are):
//   offset  0  char[8]  magic "DTACCUM\0"
//           8  u32      file format version
//          12  u32      AccumulatorState::version (the model's state layout)
//          16  u64      payload size in bytes (= sizeof(AccumulatorState))
//          24  payload  the AccumulatorState, bytewise
//   24 + size  u32      CRC-32 (ISO-HDLC, as zlib's crc32; Boost.CRC crc_32_type) of every byte
//   before it
//
// save(): write <path>.tmp, fsync it, read it back and verify it, keep the current file as
// the last good copy <path>.bak (only if it verifies: a corrupt file never replaces a good
// backup), rename <path>.tmp over <path>, fsync the directory. At every instant <path> or
// <path>.bak holds a good state.
// load(): <path>; if it is missing, truncated, foreign, of another version or fails its CRC,
// the message names the file and what is wrong, and <path>.bak is tried; the result says
// which copy was used. Both bad: status names both and nothing is loaded.
//
// Thread context: non-real-time (file I/O, allocates). The loop thread copies
// DamageAccumulator::state() at a cycle boundary and hands the copy to the thread that
// calls save().

#include <cstdint>
#include <filesystem>
#include <string>

#include "model/fatigue/damage_accumulator.hpp"

namespace app::persistence {

inline constexpr std::uint32_t kAccumulatorFileVersion = 1;
inline constexpr char kAccumulatorMagic[8] = {'D', 'T', 'A', 'C', 'C', 'U', 'M', '\0'};

enum class LoadStatus : std::uint8_t {
  kLoaded,        // <path> was good
  kLoadedBackup,  // <path> was bad or missing, <path>.bak was good (see message)
  kNoState,       // neither file exists: a first start (the message says so)
  kCorrupt,       // a file exists but no copy is good: nothing loaded
};

struct LoadResult {
  LoadStatus status = LoadStatus::kNoState;
  std::string message;  // what was wrong with which file, and which copy was used
  bool ok() const { return status == LoadStatus::kLoaded || status == LoadStatus::kLoadedBackup; }
};

class AccumulatorStore {
 public:
  /// @param path the state file; the last good copy is path + ".bak", the temporary path + ".tmp".
  explicit AccumulatorStore(std::filesystem::path path);

  /// Writes `state` atomically (see the file comment). False with `error` naming the file
  /// and the failing step; the previous files are then untouched.
  bool save(const model::fatigue::AccumulatorState& state, std::string* error) const;

  /// Reads the newest good copy into `state` (unchanged unless ok()).
  LoadResult load(model::fatigue::AccumulatorState& state) const;

  /// Checks one file; empty string when good, else what is wrong (without the path).
  static std::string check_file(const std::filesystem::path& file,
                                model::fatigue::AccumulatorState* state);

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path backup_path() const { return path_.string() + ".bak"; }
  std::filesystem::path temp_path() const { return path_.string() + ".tmp"; }

 private:
  std::filesystem::path path_;
};

}  // namespace app::persistence
