// A stand-in for systemd's notification socket, made as systemd makes its own: an AF_UNIX
// datagram socket with SO_PASSCRED, so that each message comes with the sender's process ID
// (what NotifyAccess=main checks). For the tests of firmware-bridge/protocol/notify_socket.h,
// the daemons' tests, and `dg_notify_listen` in the SocketCAN VM.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace dressguard::testkit {

// What systemd does with its notify socket: bind, SO_PASSCRED, read datagrams with credentials.
struct NotifyListener {
  int fd = -1;
  std::string address;  // as NOTIFY_SOCKET says it: "/path" or "@abstract-name"
  std::string error;    // what failed making it; empty when it listens

  // A fresh address of this process: a path in the temporary folder, or an abstract name.
  static std::string fresh_address(bool abstract) {
    const std::string name = "dg-notify-" + std::to_string(::getpid());
    return abstract ? "@" + name : (std::filesystem::temp_directory_path() / name).string();
  }
  explicit NotifyListener(bool abstract) : NotifyListener(fresh_address(abstract)) {}
  explicit NotifyListener(std::string at) : address(std::move(at)) {
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    if (address.size() < 2 || address.size() >= sizeof a.sun_path || (address[0] != '/' && address[0] != '@')) {
      error = "'" + address + "' is neither an absolute path nor an '@' name";
      return;
    }
    std::memcpy(a.sun_path, address.c_str(), address.size());
    socklen_t len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + address.size());
    if (address[0] == '@') a.sun_path[0] = '\0';
    else {
      ++len;  // the path's NUL
      ::unlink(address.c_str());
    }
    const int one = 1;
    fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0) error = std::string("socket: ") + std::strerror(errno);
    else if (::setsockopt(fd, SOL_SOCKET, SO_PASSCRED, &one, sizeof one) != 0)
      error = std::string("SO_PASSCRED: ") + std::strerror(errno);
    else if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) != 0)
      error = std::string("SO_TIMESTAMPNS: ") + std::strerror(errno);
    else if (::bind(fd, reinterpret_cast<sockaddr*>(&a), len) != 0)
      error = address + ": bind: " + std::strerror(errno);
  }
  ~NotifyListener() {
    if (fd >= 0) ::close(fd);
    if (!address.empty() && address[0] == '/') ::unlink(address.c_str());
  }
  NotifyListener(const NotifyListener&) = delete;
  NotifyListener& operator=(const NotifyListener&) = delete;

  // What take() heard, in order, when the kernel queued each (SO_TIMESTAMPNS: the send's time,
  // however late the test reads it; CLOCK_REALTIME, s), and whether any of it came from another
  // process than asked.
  std::vector<std::string> heard;
  std::vector<double> heard_at_s;
  bool other_sender = false;
  // Every message waiting, into `heard`. Call it as systemd reads, as the messages come: a
  // datagram socket queues only net.unix.max_dgram_qlen (10) of them, and a send to a full one
  // fails.
  void take(pid_t from) {
    for (;;) {
      pid_t sender = 0;
      double at_s = 0;
      const std::string m = receive(&sender, &at_s);
      if (m.empty()) return;
      heard.push_back(m);
      heard_at_s.push_back(at_s);
      if (sender != from) other_sender = true;
    }
  }
  // Takes, as systemd reads, until `message` has come or `most_ms` has passed: whether it came.
  bool wait_for(const std::string& message, pid_t from, int most_ms = 2000) {
    for (int waited = 0; count(message) == 0 && waited < most_ms; waited += 5) {
      const timespec pause{0, 5'000'000};
      nanosleep(&pause, nullptr);
      take(from);
    }
    return count(message) > 0;
  }
  long count(const std::string& message) const {
    long n = 0;
    for (const auto& m : heard) n += m == message;
    return n;
  }
  // What is wrong with `heard` for a daemon whose watchdog's pings come `least_s` to `most_s`
  // apart: READY=1 first, STOPPING=1 last, WATCHDOG=1 between, and nothing else but status
  // lines (STATUS=), all from the process asked; between READY's and STOPPING's arrival at
  // least half the pings the longest spacing gives (a slow host), never more than the shortest
  // allows. Empty when nothing is.
  std::string wrong_with_what_was_said(double least_s, double most_s) const {
    std::vector<std::string> said;
    std::vector<double> at;
    for (size_t i = 0; i < heard.size(); ++i)
      if (heard[i].rfind("STATUS=", 0) != 0) {
        said.push_back(heard[i]);
        at.push_back(heard_at_s[i]);
      }
    const double window_s = said.empty() ? 0 : at.back() - at.front();
    const std::string got =
        " (heard " + std::to_string(said.size()) + " messages over " + std::to_string(window_s) + " s)";
    if (said.size() < 3) return "fewer than 3 messages" + got;
    if (said.front() != "READY=1") return "first '" + said.front() + "', not READY=1" + got;
    if (said.back() != "STOPPING=1") return "last '" + said.back() + "', not STOPPING=1" + got;
    if (other_sender) return "a message from another process" + got;
    const long pings = count("WATCHDOG=1");
    if (static_cast<size_t>(pings) + 2 != said.size()) return "other messages than READY, WATCHDOG, STOPPING" + got;
    if (pings < static_cast<long>(window_s / most_s / 2)) return std::to_string(pings) + " pings: too few" + got;
    if (pings > static_cast<long>(window_s / least_s) + 1) return std::to_string(pings) + " pings: too many" + got;
    return "";
  }
  // The next message, its sender's process ID and when the kernel queued it; "" when none is
  // waiting. A message longer than systemd's own 4096-byte buffer comes back as "TRUNCATED".
  std::string receive(pid_t* sender = nullptr, double* at_s = nullptr) {
    char buf[4096];
    iovec iov{buf, sizeof buf};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(ucred)) + CMSG_SPACE(sizeof(timespec))];
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control;
    m.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd, &m, MSG_DONTWAIT);
    if (n < 0) return "";
    if (m.msg_flags & MSG_TRUNC) return "TRUNCATED";
    for (cmsghdr* c = CMSG_FIRSTHDR(&m); c; c = CMSG_NXTHDR(&m, c)) {
      if (sender && c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_CREDENTIALS) {
        ucred cred;
        std::memcpy(&cred, CMSG_DATA(c), sizeof cred);
        *sender = cred.pid;
      }
      if (at_s && c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec ts;
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        *at_s = static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
      }
    }
    return std::string(buf, static_cast<size_t>(n));
  }
};

}  // namespace dressguard::testkit
