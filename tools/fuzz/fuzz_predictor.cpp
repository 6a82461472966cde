// libFuzzer target for the predictor's logic (predictor/core): arbitrary bus traffic, timer ticks,
// echoes, bus errors and failed transmissions (the byte format: traffic.h), under
// -fsanitize=fuzzer,address,undefined. Besides faults, it checks after every call the rules of
// predictor_core.h against a shadow of them written from that header, not from the code:
//
//   stop policy   an accepted sample beyond the hard limit on the motion or vertical axis
//                 stops in the same call; otherwise the robot stops on "caught" exactly when
//                 P(caught) > threshold for k consecutive samples; a tick stops exactly when
//                 no sample was accepted for longer than the sensor timeout; SIGTERM in a trial
//                 stops; a frame stops exactly when the bad-frame bucket (weight per corrupted,
//                 short or lost frame, lost trial frames aside, minus 1 per accepted sample,
//                 empty at a trial start) holds more than budget * weight; a stop decided by a
//                 force frame's lost samples names that frame's sample;
//   in a trial    no stop outside a trial, except a trial refused for want of a model or
//                 because the last stop waited stop_retry or more for its echo;
//   latch         a stop stays (state and reason) until a trial start, or a trial end once its
//                 stop frame is confirmed (or its confirmation after the trial end); a trial
//                 that ends rests in idle, or in fault without a model;
//   stop frame    every stop hands a stop frame to the sink in the same call, E2E-protected,
//                 with the decision's reason, trial and sample; an unconfirmed stop is resent
//                 by every tick at least stop_retry after the last send, and only within its
//                 own trial;
//   outputs       every other frame the predictor sends is E2E-protected and 8 bytes long;
//   logical time  a sample's index counts the lost frames (the protocol's E2E checker, run
//                 beside it, says how many); a timeout's is the sample that never came;
//   reports       the heartbeat with the state, the model, the trial and the seconds since
//                 the first frame or tick; status pages in turn, each with its two counters
//                 (saturating; samples modulo 65536) and the state; posteriors in 1/255 with
//                 the sample index;
//   counters      a force frame moves the status counters (corrupted, bad length, repeated,
//                 late, wrong sequence, lost frames, samples) as that checker's verdict says;
//   filter        posteriors in [0, 1], summing to 1;
//   real time     on_frame, on_tick, on_stop_echo, on_kernel_drops, on_bus_error and on_shutdown
//                 allocate nothing (every malloc and operator new, counted by the sanitizer's
//                 allocation hook).
//
// A broken rule prints which and aborts, which libFuzzer reports with the input that did it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <sanitizer/allocator_interface.h>

#include "dg_protocol.h"
#include "predictor_core.h"
#include "traffic.h"
#include "test_model.h"

using namespace dressguard;
using fuzz::broken;
using fuzz::counter_for;
using fuzz::damage;
using fuzz::is;
using fuzz::protected_as;
using fuzz::Reader;
using fuzz::TrafficOp;
using predictor::Predictor;
using protocol::Frame;
using protocol::MsgId;
using protocol::PredictorState;
using protocol::StatusCounter;
using protocol::StopReason;

namespace {

// The sink: records what the predictor sends, in fixed storage (the hot path must not see a
// sink that allocates either).
struct RecordingSink final : predictor::PredictorSink {
  int stop_sends = 0;       // transmit_stop calls in the current operation
  Frame first_stop;         // the current operation's first stop frame
  Frame last_stop;          // the last stop frame handed over
  int64_t last_stop_ns = 0;  // when (the harness's clock)
  int64_t now_ns = 0;
  int fail_next = 0;        // the next n stop transmissions fail
  bool bad_output = false;  // a frame that is not E2E-protected or not 8 bytes
  int status_sends = 0, post_sends = 0, hb_sends = 0;  // in the current operation
  Frame last_status{}, last_post{}, last_hb{};

