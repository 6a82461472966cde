// The daemon's event loop on the in-process CAN bus (SocketCAN semantics, this host has no
// AF_CAN): the robot side hears the stop frames, the stop is confirmed by its own echo, a silent
// sensor is stopped by the deadline, SIGTERM's path shuts down cleanly, the logger thread writes
// what happened through spdlog, and the loop thread allocates nothing after start-up (in every
// test that runs it on a Rig).
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sstream>
#include <thread>

#include "alloc_counter.h"
#include "daemon.h"
#include "notify_listener.h"
#include "notify_socket.h"
#include "test_model.h"

using namespace dressguard;
using namespace dressguard::predictor;
using namespace std::chrono_literals;

namespace {

struct Rig {
  can::InProcBus bus;
  std::unique_ptr<can::CanPort> rx, stop_port, sensor, robot;
  model::OutcomeModel model = testkit::test_model();
  EventQueue events;
  std::ostringstream log_text;
  std::shared_ptr<spdlog::logger> log;
  std::unique_ptr<EventLogger> logger;
  std::unique_ptr<PredictorDaemon> daemon;
  std::thread loop;
  int rc = -1;
  uint64_t loop_allocations = 0;
  testkit::FrameSource src;

  explicit Rig(bool with_model = true, const DaemonOptions& opt = {}) {
    model.speed_min_m_s = 0.1;  // trained at the study's speeds (format version 3)
    model.speed_max_m_s = 0.15;
    rx = bus.open({PredictorDaemon::receive_ids(), false, true});
    stop_port = bus.open({{protocol::id_of(protocol::MsgId::Stop)}, true, true});
    sensor = bus.open({{}, false, true});
    robot = bus.open({{protocol::id_of(protocol::MsgId::Stop), protocol::id_of(protocol::MsgId::PredictorStatus)}, false, true});
    log = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::ostream_sink_mt>(log_text));
    logger = std::make_unique<EventLogger>(events, log, std::vector<std::string>{"good", "missed", "caught"},
                                           opt.service);
    daemon = std::make_unique<PredictorDaemon>(with_model ? &model : nullptr, PredictorConfig{}, *rx, *stop_port, events,
                                               opt);
    loop = std::thread([this] {
      testkit::CountAllocations count;
      rc = daemon->run();
      loop_allocations = count.count();
    });
  }
  // Every test's loop, not only the caught trial's: the timeout, the retries, the shutdown with
  // and without its echo, the refusal without a model and the ignored signals run on it too.
  ~Rig() {
    shutdown();
    EXPECT_EQ(loop_allocations, 0u) << "the event loop allocated after start-up";
  }
  void shutdown() {
    if (loop.joinable()) {
      daemon->request_shutdown();
      loop.join();
      logger->stop();
    }
  }
  void send_sample(double f_motion, double f_vertical) {
    sensor->send(src.force(f_motion, f_vertical));
    sensor->send(src.torque());
    src.next();
  }
  // Waits up to `timeout` for a stop frame on the robot's port.
  bool wait_stop(protocol::Stop& s, std::chrono::milliseconds timeout = 2000ms) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    protocol::Frame f;
    can::RxInfo info;
    while (std::chrono::steady_clock::now() < end) {
      while (robot->receive(f, info) == 1)
        if (protocol::decode(f, s)) return true;
      std::this_thread::sleep_for(200us);
    }
    return false;
  }
};

TEST(Daemon, CaughtTrialIsStoppedAndConfirmedByEcho) {
  Rig rig;
  rig.sensor->send(rig.src.trial_start(11));
  for (int i = 0; i < 10; ++i) {
    rig.send_sample(-2.0, 0.0);
    std::this_thread::sleep_for(1ms);
  }
  protocol::Stop s{};
  for (int i = 0; i < 30 && !rig.wait_stop(s, 5ms); ++i) rig.send_sample(-6.0, -1.0);
  ASSERT_EQ(s.reason, protocol::StopReason::Caught);
  EXPECT_EQ(s.trial_id, 11);
  EXPECT_GE(s.sample, 12) << "10 good samples, then at least 3 caught ones";
  // The echo on the stop socket confirms the stop (allow the loop a moment).
  for (int i = 0; i < 100 && rig.daemon->predictor().stop_pending(); ++i) std::this_thread::sleep_for(1ms);
  EXPECT_FALSE(rig.daemon->predictor().stop_pending());
  rig.shutdown();
  EXPECT_EQ(rig.rc, 0);
  EXPECT_NE(rig.log_text.str().find("STOP trial 11"), std::string::npos) << rig.log_text.str();
  EXPECT_NE(rig.log_text.str().find("confirmed"), std::string::npos) << rig.log_text.str();
  EXPECT_EQ(rig.loop_allocations, 0u) << "the event loop allocated after start-up";
  EXPECT_GE(rig.daemon->processing().count() + rig.daemon->processing_with_stop().count(), 13u);
}

