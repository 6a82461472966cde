// The dressguard CAN protocol: the one header shared by the firmware bridge and the predictor.
//
// Classic CAN 2.0A (11-bit identifiers), every frame 8 data bytes, 500 kbit/s or 1 Mbit/s. The
// byte layout of every message, its end-to-end protection and byte-exact examples are in
// firmware-bridge/PROTOCOL.md; a test parses the examples out of that document and checks them
// against the functions below, so the two cannot drift apart.
//
// End-to-end protection follows AUTOSAR E2E profile 1 in spirit ("in the manner of", not a
// certified implementation):
//   byte 0      CRC-8H2F (AUTOSAR profile 2's polynomial 0x2F) over the 16-bit data ID
//               (low byte, then high byte: profile 1's "both" mode) followed by bytes 1..7
//   byte 1      alive counter, 0..255, +1 per message (per sample for the two F/T frames)
//   bytes 2..7  the message's payload, little-endian integers
// The checker tells apart a good frame, a repeated one (same counter), lost frames (counter
// jumped by more than one), a late frame from the past and a corrupted one (bad CRC). E2E has no
// timeout of its own: the receiver keeps a deadline.
//
// Freestanding: no heap, no exceptions, no OS calls, so the bridge's portable core (which may run
// on a microcontroller) uses it as it is.
#pragma once

#include <cstddef>
#include <cstdint>

namespace dressguard::protocol {

// ---------------------------------------------------------------------------------------------
// Frames and identifiers

// One classic CAN data frame as the protocol sees it (the SocketCAN layer converts).
struct Frame {
  uint32_t id = 0;       // 11-bit identifier
  uint8_t len = 0;       // data length code, 0..8; every protocol message has 8
  uint8_t data[8] = {};
};

inline constexpr uint8_t kFrameLength = 8;

// Identifiers: the lower the value, the higher the bus priority, so the stop command wins
// arbitration over everything else and F/T samples over status traffic.
enum class MsgId : uint16_t {
  Stop = 0x080,                // predictor -> robot: stop now (latched until the next trial)
  FtForce = 0x100,             // bridge -> all: Fx Fy Fz of one sample
  FtTorque = 0x101,            // bridge -> all: Mx My Mz of the same sample (same counter)
  TrialStart = 0x180,          // robot -> predictor: a pull begins (speed, arm-height class)
  TrialEnd = 0x181,            // robot -> predictor: the pull ended
  PredictorStatus = 0x300,     // predictor -> all: state and bad-frame counters (paged)
  Posteriors = 0x301,          // predictor -> all: class posteriors, a few per second
  HeartbeatBridge = 0x700,     // bridge -> predictor: alive, sensor state
  HeartbeatPredictor = 0x701,  // predictor -> bridge: alive, predictor state
};

constexpr uint32_t id_of(MsgId m) { return static_cast<uint32_t>(m); }

// The 16-bit data ID that enters each message's CRC (never sent): a frame that arrives under
// the wrong identifier, or a message masquerading as another, fails its CRC.
constexpr uint16_t data_id_of(MsgId m) { return static_cast<uint16_t>(0xD000u | static_cast<uint16_t>(m)); }

// ---------------------------------------------------------------------------------------------
// CRCs (each test-checked against its published check value, the CRC of ASCII "123456789")

// CRC-8 SAE J1850: poly 0x1D, init 0xFF, final XOR 0xFF, not reflected. Check value 0x4B.
// (AUTOSAR E2E profile 1's CRC; kept for a link that wants profile 1 exactly.)
constexpr uint8_t crc8_sae_j1850(const uint8_t* p, size_t n, uint8_t crc = 0xFF) {
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b) crc = static_cast<uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x1D : (crc << 1));
  }
  return crc;
}
constexpr uint8_t crc8_sae_j1850_final(uint8_t crc) { return static_cast<uint8_t>(crc ^ 0xFF); }

// CRC-8H2F (AUTOSAR): poly 0x2F, init 0xFF, final XOR 0xFF, not reflected. Check value 0xDF.
// Hamming distance 4 up to 119 data bits (Koopman), better than J1850's for our 9-byte input;
// the protocol uses this one.
constexpr uint8_t crc8_h2f(const uint8_t* p, size_t n, uint8_t crc = 0xFF) {
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b) crc = static_cast<uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x2F : (crc << 1));
  }
  return crc;
}
constexpr uint8_t crc8_h2f_final(uint8_t crc) { return static_cast<uint8_t>(crc ^ 0xFF); }

// The E2E CRC of a frame: CRC-8H2F over data ID low, data ID high, data[1..7].
constexpr uint8_t e2e_crc(uint16_t data_id, const uint8_t (&data)[8]) {
  const uint8_t id[2] = {static_cast<uint8_t>(data_id & 0xFF), static_cast<uint8_t>(data_id >> 8)};
  return crc8_h2f_final(crc8_h2f(data + 1, 7, crc8_h2f(id, 2)));
}

// ---------------------------------------------------------------------------------------------
// Little-endian field access (byte-wise: no alignment or endianness assumptions)