  uint8_t transmit_stop(const Frame& f) noexcept override {
    if (stop_sends++ == 0) first_stop = f;
    last_stop = f;
    last_stop_ns = now_ns;
    if (f.id != protocol::id_of(MsgId::Stop) || !protected_as(f, MsgId::Stop)) bad_output = true;
    if (fail_next > 0) {
      --fail_next;
      return 1;
    }
    return 0;
  }
  uint8_t transmit(const Frame& f) noexcept override {
    MsgId m;
    switch (f.id) {
      case protocol::id_of(MsgId::PredictorStatus):
        m = MsgId::PredictorStatus;
        last_status = f;
        ++status_sends;
        break;
      case protocol::id_of(MsgId::Posteriors):
        m = MsgId::Posteriors;
        last_post = f;
        ++post_sends;
        break;
      case protocol::id_of(MsgId::HeartbeatPredictor):
        m = MsgId::HeartbeatPredictor;
        last_hb = f;
        ++hb_sends;
        break;
      default: bad_output = true; return 0;
    }
    if (!protected_as(f, m)) bad_output = true;
    return 0;
  }
  int dropped = 0;           // StopDropped events in the current operation
  predictor::Event last_dropped{};
  bool trial_ended = false;  // a TrialEnded event since the last trial start
  void event(const predictor::Event& e) noexcept override {
    if (e.kind == predictor::EventKind::TrialStarted) trial_ended = false;
    if (e.kind == predictor::EventKind::TrialEnded) trial_ended = true;
    if (e.kind != predictor::EventKind::StopDropped) return;
    ++dropped;
    last_dropped = e;
  }
};

// Allocations while a CountAllocations is open. The sanitizer's hook sees malloc and operator
// new alike (replacing operator new, as tests/predictor/alloc_counter.cpp does under GCC, trips
// ASan's start-up under libFuzzer). The harness is single-threaded.
long g_allocations = 0;
bool g_counting = false;
void on_malloc(const volatile void*, size_t) {
  if (g_counting) ++g_allocations;
}
void on_free(const volatile void*) {}

struct CountAllocations {
  long start = g_allocations;
  CountAllocations() { g_counting = true; }
  ~CountAllocations() { g_counting = false; }
  long count() const { return g_allocations - start; }
};

predictor::PredictorConfig config_from(const uint8_t* h) {
  predictor::PredictorConfig c;
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < 3; ++k) {
    c.mount.axis[k] = kPerm[h[1] % 6][k];
    c.mount.sign[k] = (h[1] >> (3 + k)) & 1 ? -1.0 : 1.0;
  }
  c.mount.bias[0] = static_cast<int8_t>(h[2]) * 0.05;
  c.mount.bias[2] = static_cast<int8_t>(h[3]) * 0.05;
  c.stop_threshold = h[4] == 0 ? -1.0 : 0.50 + (h[4] % 50) / 100.0;
  c.stop_consecutive = h[5] % 9;
  c.hard_limit_n = 2.0 + h[6] % 19;
  c.bad_frame_budget = 1 + h[7] % 8;
  c.bad_frame_weight = 1 + h[8] % 40;
  c.max_delta_counter = static_cast<uint8_t>(1 + h[9] % 5);
  c.sensor_timeout_ns = (10 + h[10] % 91) * 1'000'000LL;
  c.stop_retry_ns = (1 + h[11] % 10) * 1'000'000LL;
  c.status_period_ns = c.heartbeat_period_ns = c.posteriors_period_ns = (5 + h[12]) * 1'000'000LL;
  return c;
}

// The test model with "caught" moved to class index `caught_at`.
model::OutcomeModel model_with_caught_at(int caught_at) {
  model::OutcomeModel m = testkit::test_model();
  std::swap(m.classes[2], m.classes[caught_at]);
  return m;
}

// What the rules are judged against: the configuration as the predictor took it.
struct Rules {
  predictor::PredictorConfig cfg;
  bool has_model = false;
  double threshold = 0;
  int k = 0;
};

