// The service manager's notification socket (firmware-bridge/protocol/notify_socket.h) against a
// listener made as systemd makes its own: an AF_UNIX datagram socket with SO_PASSCRED, so that
// each message comes with the sender's process ID, which is what NotifyAccess=main checks.
// Path and abstract addresses, the watchdog's period (half of WATCHDOG_USEC) and its pacing,
// WATCHDOG_PID of another process, each malformed variable, a manager that is not there.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "notify_listener.h"
#include "notify_socket.h"

using dressguard::service::NotifySocket;
using dressguard::testkit::NotifyListener;

namespace {

constexpr int64_t kMs = 1'000'000;

}  // namespace

TEST(NotifySocket, ReadyReachesTheManagerWithThisProcessAsSender) {
  for (const bool abstract : {false, true}) {
    NotifyListener m(abstract);
    ASSERT_EQ(m.error, "");
    NotifySocket s = NotifySocket::open(m.address.c_str(), nullptr, nullptr, ::getpid());
    ASSERT_TRUE(s.connected()) << m.address << ": " << s.error();
    EXPECT_EQ(s.error(), "");
    EXPECT_EQ(s.watchdog_period_ns(), 0) << "no WATCHDOG_USEC: no watchdog";
    // From another thread of the process: the manager still sees the process (NotifyAccess=main
    // accepts it), as the daemons' loop threads send.
    std::thread([&] { EXPECT_TRUE(s.ready(0)); }).join();
    pid_t sender = 0;
    EXPECT_EQ(m.receive(&sender), "READY=1") << m.address;
    EXPECT_EQ(sender, ::getpid());
    EXPECT_TRUE(s.notify("STOPPING=1"));
    EXPECT_EQ(m.receive(), "STOPPING=1");
    EXPECT_FALSE(s.on_tick(1'000'000 * kMs)) << "no watchdog asked for: no ping";
    EXPECT_EQ(m.receive(), "");
    EXPECT_EQ(s.failed_sends(), 0u);
  }
}

TEST(NotifySocket, WatchdogPingsAtHalfTheManagersInterval) {
  NotifyListener m(false);
  // WatchdogSec=2 gives WATCHDOG_USEC=2000000: a ping at least every second.
  NotifySocket s = NotifySocket::open(m.address.c_str(), "2000000", nullptr, ::getpid());
  ASSERT_TRUE(s.connected()) << s.error();
  EXPECT_EQ(s.watchdog_period_ns(), 1000 * kMs);
  const int64_t t0 = 5000 * kMs;
  s.ready(t0);
  EXPECT_EQ(m.receive(), "READY=1");
  // The loop's 1 ms ticks: one ping per period, the first a period after ready.
  int pings = 0;
  for (int64_t t = t0; t <= t0 + 3500 * kMs; t += kMs) {
    const bool sent = s.on_tick(t);
    if (sent) {
      ++pings;
      EXPECT_EQ(m.receive(), "WATCHDOG=1") << "at " << (t - t0) / kMs << " ms";
      EXPECT_EQ((t - t0) % (1000 * kMs), 0) << "a ping between periods, at " << (t - t0) / kMs << " ms";
    }
  }
  EXPECT_EQ(pings, 3) << "1 s, 2 s and 3 s after ready";
  EXPECT_EQ(m.receive(), "");
  // A late loop pings at its next tick and the period runs from there: no burst to catch up.
  EXPECT_TRUE(s.on_tick(t0 + 9000 * kMs));
  EXPECT_FALSE(s.on_tick(t0 + 9500 * kMs));
  EXPECT_TRUE(s.on_tick(t0 + 10000 * kMs));
}

TEST(NotifySocket, WatchdogOfAnotherProcessIsNotFed) {
  NotifyListener m(false);
  const long self = ::getpid();
  EXPECT_EQ(NotifySocket::open(m.address.c_str(), "500000", std::to_string(self).c_str(), self).watchdog_period_ns(),
            250 * kMs);
  // A WATCHDOG_PID inherited from a parent: its watchdog, not this process's.
  NotifySocket other = NotifySocket::open(m.address.c_str(), "500000", std::to_string(self + 1).c_str(), self);
  EXPECT_TRUE(other.connected());
  EXPECT_EQ(other.error(), "");
  EXPECT_EQ(other.watchdog_period_ns(), 0);
  // No socket: nothing to ping, whatever the interval says.
  EXPECT_EQ(NotifySocket::open(nullptr, "500000", nullptr, self).watchdog_period_ns(), 0);
}

TEST(NotifySocket, WithoutAManagerEveryCallDoesNothing) {
  for (const char* unset : {static_cast<const char*>(nullptr), ""}) {
    NotifySocket s = NotifySocket::open(unset, nullptr, nullptr, ::getpid());
    EXPECT_FALSE(s.connected());
    EXPECT_EQ(s.error(), "");
    EXPECT_TRUE(s.ready(0));
    EXPECT_FALSE(s.on_tick(1'000'000 * kMs));
    EXPECT_EQ(s.failed_sends(), 0u);
  }
}

