#include "persistence/state_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <boost/crc.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace app::persistence {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeaderBytes = 32;
constexpr std::size_t kSectionHeaderBytes = 16;
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

std::vector<unsigned char> encode(const std::vector<StateSection>& sections,
                                  std::uint64_t generation, std::int64_t saved_at_ns) {
  std::vector<unsigned char> out;
  std::size_t size = kHeaderBytes + kCrcBytes;
  for (const StateSection& s : sections) size += kSectionHeaderBytes + s.bytes.size();
  out.reserve(size);
  out.insert(out.end(), kStateMagic, kStateMagic + sizeof kStateMagic);
  put(out, kStateFormatVersion);
  put(out, static_cast<std::uint32_t>(sections.size()));
  put(out, generation);
  put(out, saved_at_ns);
  for (const StateSection& s : sections) {
    put(out, s.id);
    put(out, s.version);
    put(out, static_cast<std::uint64_t>(s.bytes.size()));
    out.insert(out.end(), s.bytes.begin(), s.bytes.end());
  }
  put(out, crc32(out.data(), out.size()));
  return out;
}

std::string check_bytes(const std::vector<unsigned char>& b, StateRecord* record) {
  if (b.size() < kHeaderBytes + kCrcBytes) {
    return "truncated: " + std::to_string(b.size()) + " bytes, shorter than an empty record (" +
           std::to_string(kHeaderBytes + kCrcBytes) + ")";
  }
  if (std::memcmp(b.data(), kStateMagic, sizeof kStateMagic) != 0) {
    return "not a drivetwin state file (magic bytes differ)";
  }
  const auto version = get<std::uint32_t>(b.data() + 8);
  if (version != kStateFormatVersion) {
    return "file format version " + std::to_string(version) + ", this build reads version " +
           std::to_string(kStateFormatVersion);
  }
  const std::size_t body = b.size() - kCrcBytes;
  const auto stored = get<std::uint32_t>(b.data() + body);
  const std::uint32_t computed = crc32(b.data(), body);
  if (stored != computed) {
    char buf[112];
    std::snprintf(buf, sizeof buf,
                  "CRC-32 mismatch (stored %08x, computed %08x): the file is torn or damaged",
                  static_cast<unsigned>(stored), static_cast<unsigned>(computed));
    return buf;
  }
  StateRecord r;
  const auto count = get<std::uint32_t>(b.data() + 12);
  r.generation = get<std::uint64_t>(b.data() + 16);
  r.saved_at_ns = get<std::int64_t>(b.data() + 24);
  std::size_t at = kHeaderBytes;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (body - at < kSectionHeaderBytes) return "section " + std::to_string(i) + ": truncated";
    StateSection s;
    s.id = get<std::uint32_t>(b.data() + at);
    s.version = get<std::uint32_t>(b.data() + at + 4);
    const auto size = get<std::uint64_t>(b.data() + at + 8);
    at += kSectionHeaderBytes;
    if (size > body - at) {
      return "section " + std::to_string(i) + " (id " + std::to_string(s.id) +
             "): " + std::to_string(size) + " bytes overrun the record";
    }
    s.bytes.assign(b.begin() + static_cast<std::ptrdiff_t>(at),
                   b.begin() + static_cast<std::ptrdiff_t>(at + size));
    at += size;
    r.sections.push_back(std::move(s));
  }
  if (at != body) return "trailing bytes after the last section";
  if (record != nullptr) *record = std::move(r);
  return {};
}

}  // namespace

const StateSection* StateRecord::find(std::uint32_t id) const {
  for (const StateSection& s : sections) {
    if (s.id == id) return &s;
  }
  return nullptr;
}

StateStore::StateStore(fs::path dir, std::string name)
    : dir_(std::move(dir)), name_(std::move(name)) {}

fs::path StateStore::copy_path(int slot) const {
  return dir_ / (name_ + (slot == 0 ? ".a" : ".b"));
}

std::string StateStore::check_file(const fs::path& file, StateRecord* record) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "cannot open: " + errno_text();
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
  if (in.bad()) return "read error: " + errno_text();
  return check_bytes(bytes, record);
}

StateLoad StateStore::load() {
  StateLoad out;
  std::error_code ec;
  bool any = false;
  newest_slot_ = -1;
  for (int slot = 0; slot < 2; ++slot) {
    const fs::path p = copy_path(slot);
    if (!fs::exists(p, ec)) continue;
    any = true;
    StateRecord r;
    if (const std::string what = check_file(p, &r); !what.empty()) {
      out.problems.push_back("state copy '" + p.string() + "': " + what + "; skipped");
      continue;
    }
    if (!out.record || r.generation > out.record->generation) {
      out.record = std::move(r);
      out.copy = p.string();
      newest_slot_ = slot;
    }
  }
  out.first_start = !any;
  last_generation_ = out.record ? out.record->generation : 0;
  scanned_ = true;
  return out;
}

bool StateStore::save(const std::vector<StateSection>& sections, std::int64_t saved_at_ns,
                      std::string* error) {
  std::string local;
  std::string& err = error ? *error : local;
  if (!scanned_) (void)load();  // learn which copy holds the newest good record
  const std::uint64_t generation = last_generation_ + 1;
  const std::vector<unsigned char> bytes = encode(sections, generation, saved_at_ns);
  // Write the copy that does not hold the newest good record.
  const int slot = newest_slot_ == 0 ? 1 : 0;
  const fs::path target = copy_path(slot);
  const fs::path tmp = target.string() + ".tmp";
  if (!write_synced(tmp, bytes, &err)) return false;
  {
    std::ifstream in(tmp, std::ios::binary);
    const std::vector<unsigned char> back((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    if (back != bytes) {
      err = "'" + tmp.string() + "': read-back differs from what was written (" +
            std::to_string(back.size()) + " of " + std::to_string(bytes.size()) + " bytes)";
      return false;
    }
  }
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
    err = "'" + target.string() + "': rename from '" + tmp.string() + "' failed: " + errno_text();
    return false;
  }
  if (!sync_directory(dir_, &err)) return false;
  last_generation_ = generation;
  newest_slot_ = slot;
  return true;
}

}  // namespace app::persistence