// The bridge's and the robot's alive counters, and the shadow of the predictor's state that the
// rules need, kept from the header's description alone.
struct Shadow {
  uint8_t c_force = 0, c_start = 0, c_end = 0, c_hb = 0;
  int64_t now = 1'000'000'000;
  int64_t last_accept_ns = 0;  // trial start or the last accepted sample in a trial
  int64_t stop_decided_ns = 0; // the latest stop's first transmission
  int64_t bucket = 0;          // the bad-frame budget's leaky bucket, from the trial start
  uint8_t next_page = 0;       // the status page due next
  int64_t clock_start = -1;    // the predictor's clock starts at its first frame or tick
  int run = 0;                 // consecutive samples with P(caught) > threshold
  // Logical time: sample 0 is the trial's first accepted sample, and lost frames count (the
  // protocol's own E2E checker, fed the same force frames, says how many were lost).
  protocol::E2EChecker e2e;
  uint32_t sample = 0;
  bool started = false;
  bool shut_down = false;      // SIGTERM came: every later trial is refused
  explicit Shadow(uint8_t max_delta) : e2e(MsgId::FtForce, max_delta) {}
};

// One operation: what was done, and the predictor's state just before.
struct Call {
  TrafficOp kind = TrafficOp::Tick;
  bool frame_sent = false, ticked = false, shut_down = false;
  Frame sent{};
  uint8_t echo_mode = 0;
  uint32_t e2e_lost = 0;   // the shadow checker's verdict on a force frame
  bool e2e_ok = false;
  protocol::E2EStatus e2e = protocol::E2EStatus::Ok;
  bool torque_first = false;  // the op sent the sample's torque frame before its force frame
  std::array<uint32_t, static_cast<int>(StatusCounter::Count)> counters_before{};
  predictor::Decision before;
  uint32_t starts_before = 0;
  long steps_before = 0;
  bool pending_before = false;
};

// How much a status counter moved in the call.
uint32_t moved(const Call& c, const Predictor& p, StatusCounter k) {
  return p.counter(k) - c.counters_before[static_cast<int>(k)];
}

