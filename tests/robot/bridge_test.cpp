// The firmware bridge: its portable core (frames per reading, the stop latch, heartbeats), and
// the Linux port against real Modbus TCP peers on 127.0.0.1 (dg_modbus_emulator, a libmodbus
// server with fault injection, as the sensor and as the robot controller) with the CAN side on
// the in-process bus; mbpoll as an independent Modbus client checks what the peers hold.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <modbus.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>
#include <time.h>
#include <vector>

#include "bridge_app.h"
#include "ft300_stream.h"
#include "bridge_core.h"
#include "notify_listener.h"
#include "notify_socket.h"
#include "can_port.h"

using namespace dressguard;
using namespace dressguard::bridge;
using namespace std::chrono_literals;

// The machine's uptime as the bridge sees it: CLOCK_MONOTONIC plus g_uptime_shift_ms. Defined in
// this executable, clock_gettime takes the place of libc's for the code linked in statically
// (the bridge's libraries); libstdc++'s steady_clock, which the tests time with, keeps libc's.
static std::atomic<int64_t> g_uptime_shift_ms{0};
extern "C" int clock_gettime(clockid_t id, timespec* ts) noexcept {
  using Real = int (*)(clockid_t, timespec*);
  static const Real real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "clock_gettime"));
  const int r = real(id, ts);
  const int64_t shift = g_uptime_shift_ms.load();
  if (r == 0 && id == CLOCK_MONOTONIC && shift != 0) {
    const int64_t ns = ts->tv_nsec + shift % 1000 * 1000000;
    ts->tv_sec += shift / 1000 + ns / 1000000000;
    ts->tv_nsec = ns % 1000000000;
  }
  return r;
}

// While set, epoll_wait fails with EBADF, for the bridge's loop (linked in statically, as above).
static std::atomic<bool> g_fail_epoll{false};
extern "C" int epoll_wait(int epfd, epoll_event* events, int maxevents, int timeout) {
  using Real = int (*)(int, epoll_event*, int, int);
  static const Real real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "epoll_wait"));
  if (g_fail_epoll.load()) {
    errno = EBADF;
    return -1;
  }
  return real(epfd, events, maxevents, timeout);
}

namespace {

// ---- portable core ---------------------------------------------------------------------------

// The heartbeat a tick at `t` must send (one is due).
protocol::HeartbeatBridge heartbeat_at(BridgeCore& c, uint32_t t) {
  Frame hb;
  BridgeAction a;
  EXPECT_EQ(bridge_on_tick(c, t, &hb, &a), 1);
  protocol::HeartbeatBridge m{};
  EXPECT_TRUE(protocol::decode(hb, m));
  return m;
}

TEST(BridgeCore, ReadingBecomesTwoFramesWithOneCounter) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  Frame f[2];
  for (int i = 0; i < 300; ++i) {
    ASSERT_EQ(bridge_on_reading(c, FtReading{{-250, 30, -1000}, {15, -2, 0}}, i * 10, f), 2);
    protocol::FtForce force;
    protocol::FtTorque torque;
    ASSERT_TRUE(protocol::decode(f[0], force));
    ASSERT_TRUE(protocol::decode(f[1], torque));
    EXPECT_EQ(force.counter, static_cast<uint8_t>(i));
    EXPECT_EQ(torque.counter, force.counter);
    EXPECT_EQ(force.fz, -1000);
    EXPECT_EQ(torque.my, -2);
  }
  EXPECT_EQ(bridge_state(c), protocol::BridgeState::Ok);
}

// The sample counter counts sample periods, not readings: a failed read and the periods the
// port's timer overran advance it, so the receiver's E2E check counts their samples as lost (it
// counted one sample for any gap: the predictor's logical time fell behind the robot's). A gap
// of more than 127 periods advances it by 127, the most that does not read as a late frame.
TEST(BridgeCore, FailedReadsAndOverrunsAdvanceTheSampleCounter) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  protocol::E2EChecker receiver(protocol::MsgId::FtForce);
  uint32_t t = 0;
  const auto lost_before_next_reading = [&] {
    Frame f[2];
    bridge_on_reading(c, FtReading{{1, 2, 3}, {4, 5, 6}}, t += 10, f);
    uint32_t lost = 0;
    EXPECT_TRUE(protocol::accepted(receiver.check(f[0], lost))) << "sample at " << t;
    EXPECT_EQ(f[0].data[1], f[1].data[1]) << "force and torque counters";
    return lost;
  };
  EXPECT_EQ(lost_before_next_reading(), 0u);
  bridge_on_sensor_error(c, t += 10);
  EXPECT_EQ(lost_before_next_reading(), 1u) << "a failed read";
  bridge_on_periods_missed(c, 3);
  bridge_on_sensor_error(c, t += 40);
  EXPECT_EQ(lost_before_next_reading(), 4u) << "an overrun of 3 periods, then a failed read";
  EXPECT_EQ(lost_before_next_reading(), 0u);
  for (int k = 0; k < 300; ++k) bridge_on_sensor_error(c, t += 10);
  EXPECT_EQ(lost_before_next_reading(), kMaxPeriodsMissed) << "300 failed reads: capped, not late";
  bridge_on_periods_missed(c, 0xFFFFFFFFu);
  bridge_on_periods_missed(c, 0xFFFFFFFFu);
  EXPECT_EQ(lost_before_next_reading(), kMaxPeriodsMissed) << "overruns without end: capped";
  EXPECT_EQ(lost_before_next_reading(), 0u);
}

TEST(BridgeCore, StopLatchesUntilTheNextTrialAndIgnoresCorruptStops) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  Frame bad = protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 250, 1, 100});
  bad.data[6] ^= 1;
  EXPECT_EQ(bridge_on_frame(c, bad, 1), BridgeAction::None);
  EXPECT_EQ(c.bad_frames, 1u);
  EXPECT_FALSE(bridge_stop_latched(c));
  const Frame stop = protocol::encode(protocol::Stop{1, protocol::StopReason::Caught, 250, 1, 100});
  EXPECT_EQ(bridge_on_frame(c, stop, 2), BridgeAction::StopRobot);
  EXPECT_EQ(bridge_on_frame(c, stop, 3), BridgeAction::None) << "already latched";
  EXPECT_EQ(bridge_state(c), protocol::BridgeState::StopLatched);
  bridge_on_stop_written(c);  // the port wrote it to the robot
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{0, 2, 100, protocol::HeightClass::High}), 4);
  EXPECT_FALSE(bridge_stop_latched(c));
  EXPECT_EQ(bridge_on_frame(c, protocol::encode(protocol::Stop{2, protocol::StopReason::HardLimit, 0, 2, 5}), 5),
            BridgeAction::StopRobot);
}

// A stop the port could not write to the robot (its Modbus link down) is not released by the
// next trial start: the heartbeat keeps saying StopLatched, and the write, when it succeeds,
// belongs to a latch the robot controller can see. (Released, the port's pending write landed in
// the next trial under an "Ok" heartbeat.)
TEST(BridgeCore, TrialStartKeepsAStopNotYetWritten) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  EXPECT_EQ(bridge_on_frame(c, protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 250, 1, 100}), 1),
            BridgeAction::StopRobot);
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{0, 2, 100, protocol::HeightClass::High}), 2);
  EXPECT_TRUE(bridge_stop_latched(c)) << "released before the robot had it";
  EXPECT_EQ(heartbeat_at(c, 3).state, protocol::BridgeState::StopLatched);
  bridge_on_stop_written(c);
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{1, 3, 100, protocol::HeightClass::High}), 4);
  EXPECT_FALSE(bridge_stop_latched(c));
  // A predictor's silence latches an unwritten stop too.
  bridge_init(c, BridgeConfig{100, 300}, 0);
  Frame hb;
  BridgeAction a;
  bridge_on_tick(c, 400, &hb, &a);
  ASSERT_EQ(a, BridgeAction::StopRobot);
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{0, 5, 100, protocol::HeightClass::High}), 401);
  EXPECT_TRUE(bridge_stop_latched(c));
}

// The robot's stop target mirrors the latch: a TrialStart that releases it, or finds none (a
// target left set from before the bridge started), tells the port to clear it; one that keeps a
// stop not yet written does not, and nor does any other frame.
TEST(BridgeCore, ATrialStartThatLeavesNoStopClearsTheRobotsStop) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  const auto trial = [](uint8_t counter) {
    return protocol::encode(protocol::TrialStart{counter, counter, 100, protocol::HeightClass::High});
  };
  EXPECT_EQ(bridge_on_frame(c, trial(0), 1), BridgeAction::ReleaseRobot) << "nothing latched";
  EXPECT_EQ(bridge_on_frame(c, trial(0), 2), BridgeAction::None) << "a repeated frame is not accepted";
  ASSERT_EQ(bridge_on_frame(c, protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 250, 1, 9}), 3),
            BridgeAction::StopRobot);
  EXPECT_EQ(bridge_on_frame(c, trial(1), 4), BridgeAction::None) << "the stop is not written yet";
  bridge_on_stop_written(c);
  EXPECT_EQ(bridge_on_frame(c, trial(2), 5), BridgeAction::ReleaseRobot);
  EXPECT_EQ(bridge_on_frame(c, protocol::encode(protocol::TrialEnd{0, 2, 10, protocol::TrialEndReason::Completed}), 6),
            BridgeAction::None);
}

// A robot controller or predictor that restarts counts from 0 again. After a silence of
// protocol::kSporadicResyncMs its frames are heard at once; before, the E2E check discarded them
// as late until the counter passed the old one (up to 128 trial starts: a latch that never
// released; up to 12.8 s of heartbeats: a predictor taken for silent).
TEST(BridgeCore, RestartedSendersAreHeardAfterASilence) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  const auto trial_start = [&c](uint8_t counter, uint16_t trial, uint32_t t) {
    bridge_on_frame(c, protocol::encode(protocol::TrialStart{counter, trial, 100, protocol::HeightClass::High}), t);
  };
  for (uint8_t k = 0; k < 40; ++k) trial_start(k, k, 100u * k);
  const auto latch_at = [&c](uint32_t t) {
    bridge_on_frame(c, protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 250, 1, 100}), t);
    bridge_on_stop_written(c);
  };
  latch_at(4000);
  trial_start(0, 0, 4500);  // restarted within the resync time: a late frame, discarded
  EXPECT_TRUE(bridge_stop_latched(c));
  trial_start(0, 0, 4500 + protocol::kSporadicResyncMs + 1);
  EXPECT_FALSE(bridge_stop_latched(c)) << "a restarted robot controller's trial start was discarded";
  EXPECT_EQ(c.bad_frames, 1u);

  bridge_init(c, BridgeConfig{100, 300}, 0);
  Frame hb;
  BridgeAction a;
  for (uint8_t k = 0; k < 50; ++k)
    bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{k, protocol::PredictorState::Idle, 1, 0, 0}), 10u * k);
  bridge_on_tick(c, 900, &hb, &a);
  ASSERT_EQ(a, BridgeAction::StopRobot) << "silent for 410 ms";
  const uint32_t back = 490 + protocol::kSporadicResyncMs + 1;
  bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{0, protocol::PredictorState::Idle, 1, 0, 0}), back);
  EXPECT_EQ(c.last_predictor_ms, back) << "a restarted predictor's heartbeat was discarded";
}

TEST(BridgeCore, SilentPredictorStopsWhenConfigured) {
  BridgeCore c;
  bridge_init(c, BridgeConfig{100, 300}, 0);
  Frame hb;
  BridgeAction a;
  for (uint32_t t = 0; t <= 300; t += 10) {
    bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{static_cast<uint8_t>(t / 10), protocol::PredictorState::Idle, 1, 0, 0}), t);
    bridge_on_tick(c, t, &hb, &a);
    EXPECT_EQ(a, BridgeAction::None) << t;
  }
  for (uint32_t t = 310; t <= 700; t += 10) {
    bridge_on_tick(c, t, &hb, &a);
    if (a == BridgeAction::StopRobot) {
      EXPECT_GT(t - 300, 300u);
      EXPECT_LE(t - 300, 310u);
      return;
    }
  }
  FAIL() << "no stop for a predictor silent 300 ms";
}

