// SocketCAN and in-process implementations of CanPort.
#include "can_port.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace dressguard::can {
namespace {

int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

SendResult classify_errno(int e) {
  if (e == ENOBUFS || e == EAGAIN) return SendResult::NoBuffers;
  if (e == ENETDOWN || e == ENXIO || e == ENODEV) return SendResult::Down;
  return SendResult::Error;
}

[[noreturn]] void fail(const std::string& what) { throw std::system_error(errno, std::generic_category(), what); }

class SocketCanPort final : public CanPort {
 public:
  SocketCanPort(const std::string& iface, const PortOptions& opt) : iface_(iface) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) fail("socket(PF_CAN, SOCK_RAW, CAN_RAW) for " + iface + " (is the can/can-raw module loaded?)");
    std::vector<can_filter> filters;
    for (uint32_t id : opt.ids) filters.push_back({id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
    // An empty filter list receives nothing, which is what a send-only socket wants.
    if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters.empty() ? nullptr : filters.data(),
                   static_cast<socklen_t>(filters.size() * sizeof(can_filter))) < 0)
      fail_close("setsockopt(CAN_RAW_FILTER) on " + iface);
    can_err_mask_t err = opt.error_frames ? (CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_TX_TIMEOUT | CAN_ERR_RESTARTED) : 0;
    if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err, sizeof err) < 0)
      fail_close("setsockopt(CAN_RAW_ERR_FILTER) on " + iface);
    const int own = opt.receive_own ? 1 : 0;
    if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own) < 0)
      fail_close("setsockopt(CAN_RAW_RECV_OWN_MSGS) on " + iface);
    const int one = 1;
    if (setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) < 0) fail_close("setsockopt(SO_RXQ_OVFL) on " + iface);
    if (opt.receive_buffer > 0 &&
        setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &opt.receive_buffer, sizeof opt.receive_buffer) < 0 &&
        setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &opt.receive_buffer, sizeof opt.receive_buffer) < 0)
      fail_close("setsockopt(SO_RCVBUF) on " + iface);
    // The kernel reports twice what it grants as payload (socket(7): the rest is bookkeeping).
    int granted = 0;
    socklen_t len = sizeof granted;
    if (getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted, &len) == 0) rcvbuf_ = granted / 2;
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, iface.c_str(), IFNAMSIZ - 1);
    if (ioctl(fd_, SIOCGIFINDEX, &ifr) < 0) fail_close("no CAN interface '" + iface + "' (SIOCGIFINDEX)");
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) fail_close("bind to " + iface);
  }
  ~SocketCanPort() override {
    if (fd_ >= 0) ::close(fd_);
  }
  int fd() const override { return fd_; }
  int receive_buffer() const override { return rcvbuf_; }

  int receive(protocol::Frame& f, RxInfo& info) noexcept override {
    can_frame cf;
    iovec iov{&cf, sizeof cf};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(uint32_t))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = recvmsg(fd_, &msg, 0);
    if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
    if (n != sizeof cf) {
      errno = EPROTO;
      return -1;
    }
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) std::memcpy(&drops_, CMSG_DATA(c), sizeof drops_);
    }
    info = RxInfo{};
    info.kernel_drops = drops_;
    info.own_echo = (msg.msg_flags & MSG_CONFIRM) != 0;
    info.rx_time_ns = now_ns();
    if (cf.can_id & CAN_ERR_FLAG) {
      info.error_frame = true;
      info.error_class = cf.can_id & CAN_ERR_MASK;
    }
    f.id = cf.can_id & CAN_SFF_MASK;
    f.len = cf.len > 8 ? 8 : cf.len;
    std::memcpy(f.data, cf.data, 8);
    return 1;
  }

  SendResult send(const protocol::Frame& f) noexcept override {
    can_frame cf{};
    cf.can_id = f.id & CAN_SFF_MASK;
    cf.len = f.len;
    std::memcpy(cf.data, f.data, 8);
    const ssize_t n = ::write(fd_, &cf, sizeof cf);
    if (n == sizeof cf) return SendResult::Ok;
    return n < 0 ? classify_errno(errno) : SendResult::Error;
  }

 private:
  [[noreturn]] void fail_close(const std::string& what) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    errno = e;
    fail(what);
  }
  std::string iface_;
  int fd_ = -1;
  int rcvbuf_ = 0;
  uint32_t drops_ = 0;
};

// What travels through an in-process port's socket pair.
struct Wire {
  protocol::Frame frame;
  uint8_t own_echo;
};

}  // namespace

