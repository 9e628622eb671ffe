#pragma once
// A seqlock holding the latest value of a plain struct: one writer (a bus I/O
// thread) publishes, one or more readers (the RT thread) copy it out without
// locks and without blocking. A reader that races a write retries a bounded
// number of times and otherwise reports failure (the caller keeps its previous
// copy), so read() is wait-free in the bound.
//
// T must be trivially copyable. The copy goes word-wise through relaxed
// atomics, so a reader racing the writer is defined behaviour (it discards the
// torn copy when the sequence number changed).
// Thread context: write() from one thread only; read() from any thread.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace hal {

template <typename T>
class LatestValue {
  static_assert(std::is_trivially_copyable_v<T>, "LatestValue<T> needs a trivially copyable T");
  static constexpr std::size_t kWords =
      (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);

 public:
  /// Publishes `value`. Wait-free, one writer.
  void write(const T& value) {
    std::uint64_t buf[kWords] = {};
    std::memcpy(buf, &value, sizeof(T));
    const std::uint32_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: write in progress
    // Release stores: the odd sequence number above cannot move after any of them, so a
    // reader that sees one of these words also sees the write in progress (below).
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(buf[i], std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Copies the latest value into `out`.
  /// @return false if nothing was ever written or every attempt raced a write
  ///         (then `out` is untouched).
  bool read(T& out) const {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      const std::uint32_t s1 = seq_.load(std::memory_order_acquire);
      if (s1 == 0) return false;
      if (s1 & 1u) continue;
      std::uint64_t buf[kWords];
      // Acquire loads: the sequence number read after them cannot be older than the write
      // whose words they saw (no fences: ThreadSanitizer checks this form).
      for (std::size_t i = 0; i < kWords; ++i) buf[i] = words_[i].load(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s1) {
        std::memcpy(&out, buf, sizeof(T));
        return true;
      }
    }
    return false;
  }

  /// Number of writes so far (for "has anything new arrived" checks).
  std::uint32_t version() const { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  static constexpr int kMaxAttempts = 64;
  std::atomic<std::uint32_t> seq_{0};
  std::atomic<std::uint64_t> words_[kWords] = {};
};

}  // namespace hal