// With the watchdog on, a trial the predictor does not guard is a stop reason: from a TrialStart
// to its TrialEnd the predictor's heartbeat must name the trial, in trial or stopped, within
// predictor_timeout_ms (bridge_core.h). The predictor here beats every 100 ms, as the daemon
// does; `say(t)` is its heartbeat at t, then the tick.
TEST(BridgeCore, TrialThePredictorDoesNotGuardStopsWhenConfigured) {
  using protocol::PredictorState;
  struct Rig {
    BridgeCore c;
    uint8_t hb_counter = 0, trial_counter = 0;
    explicit Rig(uint32_t timeout) { bridge_init(c, BridgeConfig{100, timeout}, 0); }
    BridgeAction say(uint32_t t, PredictorState s, uint16_t trial) {
      bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{hb_counter++, s, 1, trial, 0}), t);
      Frame hb;
      BridgeAction a;
      bridge_on_tick(c, t, &hb, &a);
      return a;
    }
    BridgeAction tick(uint32_t t) {
      Frame hb;
      BridgeAction a;
      bridge_on_tick(c, t, &hb, &a);
      return a;
    }
    void start(uint32_t t, uint16_t trial) {
      bridge_on_frame(c, protocol::encode(protocol::TrialStart{trial_counter++, trial, 100, protocol::HeightClass::Middle}), t);
    }
    void end(uint32_t t, uint16_t trial) {
      bridge_on_frame(c, protocol::encode(protocol::TrialEnd{trial_counter++, trial, 300, protocol::TrialEndReason::Completed}), t);
    }
  };
  {  // the predictor lost trial 7's start: its heartbeat stays idle, naming the trial before
    Rig r(300);
    for (uint32_t t = 0; t <= 1000; t += 100) ASSERT_EQ(r.say(t, PredictorState::Idle, 6), BridgeAction::None) << t;
    r.start(1005, 7);
    uint32_t stopped_at = 0;
    for (uint32_t t = 1010; t <= 2000 && !stopped_at; t += 10) {
      const BridgeAction a = t % 100 == 0 ? r.say(t, PredictorState::Idle, 6) : r.tick(t);
      if (a == BridgeAction::StopRobot) stopped_at = t;
    }
    EXPECT_GT(stopped_at, 1005u + 300u) << "stopped before the timeout";
    EXPECT_LE(stopped_at, 1005u + 310u) << "no stop within a tick of the timeout";
    EXPECT_EQ(r.c.stop_cause, StopCause::TrialUnguarded);
  }
  {  // guarded from its first heartbeat to its end, in trial and then stopped; the trial's end
     // with the predictor idle again, and a TrialEnd of another trial, change nothing
    Rig r(300);
    r.say(0, PredictorState::Idle, 6);
    r.start(5, 7);
    for (uint32_t t = 100; t <= 3000; t += 100)
      ASSERT_EQ(r.say(t, t < 2000 ? PredictorState::InTrial : PredictorState::Stopped, 7), BridgeAction::None) << t;
    r.end(3005, 6);  // not this trial's end
    EXPECT_TRUE(r.c.trial_running);
    r.end(3010, 7);
    EXPECT_FALSE(r.c.trial_running);
    for (uint32_t t = 3100; t <= 6000; t += 100) ASSERT_EQ(r.say(t, PredictorState::Idle, 7), BridgeAction::None) << t;
  }
  {  // guarded, then not (a predictor restarted within the trial is idle, trial 0), then
     // guarded again within the timeout: no stop; not again within it: a stop
    Rig r(300);
    r.start(0, 7);
    for (uint32_t t = 100; t <= 1000; t += 100) ASSERT_EQ(r.say(t, PredictorState::InTrial, 7), BridgeAction::None);
    ASSERT_EQ(r.say(1100, PredictorState::Idle, 0), BridgeAction::None);
    ASSERT_EQ(r.say(1200, PredictorState::InTrial, 8), BridgeAction::None) << "another trial's id does not guard this one";
    ASSERT_EQ(r.say(1300, PredictorState::InTrial, 7), BridgeAction::None);
    ASSERT_EQ(r.say(1400, PredictorState::Fault, 7), BridgeAction::None);
    EXPECT_EQ(r.say(1600, PredictorState::Fault, 7), BridgeAction::None);
    EXPECT_EQ(r.say(1700, PredictorState::Fault, 7), BridgeAction::None) << "unguarded since 1400: exactly 300 ms";
    EXPECT_EQ(r.tick(1701), BridgeAction::StopRobot);
    EXPECT_EQ(r.c.stop_cause, StopCause::TrialUnguarded);
  }
  {  // watchdog off (a bridge that only records): an unguarded trial stops nothing
    Rig r(0);
    r.start(0, 7);
    for (uint32_t t = 100; t <= 3000; t += 100) ASSERT_EQ(r.say(t, PredictorState::Idle, 0), BridgeAction::None) << t;
  }
}

// Shutdown latches the bridge's own stop exactly when the predictor's last accepted heartbeat
// said "in trial" and no stop is latched; a corrupted heartbeat changes nothing.
TEST(BridgeCore, ShutdownStopsOnlyARunningTrial) {
  using protocol::PredictorState;
  for (const auto state : {PredictorState::Idle, PredictorState::InTrial, PredictorState::Stopped, PredictorState::Fault}) {
    BridgeCore c;
    bridge_init(c, {}, 0);
    bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{0, state, 1, 9, 0}), 10);
    Frame bad = protocol::encode(protocol::HeartbeatPredictor{1, PredictorState::Idle, 1, 9, 0});
    bad.data[0] ^= 0x5A;  // CRC broken: not taken
    bridge_on_frame(c, bad, 20);
    const bool in_trial = state == PredictorState::InTrial;
    EXPECT_EQ(bridge_on_shutdown(c), in_trial ? BridgeAction::StopRobot : BridgeAction::None) << int(state);
    EXPECT_EQ(c.stop_cause, in_trial ? StopCause::BridgeShutdown : StopCause::None);
    EXPECT_EQ(bridge_on_shutdown(c), BridgeAction::None) << "latched once";
  }
  BridgeCore c;  // a stop already latched by a Stop frame stays that stop
  bridge_init(c, {}, 0);
  bridge_on_frame(c, protocol::encode(protocol::HeartbeatPredictor{0, PredictorState::InTrial, 1, 9, 0}), 10);
  EXPECT_EQ(bridge_on_frame(c, protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 200, 9, 40}), 20),
            BridgeAction::StopRobot);
  EXPECT_EQ(bridge_on_shutdown(c), BridgeAction::None);
  EXPECT_EQ(c.stop_cause, StopCause::StopFrame);
}

TEST(BridgeCore, HeartbeatCarriesSensorState) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  bridge_on_sensor_error(c, 5);
  Frame hb;
  BridgeAction a;
  ASSERT_EQ(bridge_on_tick(c, 10, &hb, &a), 1);
  protocol::HeartbeatBridge m;
  ASSERT_TRUE(protocol::decode(hb, m));
  EXPECT_EQ(m.state, protocol::BridgeState::SensorLost);
  EXPECT_EQ(m.sensor_errors, 1);
  EXPECT_EQ(bridge_on_tick(c, 50, &hb, &a), 0) << "next heartbeat only after 100 ms";
}

// Uptime is whole seconds since bridge_init, across the millisecond clock's wrap (49.7 days), and
// saturates at 65,535 s (18.2 h) instead of wrapping: the robot controller reads a long-running
// bridge as "up at least that long", never as freshly restarted. (Out of fuzz_bridge's reach.)
TEST(BridgeCore, HeartbeatUptimeCrossesTheWrapAndSaturates) {
  const auto uptime = [](uint32_t start, uint32_t now) {
    BridgeCore c;
    bridge_init(c, {}, start);
    return heartbeat_at(c, now).uptime_s;
  };
  EXPECT_EQ(uptime(0xFFFFFFFFu - 999, 2500), 3) << "3.5 s across the wrap";
  EXPECT_EQ(uptime(0, 65'535'999), 65535);
  EXPECT_EQ(uptime(0, 70'000'000), 65535) << "saturates, does not wrap to 4464";
}

// Found by fuzz_bridge (session 80): a trial start used to report Ok when it released the latch,
// even with no reading since a failed one (or none at all).
TEST(BridgeCore, ReleasedLatchReportsTheSensorAsItIs) {
  BridgeCore c;
  bridge_init(c, {}, 0);
  const auto heartbeat_state = [&c](uint32_t t) { return heartbeat_at(c, t).state; };
  EXPECT_EQ(bridge_on_frame(c, protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 250, 1, 100}), 1),
            BridgeAction::StopRobot);
  EXPECT_EQ(heartbeat_state(2), protocol::BridgeState::StopLatched);
  bridge_on_stop_written(c);
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{0, 2, 100, protocol::HeightClass::High}), 3);
  EXPECT_FALSE(bridge_stop_latched(c));
  EXPECT_EQ(heartbeat_state(200), protocol::BridgeState::SensorLost) << "no reading yet";
  Frame out[2];
  bridge_on_reading(c, FtReading{{1, 2, 3}, {4, 5, 6}}, 201, out);
  EXPECT_EQ(heartbeat_state(400), protocol::BridgeState::Ok);
  bridge_on_sensor_error(c, 401);
  bridge_on_frame(c, protocol::encode(protocol::Stop{1, protocol::StopReason::HardLimit, 0, 2, 5}), 402);
  bridge_on_stop_written(c);
  bridge_on_frame(c, protocol::encode(protocol::TrialStart{1, 3, 100, protocol::HeightClass::High}), 403);
  EXPECT_EQ(heartbeat_state(600), protocol::BridgeState::SensorLost) << "the last read failed";
}

// ---- Linux port against Modbus TCP peers ------------------------------------------------------

// An emulator the test forks must not outlive the test. It inherits the test's stderr, ctest's
// pipe: one left running by a test that died (a crash, an uncaught signal: no destructor runs)
// kept ctest waiting for that pipe's end until its 900 s timeout, where the test should fail at
// once. PR_SET_PDEATHSIG survives the exec (dg_modbus_emulator is not set-user-ID) and fires when
// the forking thread ends: the tests fork from gtest's main thread. The getppid check closes the
// race of a parent gone before the prctl.
void die_with_parent(pid_t parent) {
  if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(127);
}

class Emulator {
 public:
  Emulator() {
    int fds[2];
    if (pipe(fds) != 0) return;
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ == 0) {
      die_with_parent(parent);
      dup2(fds[1], 1);
      close(fds[0]);
      execl(DG_EMULATOR, DG_EMULATOR, "--port", "0", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    FILE* f = fdopen(fds[0], "r");
    if (std::fscanf(f, "listening on %d", &port_) != 1) port_ = -1;
    std::fclose(f);
  }
  ~Emulator() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string spec() const { return "tcp:127.0.0.1:" + std::to_string(port_); }
  // The test's own Modbus client, for setting registers.
  bool write(int addr, std::vector<uint16_t> values) {
    modbus_t* c = modbus_new_tcp("127.0.0.1", port_);
    const bool ok = modbus_connect(c) == 0 && modbus_write_registers(c, addr, static_cast<int>(values.size()), values.data()) ==
                                                  static_cast<int>(values.size());
    modbus_close(c);
    modbus_free(c);
    return ok;
  }

 private:
  pid_t pid_ = -1;
  int port_ = -1;
};

std::string mbpoll(const std::string& args) {
  std::string out;
  FILE* p = popen(("mbpoll -m tcp -0 -1 " + args + " 2>&1").c_str(), "r");
  if (!p) return out;
  std::array<char, 512> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  pclose(p);
  return out;
}

// The bridge's CAN port with faults a test arms: receive errors (errno `err`) and controller
// error frames of one class, each returned by the next receives before any frame waiting (send
// a frame to wake the loop for them).
class FaultyPort final : public can::CanPort {
 public:
  explicit FaultyPort(std::unique_ptr<can::CanPort> port) : port_(std::move(port)) {}
  void fail_receives(int n, int err) {
    err_ = err;
    receive_errors_ = n;
  }
  void error_frames(int n, uint32_t error_class) {
    error_class_ = error_class;
    error_frames_ = n;
  }
  int fd() const override { return port_->fd(); }
  int receive(protocol::Frame& f, can::RxInfo& info) noexcept override {
    if (take(receive_errors_)) {
      errno = err_.load();
      return -1;
    }
    if (take(error_frames_)) {
      f = protocol::Frame{};
      info = can::RxInfo{};
      info.error_frame = true;
      info.error_class = error_class_.load();
      return 1;
    }
    return port_->receive(f, info);
  }
  can::SendResult send(const protocol::Frame& f) noexcept override { return port_->send(f); }

