// The service manager's notification socket (notify_socket.h).
#include "notify_socket.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace dressguard::service {

namespace {

// A whole decimal number in [1, max], nothing else around it (no sign, no spaces).
bool whole_number(const char* s, unsigned long long max, unsigned long long* out) {
  if (!s || *s < '0' || *s > '9') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(s, &end, 10);
  if (errno != 0 || *end != '\0' || v == 0 || v > max) return false;
  *out = v;
  return true;
}

// `what` after what `to` already says.
void add_error(std::string& to, const std::string& what) { to += (to.empty() ? "" : "; ") + what; }

}  // namespace

NotifySocket NotifySocket::from_environment() {
  return open(std::getenv("NOTIFY_SOCKET"), std::getenv("WATCHDOG_USEC"), std::getenv("WATCHDOG_PID"),
              static_cast<long>(::getpid()));
}

NotifySocket NotifySocket::open(const char* notify_socket, const char* watchdog_usec, const char* watchdog_pid,
                                long self) {
  NotifySocket s;
  // The watchdog first: it says nothing without a socket to ping, but a malformed value is said.
  if (watchdog_usec) {
    unsigned long long usec = 0, pid = 0;
    // Up to a day: the manager's own values are seconds to minutes; nanoseconds fit int64 anyway.
    if (!whole_number(watchdog_usec, 86'400'000'000ULL, &usec)) {
      s.error_ = std::string("WATCHDOG_USEC='") + watchdog_usec + "' is not a whole number of microseconds "
                 "(1 to a day): no watchdog pings";
    } else if (watchdog_pid && !whole_number(watchdog_pid, 0x7fffffffULL, &pid)) {
      s.error_ = std::string("WATCHDOG_PID='") + watchdog_pid + "' is not a process ID: no watchdog pings";
    } else if (!watchdog_pid || static_cast<long>(pid) == self) {
      s.watchdog_period_ns_ = static_cast<int64_t>(usec) * 1000 / 2;  // sd_watchdog_enabled(3): ping at half
    }
    // WATCHDOG_PID of another process: its watchdog, inherited through the environment.
  }
  if (!notify_socket || !*notify_socket) {
    s.watchdog_period_ns_ = 0;
    return s;
  }
  s.requested_ = true;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const size_t len = std::strlen(notify_socket);
  // A path needs its terminating NUL inside sun_path; an abstract name is counted by length.
  const size_t room = sizeof addr.sun_path - (notify_socket[0] == '/' ? 1 : 0);
  if ((notify_socket[0] != '/' && notify_socket[0] != '@') || len < 2 || len > room) {
    add_error(s.error_, std::string("NOTIFY_SOCKET='") + notify_socket + "' is neither an absolute path of at most " +
                            std::to_string(sizeof addr.sun_path - 1) + " bytes nor an '@' abstract name of at most " +
                            std::to_string(sizeof addr.sun_path) + ": the service manager hears nothing");
    s.watchdog_period_ns_ = 0;
    return s;
  }
  std::memcpy(addr.sun_path, notify_socket, len);
  if (addr.sun_path[0] == '@') addr.sun_path[0] = '\0';  // abstract: no terminating NUL counted
  const socklen_t addr_len =
      static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + len + (notify_socket[0] == '/' ? 1 : 0));
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  const char* step = "socket";
  if (fd >= 0) {
    step = "connect";
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), addr_len) == 0) {
      s.fd_ = fd;
      return s;
    }
  }
  const int err = errno;
  if (fd >= 0) ::close(fd);
  // A unit's RestrictAddressFamilies= without AF_UNIX ends here with EAFNOSUPPORT.
  add_error(s.error_, std::string("NOTIFY_SOCKET='") + notify_socket + "': " + step + ": " + std::strerror(err) +
                          ": the service manager hears nothing (no READY=1, no watchdog pings)");
  s.watchdog_period_ns_ = 0;
  return s;
}

NotifySocket::NotifySocket(NotifySocket&& o) noexcept { *this = std::move(o); }

NotifySocket& NotifySocket::operator=(NotifySocket&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    requested_ = o.requested_;
    ready_pending_ = std::exchange(o.ready_pending_, false);
    error_ = std::move(o.error_);
    // The moved-from object has no socket: it pings nothing.
    watchdog_period_ns_ = std::exchange(o.watchdog_period_ns_, 0);
    next_ping_ns_ = o.next_ping_ns_;
    failed_sends_ = o.failed_sends();
    last_errno_ = o.last_errno();
  }
  return *this;
}

NotifySocket::~NotifySocket() {
  if (fd_ >= 0) ::close(fd_);
}

int NotifySocket::send_state(const char* state) noexcept {
  if (fd_ < 0) return 0;
  // MSG_NOSIGNAL: a manager gone is an error here, not a SIGPIPE.
  if (::send(fd_, state, std::strlen(state), MSG_DONTWAIT | MSG_NOSIGNAL) >= 0) return 0;
  const int err = errno;
  last_errno_.store(err, std::memory_order_relaxed);
  failed_sends_.fetch_add(1, std::memory_order_relaxed);
  return err;
}

bool NotifySocket::notify(const char* state) noexcept { return send_state(state) == 0; }

namespace {
// The manager's queue was full (or the call was interrupted): the same message may go out later.
bool transient(int err) { return err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS || err == EINTR; }
}  // namespace

bool NotifySocket::ready(int64_t now_ns) noexcept {
  next_ping_ns_ = now_ns + watchdog_period_ns_;
  const int err = send_state("READY=1");
  ready_pending_ = transient(err);
  return err == 0;
}

bool NotifySocket::on_tick(int64_t now_ns) noexcept {
  if (ready_pending_) ready_pending_ = transient(send_state("READY=1"));
  if (watchdog_period_ns_ <= 0 || now_ns < next_ping_ns_) return false;
  const int err = send_state("WATCHDOG=1");
  // Sent, or refused for good (the manager gone): the next one a period on. A full queue: the
  // next tick tries again.
  if (!transient(err)) next_ping_ns_ = now_ns + watchdog_period_ns_;
  return err == 0;
}

}  // namespace dressguard::service
