// libFuzzer target for the firmware bridge's portable core (firmware-bridge/core): arbitrary
// sensor readings and read errors, bus frames and ticks of a millisecond clock that may wrap
// (the byte format: traffic.h), under -fsanitize=fuzzer,address,undefined. After every call it
// checks the rules of bridge_core.h against a shadow of them written from that header:
//
//   samples     a reading becomes one FtForce and one FtTorque frame, E2E-protected, with the
//               reading's counts and one alive counter that counts sample periods: it advances
//               by one per reading plus one per failed read and per period missed (the port's
//               timer overran) since the last reading, those at most kMaxPeriodsMissed;
//   stop        a Stop frame with a valid CRC latches the stop (a repeated one too: a stop is
//               never dropped for its counter), and asks the robot to stop exactly when it
//               was not latched; a corrupted or short one changes nothing;
//   release     only a TrialStart that its E2E check accepts releases the latch, and only once
//               the port has written the stop (bridge_on_stop_written);
//   resync      a TrialStart or TrialEnd after more than protocol::kSporadicResyncMs without
//               either, and a predictor heartbeat that long after the last accepted one, start
//               their E2E checks afresh (a restarted sender counts from 0);
//   silence     with a predictor timeout, a tick latches the stop exactly when the predictor's
//               heartbeat (E2E-accepted) is older than the timeout, wrap-safe;
//   guard       else, with a predictor timeout, a tick latches the stop exactly when a trial runs
//               (an accepted TrialStart, until an accepted TrialEnd of its id) and the
//               predictor's accepted heartbeats have not named it, in trial or stopped, since
//               the start or since the first one that stopped naming it, longer than the
//               timeout;
//   heartbeat   sent on the tick when due (period from the last one, wrap-safe), E2E-protected,
//               carrying the state: StopLatched while latched, else SensorLost after a failed
//               read until the next reading, else Ok; the failed reads (saturating at 255),
//               the reconnects (at 65535) and the whole seconds since start, across the wrap.
//
// A broken rule prints which and aborts, which libFuzzer reports with the input that did it.
#include <algorithm>
#include <cstdint>

#include "bridge_core.h"
#include "dg_protocol.h"
#include "traffic.h"

using namespace dressguard;
using bridge::BridgeAction;
using bridge::BridgeCore;
using fuzz::BridgeOp;
using fuzz::broken;
using fuzz::counter_for;
using fuzz::damage;
using fuzz::is;
using fuzz::protected_as;
using fuzz::Reader;
using protocol::BridgeState;
using protocol::Frame;
using protocol::MsgId;

