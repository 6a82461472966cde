// The bridge's Linux host port: one event loop (epoll on a timerfd at the sensor rate, the CAN
// port, a shutdown eventfd, and a streaming sensor's line) around the portable core. Reads a
// polled sensor over Modbus each period, or a streaming one whenever its line has bytes,
// publishes the frames, and on a stop writes the stop to the robot controller; reconnects to a
// lost sensor with exponential backoff (no frames meanwhile: never stale data).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "bridge_core.h"
#include "can_port.h"
#include "modbus_link.h"

namespace dressguard::service {
class NotifySocket;
}

namespace dressguard::bridge {

struct BridgeAppConfig {
  BridgeConfig core;
  int sample_period_ms = 10;       // 100 Hz, the study's rate
  int backoff_min_ms = 50;         // first reconnect delay, doubled per failure ...
  int backoff_max_ms = 2000;       // ... up to this
  int stop_retry_ms = 10;          // an unacknowledged stop write is retried this often
  // On shutdown a stop not yet written (one on the bus, one pending, or the bridge's own when
  // the predictor is in a trial: bridge_on_shutdown) is retried this long before the bridge
  // gives up and exits 1; well inside a service manager's stop timeout (systemd: 90 s).
  int shutdown_grace_ms = 1000;
  // Where the bridge says what went wrong (null: nowhere). A failing sensor or stop write is
  // reported at its 1st, 2nd, 4th, 8th, ... consecutive failure with libmodbus's reason, and
  // once when it recovers; every stop is reported; a timer overrun at the 1st, 2nd, 4th, ...;
  // CAN send and receive failures at the 1st, 2nd, 4th, ... in a row and once when they stop,
  // controller error frames at the 1st, 2nd, 4th, ... since the last restart, and the restart.
  std::FILE* log = stderr;
  // The service manager's socket (null: none): READY=1 when the loop starts, WATCHDOG=1 from
  // its timer (each a non-blocking send(2)), STOPPING=1 when a shutdown begins, and the unit's
  // status line (STATUS=) whenever the bridge says something on `log`.
  service::NotifySocket* service = nullptr;
};

struct BridgeStats {
  std::atomic<uint64_t> readings{0}, frames_sent{0}, send_failures{0}, sensor_errors{0}, reconnects{0},
      connect_failures{0}, stops_written{0}, stop_write_failures{0};
  // The robot's stop target cleared at a TrialStart that left no stop latched, and failed tries.
  std::atomic<uint64_t> releases_written{0}, release_write_failures{0};
  // Wakeups that found the timer expired more than once, and the periods they skipped.
  std::atomic<uint64_t> overruns{0}, periods_overrun{0};
  std::atomic<uint64_t> receive_failures{0}, error_frames{0};
};

class BridgeApp {
 public:
  // `robot` may be null (no robot controller: stops are only logged).
  BridgeApp(const BridgeAppConfig& cfg, Sensor& sensor, RobotStopWriter* robot, can::CanPort& port);
  ~BridgeApp();
  // Until request_shutdown(), then until no stop is left unwritten: 0, or 1 when the grace ran
  // out with a stop unwritten (said on the log) or epoll failed (said, and the shutdown's stop
  // still written within the grace).
  int run();
  void request_shutdown() noexcept; // async-signal-safe
  const BridgeStats& stats() const { return stats_; }
  const BridgeCore& core() const { return core_; }  // read only from the loop's thread or after run()
  std::string last_error() const;

 private:
  void on_timer(uint32_t now_ms);
  bool take_reading(uint32_t now_ms);
  void drain_sensor(uint32_t now_ms);
  void back_off(uint32_t now_ms);
  void timer_overran(uint64_t periods);
  void drain_can(uint32_t now_ms);
  bool received(int got, const can::RxInfo& info);
  void error_frame(uint32_t error_class);
  void send(const Frame& f);
  void try_stop(uint32_t now_ms);
  void stop_robot(uint32_t now_ms);
  void release_robot(uint32_t now_ms);
  void try_release(uint32_t now_ms);
  void begin_shutdown(uint32_t now_ms);
  int loop_failed(int err);
  void say_stop_unwritten();
  void say(const char* fmt, ...) __attribute__((format(printf, 2, 3)));
  void tell_status(const char* last);
  void sensor_failed(const char* what);

  BridgeAppConfig cfg_;
  Sensor& sensor_;
  RobotStopWriter* robot_;
  can::CanPort& port_;
  BridgeCore core_;
  BridgeStats stats_;
  int epoll_fd_ = -1, timer_fd_ = -1, shutdown_fd_ = -1;
  int backoff_ms_ = 0;
  uint32_t next_connect_ms_ = 0;
  bool sensor_was_connected_ = false;  // a connect after the first is a reconnect
  bool stop_pending_ = false;
  uint32_t next_stop_try_ms_ = 0;
  uint64_t sensor_failures_ = 0;  // in a row, since the last good reading
  uint64_t stop_failures_ = 0;    // in a row, for the pending stop
  bool release_pending_ = false;  // the robot's stop target is to be cleared (never with a stop pending)
  uint64_t release_failures_ = 0; // in a row, for the pending release
  uint64_t send_failures_ = 0;    // CAN sends, in a row
  uint64_t receive_failures_ = 0; // CAN receives, in a row
  uint64_t error_frames_ = 0;     // since the controller's last restart
};

// SIGHUP (an operator's "reload", a closed terminal) and SIGPIPE (a log pipe whose reader died)
// ignored: by default they ended the bridge at once, mid-trial, with no stop written, and systemd
// counts that as a clean exit, so the unit was not restarted. There is no reload. main's first
// call: one that came while the bridge probed the robot, set up real time or opened its socket
// ended it, and the unit stayed down.
void ignore_hangup_and_broken_pipe();

// The process's signals for `app` (null: none, the shutdown signals then do nothing): SIGTERM
// and SIGINT shut it down (request_shutdown: a running trial's stop written first); SIGHUP and
// SIGPIPE stay ignored, as above.
void handle_signals(BridgeApp* app);

}  // namespace dressguard::bridge