// Reads one operation's frame or arguments, then makes the one predictor call (allocations
// counted). False when the input ends inside the operation.
bool run_one(Reader& in, Predictor& p, RecordingSink& sink, Shadow& sh, Call& c, long op) {
  const uint8_t opbyte = in.u8();
  c.kind = static_cast<TrafficOp>(opbyte & 0x0F);
  sh.now += (opbyte >> 4) * fuzz::kTrafficTimeUnitNs;
  sink.now_ns = sh.now;
  sink.stop_sends = sink.status_sends = sink.post_sends = sink.hb_sends = sink.dropped = 0;
  c.before = p.decision();
  c.starts_before = p.trials_started();
  c.steps_before = p.filter() ? p.filter()->samples() : 0;
  c.pending_before = p.stop_pending();
  for (int k = 0; k < static_cast<int>(StatusCounter::Count); ++k) c.counters_before[k] = p.counter(static_cast<StatusCounter>(k));

  switch (c.kind) {
    case TrafficOp::Force: {
      if (!in.take(7)) return false;
      const uint8_t ctl = in.u8();
      int16_t v[3];
      for (auto& x : v) x = in.i16();
      if (!(ctl & 0x10))
        for (auto& x : v) x = static_cast<int16_t>(static_cast<int8_t>(x & 0xFF) * 10);
      const uint8_t ctr = counter_for(ctl, sh.c_force, static_cast<uint8_t>(v[0]));
      c.torque_first = ctl & 0x80;
      if (ctl & 0x80) {  // the torque frame of the same sample, first
        const CountAllocations a;
        p.on_frame(protocol::encode(protocol::FtTorque{ctr, 0, 0, 0}), sh.now);
        if (a.count() != 0) broken("on_frame allocated (torque)", op);
      }
      c.sent = protocol::encode(protocol::FtForce{ctr, v[0], v[1], v[2]});
      damage(c.sent, ctl);
      c.frame_sent = true;
      break;
    }
    case TrafficOp::TrialStart: {
      if (!in.take(3)) return false;
      const uint8_t ctl = in.u8(), id = in.u8(), speed = in.u8();
      c.sent = protocol::encode(protocol::TrialStart{counter_for(ctl, sh.c_start, id), id,
                                                     static_cast<uint16_t>(50 + speed), protocol::HeightClass::Middle});
      damage(c.sent, ctl);
      c.frame_sent = true;
      break;
    }
    case TrafficOp::TrialEnd: {
      if (!in.take(2)) return false;
      const uint8_t ctl = in.u8(), id = in.u8();
      const uint16_t trial = id == 0 ? c.before.trial : id;
      c.sent = protocol::encode(protocol::TrialEnd{counter_for(ctl, sh.c_end, id), trial, 0,
                                                   protocol::TrialEndReason::Completed});
      damage(c.sent, ctl);
      c.frame_sent = true;
      break;
    }
    case TrafficOp::RawFrame: {
      if (!in.take(fuzz::kRawFrameBytes)) return false;
      c.sent = fuzz::raw_frame(in);
      c.frame_sent = true;
      break;
    }
    case TrafficOp::Heartbeat:
      c.sent = protocol::encode(protocol::HeartbeatBridge{++sh.c_hb, protocol::BridgeState::Ok, 0, 0, 0});
      c.frame_sent = true;
      break;
    case TrafficOp::StopEcho:
    case TrafficOp::KernelDrops:
    case TrafficOp::BusError:
    case TrafficOp::Wait:
    case TrafficOp::TxFail:
      if (!in.take(1)) return false;
      break;
    default: break;
  }
  if (c.frame_sent && is(c.sent, MsgId::FtForce)) {
    c.e2e = sh.e2e.check(c.sent, c.e2e_lost);
    c.e2e_ok = protocol::accepted(c.e2e);
  }

  const CountAllocations a;
  switch (c.kind) {
    case TrafficOp::Force:
    case TrafficOp::TrialStart:
    case TrafficOp::TrialEnd:
    case TrafficOp::RawFrame:
    case TrafficOp::Heartbeat: p.on_frame(c.sent, sh.now); break;
    case TrafficOp::StopEcho: {
      c.echo_mode = in.u8() % 3;
      Frame echo = sink.last_stop;
      if (c.echo_mode == 1) echo.data[1] ^= 0x01;
      if (c.echo_mode == 2) echo = protocol::encode(protocol::FtForce{0, 0, 0, 0});
      p.on_stop_echo(echo, sh.now);
      break;
    }
    case TrafficOp::KernelDrops: p.on_kernel_drops(p.counter(StatusCounter::KernelDrops) + in.u8(), sh.now); break;
    case TrafficOp::BusError: p.on_bus_error(in.u8(), sh.now); break;
    case TrafficOp::Shutdown: p.on_shutdown(sh.now), c.shut_down = sh.shut_down = true; break;
    case TrafficOp::Wait:
      sh.now += in.u8() * 1'000'000LL;
      sink.now_ns = sh.now;
      p.on_tick(sh.now), c.ticked = true;
      break;
    case TrafficOp::TxFail: sink.fail_next = in.u8() % 8; break;
    default: p.on_tick(sh.now), c.ticked = true; break;
  }
  if (a.count() != 0) broken("a real-time call allocated", op);
  return true;
}

// Outputs and filter: every frame protected; the posteriors a distribution over the classes.
void check_outputs(const Predictor& p, const RecordingSink& sink, long op) {
  if (sink.bad_output) broken("a frame sent without E2E protection or of the wrong length or identifier", op);
  if (const auto* f = p.filter()) {
    double s = 0;
    for (int c = 0; c < f->classes(); ++c) {
      const double q = f->posterior(c);
      if (!(q >= 0.0 && q <= 1.0)) broken("a posterior outside [0, 1]", op);
      s += q;
    }
    if (std::fabs(s - 1.0) > 1e-9) broken("the posteriors do not sum to 1", op);
  }
}

