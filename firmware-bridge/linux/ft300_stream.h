// The Robotiq FT 300's data stream mode: its one way to 100 Hz. Its serial line is fixed at
// 19200 8N1, where one Modbus reading takes at least 16.7 ms (rtu_reading_ms), so polling
// cannot keep up with the study's 10 ms period; in stream mode the sensor itself sends a
// 16-byte frame every 10 ms.
//
// Where each detail comes from:
//   [M]  the FT 300 instruction manual, 4.4 "Serial communication": 4.4.1 Modbus RTU at 19200
//        bps, 8 data bits, 1 stop bit, no parity, slave ID 9; 4.4.2 "Data stream": write 0x0200
//        in register 410 to start it; frames <0x20><0x4E><LSB_data1><MSB_data1> ...
//        <LSB_data6><MSB_data6><LSB_crc><MSB_crc> at 100 Hz, data1..6 = Fx Fy Fz x 100 (N) and
//        Mx My Mz x 1000 (Nm) as 16-bit signed integers, the CRC "a standard 16-bits modbus
//        CRC"; to stop it, send a series of 0xFF characters ("for about 0.5 s (50 times)").
//   [R]  Robotiq's own driver, rq_sensor_com.c (ROS robotiq_force_torque_sensor, BSD): the start
//        is an FC16 write of one register, 410 = 0x0200 (REGISTER_SELECT_OUTPUT), and a missing
//        answer is forgiven when the stream runs; the CRC covers the 14 bytes from the header
//        on; the stop ("jam") is 50 bytes of 0xFF (RQ_COM_JAM_SIGNAL_LENGTH/_CHAR), repeated
//        while bytes still come; the stream counts as stopped after 80 ms without a byte (20 x
//        4 ms); the sensor gets 100 ms to switch back to Modbus; a stream without a valid frame
//        for 160 ms is lost, and its state machine then starts over (jam, start).
//   [S]  Scripts written independently of [R] send the same start request to FT 300s, byte for
//        byte: 09 10 01 9A 00 01 02 02 00 CD CA (checked by a test).
// What no source says, and is chosen here: a jam burst only once the last one has left the line
// (50 characters take 26 ms at 19200 baud), so that bytes do not pile up in the output queue
// and delay the start request behind them; 100 ms without a good frame, not 160, is a lost
// stream (the predictor's own deadline is 50 ms; either way the bridge only reports it sooner
// and restarts the stream); 2 s of jamming (four times the manual's 0.5 s) before giving up.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "modbus_link.h"

namespace dressguard::bridge {

namespace ft300 {
constexpr int kBaud = 19200;                   // [M] 4.4.1, fixed
constexpr int kSlave = 9;                      // [M] 4.4.1
constexpr int kOutputRegister = 410;           // [M] 4.4.2, [R] REGISTER_SELECT_OUTPUT
constexpr uint16_t kStreamOutput = 0x0200;     // [M] 4.4.2
constexpr uint8_t kHeader[2] = {0x20, 0x4E};   // [M] 4.4.2
constexpr size_t kFrameBytes = 16;             // [M] header 2 + six int16 + CRC 2
constexpr size_t kCrcBytes = kFrameBytes - 2;  // [R] the CRC covers the header and the data
constexpr int kFramePeriodMs = 10;             // [M] 100 Hz
constexpr uint8_t kJamByte = 0xFF;             // [M], [R]
constexpr size_t kJamBytes = 50;               // [R] RQ_COM_JAM_SIGNAL_LENGTH
constexpr int kJamLineMs = 30;                 // 50 x 10 bits at 19200 baud = 26 ms, and a margin
constexpr int kQuietMs = 80;                   // [R] RQ_COM_TIMER_FOR_STREAM_DETECTION_MAX_VALUE x 4 ms
constexpr int kSwitchMs = 100;                 // [R] usleep(100000) after the jam
constexpr size_t kStartRequestBytes = 11;      // FC16: slave, 0x10, address, count, 2, value, CRC
}  // namespace ft300

// CRC-16/MODBUS (reflected polynomial 0xA001, initial 0xFFFF; check value 0x4B37 over
// "123456789"). Sent low byte first, in Modbus frames and in [M]'s stream frames alike.
uint16_t crc16_modbus(const uint8_t* p, size_t n);

// The FC16 request that starts the stream: register 410 = 0x0200 on unit `slave` ([R]).
void ft300_start_request(int slave, uint8_t out[ft300::kStartRequestBytes]);

struct Ft300StreamStats {
  std::atomic<uint64_t> frames{0};         // good frames, each one reading
  std::atomic<uint64_t> crc_failures{0};   // a header whose 16 bytes failed the CRC: never published
  std::atomic<uint64_t> resyncs{0};        // the frame boundary lost after a good frame, found again
  std::atomic<uint64_t> skipped_bytes{0};  // bytes in no good frame (a jammed stream, the start's answer too)
  std::atomic<uint64_t> streams_found{0};  // at a start, a stream already running (jammed)
  std::atomic<uint64_t> starts{0};         // streams started (their first good frame came)
};

// Finds the frames in the bytes of the line: a frame starts at a header and counts only when
// its CRC holds. After a CRC failure the search goes on from the byte after that header (the
// real frame may begin inside the failed one), so that one bad byte costs one frame. Out of
// step, a header and a CRC that match by chance (1 in 65,536 per false header) would pass, as
// in [R]; in step, the CRC catches every burst of up to 16 flipped bits.
class Ft300FrameParser {
 public:
  explicit Ft300FrameParser(Ft300StreamStats& stats) : stats_(stats) {}
  // Where the next bytes of the line go, and how many fit (space() moves what is left to the
  // front); then added(n) with how many came.
  uint8_t* tail() { return buf_ + end_; }
  size_t space();
  void added(size_t n) { end_ += n; }
  // Ok: a good frame, in `out`. BadData: the frame due after a good one failed its CRC (never
  // written to `out`): one per loss of step, for the frame lost; the false headers found while
  // looking for the next frame fail theirs too, and are counted but not returned. Pending: no
  // whole frame in the bytes so far.
  ReadResult next(FtReading& out);
  void clear();  // forget what was taken so far (and that it was in step)