namespace {

// The shadow: the senders' counters and what the header's rules need to know.
struct Shadow {
  uint32_t now = 0;
  uint8_t c_stop = 0, c_trial = 0, c_phb = 0;  // the predictor's and the robot's senders
  uint8_t c_hb = 0;                            // the bridge's heartbeat, as last received
  bool latched = false;
  bool written = false;     // the latched stop was written (StopWritten)
  bool sensor_lost = true;  // until the first reading
  uint8_t next_sample = 0;      // the next reading's counter with no period missed before it
  uint32_t periods_missed = 0;  // failed reads and missed periods since the last reading, unbounded
  uint32_t last_predictor = 0;
  protocol::PredictorState predictor_state = protocol::PredictorState::Idle;  // last accepted heartbeat's
  uint32_t last_trial = 0;  // the last TrialStart or TrialEnd frame, accepted or not
  uint8_t c_end = 0;        // the robot's TrialEnd sender
  bool trial_running = false;
  uint16_t trial_id = 0;
  bool guarded = false;
  uint32_t unguarded_since = 0;
  uint32_t next_heartbeat = 0;
  uint32_t start = 0;
  uint32_t sensor_errors = 0, reconnects = 0;  // counted without bound
  protocol::E2EChecker trial_e2e{MsgId::TrialStart, 255};
  protocol::E2EChecker end_e2e{MsgId::TrialEnd, 255};
  protocol::E2EChecker hb_e2e{MsgId::HeartbeatPredictor, 255};
};

BridgeState expected_state(const Shadow& sh) {
  return sh.latched ? BridgeState::StopLatched : sh.sensor_lost ? BridgeState::SensorLost : BridgeState::Ok;
}

// A reading: two frames with the reading's counts and one counter, advanced by one and by the
// periods missed since the last reading (at most kMaxPeriodsMissed).
void reading(Reader& in, BridgeCore& c, Shadow& sh, long op) {
  bridge::FtReading r;
  for (auto& v : r.force) v = in.i16();
  for (auto& v : r.torque) v = in.i16();
  Frame out[2];
  if (bridge::bridge_on_reading(c, r, sh.now, out) != 2) broken("a reading did not give two frames", op);
  protocol::FtForce f;
  protocol::FtTorque t;
  if (!protected_as(out[0], MsgId::FtForce) || !protected_as(out[1], MsgId::FtTorque) || !protocol::decode(out[0], f) ||
      !protocol::decode(out[1], t))
    broken("a sample frame is not an E2E-protected FtForce / FtTorque", op);
  if (f.fx != r.force[0] || f.fy != r.force[1] || f.fz != r.force[2] || t.mx != r.torque[0] || t.my != r.torque[1] ||
      t.mz != r.torque[2])
    broken("a sample frame does not carry the reading's counts", op);
  if (f.counter != t.counter) broken("the force and torque frames of one reading carry different counters", op);
  const uint32_t skipped = std::min(sh.periods_missed, bridge::kMaxPeriodsMissed);
  if (f.counter != static_cast<uint8_t>(sh.next_sample + skipped))
    broken("the sample counter did not advance by one and the periods missed since the last reading", op);
  sh.next_sample = static_cast<uint8_t>(f.counter + 1);
  sh.periods_missed = 0;
  sh.sensor_lost = false;
}

// A Stop frame: a valid CRC latches; the robot is asked to stop when it was not latched before.
void stop_frame(const Frame& f, BridgeCore& c, Shadow& sh, long op) {
  const bool valid = f.len == protocol::kFrameLength && f.data[0] == protocol::e2e_crc(protocol::data_id_of(MsgId::Stop), f.data);
  const BridgeAction a = bridge::bridge_on_frame(c, f, sh.now);
  const bool asks = a == BridgeAction::StopRobot;
  if (valid && asks != !sh.latched) broken(sh.latched ? "a stop asked again while latched" : "a valid stop frame did not stop the robot", op);
  if (!valid && asks) broken("a corrupted or short stop frame stopped the robot", op);
  if (asks) sh.written = false;
  if (valid) sh.latched = true;
  if (bridge::bridge_stop_latched(c) != sh.latched) broken(valid ? "a valid stop frame did not latch" : "a corrupted or short stop frame changed the latch", op);
}

// Wrap-safe: more than protocol::kSporadicResyncMs since `then`.
bool resyncs(const Shadow& sh, uint32_t then) {
  return static_cast<uint32_t>(sh.now - then) > protocol::kSporadicResyncMs;
}

// Any other frame: a TrialStart accepted by its E2E check releases a written latch (and then
// clears the robot's stop) and starts a trial, an accepted TrialEnd of its id ends it; a predictor heartbeat accepted by its check
// restarts the silence clock and says whether the trial is guarded; nothing asks for a stop.
void other_frame(const Frame& f, BridgeCore& c, Shadow& sh, long op) {
  uint32_t lost = 0;
  if (is(f, MsgId::TrialStart) || is(f, MsgId::TrialEnd)) {
    if (resyncs(sh, sh.last_trial)) {
      sh.trial_e2e.reset();
      sh.end_e2e.reset();
    }
    sh.last_trial = sh.now;
  }
  if (is(f, MsgId::HeartbeatPredictor) && resyncs(sh, sh.last_predictor)) sh.hb_e2e.reset();
  const bool trial_ok = is(f, MsgId::TrialStart) && protocol::accepted(sh.trial_e2e.check(f, lost));
  const bool end_ok = is(f, MsgId::TrialEnd) && protocol::accepted(sh.end_e2e.check(f, lost));
  const bool hb_ok = is(f, MsgId::HeartbeatPredictor) && protocol::accepted(sh.hb_e2e.check(f, lost));
  const BridgeAction a = bridge::bridge_on_frame(c, f, sh.now);
  if (a == BridgeAction::StopRobot) broken("a frame other than a stop stopped the robot", op);
  if (trial_ok && (!sh.latched || sh.written)) sh.latched = false;
  // The robot's stop target mirrors the latch: cleared by an accepted TrialStart that leaves
  // none, and by nothing else.
  const bool clears = trial_ok && !sh.latched;
  if ((a == BridgeAction::ReleaseRobot) != clears)
    broken(clears ? "a trial start that left no stop latched did not clear the robot's stop"
                  : "the robot's stop was cleared with a stop latched or without an accepted trial start", op);
  if (protocol::TrialStart m; trial_ok && protocol::decode(f, m)) {
    sh.trial_running = true;
    sh.trial_id = m.trial_id;
    sh.guarded = false;
    sh.unguarded_since = sh.now;
  }
  if (protocol::TrialEnd m; end_ok && protocol::decode(f, m) && m.trial_id == sh.trial_id) sh.trial_running = false;
  if (hb_ok) {
    sh.last_predictor = sh.now;
    if (protocol::HeartbeatPredictor m; protocol::decode(f, m)) {
      sh.predictor_state = m.state;
      const bool guards = m.trial_id == sh.trial_id && (m.state == protocol::PredictorState::InTrial ||
                                                        m.state == protocol::PredictorState::Stopped);
      if (sh.trial_running && !guards && sh.guarded) sh.unguarded_since = sh.now;
      if (sh.trial_running) sh.guarded = guards;
    }
  }
  if (c.trial_running != sh.trial_running || (sh.trial_running && c.trial_guarded != sh.guarded))
    broken("the running trial, or whether the predictor guards it, is not the frames'", op);
  if (bridge::bridge_stop_latched(c) != sh.latched)
    broken(!trial_ok ? "a frame other than a stop or a trial start changed the latch"
           : sh.latched ? "an accepted trial start released a stop not yet written"
                        : "an accepted trial start did not release the latch", op);

}

// A tick: the predictor's silence or a trial it does not guard, then the heartbeat when due.
void tick(BridgeCore& c, Shadow& sh, long op) {
  const uint32_t timeout = c.cfg.predictor_timeout_ms;
  const bool watched = timeout > 0 && !sh.latched;
  const bool silent = watched && static_cast<uint32_t>(sh.now - sh.last_predictor) > timeout;
  const bool unguarded = watched && !silent && sh.trial_running && !sh.guarded &&
                         static_cast<uint32_t>(sh.now - sh.unguarded_since) > timeout;
  const bool due = static_cast<int32_t>(sh.now - sh.next_heartbeat) >= 0;
  Frame hb;
  BridgeAction a = BridgeAction::None;
  const int n = bridge::bridge_on_tick(c, sh.now, &hb, &a);
  if ((a == BridgeAction::StopRobot) != (silent || unguarded))
    broken(silent      ? "a silent predictor did not stop the robot"
           : unguarded ? "a trial the predictor did not guard did not stop the robot"
                       : "a tick stopped the robot with the predictor heard and guarding", op);
  if (silent || unguarded) {
    sh.latched = true;
    sh.written = false;
    const auto want = silent ? bridge::StopCause::PredictorSilent : bridge::StopCause::TrialUnguarded;
    if (c.stop_cause != want) broken("a tick's stop has the wrong cause", op);
  }
  if (bridge::bridge_stop_latched(c) != sh.latched)
    broken("a tick changed the latch other than for the predictor's silence or an unguarded trial", op);
  if ((n == 1) != due) broken(due ? "a heartbeat due was not sent" : "a heartbeat before it was due", op);
  if (n != 1) return;
  sh.next_heartbeat = sh.now + c.cfg.heartbeat_period_ms;
  protocol::HeartbeatBridge m;
  if (!protected_as(hb, MsgId::HeartbeatBridge) || !protocol::decode(hb, m)) broken("the heartbeat is not an E2E-protected HeartbeatBridge", op);
  if (m.counter != ++sh.c_hb) broken("the heartbeat counter did not advance by one", op);
  if (m.state != expected_state(sh)) broken("the heartbeat's state is not the bridge's", op);
  if (m.sensor_errors != std::min<uint32_t>(sh.sensor_errors, 255)) broken("the heartbeat's sensor errors are not the failed reads (saturating)", op);
  if (m.reconnects != std::min<uint32_t>(sh.reconnects, 0xFFFF)) broken("the heartbeat's reconnects are not the reconnects", op);
  if (m.uptime_s != std::min<uint32_t>((sh.now - sh.start) / 1000, 0xFFFF)) broken("the heartbeat's uptime is not the seconds since start", op);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < static_cast<size_t>(fuzz::kBridgeHeader)) return 0;
  const uint8_t* h = data;
  Reader in{data + fuzz::kBridgeHeader, size - fuzz::kBridgeHeader};
  bridge::BridgeConfig cfg;
  cfg.predictor_timeout_ms = h[0] < 64 ? 0 : 10 + h[0] % 200;
  cfg.heartbeat_period_ms = 1 + h[1];
  Shadow sh;
  sh.now = static_cast<uint32_t>(h[2] | h[3] << 8 | h[4] << 16 | static_cast<uint32_t>(h[5]) << 24);
  sh.last_predictor = sh.last_trial = sh.next_heartbeat = sh.start = sh.now;
  sh.c_hb = 0xFF;  // one before the first heartbeat's counter (protocol::AliveCounter starts at 0)
  BridgeCore c;
  bridge::bridge_init(c, cfg, sh.now);