TEST(NotifySocket, MalformedVariablesAndAnAbsentManagerAreNamed) {
  const long self = ::getpid();
  struct Case {
    const char *sock, *usec, *pid, *want;
  } cases[] = {
      {"run/notify", nullptr, nullptr,
       "NOTIFY_SOCKET='run/notify' is neither an absolute path of at most 107 bytes nor an '@'"},
      {"@", nullptr, nullptr, "NOTIFY_SOCKET='@' is neither"},
      {"/nonexistent-dg/notify", nullptr, nullptr,
       "NOTIFY_SOCKET='/nonexistent-dg/notify': connect: No such file or directory"},
      {"/tmp/x", "2s", nullptr, "WATCHDOG_USEC='2s' is not a whole number of microseconds"},
      {"/tmp/x", "-5", nullptr, "WATCHDOG_USEC='-5' is not a whole number"},
      {"/tmp/x", "0", nullptr, "WATCHDOG_USEC='0' is not a whole number"},
      {"/tmp/x", "100000", "12ab", "WATCHDOG_PID='12ab' is not a process ID"},
  };
  for (const Case& c : cases) {
    const NotifySocket s = NotifySocket::open(c.sock, c.usec, c.pid, self);
    EXPECT_NE(s.error().find(c.want), std::string::npos) << "got: " << s.error();
    EXPECT_EQ(s.watchdog_period_ns(), 0) << c.want;
  }
  // sun_path's 108 bytes: a path's NUL among them, an abstract name's not.
  auto error_of = [&](const std::string& address) {
    return NotifySocket::open(address.c_str(), nullptr, nullptr, self).error();
  };
  const std::string path_108 = "/" + std::string(107, 'x');
  EXPECT_NE(error_of(path_108).find("absolute path of at most 107"), std::string::npos);
  const std::string path_107 = "/nonexistent-dg/" + std::string(91, 'x');
  EXPECT_NE(error_of(path_107).find("connect: No such file"), std::string::npos)
      << "a 107-byte path is an address: it is only not there";
  const std::string abstract_108 = "@" + std::string(107, 'x');
  EXPECT_NE(error_of(abstract_108).find("connect: Connection refused"), std::string::npos);
  const std::string abstract_109 = "@" + std::string(108, 'x');
  EXPECT_NE(error_of(abstract_109).find("'@' abstract name of at most 108"), std::string::npos);
}

TEST(NotifySocket, AManagerGoneIsCountedNotSignalled) {
  NotifySocket s;
  {
    NotifyListener m(false);
    s = NotifySocket::open(m.address.c_str(), "1000", nullptr, ::getpid());
    ASSERT_TRUE(s.connected()) << s.error();
  }
  // Its socket closed: the sends fail (ECONNREFUSED, then ENOTCONN: the kernel drops the
  // association), counted, and not retried at each tick; no SIGPIPE ends the test.
  EXPECT_FALSE(s.ready(0));
  EXPECT_EQ(s.last_errno(), ECONNREFUSED) << std::strerror(s.last_errno());
  EXPECT_FALSE(s.on_tick(kMs)) << "a ping was due, and failed";
  EXPECT_EQ(s.failed_sends(), 2u) << "READY=1 is not sent again to a manager that is gone";
  EXPECT_TRUE(s.last_errno() == ECONNREFUSED || s.last_errno() == ENOTCONN) << std::strerror(s.last_errno());
  EXPECT_FALSE(s.on_tick(kMs + 100'000)) << "the next ping a period later, not at the next tick";
  EXPECT_EQ(s.failed_sends(), 2u);
}

// A manager whose queue is full (systemd busy at boot; a datagram socket queues only
// net.unix.max_dgram_qlen messages): READY=1 and a ping that met it go out at the next tick
// once there is room, not never (READY) or a period later (two lost pings end the watchdog).
TEST(NotifySocket, AFullQueueIsRetriedAtTheNextTick) {
  NotifyListener m(false);
  ASSERT_EQ(m.error, "");
  NotifySocket s = NotifySocket::open(m.address.c_str(), "20000", nullptr, ::getpid());  // a ping every 10 ms
  ASSERT_TRUE(s.connected()) << s.error();
  auto fill = [&] {
    for (int i = 0; i < 10000 && s.notify("STATUS=filler"); ++i) {
    }
    return s.last_errno();
  };
  auto drain = [&] {
    while (!m.receive().empty()) {
    }
  };
  ASSERT_EQ(fill(), EAGAIN) << std::strerror(s.last_errno());
  const int64_t t0 = 1000 * kMs;
  EXPECT_FALSE(s.ready(t0)) << "the queue is full";
  EXPECT_FALSE(s.on_tick(t0 + kMs));  // still full: READY=1 tried again, in vain
  drain();
  EXPECT_FALSE(s.on_tick(t0 + 2 * kMs)) << "READY=1 goes out; no ping is due yet";
  EXPECT_EQ(m.receive(), "READY=1");
  EXPECT_EQ(m.receive(), "") << "READY=1 once";
  ASSERT_EQ(fill(), EAGAIN);
  EXPECT_FALSE(s.on_tick(t0 + 10 * kMs)) << "the ping was due and met a full queue";
  drain();
  EXPECT_TRUE(s.on_tick(t0 + 11 * kMs)) << "tried again at the next tick";
  EXPECT_EQ(m.receive(), "WATCHDOG=1");
  EXPECT_FALSE(s.on_tick(t0 + 12 * kMs)) << "and the period runs from there";
  EXPECT_TRUE(s.on_tick(t0 + 21 * kMs));
}