// Trial start: the shadow restarts; with a model the trial runs, unless the last stop was never
// confirmed; without a model it is refused.
void check_trial_start(const Call& c, const Predictor& p, const RecordingSink& sink, const Rules& r, Shadow& sh,
                       long op) {
  protocol::TrialStart m;
  if (!protocol::decode(c.sent, m) || p.decision().trial != m.trial_id) broken("the decision's trial is not the start frame's", op);
  sh.last_accept_ns = sh.now;
  sh.run = 0;
  sh.e2e.reset();
  sh.sample = 0;
  sh.started = false;
  const predictor::Decision& d = p.decision();
  // The last stop unconfirmed for a retry period or more: the stop socket cannot send.
  const bool unconfirmed = c.pending_before && sh.now - sh.stop_decided_ns >= r.cfg.stop_retry_ns;
  if (sh.shut_down) {
    if (d.state != PredictorState::Stopped || d.reason != StopReason::Shutdown)
      broken("a trial start after SIGTERM was not refused with shutdown", op);
  } else if (r.has_model && !unconfirmed && d.state != PredictorState::InTrial)
    broken("a trial start with a model did not run the trial", op);
  if (!sh.shut_down && r.has_model && unconfirmed && (d.state != PredictorState::Stopped || d.reason != StopReason::StopUnconfirmed))
    broken("a trial start with the last stop unconfirmed was not refused with stop_unconfirmed", op);
  if (!sh.shut_down && !r.has_model && (d.state != PredictorState::Stopped || d.reason != StopReason::ModelError))
    broken("a trial start without a model was not refused", op);
  // A younger pending stop is dropped, and says so once, naming the finished trial.
  if (unconfirmed && sink.dropped != 0) broken("a stale stop was reported dropped, not refused", op);
  if (c.pending_before && !unconfirmed && sink.dropped != 1) broken("a young pending stop was dropped silently", op);
  if (sink.dropped > 1) broken("one dropped stop was reported twice", op);
  if (sink.dropped == 1 && sink.last_dropped.trial != c.before.trial) broken("the dropped stop names another trial", op);
  // The start frame decides no stop for the trial before it (its lost predecessors are not
  // charged): a stop sent after the start was on the bus would latch the new trial.
  protocol::Stop first{};
  if (sink.stop_sends > 0 && protocol::decode(sink.first_stop, first) && first.trial_id != m.trial_id)
    broken("a trial start sent a stop for the trial before it", op);
}

// No stop outside a trial; the latch; and the stop frame of a new stop.
void check_stop_state(const Call& c, const Predictor& p, const RecordingSink& sink, bool started, long op) {
  const predictor::Decision& d = p.decision();
  const bool stopped_now = c.before.state != PredictorState::Stopped && d.state == PredictorState::Stopped;
  if (stopped_now && c.before.state != PredictorState::InTrial && !started) broken("a stop outside a trial", op);
  // Latch: out of Stopped only by a trial start, or a trial end after the stop was confirmed, or
  // the confirmation after the trial end; at rest then (fault without a model).
  const PredictorState rest = p.filter() ? PredictorState::Idle : PredictorState::Fault;
  if (c.before.state == PredictorState::Stopped && !started) {
    const bool ended_clean = c.frame_sent && is(c.sent, MsgId::TrialEnd) && d.state == rest && !p.stop_pending();
    const bool confirmed_after_end = c.kind == TrafficOp::StopEcho && sink.trial_ended && d.state == rest &&
                                     c.pending_before && !p.stop_pending();
    if (d.state != PredictorState::Stopped && !ended_clean && !confirmed_after_end)
      broken("a stop was released without a trial start or end", op);
    if (d.state == PredictorState::Stopped && sink.trial_ended && !p.stop_pending())
      broken("a confirmed stop outlived its trial's end", op);
    if (d.state == PredictorState::Stopped && d.reason != c.before.reason) broken("a latched stop changed its reason", op);
  }
  // The stop frame: handed over in the same call, saying what the decision says.
  if (stopped_now) {
    if (sink.stop_sends == 0) broken("a stop with no stop frame", op);
    protocol::Stop m;
    if (!protocol::decode(sink.last_stop, m)) broken("the stop frame does not decode", op);
    if (m.reason != d.reason || m.trial_id != d.trial || m.sample != static_cast<uint16_t>(d.stop_sample))
      broken("the stop frame does not carry the decision's reason, trial and sample", op);
    if (d.reason == StopReason::None) broken("a stop without a reason", op);
  }
}

