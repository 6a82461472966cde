// The predictor's logic without a bus: each StopPolicy rule, the E2E handling of bad frames, the
// stop transmission's confirmation and retries, the status counters, the config file, and zero
// heap allocations per sample.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "alloc_counter.h"
#include "predictor_core.h"
#include "test_model.h"

using namespace dressguard;
using namespace dressguard::predictor;
using protocol::Frame;
using protocol::PredictorState;
using protocol::StatusCounter;

namespace {

constexpr int64_t kMs = 1'000'000;

// Records everything; transmit_stop answers with a scripted result.
class RecordingSink : public PredictorSink {
 public:
  uint8_t transmit_stop(const Frame& f) noexcept override {
    stops.push_back(f);
    if (fail_next > 0) {
      --fail_next;
      return 1;  // can::SendResult::NoBuffers
    }
    return 0;
  }
  uint8_t transmit(const Frame& f) noexcept override {
    others.push_back(f);
    return 0;
  }
  void event(const Event& e) noexcept override { events.push_back(e); }
  std::vector<Frame> stops, others;
  std::vector<Event> events;
  int fail_next = 0;
};

struct Harness {
  model::OutcomeModel model = testkit::test_model();
  PredictorConfig cfg;
  RecordingSink sink;
  testkit::FrameSource src;
  std::unique_ptr<Predictor> p;
  int64_t now = 0;
  explicit Harness(bool with_model = true, PredictorConfig c = {}) : cfg(c) {
    p = std::make_unique<Predictor>(with_model ? &model : nullptr, cfg, sink);
  }
  void start(uint16_t trial = 1) { p->on_frame(src.trial_start(trial), now); }
  // One sample, 10 ms after the previous one, with ticks in between.
  void sample(double f_motion, double f_vertical) {
    for (int i = 0; i < 10; ++i) p->on_tick(now += kMs);
    p->on_frame(src.force(f_motion, f_vertical), now);
    p->on_frame(src.torque(), now);
    src.next();
  }
  protocol::Stop last_stop() const {
    protocol::Stop s{};
    EXPECT_FALSE(sink.stops.empty());
    if (!sink.stops.empty()) protocol::decode(sink.stops.back(), s);
    return s;
  }
};

TEST(StopPolicy, CaughtStopsAfterKConsecutiveSamplesAboveThreshold) {
  Harness h;
  h.start(7);
  // An independent filter gives the posterior after each sample; the policy must stop at the
  // first index where the last k = 3 posteriors all exceed 0.9.
  filter::ForwardFilter ref(h.model);
  ref.reset();
  int expected_stop = -1, run = 0;
  for (int i = 0; i < 40 && h.sink.stops.empty(); ++i) {
    const double f = i < 10 ? -2.0 : -6.0;  // good-like drag, then caught-like
    h.sample(f, f < -3 ? -1.0 : 0.0);
    ref.step(f, 0.0, f < -3 ? -1.0 : 0.0);
    run = ref.posterior(2) > 0.9 ? run + 1 : 0;
    if (run == 3 && expected_stop < 0) expected_stop = i;
  }
  ASSERT_EQ(h.sink.stops.size(), 1u);
  const auto s = h.last_stop();
  EXPECT_EQ(s.reason, protocol::StopReason::Caught);
  EXPECT_EQ(s.trial_id, 7);
  EXPECT_EQ(static_cast<int>(s.sample), expected_stop);
  EXPECT_GT(s.p_caught, 0.9 * 255);
  EXPECT_EQ(h.p->decision().state, PredictorState::Stopped);
}

TEST(StopPolicy, GoodTrialNeverStops) {
  Harness h;
  h.start();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int i = 0; i < 600; ++i) h.sample(-2.0 + noise(rng), noise(rng));
  EXPECT_TRUE(h.sink.stops.empty());
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
  EXPECT_EQ(h.p->decision().sample, 599u);
}

TEST(StopPolicy, HardLimitStopsOnEitherAxisEvenWhenTheModelSaysGood) {
  for (int axis = 0; axis < 2; ++axis) {
    Harness h;
    h.start();
    for (int i = 0; i < 5; ++i) h.sample(-2.0, 0.0);
    h.sample(axis == 0 ? -9.99 : -2.0, axis == 1 ? 9.99 : 0.0);  // at the limit: no stop
    EXPECT_TRUE(h.sink.stops.empty());
    h.sample(axis == 0 ? -10.01 : -2.0, axis == 1 ? 10.01 : 0.0);  // 0.01 N above: stop
    ASSERT_EQ(h.sink.stops.size(), 1u);
    EXPECT_EQ(h.last_stop().reason, protocol::StopReason::HardLimit);
    EXPECT_EQ(h.last_stop().sample, 6);
  }
}

TEST(StopPolicy, SensorTimeoutStopsWithinTheDeadlinePlusOneTick) {
  Harness h;
  h.start();
  for (int i = 0; i < 5; ++i) h.sample(-2.0, 0.0);
  const int64_t last = h.now;
  while (h.sink.stops.empty() && h.now < last + 200 * kMs) h.p->on_tick(h.now += kMs);
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::SensorTimeout);
  // Deadline 50 ms, ticks of 1 ms: the stop comes in (50, 51] ms after the last sample.
  EXPECT_GT(h.now - last, h.cfg.sensor_timeout_ns);
  EXPECT_LE(h.now - last, h.cfg.sensor_timeout_ns + kMs);
  EXPECT_EQ(h.last_stop().sample, 5) << "the deciding sample is the one that never came";
  EXPECT_EQ(h.p->counter(StatusCounter::Timeouts), 1u);
}