 private:
  static bool take(std::atomic<int>& n) {
    for (int left = n.load(); left > 0;)
      if (n.compare_exchange_weak(left, left - 1)) return true;
    return false;
  }
  std::unique_ptr<can::CanPort> port_;
  std::atomic<int> receive_errors_{0}, error_frames_{0}, err_{0};
  std::atomic<uint32_t> error_class_{0};
};

// The lines of `text` that contain `needle`.
int lines_with(const std::string& text, const std::string& needle) {
  std::istringstream lines(text);
  int n = 0;
  for (std::string l; std::getline(lines, l);) n += l.find(needle) != std::string::npos;
  return n;
}

// What a test changes of the rig: the sensor (the emulator over TCP unless a spec is given, e.g.
// a PtyDevice's) and its response timeout, the shutdown grace.
struct RigOptions {
  int shutdown_grace_ms = 1000;
  std::string sensor_spec;  // empty: the sensor emulator
  int sensor_timeout_ms = 20;
  Sensor* own_sensor = nullptr;  // when given, read instead of a ModbusSensor
  int period_ms = 10;
  uint32_t predictor_timeout_ms = 0;
  StopTarget stop_target{true, 7, 1};
  service::NotifySocket* service = nullptr;  // the service manager's socket: none
};

struct BridgeRig {
  Emulator sensor_emu, robot_emu;
  can::InProcBus bus;
  std::unique_ptr<can::CanPort> bridge_port, listener, predictor;
  FaultyPort* faults = nullptr;  // the bridge's port
  std::unique_ptr<ModbusSensor> sensor;
  std::unique_ptr<RobotStopWriter> robot;
  std::unique_ptr<BridgeApp> app;
  std::thread loop;
  std::atomic<int> rc{-1};          // what run() returned
  std::FILE* log = std::tmpfile();  // what the bridge says
  explicit BridgeRig(const RigOptions& o = {}) {
    // The identifiers dressguard-bridge's main subscribes to.
    auto port = std::make_unique<FaultyPort>(bus.open({{std::begin(kBridgeReceives), std::end(kBridgeReceives)}, false, true}));
    faults = port.get();
    bridge_port = std::move(port);
    listener = bus.open({{protocol::id_of(protocol::MsgId::FtForce), protocol::id_of(protocol::MsgId::FtTorque),
                          protocol::id_of(protocol::MsgId::HeartbeatBridge)}, false, true});
    predictor = bus.open({{}, false, true});
    const std::string sensor_spec = o.sensor_spec.empty() ? sensor_emu.spec() : o.sensor_spec;
    sensor = std::make_unique<ModbusSensor>(ModbusEndpoint{sensor_spec, 9, o.sensor_timeout_ms}, SensorMap{});
    robot = std::make_unique<RobotStopWriter>(ModbusEndpoint{robot_emu.spec(), 1, 200}, o.stop_target);
    BridgeAppConfig cfg;
    cfg.backoff_min_ms = 20;
    cfg.backoff_max_ms = 160;
    cfg.log = log;
    cfg.shutdown_grace_ms = o.shutdown_grace_ms;
    cfg.sample_period_ms = o.period_ms;
    cfg.core.predictor_timeout_ms = o.predictor_timeout_ms;
    cfg.service = o.service;
    app = std::make_unique<BridgeApp>(cfg, o.own_sensor ? *o.own_sensor : *sensor, robot.get(), *bridge_port);
    loop = std::thread([this] { rc = app->run(); });
  }
  ~BridgeRig() {
    shut_down();
    if (log) std::fclose(log);
  }
  // Asks the bridge to shut down (as SIGTERM does) and waits for run() to return: its value.
  int shut_down() {
    if (loop.joinable()) {
      app->request_shutdown();
      loop.join();
    }
    return rc;
  }
  // What the bridge has logged so far (read through its own descriptor).
  std::string logged() const {
    std::ifstream in("/proc/self/fd/" + std::to_string(fileno(log)));
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // Waits up to `d` for the bridge to log `needle`: whether it did.
  bool logs(const std::string& needle, std::chrono::milliseconds d = 3000ms) const {
    const auto end = std::chrono::steady_clock::now() + d;
    while (logged().find(needle) == std::string::npos) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(5ms);
    }
    return true;
  }
  // Force frames received until `n` have come or `most` has passed: how many. On a loaded
  // machine (ctest -j with the VM test beside) a reconnect after a fault can take several
  // backoff steps, so a test that waits for readings to resume waits for them, not a fixed time.
  int collect_at_least(int n, std::chrono::milliseconds most, protocol::FtForce* last = nullptr) {
    int got = 0;
    for (auto waited = 0ms; got < n && waited < most; waited += 50ms) got += collect(50ms, last);
    return got;
  }
  // Force frames received within `d`, the last one in *last; every frame in *all.
  int collect(std::chrono::milliseconds d, protocol::FtForce* last = nullptr, protocol::HeartbeatBridge* hb = nullptr,
              std::vector<Frame>* all = nullptr) {
    const auto end = std::chrono::steady_clock::now() + d;
    int n = 0;
    Frame f;
    can::RxInfo info;
    while (std::chrono::steady_clock::now() < end) {
      while (listener->receive(f, info) == 1) {
        if (all) all->push_back(f);
        protocol::FtForce m;
        protocol::HeartbeatBridge h;
        if (protocol::decode(f, m)) {
          ++n;
          if (last) *last = m;
        } else if (hb && protocol::decode(f, h)) {
          *hb = h;
        }
      }
      std::this_thread::sleep_for(1ms);
    }
    return n;
  }
  // Over `d`, the time from the first force frame received to the last, and how far the
  // counter advanced between them (each step mod 256, summed); `disturb` runs after the first.
  struct Span {
    double ms = 0;
    int periods = 0;
  };
  Span counted_periods(std::chrono::milliseconds d, const std::function<void()>& disturb) {
    const auto end = std::chrono::steady_clock::now() + d;
    Span span;
    std::optional<std::chrono::steady_clock::time_point> first;
    std::optional<uint8_t> last_counter;
    Frame f;
    can::RxInfo info;
    while (std::chrono::steady_clock::now() < end) {
      protocol::FtForce m;
      while (listener->receive(f, info) == 1) {
        if (!protocol::decode(f, m)) continue;
        const auto now = std::chrono::steady_clock::now();
        if (!first) {
          first = now;
          disturb();
        }
        span.ms = std::chrono::duration<double, std::milli>(now - *first).count();
        if (last_counter) span.periods += static_cast<uint8_t>(m.counter - *last_counter);
        last_counter = m.counter;
      }
      std::this_thread::sleep_for(1ms);
    }
    return span;
  }
};

// A BridgeRig whose bridge tells `manager`, a stand-in for systemd's notification socket, with
// WATCHDOG_USEC `watchdog_usec` (null: no watchdog).
struct ManagedBridge {
  testkit::NotifyListener manager{false};
  service::NotifySocket notify;
  std::optional<BridgeRig> rig;
  explicit ManagedBridge(const char* watchdog_usec)
      : notify(service::NotifySocket::open(manager.address.c_str(), watchdog_usec, nullptr, ::getpid())) {
    RigOptions o;
    o.service = &notify;
    rig.emplace(o);
  }
  // What keeps the bridge from telling the manager: "" when nothing does.
  std::string wrong() const { return !manager.error.empty() ? manager.error : notify.connected() ? "" : notify.error(); }
};

// A test that dies (no destructor runs) takes its emulator with it: the emulator holds the test's
// stderr, as it holds ctest's pipe, and that pipe ends within 3 s of the test (die_with_parent).
TEST(BridgeModbus, AnEmulatorDiesWithItsTest) {
  int held[2], report[2];
  ASSERT_EQ(pipe(held), 0);
  ASSERT_EQ(pipe(report), 0);
  const pid_t test = fork();
  if (test == 0) {
    close(held[0]);
    close(report[0]);
    dup2(held[1], 2);
    close(held[1]);
    const Emulator* e = new Emulator;  // never destroyed: the test dies
    const pid_t emulator = e->port() > 0 ? e->pid() : -1;
    _exit(write(report[1], &emulator, sizeof emulator) == sizeof emulator && emulator > 0 ? 0 : 1);
  }
  close(held[1]);
  close(report[1]);
  pid_t emulator = -1;
  const bool reported = read(report[0], &emulator, sizeof emulator) == sizeof emulator && emulator > 0;
  close(report[0]);
  int status = 0;
  ASSERT_EQ(waitpid(test, &status, 0), test);
  ASSERT_TRUE(reported && WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the emulator did not start";
  pollfd p{held[0], POLLIN, 0};
  char c;
  const bool ended = poll(&p, 1, 3000) == 1 && read(held[0], &c, 1) == 0;
  close(held[0]);
  if (!ended) kill(emulator, SIGKILL);  // not left behind by this test either
  EXPECT_TRUE(ended) << "the emulator (pid " << emulator << ") outlived its test, holding the test's stderr";
}

TEST(BridgeModbus, EmulatorAnswersAnIndependentClient) {
  Emulator emu;
  ASSERT_GT(emu.port(), 0) << "emulator did not start";
  ASSERT_TRUE(emu.write(180, {static_cast<uint16_t>(-250), 30, static_cast<uint16_t>(-1000), 15, static_cast<uint16_t>(-2), 0}));
  const std::string out = mbpoll("-p " + std::to_string(emu.port()) + " -a 9 -r 180 -c 6 -t 4 127.0.0.1");
  // mbpoll prints unsigned 16-bit values: -250 is 65286.
  EXPECT_NE(out.find("[180]: \t65286"), std::string::npos) << out;
  EXPECT_NE(out.find("[182]: \t64536"), std::string::npos) << out;
  EXPECT_NE(out.find("[183]: \t15"), std::string::npos) << out;
}

TEST(BridgeModbus, ReadingsFlowToCanAndSurviveFaults) {
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  ASSERT_TRUE(rig.sensor_emu.write(180, {static_cast<uint16_t>(-250), 30, static_cast<uint16_t>(-1000), 15, 0, 0}));
  protocol::FtForce last{};
  protocol::HeartbeatBridge hb{};
  // 100 Hz for 300 ms: about 30 frames (this shared host's timer jitter: accept >= 15).
  const int normal = rig.collect(300ms, &last, &hb);
  EXPECT_GE(normal, 15);
  EXPECT_EQ(last.fx, -250);
  EXPECT_EQ(last.fz, -1000);
  EXPECT_EQ(hb.state, protocol::BridgeState::Ok);

  // Exceptions: no frames at all (never stale data), the heartbeat says the sensor is lost.
  ASSERT_TRUE(rig.sensor_emu.write(900, {1}));
  rig.collect(50ms);  // frames already in flight
  EXPECT_EQ(rig.collect(200ms, nullptr, &hb), 0) << "frames sent while the sensor answers with exceptions";
  EXPECT_EQ(hb.state, protocol::BridgeState::SensorLost);
  // Timeouts (the sensor does not answer): the same.
  ASSERT_TRUE(rig.sensor_emu.write(900, {2}));
  rig.collect(50ms);
  EXPECT_EQ(rig.collect(200ms), 0) << "frames sent while the sensor times out";
  // Back to normal with new values: the first frames carry them.
  ASSERT_TRUE(rig.sensor_emu.write(180, {100, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(rig.sensor_emu.write(900, {0}));
  EXPECT_GE(rig.collect(200ms, &last), 5);
  EXPECT_EQ(last.fx, 100);
  EXPECT_GE(rig.app->stats().sensor_errors.load(), 10u);

  // Unplugged for 400 ms: reconnect with backoff, no frames in the dark.
  const uint64_t reconnects = rig.app->stats().reconnects.load();
  ASSERT_TRUE(rig.sensor_emu.write(901, {400}));
  ASSERT_TRUE(rig.sensor_emu.write(900, {3}));
  rig.collect(30ms);
  EXPECT_EQ(rig.collect(300ms), 0) << "frames while the sensor was gone";
  EXPECT_GE(rig.collect(1000ms), 20) << "did not come back after the sensor did";
  EXPECT_GT(rig.app->stats().reconnects.load(), reconnects);
  EXPECT_GE(rig.app->stats().connect_failures.load(), 1u) << "the backoff never tried while it was gone";
}

// The heartbeat's and the stats' reconnects count the sensor's connections after the first: a
// bridge that never lost its sensor said 1.
TEST(BridgeModbus, TheFirstConnectIsNoReconnect) {
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  protocol::HeartbeatBridge hb{};
  hb.reconnects = 0xFFFF;
  EXPECT_GE(rig.collect_at_least(5, 3000ms), 5) << "no readings";
  rig.collect(250ms, nullptr, &hb);  // a heartbeat (every 100 ms) sent after the first reading
  EXPECT_EQ(hb.state, protocol::BridgeState::Ok);
  EXPECT_EQ(hb.reconnects, 0);
  EXPECT_EQ(rig.app->stats().reconnects.load(), 0u);
}

// The bridge's millisecond clock is CLOCK_MONOTONIC mod 2^32 (49.7 days), compared wrap-safely.
// Its first connect used to be due at 0, which such a comparison finds due only while the clock
// is below 2^31: on a machine up 24.9 to 49.7 days (mod 49.7) it never connected, sent no frame
// and said nothing. Here the clock reads 2^31 + 2^30 ms, the middle of that half.
TEST(BridgeModbus, ConnectsWhateverTheUptime) {
  timespec ts;
  ASSERT_EQ(clock_gettime(CLOCK_MONOTONIC, &ts), 0);
  const uint32_t now = static_cast<uint32_t>(static_cast<uint64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000);
  g_uptime_shift_ms = static_cast<uint32_t>((3u << 30) - now);
  struct Unshift {
    ~Unshift() { g_uptime_shift_ms = 0; }
  } unshift;
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  EXPECT_GE(rig.collect(300ms), 15) << "no readings at an uptime of 37.3 days (mod 49.7)";
}

// One answer 40 ms late against the 20 ms timeout: the link is closed at the timeout and
// reopened after it, so the late answer is never taken for the next request's (on TCP,
// libmodbus then failed every later request on the transaction id: the sensor stayed lost until
// the bridge restarted). Readings resume within a backoff or two, with new values.
TEST(BridgeModbus, ALateAnswerIsDroppedWithItsConnection) {
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  ASSERT_TRUE(rig.sensor_emu.write(180, {200, 0, 0, 0, 0, 0}));
  EXPECT_GE(rig.collect(200ms), 5);
  const uint64_t reconnects = rig.app->stats().reconnects.load();
  ASSERT_TRUE(rig.sensor_emu.write(902, {40}));
  ASSERT_TRUE(rig.sensor_emu.write(900, {4}));
  rig.collect(100ms);
  ASSERT_TRUE(rig.sensor_emu.write(180, {300, 0, 0, 0, 0, 0}));
  protocol::FtForce last{};
  EXPECT_GE(rig.collect_at_least(10, 3000ms, &last), 10) << "readings did not resume after one late answer";
  EXPECT_EQ(last.fx, 300);
  EXPECT_GT(rig.app->stats().reconnects.load(), reconnects) << "the late answer's connection was kept";
  EXPECT_LE(rig.app->stats().sensor_errors.load(), 3u) << "more than the one late answer failed";
}

// The bridge says what fails: a sensor that times out at the 1st, 2nd, 4th, ... failure in a
// row with libmodbus's reason (not once per period), once when it answers again, and every stop.
TEST(BridgeModbus, FailuresAndStopsAreLoggedAtEachDoubling) {
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  EXPECT_GE(rig.collect(100ms), 3);
  ASSERT_TRUE(rig.sensor_emu.write(900, {2}));
  rig.collect(400ms);
  ASSERT_TRUE(rig.sensor_emu.write(900, {0}));
  EXPECT_GE(rig.collect_at_least(5, 3000ms), 5) << "readings did not resume";
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 3, 250}));
  for (int i = 0; i < 2000 && rig.app->stats().stops_written.load() == 0; ++i) std::this_thread::sleep_for(1ms);
  std::this_thread::sleep_for(5ms);
  const std::string text = rig.logged();
  const int failures = lines_with(text, "sensor: timeout: ");
  const uint64_t errors = rig.app->stats().sensor_errors.load();
  ASSERT_GE(errors, 2u);
  // One line per power of two up to the run's length: floor(log2(errors)) + 1 at most.
  EXPECT_GE(failures, 1);
  EXPECT_LE(failures, static_cast<int>(std::log2(static_cast<double>(errors))) + 1) << text;
  EXPECT_NE(text.find("(1 in a row; no frames until it answers)"), std::string::npos) << text;
  EXPECT_NE(text.find("sensor answers again after "), std::string::npos) << text;
  EXPECT_NE(text.find("stop written to the robot controller"), std::string::npos) << text;
}

TEST(BridgeModbus, StopFrameWritesTheRobotsStopCoil) {
  BridgeRig rig;
  ASSERT_GT(rig.robot_emu.port(), 0);
  const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
  EXPECT_NE(mbpoll(coil).find("[7]: \t0"), std::string::npos);
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 3, 250}));
  for (int i = 0; i < 200 && rig.app->stats().stops_written.load() == 0; ++i) std::this_thread::sleep_for(1ms);
  EXPECT_EQ(rig.app->stats().stops_written.load(), 1u);
  // Read back by mbpoll, an independent Modbus client.
  EXPECT_NE(mbpoll(coil).find("[7]: \t1"), std::string::npos) << mbpoll(coil);
}

