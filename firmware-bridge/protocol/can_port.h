// A CAN port: the one seam between the protocol code and a bus, so that the predictor daemon and
// the bridge run the same code on a real SocketCAN interface (a robot, or vcan in the test VM)
// and on an in-process bus in host unit tests (this build machine's kernel refuses AF_CAN).
//
// Both kinds are file descriptors that epoll can wait on, are non-blocking, and report what
// SocketCAN reports: the sender's own frames echoed back when asked (CAN_RAW_RECV_OWN_MSGS, the
// confirmation that a frame went out), frames the kernel dropped for a full receive queue
// (SO_RXQ_OVFL), controller error frames (bus-off), and send failures by kind (ENOBUFS when the
// transmit queue is full, ENETDOWN when the interface or controller is down).
// Linux only; receive() and send() neither allocate nor lock.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dg_protocol.h"

namespace dressguard::can {

enum class SendResult : uint8_t {
  Ok = 0,
  NoBuffers = 1,  // ENOBUFS/EAGAIN: the transmit queue is full; retry later (as cangen does)
  Down = 2,       // ENETDOWN/ENXIO: interface down or controller bus-off
  Error = 3,      // anything else (errno kept)
};
const char* send_result_name(SendResult r);

// The error classes of RxInfo::error_class that the ports subscribe to (linux/can/error.h's
// CAN_ERR_TX_TIMEOUT, _CRTL, _BUSOFF, _RESTARTED), for code that includes no SocketCAN header.
inline constexpr uint32_t kErrorTxTimeout = 0x001, kErrorController = 0x004, kErrorBusOff = 0x040,
                          kErrorRestarted = 0x100;
// The gravest class set in `error_class`: "bus-off", "restarted", "controller problem",
// "tx timeout", else "other".
const char* error_class_name(uint32_t error_class);

struct RxInfo {
  bool own_echo = false;        // our own transmitted frame, echoed back: it reached the bus
  bool error_frame = false;     // a controller error frame (CAN_ERR_FLAG); see error_class
  uint32_t error_class = 0;     // CAN_ERR_* bits (CAN_ERR_BUSOFF = 0x40, ...)
  uint32_t kernel_drops = 0;    // cumulative frames the kernel dropped for this socket
  int64_t rx_time_ns = 0;       // CLOCK_MONOTONIC when the frame was read (0 if unknown)
};

struct PortOptions {
  std::vector<uint32_t> ids;    // exact 11-bit identifiers to receive (kernel filters); empty: none
  bool receive_own = false;     // echo own frames back (CAN_RAW_RECV_OWN_MSGS)
  bool error_frames = true;     // receive bus-off / controller error frames
  int receive_buffer = 0;       // SO_RCVBUF(FORCE) bytes, 0: the kernel's default
};

class CanPort {
 public:
  virtual ~CanPort() = default;
  // Pollable for input (EPOLLIN), non-blocking.
  virtual int fd() const = 0;
  // 1: a frame (or error frame) was read; 0: nothing waiting; -1: error (errno set).
  virtual int receive(protocol::Frame& f, RxInfo& info) noexcept = 0;
  virtual SendResult send(const protocol::Frame& f) noexcept = 0;
  // The receive buffer the kernel granted, in bytes of payload (0: not a kernel socket). Without
  // CAP_NET_ADMIN, SO_RCVBUFFORCE fails and SO_RCVBUF is capped at net.core.rmem_max.
  virtual int receive_buffer() const { return 0; }
};

// A raw SocketCAN socket bound to `iface` with exact-id filters. Throws std::system_error naming
// the interface and the call that failed (e.g. socket(AF_CAN) on a kernel without CAN).
std::unique_ptr<CanPort> open_socketcan(const std::string& iface, const PortOptions& opt);

// True when this kernel lets us open an AF_CAN socket (false here on the build machine).
bool socketcan_available();

// An in-process broadcast bus with SocketCAN's semantics, for host tests. Every port is a
// SOCK_SEQPACKET socket pair; a send writes the frame into each other port's queue whose filter
// matches (and into the sender's own, flagged, when it asked for echoes). A full receive queue
// drops the frame and counts it, like the kernel's SO_RXQ_OVFL. Open all ports before traffic
// starts; after that sends may come from any thread.
class InProcBus {
 public:
  InProcBus();
  ~InProcBus();
  std::unique_ptr<CanPort> open(const PortOptions& opt);

  // Fault injection: the next `n` sends from any port fail with `r` (frame not delivered).
  void fail_next_sends(int n, SendResult r) { fail_result_ = r; fail_count_.store(n); }
  // When false, own frames are delivered to others but not echoed back (a lost confirmation).
  void set_echo(bool on) { echo_.store(on); }
  // Frames delivered so far (all ports), for tests.
  uint64_t delivered() const { return delivered_.load(); }

  struct Endpoint;  // internal

 private:
  friend class InProcPort;
  SendResult broadcast(const Endpoint* from, const protocol::Frame& f) noexcept;
  std::mutex open_mutex_;                  // guards endpoints_ while ports are being opened
  std::vector<std::shared_ptr<Endpoint>> endpoints_;
  std::atomic<int> fail_count_{0};
  SendResult fail_result_ = SendResult::Ok;
  std::atomic<bool> echo_{true};
  std::atomic<uint64_t> delivered_{0};
};

}  // namespace dressguard::can
