#pragma once
// The mailboxes between the application's threads. model/ has no thread protocol of
// its own (a Rom and a Calibrator are plain objects owned by one thread); everything
// that crosses a thread boundary goes through one of these, each wait-free on the
// real-time side:
//
//  - Latest<T>: the latest value of a plain struct, one writer, any readers (a seqlock:
//    hal::LatestValue). The calibration thread publishes its CalibrationResult, the
//    RT thread publishes loop counters; a reader racing the writer retries a bounded
//    number of times and otherwise keeps its previous copy.
//  - Handover<T>: an object built off the RT thread (a calibrated RomData) handed to
//    the RT thread, which adopts it at a cycle boundary, and the object it replaced
//    handed back to be freed or reused off the RT thread. Nothing is ever lost or
//    overwritten: offering while an earlier offer is still untaken gives the earlier
//    one back to the offerer; when the return path is full the RT thread keeps the old
//    object and tries again next cycle.
//  - Queue<T, N>: a bounded single-producer single-consumer FIFO (snapshots, log events);
//    push() fails when full (the producer drops and counts), pop() fails when empty.
//
// Thread context: stated per member. Nothing here allocates after construction, locks
// or blocks.

#include <atomic>
#include <cstddef>
#include <memory>
#include <type_traits>

// GCC 12 reports the ring buffer's never-read storage as maybe-uninitialized when it
// inlines a pop() of a scalar payload (a false positive in Boost.Lockfree's copy_payload).
// (clang has no such warning and rejects the unknown group under -Werror.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/lockfree/spsc_queue.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "hal/latest_value.hpp"

namespace app::loop {

/// Latest value of a trivially copyable T (seqlock). write(): one thread; read(): any.
template <typename T>
using Latest = hal::LatestValue<T>;

/// Bounded SPSC FIFO of trivially copyable T with capacity N, storage inside the object.
/// push(): the producer thread only; pop(): the consumer thread only. Both wait-free.
template <typename T, std::size_t N>
class Queue {
  static_assert(std::is_trivially_copyable_v<T>, "Queue<T, N> carries plain structs");

 public:
  /// @return false when full (nothing is written; the caller counts the drop).
  bool push(const T& value) noexcept { return queue_.push(value); }
  /// @return false when empty (`out` untouched).
  bool pop(T& out) noexcept { return queue_.pop(out); }
  /// Elements waiting (consumer thread).
  std::size_t size() const noexcept { return queue_.read_available(); }
  static constexpr std::size_t capacity() noexcept { return N; }

 private:
  boost::lockfree::spsc_queue<T, boost::lockfree::capacity<N>> queue_;
};

/// Hands owned objects from one non-RT thread (the builder) to the RT thread and the
/// replaced ones back. Ownership: an object is owned by the builder until offer()
/// succeeds, by the mailbox until take(), by the RT thread until give_back(), by the
/// mailbox until reclaim(). The destructor frees what the mailbox still owns.
/// @tparam N how many replaced objects may wait to be reclaimed
template <typename T, std::size_t N = 4>
class Handover {
 public:
  Handover() = default;
  Handover(const Handover&) = delete;
  Handover& operator=(const Handover&) = delete;
  ~Handover() {
    delete offered_.exchange(nullptr, std::memory_order_acq_rel);
    T* p = nullptr;
    while (returned_.pop(p)) delete p;
  }

  /// Builder thread: offers `next` to the RT thread.
  /// @return the previous offer if the RT thread had not taken it yet (never lost:
  ///         the caller frees or re-offers it), else nullptr. Wait-free.
  std::unique_ptr<T> offer(std::unique_ptr<T> next) noexcept {
    return std::unique_ptr<T>(offered_.exchange(next.release(), std::memory_order_acq_rel));
  }
  /// RT thread: the newest offered object, now owned by the caller; nullptr when there
  /// is none. Wait-free, no allocation.
  T* take() noexcept { return offered_.exchange(nullptr, std::memory_order_acq_rel); }
  /// RT thread: hands a replaced object back. @return false when the return path is
  /// full: the caller keeps `old` and tries again later. Wait-free, no allocation.
  bool give_back(T* old) noexcept { return old == nullptr || returned_.push(old); }
  /// Builder thread: one replaced object to free or reuse; nullptr when none waits.
  std::unique_ptr<T> reclaim() noexcept {
    T* p = nullptr;
    return returned_.pop(p) ? std::unique_ptr<T>(p) : nullptr;
  }
  /// Any thread: whether an offer waits to be taken (a hint, racy by nature).
  bool pending() const noexcept { return offered_.load(std::memory_order_acquire) != nullptr; }

 private:
  std::atomic<T*> offered_{nullptr};
  boost::lockfree::spsc_queue<T*, boost::lockfree::capacity<N>> returned_;
};

}  // namespace app::loop
