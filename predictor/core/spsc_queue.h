// A bounded lock-free single-producer single-consumer ring: how the real-time thread hands events
// to the normal-priority logging thread without a lock, an allocation or a system call.
//
// Lamport's ring with acquire/release indices: the producer owns `head_`, the consumer `tail_`;
// each reads the other's index with acquire and publishes its own with release, so a slot's
// contents are visible before its index is. Capacity is a power of two; one slot stays empty to
// tell full from empty. A full queue refuses the push (the producer counts the loss) rather than
// blocking the real-time thread.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace dressguard::predictor {

template <typename T, size_t Capacity>
class SpscQueue {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity must be a power of two");

 public:
  // Producer only. False when full (the item is not queued).
  bool push(const T& item) noexcept {
    const size_t head = head_.load(std::memory_order_relaxed);
    const size_t next = (head + 1) & (Capacity - 1);
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head] = item;
    head_.store(next, std::memory_order_release);
    return true;
  }
  // Consumer only. False when empty.
  bool pop(T& out) noexcept {
    const size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail];
    tail_.store((tail + 1) & (Capacity - 1), std::memory_order_release);
    return true;
  }
  // Items refused because the queue was full.
  uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::array<T, Capacity> slots_{};
  alignas(64) std::atomic<size_t> head_{0};
  alignas(64) std::atomic<size_t> tail_{0};
  alignas(64) std::atomic<uint64_t> dropped_{0};
};

}  // namespace dressguard::predictor
