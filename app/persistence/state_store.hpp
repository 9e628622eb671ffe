#pragma once
// Crash-safe store of the twin's persistent state (damage accumulators, RUL rate history,
// calibration), written by the persistence thread every N seconds and on SIGTERM, read at
// start. Generic: a record is a set of sections (id, layout version, bytes); what they hold
// is the caller's (app/persistence/twin_state.hpp).
//
// Two copies, written alternately: <dir>/<name>.a and <dir>/<name>.b. A save writes the
// copy NOT holding the newest good record, so the newest good record is never touched
// while it is being replaced; at any instant at least one copy holds a good record (the
// newest one, or the one before it). Each save:
//   1. writes <copy>.tmp and fsyncs it;
//   2. reads it back and compares it byte for byte with what was meant (a disk or
//      filesystem that returns something else is caught before it can replace anything);
//   3. renames <copy>.tmp over <copy> and fsyncs the directory (the rename is durable).
// Load reads both copies, checks each (magic, format version, length, CRC-32) and takes the
// valid one with the highest generation; a copy that is missing, torn, bit-flipped or
// foreign is reported by name with what is wrong and skipped.
//
// File format "drivetwin-state" version kStateFormatVersion (little-endian):
//   0   char[8] "DTSTATE\0"
//   8   u32     format version
//   12  u32     section count
//   16  u64     generation (+1 per save; the newest record has the highest)
//   24  i64     saved_at_ns (the loop's clock when the state was taken)
//   32  sections: u32 id, u32 layout version, u64 size, then `size` bytes
//   end u32     CRC-32 (ISO-HDLC, as zlib's crc32; Boost.CRC crc_32_type) of all bytes before
//
// Thread context: non-real-time (file I/O, allocates); one thread saves at a time.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace app::persistence {

inline constexpr std::uint32_t kStateFormatVersion = 1;
inline constexpr char kStateMagic[8] = {'D', 'T', 'S', 'T', 'A', 'T', 'E', '\0'};

struct StateSection {
  std::uint32_t id = 0;       // what it holds (the caller's ids; permanent, never reused)
  std::uint32_t version = 0;  // layout version of the bytes
  std::vector<unsigned char> bytes;
};

struct StateRecord {
  std::uint64_t generation = 0;
  std::int64_t saved_at_ns = 0;
  std::vector<StateSection> sections;
  const StateSection* find(std::uint32_t id) const;
};

/// What load() found.
struct StateLoad {
  std::optional<StateRecord> record;  // the newest valid record, if any
  std::string copy;                   // its file
  std::vector<std::string> problems;  // one line per copy that exists but is bad
  bool first_start = false;           // neither copy exists
};

class StateStore {
 public:
  /// @param dir the state directory; @param name the files' base name ("twin-state").
  StateStore(std::filesystem::path dir, std::string name);

  /// Saves `sections` as the next generation (one more than the newest good record on disk,
  /// or than the last save). False with `error` naming the file and the failing step; the
  /// newest good record is then untouched.
  bool save(const std::vector<StateSection>& sections, std::int64_t saved_at_ns,
            std::string* error);

  /// Reads both copies and returns the newest valid record (see StateLoad).
  StateLoad load();

  /// Checks one file. Empty string when good (and *record filled if given), else what is
  /// wrong (without the path).
  static std::string check_file(const std::filesystem::path& file, StateRecord* record);

  std::filesystem::path copy_path(int slot) const;  // slot 0: .a, 1: .b
  std::uint64_t last_generation() const { return last_generation_; }

 private:
  std::filesystem::path dir_;
  std::string name_;
  std::uint64_t last_generation_ = 0;
  int newest_slot_ = -1;  // the slot holding the newest good record (−1: unknown/none)
  bool scanned_ = false;
};

}  // namespace app::persistence
