// The bridge's Linux event loop.
#include "bridge_app.h"

#include <signal.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <system_error>
#include <utility>

#include "notify_socket.h"

namespace dressguard::bridge {
namespace {

// CLOCK_MONOTONIC in ns: the watchdog's clock (notify_socket.h).
int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The loop's clock, in ms: 32 bits that wrap after 49.7 days of uptime (the core compares with
// due(), across the wrap); not for the watchdog, whose ping times are absolute.
uint32_t now_ms() { return static_cast<uint32_t>(static_cast<uint64_t>(now_ns()) / 1000000); }

constexpr uint64_t kTimer = 1, kCan = 2, kShutdown = 3, kSensor = 4, kTags = 5;

bool due(uint32_t now, uint32_t t) { return static_cast<int32_t>(now - t) >= 0; }
bool power_of_two(uint64_t n) { return n != 0 && (n & (n - 1)) == 0; }

}  // namespace

BridgeApp::BridgeApp(const BridgeAppConfig& cfg, Sensor& sensor, RobotStopWriter* robot, can::CanPort& port)
    : cfg_(cfg), sensor_(sensor), robot_(robot), port_(port) {
  const uint32_t t0 = now_ms();
  bridge_init(core_, cfg.core, t0);
  // The first connect is due now. (0 would be due only while the uptime modulo 2^32 ms is below
  // 2^31 ms, due() being wrap-safe: on a machine up 24.9 to 49.7 days, never.)
  next_connect_ms_ = t0;
  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  timer_fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  shutdown_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (epoll_fd_ < 0 || timer_fd_ < 0 || shutdown_fd_ < 0) throw std::system_error(errno, std::generic_category(), "epoll/timerfd/eventfd");
  for (auto [fd, tag] : {std::pair{timer_fd_, kTimer}, std::pair{port_.fd(), kCan}, std::pair{shutdown_fd_, kShutdown},
                        std::pair{sensor_.events_fd(), kSensor}}) {
    if (fd < 0) continue;  // a polled sensor has no events
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = tag;
    if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev) < 0) throw std::system_error(errno, std::generic_category(), "epoll_ctl");
  }
  itimerspec its{};
  its.it_interval.tv_sec = cfg_.sample_period_ms / 1000;
  its.it_interval.tv_nsec = (cfg_.sample_period_ms % 1000) * 1000000L;
  its.it_value = its.it_interval;
  // A period of 0 would disarm the timer: no reading, no heartbeat, without a word.
  if (cfg_.sample_period_ms <= 0 || timerfd_settime(timer_fd_, 0, &its, nullptr) < 0)
    throw std::system_error(cfg_.sample_period_ms <= 0 ? EINVAL : errno, std::generic_category(), "timerfd_settime");
}

BridgeApp::~BridgeApp() {
  for (int fd : {epoll_fd_, timer_fd_, shutdown_fd_})
    if (fd >= 0) ::close(fd);
}

void BridgeApp::request_shutdown() noexcept {
  const uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(shutdown_fd_, &one, sizeof one);
}

namespace {
// Read by the signal handler: an atomic, not a plain pointer the handler might see half-written.
std::atomic<BridgeApp*> g_signalled_app{nullptr};
static_assert(std::atomic<BridgeApp*>::is_always_lock_free);

void shut_down_on_signal(int) {
  if (BridgeApp* app = g_signalled_app.load()) app->request_shutdown();
}
}  // namespace

void ignore_hangup_and_broken_pipe() {
  struct sigaction ignored{};
  ignored.sa_handler = SIG_IGN;
  sigemptyset(&ignored.sa_mask);
  for (const int sig : {SIGHUP, SIGPIPE}) sigaction(sig, &ignored, nullptr);
}

void handle_signals(BridgeApp* app) {
  g_signalled_app.store(app);
  struct sigaction on{};
  on.sa_handler = shut_down_on_signal;
  sigemptyset(&on.sa_mask);
  for (const int sig : {SIGTERM, SIGINT}) sigaction(sig, &on, nullptr);
  ignore_hangup_and_broken_pipe();
}

