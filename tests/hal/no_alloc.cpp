// Counting global operator new for no_alloc.hpp: counts only on threads inside
// a no_alloc::Scope, so I/O threads of the backends do not disturb the count.
// GCC 12 (with ASan) inlines the replaced operator delete below into gtest's
// code and then mistakes free() on operator new's malloc() for a mismatch;
// both are ours and match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#include "no_alloc.hpp"

#include <cstdlib>
#include <new>

namespace {
thread_local int g_depth = 0;
thread_local std::size_t g_count = 0;

void* counted(std::size_t n) {
  if (g_depth > 0) ++g_count;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return counted(n); }
void* operator new[](std::size_t n) { return counted(n); }
// The nothrow forms too (std::stable_sort's temporary buffer): otherwise the runtime's own
// nothrow new pairs with the free() below, an alloc-dealloc mismatch under ASan.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  if (g_depth > 0) ++g_count;
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace no_alloc {
std::size_t count() { return g_count; }
Scope::Scope() : start_(g_count) { ++g_depth; }
Scope::~Scope() { --g_depth; }
std::size_t Scope::allocations() const { return g_count - start_; }
}  // namespace no_alloc
