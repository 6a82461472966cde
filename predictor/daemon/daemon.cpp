// The predictor daemon's event loop, event logger, latency histogram and real-time setup.
#include "daemon.h"

#include <sched.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <spdlog/spdlog.h>
#include <system_error>

#include "notify_socket.h"

namespace dressguard::predictor {
namespace {

int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

constexpr uint64_t kTagRx = 1, kTagStop = 2, kTagTimer = 3, kTagShutdown = 4;

}  // namespace

// ---------------------------------------------------------------------------------------------

int64_t LatencyHistogram::quantile(double q) const {
  if (count_ == 0) return 0;
  const uint64_t target = static_cast<uint64_t>(q * static_cast<double>(count_ - 1)) + 1;
  uint64_t acc = 0;
  for (int b = 0; b < kBins; ++b) {
    acc += bins_[static_cast<size_t>(b)];
    if (acc >= target) return (b + 1) * bin_ns_;
  }
  return max_;  // among the values beyond the range
}

void LatencyHistogram::merge(const LatencyHistogram& o) {
  for (int b = 0; b < kBins; ++b) bins_[static_cast<size_t>(b)] += o.bins_[static_cast<size_t>(b)];
  overflow_ += o.overflow_;
  count_ += o.count_;
  if (o.max_ > max_) max_ = o.max_;
}

// ---------------------------------------------------------------------------------------------

EventLogger::EventLogger(EventQueue& q, std::shared_ptr<spdlog::logger> log, const std::vector<std::string>& names,
                         service::NotifySocket* service)
    : q_(q), log_(std::move(log)), names_(names), service_(service), thread_([this] { run(); }) {}

EventLogger::~EventLogger() { stop(); }

void EventLogger::stop() {
  if (thread_.joinable()) {
    stop_.store(true);
    thread_.join();
  }
}

void EventLogger::run() {
  Event e;
  for (;;) {
    bool any = false;
    while (q_.pop(e)) {
      log_one(e);
      any = true;
    }
    if (stop_.load() && !any) {
      while (q_.pop(e)) log_one(e);
      break;
    }
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (q_.dropped()) log_->warn("event queue overflowed: {} events were not logged", q_.dropped());
  log_->flush();
}

void EventLogger::log_one(const Event& e) {
  auto cname = [&](int c) { return c < static_cast<int>(names_.size()) ? names_[static_cast<size_t>(c)] : std::to_string(c); };
  switch (e.kind) {
    case EventKind::TrialStarted: log_->info("trial {} started", e.trial); break;
    case EventKind::TrialEnded:
      log_->info("trial {} ended after {} samples ({})", e.trial, e.value,
                 e.reason == StopReason::None ? "no stop" : protocol::stop_reason_name(e.reason));
      break;
    case EventKind::BadFrame:
      log_->warn("trial {} sample {}: frame 0x{:03X} {} (discarded)", e.trial, e.sample, e.can_id,
                 protocol::e2e_status_name(e.status));
      break;
    case EventKind::LostFrames:
      log_->warn("trial {} sample {}: {} frame(s) 0x{:03X} lost ({})", e.trial, e.sample, e.value, e.can_id,
                 protocol::e2e_status_name(e.status));
      break;
    case EventKind::KernelDrops: log_->warn("kernel dropped {} received frame(s) (receive queue full)", e.value); break;
    case EventKind::StopSent:
      log_->warn("STOP trial {} sample {}: {} (F_motion {:.2f} N, F_vertical {:.2f} N, P({})={:.3f} P({})={:.3f} P({})={:.3f})",
                 e.trial, e.sample, protocol::stop_reason_name(e.reason), e.f_motion, e.f_vertical, cname(0), e.p[0],
                 cname(1), e.p[1], cname(2), e.p[2]);
      break;
    case EventKind::StopConfirmed:
      log_->info("stop of trial {} confirmed on the bus after {} retries", e.trial, e.value);
      break;
    // A stop that cannot get out is retried every tick (500 times a second) and may fail each
    // time: logged at the 1st, 2nd, 4th, 8th, ... so that an outage of minutes writes tens of
    // lines, not tens of thousands. The counters (status pages) and "confirmed after N retries"
    // keep the exact numbers.
    case EventKind::StopRetry:
      if (power_of_two(e.value)) log_->warn("stop of trial {} not confirmed: {} retries so far", e.trial, e.value);
      break;
    case EventKind::TxError:
      if (power_of_two(++tx_errors_))
        log_->error("send of 0x{:03X} failed: {} ({} failed sends so far)", e.can_id,
                    can::send_result_name(static_cast<can::SendResult>(e.send_result)), tx_errors_);
      break;
    case EventKind::BusError: log_->error("CAN controller error frame, class 0x{:X}", e.value); break;
    case EventKind::ModelMissing: log_->error("trial {} refused: no model loaded", e.trial); break;
    case EventKind::StopDropped:
      log_->warn("stop of trial {} ({}) not confirmed {} us after it was sent: dropped, a new trial started", e.trial,
                 protocol::stop_reason_name(e.reason), e.value);
      break;
    case EventKind::ReceiveError:
      // An interface taken down (ENETDOWN) reports once per socket; one unregistered (ENODEV, a
      // USB adapter unplugged) ends the loop (PredictorDaemon::run).
      if (power_of_two(e.sample))
        log_->error("receive on the {} socket failed: {} ({} failures so far)", e.can_id ? "stop" : "frame",
                    std::strerror(static_cast<int>(e.value)), e.sample);
      break;
    case EventKind::Posteriors: break;
  }
  if (service_) tell_status(e);
}

void EventLogger::tell_status(const Event& e) {
  std::string now;
  switch (e.kind) {
    case EventKind::TrialStarted:
      ++trials_;
      now = fmt::format("trial {} running", e.trial);
      break;
    case EventKind::StopSent:
      ++stopped_;
      last_stop_ = fmt::format("trial {}, {}", e.trial, protocol::stop_reason_name(e.reason));
      now = fmt::format("trial {} stopped: {}", e.trial, protocol::stop_reason_name(e.reason));
      break;
    case EventKind::TrialEnded: now = "idle"; break;
    case EventKind::ModelMissing: now = fmt::format("trial {} refused: no model", e.trial); break;
    default: return;
  }
  const std::string status = fmt::format("STATUS={}; trials {}, stopped {}{}", now, trials_, stopped_,
                                         last_stop_.empty() ? "" : " (last: " + last_stop_ + ")");
  service_->notify(status.c_str());
}

// ---------------------------------------------------------------------------------------------

std::vector<uint32_t> PredictorDaemon::receive_ids() {
  using protocol::MsgId;
  return {protocol::id_of(MsgId::FtForce), protocol::id_of(MsgId::FtTorque), protocol::id_of(MsgId::TrialStart),
          protocol::id_of(MsgId::TrialEnd), protocol::id_of(MsgId::HeartbeatBridge)};
}

PredictorDaemon::PredictorDaemon(const model::OutcomeModel* model, const PredictorConfig& cfg, can::CanPort& rx,
                                 can::CanPort& stop_port, EventQueue& events, const DaemonOptions& opt)
    : rx_(rx), stop_port_(stop_port), events_(events), opt_(opt), predictor_(model, cfg, *this) {
  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  timer_fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  shutdown_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (epoll_fd_ < 0 || timer_fd_ < 0 || shutdown_fd_ < 0)
    throw std::system_error(errno, std::generic_category(), "epoll/timerfd/eventfd");
  auto add = [&](int fd, uint64_t tag) {
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = tag;
    if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev) < 0) throw std::system_error(errno, std::generic_category(), "epoll_ctl");
  };
  add(rx_.fd(), kTagRx);
  add(stop_port_.fd(), kTagStop);
  add(timer_fd_, kTagTimer);
  add(shutdown_fd_, kTagShutdown);
  itimerspec its{};
  its.it_interval.tv_sec = opt_.tick_ns / 1000000000;
  its.it_interval.tv_nsec = opt_.tick_ns % 1000000000;
  its.it_value = its.it_interval;
  if (timerfd_settime(timer_fd_, 0, &its, nullptr) < 0) throw std::system_error(errno, std::generic_category(), "timerfd_settime");
}

