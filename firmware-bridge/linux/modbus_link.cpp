// libmodbus connections of the bridge's Linux port.
#include "modbus_link.h"

#include <arpa/inet.h>
#include <modbus.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace dressguard::bridge {

const char* read_result_name(ReadResult r) {
  switch (r) {
    case ReadResult::Ok: return "ok";
    case ReadResult::Timeout: return "timeout";
    case ReadResult::Exception: return "modbus exception";
    case ReadResult::Disconnected: return "disconnected";
    case ReadResult::BadData: return "bad data";
    case ReadResult::Pending: return "pending";
  }
  return "unknown";
}

double rtu_reading_ms(const EndpointParts& p) {
  if (p.tcp || p.number <= 0) return 0.0;
  const double characters = 8 + 17 + 2 * 3.5;
  const double bits = p.parity == 'N' ? 10.0 : 11.0;
  return 1000.0 * characters * bits / p.number;
}

namespace {

// The rates libmodbus 3.1 turns into a termios speed; it opens a line at any other at 9600
// without a word (a typo such as 11520 then looks like a sensor that never answers).
bool libmodbus_sets_baud(long baud) {
  static constexpr long kRates[] = {110,     300,     600,     1200,    2400,    4800,    9600,    19200,
                                    38400,   57600,   115200,  230400,  460800,  500000,  576000,  921600,
                                    1000000, 1152000, 1500000, 2500000, 3000000, 3500000, 4000000};
  for (long r : kRates)
    if (r == baud) return true;
  return false;
}

}  // namespace

std::string parse_endpoint(const std::string& spec, EndpointParts* out) {
  std::vector<std::string> parts;
  std::stringstream in(spec);
  std::string tok;
  while (std::getline(in, tok, ':')) parts.push_back(tok);
  const auto whole = [](const std::string& s, long lo, long hi, int& v) {
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || errno != 0 || n < lo || n > hi) return false;
    v = static_cast<int>(n);
    return true;
  };
  EndpointParts p;
  if (parts.size() == 3 && parts[0] == "tcp") {
    p.tcp = true;
    in_addr a{};
    if (inet_pton(AF_INET, parts[1].c_str(), &a) != 1)
      return "'" + spec + "': host '" + parts[1] + "' is not a numeric IPv4 address (libmodbus resolves no names)";
    if (!whole(parts[2], 1, 65535, p.number)) return "'" + spec + "': port '" + parts[2] + "' is not in 1-65535";
  } else if ((parts.size() == 3 || parts.size() == 4) && parts[0] == "rtu") {
    if (parts[1].empty()) return "'" + spec + "': no device";
    if (!whole(parts[2], 1, 4000000, p.number) || !libmodbus_sets_baud(p.number))
      return "'" + spec + "': baud rate '" + parts[2] + "' is not one libmodbus sets (a standard rate: ..., 9600, "
             "19200, 38400, 57600, 115200, 230400, ... 4000000; any other runs the line at 9600)";
    if (parts.size() == 4) {
      if (parts[3] != "N" && parts[3] != "E" && parts[3] != "O") return "'" + spec + "': parity is not N, E or O";
      p.parity = parts[3][0];
    }
  } else {
    return "'" + spec + "' is not tcp:HOST:PORT or rtu:DEVICE:BAUD[:PARITY]";
  }
  p.where = parts[1];
  if (out) *out = p;
  return {};
}

ModbusLink::ModbusLink(ModbusEndpoint ep) : ep_(std::move(ep)) {}

ModbusLink::~ModbusLink() { close(); }

