// The byte formats that the robot side's fuzz targets read as bus traffic (fuzz_predictor,
// fuzz_bridge), the frame helpers both use, and writers for their seed corpora (dg_fuzz_seeds
// predictor|bridge DIR). One header so that the seeds and the harnesses cannot disagree.
//
// ---- fuzz_predictor ----
// An input is a configuration header of kTrafficHeader bytes, then a stream of operations:
//
//   header[0]   model: 0 mod 8 = no model (the daemon's "model did not load"); otherwise the
//               test model with "caught" at class index (header[0] / 8) mod 3
//   header[1]   sensor mount: axis permutation (mod 6), then 3 sign bits (bits 3-5)
//   header[2,3] bias on the motion and vertical axes, int8 x 0.05 N
//   header[4]   stop threshold: 0 = the model's, else 0.50 + (b mod 50) / 100
//   header[5]   consecutive samples: b mod 9 (0 = the model's)
//   header[6]   hard limit 2 + (b mod 19) N
//   header[7,8] bad-frame budget 1 + (b mod 8), weight 1 + (b mod 40)
//   header[9]   E2E max delta 1 + (b mod 5)
//   header[10]  sensor timeout 10 + (b mod 91) ms
//   header[11]  stop retry 1 + (b mod 10) ms
//   header[12]  status, heartbeat and posterior periods 5 + b ms
//
// Each operation is one byte: the low nibble its kind (TrafficOp), the high nibble the time that
// passes before it, in 2 ms units; then the kind's payload. An input that ends inside an
// operation ends there.
//
// ---- fuzz_bridge ----
// A header of kBridgeHeader bytes, then operations as above (BridgeOp; the high nibble in 4 ms
// units):
//
//   header[0]     predictor timeout: 0 when b < 64, else 10 + (b mod 200) ms
//   header[1]     heartbeat period 1 + b ms
//   header[2..5]  the port's millisecond clock at start, little-endian (near 2^32: the wrap)
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <string_view>
#include <vector>

#include "dg_protocol.h"

