// The bridge's real-time setup (rt_setup.h).
#include "rt_setup.h"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace dressguard::bridge {
namespace {

std::string memory_lock_failure(int err) {
  return std::string("mlockall failed (") + std::strerror(err) +
         "): the loop's pages may fault in while a stop is written; grant CAP_IPC_LOCK or LimitMEMLOCK=infinity";
}

std::string cpu_pinning_failure(int cpu, int err) {
  return "pinning to CPU " + std::to_string(cpu) + " failed (" + std::strerror(err) +
         "): the loop runs on any CPU (is CPU " + std::to_string(cpu) + " online and in the process's cpuset?)";
}

// Said as a warning with what it means for the loop, or as the reason the bridge does not start.
std::string fifo_failure(int priority, int err) {
  return "SCHED_FIFO priority " + std::to_string(priority) + " not had (" + std::strerror(err) +
         "; grant CAP_SYS_NICE or LimitRTPRIO=" + std::to_string(priority) + ")";
}

// The stack the loop may use, faulted in now: a page first touched later faults (even locked,
// MCL_FUTURE only keeps it once it is there) in the middle of a stop's write.
[[gnu::noinline]] void prefault_stack() {
  constexpr std::size_t kReserve = 256 * 1024, kPage = 4096;
  [[maybe_unused]] volatile char reserve[kReserve];
  for (std::size_t i = 0; i < kReserve; i += kPage) reserve[i] = 0;
}

// Whether the process's effective capabilities hold CAP_IPC_LOCK (bit 14 of /proc's CapEff),
// which lifts RLIMIT_MEMLOCK.
bool can_lock_past_the_limit() {
  constexpr unsigned kCapIpcLock = 14;
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("CapEff:", 0) == 0) return (std::strtoull(line.c_str() + 7, nullptr, 16) >> kCapIpcLock) & 1;
  return false;
}

// Why locking is not even tried, or "": under a finite RLIMIT_MEMLOCK without CAP_IPC_LOCK,
// MCL_FUTURE counts every later mapping against the limit, and an allocation past it fails in
// the loop (an error, perhaps while a stop is written) where a page fault was only a delay.
std::string memory_lock_limit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_MEMLOCK, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY || can_lock_past_the_limit())
    return {};
  return "mlockall not tried: RLIMIT_MEMLOCK is " + std::to_string(limit.rlim_cur / 1024) +
         " KiB without CAP_IPC_LOCK, and locking all later memory under it makes an allocation past it fail in the "
         "loop; grant CAP_IPC_LOCK or LimitMEMLOCK=infinity";
}

std::string lock_memory() {
  if (std::string why = memory_lock_limit(); !why.empty()) return why;
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) return memory_lock_failure(errno);
  prefault_stack();
  return {};
}

std::string pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return sched_setaffinity(0, sizeof set, &set) == 0 ? std::string() : cpu_pinning_failure(cpu, errno);
}

std::string run_fifo(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  return sched_setscheduler(0, SCHED_FIFO, &param) == 0 ? std::string() : fifo_failure(priority, errno);
}

}  // namespace

RtOutcome setup_realtime(const RtRequest& request) {
  RtOutcome out;
  auto note = [&out](std::string why) {
    if (!why.empty()) out.warnings.push_back(std::move(why));
  };
  if (request.lock_memory) note(lock_memory());
  if (request.cpu >= 0) note(pin_to_cpu(request.cpu));
  if (std::string why = run_fifo(request.fifo_priority); !why.empty()) {
    if (request.priority_required) out.refusal = std::move(why);
    else out.warnings.push_back(why + ": the loop runs as SCHED_OTHER, preempted by any busy process");
  }
  return out;
}

}  // namespace dressguard::bridge