// The robot's stop target is read once at start (dressguard-bridge's main, before the loop): the
// link used to be first used at the first stop, so a wrong address or a controller that was off
// was found when an arm was caught. An address the controller lacks is told apart (main refuses
// it) from a controller that does not answer (main warns: it may not be powered yet), and a stop
// left set is seen.
TEST(BridgeModbus, TheRobotsStopTargetIsProbedAtStart) {
  Emulator robot_emu;
  ASSERT_GT(robot_emu.port(), 0);
  const ModbusEndpoint ep{robot_emu.spec(), 1, 200};
  RobotStopWriter coil(ep, StopTarget{true, 7, 1});
  EXPECT_EQ(coil.probe(), ProbeResult::Clear) << coil.link().last_error();
  EXPECT_TRUE(coil.link().connected()) << "the first stop would have to connect";
  ASSERT_TRUE(coil.write_stop());
  EXPECT_EQ(RobotStopWriter(ep, StopTarget{true, 7, 1}).probe(), ProbeResult::StopSet);
  ASSERT_TRUE(robot_emu.write(20, {5}));
  EXPECT_EQ(RobotStopWriter(ep, StopTarget{false, 20, 5}).probe(), ProbeResult::StopSet);
  EXPECT_EQ(RobotStopWriter(ep, StopTarget{false, 20, 6}).probe(), ProbeResult::Clear);
  // The emulator has 1000 coils and registers.
  RobotStopWriter absent(ep, StopTarget{true, 5000, 1});
  EXPECT_EQ(absent.probe(), ProbeResult::NoSuchTarget);
  EXPECT_NE(absent.link().last_error().find("Illegal data address"), std::string::npos) << absent.link().last_error();
  EXPECT_EQ(RobotStopWriter(ep, StopTarget{false, 5000, 1}).probe(), ProbeResult::NoSuchTarget);
  RobotStopWriter nobody(ModbusEndpoint{"tcp:127.0.0.1:1", 1, 200}, StopTarget{true, 7, 1});
  EXPECT_EQ(nobody.probe(), ProbeResult::Failed);
  EXPECT_NE(nobody.link().last_error().find("Connection refused"), std::string::npos) << nobody.link().last_error();
  EXPECT_EQ(stop_target_name(StopTarget{false, 20, 5}), "holding register 20");
}

// What mbpoll, an independent Modbus client, reads at the robot's stop target: 1 set, 0 clear
// (a register holding the target's value is 1), -1 nothing read.
int robot_reads(const Emulator& robot, const StopTarget& t) {
  const std::string out = mbpoll("-p " + std::to_string(robot.port()) + " -a 1 -r " + std::to_string(t.address) +
                                 " -c 1 -t " + (t.coil ? "0" : "4") + " 127.0.0.1");
  const std::string at = "[" + std::to_string(t.address) + "]: \t";
  const size_t k = out.find(at);
  if (k == std::string::npos) return -1;
  return std::atoi(out.c_str() + k + at.size()) == (t.coil ? 1 : t.value) ? 1 : 0;
}

// Waits up to 1 s for the robot's stop target to read `want`: whether it did.
bool robot_comes_to(const Emulator& robot, const StopTarget& t, int want) {
  for (int i = 0; i < 50; ++i) {
    if (robot_reads(robot, t) == want) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

// The robot's stop target mirrors the bridge's latch: set at a stop, cleared when the robot
// controller's next TrialStart releases the latch, so a robot program that acts on the rising
// edge sees every stop (the bridge used to write it ON and never OFF: the second stop was 1 -> 1,
// no edge). One left set from an earlier run is cleared by the first TrialStart, not at start.
// A coil, and a holding register (cleared to 0).
TEST(BridgeModbus, SecondStopIsSeenByTheRobot) {
  for (const StopTarget target : {StopTarget{true, 7, 1}, StopTarget{false, 20, 5}}) {
    SCOPED_TRACE(stop_target_name(target));
    RigOptions o;
    o.stop_target = target;
    BridgeRig rig(o);
    ASSERT_GT(rig.robot_emu.port(), 0);
    // Left set from an earlier run: the bridge does not clear it at start ...
    ASSERT_TRUE(rig.robot_emu.write(20, {5}));
    ASSERT_NE(mbpoll("-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -t 0 127.0.0.1 1").find("Written"),
              std::string::npos);
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(robot_reads(rig.robot_emu, target), 1);
    uint8_t trial = 0, stop = 0;
    const auto start_trial = [&] {
      rig.predictor->send(protocol::encode(protocol::TrialStart{trial, trial, 100, protocol::HeightClass::High}));
      ++trial;
    };
    const auto stop_robot = [&] {
      rig.predictor->send(protocol::encode(protocol::Stop{stop++, protocol::StopReason::Caught, 240, trial, 50}));
    };
    // ... the robot controller's first TrialStart does.
    start_trial();
    EXPECT_TRUE(robot_comes_to(rig.robot_emu, target, 0)) << rig.logged();
    for (int k = 0; k < 2; ++k) {
      stop_robot();
      EXPECT_TRUE(robot_comes_to(rig.robot_emu, target, 1)) << "stop " << k << "\n" << rig.logged();
      start_trial();
      EXPECT_TRUE(robot_comes_to(rig.robot_emu, target, 0)) << "release " << k << "\n" << rig.logged();
    }
    stop_robot();
    EXPECT_TRUE(robot_comes_to(rig.robot_emu, target, 1)) << rig.logged();
    EXPECT_EQ(rig.app->stats().stops_written.load(), 3u);
    EXPECT_EQ(rig.app->stats().releases_written.load(), 3u);
  }
}

// A clear that could not be written yet (the robot controller dark when its TrialStart came) is
// superseded by the next stop: written after the stop, it would take the stop back.
TEST(BridgeModbus, AStopSupersedesAClearNotYetWritten) {
  BridgeRig rig;
  ASSERT_GT(rig.robot_emu.port(), 0);
  const StopTarget target{true, 7, 1};
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 1, 50}));
  ASSERT_TRUE(robot_comes_to(rig.robot_emu, target, 1)) << rig.logged();
  ASSERT_TRUE(rig.robot_emu.write(901, {300}));
  ASSERT_TRUE(rig.robot_emu.write(900, {3}));
  rig.predictor->send(protocol::encode(protocol::TrialStart{0, 2, 100, protocol::HeightClass::High}));
  ASSERT_TRUE(rig.logs("clearing the stop failed")) << rig.logged();
  rig.predictor->send(protocol::encode(protocol::Stop{1, protocol::StopReason::Caught, 240, 2, 50}));
  ASSERT_TRUE(rig.logs("stop written to the robot controller (after failed writes)", 2000ms)) << rig.logged();
  std::this_thread::sleep_for(100ms);  // a clear still pending would be written by now
  EXPECT_EQ(robot_reads(rig.robot_emu, target), 1) << rig.logged();
  EXPECT_EQ(rig.app->stats().releases_written.load(), 0u) << rig.logged();
}

