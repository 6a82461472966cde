// Modbus connections of the bridge's Linux port (libmodbus): the F/T sensor it reads and the
// robot controller it writes a stop to. Failures follow libmodbus: the call fails, errno says
// why (libmodbus's own codes for exceptions, e.g. EMBXSFAIL), modbus_strerror names it.
#pragma once

#include <cstdint>
#include <string>

#include "bridge_core.h"

typedef struct _modbus modbus_t;

namespace dressguard::bridge {

// Where a Modbus device is: "tcp:HOST:PORT" or "rtu:/dev/ttyUSB0:BAUD[:PARITY]" (parity N/E/O,
// 8 data bits, 1 stop bit; the FT 300's default is rtu:...:19200:N).
struct ModbusEndpoint {
  std::string spec = "rtu:/dev/ttyUSB0:19200:N";
  int slave = 9;
  int response_timeout_ms = 20;  // bounds the whole answer (libmodbus's byte timeout is off)
};

// A spec taken apart: "tcp:HOST:PORT" (HOST a numeric IPv4 address: libmodbus 3.1 resolves no
// names) or "rtu:DEVICE:BAUD[:PARITY]".
struct EndpointParts {
  bool tcp = false;
  std::string where;   // host or device
  int number = 0;      // port (1-65535) or baud (one libmodbus sets: termios' rates)
  char parity = 'N';   // N, E or O
};
// Empty when `spec` is a valid endpoint (written to *out), else what is wrong with it.
std::string parse_endpoint(const std::string& spec, EndpointParts* out = nullptr);

// [ms] The least time one reading (six registers, FC03 or FC04) takes on an RTU line: the
// 8-byte request and the 17-byte answer (address, function, count, 12 data bytes, CRC), each
// character 10 bits (start, 8 data, stop; 11 with parity), and the 3.5-character silence that
// ends each frame; the sensor's own turnaround comes on top. 0 for TCP. At the FT 300's 19200
// baud it is 16.7 ms: 100 Hz polling needs 38400 baud or more.
double rtu_reading_ms(const EndpointParts& p);

// Pending: no reading yet, and nothing failed (a streaming sensor between two frames).
enum class ReadResult : uint8_t { Ok = 0, Timeout = 1, Exception = 2, Disconnected = 3, BadData = 4, Pending = 5 };
const char* read_result_name(ReadResult r);

// A Modbus connection that knows how to (re)open itself.
class ModbusLink {
 public:
  explicit ModbusLink(ModbusEndpoint ep);
  ~ModbusLink();
  ModbusLink(const ModbusLink&) = delete;
  ModbusLink& operator=(const ModbusLink&) = delete;
  // Opens (or reopens) the connection; false with last_error() set when it fails.
  bool connect();
  void close();
  bool connected() const { return ctx_ != nullptr; }
  const std::string& last_error() const { return error_; }
  modbus_t* ctx() { return ctx_; }
  // Classifies the errno of a failed libmodbus call. The link is closed unless the device answered
  // with a Modbus exception: after a timeout or a garbled answer, a late answer may still be on
  // its way, and on a serial line nothing tells it from the answer to the next request (TCP's
  // transaction id does, but libmodbus then fails every later request). A closed link reopens
  // on a fresh connection, flushed.
  ReadResult classify_failure();
  const ModbusEndpoint& endpoint() const { return ep_; }

 private:
  ModbusEndpoint ep_;
  modbus_t* ctx_ = nullptr;
  std::string error_;
};

// The F/T sensor's register map. Default: Robotiq FT 300 (holding registers 180-185: Fx Fy Fz
// in 0.01 N, Mx My Mz in 0.001 Nm, int16). `force_scale`/`torque_scale` convert other sensors'
// counts to the protocol's (1.0 for the FT 300).
struct SensorMap {
  int first_register = 180;
  bool input_registers = false;  // FC04 instead of FC03
  double force_scale = 1.0;
  double torque_scale = 1.0;
};

// What the bridge's loop needs of a force-torque sensor: polled over Modbus each period
// (ModbusSensor), or streaming on its own clock (Ft300Stream, ft300_stream.h).
class Sensor {
 public:
  virtual ~Sensor() = default;
  // Opens (or reopens) it; false with last_error() set when that fails.
  virtual bool connect() = 0;
  virtual bool connected() const = 0;
  // The next reading; on failure nothing is written to `out`, and the sensor may have closed
  // itself (connected() says).
  virtual ReadResult read(FtReading& out) = 0;
  virtual const std::string& last_error() const = 0;
  // [ms] After a failure that closed it, the least wait before it is reopened.
  virtual int reopen_quiet_ms() const = 0;
  // -1: a polled sensor, read once per period (read() blocks up to its timeout). Else a
  // descriptor that is readable when a streaming sensor has bytes: read() never blocks and
  // says Pending when no reading is complete, and it is read on every period too (which finds
  // a stream gone silent).
  virtual int events_fd() const { return -1; }
};

class ModbusSensor : public Sensor {
 public:
  ModbusSensor(ModbusEndpoint ep, SensorMap map) : link_(std::move(ep)), map_(map) {}
  ModbusLink& link() { return link_; }
  // One reading (six registers in one request); on failure nothing is written to `out`.
  ReadResult read(FtReading& out) override;
  bool connect() override { return link_.connect(); }
  bool connected() const override { return link_.connected(); }
  const std::string& last_error() const override { return link_.last_error(); }
  // A late answer lands before the link reopens (ModbusLink::classify_failure).
  int reopen_quiet_ms() const override { return link_.endpoint().response_timeout_ms; }

 private:
  ModbusLink link_;
  SensorMap map_;
};

// How the stop reaches the robot controller: a coil (FC05) or a holding register (FC06). It
// mirrors the bridge's latch: set (coil ON, register = value) when a stop is latched, clear
// (coil OFF, register 0) when the robot controller's TrialStart leaves none (PROTOCOL.md, Stop).
struct StopTarget {
  bool coil = true;
  int address = 0;
  int value = 1;  // register value, not 0 (a coil is written ON)
};
// "coil 7", "holding register 7": the target as the log and the errors name it.
std::string stop_target_name(const StopTarget& t);

// What the robot controller said when the bridge read its stop target at start
// (RobotStopWriter::probe).
enum class ProbeResult : uint8_t {
  Clear = 0,         // it answered: no stop set
  StopSet = 1,       // it answered: the stop is set already (left from an earlier run)
  NoSuchTarget = 2,  // it has no such coil or register (Modbus exception 02, illegal data address)
  Failed = 3,        // no connection or no answer (it may not be powered yet), or another exception
};

class RobotStopWriter {
 public:
  RobotStopWriter(ModbusEndpoint ep, StopTarget t) : link_(std::move(ep)), target_(t) {}
  ModbusLink& link() { return link_; }
  // Writes the stop; reconnects once if needed. False with link().last_error() on failure.
  bool write_stop() { return write_target(true); }
  // Clears it (coil OFF, register 0), as write_stop writes it.
  bool write_release() { return write_target(false); }
  // Once at start, before the loop: connects and reads the target (FC01 for a coil, FC03 for a
  // register), so that a wrong endpoint, unit id or address is found then, not when an arm is
  // caught. link().last_error() says why for NoSuchTarget and Failed; the link stays open when
  // the controller answered (the first stop then needs no connect).
  ProbeResult probe();

 private:
  bool write_target(bool stop);

  ModbusLink link_;
  StopTarget target_;
};

}  // namespace dressguard::bridge