TEST(StopPolicy, NoTimeoutOutsideATrial) {
  Harness h;
  for (int i = 0; i < 500; ++i) h.p->on_tick(h.now += kMs);
  EXPECT_TRUE(h.sink.stops.empty());
}

TEST(StopPolicy, ModelThatDidNotLoadRefusesEveryTrial) {
  Harness h(false);
  EXPECT_EQ(h.p->decision().state, PredictorState::Fault);
  h.start(3);
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::ModelError);
  EXPECT_EQ(h.last_stop().trial_id, 3);
  // After the refused trial's end the heartbeat says fault again (PROTOCOL.md: 3 fault, no
  // model), not idle as if a model were loaded.
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  h.p->on_frame(h.src.trial_end(3, 0), h.now);
  EXPECT_EQ(h.p->decision().state, PredictorState::Fault);
}

// A trial end that comes before the stop's echo leaves the stop latched (unconfirmed, it is
// still being resent); the echo then rests the predictor, instead of leaving it "stopped",
// sending posteriors, until the next trial start.
TEST(StopTransmission, AnEchoAfterTheTrialEndRestsThePredictor) {
  Harness h;
  h.start(4);
  h.sample(-20.0, 0.0);
  ASSERT_TRUE(h.p->stop_pending());
  h.p->on_frame(h.src.trial_end(4, 1), h.now);
  EXPECT_EQ(h.p->decision().state, PredictorState::Stopped);
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  EXPECT_FALSE(h.p->stop_pending());
  EXPECT_EQ(h.p->decision().state, PredictorState::Idle);
  EXPECT_EQ(h.p->decision().reason, protocol::StopReason::HardLimit) << "the finished trial's reason stays readable";
}

TEST(E2EHandling, CorruptedRepeatedLateFramesAreCountedAndNotUsed) {
  Harness h;
  h.start();
  for (int i = 0; i < 30; ++i) h.sample(-2.0, 0.0);
  // A corrupted caught-like frame must not reach the filter.
  Frame bad = h.src.force(-50.0, 0.0);
  bad.data[4] ^= 0x01;
  h.p->on_frame(bad, h.now);
  EXPECT_TRUE(h.sink.stops.empty()) << "a corrupted -50 N frame was used";
  // A repeated frame (same counter as the last sample) and a late one are discarded.
  testkit::FrameSource old = h.src;
  old.sample_counter = static_cast<uint8_t>(h.src.sample_counter - 1);
  h.p->on_frame(old.force(-50.0, 0.0), h.now);
  old.sample_counter = static_cast<uint8_t>(h.src.sample_counter - 5);
  h.p->on_frame(old.force(-50.0, 0.0), h.now);
  EXPECT_TRUE(h.sink.stops.empty());
  EXPECT_EQ(h.p->counter(StatusCounter::Corrupted), 1u);
  EXPECT_EQ(h.p->counter(StatusCounter::Repeated), 1u);
  EXPECT_EQ(h.p->counter(StatusCounter::Late), 1u);
  EXPECT_EQ(h.p->decision().sample, 29u);
}

TEST(E2EHandling, LostFramesAdvanceLogicalTime) {
  Harness h;
  h.start();
  for (int i = 0; i < 10; ++i) h.sample(-2.0, 0.0);
  h.src.next();  // sample 10 lost (both frames)
  h.src.next();  // sample 11 lost
  h.sample(-2.0, 0.0);
  EXPECT_EQ(h.p->decision().sample, 12u);
  EXPECT_EQ(h.p->counter(StatusCounter::LostFrames), 4u) << "2 force + 2 torque frames";
  EXPECT_TRUE(h.sink.stops.empty()) << "two lost samples are within the budget";
}

// Trial frames are sporadic: trial starts and ends of other trials lost on the way (here the
// previous trial's end and six starts) are counted, not charged to the running trial's budget.
// Charged, they stopped the old trial with its id after the new start was on the bus, and the
// bridge latched that stop into the new trial.
TEST(E2EHandling, LostTrialFramesAreNotChargedToTheRunningTrial) {
  Harness h;
  h.start(1);
  for (int i = 0; i < 10; ++i) h.sample(-2.0, 0.0);
  h.src.trial_end(1, 10);  // lost
  for (uint16_t t = 2; t < 8; ++t) h.src.trial_start(t);  // lost
  h.start(8);
  EXPECT_TRUE(h.sink.stops.empty()) << "a stop for trial " << h.last_stop().trial_id;
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
  EXPECT_EQ(h.p->decision().trial, 8);
  EXPECT_EQ(h.p->counter(StatusCounter::LostFrames), 6u) << "the six starts; the end is another stream";
  for (int i = 0; i < 10; ++i) h.sample(-2.0, 0.0);
  EXPECT_TRUE(h.sink.stops.empty());
}

// A stop decided by the samples a force frame's counter says were lost names that frame's
// sample (previous + 1 + lost), as the protocol's `sample` field promises, not the previous one.
TEST(E2EHandling, ABadFramesStopNamesTheSampleThatDecided) {
  Harness h;
  h.start();
  for (int i = 0; i < 10; ++i) h.sample(-2.0, 0.0);  // samples 0..9
  for (int i = 0; i < 6; ++i) h.src.next();          // 10..15 lost: 6 x 20 > budget 5 x 20
  h.sample(-2.0, 0.0);                               // sample 16 decides
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::BadFrames);
  EXPECT_EQ(h.last_stop().sample, 16);
  EXPECT_EQ(h.p->decision().stop_sample, 16u);
}

