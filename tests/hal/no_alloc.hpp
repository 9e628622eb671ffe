#pragma once
// Counts heap allocations made by the current thread while a NoAllocScope is
// alive (a counting global operator new, defined in no_alloc.cpp, which each
// test binary that uses this links once). Used to show that the RT-side calls
// (read/publish/health) allocate nothing. Test-only.
#include <cstddef>

namespace no_alloc {

/// Allocations counted on this thread so far.
std::size_t count();

class Scope {
 public:
  Scope();
  ~Scope();
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;
  /// Allocations on this thread since the scope began.
  std::size_t allocations() const;

 private:
  std::size_t start_;
};

}  // namespace no_alloc