void ModbusLink::close() {
  if (ctx_) {
    modbus_close(ctx_);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
}

bool ModbusLink::connect() {
  close();
  EndpointParts p;
  if (const std::string why = parse_endpoint(ep_.spec, &p); !why.empty()) {
    error_ = "bad Modbus endpoint " + why;
    return false;
  }
  ctx_ = p.tcp ? modbus_new_tcp(p.where.c_str(), p.number) : modbus_new_rtu(p.where.c_str(), p.number, p.parity, 8, 1);
  if (!ctx_) {
    error_ = ep_.spec + ": modbus_new: " + modbus_strerror(errno);
    return false;
  }
  const auto fail = [this](const char* what) {
    error_ = ep_.spec + ": " + what + ": " + modbus_strerror(errno);
    modbus_free(ctx_);
    ctx_ = nullptr;
    return false;
  };
  if (modbus_set_slave(ctx_, ep_.slave) != 0) return fail("unit id");
  if (modbus_set_response_timeout(ctx_, static_cast<uint32_t>(ep_.response_timeout_ms / 1000),
                                  static_cast<uint32_t>((ep_.response_timeout_ms % 1000) * 1000)) != 0)
    return fail("response timeout");
  // No time between the bytes of an answer: the response timeout then bounds the whole answer.
  // (libmodbus's default, 500 ms after each chunk, held a read whose answer stopped part-way for
  // half a second, and every stop frame with it.)
  if (modbus_set_byte_timeout(ctx_, 0, 0) != 0) return fail("byte timeout");
  if (modbus_connect(ctx_) != 0) return fail("connect");
  modbus_flush(ctx_);  // whatever a device sent before this connection is not an answer to it
  error_.clear();
  return true;
}

namespace {

// The device answered with one of the exception codes Modbus defines (libmodbus: EMBXILFUN to
// EMBXGTAR). An exception reply whose code is none of them is EMBBADEXC: garbled, not answered.
bool modbus_exception(int e) { return e >= EMBXILFUN && e <= EMBXGTAR; }

// libmodbus's own codes past the exceptions: a bad CRC, unit id, length or exception code.
bool garbled_answer(int e) { return e > EMBXGTAR && e < MODBUS_ENOBASE + 20; }

}  // namespace

ReadResult ModbusLink::classify_failure() {
  const int e = errno;
  error_ = ep_.spec + ": " + modbus_strerror(e);
  // Modbus exceptions keep the link (the device answered); anything else may have lost it.
  if (modbus_exception(e)) return ReadResult::Exception;
  close();  // see the header: a late or garbled answer must not be read as the next one's
  if (e == ETIMEDOUT) return ReadResult::Timeout;
  if (garbled_answer(e)) return ReadResult::BadData;
  return ReadResult::Disconnected;
}

ReadResult ModbusSensor::read(FtReading& out) {
  if (!link_.connected()) return ReadResult::Disconnected;
  uint16_t regs[6];
  const int n = map_.input_registers ? modbus_read_input_registers(link_.ctx(), map_.first_register, 6, regs)
                                     : modbus_read_registers(link_.ctx(), map_.first_register, 6, regs);
  if (n != 6) {
    if (n >= 0) {  // a short answer: as garbled as any
      link_.close();
      return ReadResult::BadData;
    }
    return link_.classify_failure();
  }
  auto scaled = [](uint16_t raw, double s) {
    const double v = static_cast<int16_t>(raw) * s;
    if (v >= 32767.0) return static_cast<int16_t>(32767);
    if (v <= -32768.0) return static_cast<int16_t>(-32768);
    return static_cast<int16_t>(std::lround(v));
  };
  for (int k = 0; k < 3; ++k) {
    out.force[k] = scaled(regs[k], map_.force_scale);
    out.torque[k] = scaled(regs[3 + k], map_.torque_scale);
  }
  return ReadResult::Ok;
}

std::string stop_target_name(const StopTarget& t) {
  return (t.coil ? "coil " : "holding register ") + std::to_string(t.address);
}

ProbeResult RobotStopWriter::probe() {
  if (!link_.connected() && !link_.connect()) return ProbeResult::Failed;
  uint8_t bit = 0;
  uint16_t reg = 0;
  const int rc = target_.coil ? modbus_read_bits(link_.ctx(), target_.address, 1, &bit)
                              : modbus_read_registers(link_.ctx(), target_.address, 1, &reg);
  if (rc == 1) return (target_.coil ? bit != 0 : reg == target_.value) ? ProbeResult::StopSet : ProbeResult::Clear;
  const int e = errno;
  link_.classify_failure();
  return e == EMBXILADD ? ProbeResult::NoSuchTarget : ProbeResult::Failed;
}

bool RobotStopWriter::write_target(bool stop) {
  const uint16_t value = stop ? static_cast<uint16_t>(target_.value) : 0;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!link_.connected() && !link_.connect()) continue;
    const int rc = target_.coil ? modbus_write_bit(link_.ctx(), target_.address, stop ? 1 : 0)
                                : modbus_write_register(link_.ctx(), target_.address, value);
    if (rc == 1) return true;
    link_.classify_failure();
  }
  return false;
}

}  // namespace dressguard::bridge