TEST(E2EHandling, BurstOfCorruptedFramesIsAFailSafeStop) {
  Harness h;
  h.start();
  for (int i = 0; i < 10; ++i) h.sample(-2.0, 0.0);
  // Budget 5 x weight 20 = 100: the 6th corrupted frame in a row exceeds it.
  for (int i = 0; i < 6; ++i) {
    Frame bad = h.src.force(-2.0, 0.0);
    bad.data[2] ^= 0x80;
    h.p->on_frame(bad, h.now);
    if (i < 5) {
      EXPECT_TRUE(h.sink.stops.empty()) << i;
    }
  }
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::BadFrames);
}

TEST(E2EHandling, SparseCorruptionDoesNotStop) {
  Harness h;
  h.start();
  // One corrupted frame every 25 samples for 1000 samples: the bucket drains in between.
  for (int i = 0; i < 1000; ++i) {
    if (i % 25 == 0) {
      Frame bad = h.src.force(-2.0, 0.0);
      bad.data[3] ^= 0x04;
      h.p->on_frame(bad, h.now);
    }
    h.sample(-2.0, 0.0);
  }
  EXPECT_TRUE(h.sink.stops.empty());
  EXPECT_EQ(h.p->counter(StatusCounter::Corrupted), 40u);
}

TEST(StopTransmission, RetriedUntilEchoConfirmsWithFreshCounters) {
  Harness h;
  h.sink.fail_next = 2;  // ENOBUFS twice
  h.start();
  h.sample(-20.0, 0.0);  // hard limit
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_TRUE(h.p->stop_pending());
  for (int i = 0; i < 10; ++i) h.p->on_tick(h.now += kMs);  // retries every 2 ms
  ASSERT_GE(h.sink.stops.size(), 3u);
  EXPECT_EQ(h.p->counter(StatusCounter::TxErrors), 2u);
  // The echo of the latest transmission confirms; an echo of an older one would not.
  h.p->on_stop_echo(h.sink.stops.front(), h.now);
  EXPECT_TRUE(h.p->stop_pending()) << "an old frame's echo must not confirm the latest";
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  EXPECT_FALSE(h.p->stop_pending());
  const size_t sent = h.sink.stops.size();
  for (int i = 0; i < 20; ++i) h.p->on_tick(h.now += kMs);
  EXPECT_EQ(h.sink.stops.size(), sent) << "no retries after confirmation";
  // Each retry has its own counter, so the robot's E2E check never drops one as repeated.
  for (size_t i = 1; i < h.sink.stops.size(); ++i) EXPECT_NE(h.sink.stops[i].data[1], h.sink.stops[i - 1].data[1]);
  for (const auto& f : h.sink.stops) {
    protocol::Stop s;
    ASSERT_TRUE(protocol::decode(f, s));
    EXPECT_EQ(s.reason, protocol::StopReason::HardLimit);
  }
}

TEST(StopTransmission, BusOffIsCountedAndTheStopKeepsRetrying) {
  Harness h;
  h.sink.fail_next = 1000;  // every send fails while the controller is bus-off
  h.start();
  h.sample(-20.0, 0.0);
  h.p->on_bus_error(0x40 /* CAN_ERR_BUSOFF */, h.now);
  for (int i = 0; i < 20; ++i) h.p->on_tick(h.now += kMs);
  EXPECT_TRUE(h.p->stop_pending());
  EXPECT_GE(h.sink.stops.size(), 10u) << "retried every 2 ms while the bus is off";
  EXPECT_GE(h.p->counter(StatusCounter::TxErrors), 11u);  // 1 bus error + the failed sends
  h.sink.fail_next = 0;  // the controller recovered (restart-ms)
  for (int i = 0; i < 3; ++i) h.p->on_tick(h.now += kMs);
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  EXPECT_FALSE(h.p->stop_pending());
  bool logged = false;
  for (const auto& e : h.sink.events) logged |= e.kind == EventKind::BusError && e.value == 0x40;
  EXPECT_TRUE(logged);
}

// A stop that never reached the bus (its echo never came) belongs to a trial that is over once
// the next TrialStart arrives. Resending it would latch the new trial's robot with the old
// trial's reason and id; dropping it would run the new trial with a guard that cannot stop it.
// So the new trial is refused: a stop of its own, reason stop_unconfirmed, retried as any stop.
TEST(StopTransmission, AStopNeverConfirmedRefusesTheNextTrial) {
  Harness h;
  h.sink.fail_next = 1000;  // the stop socket's sends fail (ENOBUFS) between the trials
  h.start(1);
  h.sample(-20.0, 0.0);
  for (int i = 0; i < 1500; ++i) h.p->on_tick(h.now += kMs);
  ASSERT_TRUE(h.p->stop_pending());
  h.start(2);
  EXPECT_EQ(h.p->decision().state, PredictorState::Stopped);
  EXPECT_EQ(h.p->decision().reason, protocol::StopReason::StopUnconfirmed);
  EXPECT_EQ(h.p->decision().trial, 2);
  EXPECT_TRUE(h.p->stop_pending());
  const size_t at_start = h.sink.stops.size();
  h.sink.fail_next = 0;  // the bus recovers
  for (int i = 0; i < 10; ++i) h.p->on_tick(h.now += kMs);
  ASSERT_GT(h.sink.stops.size(), at_start);
  for (size_t i = at_start - 1; i < h.sink.stops.size(); ++i) {
    protocol::Stop s;
    ASSERT_TRUE(protocol::decode(h.sink.stops[i], s));
    EXPECT_EQ(s.trial_id, 2) << "the finished trial's stop was sent into the next one (send " << i << ")";
    EXPECT_EQ(s.reason, protocol::StopReason::StopUnconfirmed);
  }
  // Once confirmed, the trial after runs normally.
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  EXPECT_FALSE(h.p->stop_pending());
  const size_t confirmed = h.sink.stops.size();
  h.start(3);
  h.sample(1.0, 0.0);
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
  EXPECT_EQ(h.sink.stops.size(), confirmed);
}

