#include "persistence/accumulator_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <boost/crc.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

namespace app::persistence {
namespace {

namespace fs = std::filesystem;
using model::fatigue::AccumulatorState;

// The file holds AccumulatorState's bytes as they are, and save() compares them after reading
// back: both need a struct without padding (4 × u32, 7 × u64, then u64 and double arrays).
constexpr std::size_t kStateFieldBytes =
    4 * 4 + 7 * 8 +
    2 * model::fatigue::kMaxChannels * (model::fatigue::kMaxBins + 1) * sizeof(std::uint64_t) +
    3 * model::fatigue::kMaxChannels * sizeof(double);
static_assert(sizeof(AccumulatorState) == kStateFieldBytes, "AccumulatorState has padding");

constexpr std::size_t kHeaderBytes = 24;
constexpr std::size_t kCrcBytes = 4;

std::uint32_t crc32(const unsigned char* data, std::size_t n) {
  boost::crc_32_type crc;
  crc.process_bytes(data, n);
  return crc.checksum();
}

template <typename T>
void put(std::vector<unsigned char>& out, const T& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(&v);
  out.insert(out.end(), p, p + sizeof v);
}

template <typename T>
T get(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string errno_text() { return std::strerror(errno); }

// Writes all of `bytes` to `file` and fsyncs it.
bool write_synced(const fs::path& file, const std::vector<unsigned char>& bytes,
                  std::string* error) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    *error = "'" + file.string() + "': cannot create: " + errno_text();
    return false;
  }
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      *error = "'" + file.string() + "': write failed: " + errno_text();
      ::close(fd);
      return false;
    }
    done += static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0) {
    *error = "'" + file.string() + "': fsync failed: " + errno_text();
    ::close(fd);
    return false;
  }
  if (::close(fd) != 0) {
    *error = "'" + file.string() + "': close failed: " + errno_text();
    return false;
  }
  return true;
}

bool sync_directory(const fs::path& dir, std::string* error) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    *error = "'" + dir.string() + "': cannot open the folder to fsync it: " + errno_text();
    return false;
  }
  const bool ok = ::fsync(fd) == 0;
  if (!ok) *error = "'" + dir.string() + "': fsync of the folder failed: " + errno_text();
  ::close(fd);
  return ok;
}

}  // namespace

AccumulatorStore::AccumulatorStore(fs::path path) : path_(std::move(path)) {}

std::string AccumulatorStore::check_file(const fs::path& file, AccumulatorState* state) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "cannot open: " + errno_text();
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
  if (bytes.size() < kHeaderBytes) {
    return "truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the " +
           std::to_string(kHeaderBytes) + "-byte header";
  }
  if (std::memcmp(bytes.data(), kAccumulatorMagic, sizeof kAccumulatorMagic) != 0) {
    return "not a drivetwin accumulator state file (magic bytes differ)";
  }
  const auto version = get<std::uint32_t>(bytes.data() + 8);
  const auto state_version = get<std::uint32_t>(bytes.data() + 12);
  const auto size = get<std::uint64_t>(bytes.data() + 16);
  if (version != kAccumulatorFileVersion) {
    return "file format version " + std::to_string(version) + ", this build reads version " +
           std::to_string(kAccumulatorFileVersion);
  }
  if (state_version != model::fatigue::kAccumulatorStateVersion) {
    return "accumulator state version " + std::to_string(state_version) +
           ", this build has version " + std::to_string(model::fatigue::kAccumulatorStateVersion);
  }
  if (size != sizeof(AccumulatorState)) {
    return "payload of " + std::to_string(size) + " bytes, this build's state has " +
           std::to_string(sizeof(AccumulatorState));
  }
  const std::size_t expect = kHeaderBytes + sizeof(AccumulatorState) + kCrcBytes;
  if (bytes.size() != expect) {
    return std::string(bytes.size() < expect ? "truncated" : "trailing bytes") + ": " +
           std::to_string(bytes.size()) + " bytes, expected " + std::to_string(expect);
  }
  const std::size_t body = kHeaderBytes + sizeof(AccumulatorState);
  const auto stored = get<std::uint32_t>(bytes.data() + body);
  const std::uint32_t computed = crc32(bytes.data(), body);
  if (stored != computed) {
    char buf[96];
    std::snprintf(buf, sizeof buf,
                  "CRC-32 mismatch (stored %08x, computed %08x): the file is damaged",
                  static_cast<unsigned>(stored), static_cast<unsigned>(computed));
    return buf;
  }
  if (state != nullptr) std::memcpy(state, bytes.data() + kHeaderBytes, sizeof(AccumulatorState));
  return {};
}