static_assert(kErrorTxTimeout == CAN_ERR_TX_TIMEOUT && kErrorController == CAN_ERR_CRTL &&
              kErrorBusOff == CAN_ERR_BUSOFF && kErrorRestarted == CAN_ERR_RESTARTED);

const char* error_class_name(uint32_t error_class) {
  if (error_class & kErrorBusOff) return "bus-off";
  if (error_class & kErrorRestarted) return "restarted";
  if (error_class & kErrorController) return "controller problem";
  if (error_class & kErrorTxTimeout) return "tx timeout";
  return "other";
}

const char* send_result_name(SendResult r) {
  switch (r) {
    case SendResult::Ok: return "ok";
    case SendResult::NoBuffers: return "no_buffers";
    case SendResult::Down: return "down";
    case SendResult::Error: return "error";
  }
  return "unknown";
}

std::unique_ptr<CanPort> open_socketcan(const std::string& iface, const PortOptions& opt) {
  return std::make_unique<SocketCanPort>(iface, opt);
}

bool socketcan_available() {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

// ---------------------------------------------------------------------------------------------

struct InProcBus::Endpoint {
  int read_fd = -1;   // the port reads here
  int write_fd = -1;  // the bus writes here
  PortOptions opt;
  std::atomic<uint32_t> drops{0};
  std::atomic<bool> open{true};
  bool wants(uint32_t id) const {
    for (uint32_t x : opt.ids)
      if (x == id) return true;
    return false;
  }
};

class InProcPort final : public CanPort {
 public:
  InProcPort(InProcBus* bus, std::shared_ptr<InProcBus::Endpoint> ep) : bus_(bus), ep_(std::move(ep)) {}
  ~InProcPort() override {
    ep_->open.store(false);
    ::close(ep_->read_fd);
  }
  int fd() const override { return ep_->read_fd; }
  int receive(protocol::Frame& f, RxInfo& info) noexcept override {
    Wire w;
    const ssize_t n = ::recv(ep_->read_fd, &w, sizeof w, MSG_DONTWAIT);
    if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
    if (n != sizeof w) {
      errno = EPROTO;
      return -1;
    }
    f = w.frame;
    info = RxInfo{};
    info.own_echo = w.own_echo != 0;
    info.kernel_drops = ep_->drops.load(std::memory_order_relaxed);
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    info.rx_time_ns = static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
    return 1;
  }
  SendResult send(const protocol::Frame& f) noexcept override { return bus_->broadcast(ep_.get(), f); }

 private:
  InProcBus* bus_;
  std::shared_ptr<InProcBus::Endpoint> ep_;
};

InProcBus::InProcBus() = default;

InProcBus::~InProcBus() {
  for (auto& ep : endpoints_) ::close(ep->write_fd);
}

std::unique_ptr<CanPort> InProcBus::open(const PortOptions& opt) {
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) < 0) fail("socketpair for the in-process CAN bus");
  // Non-blocking writes: a full queue is a drop at that receiver, never a stalled sender.
  fcntl(sv[1], F_SETFL, fcntl(sv[1], F_GETFL) | O_NONBLOCK);
  fcntl(sv[0], F_SETFL, fcntl(sv[0], F_GETFL) | O_NONBLOCK);
  auto ep = std::make_shared<Endpoint>();
  ep->read_fd = sv[0];
  ep->write_fd = sv[1];
  ep->opt = opt;
  std::lock_guard<std::mutex> lock(open_mutex_);
  endpoints_.push_back(ep);
  return std::make_unique<InProcPort>(this, ep);
}

SendResult InProcBus::broadcast(const Endpoint* from, const protocol::Frame& f) noexcept {
  int pending = fail_count_.load();
  while (pending > 0) {
    if (fail_count_.compare_exchange_weak(pending, pending - 1)) return fail_result_;
  }
  for (auto& ep : endpoints_) {
    if (!ep->open.load(std::memory_order_relaxed)) continue;
    const bool self = ep.get() == from;
    if (self && !(ep->opt.receive_own && echo_.load())) continue;
    if (!self && !ep->wants(f.id)) continue;
    Wire w{f, static_cast<uint8_t>(self ? 1 : 0)};
    if (::send(ep->write_fd, &w, sizeof w, MSG_DONTWAIT | MSG_NOSIGNAL) != sizeof w) {
      ep->drops.fetch_add(1, std::memory_order_relaxed);
    } else {
      delivered_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  return SendResult::Ok;
}

}  // namespace dressguard::can