PredictorDaemon::~PredictorDaemon() {
  for (int fd : {epoll_fd_, timer_fd_, shutdown_fd_})
    if (fd >= 0) ::close(fd);
}

void PredictorDaemon::request_shutdown() noexcept {
  const uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(shutdown_fd_, &one, sizeof one);
}

uint8_t PredictorDaemon::transmit_stop(const Frame& f) noexcept {
  ++stops_sent_;
  return static_cast<uint8_t>(stop_port_.send(f));
}

uint8_t PredictorDaemon::transmit(const Frame& f) noexcept {
  // Heartbeats, status pages and posteriors: a failure is not retried (the next one supersedes
  // it) but logged, at each doubling, as a stop's is: an interface down must not go unsaid.
  const can::SendResult r = rx_.send(f);
  if (r != can::SendResult::Ok) {
    Event e;
    e.kind = EventKind::TxError;
    e.can_id = f.id;
    e.send_result = static_cast<uint8_t>(r);
    events_.push(e);
  }
  return static_cast<uint8_t>(r);
}

void PredictorDaemon::receive_failed(int err, bool stop_socket, int64_t now) noexcept {
  Event e;
  e.kind = EventKind::ReceiveError;
  e.time_ns = now;
  e.value = static_cast<uint32_t>(err);
  e.sample = ++receive_errors_;
  e.can_id = stop_socket ? 1 : 0;
  events_.push(e);
  if (err == ENODEV) interface_gone_ = true;
}