// Under systemd (Type=notify, WatchdogSec=): READY=1 once the loop runs, WATCHDOG=1 from the
// loop's ticks at half the manager's interval, STOPPING=1 at shutdown, all from this process;
// the Rig's destructor asserts that the loop allocated nothing meanwhile.
TEST(Daemon, TellsTheServiceManagerItIsReadyAndFeedsItsWatchdog) {
  testkit::NotifyListener manager(false);
  ASSERT_EQ(manager.error, "");
  // WatchdogSec=0.04: a ping every 20 ms from the 1 ms ticks.
  service::NotifySocket notify = service::NotifySocket::open(manager.address.c_str(), "40000", nullptr, ::getpid());
  ASSERT_TRUE(notify.connected()) << notify.error();
  DaemonOptions opt;
  opt.service = &notify;
  {
    Rig r(true, opt);
    for (int i = 0; i < 100; ++i) {
      if (i == 60) r.send_sample(-1.0, 0.0);  // a trial's frames do not hold the pings back
      std::this_thread::sleep_for(5ms);
      manager.take(::getpid());
    }
    r.shutdown();
    manager.take(::getpid());
    // Every 20 ms over ~0.5 s: about 25 pings (a ping late by a tick restarts the period there).
    EXPECT_EQ(manager.wrong_with_what_was_said(0.020, 0.021), "");
  }
  EXPECT_EQ(notify.failed_sends(), 0u);
}

// The unit's status line (`systemctl status`) follows the trials: set by the logging thread at
// each trial's start, stop and end, never by the loop.
TEST(Daemon, TheUnitsStatusLineFollowsTheTrials) {
  testkit::NotifyListener manager(false);
  ASSERT_EQ(manager.error, "");
  service::NotifySocket notify = service::NotifySocket::open(manager.address.c_str(), nullptr, nullptr, ::getpid());
  ASSERT_TRUE(notify.connected()) << notify.error();
  DaemonOptions opt;
  opt.service = &notify;
  Rig rig(true, opt);
  rig.sensor->send(rig.src.trial_start(11));
  for (int i = 0; i < 10; ++i) rig.send_sample(-2.0, 0.0);
  protocol::Stop s{};
  for (int i = 0; i < 30 && !rig.wait_stop(s, 5ms); ++i) rig.send_sample(-6.0, -1.0);
  ASSERT_EQ(s.reason, protocol::StopReason::Caught);
  rig.sensor->send(rig.src.trial_end(11, 20));
  rig.sensor->send(rig.src.trial_start(12));
  const std::string second_running = "STATUS=trial 12 running; trials 2, stopped 1 (last: trial 11, caught)";
  manager.wait_for(second_running, ::getpid());
  rig.shutdown();
  manager.take(::getpid());
  std::vector<std::string> statuses;
  for (const auto& m : manager.heard)
    if (m.rfind("STATUS=", 0) == 0) statuses.push_back(m);
  const std::vector<std::string> want = {
      "STATUS=trial 11 running; trials 1, stopped 0",
      "STATUS=trial 11 stopped: caught; trials 1, stopped 1 (last: trial 11, caught)",
      "STATUS=idle; trials 1, stopped 1 (last: trial 11, caught)",
      "STATUS=trial 12 running; trials 2, stopped 1 (last: trial 11, caught)",
      // The shutdown stops the running trial first.
      "STATUS=trial 12 stopped: shutdown; trials 2, stopped 2 (last: trial 12, shutdown)",
  };
  EXPECT_EQ(statuses, want);
  EXPECT_FALSE(manager.other_sender);
}

