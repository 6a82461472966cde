// Counts heap allocations (operator new and malloc/calloc/realloc) made by the calling thread
// while a counting scope is open: the proof that real-time code allocates nothing.
#pragma once

#include <cstdint>

namespace dressguard::testkit {

// Allocations by this thread since the last reset (only while counting() is on).
uint64_t thread_allocations();
void set_counting(bool on);
// Whether malloc itself is intercepted (not under AddressSanitizer, which owns malloc).
bool malloc_intercepted();

struct CountAllocations {
  CountAllocations() { set_counting(true); start = thread_allocations(); }
  ~CountAllocations() { set_counting(false); }
  uint64_t count() const { return thread_allocations() - start; }
  uint64_t start;
};

}  // namespace dressguard::testkit