void PredictorDaemon::event(const Event& e) noexcept { events_.push(e); }

void PredictorDaemon::drain_rx(int64_t) noexcept {
  Frame f;
  can::RxInfo info;
  // Bounded: a babbling bus cannot starve the timer and the stop socket.
  for (int n = 0; n < 64; ++n) {
    const int r = rx_.receive(f, info);
    if (r < 0) receive_failed(errno, false, now_ns());
    if (r <= 0) break;
    if (info.error_frame) {
      predictor_.on_bus_error(info.error_class, info.rx_time_ns);
      continue;
    }
    predictor_.on_kernel_drops(info.kernel_drops, info.rx_time_ns);
    const uint32_t stops_before = stops_sent_;
    predictor_.on_frame(f, info.rx_time_ns);
    if (f.id == protocol::id_of(protocol::MsgId::FtForce)) {
      const int64_t dt = now_ns() - info.rx_time_ns;
      (stops_sent_ != stops_before ? processing_stop_ : processing_).add(dt);
    }
  }
}

void PredictorDaemon::drain_stop(int64_t now) noexcept {
  Frame f;
  can::RxInfo info;
  for (int n = 0; n < 64; ++n) {
    const int r = stop_port_.receive(f, info);
    if (r < 0) receive_failed(errno, true, now);
    if (r <= 0) break;
    if (info.error_frame) {
      predictor_.on_bus_error(info.error_class, now);
      continue;
    }
    if (info.own_echo) predictor_.on_stop_echo(f, now);
  }
}

int PredictorDaemon::run() {
  epoll_event evs[8];
  int64_t shutdown_at = -1;
  // Ready once the loop runs: the sockets are bound and the model read, so the units ordered
  // after this one start with the bus guarded.
  if (opt_.service) opt_.service->ready(now_ns());
  for (;;) {
    const int n = epoll_wait(epoll_fd_, evs, 8, shutdown_at >= 0 ? 1 : -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      predictor_.on_shutdown(now_ns());  // cannot wait any more: a running trial is stopped first
      return 1;
    }
    const int64_t now = now_ns();
    // Frames first, then the timer: when the thread was late, the frames that waited must
    // count before the deadline is judged (never a timeout for samples already queued).
    bool timer = false, shutdown = false;
    for (int i = 0; i < n; ++i) {
      switch (evs[i].data.u64) {
        case kTagRx: drain_rx(now); break;
        case kTagStop: drain_stop(now); break;
        case kTagTimer: timer = true; break;
        case kTagShutdown: shutdown = true; break;
      }
    }
    if (timer) {
      uint64_t expirations;
      [[maybe_unused]] ssize_t r = ::read(timer_fd_, &expirations, sizeof expirations);
      const int64_t t = now_ns();
      predictor_.on_tick(t);
      // The loop's ticks keep the manager's watchdog fed (and resend a READY=1 that met a full
      // queue): a loop that hangs stops them.
      if (opt_.service) opt_.service->on_tick(t);
    }
    if (shutdown) {
      uint64_t v;
      [[maybe_unused]] ssize_t r = ::read(shutdown_fd_, &v, sizeof v);
      if (shutdown_at < 0) {
        shutdown_at = now;
        if (opt_.service) opt_.service->notify("STOPPING=1");
        predictor_.on_shutdown(now);
      }
    }
    // The interface was unregistered (ENODEV): the sockets are unbound and hear nothing again.
    // Exit 1 so that the service manager restarts the daemon on the interface when it is back.
    if (interface_gone_) {
      predictor_.on_shutdown(now);
      return 1;
    }
    // Clean shutdown once no stop is waiting for its echo; 1 when the grace ran out with one
    // waiting (the robot may not be stopped: said by main, and the service manager sees it).
    if (shutdown_at >= 0 && !predictor_.stop_pending()) return 0;
    if (shutdown_at >= 0 && now - shutdown_at > opt_.shutdown_grace_ns) return 1;
  }
}