// A force frame in a trial: E2E as the protocol says, logical time, the hard limit, then the
// k-sample rule.
void check_sample(const Call& c, const Predictor& p, const Rules& r, Shadow& sh, long op) {
  const predictor::Decision& d = p.decision();
  const bool bad_frame_stop = d.state == PredictorState::Stopped && d.reason == StopReason::BadFrames;
  const bool accepted = moved(c, p, StatusCounter::Samples) != 0;
  const bool stepped = p.filter() && p.filter()->samples() != c.steps_before;
  if (accepted && !stepped && !bad_frame_stop) broken("an accepted sample in a trial did not reach the filter", op);
  // A bad-frames stop that this accepted frame's lost samples decided names this frame's sample.
  // (Not when the sample's torque frame came first: its own losses may have decided.)
  if (accepted && !stepped && bad_frame_stop && !c.torque_first &&
      d.stop_sample != (sh.started ? sh.sample + 1 + c.e2e_lost : 0))
    broken("a bad-frames stop decided by lost samples does not name the sample that decided", op);
  if (!accepted && d.state != PredictorState::InTrial && !bad_frame_stop)
    broken("a rejected frame changed the trial's state other than by the bad-frame budget", op);
  if (accepted != c.e2e_ok) broken("the sample's E2E verdict is not the protocol's", op);
  if (accepted) sh.last_accept_ns = sh.now;
  if (!stepped) return;

  if (sh.started) sh.sample += 1 + c.e2e_lost;
  sh.started = true;
  if (d.sample != sh.sample) broken("the sample index is not the trial's logical time", op);
  protocol::FtForce m;
  protocol::decode(c.sent, m);
  const double fs[3] = {protocol::force_newtons(m.fx), protocol::force_newtons(m.fy), protocol::force_newtons(m.fz)};
  double rig[3];
  for (int k = 0; k < 3; ++k) rig[k] = r.cfg.mount.sign[k] * fs[r.cfg.mount.axis[k]] - r.cfg.mount.bias[k];
  if (std::fabs(rig[0]) > r.cfg.hard_limit_n || std::fabs(rig[2]) > r.cfg.hard_limit_n) {
    if (d.state != PredictorState::Stopped || d.reason != StopReason::HardLimit)
      broken("a sample beyond the hard limit did not stop with reason hard_limit", op);
    return;
  }
  sh.run = p.filter()->posterior(p.caught_class()) > r.threshold ? sh.run + 1 : 0;
  const bool should = sh.run >= r.k;
  const bool did = d.state == PredictorState::Stopped && d.reason == StopReason::Caught;
  if (should != did) broken(should ? "k samples over the threshold did not stop" : "a caught stop before k samples over the threshold", op);
}

// The status counters of a force frame (alone in its call): each counts what the protocol's E2E
// checker, run beside the predictor, says of it, and nothing else moves.
void check_force_counters(const Call& c, const Predictor& p, long op) {
  using S = protocol::E2EStatus;
  const auto delta = [&](StatusCounter k) { return moved(c, p, k); };
  const bool lost = c.e2e == S::OkSomeLost || c.e2e == S::WrongSequence;
  if (delta(StatusCounter::Corrupted) != (c.e2e == S::Corrupted) || delta(StatusCounter::BadLength) != (c.e2e == S::BadLength) ||
      delta(StatusCounter::Repeated) != (c.e2e == S::Repeated) || delta(StatusCounter::Late) != (c.e2e == S::Late) ||
      delta(StatusCounter::WrongSequence) != (c.e2e == S::WrongSequence) ||
      delta(StatusCounter::LostFrames) != (lost ? c.e2e_lost : 0u) || delta(StatusCounter::Samples) != (c.e2e_ok ? 1u : 0u))
    broken("a force frame's status counters are not what the protocol's E2E check says of it", op);
}

// The bad-frame budget (a leaky bucket): every charged frame adds the weight, every sample
// accepted in a running trial drains 1, and a running trial stops the moment the bucket holds
// more than budget * weight; a trial start empties it.
void check_bucket(const Call& c, const Predictor& p, const Rules& r, Shadow& sh, bool started, long op) {
  // Charged: corrupted frames, frames of a bad length and lost frames, of any stream the
  // predictor checks (its own counters say how many), except the sporadic trial frames' losses.
  const bool trial_frame = is(c.sent, MsgId::TrialStart) || is(c.sent, MsgId::TrialEnd);
  const uint32_t charged = moved(c, p, StatusCounter::Corrupted) + moved(c, p, StatusCounter::BadLength) +
                           (trial_frame ? 0u : moved(c, p, StatusCounter::LostFrames));
  sh.bucket += static_cast<int64_t>(charged) * r.cfg.bad_frame_weight;
  if (started) {
    sh.bucket = 0;
    return;
  }
  const predictor::Decision& d = p.decision();
  const bool running = c.before.state == PredictorState::InTrial;
  const bool over = running && sh.bucket > static_cast<int64_t>(r.cfg.bad_frame_budget) * r.cfg.bad_frame_weight;
  const bool did = running && d.state == PredictorState::Stopped && d.reason == StopReason::BadFrames;
  if (over != did) broken(over ? "bad frames over the budget did not stop" : "a bad-frames stop within the budget", op);
  const bool accepted = moved(c, p, StatusCounter::Samples) != 0;
  if (running && !over && accepted && sh.bucket > 0) --sh.bucket;
}