// Shutdown with a stop that the robot controller has not received: the bridge is the only way
// to the robot, so it keeps retrying the write through its grace instead of returning at once.
// The robot controller is dark for 300 ms (emulator mode 3) when the stop comes and SIGTERM
// follows; it comes back inside the 1 s grace and gets the stop.
TEST(BridgeModbus, ShutdownWritesAStopTheRobotHasNotReceived) {
  BridgeRig rig;
  ASSERT_GT(rig.robot_emu.port(), 0);
  ASSERT_TRUE(rig.robot_emu.write(901, {300}));
  ASSERT_TRUE(rig.robot_emu.write(900, {3}));
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Shutdown, 0, 3, 250}));
  for (int i = 0; i < 200 && rig.app->stats().stop_write_failures.load() == 0; ++i) std::this_thread::sleep_for(1ms);
  ASSERT_GT(rig.app->stats().stop_write_failures.load(), 0u) << "the dark robot controller took the write";
  EXPECT_EQ(rig.shut_down(), 0) << rig.logged();
  EXPECT_EQ(rig.app->stats().stops_written.load(), 1u) << rig.logged();
  const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
  EXPECT_NE(mbpoll(coil).find("[7]: \t1"), std::string::npos) << mbpoll(coil);
}

// A stop that cannot be written within the grace: the bridge exits 1 and says the robot may not
// be stopped (a clean 0 would hide it from the service manager).
TEST(BridgeModbus, ShutdownSaysWhenAStopStaysUnwritten) {
  RigOptions short_grace;
  short_grace.shutdown_grace_ms = 150;
  BridgeRig rig(short_grace);
  ASSERT_GT(rig.robot_emu.port(), 0);
  ASSERT_TRUE(rig.robot_emu.write(901, {3000}));
  ASSERT_TRUE(rig.robot_emu.write(900, {3}));
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 3, 250}));
  for (int i = 0; i < 200 && rig.app->stats().stop_write_failures.load() == 0; ++i) std::this_thread::sleep_for(1ms);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(rig.shut_down(), 1);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 150ms);  // it did retry through the grace
  EXPECT_EQ(rig.app->stats().stops_written.load(), 0u);
  EXPECT_NE(rig.logged().find("the robot may not be stopped"), std::string::npos) << rig.logged();
}

// Shutdown while the predictor says a trial is running: once the bridge is gone no sample reaches
// the predictor and no stop reaches the robot, so the bridge stops the robot itself first.
// Idle, it writes nothing.
TEST(BridgeModbus, ShutdownDuringATrialStopsTheRobot) {
  for (const auto state : {protocol::PredictorState::Idle, protocol::PredictorState::InTrial}) {
    const bool in_trial = state == protocol::PredictorState::InTrial;
    BridgeRig rig;
    ASSERT_GT(rig.robot_emu.port(), 0);
    rig.predictor->send(protocol::encode(protocol::HeartbeatPredictor{0, state, 1, 12, 5}));
    std::this_thread::sleep_for(30ms);  // the bridge's loop takes it
    EXPECT_EQ(rig.shut_down(), 0) << rig.logged();
    EXPECT_EQ(rig.app->stats().stops_written.load(), in_trial ? 1u : 0u) << rig.logged();
    EXPECT_EQ(bridge_stop_latched(rig.app->core()), in_trial);
    if (in_trial) {
      EXPECT_NE(rig.logged().find("during the predictor's trial 12"), std::string::npos) << rig.logged();
    }
    const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
    EXPECT_NE(mbpoll(coil).find(in_trial ? "[7]: \t1" : "[7]: \t0"), std::string::npos) << mbpoll(coil);
  }
}

// Under systemd (Type=notify, WatchdogSec=): READY=1 once the loop runs, WATCHDOG=1 from its
// timer at half the manager's interval, STOPPING=1 when the shutdown begins, all from this
// process.
TEST(BridgeModbus, TellsTheServiceManagerItIsReadyAndFeedsItsWatchdog) {
  // WatchdogSec=0.06: a ping due every 30 ms, sent at the next of the 10 ms periods.
  ManagedBridge b("60000");
  ASSERT_EQ(b.wrong(), "");
  testkit::NotifyListener& manager = b.manager;
  BridgeRig& rig = *b.rig;
  for (int i = 0; i < 100; ++i) {
    std::this_thread::sleep_for(5ms);
    manager.take(::getpid());
  }
  EXPECT_EQ(rig.shut_down(), 0) << rig.logged();
  manager.take(::getpid());
  // A ping due every 30 ms, sent at the next 10 ms period: 30-40 ms apart, about 14 in 0.5 s.
  EXPECT_EQ(manager.wrong_with_what_was_said(0.030, 0.040), "") << rig.logged();
  EXPECT_EQ(b.notify.failed_sends(), 0u);
}

// The unit's status line (`systemctl status`) says the sensor's state, the stops written and
// what the bridge said last: here a predictor's stop, written to the robot.
TEST(BridgeModbus, TheUnitsStatusLineSaysWhatTheBridgeSaidLast) {
  ManagedBridge b(nullptr);
  ASSERT_EQ(b.wrong(), "");
  testkit::NotifyListener& manager = b.manager;
  BridgeRig& rig = *b.rig;
  ASSERT_GE(rig.collect_at_least(3, 2000ms), 3) << "the sensor is read";
  rig.predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 3, 250}));
  // The stop is written in the wakeup that reads the frame, then its cause is said. (Other lines
  // may come between, e.g. a timer overrun on a loaded host.)
  const std::string written = "STATUS=sensor ok; stops written 1; last: stop written to the robot controller";
  const std::string cause = "STATUS=sensor ok; stops written 1; last: stop frame from the predictor: caught";
  manager.wait_for(cause, ::getpid());
  const auto& h = manager.heard;
  ASSERT_FALSE(h.empty());
  EXPECT_EQ(h.front(), "READY=1");
  const auto w = std::find(h.begin(), h.end(), written);
  EXPECT_TRUE(w != h.end() && std::find(w, h.end(), cause) != h.end()) << ::testing::PrintToString(h) << rig.logged();
  EXPECT_FALSE(manager.other_sender);
}

// The status line follows the sensor: failing while it answers with exceptions, ok again the
// moment it answers (said with the recovery, not only at the next thing the bridge says).
TEST(BridgeModbus, TheUnitsStatusLineFollowsTheSensor) {
  ManagedBridge b(nullptr);
  ASSERT_EQ(b.wrong(), "");
  testkit::NotifyListener& manager = b.manager;
  BridgeRig& rig = *b.rig;
  ASSERT_GE(rig.collect_at_least(3, 2000ms), 3) << "the sensor is read";
  auto last_status = [&] {
    manager.take(::getpid());
    for (auto m = manager.heard.rbegin(); m != manager.heard.rend(); ++m)
      if (m->rfind("STATUS=", 0) == 0) return *m;
    return std::string();
  };
  auto wait_for = [&](const std::string& prefix) {
    for (int i = 0; i < 400 && last_status().rfind(prefix, 0) != 0; ++i) std::this_thread::sleep_for(5ms);
    return last_status();
  };
  ASSERT_TRUE(rig.sensor_emu.write(900, {1}));  // exceptions
  EXPECT_EQ(wait_for("STATUS=sensor failing; stops written 0; last: sensor: modbus exception:").rfind(
                "STATUS=sensor failing; stops written 0; last: sensor: modbus exception:", 0),
            0u)
      << last_status() << "\n" << rig.logged();
  ASSERT_TRUE(rig.sensor_emu.write(900, {0}));
  const std::string back = "STATUS=sensor ok; stops written 0; last: sensor answers again after ";
  EXPECT_EQ(wait_for(back).rfind(back, 0), 0u) << rig.logged();
}

// SIGHUP (an operator's "reload", a closed terminal) and SIGPIPE (a log pipe whose reader died)
// ended the bridge at once, mid-trial, with no stop written, and systemd took that for a clean
// exit and did not restart the unit. Both are now ignored: the bridge goes on carrying the
// trial's stop, and SIGTERM still shuts it down, writing the running trial's stop first.
TEST(BridgeModbus, HangupAndBrokenPipeDoNotEndTheBridge) {
  BridgeRig rig;
  ASSERT_GT(rig.robot_emu.port(), 0);
  handle_signals(rig.app.get());
  rig.predictor->send(protocol::encode(protocol::HeartbeatPredictor{0, protocol::PredictorState::InTrial, 1, 12, 5}));
  ASSERT_EQ(raise(SIGHUP), 0);
  ASSERT_EQ(raise(SIGPIPE), 0);
  std::this_thread::sleep_for(30ms);  // the bridge's loop takes the heartbeat
  EXPECT_EQ(rig.rc.load(), -1) << "the bridge's loop ended: " << rig.logged();
  ASSERT_EQ(raise(SIGTERM), 0);
  rig.loop.join();
  handle_signals(nullptr);
  EXPECT_EQ(rig.rc.load(), 0) << "SIGTERM: a clean shutdown. " << rig.logged();
  EXPECT_EQ(rig.app->stats().stops_written.load(), 1u) << "the running trial's stop. " << rig.logged();
  const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
  EXPECT_NE(mbpoll(coil).find("[7]: \t1"), std::string::npos) << mbpoll(coil);
}

