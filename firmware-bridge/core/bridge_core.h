// The firmware bridge's portable core: turns force-torque readings into protocol frames and
// watches the stop line. No heap, no OS calls, no exceptions, no globals: everything lives in a
// BridgeCore context the port passes in (as SOEM passes its context), and time comes in as a
// millisecond tick from the port. A microcontroller port calls the same functions as the Linux
// host port (firmware-bridge/linux/).
//
// Rules it enforces:
//   - a reading becomes exactly one FtForce and one FtTorque frame with the same alive counter;
//     a failed read produces no frame at all (never stale data: the predictor's deadline then
//     stops the robot), and the heartbeat says "sensor lost";
//   - the sample counter counts sample periods, not readings: a failed read and each period the
//     port's timer overran (bridge_on_periods_missed) advance it, so that the receiver's E2E
//     check counts the missing samples as lost and its logical time (the counter) keeps pace
//     with the robot's; one gap advances it by at most kMaxPeriodsMissed + 1;
//   - a valid Stop frame (E2E-checked) latches a stop: the port must stop the robot and keeps
//     the latch until the next TrialStart frame on the bus, once the port has written the stop
//     (bridge_on_stop_written); a stop the robot never received is not released by a trial
//     start, so it is neither lost nor written into the next trial unannounced: the heartbeat
//     says StopLatched until it is written; a TrialStart that leaves no stop latched tells the
//     port to clear the robot's stop (ReleaseRobot: the robot's stop target mirrors the latch,
//     so a robot program that acts on the rising edge sees every stop);
//   - trial starts and the predictor's heartbeat are sporadic streams whose sender may restart:
//     their E2E checkers resynchronise after protocol::kSporadicResyncMs of silence;
//   - optionally (predictor_timeout_ms > 0), the predictor is watched, and the robot must not
//     run unguarded:
//       - a predictor whose heartbeat is silent for predictor_timeout_ms is a reason to stop;
//       - so is a trial the predictor does not guard: from a TrialStart to its TrialEnd, the
//         predictor's heartbeat must name that trial in state "in trial" or "stopped" within
//         predictor_timeout_ms of the start, and again within predictor_timeout_ms whenever it
//         stops naming it. A TrialStart the predictor lost (its socket's queue overflowed, it
//         restarted just then, its E2E check refused the frame) left it idle while the robot
//         pulled, and it stops nothing outside a trial; a predictor restarted within a trial
//         comes back idle the same way. The bridge, which hears the same frames, is the one
//         node that can tell (PROTOCOL.md, TrialStart);
//   - a bridge that shuts down while the predictor's last heartbeat said "in trial" latches a
//     stop itself: without the bridge no sample reaches the predictor and no stop reaches the
//     robot, so the trial would run on unguarded.
#pragma once

#include <cstdint>

#include "dg_protocol.h"