std::string BridgeApp::last_error() const { return sensor_.last_error(); }

void BridgeApp::say(const char* fmt, ...) {
  if (!cfg_.log && !cfg_.service) return;
  char line[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  if (cfg_.log) {
    std::fprintf(cfg_.log, "dressguard-bridge: %s\n", line);
    std::fflush(cfg_.log);
  }
  tell_status(line);
}

// The unit's status line (`systemctl status`, STATUS=), set whenever the bridge says something:
// its sensor's state, the stops it wrote, and what it said last. Into a buffer on the stack.
void BridgeApp::tell_status(const char* last) {
  if (!cfg_.service) return;
  char status[700];
  std::snprintf(status, sizeof status, "STATUS=sensor %s; stops written %llu%s; last: %s",
                !sensor_.connected() ? "not connected" : sensor_failures_ ? "failing" : "ok",
                static_cast<unsigned long long>(stats_.stops_written.load()), stop_pending_ ? ", one pending" : "",
                last);
  cfg_.service->notify(status);
}

void BridgeApp::sensor_failed(const char* what) {
  if (power_of_two(++sensor_failures_))
    say("sensor: %s: %s (%llu in a row; no frames until it answers)", what, sensor_.last_error().c_str(),
        static_cast<unsigned long long>(sensor_failures_));
}

void BridgeApp::send(const Frame& f) {
  // A full transmit queue or a bus-off drops this frame (the next sample supersedes it): counted,
  // never blocked on, and said, since nothing the bridge publishes gets out meanwhile.
  const can::SendResult r = port_.send(f);
  if (r == can::SendResult::Ok) {
    ++stats_.frames_sent;
    if (send_failures_ > 0)
      say("CAN sends go out again after %llu failures", static_cast<unsigned long long>(send_failures_));
    send_failures_ = 0;
    return;
  }
  const int err = errno;
  ++stats_.send_failures;
  if (power_of_two(++send_failures_))
    say("CAN send failed: %s%s%s (%llu in a row; frames are dropped meanwhile)", can::send_result_name(r),
        r == can::SendResult::Error ? ": " : "", r == can::SendResult::Error ? std::strerror(err) : "",
        static_cast<unsigned long long>(send_failures_));
}

// The core latched a stop: write it to the robot at once, then say why (the log is a pipe
// that can be slow; the robot's stop comes first).
void BridgeApp::stop_robot(uint32_t t) {
  // A clear not yet written is superseded: written after this stop, it would take it back.
  release_pending_ = false;
  stop_pending_ = true;
  next_stop_try_ms_ = t;
  try_stop(t);
  const BridgeCore& c = core_;
  const unsigned timeout = c.cfg.predictor_timeout_ms;
  switch (c.stop_cause) {
    case StopCause::StopFrame: say("stop frame from the predictor: %s", protocol::stop_reason_name(c.last_stop_reason)); break;
    case StopCause::PredictorSilent: say("no heartbeat from the predictor for more than %u ms: stopping the robot", timeout); break;
    case StopCause::TrialUnguarded:
      say("the predictor has not guarded trial %u for more than %u ms (its heartbeat says %s, trial %u): "
          "stopping the robot",
          static_cast<unsigned>(c.trial_id), timeout, protocol::predictor_state_name(c.predictor_state),
          static_cast<unsigned>(c.predictor_trial));
      break;
    case StopCause::BridgeShutdown:  // begin_shutdown says it
    case StopCause::None: break;
  }
}

// The robot controller's TrialStart left no stop latched: its stop target is cleared, so that it
// mirrors the latch (and the next stop is a rising edge), retried as a stop is.
void BridgeApp::release_robot(uint32_t t) {
  if (!robot_) return;
  release_pending_ = true;
  next_stop_try_ms_ = t;
}

void BridgeApp::try_release(uint32_t t) {
  if (!release_pending_ || !due(t, next_stop_try_ms_)) return;
  if (robot_->write_release()) {
    release_pending_ = false;
    ++stats_.releases_written;
    if (release_failures_)
      say("stop cleared on the robot controller after %llu failed writes",
          static_cast<unsigned long long>(release_failures_));
    release_failures_ = 0;
    return;
  }
  ++stats_.release_write_failures;
  if (power_of_two(++release_failures_))
    say("clearing the stop failed: %s (%llu in a row; retried every %d ms; the robot still reads a stop)",
        robot_->link().last_error().c_str(), static_cast<unsigned long long>(release_failures_), cfg_.stop_retry_ms);
  next_stop_try_ms_ = t + static_cast<uint32_t>(cfg_.stop_retry_ms);
}

void BridgeApp::try_stop(uint32_t t) {
  if (!stop_pending_ || !due(t, next_stop_try_ms_)) return;
  if (!robot_) {
    stop_pending_ = false;
    bridge_on_stop_written(core_);  // nothing will ever write it: a trial start may release it
    say("stop requested; no --robot: not written");
    return;
  }
  if (robot_->write_stop()) {
    stop_pending_ = false;
    bridge_on_stop_written(core_);
    ++stats_.stops_written;
    say("stop written to the robot controller%s", stop_failures_ ? " (after failed writes)" : "");
    stop_failures_ = 0;
  } else {
    ++stats_.stop_write_failures;
    if (power_of_two(++stop_failures_))
      say("stop write failed: %s (%llu in a row; retried every %d ms)", robot_->link().last_error().c_str(),
          static_cast<unsigned long long>(stop_failures_), cfg_.stop_retry_ms);
    next_stop_try_ms_ = t + static_cast<uint32_t>(cfg_.stop_retry_ms);
  }
}

void BridgeApp::back_off(uint32_t t) {
  next_connect_ms_ = t + static_cast<uint32_t>(backoff_ms_);
  backoff_ms_ = backoff_ms_ == 0 ? cfg_.backoff_min_ms : std::min(2 * backoff_ms_, cfg_.backoff_max_ms);
}

// One read of the sensor: a reading is published, a failure reported. False when there is
// nothing more to read now (Pending, or the sensor closed itself).
bool BridgeApp::take_reading(uint32_t t) {
  FtReading r;
  const ReadResult rr = sensor_.read(r);
  if (rr == ReadResult::Pending) return false;
  if (rr == ReadResult::Ok) {
    Frame frames[2];
    const int n = bridge_on_reading(core_, r, t, frames);
    for (int i = 0; i < n; ++i) send(frames[i]);
    ++stats_.readings;
    backoff_ms_ = 0;
    // Cleared before it is said: the status line said with it is the sensor's state now.
    if (const uint64_t failed = std::exchange(sensor_failures_, 0); failed > 0)
      say("sensor answers again after %llu failures", static_cast<unsigned long long>(failed));
    return true;
  }
  bridge_on_sensor_error(core_, t);
  ++stats_.sensor_errors;
  sensor_failed(read_result_name(rr));
  if (sensor_.connected()) return true;  // e.g. one stream frame's CRC failed: the next may be good
  // Closed after a timeout or a garbled answer (modbus_link.h): the first reconnect waits
  // reopen_quiet_ms, so that a late answer lands before the link reopens.
  back_off(t);
  const uint32_t quiet = t + static_cast<uint32_t>(sensor_.reopen_quiet_ms());
  if (!due(next_connect_ms_, quiet)) next_connect_ms_ = quiet;
  return false;
}

// A streaming sensor: every reading its line holds now (bounded: a level-triggered epoll calls
// again for the rest).
void BridgeApp::drain_sensor(uint32_t t) {
  for (int n = 0; n < 64 && sensor_.connected() && take_reading(t); ++n) {
  }
}

void BridgeApp::on_timer(uint32_t t) {
  // The sensor: reconnect with exponential backoff, else read one sample. The backoff is reset
  // by a good reading, not by a connect: a device that accepts and then fails every request is
  // retried ever more slowly too.
  if (!sensor_.connected()) {
    if (due(t, next_connect_ms_)) {
      if (sensor_.connect()) {
        // The first connect is none: the count says how often the sensor was lost and found again
        // (a healthy bridge's heartbeat said 1).
        if (sensor_was_connected_) {
          bridge_on_reconnect(core_);
          ++stats_.reconnects;
        }
        sensor_was_connected_ = true;
      } else {
        ++stats_.connect_failures;
        sensor_failed("connect");
        back_off(t);
      }
    }
  }
  if (sensor_.connected()) {
    // A polled sensor is read once per period. A streaming one is read whenever its line has
    // bytes (kSensor), and here too: that finds its silence.
    if (sensor_.events_fd() < 0) take_reading(t);
    else drain_sensor(t);
  } else {
    bridge_on_sensor_error(core_, t);
  }
  Frame hb;
  BridgeAction a;
  if (bridge_on_tick(core_, t, &hb, &a)) send(hb);
  if (a == BridgeAction::StopRobot) stop_robot(t);
  try_stop(t);
  try_release(t);
}

// The loop came back to the timer more than a period late (a read longer than a period, a busy
// machine): the periods it slept through have no sample, and the sample counter says so.
void BridgeApp::timer_overran(uint64_t periods) {
  // A polled sensor is read once per period: the periods the loop missed carry no sample. A
  // streaming one sends on its own clock, and its frames wait in the line for the late loop.
  const bool polled = sensor_.events_fd() < 0;
  if (polled) bridge_on_periods_missed(core_, static_cast<uint32_t>(std::min<uint64_t>(periods, kMaxPeriodsMissed)));
  stats_.periods_overrun += periods;
  const uint64_t overruns = ++stats_.overruns;
  if (power_of_two(overruns))
    say("timer overran: %llu period(s) of %d ms late (overrun %llu; %s)", static_cast<unsigned long long>(periods),
        cfg_.sample_period_ms, static_cast<unsigned long long>(overruns),
        polled ? "no reading in them: the sample counter skips them" : "the stream's frames wait in the line");
}

// A receive's outcome said when it fails (1st, 2nd, 4th, ... in a row) and once when it works
// again: true when a frame was read.
bool BridgeApp::received(int got, const can::RxInfo& info) {
  if (got < 0) {
    const int err = errno;
    ++stats_.receive_failures;
    if (power_of_two(++receive_failures_))
      say("CAN receive failed: %s (%llu in a row; no stop frame can reach the bridge meanwhile)", std::strerror(err),
          static_cast<unsigned long long>(receive_failures_));
    return false;
  }
  if (got == 0) return false;
  if (receive_failures_ > 0)
    say("CAN receives work again after %llu failures", static_cast<unsigned long long>(receive_failures_));
  receive_failures_ = 0;
  if (info.error_frame) error_frame(info.error_class);
  return true;
}

// A controller error frame: a restart (the recovery from bus-off) is said each time, the others
// at the 1st, 2nd, 4th, ... since the last restart (a babbling fault must not flood the log).
void BridgeApp::error_frame(uint32_t error_class) {
  ++stats_.error_frames;
  if (error_class & can::kErrorRestarted) {
    say("CAN controller restarted (after %llu error frames)", static_cast<unsigned long long>(error_frames_));
    error_frames_ = 0;
  } else if (power_of_two(++error_frames_)) {
    say("CAN error frame: %s (class 0x%X; %llu since the controller's last restart)",
        can::error_class_name(error_class), static_cast<unsigned>(error_class),
        static_cast<unsigned long long>(error_frames_));
  }
}

void BridgeApp::drain_can(uint32_t t) {
  Frame f;
  can::RxInfo info;
  for (int n = 0; n < 64 && received(port_.receive(f, info), info); ++n) {
    if (info.error_frame || info.own_echo) continue;
    const BridgeAction a = bridge_on_frame(core_, f, t);
    if (a == BridgeAction::StopRobot) stop_robot(t);
    else if (a == BridgeAction::ReleaseRobot) release_robot(t);
  }
  try_stop(t);  // in the same wakeup as the stop frame
  try_release(t);
}

void BridgeApp::begin_shutdown(uint32_t t) {
  // A stop already on the bus is taken first (the predictor's own shutdown stop comes this way
  // when both services are stopped together) ...
  drain_can(t);
  // ... and a trial still running gets the bridge's own: it is the only way to the robot.
  if (bridge_on_shutdown(core_) == BridgeAction::StopRobot) {
    stop_robot(t);
    say("shutting down during the predictor's trial %u: stopping the robot first",
        static_cast<unsigned>(core_.predictor_trial));
  }
}

void BridgeApp::say_stop_unwritten() {
  say("shutting down with a stop not written to the robot controller after %d ms (%llu failed writes): "
      "the robot may not be stopped", cfg_.shutdown_grace_ms, static_cast<unsigned long long>(stop_failures_));
}

// epoll failed: the loop cannot wait for anything any more. It is said, and the shutdown's stop
// still runs (the bridge is the only way to the robot), its retries paced by sleeping.
int BridgeApp::loop_failed(int err) {
  say("epoll_wait failed: %s; shutting down", std::strerror(err));
  uint32_t t = now_ms();
  const uint32_t give_up_ms = t + static_cast<uint32_t>(cfg_.shutdown_grace_ms);
  begin_shutdown(t);
  while (stop_pending_ && !due(t, give_up_ms)) {
    const timespec pause{cfg_.stop_retry_ms / 1000, (cfg_.stop_retry_ms % 1000) * 1000000L};
    nanosleep(&pause, nullptr);
    t = now_ms();
    try_stop(t);
  }
  if (stop_pending_) say_stop_unwritten();
  return 1;
}

int BridgeApp::run() {
  epoll_event evs[4];
  bool shutting_down = false;
  uint32_t give_up_ms = 0;
  // Ready once the loop runs: the CAN socket is open and the robot controller answered.
  if (cfg_.service) cfg_.service->ready(now_ns());
  for (;;) {
    const int n = epoll_wait(epoll_fd_, evs, 4, -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      return loop_failed(errno);
    }
    const uint32_t t = now_ms();
    bool woke[kTags] = {};
    for (int i = 0; i < n; ++i) woke[evs[i].data.u64] = true;
    if (woke[kShutdown]) {
      uint64_t v;
      [[maybe_unused]] ssize_t r = ::read(shutdown_fd_, &v, sizeof v);
      if (!shutting_down) {
        shutting_down = true;
        if (cfg_.service) cfg_.service->notify("STOPPING=1");
        give_up_ms = t + static_cast<uint32_t>(cfg_.shutdown_grace_ms);
        begin_shutdown(t);
      }
    }
    // The bus before the sensor: a stop waiting there is written before a read that may take a
    // whole response timeout (epoll lists the timer first when it expired first).
    if (woke[kCan]) drain_can(t);
    if (woke[kSensor]) {
      // No more readings once shutting down (as on the timer): the line is no longer watched.
      if (shutting_down) epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, sensor_.events_fd(), nullptr);
      else drain_sensor(t);
    }
    if (woke[kTimer]) {
      uint64_t expirations = 0;
      [[maybe_unused]] ssize_t r = ::read(timer_fd_, &expirations, sizeof expirations);
      if (shutting_down) {
        try_stop(t);  // no more readings: only the stop's retries
      } else {
        // The loop's periods keep the manager's watchdog fed (and resend a READY=1 that met a
        // full queue): a loop that hangs stops them. Before the sensor and the robot, whose
        // reads and writes may block up to their response timeouts: a slow device delays the
        // next ping, not this one (main checks those timeouts against the watchdog).
        if (cfg_.service) cfg_.service->on_tick(now_ns());
        if (expirations > 1) timer_overran(expirations - 1);
        on_timer(t);
      }
    }
    if (shutting_down) {
      if (!stop_pending_) return 0;
      if (due(t, give_up_ms)) {
        say_stop_unwritten();
        return 1;
      }
    }
  }
}

}  // namespace dressguard::bridge
