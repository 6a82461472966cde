// The firmware bridge's portable core (see bridge_core.h). Freestanding: no heap, no OS calls.
#include "bridge_core.h"

namespace dressguard::bridge {

protocol::BridgeState bridge_state(const BridgeCore& c) {
  if (bridge_stop_latched(c)) return protocol::BridgeState::StopLatched;
  return c.sensor_ok ? protocol::BridgeState::Ok : protocol::BridgeState::SensorLost;
}

void bridge_init(BridgeCore& c, const BridgeConfig& cfg, uint32_t now_ms) {
  c = BridgeCore{};
  c.cfg = cfg;
  c.start_ms = now_ms;
  c.next_heartbeat_ms = now_ms;
  c.last_predictor_ms = now_ms;
  c.last_trial_frame_ms = now_ms;
}

const char* stop_cause_name(StopCause c) {
  switch (c) {
    case StopCause::None: return "none";
    case StopCause::StopFrame: return "stop_frame";
    case StopCause::PredictorSilent: return "predictor_silent";
    case StopCause::BridgeShutdown: return "bridge_shutdown";
    case StopCause::TrialUnguarded: return "trial_unguarded";
  }
  return "unknown";
}

namespace {

// Wrap-safe: more than `ms` since `then`.
bool longer_than(uint32_t now_ms, uint32_t then, uint32_t ms) { return static_cast<uint32_t>(now_ms - then) > ms; }

// Wrap-safe: more than protocol::kSporadicResyncMs since `then`.
bool silent_since(uint32_t now_ms, uint32_t then) { return longer_than(now_ms, then, protocol::kSporadicResyncMs); }

// TrialStart and TrialEnd come from the robot controller, sporadically: a controller that
// restarted counts from 0 again, so after a silence both checkers start afresh. Counts a frame
// that fails its check and says whether it was accepted.
bool trial_frame_accepted(BridgeCore& c, protocol::E2EChecker& checker, const Frame& f, uint32_t now_ms) {
  if (silent_since(now_ms, c.last_trial_frame_ms)) {
    c.trial_checker.reset();
    c.trial_end_checker.reset();
  }
  c.last_trial_frame_ms = now_ms;
  uint32_t lost = 0;
  if (protocol::accepted(checker.check(f, lost))) return true;
  ++c.bad_frames;
  return false;
}

// Whether the predictor's heartbeat guards the running trial: it names the trial, in trial or
// stopped (a stop it decided is latched here already). Idle or fault, or another trial's id,
// is a predictor that missed the TrialStart or restarted since.
void note_guard(BridgeCore& c, const protocol::HeartbeatPredictor& hb, uint32_t now_ms) {
  if (!c.trial_running) return;
  const bool guards = hb.trial_id == c.trial_id && (hb.state == protocol::PredictorState::InTrial ||
                                                    hb.state == protocol::PredictorState::Stopped);
  if (!guards && c.trial_guarded) c.unguarded_since_ms = now_ms;
  c.trial_guarded = guards;
}

}  // namespace

void bridge_on_periods_missed(BridgeCore& c, uint32_t periods) {
  const uint32_t room = kMaxPeriodsMissed - c.periods_missed;
  c.periods_missed += periods < room ? periods : room;
}

int bridge_on_reading(BridgeCore& c, const FtReading& r, uint32_t, Frame out[2]) {
  // The periods since the last reading that had none are lost samples to the receiver.
  c.sample_counter.value = static_cast<uint8_t>(c.sample_counter.value + c.periods_missed);
  c.periods_missed = 0;
  const uint8_t n = c.sample_counter.next();
  out[0] = protocol::encode(protocol::FtForce{n, r.force[0], r.force[1], r.force[2]});
  out[1] = protocol::encode(protocol::FtTorque{n, r.torque[0], r.torque[1], r.torque[2]});
  ++c.readings;
  c.sensor_ok = true;
  return 2;
}

void bridge_on_sensor_error(BridgeCore& c, uint32_t) {
  if (c.sensor_errors < 255) ++c.sensor_errors;
  c.sensor_ok = false;
  bridge_on_periods_missed(c, 1);
}

void bridge_on_reconnect(BridgeCore& c) {
  if (c.reconnects < 0xFFFF) ++c.reconnects;
}

BridgeAction bridge_on_frame(BridgeCore& c, const Frame& f, uint32_t now_ms) {
  uint32_t lost = 0;
  switch (f.id) {
    case protocol::id_of(protocol::MsgId::Stop): {
      if (!protocol::accepted(c.stop_checker.check(f, lost))) {
        // A repeated stop is still a stop request; only a corrupted one is ignored.
        protocol::Stop s;
        if (protocol::e2e_crc(protocol::data_id_of(protocol::MsgId::Stop), f.data) != f.data[0] || !protocol::decode(f, s)) {
          ++c.bad_frames;
          return BridgeAction::None;
        }
      }
      protocol::Stop s;
      protocol::decode(f, s);
      c.last_stop_reason = s.reason;
      if (c.stop_cause != StopCause::None) return BridgeAction::None;  // already latched
      c.stop_cause = StopCause::StopFrame;
      c.stop_written = false;
      return BridgeAction::StopRobot;
    }
    case protocol::id_of(protocol::MsgId::TrialStart): {
      if (!trial_frame_accepted(c, c.trial_checker, f, now_ms)) return BridgeAction::None;
      protocol::TrialStart m;
      protocol::decode(f, m);
      c.trial_running = true;
      c.trial_id = m.trial_id;
      c.trial_guarded = false;
      c.unguarded_since_ms = now_ms;
      // A new trial releases a latch whose stop reached the robot (the robot controller restarts
      // the motion itself), and the robot's stop target is cleared with it (also one left set
      // from before the bridge started); one still unwritten stands (bridge_core.h).
      if (c.stop_cause != StopCause::None && !c.stop_written) return BridgeAction::None;
      c.stop_cause = StopCause::None;
      c.last_stop_reason = protocol::StopReason::None;
      return BridgeAction::ReleaseRobot;
    }
    case protocol::id_of(protocol::MsgId::TrialEnd): {
      if (!trial_frame_accepted(c, c.trial_end_checker, f, now_ms)) return BridgeAction::None;
      protocol::TrialEnd m;
      protocol::decode(f, m);
      if (m.trial_id == c.trial_id) c.trial_running = false;  // another's end: not this trial's
      return BridgeAction::None;
    }
    case protocol::id_of(protocol::MsgId::HeartbeatPredictor):
      // A restarted predictor counts from 0 again; it was silent for its restart.
      if (silent_since(now_ms, c.last_predictor_ms)) c.predictor_hb_checker.reset();
      if (!protocol::accepted(c.predictor_hb_checker.check(f, lost))) {
        ++c.bad_frames;
        return BridgeAction::None;
      }
      c.predictor_seen = true;
      c.last_predictor_ms = now_ms;
      if (protocol::HeartbeatPredictor hb; protocol::decode(f, hb)) {
        c.predictor_state = hb.state;
        c.predictor_trial = hb.trial_id;
        note_guard(c, hb, now_ms);
      }
      return BridgeAction::None;
    default: return BridgeAction::None;
  }
}

BridgeAction bridge_on_shutdown(BridgeCore& c) {
  if (c.stop_cause != StopCause::None || c.predictor_state != protocol::PredictorState::InTrial)
    return BridgeAction::None;
  c.stop_cause = StopCause::BridgeShutdown;
  c.stop_written = false;
  return BridgeAction::StopRobot;
}

int bridge_on_tick(BridgeCore& c, uint32_t now_ms, Frame* out, BridgeAction* action) {
  *action = BridgeAction::None;
  const uint32_t timeout = c.cfg.predictor_timeout_ms;
  if (timeout > 0 && c.stop_cause == StopCause::None) {
    if (longer_than(now_ms, c.last_predictor_ms, timeout)) c.stop_cause = StopCause::PredictorSilent;
    else if (c.trial_running && !c.trial_guarded && longer_than(now_ms, c.unguarded_since_ms, timeout))
      c.stop_cause = StopCause::TrialUnguarded;
    if (c.stop_cause != StopCause::None) {
      c.stop_written = false;
      *action = BridgeAction::StopRobot;
    }
  }
  // Wrap-safe comparison of millisecond ticks.
  if (static_cast<int32_t>(now_ms - c.next_heartbeat_ms) < 0) return 0;
  c.next_heartbeat_ms = now_ms + c.cfg.heartbeat_period_ms;
  const uint32_t up = (now_ms - c.start_ms) / 1000;
  *out = protocol::encode(protocol::HeartbeatBridge{c.heartbeat_counter.next(), bridge_state(c), c.sensor_errors, c.reconnects,
                                                    static_cast<uint16_t>(up > 0xFFFF ? 0xFFFF : up)});
  return 1;
}

}  // namespace dressguard::bridge