namespace dressguard::fuzz {

inline constexpr int kTrafficHeader = 13;
inline constexpr int64_t kTrafficTimeUnitNs = 2'000'000;

enum class TrafficOp : uint8_t {
  Force = 0,      // ctl, fx, fy, fz: ctl bits 0-1 counter (0 next, 1 repeat, 2 skip 1 + bits 2-3,
                  //   3 the payload's counter byte), bit 4 raw int16 counts (else int8 x 0.1 N and
                  //   the high bytes ignored), bit 5 corrupt byte 2, bit 6 length 7, bit 7 torque
                  //   frame first; fx, fy, fz little-endian int16 (6 bytes)
  TrialStart = 1, // ctl (counter and corruption bits as Force), trial id, speed 50 + b mm/s
  TrialEnd = 2,   // ctl, trial id (0 = the current trial's)
  Tick = 3,       // the daemon's periodic timer
  StopEcho = 4,   // b mod 3: 0 the last stop frame sent, 1 it with another counter, 2 a force frame
  KernelDrops = 5,  // b more frames dropped by the receive socket
  BusError = 6,   // error class b
  Shutdown = 7,   // SIGTERM
  RawFrame = 8,   // id selector, length, 8 data bytes, protect flag (11 bytes; raw_frame())
  Wait = 9,       // b ms pass, then a tick
  TxFail = 10,    // the next b mod 8 stop transmissions fail (ENOBUFS, bus-off)
  Heartbeat = 11, // the bridge's heartbeat, next counter
};

inline constexpr int kBridgeHeader = 6;
inline constexpr uint32_t kBridgeTimeUnitMs = 4;

enum class BridgeOp : uint8_t {
  Reading = 0,      // fx, fy, fz, mx, my, mz: little-endian int16 counts (12 bytes)
  SensorError = 1,  // the read failed
  Reconnect = 2,    // the port reconnected to the sensor
  Stop = 3,         // ctl (counter and damage bits as TrafficOp::Force), reason, trial id
  TrialStart = 4,   // ctl, trial id
  PredictorHeartbeat = 5,  // ctl (its bits 4 and 7 are the predictor's state, bit 4 low), trial id
  RawFrame = 6,     // as TrafficOp::RawFrame
  Tick = 7,         // the port's periodic tick
  Wait = 8,         // 4 x b ms pass, then a tick
  StopWritten = 9,  // the port wrote the latched stop to the robot
  Shutdown = 10,    // the port is shutting down (bridge_on_shutdown)
  TrialEnd = 11,    // ctl, trial id
  PeriodsMissed = 12,  // b periods passed without a read (the port's timer overran)
};

// ---- helpers of both harnesses ----

// A rule of the harness's header does not hold: says which, and aborts (libFuzzer then reports
// the input that did it; tools/fuzz/mutants.py reads the line).
[[noreturn]] inline void broken(const char* rule, long op) {
  std::fprintf(stderr, "rule broken at operation %ld: %s\n", op, rule);
  std::abort();
}

// A reader's error must say "NAME:LINE: what", LINE a line of `text` (1-based) and `what` not
// empty; with `line_optional`, "NAME: what" (about the whole input) is allowed too.
inline void check_error_names_line(std::string_view what, std::string_view name, std::string_view text,
                                   bool line_optional = false) {
  if (what.substr(0, name.size()) != name || what.substr(name.size(), 1) != ":") broken("an error that does not name the file", 0);
  size_t i = name.size() + 1;
  if (line_optional && i < what.size() && what[i] == ' ') return;
  long line = 0;
  while (i < what.size() && what[i] >= '0' && what[i] <= '9' && line < 1'000'000'000) line = line * 10 + (what[i++] - '0');
  long lines = 1;
  for (char ch : text) lines += ch == '\n';
  if (line < 1 || line > lines || what.substr(i, 2) != ": " || what.size() <= i + 2)
    broken("an error that does not name a line of the input and what is wrong", line);
}

// Reads an input front to back.
struct Reader {
  const uint8_t* p;
  size_t n;
  bool take(size_t k) const { return n >= k; }
  uint8_t u8() { return --n, *p++; }
  int16_t i16() {
    const uint8_t lo = u8();
    return static_cast<int16_t>(lo | (u8() << 8));
  }
};

// A frame's alive counter per the ctl bits 0-3: next, repeat, skip, or `raw`.
inline uint8_t counter_for(uint8_t ctl, uint8_t& running, uint8_t raw) {
  switch (ctl & 3) {
    case 0: return ++running;
    case 1: return running;
    case 2: return running = static_cast<uint8_t>(running + 2 + ((ctl >> 2) & 3));
    default: return running = raw;
  }
}

// ctl bit 5: a payload byte flipped after the CRC (the checker must see it); bit 6: length 7.
inline void damage(protocol::Frame& f, uint8_t ctl) {
  if (ctl & 0x20) f.data[2] ^= 0x5A;
  if (ctl & 0x40) f.len = 7;
}

inline bool is(const protocol::Frame& f, protocol::MsgId m) { return f.id == protocol::id_of(m); }

// True when a fresh receiver would take the frame as message m (length, CRC).
inline bool protected_as(const protocol::Frame& f, protocol::MsgId m) {
  protocol::E2EChecker chk(m);
  uint32_t lost = 0;
  return protocol::accepted(chk.check(f, lost));
}

// TrafficOp::RawFrame / BridgeOp::RawFrame: an identifier of the protocol (or any 11-bit one),
// a length 0-8, 8 data bytes, and when the flag's bit 0 is set the CRC of that identifier.
inline protocol::Frame raw_frame(Reader& in) {
  static constexpr protocol::MsgId kIds[] = {protocol::MsgId::FtForce,    protocol::MsgId::FtTorque,
                                             protocol::MsgId::TrialStart, protocol::MsgId::TrialEnd,
                                             protocol::MsgId::HeartbeatBridge, protocol::MsgId::Stop,
                                             protocol::MsgId::HeartbeatPredictor};
  protocol::Frame f;
  const uint8_t sel = in.u8();
  f.id = sel < 224 ? protocol::id_of(kIds[sel % 7]) : (sel * 37u) & 0x7FF;
  f.len = in.u8() % 9;
  for (auto& b : f.data) b = in.u8();
  if (in.u8() & 1)
    for (protocol::MsgId m : kIds)
      if (is(f, m)) protocol::protect(f, m);
  return f;
}
inline constexpr size_t kRawFrameBytes = 11;

// ---- seed writers ----

// Appends operations; each call is one operation (payloads as above).
template <typename Op, int Header>
struct OpWriter {
  std::vector<uint8_t> bytes;

  explicit OpWriter(const uint8_t (&header)[Header]) : bytes(header, header + Header) {}
  void op(Op k, uint8_t dt_units, std::initializer_list<uint8_t> payload = {}) {
    bytes.push_back(static_cast<uint8_t>(static_cast<uint8_t>(k) | (dt_units << 4)));
    bytes.insert(bytes.end(), payload.begin(), payload.end());
  }
};

struct TrafficWriter : OpWriter<TrafficOp, kTrafficHeader> {
  using OpWriter::OpWriter;
  // A sample in newtons on the sensor's axes, next counter, 0.1 N resolution.
  void force(double fx, double fy, double fz, uint8_t dt_units = 5) {
    const auto d = [](double f) { return static_cast<uint8_t>(static_cast<int8_t>(f * 10.0)); };
    op(TrafficOp::Force, dt_units, {0, d(fx), 0, d(fy), 0, d(fz), 0});
  }
  void start(uint8_t trial, uint8_t speed_minus_50 = 50) { op(TrafficOp::TrialStart, 1, {0, trial, speed_minus_50}); }
  void end(uint8_t trial = 0) { op(TrafficOp::TrialEnd, 1, {0, trial}); }
  void tick(uint8_t dt_units = 0) { op(TrafficOp::Tick, dt_units); }
};

struct BridgeWriter : OpWriter<BridgeOp, kBridgeHeader> {
  using OpWriter::OpWriter;
  // A reading in newtons and newton-metres, as the sensor's registers give them.
  void reading(double fx, double fy, double fz, double mz = 0.0, uint8_t dt_units = 2) {
    const auto le = [](int16_t v, std::vector<uint8_t>& b) {
      b.push_back(static_cast<uint8_t>(v & 0xFF));
      b.push_back(static_cast<uint8_t>((v >> 8) & 0xFF));
    };
    std::vector<uint8_t> b;
    for (double f : {fx, fy, fz}) le(protocol::to_counts(f, protocol::kForceCountsPerNewton), b);
    for (double m : {0.0, 0.0, mz}) le(protocol::to_counts(m, protocol::kTorqueCountsPerNewtonMetre), b);
    bytes.push_back(static_cast<uint8_t>(static_cast<uint8_t>(BridgeOp::Reading) | (dt_units << 4)));
    bytes.insert(bytes.end(), b.begin(), b.end());
  }
  void tick(uint8_t dt_units = 0) { op(BridgeOp::Tick, dt_units); }
};

}  // namespace dressguard::fuzz