constexpr void put_u16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v & 0xFF);
  p[1] = static_cast<uint8_t>(v >> 8);
}
constexpr uint16_t get_u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
constexpr void put_i16(uint8_t* p, int16_t v) { put_u16(p, static_cast<uint16_t>(v)); }
constexpr int16_t get_i16(const uint8_t* p) { return static_cast<int16_t>(get_u16(p)); }

// ---------------------------------------------------------------------------------------------
// Scaling: integer counts as a Robotiq FT 300 reports them (its Modbus registers 180-185)

inline constexpr double kForceCountsPerNewton = 100.0;       // 0.01 N per count, +-327.67 N
inline constexpr double kTorqueCountsPerNewtonMetre = 1000.0;  // 0.001 Nm per count, +-32.767 Nm

// Rounds to the nearest count and saturates at the int16 range (a saturated reading is still
// beyond every hard limit the predictor's config accepts, so saturation never hides a stop).
constexpr int16_t to_counts(double value, double counts_per_unit) {
  const double c = value * counts_per_unit;
  if (!(c == c)) return 0;  // NaN: the bridge never sends one; 0 keeps the frame well-formed
  if (c >= 32767.0) return 32767;
  if (c <= -32768.0) return -32768;
  return static_cast<int16_t>(c < 0 ? c - 0.5 : c + 0.5);
}
constexpr double force_newtons(int16_t counts) { return counts / kForceCountsPerNewton; }
constexpr double torque_newton_metres(int16_t counts) { return counts / kTorqueCountsPerNewtonMetre; }

// ---------------------------------------------------------------------------------------------
// Messages (payload bytes 2..7; bytes 0 and 1 are CRC and counter, filled by protect())

// 0x100 / 0x101: one F/T sample in sensor axes. Both frames carry the same counter.
struct FtForce { uint8_t counter; int16_t fx, fy, fz; };    // counts of 0.01 N
struct FtTorque { uint8_t counter; int16_t mx, my, mz; };   // counts of 0.001 Nm

// Arm-height class of the trial, as the study's conditions (0xFF: unknown).
enum class HeightClass : uint8_t { High = 0, Middle = 1, Low = 2, Unknown = 0xFF };

// 0x180: trial start. Travel is not sent per sample: the predictor reconstructs the commanded
// travel from the speed (as the study itself stamped positions from the motion profile).
struct TrialStart { uint8_t counter; uint16_t trial_id; uint16_t speed_mm_s; HeightClass height; };

enum class TrialEndReason : uint8_t { Completed = 0, RobotForceLimit = 1, Aborted = 2, StoppedByPredictor = 3 };
// 0x181: trial end; `samples` = number of F/T samples the trial sent (mod 65536).
struct TrialEnd { uint8_t counter; uint16_t trial_id; uint16_t samples; TrialEndReason reason; };

// Why the predictor stopped the robot.
enum class StopReason : uint8_t {
  None = 0,
  Caught = 1,         // P(caught) above the threshold for k consecutive samples
  HardLimit = 2,      // |force| above the hard limit on the motion or vertical axis
  SensorTimeout = 3,  // no valid sample within the deadline during a trial
  BadFrames = 4,      // too many corrupted or lost frames
  ModelError = 5,     // the model did not load (every trial is refused), or it failed on a sample
  Shutdown = 6,       // the daemon is shutting down during a trial
  StopUnconfirmed = 7,  // the previous trial's stop got no echo within a retry period: refused
};
const char* stop_reason_name(StopReason r);  // "caught", "hard_limit", ...

// 0x080: stop command. `sample` is the index within the trial (0-based) of the sample that
// decided: logical time, independent of bus timing. p_caught in 1/255.
struct Stop { uint8_t counter; StopReason reason; uint8_t p_caught; uint16_t trial_id; uint16_t sample; };

enum class PredictorState : uint8_t { Idle = 0, InTrial = 1, Stopped = 2, Fault = 3 };
const char* predictor_state_name(PredictorState s);  // "idle", "in_trial", "stopped", "fault"

// 0x300: status, paged: page p carries counters 2p and 2p+1 of StatusCounter (saturating u16,
// but Samples mod 65536, as PROTOCOL.md's page table says), so one page per status period
// cycles the whole set.
enum class StatusCounter : uint8_t {
  Corrupted = 0, Repeated = 1, WrongSequence = 2, LostFrames = 3, Late = 4, BadLength = 5,
  KernelDrops = 6, Timeouts = 7, TxRetries = 8, TxErrors = 9, Samples = 10, Stops = 11,
  Count = 12,
};
inline constexpr uint8_t kStatusPages = static_cast<uint8_t>(StatusCounter::Count) / 2;
const char* status_counter_name(StatusCounter c);  // "corrupted", "repeated", ...
struct PredictorStatus { uint8_t counter; uint8_t page; PredictorState state; uint16_t value0, value1; };

// 0x301: posteriors of classes 0..2 in 1/255 at trial sample `sample`.
struct Posteriors { uint8_t counter; uint16_t sample; uint8_t p[3]; PredictorState state; };

