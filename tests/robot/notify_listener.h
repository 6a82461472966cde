// A stand-in for systemd's notification socket, made as systemd makes its own: an AF_UNIX
// datagram socket with SO_PASSCRED, so that each message comes with the sender's process ID
// (what NotifyAccess=main checks). For the tests of firmware-bridge/protocol/notify_socket.h,
// the daemons' tests, and `dg_notify_listen` in the SocketCAN VM.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>
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
    else if (::bind(fd, reinterpret_cast<sockaddr*>(&a), len) != 0)
      error = address + ": bind: " + std::strerror(errno);
  }
  ~NotifyListener() {
    if (fd >= 0) ::close(fd);
    if (!address.empty() && address[0] == '/') ::unlink(address.c_str());
  }
  NotifyListener(const NotifyListener&) = delete;
  NotifyListener& operator=(const NotifyListener&) = delete;

  // What take() heard, in order, and whether any of it came from another process than asked.
  std::vector<std::string> heard;
  bool other_sender = false;
  // Every message waiting, into `heard`. Call it as systemd reads, as the messages come: a
  // datagram socket queues only net.unix.max_dgram_qlen (10) of them, and a send to a full one
  // fails.
  void take(pid_t from) {
    pid_t sender = 0;
    for (std::string m; !(m = receive(&sender)).empty();) {
      heard.push_back(m);
      if (sender != from) other_sender = true;
    }
  }
  long count(const std::string& message) const {
    long n = 0;
    for (const auto& m : heard) n += m == message;
    return n;
  }
  // What is wrong with `heard` for a daemon that ran `ran_s` seconds with its watchdog's pings
  // `least_s` to `most_s` apart: READY=1 first, STOPPING=1 last, WATCHDOG=1 between and nothing
  // else, all from the process asked; at least half the pings the longest spacing gives (a slow
  // host), never more than the shortest allows. Empty when nothing is.
  std::string wrong_with_what_was_said(double ran_s, double least_s, double most_s) const {
    const std::string got =
        " (heard " + std::to_string(heard.size()) + " messages over " + std::to_string(ran_s) + " s)";
    if (heard.size() < 3) return "fewer than 3 messages" + got;
    if (heard.front() != "READY=1") return "first '" + heard.front() + "', not READY=1" + got;
    if (heard.back() != "STOPPING=1") return "last '" + heard.back() + "', not STOPPING=1" + got;
    if (other_sender) return "a message from another process" + got;
    const long pings = count("WATCHDOG=1");
    if (static_cast<size_t>(pings) + 2 != heard.size()) return "other messages than READY, WATCHDOG and STOPPING" + got;
    if (pings < static_cast<long>(ran_s / most_s / 2)) return std::to_string(pings) + " pings: too few" + got;
    if (pings > static_cast<long>(ran_s / least_s) + 1) return std::to_string(pings) + " pings: too many" + got;
    return "";
  }
  // The next message and its sender's process ID; "" when none is waiting.
  std::string receive(pid_t* sender = nullptr) {
    char buf[256];
    iovec iov{buf, sizeof buf};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(ucred))];
    msghdr m{};
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control;
    m.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd, &m, MSG_DONTWAIT);
    if (n < 0) return "";
    for (cmsghdr* c = CMSG_FIRSTHDR(&m); c; c = CMSG_NXTHDR(&m, c))
      if (sender && c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_CREDENTIALS) {
        ucred cred;
        std::memcpy(&cred, CMSG_DATA(c), sizeof cred);
        *sender = cred.pid;
      }
    return std::string(buf, static_cast<size_t>(n));
  }
};

}  // namespace dressguard::testkit
