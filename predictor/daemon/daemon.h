// The dressguard-predictor daemon's machinery around the Predictor (predictor/core): one
// real-time event loop blocking in epoll on the CAN receive socket, the stop socket, a timerfd
// and a shutdown eventfd; a lock-free queue to a normal-priority thread that logs with spdlog;
// the real-time setup; a latency histogram. The loop runs on any CanPort, so host tests drive it
// on the in-process bus and the VM test on vcan.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "can_port.h"
#include "predictor_core.h"
#include "spsc_queue.h"

namespace spdlog {
class logger;
}
namespace dressguard::service {
class NotifySocket;
}

namespace dressguard::predictor {

using EventQueue = SpscQueue<Event, 4096>;

// Fixed-bin histogram, added to on the real-time loop (no allocation, no lock: a fixed array and
// counters): kBins bins of `bin_ns` cover [0, range_ns()); a value at or beyond range_ns() is
// counted in overflow(), not in a bin (folded into the last bin, a stall read as that bin's
// latency). count() holds both.
class LatencyHistogram {
 public:
  static constexpr int kBins = 4096;
  explicit LatencyHistogram(int64_t bin_ns = 100) : bin_ns_(bin_ns) {}  // 100 ns x 4096: up to 410 us
  void add(int64_t ns) noexcept {
    const int64_t b = ns < 0 ? 0 : ns / bin_ns_;
    if (b < kBins)
      ++bins_[static_cast<size_t>(b)];
    else
      ++overflow_;
    ++count_;
    if (ns > max_) max_ = ns;
  }
  uint64_t count() const { return count_; }
  uint64_t overflow() const { return overflow_; }  // values >= range_ns()
  int64_t max() const { return max_; }
  int64_t bin_ns() const { return bin_ns_; }
  int64_t range_ns() const { return kBins * bin_ns_; }
  // Upper edge of the bin holding quantile q (0..1), in ns; max() when it lies beyond the range.
  int64_t quantile(double q) const;
  const std::array<uint64_t, kBins>& bins() const { return bins_; }
  void merge(const LatencyHistogram& o);

 private:
  int64_t bin_ns_;
  std::array<uint64_t, kBins> bins_{};
  uint64_t overflow_ = 0;
  uint64_t count_ = 0;
  int64_t max_ = 0;
};

// Drains the event queue into spdlog on a normal-priority thread (spdlog takes locks). With a
// service manager's socket it also keeps the unit's one-line status (`systemctl status`, STATUS=)
// current at each trial's start, stop and end: "trial 12 running; trials 12, stopped 2 (last:
// trial 9, caught)". Formatted here, off the real-time loop.
class EventLogger {
 public:
  EventLogger(EventQueue& q, std::shared_ptr<spdlog::logger> log, const std::vector<std::string>& class_names,
              service::NotifySocket* service = nullptr);
  ~EventLogger();  // drains what is left, then joins
  void stop();

 private:
  void run();
  void log_one(const Event& e);
  void tell_status(const Event& e);
  static bool power_of_two(uint64_t n) { return n != 0 && (n & (n - 1)) == 0; }
  EventQueue& q_;
  std::shared_ptr<spdlog::logger> log_;
  std::vector<std::string> names_;
  std::atomic<bool> stop_{false};
  uint64_t tx_errors_ = 0;  // failed sends seen (the logging thread's own count)
  service::NotifySocket* service_ = nullptr;
  uint64_t trials_ = 0, stopped_ = 0;  // for the status line: trials started, trials stopped
  std::string last_stop_;              // "trial 9, caught"
  std::thread thread_;
};

struct DaemonOptions {
  int64_t tick_ns = 1'000'000;         // timerfd period: deadline resolution, stop retry pacing
  // Wait this long for a shutdown stop's echo (bus-off recovery takes ~100 ms), well inside the
  // unit's TimeoutStopSec=5.
  int64_t shutdown_grace_ns = 1'000'000'000;
  // The service manager's socket (null: none): READY=1 when the loop starts, WATCHDOG=1 from
  // its ticks (each a non-blocking send(2)), STOPPING=1 when a shutdown begins.
  service::NotifySocket* service = nullptr;
};

class PredictorDaemon final : private PredictorSink {
 public:
  // `rx`: kernel filters for the F/T, trial and bridge-heartbeat identifiers; also sends status,
  // posteriors and heartbeats. `stop_port`: its own socket, filter = Stop, own echoes on.
  PredictorDaemon(const model::OutcomeModel* model, const PredictorConfig& cfg, can::CanPort& rx,
                  can::CanPort& stop_port, EventQueue& events, const DaemonOptions& opt = {});
  ~PredictorDaemon() override;

  // The event loop; returns 0 after a clean shutdown, 1 on an unrecoverable error (logged via
  // the queue: the interface unregistered) or when the grace ran out with a stop unconfirmed
  // (predictor().stop_pending() then). Call from the thread that should be real-time.
  int run();
  // Async-signal-safe: a write to an eventfd.
  void request_shutdown() noexcept;

  const Predictor& predictor() const { return predictor_; }
  // Frame read (kernel receive) to decision made, per F/T force frame, and the same with the
  // stop frame's send() included when that frame stopped.
  const LatencyHistogram& processing() const { return processing_; }
  const LatencyHistogram& processing_with_stop() const { return processing_stop_; }

  // The identifiers the receive socket filters for.
  static std::vector<uint32_t> receive_ids();

 private:
  uint8_t transmit_stop(const Frame& f) noexcept override;
  uint8_t transmit(const Frame& f) noexcept override;
  void event(const Event& e) noexcept override;
  void drain_rx(int64_t now) noexcept;
  void drain_stop(int64_t now) noexcept;
  void receive_failed(int err, bool stop_socket, int64_t now) noexcept;

  can::CanPort& rx_;
  can::CanPort& stop_port_;
  EventQueue& events_;
  DaemonOptions opt_;
  Predictor predictor_;
  int epoll_fd_ = -1, timer_fd_ = -1, shutdown_fd_ = -1;
  LatencyHistogram processing_, processing_stop_;
  uint32_t stops_sent_ = 0;
  uint32_t receive_errors_ = 0;
  bool interface_gone_ = false;
};

// SIGHUP and SIGPIPE ignored: their default action ends the process at once, with no stop for a
// running trial, and systemd takes such an end for a clean exit and does not restart the unit.
// SIGHUP is what an operator sends to "reload" and what a closed terminal sends; the daemon reads
// its config and model at start only. main's first call: one that came while the daemon read its
// config or model, set up real time or opened its sockets ended it, and the unit stayed down.
void ignore_hangup_and_broken_pipe();

// The process's signals, routed to `daemon` (nullptr: to none). SIGTERM and SIGINT ask it to shut
// down (a running trial is stopped first); SIGHUP and SIGPIPE stay ignored, as above.
void handle_signals(PredictorDaemon* daemon);

// Real-time setup, each step optional: a step that is not permitted yields a warning string
// (mlockall without CAP_IPC_LOCK, SCHED_FIFO without CAP_SYS_NICE, a CPU that does not exist).
struct RtOptions {
  bool lock_memory = true;
  int fifo_priority = 80;  // 0: stay SCHED_OTHER
  int cpu = -1;            // -1: no affinity
};
std::vector<std::string> setup_realtime(const RtOptions& opt);

}  // namespace dressguard::predictor
