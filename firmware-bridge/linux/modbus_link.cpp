// libmodbus connections of the bridge's Linux port.
#include "modbus_link.h"

#include <modbus.h>

#include <cerrno>
#include <cmath>
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
  }
  return "unknown";
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
  std::vector<std::string> parts;
  std::stringstream in(ep_.spec);
  std::string tok;
  while (std::getline(in, tok, ':')) parts.push_back(tok);
  if (parts.size() >= 3 && parts[0] == "tcp") {
    ctx_ = modbus_new_tcp(parts[1].c_str(), std::stoi(parts[2]));
  } else if (parts.size() >= 3 && parts[0] == "rtu") {
    const char parity = parts.size() >= 4 && !parts[3].empty() ? parts[3][0] : 'N';
    ctx_ = modbus_new_rtu(parts[1].c_str(), std::stoi(parts[2]), parity, 8, 1);
  } else {
    error_ = "bad Modbus endpoint '" + ep_.spec + "' (expected tcp:HOST:PORT or rtu:DEVICE:BAUD[:PARITY])";
    return false;
  }
  if (!ctx_) {
    error_ = std::string("modbus_new: ") + modbus_strerror(errno);
    return false;
  }
  modbus_set_slave(ctx_, ep_.slave);
  modbus_set_response_timeout(ctx_, static_cast<uint32_t>(ep_.response_timeout_ms / 1000),
                              static_cast<uint32_t>((ep_.response_timeout_ms % 1000) * 1000));
  if (modbus_connect(ctx_) != 0) {
    error_ = ep_.spec + ": " + modbus_strerror(errno);
    modbus_free(ctx_);
    ctx_ = nullptr;
    return false;
  }
  error_.clear();
  return true;
}

ReadResult ModbusLink::classify_failure() {
  const int e = errno;
  error_ = ep_.spec + ": " + modbus_strerror(e);
  // Modbus exceptions keep the link (the device answered); anything else may have lost it.
  if (e > MODBUS_ENOBASE && e < MODBUS_ENOBASE + 20 && e != EMBBADDATA && e != EMBBADCRC && e != EMBBADSLAVE)
    return ReadResult::Exception;
  if (e == ETIMEDOUT) return ReadResult::Timeout;
  if (e == EMBBADDATA || e == EMBBADCRC || e == EMBBADSLAVE || e == EMBBADEXC || e == EMBUNKEXC) {
    // A garbled answer: flush and keep the link.
    modbus_flush(ctx_);
    return ReadResult::BadData;
  }
  close();
  return ReadResult::Disconnected;
}

ReadResult ModbusSensor::read(FtReading& out) {
  if (!link_.connected()) return ReadResult::Disconnected;
  uint16_t regs[6];
  const int n = map_.input_registers ? modbus_read_input_registers(link_.ctx(), map_.first_register, 6, regs)
                                     : modbus_read_registers(link_.ctx(), map_.first_register, 6, regs);
  if (n != 6) {
    if (n >= 0) return ReadResult::BadData;
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

bool RobotStopWriter::write_stop() {
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!link_.connected() && !link_.connect()) continue;
    const int rc = target_.coil ? modbus_write_bit(link_.ctx(), target_.address, 1)
                                : modbus_write_register(link_.ctx(), target_.address, static_cast<uint16_t>(target_.value));
    if (rc == 1) return true;
    link_.classify_failure();
  }
  return false;
}

}  // namespace dressguard::bridge
