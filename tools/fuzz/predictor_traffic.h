// The byte format that fuzz_predictor reads as bus traffic, and a writer for its seed corpus
// (dg_fuzz_seeds predictor DIR). One header so that the seeds and the harness cannot disagree.
//
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
#pragma once

#include <cstdint>
#include <vector>

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
  RawFrame = 8,   // id selector, length, 8 data bytes, protect flag (11 bytes; see the harness)
  Wait = 9,       // b ms pass, then a tick
  TxFail = 10,    // the next b mod 8 stop transmissions fail (ENOBUFS, bus-off)
  Heartbeat = 11, // the bridge's heartbeat, next counter
};

// Appends operations for seeds; each call is one operation (payloads as above).
struct TrafficWriter {
  std::vector<uint8_t> bytes;

  explicit TrafficWriter(const uint8_t (&header)[kTrafficHeader]) : bytes(header, header + kTrafficHeader) {}
  void op(TrafficOp k, uint8_t dt_units, std::initializer_list<uint8_t> payload = {}) {
    bytes.push_back(static_cast<uint8_t>(static_cast<uint8_t>(k) | (dt_units << 4)));
    bytes.insert(bytes.end(), payload.begin(), payload.end());
  }
  // A sample in newtons on the sensor's axes, next counter, 0.1 N resolution.
  void force(double fx, double fy, double fz, uint8_t dt_units = 5) {
    const auto d = [](double f) { return static_cast<uint8_t>(static_cast<int8_t>(f * 10.0)); };
    op(TrafficOp::Force, dt_units, {0, d(fx), 0, d(fy), 0, d(fz), 0});
  }
  void start(uint8_t trial, uint8_t speed_minus_50 = 50) { op(TrafficOp::TrialStart, 1, {0, trial, speed_minus_50}); }
  void end(uint8_t trial = 0) { op(TrafficOp::TrialEnd, 1, {0, trial}); }
  void tick(uint8_t dt_units = 0) { op(TrafficOp::Tick, dt_units); }
};

}  // namespace dressguard::fuzz