  for (long op = 0; in.take(1); ++op) {
    const uint8_t opbyte = in.u8();
    const auto kind = static_cast<BridgeOp>(opbyte & 0x0F);
    sh.now += (opbyte >> 4) * fuzz::kBridgeTimeUnitMs;
    switch (kind) {
      case BridgeOp::Reading:
        if (!in.take(12)) return 0;
        reading(in, c, sh, op);
        break;
      case BridgeOp::SensorError:
        bridge::bridge_on_sensor_error(c, sh.now);
        sh.sensor_lost = true;
        ++sh.sensor_errors;
        ++sh.periods_missed;
        break;
      case BridgeOp::PeriodsMissed: {
        if (!in.take(1)) return 0;
        const uint8_t periods = in.u8();
        bridge::bridge_on_periods_missed(c, periods);
        sh.periods_missed += periods;
        if (bridge::bridge_state(c) != expected_state(sh)) broken("missed periods changed the bridge's state", op);
        break;
      }
      case BridgeOp::Reconnect:
        bridge::bridge_on_reconnect(c);
        ++sh.reconnects;
        break;
      case BridgeOp::Stop: {
        if (!in.take(3)) return 0;
        const uint8_t ctl = in.u8(), reason = in.u8(), trial = in.u8();
        Frame f = protocol::encode(protocol::Stop{counter_for(ctl, sh.c_stop, trial), static_cast<protocol::StopReason>(reason % 8),
                                                  static_cast<uint8_t>(reason), trial, 0});
        damage(f, ctl);
        stop_frame(f, c, sh, op);
        break;
      }
      case BridgeOp::TrialStart: {
        if (!in.take(2)) return 0;
        const uint8_t ctl = in.u8(), trial = in.u8();
        Frame f = protocol::encode(protocol::TrialStart{counter_for(ctl, sh.c_trial, trial), trial, 100, protocol::HeightClass::Middle});
        damage(f, ctl);
        other_frame(f, c, sh, op);
        break;
      }
      case BridgeOp::PredictorHeartbeat: {
        if (!in.take(2)) return 0;
        const uint8_t ctl = in.u8(), trial = in.u8();
        const auto state = static_cast<protocol::PredictorState>((ctl >> 4 & 1) | (ctl >> 6 & 2));
        Frame f = protocol::encode(protocol::HeartbeatPredictor{counter_for(ctl, sh.c_phb, ctl), state, 1, trial, 0});
        damage(f, ctl);
        other_frame(f, c, sh, op);
        break;
      }
      case BridgeOp::TrialEnd: {
        if (!in.take(2)) return 0;
        const uint8_t ctl = in.u8(), trial = in.u8();
        Frame f = protocol::encode(protocol::TrialEnd{counter_for(ctl, sh.c_end, trial), trial, 0, protocol::TrialEndReason::Completed});
        damage(f, ctl);
        other_frame(f, c, sh, op);
        break;
      }
      case BridgeOp::RawFrame: {
        if (!in.take(fuzz::kRawFrameBytes)) return 0;
        const Frame f = fuzz::raw_frame(in);
        if (is(f, MsgId::Stop)) stop_frame(f, c, sh, op); else other_frame(f, c, sh, op);
        break;
      }
      case BridgeOp::StopWritten:
        bridge::bridge_on_stop_written(c);
        sh.written = true;
        if (bridge::bridge_stop_latched(c) != sh.latched) broken("a written stop changed the latch", op);
        break;
      case BridgeOp::Shutdown: {
        // The bridge's own stop exactly when the predictor last said "in trial" and none is latched.
        const bool expect = !sh.latched && sh.predictor_state == protocol::PredictorState::InTrial;
        const bool asks = bridge::bridge_on_shutdown(c) == BridgeAction::StopRobot;
        if (asks != expect)
          broken(expect ? "a shutdown during a trial did not stop the robot" : "a shutdown stopped the robot outside a trial "
                                                                               "or while latched", op);
        if (asks) {
          sh.latched = true;
          sh.written = false;
        }
        if (bridge::bridge_stop_latched(c) != sh.latched) broken("a shutdown changed the latch other than for a trial", op);
        break;
      }
      case BridgeOp::Wait:
        if (!in.take(1)) return 0;
        sh.now += in.u8() * fuzz::kBridgeTimeUnitMs;
        tick(c, sh, op);
        break;
      default: tick(c, sh, op); break;
    }
  }
  return 0;
}