// A trial at a speed the model was never trained at (300 mm/s against 100-150) is counted on
// the loop without a log line or an allocation, and reported in the shutdown line's counters.
TEST(Daemon, ATrialOutsideTheTrainingSpeedsIsCountedWithoutAllocating) {
  Rig rig;
  rig.sensor->send(rig.src.trial_start(12, 300));
  for (int i = 0; i < 200 && rig.daemon->predictor().trials_outside_training_speeds() == 0; ++i)
    std::this_thread::sleep_for(1ms);
  rig.shutdown();
  EXPECT_EQ(rig.daemon->predictor().trials_outside_training_speeds(), 1u);
  EXPECT_EQ(rig.loop_allocations, 0u) << "the event loop allocated after start-up";
}

TEST(Daemon, SilentSensorIsAFailSafeStop) {
  Rig rig;
  rig.sensor->send(rig.src.trial_start(2));
  for (int i = 0; i < 5; ++i) rig.send_sample(-2.0, 0.0);
  const auto t0 = std::chrono::steady_clock::now();
  protocol::Stop s{};
  ASSERT_TRUE(rig.wait_stop(s));
  const auto waited = std::chrono::steady_clock::now() - t0;
  EXPECT_EQ(s.reason, protocol::StopReason::SensorTimeout);
  // The deadline is 50 ms; the lower bound is exact (no early stop). The upper bound only says
  // "the timer works": this shared host's scheduling is not a real-time measurement.
  EXPECT_GE(waited, 49ms);
  EXPECT_LT(waited, 1000ms);
}

TEST(Daemon, UnconfirmedStopIsRetriedUntilTheEchoComes) {
  Rig rig;
  rig.bus.set_echo(false);
  rig.sensor->send(rig.src.trial_start(4));
  rig.send_sample(-25.0, 0.0);  // hard limit
  protocol::Stop s{};
  ASSERT_TRUE(rig.wait_stop(s));
  EXPECT_EQ(s.reason, protocol::StopReason::HardLimit);
  std::this_thread::sleep_for(20ms);  // retries every 2 ms while the echo is missing
  EXPECT_TRUE(rig.daemon->predictor().stop_pending());
  rig.bus.set_echo(true);
  for (int i = 0; i < 200 && rig.daemon->predictor().stop_pending(); ++i) std::this_thread::sleep_for(1ms);
  EXPECT_FALSE(rig.daemon->predictor().stop_pending());
  EXPECT_GE(rig.daemon->predictor().counter(protocol::StatusCounter::TxRetries), 3u);
  int stops = 1;
  while (rig.wait_stop(s, 5ms)) ++stops;
  EXPECT_GE(stops, 4) << "the robot heard the retries";
}

// A stop that cannot get out for 2 s: 1000 retries, each send failing. The log keeps a line per
// doubling (1, 2, 4, ..., 512: 10 of each kind), not one per retry.
TEST(EventLogger, RetriesAndFailedSendsAreLoggedAtEachDoubling) {
  EventQueue q;
  for (uint32_t i = 1; i <= 1000; ++i) {
    Event r;
    r.kind = EventKind::StopRetry;
    r.trial = 7;
    r.value = i;
    Event t;
    t.kind = EventKind::TxError;
    t.can_id = protocol::id_of(protocol::MsgId::Stop);
    t.send_result = static_cast<uint8_t>(can::SendResult::NoBuffers);
    ASSERT_TRUE(q.push(r) && q.push(t));
  }
  std::ostringstream text;
  auto log = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::ostream_sink_mt>(text));
  {
    EventLogger logger(q, log, {"good", "missed", "caught"});
  }
  std::istringstream lines(text.str());
  int retries = 0, failures = 0;
  for (std::string l; std::getline(lines, l);) {
    retries += l.find("not confirmed") != std::string::npos;
    failures += l.find("failed sends so far") != std::string::npos;
  }
  EXPECT_EQ(retries, 10);
  EXPECT_EQ(failures, 10);
  EXPECT_NE(text.str().find("stop of trial 7 not confirmed: 512 retries so far"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("(512 failed sends so far)"), std::string::npos) << text.str();
}