// The bridge's pid with its stderr on `pipe_out`'s write end, which the test fills first: the
// bridge's first message on stderr blocks. SIGHUP and SIGPIPE as systemd leaves them for a
// service (default), whatever this test process set (HangupAndBrokenPipeDoNotEndTheBridge).
pid_t bridge_with_stderr_held(int pipe_out[2]) {
  fcntl(pipe_out[1], F_SETFL, O_NONBLOCK);
  const std::string page(4096, '.');
  while (write(pipe_out[1], page.data(), page.size()) > 0) {}
  while (write(pipe_out[1], ".", 1) > 0) {}
  fcntl(pipe_out[1], F_SETFL, 0);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    die_with_parent(parent);
    for (const int sig : {SIGHUP, SIGPIPE}) signal(sig, SIG_DFL);
    dup2(pipe_out[1], 2);
    close(pipe_out[0]);
    close(pipe_out[1]);
    execl(DG_BRIDGE, DG_BRIDGE, "--interface", "dg_none", "--no-rt", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(pipe_out[1]);
  return pid;
}

// True once `pid` sleeps in a write to its stderr (fd 2), in main: /proc's syscall file names the
// call it is blocked in and its arguments. False if it ended first or 10 s went by.
bool blocked_writing_stderr(pid_t pid) {
  const std::string in_write = std::to_string(SYS_write) + " 0x2 ";
  const std::string in_writev = std::to_string(SYS_writev) + " 0x2 ";
  for (int i = 0; i < 1000; ++i) {
    std::ifstream f("/proc/" + std::to_string(pid) + "/syscall");
    std::string call;
    std::getline(f, call);
    if (call.rfind(in_write, 0) == 0 || call.rfind(in_writev, 0) == 0) return true;
    siginfo_t ended{};  // WNOWAIT: left for the test's waitpid
    if (waitid(P_PID, static_cast<id_t>(pid), &ended, WEXITED | WNOHANG | WNOWAIT) != 0 || ended.si_pid == pid)
      return false;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

// SIGHUP and SIGPIPE are ignored from main's first line: one that came during the start-up (the
// robot's probe, the real-time setup, the CAN socket's opening) ended the bridge, which systemd
// counts as a clean exit and does not restart. Held in its first message on stderr (no --robot),
// the bridge gets the signal, then goes on as without it: no interface dg_none, exit 1.
TEST(BridgeCli, HangupAndBrokenPipeDuringStartUpDoNotEndIt) {
  for (const int sig : {SIGHUP, SIGPIPE}) {
    int out[2];
    ASSERT_EQ(pipe(out), 0);
    const pid_t pid = bridge_with_stderr_held(out);
    ASSERT_GT(pid, 0);
    const bool held = blocked_writing_stderr(pid);
    if (held) kill(pid, sig);
    std::string said;
    char buf[4096];
    for (ssize_t n; (n = read(out[0], buf, sizeof buf)) > 0;) said.append(buf, static_cast<size_t>(n));
    close(out[0]);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    said.erase(0, said.find_first_not_of('.'));
    ASSERT_TRUE(held) << "the bridge never blocked on its stderr: " << said;
    EXPECT_FALSE(WIFSIGNALED(status)) << strsignal(sig) << " during the start-up ended the bridge by "
                                      << strsignal(WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << strsignal(sig) << ": " << said;
    EXPECT_NE(said.find("dg_none"), std::string::npos) << strsignal(sig) << ": " << said;
  }
}

// The Linux port with the watchdog on: the robot controller starts trial 7, and the predictor
// beats every 50 ms. Idle (it lost the TrialStart), the bridge writes the stop coil and says
// why; naming trial 7 in trial, it writes nothing.
TEST(BridgeModbus, TrialThePredictorDoesNotGuardStopsTheRobot) {
  for (const auto state : {protocol::PredictorState::Idle, protocol::PredictorState::InTrial}) {
    const bool guarded = state == protocol::PredictorState::InTrial;
    RigOptions watched;
    watched.predictor_timeout_ms = 300;
    BridgeRig rig(watched);
    ASSERT_GT(rig.robot_emu.port(), 0);
    uint8_t counter = 0;
    const auto beat_for = [&](std::chrono::milliseconds d) {
      for (const auto end = std::chrono::steady_clock::now() + d; std::chrono::steady_clock::now() < end;) {
        rig.predictor->send(protocol::encode(protocol::HeartbeatPredictor{counter++, state, 1, guarded ? uint16_t{7} : uint16_t{6}, 5}));
        std::this_thread::sleep_for(50ms);
      }
    };
    beat_for(200ms);
    rig.predictor->send(protocol::encode(protocol::TrialStart{0, 7, 100, protocol::HeightClass::High}));
    beat_for(800ms);
    EXPECT_EQ(rig.app->stats().stops_written.load(), guarded ? 0u : 1u) << rig.logged();
    const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
    EXPECT_NE(mbpoll(coil).find(guarded ? "[7]: \t0" : "[7]: \t1"), std::string::npos) << mbpoll(coil);
    if (!guarded) {
      EXPECT_NE(rig.logged().find("the predictor has not guarded trial 7 for more than 300 ms (its heartbeat says idle, trial 6)"),
                std::string::npos)
          << rig.logged();
    }
  }
}

// The least line time of one reading, in closed form: (8 + 17 characters + 2 x 3.5 of silence)
// x 10 bits (11 with parity) / baud. 100 Hz polling needs 38400 baud or more.
TEST(BridgeModbus, RtuLineTimeOfOneReading) {
  EndpointParts p;
  ASSERT_EQ(parse_endpoint("rtu:/dev/ttyUSB0:19200:N", &p), "");
  EXPECT_NEAR(rtu_reading_ms(p), 32.0 * 10 / 19200 * 1000, 1e-9);
  EXPECT_GT(rtu_reading_ms(p), 10.0);
  ASSERT_EQ(parse_endpoint("rtu:/dev/ttyUSB0:19200:E", &p), "");
  EXPECT_NEAR(rtu_reading_ms(p), 32.0 * 11 / 19200 * 1000, 1e-9);
  ASSERT_EQ(parse_endpoint("rtu:/dev/ttyUSB0:38400:N", &p), "");
  EXPECT_LT(rtu_reading_ms(p), 10.0);
  ASSERT_EQ(parse_endpoint("tcp:127.0.0.1:502", &p), "");
  EXPECT_EQ(rtu_reading_ms(p), 0.0);
}

// A null-modem cable made of two pseudo-terminals: bytes written to one end's slave come out of
// the other end's slave (a thread copies between the two masters), so libmodbus's RTU code runs
// on real tty devices with termios, as on the FT 300's RS-485 adapter.
class NullModem {
 public:
  NullModem() {
    for (int k = 0; k < 2; ++k) {
      master_[k] = posix_openpt(O_RDWR | O_NOCTTY);
      grantpt(master_[k]);
      unlockpt(master_[k]);
      name_[k] = ptsname(master_[k]);
      // Keep a slave open so that the master never sees a hang-up between the clients' opens.
      hold_[k] = ::open(name_[k].c_str(), O_RDWR | O_NOCTTY);
      termios t;
      tcgetattr(hold_[k], &t);
      cfmakeraw(&t);
      tcsetattr(hold_[k], TCSANOW, &t);
    }
    relay_ = std::thread([this] {
      char buf[256];
      while (!stop_.load()) {
        pollfd p[2] = {{master_[0], POLLIN, 0}, {master_[1], POLLIN, 0}};
        if (poll(p, 2, 20) <= 0) continue;
        for (int k = 0; k < 2; ++k) {
          if (!(p[k].revents & POLLIN)) continue;
          const ssize_t n = ::read(master_[k], buf, sizeof buf);
          if (n > 0) [[maybe_unused]] ssize_t w = ::write(master_[1 - k], buf, static_cast<size_t>(n));
        }
      }
    });
  }
  ~NullModem() {
    stop_.store(true);
    relay_.join();
    for (int k = 0; k < 2; ++k) {
      ::close(hold_[k]);
      ::close(master_[k]);
    }
  }
  const std::string& end(int k) const { return name_[k]; }

 private:
  int master_[2] = {-1, -1}, hold_[2] = {-1, -1};
  std::string name_[2];
  std::atomic<bool> stop_{false};
  std::thread relay_;
};

TEST(BridgeModbus, RtuSensorOnASerialLine) {
  NullModem cable;
  // The emulator serves the sensor's registers on one end of the cable.
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    die_with_parent(parent);
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    execl(DG_EMULATOR, DG_EMULATOR, "--rtu", cable.end(0).c_str(), "--slave", "9", static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(200ms);
  // The test sets the registers through the bridge's own link type, on the other end.
  ModbusLink setter(ModbusEndpoint{"rtu:" + cable.end(1) + ":115200:N", 9, 500});
  ASSERT_TRUE(setter.connect()) << setter.last_error();
  const uint16_t values[6] = {static_cast<uint16_t>(-420), 17, 999, 1, 2, 3};
  ASSERT_EQ(modbus_write_registers(setter.ctx(), 180, 6, values), 6) << modbus_strerror(errno);
  setter.close();
  ModbusSensor sensor(ModbusEndpoint{"rtu:" + cable.end(1) + ":115200:N", 9, 500}, SensorMap{});
  ASSERT_TRUE(sensor.link().connect()) << sensor.link().last_error();
  FtReading r{};
  EXPECT_EQ(sensor.read(r), ReadResult::Ok) << sensor.link().last_error();
  EXPECT_EQ(r.force[0], -420);
  EXPECT_EQ(r.force[2], 999);
  EXPECT_EQ(r.torque[2], 3);
  // An exception on the line: reported as such, the link kept.
  ModbusLink fault(ModbusEndpoint{"rtu:" + cable.end(1) + ":115200:N", 9, 500});
  sensor.link().close();
  ASSERT_TRUE(fault.connect());
  const uint16_t one = 1;
  ASSERT_EQ(modbus_write_registers(fault.ctx(), 900, 1, &one), 1);
  fault.close();
  ASSERT_TRUE(sensor.link().connect());
  EXPECT_EQ(sensor.read(r), ReadResult::Exception) << sensor.link().last_error();
  EXPECT_TRUE(sensor.link().connected());
  sensor.link().close();
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
}

// ---- the FT 300's data stream (ft300_stream.h) -----------------------------------------------

// A stream frame as the FT 300 manual draws it: 0x20 0x4E, six int16 low byte first, the CRC.
std::vector<uint8_t> ft300_frame(std::array<int16_t, 6> v) {
  std::vector<uint8_t> f = {0x20, 0x4E};
  for (const int16_t x : v) {
    f.push_back(static_cast<uint8_t>(static_cast<uint16_t>(x) & 0xFF));
    f.push_back(static_cast<uint8_t>(static_cast<uint16_t>(x) >> 8));
  }
  const uint16_t crc = crc16_modbus(f.data(), f.size());
  f.push_back(static_cast<uint8_t>(crc & 0xFF));
  f.push_back(static_cast<uint8_t>(crc >> 8));
  return f;
}

void feed(Ft300FrameParser& p, const std::vector<uint8_t>& bytes) {
  ASSERT_GE(p.space(), bytes.size());
  std::memcpy(p.tail(), bytes.data(), bytes.size());
  p.added(bytes.size());
}

// The CRC against the catalogue's check value, the start request against the bytes that
// scripts written apart from Robotiq's driver send to FT 300s (its CRC, CD CA, included).
TEST(Ft300Stream, CrcAndStartRequestAsPublished) {
  const uint8_t digits[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc16_modbus(digits, sizeof digits), 0x4B37);
  uint8_t request[ft300::kStartRequestBytes];
  ft300_start_request(9, request);
  const std::vector<uint8_t> want = {0x09, 0x10, 0x01, 0x9A, 0x00, 0x01, 0x02, 0x02, 0x00, 0xCD, 0xCA};
  EXPECT_EQ(std::vector<uint8_t>(request, request + sizeof request), want);
  std::string device;
  EXPECT_EQ(parse_stream_spec("rtu-stream:/dev/ttyUSB0", &device), "");
  EXPECT_EQ(device, "/dev/ttyUSB0");
  EXPECT_NE(parse_stream_spec("rtu-stream:", &device).find("no device"), std::string::npos);
  EXPECT_FALSE(is_stream_spec("rtu:/dev/ttyUSB0:19200:N"));
}

// Frames among junk, a damaged frame, a false header (also one inside the data: 20000 is
// 0x4E20, sent 20 4E), a frame split across two reads: every good frame exactly, no damaged
// one, each loss of step counted once.
TEST(Ft300Stream, ParserResynchronisesAndPublishesOnlyGoodFrames) {
  Ft300StreamStats stats;
  Ft300FrameParser p(stats);
  FtReading r{};
  const auto expect_frame = [&](std::array<int16_t, 6> v) {
    ASSERT_EQ(p.next(r), ReadResult::Ok);
    EXPECT_EQ(r.force[0], v[0]);
    EXPECT_EQ(r.force[2], v[2]);
    EXPECT_EQ(r.torque[0], v[3]);
    EXPECT_EQ(r.torque[2], v[5]);
  };
  feed(p, {0x00, 0x20, 0x11});  // junk before the first frame: skipped, not a resync
  feed(p, ft300_frame({-420, 17, 20000, -1, 2, -3}));
  expect_frame({-420, 17, 20000, -1, 2, -3});
  EXPECT_EQ(stats.resyncs.load(), 0u);
  EXPECT_EQ(stats.skipped_bytes.load(), 3u);
  std::vector<uint8_t> damaged = ft300_frame({-420, 17, 20000, -1, 2, -3});
  damaged[2] ^= 0x01;
  feed(p, damaged);
  feed(p, ft300_frame({100, -200, 300, -400, 500, -600}));
  EXPECT_EQ(p.next(r), ReadResult::BadData) << "the damaged frame";
  // The false header inside the damaged frame's data (its 20000) fails too, counted but not
  // returned: one frame was lost.
  expect_frame({100, -200, 300, -400, 500, -600});
  EXPECT_EQ(stats.resyncs.load(), 1u);
  EXPECT_EQ(stats.crc_failures.load(), 2u);
  const uint64_t failures = stats.crc_failures.load();
  feed(p, {0x20, 0x4E, 0x01});  // a false header before a frame
  feed(p, ft300_frame({1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(p.next(r), ReadResult::BadData);
  expect_frame({1, 2, 3, 4, 5, 6});
  EXPECT_EQ(stats.crc_failures.load(), failures + 1);
  EXPECT_EQ(stats.resyncs.load(), 2u);
  const std::vector<uint8_t> split = ft300_frame({-32768, 32767, 0, 0, 0, 0});
  feed(p, std::vector<uint8_t>(split.begin(), split.begin() + 9));
  EXPECT_EQ(p.next(r), ReadResult::Pending);
  feed(p, std::vector<uint8_t>(split.begin() + 9, split.end()));
  expect_frame({-32768, 32767, 0, 0, 0, 0});
  EXPECT_EQ(p.next(r), ReadResult::Pending);
  EXPECT_EQ(stats.frames.load(), 4u);
}

// dg_modbus_emulator as an FT 300 on one end of a null-modem cable, commanded through its stdin
// (--control: what Modbus cannot reach while the line streams); the bridge's end is device().
class Ft300OnALine {
 public:
  Ft300OnALine(bool streaming, const std::vector<std::string>& commands) {
    int in[2], out[2];
    if (pipe(in) != 0 || pipe(out) != 0) return;
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ == 0) {
      die_with_parent(parent);
      dup2(in[0], 0);
      dup2(out[1], 1);
      close(in[1]);
      close(out[0]);
      execl(DG_EMULATOR, DG_EMULATOR, "--rtu", cable_.end(0).c_str(), "--stream", streaming ? "1" : "0", "--control",
            "1", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(in[0]);
    close(out[1]);
    control_ = in[1];
    FILE* f = fdopen(out[0], "r");
    char line[256];
    ready_ = std::fgets(line, sizeof line, f) && std::strncmp(line, "serving", 7) == 0;
    std::fclose(f);
    for (const std::string& c : commands) command(c);
  }
  ~Ft300OnALine() {
    if (control_ >= 0) close(control_);
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  bool ready() const { return ready_; }
  void command(const std::string& c) {
    const std::string line = c + "\n";
    ASSERT_EQ(::write(control_, line.data(), line.size()), static_cast<ssize_t>(line.size()));
  }
  const std::string& device() const { return cable_.end(1); }
  // Over Modbus on the bridge's end (the stream stopped): holding register `addr`, or -1.
  int read_register(int addr) {
    ModbusLink link(ModbusEndpoint{"rtu:" + device() + ":19200:N", 9, 500});
    uint16_t v = 0;
    if (!link.connect() || modbus_read_registers(link.ctx(), addr, 1, &v) != 1) return -1;
    return v;
  }

 private:
  NullModem cable_;
  pid_t pid_ = -1;
  int control_ = -1;
  bool ready_ = false;
};

// The bridge reading the stream of an emulated FT 300 (its values set first), the CAN side on
// the in-process bus. Declared in this order, the bridge stops before its sensor goes.
struct StreamRig {
  Ft300OnALine ft300;
  Ft300Stream stream;
  BridgeRig rig;
  explicit StreamRig(bool streaming, int period_ms = 10)
      : ft300(streaming, {"set 180 -420 17 20000 -1 2 -3"}), stream(Ft300StreamConfig{ft300.device()}),
        rig(options(&stream, period_ms)) {}
  static RigOptions options(Sensor* sensor, int period_ms) {
    RigOptions o;
    o.own_sensor = sensor;
    o.period_ms = period_ms;
    return o;
  }
  const Ft300StreamStats& stats() const { return stream.stats(); }
};

// Force and torque frames of `frames` in pairs: each pair's counter, and whether all were
// exactly `want` (the emulated sensor's values).
struct Samples {
  std::vector<uint8_t> counters;
  int wrong = 0, unpaired = 0;
};
Samples samples_of(const std::vector<Frame>& frames, std::array<int16_t, 6> want) {
  Samples s;
  for (size_t i = 0; i < frames.size(); ++i) {
    protocol::FtForce force;
    protocol::FtTorque torque;
    if (!protocol::decode(frames[i], force)) continue;
    if (i + 1 >= frames.size() || !protocol::decode(frames[i + 1], torque) || torque.counter != force.counter) {
      ++s.unpaired;
      continue;
    }
    s.counters.push_back(force.counter);
    const std::array<int16_t, 6> got = {force.fx, force.fy, force.fz, torque.mx, torque.my, torque.mz};
    s.wrong += got != want;
  }
  return s;
}

// The stream started by the bridge: 100 frames a second on CAN (the sensor's clock, not the
// bridge's timer), each a force and a torque frame with one counter, the counters in step,
// the values and their signs as the sensor holds them (-1 is sent FF FF, 20000 as 20 4E: a
// false header inside every frame).
TEST(BridgeStream, FramesFlowAt100HzWithTheirSigns) {
  StreamRig s(/*streaming=*/false);
  ASSERT_TRUE(s.ft300.ready());
  ASSERT_GE(s.rig.collect(600ms), 10) << s.rig.logged();  // started (listen 80 ms, switch, start)
  const uint64_t n0 = s.rig.app->stats().readings.load();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Frame> frames;
  s.rig.collect(1500ms, nullptr, nullptr, &frames);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double hz = static_cast<double>(s.rig.app->stats().readings.load() - n0) / seconds;
  EXPECT_NEAR(hz, 100.0, 12.0) << "readings per second";
  const Samples got = samples_of(frames, {-420, 17, 20000, -1, 2, -3});
  ASSERT_GE(got.counters.size(), 100u);
  EXPECT_EQ(got.wrong, 0);
  EXPECT_LE(got.unpaired, 1);  // the last force frame's torque may come after the window
  for (size_t i = 1; i < got.counters.size(); ++i)
    ASSERT_EQ(static_cast<uint8_t>(got.counters[i] - got.counters[i - 1]), 1) << "a sample lost or repeated at " << i;
  EXPECT_EQ(s.stats().crc_failures.load(), 0u);
  EXPECT_EQ(s.stats().streams_found.load(), 0u) << "it was not streaming";
  EXPECT_EQ(s.stats().starts.load(), 1u);
  EXPECT_EQ(s.rig.app->stats().sensor_errors.load(), 0u) << s.rig.logged();
}

// Each frame is published when its bytes come (epoll on the line), not on the bridge's next
// tick: with a 100 ms period, the frames still come every 10 ms, one at a time. (Read only on
// the timer they came ten at once; and the loop never waits on the line, so a stop frame does
// not wait either.)
TEST(BridgeStream, FramesArePublishedAsTheyComeNotOnTheTimer) {
  StreamRig s(/*streaming=*/false, /*period_ms=*/100);
  ASSERT_TRUE(s.ft300.ready());
  ASSERT_GE(s.rig.collect(800ms), 10) << s.rig.logged();
  std::vector<double> gaps_ms;
  auto last = std::chrono::steady_clock::now();
  const auto end = last + 1000ms;
  Frame f;
  can::RxInfo info;
  while (std::chrono::steady_clock::now() < end) {
    protocol::FtForce m;
    while (s.rig.listener->receive(f, info) == 1) {
      if (!protocol::decode(f, m)) continue;
      const auto now = std::chrono::steady_clock::now();
      gaps_ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
      last = now;
    }
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_GE(gaps_ms.size(), 80u);
  std::sort(gaps_ms.begin(), gaps_ms.end());
  EXPECT_GT(gaps_ms[gaps_ms.size() / 2], 5.0) << "frames came in bursts (the median gap)";
  EXPECT_LT(gaps_ms[gaps_ms.size() * 9 / 10], 30.0) << "frames waited for the timer (the 90th percentile gap)";
}

// A frame with one flipped bit (its CRC as sent) and a false header before a frame: neither is
// published, the reader finds the next frame, and the bridge says so (a sensor error, the line
// kept: no restart).
TEST(BridgeStream, ACorruptedByteIsNeverPublished) {
  StreamRig s(/*streaming=*/false);
  ASSERT_TRUE(s.ft300.ready());
  ASSERT_GE(s.rig.collect(600ms), 10) << s.rig.logged();
  std::vector<Frame> frames;
  for (const char* fault : {"corrupt", "junk", "corrupt"}) {
    s.ft300.command(fault);
    s.rig.collect(150ms, nullptr, nullptr, &frames);
  }
  s.rig.collect(200ms, nullptr, nullptr, &frames);
  const Samples got = samples_of(frames, {-420, 17, 20000, -1, 2, -3});
  EXPECT_EQ(got.wrong, 0) << "a damaged frame was published (fx -420 flipped is -419)";
  EXPECT_GE(got.counters.size(), 45u) << "frames stopped after the faults";
  EXPECT_GE(s.stats().crc_failures.load(), 3u);
  EXPECT_EQ(s.stats().resyncs.load(), 3u);
  EXPECT_EQ(s.stats().starts.load(), 1u) << "the line was restarted for a bad frame";
  EXPECT_EQ(s.rig.app->stats().sensor_errors.load(), 3u) << "one sensor error per lost frame";
  EXPECT_NE(s.rig.logged().find("a stream frame failed its CRC: not published"), std::string::npos) << s.rig.logged();
  EXPECT_NE(s.rig.logged().find("sensor answers again"), std::string::npos) << s.rig.logged();
}

// A sensor left streaming (by Robotiq's software, or just booted): the bridge hears it, jams it
// until the line is quiet, starts it again and reads it. At the end the stream is stopped, and
// the sensor answers Modbus on the line: it counted the jam and the start.
TEST(BridgeStream, AStreamLeftRunningIsJammedAndRestarted) {
  StreamRig s(/*streaming=*/true);
  ASSERT_TRUE(s.ft300.ready());
  protocol::FtForce last{};
  ASSERT_GE(s.rig.collect(800ms), 10) << s.rig.logged();
  EXPECT_GE(s.rig.collect(300ms, &last), 20);
  EXPECT_EQ(last.fx, -420);
  EXPECT_EQ(s.stats().streams_found.load(), 1u);
  EXPECT_EQ(s.stats().starts.load(), 1u);
  EXPECT_EQ(s.rig.shut_down(), 0);
  EXPECT_TRUE(s.stream.stop_stream(1000)) << s.stream.last_error();
  EXPECT_EQ(s.ft300.read_register(911), 2) << "streams stopped: the one found, the one at the end";
  EXPECT_EQ(s.ft300.read_register(912), 1) << "streams started";
}

// A sensor that goes dark for 300 ms (a power cut; it boots streaming): the silence is a sensor
// error within the stream's 100 ms, the heartbeat says so, no frame is sent meanwhile; the
// bridge restarts the stream once the sensor is back (jamming the one it booted into, or taking
// it for its start's when it comes while a start waits for its first frame, as [R] does).
TEST(BridgeStream, ASilentStreamIsASensorErrorAndRecovers) {
  StreamRig s(/*streaming=*/false);
  ASSERT_TRUE(s.ft300.ready());
  ASSERT_GE(s.rig.collect(600ms), 10) << s.rig.logged();
  s.ft300.command("dark 300");
  s.rig.collect(30ms);
  protocol::HeartbeatBridge hb{};
  EXPECT_EQ(s.rig.collect(250ms, nullptr, &hb), 0) << "frames while the sensor was dark";
  EXPECT_EQ(hb.state, protocol::BridgeState::SensorLost);
  EXPECT_GE(s.rig.app->stats().sensor_errors.load(), 1u);
  EXPECT_NE(s.rig.logged().find("sensor: timeout: " + s.ft300.device() + ": no good stream frame for "),
            std::string::npos) << s.rig.logged();
  protocol::FtForce last{};
  EXPECT_GE(s.rig.collect(1500ms, &last, &hb), 50) << "the stream did not come back: " << s.rig.logged();
  EXPECT_EQ(last.fx, -420);
  EXPECT_EQ(hb.state, protocol::BridgeState::Ok);
  EXPECT_GE(s.stats().starts.load(), 2u);
  EXPECT_NE(s.rig.logged().find("sensor answers again"), std::string::npos) << s.rig.logged();
}

// The Modbus RTU CRC-16 (reflected polynomial 0xA001, initial 0xFFFF) appended to `frame`, low
// byte first, as on the line.
std::vector<uint8_t> with_crc(std::vector<uint8_t> frame) {
  const uint16_t crc = crc16_modbus(frame.data(), frame.size());
  frame.push_back(static_cast<uint8_t>(crc & 0xFF));
  frame.push_back(static_cast<uint8_t>(crc >> 8));
  return frame;
}

// A Modbus RTU device on a pseudo-terminal whose answers the test writes byte by byte:
// `answer(k)` returns what goes back to the k-th request (0-based; nothing: no answer). It may
// wait or act first (an answer that comes late or stops part-way, a frame sent meanwhile).
class PtyDevice {
 public:
  using Answer = std::function<std::vector<uint8_t>(int request)>;
  explicit PtyDevice(Answer answer) : answer_(std::move(answer)) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY);
    grantpt(master_);
    unlockpt(master_);
    path_ = ptsname(master_);
    // Keep the slave open so that the master never sees a hang-up between the link's opens.
    hold_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY);
    termios t;
    tcgetattr(hold_, &t);
    cfmakeraw(&t);
    tcsetattr(hold_, TCSANOW, &t);
    serving_ = std::thread([this] { serve(); });
  }
  ~PtyDevice() {
    stop();
    ::close(hold_);
    ::close(master_);
  }
  // No more answers (before what `answer` uses goes away).
  void stop() {
    stop_.store(true);
    if (serving_.joinable()) serving_.join();
  }
  std::string spec() const { return "rtu:" + path_ + ":115200:N"; }
  int requests() const { return requests_.load(); }

 private:
  void serve() {
    uint8_t request[256];
    while (!stop_.load()) {
      pollfd p{master_, POLLIN, 0};
      if (poll(&p, 1, 20) <= 0 || ::read(master_, request, sizeof request) <= 0) continue;
      const std::vector<uint8_t> bytes = answer_(requests_.load());
      ++requests_;
      if (!bytes.empty()) [[maybe_unused]] ssize_t w = ::write(master_, bytes.data(), bytes.size());
    }
  }
  Answer answer_;
  int master_ = -1, hold_ = -1;
  std::string path_;
  std::atomic<int> requests_{0};
  std::atomic<bool> stop_{false};
  std::thread serving_;
};

// A garbled exception reply (function 0x83 with code 0x20, which Modbus does not define; its CRC
// right) is a line fault like any garbled answer: the link is closed, so that what is left of it
// on the line is never read as the next answer. It was classed as a Modbus exception and the
// link kept. Every libmodbus code past the standard's exceptions (EMBXILFUN..EMBXGTAR) is one.
TEST(BridgeModbus, AGarbledExceptionClosesTheLink) {
  PtyDevice device([](int) { return with_crc({0x09, 0x83, 0x20}); });
  ModbusSensor sensor(ModbusEndpoint{device.spec(), 9, 200}, SensorMap{});
  ASSERT_TRUE(sensor.link().connect()) << sensor.link().last_error();
  FtReading r{};
  EXPECT_STREQ(read_result_name(sensor.read(r)), "bad data") << sensor.link().last_error();
  EXPECT_FALSE(sensor.link().connected()) << "the link was kept after a garbled answer";
  using Outcome = std::pair<std::string, bool>;  // what it was classed as, the link kept
  const auto classified = [&sensor](int e) {
    EXPECT_TRUE(sensor.link().connect()) << sensor.link().last_error();
    errno = e;
    const ReadResult rr = sensor.link().classify_failure();
    return Outcome{read_result_name(rr), sensor.link().connected()};
  };
  for (int e : {EMBBADCRC, EMBBADDATA, EMBBADEXC, EMBUNKEXC, EMBMDATA, EMBBADSLAVE})
    EXPECT_EQ(classified(e), (Outcome{"bad data", false})) << modbus_strerror(e);
  for (int e = EMBXILFUN; e <= EMBXGTAR; ++e)
    EXPECT_EQ(classified(e), (Outcome{"modbus exception", true})) << modbus_strerror(e);
  sensor.link().close();
}

// The answer of a sensor (FC03, six registers) whose registers all read `value`.
std::vector<uint8_t> ft_answer(uint8_t value = 0) {
  std::vector<uint8_t> a = {0x09, 0x03, 0x0C};
  for (int k = 0; k < 6; ++k) a.insert(a.end(), {0, value});
  return with_crc(a);
}

// An answer that stops part-way (RS-485 noise, a device reset mid-frame) ends at the response
// timeout, on the sensor's link and on the robot's. libmodbus's default byte timeout (500 ms
// after each chunk) held such a read for 0.5 s, and every stop frame behind it. The bound is the
// timeout plus 100 ms: a busy 2-core machine's scheduling delay (the device thread, the reader),
// and still a fifth of the half second the byte timeout added.
TEST(BridgeModbus, ACutShortAnswerEndsAtTheResponseTimeout) {
  constexpr int kTimeoutMs = 20;
  constexpr auto kMargin = 100ms;
  const auto elapsed_since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0);
  };
  PtyDevice sensor_device([](int) { return std::vector<uint8_t>{0x09, 0x03, 0x0C}; });
  ModbusSensor sensor(ModbusEndpoint{sensor_device.spec(), 9, kTimeoutMs}, SensorMap{});
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(sensor.link().connect()) << sensor.link().last_error();
    FtReading r{};
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_STREQ(read_result_name(sensor.read(r)), "timeout") << sensor.link().last_error();
    EXPECT_LE(elapsed_since(t0), std::chrono::milliseconds(kTimeoutMs) + kMargin) << "read " << k;
  }
  // The robot's link: write_stop tries twice (a reconnect between), each bounded the same way.
  PtyDevice robot_device([](int) { return std::vector<uint8_t>{0x01, 0x05, 0x00}; });
  RobotStopWriter robot(ModbusEndpoint{robot_device.spec(), 1, kTimeoutMs}, StopTarget{true, 7, 1});
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(robot.write_stop());
  EXPECT_EQ(robot_device.requests(), 2);
  EXPECT_LE(elapsed_since(t0), std::chrono::milliseconds(2 * kTimeoutMs) + kMargin) << robot.link().last_error();
}

// A wakeup that finds both the timer and a stop frame ready takes the stop first: the stop is
// written before the next sensor read, which may take a whole response timeout. Here one answer
// comes 35 ms late (timeout 100 ms) with a stop sent 25 ms into it: the timer expired first, and
// epoll listed it first, so the next read went out with the stop still unwritten.
TEST(BridgeModbus, AStopOnTheBusGoesBeforeTheNextSensorRead) {
  std::atomic<BridgeRig*> rig_seen{nullptr};
  std::atomic<int> slow_read{-1}, written_at_next_read{-1};
  PtyDevice device([&](int k) {
    BridgeRig* rig = rig_seen.load();
    if (rig && slow_read.load() < 0) {
      slow_read = k;
      std::this_thread::sleep_for(25ms);
      rig->predictor->send(protocol::encode(protocol::Stop{0, protocol::StopReason::Caught, 240, 3, 250}));
      std::this_thread::sleep_for(10ms);
    } else if (rig && k == slow_read.load() + 1) {
      written_at_next_read = static_cast<int>(rig->app->stats().stops_written.load());
    }
    return ft_answer();
  });
  RigOptions pty_sensor;
  pty_sensor.sensor_spec = device.spec();
  pty_sensor.sensor_timeout_ms = 100;
  BridgeRig rig(pty_sensor);
  struct DeviceFirst {  // the device stops answering before the rig it sends on goes away
    PtyDevice& d;
    ~DeviceFirst() { d.stop(); }
  } device_first{device};
  ASSERT_GT(rig.robot_emu.port(), 0);
  rig_seen = &rig;
  for (int i = 0; i < 2000 && written_at_next_read.load() < 0; ++i) std::this_thread::sleep_for(1ms);
  EXPECT_EQ(written_at_next_read.load(), 1) << "the sensor was read again before the stop was written\n" << rig.logged();
}

// A gap in the readings shows on the sample counter as that many periods: across a late
// answer the counter advances by the time between the first and the last force frame in 10 ms
// periods (+-1: the two frames' jitter). It advanced by one per reading, and the predictor's
// logical time fell behind by the gap (4-5 periods here). First an answer 60 ms late against
// the 20 ms timeout (failed reads, timer overruns, reconnects), then on a pty sensor one answer
// 55 ms late within a 100 ms timeout (no failed read: only the overrun, counted and logged).
TEST(BridgeModbus, ALateAnswerShowsAsLostSamples) {
  const auto expect_periods_are_the_time = [](const BridgeRig::Span& span) {
    EXPECT_GE(span.ms, 250.0) << "too few readings";
    EXPECT_NEAR(span.periods, std::round(span.ms / 10.0), 1.0) << "over " << span.ms << " ms";
  };
  {
    SCOPED_TRACE("an answer after the timeout");
    BridgeRig rig;
    ASSERT_GT(rig.sensor_emu.port(), 0);
    EXPECT_GE(rig.collect(100ms), 3);
    expect_periods_are_the_time(rig.counted_periods(400ms, [&rig] {
      EXPECT_TRUE(rig.sensor_emu.write(902, {60}));
      EXPECT_TRUE(rig.sensor_emu.write(900, {4}));
    }));
    EXPECT_GE(rig.app->stats().sensor_errors.load(), 1u);
  }
  SCOPED_TRACE("an answer before the timeout");
  std::atomic<bool> slow_next{false};
  PtyDevice device([&](int) {
    if (slow_next.exchange(false)) std::this_thread::sleep_for(55ms);
    return ft_answer();
  });
  RigOptions pty_sensor;
  pty_sensor.sensor_spec = device.spec();
  pty_sensor.sensor_timeout_ms = 100;
  BridgeRig rig(pty_sensor);
  EXPECT_GE(rig.collect(100ms), 3);
  expect_periods_are_the_time(rig.counted_periods(400ms, [&slow_next] { slow_next = true; }));
  EXPECT_EQ(rig.app->stats().sensor_errors.load(), 0u) << rig.logged();
  EXPECT_GE(rig.app->stats().overruns.load(), 1u);
  EXPECT_NE(rig.logged().find("timer overran: "), std::string::npos) << rig.logged();
}

// The CAN side says what fails, as the sensor side does: a send failing at its 1st, 2nd, 4th,
// ... failure in a row by its kind, once when sends go out again; the same for receives (by
// errno); controller error frames by class at the 1st, 2nd, 4th, ... since the last restart, and
// the restart. 300 sends failed with "down" (a bus-off controller) and the log stayed empty.
TEST(BridgeModbus, CanFailuresAreLoggedAtEachDoublingAndAtRecovery) {
  BridgeRig rig;
  ASSERT_GT(rig.sensor_emu.port(), 0);
  EXPECT_GE(rig.collect(100ms), 3);
  rig.bus.fail_next_sends(300, can::SendResult::Down);
  ASSERT_TRUE(rig.logs("CAN sends go out again after 300 failures")) << rig.logged();
  EXPECT_EQ(lines_with(rig.logged(), "CAN send failed: down ("), 9) << "1, 2, 4, ..., 256\n" << rig.logged();
  uint8_t counter = 0;
  const auto wake_the_loop = [&] {
    rig.predictor->send(protocol::encode(
        protocol::HeartbeatPredictor{counter++, protocol::PredictorState::Idle, 1, 0, 0}));
  };
  rig.faults->fail_receives(20, ENETDOWN);
  wake_the_loop();
  ASSERT_TRUE(rig.logs("CAN receives work again after 20 failures")) << rig.logged();
  EXPECT_EQ(lines_with(rig.logged(), "CAN receive failed: Network is down ("), 5) << rig.logged();
  rig.faults->error_frames(40, can::kErrorBusOff);
  wake_the_loop();
  ASSERT_TRUE(rig.logs("(class 0x40; 32 since the controller's last restart)")) << rig.logged();
  EXPECT_EQ(lines_with(rig.logged(), "CAN error frame: bus-off (class 0x40; "), 6) << rig.logged();
  rig.faults->error_frames(1, can::kErrorRestarted);
  wake_the_loop();
  EXPECT_TRUE(rig.logs("CAN controller restarted (after 40 error frames)")) << rig.logged();
  EXPECT_EQ(rig.app->stats().error_frames.load(), 41u);
  EXPECT_EQ(rig.app->stats().receive_failures.load(), 20u);
}

// epoll failing ends the loop (exit 1), but not silently and not without the shutdown's stop:
// with the predictor in a trial the bridge stops the robot first, as at SIGTERM. It returned 1
// at once, saying nothing and leaving the trial unguarded.
TEST(BridgeModbus, AnEpollFailureIsSaidAndStillStopsARunningTrial) {
  BridgeRig rig;
  ASSERT_GT(rig.robot_emu.port(), 0);
  rig.predictor->send(protocol::encode(protocol::HeartbeatPredictor{0, protocol::PredictorState::InTrial, 1, 12, 5}));
  std::this_thread::sleep_for(30ms);  // the bridge's loop takes it
  g_fail_epoll = true;
  for (int i = 0; i < 3000 && rig.rc.load() == -1; ++i) std::this_thread::sleep_for(1ms);
  g_fail_epoll = false;
  EXPECT_EQ(rig.rc.load(), 1);
  EXPECT_NE(rig.logged().find("epoll_wait failed: Bad file descriptor; shutting down"), std::string::npos)
      << rig.logged();
  EXPECT_EQ(rig.app->stats().stops_written.load(), 1u) << rig.logged();
  const std::string coil = "-p " + std::to_string(rig.robot_emu.port()) + " -a 1 -r 7 -c 1 -t 0 127.0.0.1";
  EXPECT_NE(mbpoll(coil).find("[7]: \t1"), std::string::npos) << mbpoll(coil);
}

}  // namespace
