#pragma once
// A single-writer, many-reader publication of a trivially copyable value through a
// sequence lock of atomic words: the writer never blocks, a reader retries while a
// write is in progress and gives up after a bounded number of attempts.
//
// Thread context: publish() from one owning thread; read() from any thread, lock-free,
// allocation-free.

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace model::diagnosis {

template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>);
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

 public:
  void publish(const T& value) {
    std::array<std::uint64_t, kWords> words{};
    std::memcpy(words.data(), &value, sizeof(T));
    const std::uint32_t s = sequence_.load(std::memory_order_relaxed);
    sequence_.store(s + 1, std::memory_order_relaxed);  // odd: writing
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(words[i], std::memory_order_relaxed);
    sequence_.store(s + 2, std::memory_order_release);
  }

  /// false when nothing was published yet or the writer kept writing.
  bool read(T& out) const {
    for (int attempt = 0; attempt < 64; ++attempt) {
      const std::uint32_t s1 = sequence_.load(std::memory_order_acquire);
      if (s1 & 1U) continue;
      std::array<std::uint64_t, kWords> words{};
      for (std::size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (sequence_.load(std::memory_order_relaxed) != s1) continue;
      if (s1 == 0) return false;
      std::memcpy(static_cast<void*>(&out), words.data(), sizeof(T));
      return true;
    }
    return false;
  }

 private:
  std::atomic<std::uint32_t> sequence_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace model::diagnosis