// A young stop dropped at the next trial's start gets its own line: trial, reason and age.
TEST(EventLogger, ADroppedStopIsLogged) {
  EventQueue q;
  Event e;
  e.kind = EventKind::StopDropped;
  e.trial = 9;
  e.reason = protocol::StopReason::Caught;
  e.value = 1500;
  ASSERT_TRUE(q.push(e));
  std::ostringstream text;
  auto log = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::ostream_sink_mt>(text));
  {
    EventLogger logger(q, log, {"good", "missed", "caught"});
  }
  const std::string want = std::string("stop of trial 9 (") + protocol::stop_reason_name(protocol::StopReason::Caught) +
                           ") not confirmed 1500 us after it was sent: dropped";
  EXPECT_NE(text.str().find(want), std::string::npos) << text.str();
}

TEST(Daemon, ShutdownDuringATrialStopsTheRobotFirst) {
  Rig rig;
  rig.sensor->send(rig.src.trial_start(5));
  for (int i = 0; i < 3; ++i) rig.send_sample(-2.0, 0.0);
  std::this_thread::sleep_for(5ms);
  rig.shutdown();
  EXPECT_EQ(rig.rc, 0);
  protocol::Stop s{};
  ASSERT_TRUE(rig.wait_stop(s, 100ms));
  EXPECT_EQ(s.reason, protocol::StopReason::Shutdown);
}

// The shutdown stop never confirmed (no echo: bus-off, no ACK): the daemon retries it through its
// 1 s grace, then exits 1 with the stop still pending (main says "the robot may not be
// stopped"); it used to exit 0 after 50 ms.
TEST(Daemon, AShutdownStopNeverConfirmedIsAFailedExit) {
  Rig rig;
  rig.bus.set_echo(false);
  rig.sensor->send(rig.src.trial_start(7));
  for (int i = 0; i < 3; ++i) rig.send_sample(-2.0, 0.0);
  std::this_thread::sleep_for(5ms);
  const auto t0 = std::chrono::steady_clock::now();
  rig.shutdown();
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 1000ms);
  EXPECT_EQ(rig.rc, 1);
  EXPECT_TRUE(rig.daemon->predictor().stop_pending());
  EXPECT_GE(rig.daemon->predictor().counter(protocol::StatusCounter::TxRetries), 100u) << "retried through the grace";
}

// A port whose next receive fails with a chosen errno (as SocketCAN reports an interface taken
// down, ENETDOWN, or unregistered, ENODEV, once on the socket); otherwise the in-process port.
class FailingPort final : public can::CanPort {
 public:
  explicit FailingPort(std::unique_ptr<can::CanPort> inner) : inner_(std::move(inner)) {}
  int fd() const override { return inner_->fd(); }
  int receive(protocol::Frame& f, can::RxInfo& info) noexcept override {
    if (const int e = fail_with.exchange(0)) {
      errno = e;
      return -1;
    }
    return inner_->receive(f, info);
  }
  can::SendResult send(const protocol::Frame& f) noexcept override { return inner_->send(f); }
  std::atomic<int> fail_with{0};

 private:
  std::unique_ptr<can::CanPort> inner_;
};

// An interface taken down is said on the log, and the daemon goes on; one unregistered (a USB
// adapter unplugged: the sockets are unbound for good) ends it with exit 1 for the service
// manager to restart it. Both used to pass in silence.
TEST(Daemon, ReceiveErrorsAreLoggedAndAVanishedInterfaceEndsTheLoop) {
  can::InProcBus bus;
  FailingPort rx(bus.open({PredictorDaemon::receive_ids(), false, true}));
  auto stop_port = bus.open({{protocol::id_of(protocol::MsgId::Stop)}, true, true});
  auto sensor = bus.open({{}, false, true});
  const model::OutcomeModel model = testkit::test_model();
  EventQueue events;
  std::ostringstream text;
  auto log = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::ostream_sink_mt>(text));
  EventLogger logger(events, log, {"good", "missed", "caught"});
  PredictorDaemon daemon(&model, PredictorConfig{}, rx, *stop_port, events);
  std::atomic<int> rc{-1};
  std::thread loop([&] { rc = daemon.run(); });
  testkit::FrameSource src;
  rx.fail_with = ENETDOWN;
  sensor->send(src.trial_start(3));  // wakes the loop: its receive fails, the frame waits
  for (int i = 0; i < 200 && daemon.predictor().decision().trial != 3; ++i) std::this_thread::sleep_for(1ms);
  EXPECT_EQ(daemon.predictor().decision().trial, 3) << "the frame after the failure was still read";
  EXPECT_EQ(rc.load(), -1) << "an interface down is not the end";
  rx.fail_with = ENODEV;
  sensor->send(src.trial_end(3, 0));
  for (int i = 0; i < 1000 && rc.load() < 0; ++i) std::this_thread::sleep_for(1ms);
  if (rc.load() < 0) daemon.request_shutdown();
  loop.join();
  logger.stop();
  EXPECT_EQ(rc.load(), 1);
  EXPECT_NE(text.str().find("receive on the frame socket failed: " + std::string(std::strerror(ENETDOWN)) +
                            " (1 failures so far)"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find(std::strerror(ENODEV)), std::string::npos) << text.str();
}