enum class BridgeState : uint8_t { Ok = 0, SensorLost = 1, StopLatched = 2 };
// 0x700: bridge heartbeat.
struct HeartbeatBridge { uint8_t counter; BridgeState state; uint8_t sensor_errors; uint16_t reconnects; uint16_t uptime_s; };
// 0x701: predictor heartbeat.
struct HeartbeatPredictor { uint8_t counter; PredictorState state; uint8_t model_loaded; uint16_t trial_id; uint16_t uptime_s; };

// encode(): the whole frame, CRC included. decode(): fields from a frame whose identifier and
// length match, false otherwise (no E2E check: that is E2EChecker's job).
Frame encode(const FtForce& m);
Frame encode(const FtTorque& m);
Frame encode(const TrialStart& m);
Frame encode(const TrialEnd& m);
Frame encode(const Stop& m);
Frame encode(const PredictorStatus& m);
Frame encode(const Posteriors& m);
Frame encode(const HeartbeatBridge& m);
Frame encode(const HeartbeatPredictor& m);
bool decode(const Frame& f, FtForce& m);
bool decode(const Frame& f, FtTorque& m);
bool decode(const Frame& f, TrialStart& m);
bool decode(const Frame& f, TrialEnd& m);
bool decode(const Frame& f, Stop& m);
bool decode(const Frame& f, PredictorStatus& m);
bool decode(const Frame& f, Posteriors& m);
bool decode(const Frame& f, HeartbeatBridge& m);
bool decode(const Frame& f, HeartbeatPredictor& m);

// Writes the E2E CRC into byte 0 (counter and payload already in place).
inline void protect(Frame& f, MsgId m) { f.data[0] = e2e_crc(data_id_of(m), f.data); }

// ---------------------------------------------------------------------------------------------
// E2E checking (receiver side)

enum class E2EStatus : uint8_t {
  Ok = 0,             // counter advanced by exactly one (or the first frame: Initial)
  Initial = 1,        // first valid frame since reset(): accepted, sequence unknown
  OkSomeLost = 2,     // counter advanced by 2..max_delta: accepted, delta-1 frames lost
  WrongSequence = 3,  // counter advanced by more than max_delta: accepted as a resync, frames lost
  Repeated = 4,       // same counter as the last accepted frame: discarded
  Late = 5,           // counter behind the last accepted one (a delayed frame): discarded
  Corrupted = 6,      // CRC mismatch: discarded, the checker's state is untouched
  BadLength = 7,      // DLC is not 8: discarded
};
const char* e2e_status_name(E2EStatus s);

// True when the frame's payload may be used.
constexpr bool accepted(E2EStatus s) {
  return s == E2EStatus::Ok || s == E2EStatus::Initial || s == E2EStatus::OkSomeLost || s == E2EStatus::WrongSequence;
}

// One checker per received message stream (data ID). The counter difference d = (new - last)
// mod 256 classifies the frame: d = 0 repeated; 1 <= d <= max_delta in sequence (d-1 lost);
// max_delta < d < 128 wrong sequence (resync, d-1 lost); d >= 128 a frame from the past (late).
// The 128 split assumes fewer than 128 consecutive frames are ever lost without a timeout:
// at 100 Hz that is 1.28 s, far beyond the daemon's sensor deadline.
class E2EChecker {
 public:
  constexpr explicit E2EChecker(MsgId msg, uint8_t max_delta = 3) : data_id_(data_id_of(msg)), max_delta_(max_delta) {}
  constexpr void reset() { have_last_ = false; }

  // `lost` receives the number of frames missing before this one (0 unless OkSomeLost or
  // WrongSequence).
  constexpr E2EStatus check(const Frame& f, uint32_t& lost) {
    lost = 0;
    if (f.len != kFrameLength) return E2EStatus::BadLength;
    if (e2e_crc(data_id_, f.data) != f.data[0]) return E2EStatus::Corrupted;
    const uint8_t c = f.data[1];
    if (!have_last_) {
      have_last_ = true;
      last_ = c;
      return E2EStatus::Initial;
    }
    const uint8_t d = static_cast<uint8_t>(c - last_);
    if (d == 0) return E2EStatus::Repeated;
    if (d >= 128) return E2EStatus::Late;
    last_ = c;
    lost = d - 1u;
    if (d == 1) return E2EStatus::Ok;
    return d <= max_delta_ ? E2EStatus::OkSomeLost : E2EStatus::WrongSequence;
  }
  constexpr uint8_t last_counter() const { return last_; }

 private:
  uint16_t data_id_;
  uint8_t max_delta_;
  uint8_t last_ = 0;
  bool have_last_ = false;
};

// Sporadic streams (trial frames, the other node's heartbeat) have no deadline of their own, and
// their sender may restart with its counter at 0: a receiver that has heard nothing of a stream
// for this long resets its checker, so that the restarted sender's frames are not discarded as
// late for up to 128 of them. A delayed frame is never this late on CAN.
inline constexpr uint32_t kSporadicResyncMs = 1000;

// A sender's alive counter: one per transmitted stream.
struct AliveCounter {
  uint8_t value = 0;
  constexpr uint8_t next() { return value++; }
};

}  // namespace dressguard::protocol