// What a tick reports: the heartbeat (state, model, trial, seconds since the clock started); the
// status pages in turn, each with its two counters (saturating at 65535, the sample count modulo
// 65536) and the state; the posteriors in 1/255 with the sample.
void check_reports(const Predictor& p, const RecordingSink& sink, const Rules& r, Shadow& sh, long op) {
  const predictor::Decision& d = p.decision();
  if (sink.hb_sends > 0) {
    protocol::HeartbeatPredictor m;
    protocol::decode(sink.last_hb, m);
    const int64_t up = (sh.now - sh.clock_start) / 1'000'000'000;
    if (m.state != d.state || m.model_loaded != (r.has_model ? 1 : 0) || m.trial_id != d.trial ||
        m.uptime_s != std::min<int64_t>(up, 0xFFFF))
      broken("the heartbeat does not carry the state, the model, the trial and the seconds since start", op);
  }
  if (sink.status_sends > 0) {
    protocol::PredictorStatus m;
    protocol::decode(sink.last_status, m);
    if (m.page != sh.next_page) broken("the status pages are not sent in turn", op);
    sh.next_page = static_cast<uint8_t>((m.page + 1) % protocol::kStatusPages);
    const auto sat = [](uint32_t v) { return static_cast<uint16_t>(std::min<uint32_t>(v, 0xFFFF)); };
    const uint32_t v0 = p.counter(static_cast<StatusCounter>(2 * m.page)), v1 = p.counter(static_cast<StatusCounter>(2 * m.page + 1));
    const uint16_t e0 = 2 * m.page == static_cast<int>(StatusCounter::Samples) ? static_cast<uint16_t>(v0) : sat(v0);
    if (m.value0 != e0 || m.value1 != sat(v1) || m.state != d.state) broken("a status page does not carry its two counters and the state", op);
  }
  if (sink.post_sends > 0 && p.filter()) {
    protocol::Posteriors m;
    protocol::decode(sink.last_post, m);
    if (m.sample != static_cast<uint16_t>(d.sample) || m.state != d.state) broken("the posteriors frame does not carry the sample and the state", op);
    for (int k = 0; k < p.filter()->classes() && k < 3; ++k)
      if (m.p[k] != std::lround(p.filter()->posterior(k) * 255.0)) broken("the posteriors frame is not the filter's posteriors in 1/255", op);
  }
}

// A tick: the sensor deadline, exactly; an unconfirmed stop resent on time; nothing else.
void check_tick(const Call& c, const Predictor& p, const RecordingSink& sink, const Rules& r, const Shadow& sh, long op) {
  const predictor::Decision& d = p.decision();
  if (c.before.state == PredictorState::InTrial) {
    const bool late = sh.now - sh.last_accept_ns > r.cfg.sensor_timeout_ns;
    const bool did = d.state == PredictorState::Stopped && d.reason == StopReason::SensorTimeout;
    if (late != did) broken(late ? "no sample for longer than the timeout did not stop" : "a timeout stop before the deadline", op);
    // The deciding "sample" of a timeout is the one that never came.
    if (did && d.stop_sample != sh.sample + (sh.started ? 1 : 0)) broken("a timeout stop's sample is not the one that never came", op);
  }
  if (p.stop_pending() && sh.now - sink.last_stop_ns >= r.cfg.stop_retry_ns) broken("an unconfirmed stop was not resent", op);
  // A retry says what the decision says: a stop never confirmed is not carried into the next trial.
  if (sink.stop_sends > 0) {
    protocol::Stop m;
    protocol::decode(sink.last_stop, m);
    if (m.trial_id != d.trial || m.reason != d.reason) broken("a stop resent that is not the decision's (another trial's?)", op);
  }
  if (d.state != c.before.state && d.reason != StopReason::SensorTimeout)
    broken("a tick changed the state other than by the sensor timeout", op);
}