// SIGHUP (an operator's "reload", a closed terminal) and SIGPIPE (a log pipe whose reader died)
// ended the process at once, mid-trial, with no stop, and systemd took that for a clean exit and
// did not restart the unit. Both are now ignored: the daemon goes on guarding the trial, and
// SIGTERM still shuts it down cleanly.
TEST(Daemon, HangupAndBrokenPipeDoNotEndTheDaemon) {
  Rig rig;
  handle_signals(rig.daemon.get());
  rig.sensor->send(rig.src.trial_start(4));
  ASSERT_EQ(raise(SIGHUP), 0);
  ASSERT_EQ(raise(SIGPIPE), 0);
  protocol::Stop s{};
  for (int i = 0; i < 30 && !rig.wait_stop(s, 5ms); ++i) rig.send_sample(-6.0, -1.0);
  EXPECT_EQ(s.reason, protocol::StopReason::Caught) << "the trial after SIGHUP and SIGPIPE was guarded";
  EXPECT_EQ(s.trial_id, 4);
  ASSERT_EQ(raise(SIGTERM), 0);
  rig.loop.join();
  rig.logger->stop();
  handle_signals(nullptr);
  EXPECT_EQ(rig.rc, 0) << "SIGTERM: a clean shutdown";
}

TEST(Daemon, WithoutAModelEveryTrialIsRefused) {
  Rig rig(false);
  rig.sensor->send(rig.src.trial_start(9));
  protocol::Stop s{};
  ASSERT_TRUE(rig.wait_stop(s));
  EXPECT_EQ(s.reason, protocol::StopReason::ModelError);
}

// A latency beyond the histogram's range (kBins x bin_ns) is counted apart, not in the last bin:
// folded into it, a 1 ms stall read as the bin [409.5, 409.6) us on every picture and report.
TEST(LatencyHistogram, AValueBeyondTheRangeIsOverflowNotTheLastBin) {
  LatencyHistogram h(100);  // 100 ns bins: [0, 409.6 us)
  const int64_t range = LatencyHistogram::kBins * int64_t{100};
  h.add(range - 1);  // the last bin's own value
  h.add(range);      // the first beyond
  h.add(10 * range);
  EXPECT_EQ(h.bins().back(), 1u) << "a value beyond the range went into the last bin";
  EXPECT_EQ(h.overflow(), 2u);
  EXPECT_EQ(h.range_ns(), range);
  EXPECT_EQ(h.count(), 3u);
  EXPECT_EQ(h.max(), 10 * range);
  // The median lies in the last bin (its upper edge); the top quantile beyond it (the maximum).
  EXPECT_EQ(h.quantile(0.0), range);
  EXPECT_EQ(h.quantile(1.0), 10 * range);
  // Merged, the overflow adds up as the bins do; adding allocates nothing (the real-time loop's).
  LatencyHistogram g(100);
  {
    testkit::CountAllocations allocs;
    g.add(range + 5);
    g.add(50);
    EXPECT_EQ(allocs.count(), 0u);
  }
  g.merge(h);
  EXPECT_EQ(g.overflow(), 3u);
  EXPECT_EQ(g.count(), 5u);
  EXPECT_EQ(g.bins().front(), 1u);
  EXPECT_EQ(g.bins().back(), 1u);
}

}  // namespace