 private:
  void skip(size_t n);
  Ft300StreamStats& stats_;
  uint8_t buf_[512];
  size_t begin_ = 0, end_ = 0;
  bool in_step_ = false;  // the last frame was good: a byte skipped now is a resync
};

// "rtu-stream:DEVICE", the bridge's --sensor spec for this mode.
bool is_stream_spec(const std::string& spec);
// Empty when `spec` names a device (written to *device), else what is wrong with it.
std::string parse_stream_spec(const std::string& spec, std::string* device);

struct Ft300StreamConfig {
  std::string device;        // the serial line: /dev/ttyUSB0, or better /dev/serial/by-id/...
  int slave = ft300::kSlave;
  int silence_ms = 100;      // no good frame this long (or since the start request): lost
  int jam_give_up_ms = 2000; // a line not quiet after this long of jamming: a sensor error
  int quiet_ms = ft300::kQuietMs;
  int switch_ms = ft300::kSwitchMs;
};

// The FT 300 in data stream mode as the bridge's sensor. connect() opens the line raw at 19200
// 8N1; then read(), called whenever events_fd() is readable and on every period, never blocks
// and moves through the phases: listen until the line is quiet, jamming a stream the sensor was
// left in; write register 410; take frames. Every good frame is one reading; a frame whose CRC
// fails is BadData (the line stays open); a stream silent for silence_ms, a start without
// frames, a jam that does not quiet the line, or a line that hangs up is a failure that closes
// the line, and the next connect() starts over with the jam.
class Ft300Stream : public Sensor {
 public:
  explicit Ft300Stream(Ft300StreamConfig cfg);
  ~Ft300Stream() override;  // closes the line; the sensor streams on (stop_stream() stops it)
  Ft300Stream(const Ft300Stream&) = delete;
  Ft300Stream& operator=(const Ft300Stream&) = delete;

  bool connect() override;
  bool connected() const override { return tty_ >= 0; }
  ReadResult read(FtReading& out) override;
  const std::string& last_error() const override { return error_; }
  int reopen_quiet_ms() const override { return 0; }  // the next connect listens to the line first
  int events_fd() const override { return epoll_fd_; }
  void close();
  // For shutdown: jams the stream until the line is quiet (blocking, at most give_up_ms), so
  // that the sensor answers Modbus again, and closes the line. False, with last_error(), when
  // the line cannot be opened or does not go quiet.
  bool stop_stream(int give_up_ms);
  const Ft300StreamStats& stats() const { return stats_; }

 private:
  using Clock = std::chrono::steady_clock;
  enum class Phase : uint8_t { Jamming, Starting, Streaming };
  enum class Jam : uint8_t { Quiet, Going, GaveUp, LineFailed };
  bool open_line();
  bool configure_line();
  ReadResult take_bytes();
  bool write_all(const uint8_t* p, size_t n, const char* what);
  Jam jam_step(Clock::time_point now, int give_up_ms);
  ReadResult on_jamming(Clock::time_point now);
  ReadResult on_starting(FtReading& out, Clock::time_point now);
  ReadResult next_frame(FtReading& out, Clock::time_point now);
  ReadResult fail(ReadResult why, const std::string& what);  // error_ = the device and `what`; closes
  ReadResult closed(ReadResult why);                         // error_ already said; closes
  std::string reply_said() const;
  std::string counts() const;

  Ft300StreamConfig cfg_;
  Ft300StreamStats stats_;
  Ft300FrameParser parser_{stats_};
  int tty_ = -1, epoll_fd_ = -1;
  std::string error_;
  Phase phase_ = Phase::Jamming;
  Clock::time_point phase_start_{}, last_rx_{}, last_burst_{}, last_good_{};
  bool jammed_ = false;          // a burst was sent in this jam
  bool heard_since_burst_ = false;
  uint8_t reply_[8] = {};        // the first bytes after the start request: its answer
  size_t reply_len_ = 0;
};

}  // namespace dressguard::bridge