bool AccumulatorStore::save(const AccumulatorState& state, std::string* error) const {
  std::string local;
  std::string& err = error ? *error : local;
  std::vector<unsigned char> bytes;
  bytes.reserve(kHeaderBytes + sizeof state + kCrcBytes);
  bytes.insert(bytes.end(), kAccumulatorMagic, kAccumulatorMagic + sizeof kAccumulatorMagic);
  put(bytes, kAccumulatorFileVersion);
  put(bytes, model::fatigue::kAccumulatorStateVersion);
  put(bytes, static_cast<std::uint64_t>(sizeof state));
  const auto* p = reinterpret_cast<const unsigned char*>(&state);
  bytes.insert(bytes.end(), p, p + sizeof state);
  put(bytes, crc32(bytes.data(), bytes.size()));

  const fs::path tmp = temp_path();
  if (!write_synced(tmp, bytes, &err)) return false;
  // Read back: what is on disk must be what we meant to write.
  auto check = std::make_unique<AccumulatorState>();
  if (const std::string what = check_file(tmp, check.get()); !what.empty()) {
    err = "'" + tmp.string() + "': read-back after writing failed: " + what;
    return false;
  }
  // Bit-identical, doubles included (-0.0, NaN payloads): exactly what the file must restore.
  // AccumulatorState has no padding (asserted at the top of this file).
  // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison)
  if (std::memcmp(check.get(), &state, sizeof state) != 0) {
    err = "'" + tmp.string() + "': read-back differs from the state written";
    return false;
  }
  // The current file becomes the last good copy, if it is good.
  std::error_code ec;
  if (fs::exists(path_, ec) && check_file(path_, nullptr).empty()) {
    const fs::path bak = backup_path();
    fs::remove(bak, ec);
    if (::link(path_.c_str(), bak.c_str()) != 0) {
      err = "'" + bak.string() + "': cannot keep the last good copy: " + errno_text();
      return false;
    }
  }
  if (::rename(tmp.c_str(), path_.c_str()) != 0) {
    err = "'" + path_.string() + "': rename from '" + tmp.string() + "' failed: " + errno_text();
    return false;
  }
  return sync_directory(path_.parent_path(), &err);
}

LoadResult AccumulatorStore::load(AccumulatorState& state) const {
  LoadResult r;
  std::error_code ec;
  const fs::path bak = backup_path();
  const bool have_main = fs::exists(path_, ec);
  const bool have_bak = fs::exists(bak, ec);
  if (!have_main && !have_bak) {
    r.status = LoadStatus::kNoState;
    r.message = "accumulator state '" + path_.string() + "': no saved state (nor '" + bak.string() +
                "'): starting from zero damage";
    return r;
  }
  auto tmp = std::make_unique<AccumulatorState>();
  std::string main_problem = have_main ? check_file(path_, tmp.get()) : "missing";
  if (main_problem.empty()) {
    state = *tmp;
    r.status = LoadStatus::kLoaded;
    r.message = "accumulator state '" + path_.string() + "': loaded";
    return r;
  }
  const std::string bak_problem = have_bak ? check_file(bak, tmp.get()) : "missing";
  if (bak_problem.empty()) {
    state = *tmp;
    r.status = LoadStatus::kLoadedBackup;
    r.message = "accumulator state '" + path_.string() + "': " + main_problem +
                "; using the last good copy '" + bak.string() +
                "' (damage since it was replaced is lost)";
    return r;
  }
  r.status = LoadStatus::kCorrupt;
  r.message = "accumulator state '" + path_.string() + "': " + main_problem + "; last good copy '" +
              bak.string() + "': " + bak_problem + "; no state loaded";
  return r;
}

}  // namespace app::persistence