namespace dressguard::bridge {

using protocol::Frame;

// One sensor reading in protocol counts (a Robotiq FT 300 register already is: F x 100, M x 1000).
struct FtReading {
  int16_t force[3];   // 0.01 N
  int16_t torque[3];  // 0.001 Nm
};

// The most missing samples one gap in the readings puts on the sample counter: a step of 128 or
// more reads as a late frame (protocol::E2EChecker discards it), so a longer gap is sent as 126
// lost samples (the predictor's sensor deadline, 5 periods, has stopped any trial long before).
inline constexpr uint32_t kMaxPeriodsMissed = 126;

struct BridgeConfig {
  uint32_t heartbeat_period_ms = 100;
  uint32_t predictor_timeout_ms = 0;  // 0: a silent predictor is not a stop reason
};

enum class BridgeAction : uint8_t {
  None = 0,
  StopRobot = 1,     // newly latched: write the stop to the robot controller now
  // A TrialStart left no stop latched (it released one, or none was): clear the robot's stop
  // target. It mirrors the latch, and only the robot controller's own TrialStart clears it.
  ReleaseRobot = 2,
};

enum class StopCause : uint8_t { None = 0, StopFrame = 1, PredictorSilent = 2, BridgeShutdown = 3, TrialUnguarded = 4 };
const char* stop_cause_name(StopCause c);  // "stop_frame", "predictor_silent", ...

// The identifiers a port receives and passes to bridge_on_frame (its receive filter).
inline constexpr uint32_t kBridgeReceives[] = {
    protocol::id_of(protocol::MsgId::Stop), protocol::id_of(protocol::MsgId::TrialStart),
    protocol::id_of(protocol::MsgId::TrialEnd), protocol::id_of(protocol::MsgId::HeartbeatPredictor)};

struct BridgeCore {
  BridgeConfig cfg;
  protocol::AliveCounter sample_counter;  // counts sample periods (the rules above)
  uint32_t periods_missed = 0;           // since the last reading, at most kMaxPeriodsMissed
  protocol::AliveCounter heartbeat_counter;
  protocol::E2EChecker stop_checker{protocol::MsgId::Stop, 255};
  protocol::E2EChecker trial_checker{protocol::MsgId::TrialStart, 255};
  protocol::E2EChecker trial_end_checker{protocol::MsgId::TrialEnd, 255};
  protocol::E2EChecker predictor_hb_checker{protocol::MsgId::HeartbeatPredictor, 255};
  bool sensor_ok = false;        // the last read succeeded (false before the first reading)
  StopCause stop_cause = StopCause::None;
  protocol::StopReason last_stop_reason = protocol::StopReason::None;
  uint8_t sensor_errors = 0;     // saturating
  uint16_t reconnects = 0;
  uint32_t readings = 0;
  uint32_t bad_frames = 0;       // stop/trial/heartbeat frames that failed their E2E check
  uint32_t start_ms = 0;
  uint32_t next_heartbeat_ms = 0;
  uint32_t last_predictor_ms = 0;     // the last accepted predictor heartbeat (or the start)
  uint32_t last_trial_frame_ms = 0;   // the last TrialStart or TrialEnd frame, accepted or not (or the start)
  bool predictor_seen = false;
  protocol::PredictorState predictor_state = protocol::PredictorState::Idle;  // its last heartbeat's
  uint16_t predictor_trial = 0;                                                // ... and trial id
  bool stop_written = false;          // the latched stop reached the robot (bridge_on_stop_written)
  // The robot controller's trial, from its TrialStart to its TrialEnd, and whether the predictor
  // guards it: its last heartbeat named the trial, in trial or stopped (watched only with
  // predictor_timeout_ms > 0).
  bool trial_running = false;
  uint16_t trial_id = 0;
  bool trial_guarded = false;
  uint32_t unguarded_since_ms = 0;    // the trial's start, or the heartbeat that stopped guarding it
};

void bridge_init(BridgeCore& c, const BridgeConfig& cfg, uint32_t now_ms);

// A reading arrived: writes the two sample frames to out[0..1] and returns 2.
int bridge_on_reading(BridgeCore& c, const FtReading& r, uint32_t now_ms, Frame out[2]);

// The sensor could not be read (timeout, exception, connection lost): no frames; the period's
// sample is missing.
void bridge_on_sensor_error(BridgeCore& c, uint32_t now_ms);
// `periods` sample periods passed with no read at all (the port's timer overran: its expiration
// count less the one it handles): their samples are missing.
void bridge_on_periods_missed(BridgeCore& c, uint32_t periods);
// The port reconnected to the sensor.
void bridge_on_reconnect(BridgeCore& c);

// The port wrote the latched stop to the robot controller (or has no robot to write it to): a
// TrialStart may release the latch from now on.
inline void bridge_on_stop_written(BridgeCore& c) { c.stop_written = true; }

// A frame received from the bus (kBridgeReceives; others are ignored).
BridgeAction bridge_on_frame(BridgeCore& c, const Frame& f, uint32_t now_ms);

// The periodic tick: writes a heartbeat frame to *out when one is due (returns 1, else 0);
// *action becomes StopRobot when the predictor's heartbeat timed out or it has not guarded the
// running trial for predictor_timeout_ms.
int bridge_on_tick(BridgeCore& c, uint32_t now_ms, Frame* out, BridgeAction* action);

// The port is shutting down: StopRobot when the predictor's last accepted heartbeat said a trial
// is running and no stop is latched yet (the latch's cause is then BridgeShutdown).
BridgeAction bridge_on_shutdown(BridgeCore& c);
inline bool bridge_stop_latched(const BridgeCore& c) { return c.stop_cause != StopCause::None; }

// What the heartbeat reports: StopLatched while a stop is latched, else SensorLost from a failed
// read (and before the first reading) until the next reading, else Ok.
protocol::BridgeState bridge_state(const BridgeCore& c);

}  // namespace dressguard::bridge