// A stop decided less than a retry period before the next TrialStart may simply not have been
// echoed yet: it is dropped (not resent into the new trial), and the new trial runs.
// A filter whose posteriors failed (NaN compares false against the threshold) stops the robot
// as a model error instead of letting the trial run unguarded. The model's feature scale of
// 1e-200 makes any non-zero force overflow the Gaussian's exponent.
TEST(StopPolicy, AFailedFilterIsAModelError) {
  Harness h;
  h.model.features.scale[0] = 1e-200;
  h.p = std::make_unique<Predictor>(&h.model, h.cfg, h.sink);
  h.start(3);
  h.sample(0.0, 0.0);
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
  h.sample(-2.0, 0.0);
  EXPECT_EQ(h.p->decision().state, PredictorState::Stopped);
  EXPECT_EQ(h.p->decision().reason, protocol::StopReason::ModelError);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::ModelError);
}

TEST(StopTransmission, AStopJustSentIsDroppedAtTheNextTrialStart) {
  Harness h;
  h.start(1);
  h.sample(-20.0, 0.0);
  ASSERT_TRUE(h.p->stop_pending());
  const size_t sent = h.sink.stops.size();
  h.sink.events.clear();
  h.p->on_frame(h.src.trial_start(2), h.now + kMs);  // within stop_retry_ns (2 ms)
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
  EXPECT_FALSE(h.p->stop_pending());
  // It is not dropped silently: one event names the finished trial, its reason and its age.
  int dropped = 0;
  for (const auto& e : h.sink.events) {
    if (e.kind != EventKind::StopDropped) continue;
    ++dropped;
    EXPECT_EQ(e.trial, 1);
    EXPECT_EQ(e.reason, protocol::StopReason::HardLimit);
    EXPECT_EQ(e.value, 1000u) << "age in microseconds";
  }
  EXPECT_EQ(dropped, 1);
  h.now += kMs;
  h.sample(1.0, 0.0);
  EXPECT_EQ(h.sink.stops.size(), sent) << "the finished trial's stop was resent into the next one";
  h.p->on_stop_echo(h.sink.stops.back(), h.now);  // its late echo changes nothing
  EXPECT_EQ(h.p->decision().state, PredictorState::InTrial);
}

// SIGTERM stops the running trial, and a trial that starts while the daemon still waits for that
// stop's echo is refused with its own Shutdown stop (it used to run, unguarded once the daemon
// had gone, and the pending stop was dropped); later trials too.
TEST(StopTransmission, ATrialStartingAfterShutdownIsRefused) {
  Harness h;
  h.start(1);
  h.sample(-2.0, 0.0);
  h.p->on_shutdown(h.now);
  ASSERT_TRUE(h.p->stop_pending());
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::Shutdown);
  h.p->on_frame(h.src.trial_start(2), h.now + kMs / 2);  // before the first stop's echo
  EXPECT_EQ(h.p->decision().state, PredictorState::Stopped);
  EXPECT_EQ(h.p->decision().trial, 2);
  EXPECT_EQ(h.p->decision().reason, protocol::StopReason::Shutdown);
  EXPECT_TRUE(h.p->stop_pending()) << "the refusal waits for its echo: the daemon does not exit before it";
  EXPECT_EQ(h.last_stop().trial_id, 2);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::Shutdown);
  h.p->on_stop_echo(h.sink.stops.back(), h.now + kMs);
  EXPECT_FALSE(h.p->stop_pending());
  h.p->on_frame(h.src.trial_start(3), h.now + 10 * kMs);  // confirmed, idle: still refused
  EXPECT_EQ(h.p->decision().reason, protocol::StopReason::Shutdown);
  EXPECT_EQ(h.last_stop().trial_id, 3);
}

