// The bridge's real-time setup: locked memory, SCHED_FIFO and an optional CPU for its one thread,
// the loop that carries the sensor's readings to CAN and the predictor's Stop to the robot. Its
// own code, not the predictor's: the CAN protocol header is all the two programs share.
#pragma once

#include <string>
#include <vector>

namespace dressguard::bridge {

// The default SCHED_FIFO priority: above PREEMPT_RT's interrupt threads (50), so that a storm of
// interrupts of other devices (disk, network) does not hold the loop, and below the predictor's
// 80 (predictor/daemon/dressguard-predictor.conf): on a CPU the two share, the predictor's work
// on a sample, which decides a stop, runs first; the bridge's per-frame work is short, and it
// sleeps in epoll or in a Modbus wait, where the CAN and serial interrupt threads it waits on
// run. Well below the kernel's own 99 (watchdogs, migration).
constexpr int kDefaultFifoPriority = 70;

struct RtRequest {
  bool lock_memory = true;
  int fifo_priority = kDefaultFifoPriority;  // 1-99
  // Given on the command line: a deployment that asks for a priority and does not get it must
  // not run as if it had it (the bridge refuses to start); the default is only a warning.
  bool priority_required = false;
  int cpu = -1;  // -1: no pinning
};

struct RtOutcome {
  std::vector<std::string> warnings;  // each step not had: what failed, why, and what grants it
  std::string refusal;                // the required priority not had: the bridge must not start
};

// Applies `request` to the calling thread (and the process's memory). Call it on the loop's
// thread before the loop starts; threads started later inherit the policy and the CPU.
RtOutcome setup_realtime(const RtRequest& request);

}  // namespace dressguard::bridge