// ---------------------------------------------------------------------------------------------

namespace {

// Read by the signal handler: atomic, and lock-free, so async-signal-safe.
std::atomic<PredictorDaemon*> g_signalled_daemon{nullptr};
static_assert(std::atomic<PredictorDaemon*>::is_always_lock_free);

void on_shutdown_signal(int) {
  if (PredictorDaemon* d = g_signalled_daemon.load()) d->request_shutdown();
}

void set_handler(int sig, void (*handler)(int)) {
  struct sigaction sa{};
  sa.sa_handler = handler;
  sigemptyset(&sa.sa_mask);
  sigaction(sig, &sa, nullptr);
}

}  // namespace

void ignore_hangup_and_broken_pipe() {
  set_handler(SIGHUP, SIG_IGN);
  set_handler(SIGPIPE, SIG_IGN);
}

void handle_signals(PredictorDaemon* daemon) {
  g_signalled_daemon.store(daemon);
  set_handler(SIGTERM, on_shutdown_signal);
  set_handler(SIGINT, on_shutdown_signal);
  ignore_hangup_and_broken_pipe();
}

// ---------------------------------------------------------------------------------------------

namespace {

// CAP_IPC_LOCK (bit 14) in the process's effective set, /proc's CapEff: it lifts RLIMIT_MEMLOCK.
bool has_ipc_lock() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.compare(0, 7, "CapEff:") == 0) return (std::stoull(line.substr(7), nullptr, 16) >> 14) & 1u;
  return false;
}

// The finite RLIMIT_MEMLOCK in KiB that mlockall would be held to, or -1 when none holds it.
// Under one, MCL_FUTURE counts every later mapping against it, so an allocation past it fails
// on the loop (an error, perhaps while a stop is sent) where a page fault was only a delay.
long long memlock_limit_kib() {
  rlimit lim{};
  if (getrlimit(RLIMIT_MEMLOCK, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY || has_ipc_lock()) return -1;
  return static_cast<long long>(lim.rlim_cur / 1024);
}

// Locks the process's memory, now and later, and faults in a stack reserve: "", or why not.
std::string lock_memory() {
  if (const long long kib = memlock_limit_kib(); kib >= 0)
    return "mlockall not tried: RLIMIT_MEMLOCK is " + std::to_string(kib) +
           " KiB without CAP_IPC_LOCK, and locking all later memory under it makes an allocation past it fail on "
           "the hot path; grant CAP_IPC_LOCK or LimitMEMLOCK=infinity";
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    return std::string("mlockall failed (") + std::strerror(errno) +
           "): pages may fault in on the hot path; grant CAP_IPC_LOCK or LimitMEMLOCK=infinity";
  // Touch a stack reserve now so that deeper calls later do not fault.
  volatile char reserve[256 * 1024];
  for (size_t i = 0; i < sizeof reserve; i += 4096) reserve[i] = 0;
  return {};
}

}  // namespace

std::vector<std::string> setup_realtime(const RtOptions& opt) {
  std::vector<std::string> warnings;
  if (opt.lock_memory)
    if (std::string why = lock_memory(); !why.empty()) warnings.push_back(std::move(why));
  if (opt.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(opt.cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0)
      warnings.push_back("CPU affinity to CPU " + std::to_string(opt.cpu) + " failed (" + std::strerror(errno) + ")");
  }
  if (opt.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = opt.fifo_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      warnings.push_back("SCHED_FIFO priority " + std::to_string(opt.fifo_priority) + " not permitted (" +
                         std::strerror(errno) + "): running as SCHED_OTHER; grant CAP_SYS_NICE or LimitRTPRIO");
  }
  return warnings;
}

}  // namespace dressguard::predictor