// The heartbeat's uptime is whole seconds since the predictor's first frame or tick, saturating
// at 65,535 s (18.2 h) rather than wrapping to a freshly restarted daemon's. (Out of
// fuzz_predictor's reach.)
TEST(Status, HeartbeatUptimeSaturates) {
  Harness h;
  const int64_t s = 1'000'000'000;
  const auto uptime = [&h](int64_t t) {
    h.sink.others.clear();
    h.p->on_tick(t);
    for (const Frame& f : h.sink.others) {
      protocol::HeartbeatPredictor m;
      if (protocol::decode(f, m)) return static_cast<int>(m.uptime_s);
    }
    return -1;
  };
  EXPECT_EQ(uptime(5 * s), 0);  // the clock starts here
  EXPECT_EQ(uptime(5 * s + 65'535 * s), 65535);
  EXPECT_EQ(uptime(5 * s + 70'000 * s), 65535) << "saturates, does not wrap to 4464";
}

// Ticks through `periods` status periods and checks every PredictorStatus frame against the
// header: page p < kStatusPages carries counters 2p and 2p+1 as `want` gives them and the
// predictor's state; every page comes by.
static_assert(static_cast<int>(StatusCounter::Count) == 12, "a new counter needs its step in PagesCarryEveryCounter");
void check_status_pages(Harness& h, const std::array<uint32_t, 12>& want, int periods = 7) {
  h.sink.others.clear();
  for (int i = 0; i < periods * 100; ++i) h.p->on_tick(h.now += kMs);
  std::vector<int> seen(protocol::kStatusPages, 0);
  for (const Frame& f : h.sink.others) {
    protocol::PredictorStatus st;
    if (!protocol::decode(f, st)) continue;
    EXPECT_LT(st.page, protocol::kStatusPages);
    if (st.page >= protocol::kStatusPages) continue;
    ++seen[st.page];
    const auto name = [](int c) { return protocol::status_counter_name(static_cast<StatusCounter>(c)); };
    EXPECT_EQ(st.value0, want[2 * st.page]) << "page " << int{st.page} << " value0, " << name(2 * st.page);
    EXPECT_EQ(st.value1, want[2 * st.page + 1]) << "page " << int{st.page} << " value1, " << name(2 * st.page + 1);
    EXPECT_EQ(st.state, h.p->decision().state) << "page " << int{st.page};
  }
  for (int p = 0; p < protocol::kStatusPages; ++p) EXPECT_GE(seen[p], 1) << "page " << p << " never sent";
}

// Each of the twelve counters is driven to a value of its own (1 to 10, 14 and 30), so that a
// page carrying another page's counters, a page's two values swapped, or a counter left off a
// page shows; every page must carry exactly the core's counter(c) for its two counters, and its
// state. (The test once compared 3 of the 12.) The scenario, one counter per step:
//   trial 1: 20 samples; 3 corrupted force frames; 4 repeated (the last sample's counter again);
//   5 late (4 behind it); 6 frames of 6 bytes (bad length); 7 samples lost, force and torque
//   both: a jump of 8 > max_delta 3, so 2 wrong sequences and 14 lost frames; the 21st sample;
//   the kernel's cumulative drops 4, then 9; then silence: one timeout, the first stop, its
//   first two sends failing (2 tx errors), retried every 2 ms for 16 ms (8 retries) before its
//   echo; 5 bus errors (7 tx errors in all);
//   trials 2..10: one sample over the hard limit each, a stop each (10 stops, 30 samples), the
//   last left stopped (its stop confirmed, no TrialEnd): the pages must say "stopped".
// The bad-frame budget is raised: the 23 bad and lost frames charged would otherwise stop trial 1.
TEST(Status, PagesCarryEveryCounter) {
  PredictorConfig cfg;
  cfg.bad_frame_budget = 1000;
  Harness h(true, cfg);
  h.start(1);
  for (int i = 0; i < 20; ++i) h.sample(-2.0, 0.0);
  for (int i = 0; i < 3; ++i) {
    Frame bad = h.src.force(-2.0, 0.0);
    bad.data[3] ^= 1;
    h.p->on_frame(bad, h.now);
  }
  testkit::FrameSource old = h.src;
  old.sample_counter = static_cast<uint8_t>(h.src.sample_counter - 1);
  for (int i = 0; i < 4; ++i) h.p->on_frame(old.force(-2.0, 0.0), h.now);
  old.sample_counter = static_cast<uint8_t>(h.src.sample_counter - 5);
  for (int i = 0; i < 5; ++i) h.p->on_frame(old.force(-2.0, 0.0), h.now);
  for (int i = 0; i < 6; ++i) {
    Frame shorter = h.src.force(-2.0, 0.0);
    shorter.len = 6;
    h.p->on_frame(shorter, h.now);
  }
  for (int i = 0; i < 7; ++i) h.src.next();
  h.sample(-2.0, 0.0);
  h.p->on_kernel_drops(4, h.now);
  h.p->on_kernel_drops(9, h.now);
  h.sink.fail_next = 2;
  while (!h.p->stop_pending()) h.p->on_tick(h.now += kMs);
  ASSERT_EQ(h.p->decision().reason, protocol::StopReason::SensorTimeout);
  for (int i = 0; i < 16; ++i) h.p->on_tick(h.now += kMs);
  h.p->on_stop_echo(h.sink.stops.back(), h.now);
  ASSERT_FALSE(h.p->stop_pending());
  for (int i = 0; i < 5; ++i) h.p->on_bus_error(0x04 /* CAN_ERR_CRTL */, h.now);
  h.p->on_frame(h.src.trial_end(1, 28), h.now);
  for (uint16_t t = 2; t <= 10; ++t) {
    h.start(t);
    h.sample(-20.0, 0.0);
    ASSERT_EQ(h.p->decision().reason, protocol::StopReason::HardLimit) << "trial " << t;
    h.p->on_stop_echo(h.sink.stops.back(), h.now);
    if (t < 10) h.p->on_frame(h.src.trial_end(t, 1), h.now);
  }
  ASSERT_EQ(h.p->decision().state, PredictorState::Stopped);
  ASSERT_FALSE(h.p->stop_pending());

  // The scenario reached what it meant to: if it did not, the pages below would be compared
  // with counters that are zero or equal, and prove little.
  const std::array<std::pair<StatusCounter, uint32_t>, 12> meant = {{
      {StatusCounter::Corrupted, 3}, {StatusCounter::Repeated, 4}, {StatusCounter::WrongSequence, 2},
      {StatusCounter::LostFrames, 14}, {StatusCounter::Late, 5}, {StatusCounter::BadLength, 6},
      {StatusCounter::KernelDrops, 9}, {StatusCounter::Timeouts, 1}, {StatusCounter::TxRetries, 8},
      {StatusCounter::TxErrors, 7}, {StatusCounter::Samples, 30}, {StatusCounter::Stops, 10},
  }};
  std::array<uint32_t, 12> want{};
  for (int c = 0; c < 12; ++c) {
    ASSERT_EQ(meant[c].first, static_cast<StatusCounter>(c));
    want[c] = h.p->counter(static_cast<StatusCounter>(c));
    EXPECT_EQ(want[c], meant[c].second) << protocol::status_counter_name(meant[c].first);
  }
  check_status_pages(h, want);

  // What a u16 cannot hold: every counter saturates at 65535 but samples, sent mod 65536
  // (PROTOCOL.md's page table). 70,000 kernel drops and 65,536 more samples (outside a trial,
  // still counted) leave kernel_drops' value at 65535 and samples' at 30 again.
  h.p->on_kernel_drops(70'009, h.now);
  for (int i = 0; i < 65536; ++i) {
    h.p->on_frame(h.src.force(-2.0, 0.0), h.now);
    h.src.next();
  }
  ASSERT_EQ(h.p->counter(StatusCounter::KernelDrops), 70'009u);
  ASSERT_EQ(h.p->counter(StatusCounter::Samples), 30u + 65536u);
  want[static_cast<int>(StatusCounter::KernelDrops)] = 65535;
  want[static_cast<int>(StatusCounter::Samples)] = 30;
  check_status_pages(h, want);
}

TEST(Mounting, SensorAxesMapToRigAxes) {
  PredictorConfig cfg;
  // Sensor z points against the motion, sensor x is vertical: motion = -z, vertical = x.
  cfg = parse_predictor_config("mount_axes = -z y x\nmount_bias = 0 0 1.5\n", "t.conf");
  Harness h(true, cfg);
  h.start();
  // Sensor reads z = +10.5 N (motion -10.5 N): hard limit through the mapping.
  for (int i = 0; i < 10; ++i) h.p->on_tick(h.now += kMs);
  h.p->on_frame(protocol::encode(protocol::FtForce{0, 150, 0, 1050}), h.now);
  ASSERT_EQ(h.sink.stops.size(), 1u);
  EXPECT_EQ(h.last_stop().reason, protocol::StopReason::HardLimit);
  EXPECT_NEAR(h.p->decision().stop_f_motion, -10.5, 1e-9);
  EXPECT_NEAR(h.p->decision().stop_f_vertical, 0.0, 1e-9) << "x = 1.5 N minus the 1.5 N bias";
}

TEST(Config, ParsesKeysAndNamesBadLines) {
  std::vector<ConfigEntry> others;
  const auto c = parse_predictor_config(
      "# comment\nstop_threshold = 0.8\nstop_consecutive=4\nsensor_timeout_ms = 30\ninterface = vcan0\n", "p.conf",
      &others);
  EXPECT_DOUBLE_EQ(c.stop_threshold, 0.8);
  EXPECT_EQ(c.stop_consecutive, 4);
  EXPECT_EQ(c.sensor_timeout_ns, 30 * kMs);
  ASSERT_EQ(others.size(), 1u);
  EXPECT_EQ(others[0].key, "interface");
  for (const char* bad : {"stop_threshold = 1.5\n", "x\n", "hard_limit_n = ten\n", "mount_axes = x y w\n", "bogus = 1\n"}) {
    try {
      parse_predictor_config(std::string("\n") + bad, "p.conf");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("p.conf:2:"), std::string::npos) << e.what();
    }
  }
}

// A typo must not become a silent misconfiguration: 1e300 samples or milliseconds do not fit the
// integers they are stored in (undefined behaviour, in practice a negative count that falls back
// to the model's k or a deadline already past), 2.5 samples is not a count, and a sensor axis
// read twice leaves a rig axis unread. Each is an error naming the line, the key and its range.
TEST(Config, ValuesOutOfRangeOrNotWholeAreErrors) {
  for (const char* bad : {"stop_consecutive = 1e300\n", "stop_consecutive = 2.5\n", "sensor_timeout_ms = 1e300\n",
                          "bad_frame_budget = 3e9\n", "bad_frame_weight = 0.5\n", "max_delta_counter = 3.5\n",
                          "stop_retry_ms = 1e18\n", "hard_limit_n = 1e9\n", "mount_bias = 0 0 1e12\n",
                          "mount_axes = x -x z\n"}) {
    try {
      parse_predictor_config(std::string("\n") + bad, "p.conf");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      const std::string key = std::string(bad).substr(0, std::string(bad).find(' '));
      EXPECT_NE(std::string(e.what()).find("p.conf:2: " + key), std::string::npos) << e.what();
    }
  }
  // The largest values the VM test and a slow rig use still parse.
  const auto c = parse_predictor_config("stop_consecutive = 100000\nsensor_timeout_ms = 5000\n", "p.conf");
  EXPECT_EQ(c.stop_consecutive, 100000);
  EXPECT_EQ(c.sensor_timeout_ns, 5000 * kMs);
}

// The protocol's forces saturate at 327.67 N: a hard limit that a saturated reading, less the
// mount bias, cannot pass would never fire. Refused, naming the line of the limit (or of the
// bias when the limit is the default); the lateral axis, which the limit does not watch, is free.
TEST(Config, AHardLimitASaturatedReadingCannotPassIsAnError) {
  const auto error_of = [](const std::string& text) -> std::string {
    try {
      parse_predictor_config(text, "p.conf");
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of("\nhard_limit_n = 400\n").find("p.conf:2: hard_limit_n 400 N"), std::string::npos);
  EXPECT_NE(error_of("hard_limit_n = 300\nmount_bias = 0 0 -30\n").find("p.conf:1: hard_limit_n 300 N plus the mount "
                                                                          "bias's 30 N on the vertical axis"),
            std::string::npos);
  EXPECT_NE(error_of("mount_bias = 320 0 0\n").find("p.conf:1: hard_limit_n 10 N plus the mount bias's 320 N on the "
                                                     "motion axis"),
            std::string::npos);
  EXPECT_EQ(error_of("hard_limit_n = 300\nmount_bias = 0 200 0\n"), "");
  EXPECT_EQ(error_of("hard_limit_n = 327.66\n"), "");
}

// A key the file gave twice ran with the last value in silence (hard_limit_n = 10, then 50
// appended at the end by someone who did not see the first): now an error naming the key and
// both lines, for the daemon's keys too. A --set still overrides the file and an earlier --set.
TEST(Config, AKeyGivenTwiceInTheFileIsAnError) {
  const auto error_of = [](const std::string& text) -> std::string {
    std::vector<ConfigEntry> others;
    try {
      parse_config_with_sets(text, "p.conf", {}, &others);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of("hard_limit_n = 10\nsensor_timeout_ms = 50\nhard_limit_n = 50\n"),
            "p.conf:3: key 'hard_limit_n' given twice (first on p.conf:1)");
  EXPECT_EQ(error_of("model = a.dgm\n# the other one\nmodel=b.dgm\n"),
            "p.conf:3: key 'model' given twice (first on p.conf:1)");
  try {
    parse_predictor_config("stop_consecutive = 5\nstop_consecutive = 5\n", "q.conf");
    ADD_FAILURE() << "a key given twice was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "q.conf:2: key 'stop_consecutive' given twice (first on q.conf:1)");
  }
  std::vector<ConfigEntry> others;
  const auto c =
      parse_config_with_sets("hard_limit_n = 10\n", "p.conf", {"hard_limit_n=20", "hard_limit_n=30"}, &others);
  EXPECT_DOUBLE_EQ(c.hard_limit_n, 30.0) << "--set overrides the file, a later --set an earlier one";
}

// The configuration file installed with the daemon says "the values below are the defaults":
// it parses, every key it sets equals PredictorConfig's default, and the daemon's own keys come
// back to the daemon.
TEST(Config, TheShippedFileParsesToTheDefaults) {
  const std::string path = std::string(DRESSGUARD_SOURCE_DIR) + "/predictor/daemon/dressguard-predictor.conf";
  std::ifstream f(path);
  ASSERT_TRUE(f) << path;
  std::stringstream text;
  text << f.rdbuf();
  std::vector<ConfigEntry> others;
  const PredictorConfig c = parse_predictor_config(text.str(), path, &others);
  const PredictorConfig d;
  EXPECT_EQ(c.stop_threshold, d.stop_threshold);
  EXPECT_EQ(c.stop_consecutive, d.stop_consecutive);
  EXPECT_EQ(c.hard_limit_n, d.hard_limit_n);
  EXPECT_EQ(c.sensor_timeout_ns, d.sensor_timeout_ns);
  EXPECT_EQ(c.bad_frame_budget, d.bad_frame_budget);
  EXPECT_EQ(c.bad_frame_weight, d.bad_frame_weight);
  EXPECT_EQ(c.max_delta_counter, d.max_delta_counter);
  EXPECT_EQ(c.stop_retry_ns, d.stop_retry_ns);
  EXPECT_EQ(c.status_period_ns, d.status_period_ns);
  EXPECT_EQ(c.heartbeat_period_ns, d.heartbeat_period_ns);
  EXPECT_EQ(c.posteriors_period_ns, d.posteriors_period_ns);
  EXPECT_DOUBLE_EQ(c.sample_period_s, d.sample_period_s);
  EXPECT_DOUBLE_EQ(c.acceleration_m_s2, d.acceleration_m_s2);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(c.mount.axis[k], d.mount.axis[k]);
    EXPECT_EQ(c.mount.sign[k], d.mount.sign[k]);
    EXPECT_EQ(c.mount.bias[k], d.mount.bias[k]);
  }
  std::vector<std::string> keys;
  for (const auto& e : others) keys.push_back(e.key);
  EXPECT_EQ(keys, (std::vector<std::string>{"interface", "model", "tick_ms", "rt_priority", "cpu", "mlock",
                                            "rt_required", "log_level"}));
}

TEST(CommandedTravel, TrapezoidProfile) {
  // 0.1 m/s at 1 m/s^2: ramp 0.1 s covering 5 mm, then 0.1 m/s.
  EXPECT_NEAR(commanded_travel(0.1, 1.0, 0.05), 0.00125, 1e-12);
  EXPECT_NEAR(commanded_travel(0.1, 1.0, 0.1), 0.005, 1e-12);
  EXPECT_NEAR(commanded_travel(0.1, 1.0, 6.0), 0.595, 1e-12);
}

TEST(RealTime, NoHeapAllocationPerSampleTickOrStop) {
  if (!testkit::malloc_intercepted()) GTEST_LOG_(INFO) << "malloc not intercepted (sanitizer build): counting operator new only";
  // Sink that stores into fixed arrays (as the daemon's does: a lock-free ring).
  struct FixedSink : PredictorSink {
    uint8_t transmit_stop(const Frame& f) noexcept override {
      last_stop = f;
      return 0;
    }
    uint8_t transmit(const Frame&) noexcept override { return 0; }
    void event(const Event& e) noexcept override {
      last = e;
      if (e.kind == EventKind::StopSent && e.reason == protocol::StopReason::StopUnconfirmed) ++refused;
    }
    Event last;
    Frame last_stop{};
    int refused = 0;
  } sink;
  model::OutcomeModel m = testkit::test_model();
  Predictor p(&m, PredictorConfig{}, sink);
  testkit::FrameSource src;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.5);
  // Frames are prepared before counting (the daemon reads them into a stack buffer).
  std::vector<Frame> frames;
  for (int trial = 0; trial < 10; ++trial) {
    frames.push_back(src.trial_start(static_cast<uint16_t>(trial)));
    for (int i = 0; i < 1000; ++i) {
      frames.push_back(src.force(trial % 2 ? -6.0 + noise(rng) : -2.0 + noise(rng), noise(rng)));
      if (i % 97 == 5) frames.back().data[5] ^= 1;  // corrupted frames take the error paths too
      frames.push_back(src.torque());
      src.next();
    }
    frames.push_back(src.trial_end(static_cast<uint16_t>(trial), 1000));
  }
  {
    // The counter itself works: one vector is at least one allocation.
    testkit::CountAllocations probe;
    std::vector<int> v(100);
    EXPECT_GE(probe.count(), 1u);
  }
  int64_t now = 0;
  uint64_t allocations = 0;
  {
    testkit::CountAllocations count;
    for (const Frame& f : frames) {
      p.on_frame(f, now += 5 * kMs);
      p.on_tick(now);
      p.on_stop_echo(f, now);               // not the stop frame: ignored
      p.on_stop_echo(sink.last_stop, now);  // the echo confirms: the next trial runs
    }
    p.on_shutdown(now);
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0u) << "the predictor allocated on its hot path";
  EXPECT_GE(p.counter(StatusCounter::Samples), 9000u);
  EXPECT_GE(p.counter(StatusCounter::Stops), 5u) << "the caught trials stopped (so the stop path was counted too)";
  EXPECT_EQ(sink.refused, 0) << "a trial was refused: a stop went unconfirmed though its echo came";
}

}  // namespace

// A TrialStart whose speed lies outside the model's training speed range (format version 3) by
// more than 5 mm/s is counted: a pull the model never saw. No count for a model that does not
// know its speeds. The trial runs as ever (nothing is stopped for it).
TEST(TrialSpeed, AStartOutsideTheTrainingSpeedsIsCounted) {
  Harness h;
  h.model.speed_min_m_s = 0.1;
  h.model.speed_max_m_s = 0.15;
  h.p = std::make_unique<Predictor>(&h.model, h.cfg, h.sink);
  uint16_t trial = 1;
  for (uint16_t speed : {100, 150, 95, 155, 120}) h.p->on_frame(h.src.trial_start(trial++, speed), h.now);
  EXPECT_EQ(h.p->trials_outside_training_speeds(), 0u);
  h.p->on_frame(h.src.trial_start(trial++, 156), h.now);
  EXPECT_EQ(h.p->trials_outside_training_speeds(), 1u);
  h.p->on_frame(h.src.trial_start(trial++, 94), h.now);
  EXPECT_EQ(h.p->trials_outside_training_speeds(), 2u);
  EXPECT_EQ(h.p->decision().state, protocol::PredictorState::InTrial);
  EXPECT_TRUE(h.sink.stops.empty());
  Harness unknown;
  unknown.p->on_frame(unknown.src.trial_start(1, 1000), unknown.now);
  EXPECT_EQ(unknown.p->trials_outside_training_speeds(), 0u);
}

// The start-up check of a model's sample period against the config's (format version 3): the
// same rate passes, another is refused and an unknown one is a warning; each message names the
// whole model path (a path of any length: it was formatted into a 512-byte buffer and cut) and
// both periods in milliseconds.
TEST(ModelPeriod, SameRatePassesAnotherIsRefusedUnknownIsAWarning) {
  model::OutcomeModel m = testkit::test_model();
  const std::string path = "/robot/models/" + std::string(600, 'm') + "/trained.dgm";
  const PeriodCheck unknown = check_model_period(m, path, 0.01);
  EXPECT_EQ(unknown.verdict, PeriodVerdict::Unknown);
  EXPECT_NE(unknown.message.find(path + " does not say"), std::string::npos) << unknown.message;
  EXPECT_NE(unknown.message.find("sample_period_ms 10 unchecked"), std::string::npos) << unknown.message;
  m.sample_period_s = 0.01;
  EXPECT_EQ(check_model_period(m, path, 0.01).verdict, PeriodVerdict::Same);
  EXPECT_EQ(check_model_period(m, path, 0.01 * (1 + 5e-7)).verdict, PeriodVerdict::Same);  // within 1e-6
  const PeriodCheck other = check_model_period(m, path, 0.008);
  EXPECT_EQ(other.verdict, PeriodVerdict::Differs);
  EXPECT_EQ(other.message.rfind(path + " was trained at a sample period of 10 ms, the config's sample_period_ms is 8:", 0),
            0u)
      << other.message;
}