// The calls that carry no frame and no tick: the echo, SIGTERM, drops, bus errors.
void check_quiet_call(const Call& c, const Predictor& p, const RecordingSink& sink, long op) {
  const predictor::Decision& d = p.decision();
  // The echo of the stop frame last sent confirms it; nothing else does.
  if (c.kind == TrafficOp::StopEcho && c.pending_before) {
    if (c.echo_mode == 0 && p.stop_pending()) broken("the stop frame's own echo did not confirm it", op);
    if (c.echo_mode != 0 && !p.stop_pending()) broken("another frame confirmed the stop", op);
  }
  const bool was_in = c.before.state == PredictorState::InTrial;
  if (c.shut_down && was_in && (d.state != PredictorState::Stopped || d.reason != StopReason::Shutdown))
    broken("SIGTERM in a trial did not stop with reason shutdown", op);
  // Or the echo that confirms a stop after its trial's end, which rests the predictor (the
  // latch rule checks that).
  const bool rested = c.kind == TrafficOp::StopEcho && sink.trial_ended && c.before.state == PredictorState::Stopped;
  if (!(c.shut_down && was_in) && !rested && d.state != c.before.state)
    broken("a call that carries no frame changed the state", op);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < static_cast<size_t>(fuzz::kTrafficHeader)) return 0;
  const uint8_t* h = data;
  Reader in{data + fuzz::kTrafficHeader, size - fuzz::kTrafficHeader};

  Rules r;
  r.cfg = config_from(h);
  r.has_model = h[0] % 8 != 0;
  const int caught_at = (h[0] / 8) % 3;
  const model::OutcomeModel model = model_with_caught_at(caught_at);
  RecordingSink sink;
  Predictor p(r.has_model ? &model : nullptr, r.cfg, sink);
  if (r.has_model && p.caught_class() != caught_at) broken("the caught class is not the model's 'caught'", -1);
  r.threshold = p.threshold();
  r.k = p.consecutive();
  if (r.cfg.stop_threshold > 0 && r.threshold != r.cfg.stop_threshold) broken("the config's threshold is not used", -1);
  if (r.cfg.stop_consecutive > 0 && r.k != r.cfg.stop_consecutive) broken("the config's k is not used", -1);

  Shadow sh(r.cfg.max_delta_counter);
  for (long op = 0; in.take(1); ++op) {
    Call c;
    if (!run_one(in, p, sink, sh, c, op)) break;
    const bool started = p.trials_started() != c.starts_before;
    if (sh.clock_start < 0 && (c.frame_sent || c.ticked)) sh.clock_start = sh.now;
    check_outputs(p, sink, op);
    if (started) check_trial_start(c, p, sink, r, sh, op);
    if (!started && sink.dropped != 0) broken("a stop was dropped without a trial start", op);
    check_stop_state(c, p, sink, started, op);
    const bool force = c.frame_sent && is(c.sent, MsgId::FtForce);
    if (force && !started && c.before.state == PredictorState::InTrial) check_sample(c, p, r, sh, op);
    if (force && c.before.state != PredictorState::InTrial && p.decision().state != c.before.state)
      broken("a force frame outside a trial changed the state", op);
    if (c.ticked) check_tick(c, p, sink, r, sh, op);
    if (c.ticked) check_reports(p, sink, r, sh, op);
    if (c.frame_sent) check_bucket(c, p, r, sh, started, op);
    if (force && !c.torque_first) check_force_counters(c, p, op);
    const bool new_stop = p.decision().state == PredictorState::Stopped && (c.before.state != PredictorState::Stopped || started);
    if (new_stop) sh.stop_decided_ns = sh.now;
    if (!c.frame_sent && !c.ticked) check_quiet_call(c, p, sink, op);
  }
  return 0;
}
