// The service manager's notification socket (systemd's sd_notify(3) protocol), as both daemons
// use it: "READY=1" once the loop runs, "WATCHDOG=1" from the loop while it keeps running,
// "STOPPING=1" when a shutdown begins. With Type=notify the manager counts a unit started only
// when its daemon says it listens (so `systemctl start` and the units ordered after it wait for
// that), and with WatchdogSec= it kills and restarts a daemon whose loop stopped saying so: a
// hung loop is found, not only a dead process.
//
// The protocol, as sd_notify(3) and systemd.service(5) define it (stable since systemd 209):
//   - NOTIFY_SOCKET holds an AF_UNIX datagram socket's address: a path ("/run/systemd/notify")
//     or, with a leading '@', an abstract name. Unset: no service manager listens.
//   - Each message is one datagram of newline-separated KEY=VALUE assignments. The manager
//     knows the sender from the credentials the kernel attaches (SO_PASSCRED on its side): the
//     process ID, for every thread of the process, which NotifyAccess=main accepts.
//   - WATCHDOG_USEC: the manager expects "WATCHDOG=1" at least this often (microseconds);
//     WATCHDOG_PID, when set, names the process the watchdog is for. sd_watchdog_enabled(3)
//     advises pinging at half the interval; so does this.
// Own code rather than libsystemd: sd_notify() opens, connects and closes a socket on each call;
// here the socket is opened once at start, and a ping from the real-time loop is one send(2):
// no allocation, no lock, no blocking (MSG_DONTWAIT: a manager whose queue is full loses a
// ping, not the loop its time). Without a service manager every call does nothing.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

namespace dressguard::service {

class NotifySocket {
 public:
  // No service manager: every call does nothing.
  NotifySocket() = default;
  // From the process's environment (NOTIFY_SOCKET, WATCHDOG_USEC, WATCHDOG_PID).
  static NotifySocket from_environment();
  // From the three values (null: unset) for the process `self`; what from_environment() does.
  static NotifySocket open(const char* notify_socket, const char* watchdog_usec, const char* watchdog_pid, long self);

  NotifySocket(NotifySocket&& o) noexcept;
  NotifySocket& operator=(NotifySocket&& o) noexcept;
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;
  ~NotifySocket();

  // NOTIFY_SOCKET was set: a service manager expects to hear from this process.
  bool requested() const { return requested_; }
  // A service manager listens (the socket is open and connected).
  bool connected() const { return fd_ >= 0; }
  // What went wrong reading the environment or opening the socket, one line naming the variable
  // and its value; empty when nothing did. With requested() and not connected(), the manager
  // would never hear READY=1 and would end the start at TimeoutStartSec=, then restart the unit,
  // over and over: the daemons exit 2 at start instead (the unit's RestartPreventExitStatus=).
  const std::string& error() const { return error_; }
  // The watchdog's ping period, half of WATCHDOG_USEC, in ns; 0 when no watchdog is asked for
  // this process (none, or WATCHDOG_PID names another).
  int64_t watchdog_period_ns() const { return watchdog_period_ns_; }

  // One message (sd_notify(3)'s assignments). True when it was sent or there is no manager.
  // Safe from several threads (the predictor's loop pings, its logging thread sets STATUS=): a
  // datagram goes out whole, and the failure counts are atomic.
  bool notify(const char* state) noexcept;
  // "READY=1", and the watchdog's first ping is due one period after `now_ns`. True when sent;
  // when the manager's queue was full (EAGAIN, ENOBUFS) on_tick() sends it again, as a lost
  // READY=1 would have the manager end the start at its timeout.
  bool ready(int64_t now_ns) noexcept;
  // Call from the loop on each wakeup it gets anyway (the daemons' timer ticks): READY=1 again if
  // it is still to go out, and "WATCHDOG=1" when a period has passed since the last one (or since
  // ready()); one that met a full queue is tried again at the next tick, not a period later (two
  // lost pings in a row would be the watchdog's end). True when it sent a ping.
  bool on_tick(int64_t now_ns) noexcept;
  // Sends that failed (the manager's queue full, the manager gone); the last one's errno.
  uint64_t failed_sends() const { return failed_sends_.load(std::memory_order_relaxed); }
  int last_errno() const { return last_errno_.load(std::memory_order_relaxed); }

 private:
  // 0 when `state` went out, else the send's errno (counted).
  int send_state(const char* state) noexcept;

  int fd_ = -1;
  bool requested_ = false;
  bool ready_pending_ = false;  // READY=1 met a full queue: on_tick() sends it again
  std::string error_;
  int64_t watchdog_period_ns_ = 0;
  int64_t next_ping_ns_ = 0;
  std::atomic<uint64_t> failed_sends_{0};
  std::atomic<int> last_errno_{0};
};

}  // namespace dressguard::service
