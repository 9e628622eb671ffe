// Threads with explicit attributes: see hal/thread.hpp.
#include "hal/thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <utility>

namespace hal {
namespace {

constexpr std::size_t kMinStackBytes = 16 * 1024;
constexpr std::size_t kNameChars = 15;  // pthread_setname_np: 16 bytes with the terminator

bool is_realtime(SchedPolicy p) { return p == SchedPolicy::kFifo || p == SchedPolicy::kRoundRobin; }
bool uses_nice(SchedPolicy p) { return p == SchedPolicy::kOther || p == SchedPolicy::kBatch; }

int os_policy(SchedPolicy p) {
  switch (p) {
    case SchedPolicy::kOther:
      return SCHED_OTHER;
    case SchedPolicy::kBatch:
      return SCHED_BATCH;
    case SchedPolicy::kIdle:
      return SCHED_IDLE;
    case SchedPolicy::kFifo:
      return SCHED_FIFO;
    case SchedPolicy::kRoundRobin:
      return SCHED_RR;
  }
  return SCHED_OTHER;
}

}  // namespace

const char* to_string(SchedPolicy policy) {
  switch (policy) {
    case SchedPolicy::kOther:
      return "other";
    case SchedPolicy::kBatch:
      return "batch";
    case SchedPolicy::kIdle:
      return "idle";
    case SchedPolicy::kFifo:
      return "fifo";
    case SchedPolicy::kRoundRobin:
      return "rr";
  }
  return "?";
}

std::string validate(const ThreadAttributes& a) {
  if (a.name == nullptr || a.name[0] == '\0') return "name: empty";
  if (is_realtime(a.policy) && (a.priority < 1 || a.priority > 99)) {
    return "priority: " + std::to_string(a.priority) + " is outside 1..99 for policy " +
           to_string(a.policy);
  }
  if (uses_nice(a.policy) && (a.priority < -20 || a.priority > 19)) {
    return "priority: nice value " + std::to_string(a.priority) +
           " is outside -20..19 for policy " + to_string(a.policy);
  }
  if (a.cpu < -1) return "cpu: " + std::to_string(a.cpu) + " (expected -1 for any, or a CPU index)";
  if (a.stack_bytes != 0 && a.stack_bytes < kMinStackBytes) {
    return "stack_bytes: " + std::to_string(a.stack_bytes) + " is below the 16 KiB minimum";
  }
  return {};
}

struct Thread::Impl {
  ThreadAttributes attributes;
  std::function<void()> body;
  ThreadReport* report = nullptr;
  std::mutex mutex;
  std::condition_variable cv;
  bool applied = false;  // guarded by mutex
  pthread_t handle{};

  // Runs on the new thread: applies what can only be applied from inside, then the body.
  static void* trampoline(void* arg) {
    auto* self = static_cast<Impl*>(arg);
    self->apply();
    self->body();
    return nullptr;
  }

  void apply() {
    ThreadReport& r = *report;
    char name[kNameChars + 1] = {};
    std::strncpy(name, attributes.name, kNameChars);
    r.name_applied = pthread_setname_np(pthread_self(), name) == 0;
    if (attributes.cpu >= 0) {
      cpu_set_t set;
      CPU_ZERO(&set);
      if (attributes.cpu < CPU_SETSIZE) CPU_SET(attributes.cpu, &set);
      const int e = attributes.cpu < CPU_SETSIZE
                        ? pthread_setaffinity_np(pthread_self(), sizeof set, &set)
                        : EINVAL;
      r.affinity_applied = e == 0;
      r.affinity_errno = e;
    }
    sched_param param{};
    param.sched_priority = is_realtime(attributes.policy) ? attributes.priority : 0;
    int e = pthread_setschedparam(pthread_self(), os_policy(attributes.policy), &param);
    if (e == 0 && uses_nice(attributes.policy)) {
      // The nice value is per thread on Linux and inherited from the creator: always set it,
      // with setpriority() on the thread id.
      errno = 0;
      if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), attributes.priority) != 0) {
        e = errno;
      }
    }
    r.policy_applied = e == 0;
    r.policy_errno = e;
    if (e != 0) {
      // Whatever part was applied, fall back to a known state: SCHED_OTHER at nice 0.
      sched_param zero{};
      (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &zero);
      (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 0);
    }
    std::string w;
    if (!r.policy_applied) {
      w += std::string("policy ") + to_string(attributes.policy) + " priority " +
           std::to_string(attributes.priority) + " refused (" + std::strerror(r.policy_errno) +
           "), running SCHED_OTHER at nice 0";
    }
    if (!r.affinity_applied) {
      if (!w.empty()) w += "; ";
      w += "CPU " + std::to_string(attributes.cpu) + " refused (" +
           std::strerror(r.affinity_errno) + "), running on any CPU";
    }
    if (!w.empty()) r.warning = std::string("thread '") + name + "': " + w;
    {
      std::lock_guard lock(mutex);
      applied = true;
    }
    cv.notify_one();
  }
};

Thread::Thread() = default;
Thread::~Thread() { join(); }

Status Thread::start(const ThreadAttributes& attributes, std::function<void()> body) {
  if (impl_) return Status::kWrongState;
  if (!validate(attributes).empty() || !body) return Status::kInvalidConfig;
  report_ = ThreadReport{};
  auto impl = std::make_unique<Impl>();
  impl->attributes = attributes;
  impl->body = std::move(body);
  impl->report = &report_;

  pthread_attr_t attr;
  if (pthread_attr_init(&attr) != 0) return Status::kIoError;
  // Start from a known scheduling state whatever the creating thread runs at; the new
  // thread then applies its own policy (so a refusal can fall back instead of failing).
  sched_param zero{};
  (void)pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  (void)pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  (void)pthread_attr_setschedparam(&attr, &zero);
  if (attributes.stack_bytes != 0) {
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    std::size_t stack = (attributes.stack_bytes + page - 1) / page * page;
    if (stack < static_cast<std::size_t>(PTHREAD_STACK_MIN)) {
      stack = static_cast<std::size_t>(PTHREAD_STACK_MIN);
    }
    if (pthread_attr_setstacksize(&attr, stack) != 0) {
      pthread_attr_destroy(&attr);
      return Status::kInvalidConfig;
    }
  }
  const int e = pthread_create(&impl->handle, &attr, &Impl::trampoline, impl.get());
  std::size_t granted = 0;
  if (e == 0 && attributes.stack_bytes != 0) (void)pthread_attr_getstacksize(&attr, &granted);
  pthread_attr_destroy(&attr);
  if (e != 0) {
    report_.warning =
        std::string("thread '") + attributes.name + "': pthread_create failed: " + std::strerror(e);
    return Status::kIoError;
  }
  {
    std::unique_lock lock(impl->mutex);
    impl->cv.wait(lock, [&] { return impl->applied; });
  }
  report_.started = true;
  report_.stack_bytes = granted;
  impl_ = std::move(impl);
  return Status::kOk;
}

void Thread::join() {
  if (!impl_) return;
  pthread_join(impl_->handle, nullptr);
  impl_.reset();
}

}  // namespace hal
