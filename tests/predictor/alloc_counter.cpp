// Global allocation hooks for the zero-allocation tests. operator new/delete are replaced (the
// standard allows it); malloc and friends are interposed by defining them in the executable and
// forwarding to glibc's __libc_* entry points (skipped under ASan, which provides its own).
#include "alloc_counter.h"

#include <cstdlib>
#include <new>

namespace {
thread_local bool t_counting = false;
thread_local uint64_t t_allocations = 0;
inline void note() {
  if (t_counting) ++t_allocations;
}
}  // namespace

namespace dressguard::testkit {
uint64_t thread_allocations() { return t_allocations; }
void set_counting(bool on) { t_counting = on; }
#if defined(__SANITIZE_ADDRESS__)
bool malloc_intercepted() { return false; }
#else
bool malloc_intercepted() { return true; }
#endif
}  // namespace dressguard::testkit

#if !defined(__SANITIZE_ADDRESS__)
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t s) {
  note();
  return __libc_calloc(n, s);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
}
#endif

void* operator new(size_t n) {
  note();
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
