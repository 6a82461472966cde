// dressguard-bridge: force-torque sensor (Modbus, or an FT 300's data stream) -> CAN, and CAN
// stop -> robot controller.
#include <sched.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>

#include "bridge_app.h"
#include "candump_log.h"
#include "ft300_stream.h"
#include "notify_socket.h"
#include "rt_setup.h"

using namespace dressguard;
using namespace dressguard::bridge;

namespace {

const char* kUsage =
    "usage: dressguard-bridge [options]\n"
    "  Reads a force-torque sensor over Modbus (default: a Robotiq FT 300, holding registers\n"
    "  180-185, int16, F x 100 and M x 1000, slave 9) at a fixed rate, or an FT 300's own 100 Hz\n"
    "  data stream (rtu-stream:DEVICE), and publishes each reading as the protocol's FtForce +\n"
    "  FtTorque frames on SocketCAN (firmware-bridge/PROTOCOL.md). On a Stop frame it writes a stop\n"
    "  to the robot controller over Modbus. A lost sensor is reconnected with exponential backoff;\n"
    "  meanwhile no sample frames are sent (the predictor's deadline stops the robot).\n"
    "  --interface IF          SocketCAN interface, 1-15 characters (default can0)\n"
    "  --sensor SPEC           rtu-stream:DEVICE (the default, rtu-stream:/dev/ttyUSB0), an FT 300's data\n"
    "                          stream: its line is fixed at 19200 8N1, where polling gives about 60\n"
    "                          readings/s, the stream 100 frames/s (a stream left running is stopped\n"
    "                          first; silent 100 ms: lost, restarted; stopped at exit); or tcp:HOST:PORT\n"
    "                          or rtu:DEVICE:BAUD[:PARITY], read over Modbus every period (HOST a numeric\n"
    "                          IPv4 address, BAUD a standard rate: 9600, 19200, 38400, ...)\n"
    "  --sensor-slave N        Modbus unit id, 1-247 (1-255 on TCP; default 9)\n"
    "  --sensor-register N     first of the six registers (default 180)\n"
    "  --input-registers       read with FC04 instead of FC03\n"
    "  --force-scale S         sensor counts -> 0.01 N counts, 0.0001-10000 (default 1, the FT 300's)\n"
    "  --torque-scale S        sensor counts -> 0.001 Nm counts, 0.0001-10000 (default 1)\n"
    "  --timeout-ms N          Modbus response timeout, 1-1000 (default 20), for the whole answer; a stop\n"
    "                          frame can wait about this long behind a sensor read that gets no answer\n"
    "                          or one cut short (rtu-stream never waits)\n"
    "  --period-ms N           sampling period, 1-100 (default 10: 100 Hz); with rtu-stream the sensor's\n"
    "                          frames set the rate; either way the tick of the heartbeat (every 100 ms),\n"
    "                          the predictor watchdog and a stop's retries\n"
    "  --robot SPEC            robot controller, tcp:HOST:PORT or rtu:... (not the sensor's device; its\n"
    "                          response timeout is 100 ms); none: stops are only logged. Its stop target is\n"
    "                          read once at start: one it lacks exits 2, no answer is a warning\n"
    "  --robot-slave N         its unit id, as --sensor-slave (default 1)\n"
    "  --stop-coil ADDR        write the stop as coil ADDR = ON (default: coil 0); it mirrors the stop\n"
    "                          latch: OFF when the robot's next TrialStart releases it (PROTOCOL.md, Stop)\n"
    "  --stop-register ADDR=V  write the stop as holding register ADDR = V (1-65535) instead, 0 to clear it\n"
    "  --predictor-timeout-ms N  stop the robot when the predictor's heartbeat is silent this long, or\n"
    "                          does not name the robot's running trial (TrialStart to TrialEnd) for this\n"
    "                          long: 0 (off, the default) or 200-60000\n"
    "  --shutdown-grace-ms N   on SIGTERM/SIGINT, a stop not yet written (one on the bus, or the bridge's\n"
    "                          own when the predictor is in a trial) is retried this long (default 1000)\n"
    "  --rt-priority N         SCHED_FIFO priority of the loop, 1-99 (default 70: above the kernel's\n"
    "                          interrupt threads, below the predictor's 80); given, the bridge does not\n"
    "                          start without it (exit 1); the default not had is a warning\n"
    "  --cpu N                 pin the loop to CPU N, 0-1023 (default: any CPU); not had: a warning\n"
    "  --no-rt                 skip the real-time setup (mlockall, SCHED_FIFO, --cpu); by default\n"
    "                          memory is locked (not had: a warning) and the loop runs SCHED_FIFO\n"
    "  --help                  this text\n"
    "Exit codes: 0 clean shutdown (SIGTERM/SIGINT), 1 runtime error, an --rt-priority not had, or a stop\n"
    "still unwritten at the end of the shutdown grace, 2 bad arguments or a NOTIFY_SOCKET that cannot\n"
    "be reached.\n"
    "Signals: SIGTERM and SIGINT shut it down (a running trial's stop written first). SIGHUP and\n"
    "SIGPIPE are ignored from the start on: there is no reload, the options are read at start and a\n"
    "change takes a restart.\n"
    "Service manager: with NOTIFY_SOCKET set (systemd, Type=notify) it sends READY=1 when its loop\n"
    "starts, WATCHDOG=1 every half WATCHDOG_USEC from the loop's timer, and STOPPING=1 when it shuts down.";

int bad(const std::string& why) {
  std::fprintf(stderr, "dressguard-bridge: %s (see --help)\n", why.c_str());
  return 2;
}

// An rtu-stream sensor: its device, and no register map (the stream's frames carry the FT 300's
// six values in its own counts, which are the protocol's).
std::string stream_spec_error(const std::string& spec, const SensorMap& map, std::string* device) {
  if (const std::string why = parse_stream_spec(spec, device); !why.empty()) return why;
  const SensorMap plain;
  if (map.first_register != plain.first_register || map.input_registers || map.force_scale != plain.force_scale ||
      map.torque_scale != plain.torque_scale)
    return "'" + spec + "': the data stream has no register map: --sensor-register, --input-registers, "
           "--force-scale and --torque-scale apply to polling only";
  return {};
}

// Whole-number options and their ranges: Modbus addresses are 16 bits (the six sensor registers
// must fit), unit ids a byte (unit_id_error then holds them to their line), and a response
// timeout beyond a second is no sampling of a 100 Hz sensor. The period is also the loop's tick,
// which sends the heartbeat (PROTOCOL.md: 10 Hz), judges the predictor's silence and retries a
// stop's write: beyond 100 ms the heartbeat comes late and a stop waits a period per retry.
struct Range { const char* name; long lo, hi; };
constexpr Range kRanges[] = {
    {"--sensor-slave", 0, 255},   {"--sensor-register", 0, 65530}, {"--timeout-ms", 1, 1000},
    {"--period-ms", 1, 100},      {"--robot-slave", 0, 255},       {"--stop-coil", 0, 65535},
    {"--predictor-timeout-ms", 0, 60000}, {"--shutdown-grace-ms", 0, 60000},
    {"--rt-priority", 1, 99},     {"--cpu", 0, CPU_SETSIZE - 1},
};
constexpr const char* kTextOptions[] = {"--interface", "--sensor", "--robot", "--force-scale", "--torque-scale",
                                        "--stop-register"};

const Range* range_of(const std::string& a) {
  for (const auto& k : kRanges)
    if (a == k.name) return &k;
  return nullptr;
}

bool takes_value(const std::string& a) {
  for (const char* k : kTextOptions)
    if (a == k) return true;
  return range_of(a) != nullptr;
}

bool to_int(const std::string& s, long& v) {
  char* end = nullptr;
  errno = 0;
  v = std::strtol(s.c_str(), &end, 10);
  return !s.empty() && end && *end == '\0' && errno == 0;
}

// A sensor-count scale: finite, in [1e-4, 1e4] (inf made a zero count NaN; 1e-300 made every
// force 0, and the predictor's hard limit could never fire). NaN fails the comparisons.
bool sane_scale(double s) { return s >= 1e-4 && s <= 1e4; }

// The least --predictor-timeout-ms besides 0 (off): two of the predictor's 100 ms heartbeats.
// A shorter one stops the robot whenever a heartbeat comes a little late.
constexpr long kLeastPredictorTimeoutMs = 200;

// Why `option`'s unit id cannot address a device on `line` (null: no such link), or "". 0 is
// Modbus's broadcast: no device answers it, so a read never gets an answer and a stop is never
// confirmed (its latch would never release); a serial line's ids end at 247 (libmodbus refuses
// the rest at every connect, forever).
std::string unit_id_error(const char* option, int id, const EndpointParts* line) {
  if (id == 0)
    return std::string(option) + ": 0 is the broadcast address: no device answers it (give the device's unit id)";
  if (line && !line->tcp && id > 247) return std::string(option) + ": " + std::to_string(id) + " is not in 1-247, "
                                             "the unit ids of a serial line";
  return {};
}

// Two endpoints on one serial device (also under another name, e.g. a /dev/serial/by-id link).
bool same_serial_device(const EndpointParts& a, const EndpointParts& b) {
  if (a.tcp || b.tcp) return false;
  if (a.where == b.where) return true;
  struct stat sa {}, sb {};
  return stat(a.where.c_str(), &sa) == 0 && stat(b.where.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

// The robot's link, tried once at start, before the CAN socket is opened and the loop runs: a
// target the controller does not have is refused (every stop would fail on it, found when an arm
// is caught); a controller that does not answer is said, not refused (it may not be powered
// yet); a stop already set is said too. 0, or 2 when refused.
int probe_robot(RobotStopWriter& robot, const StopTarget& target) {
  const std::string what = stop_target_name(target);
  const char* option = target.coil ? "--stop-coil" : "--stop-register";
  const ProbeResult said = robot.probe();
  const std::string& why = robot.link().last_error();
  switch (said) {
    case ProbeResult::NoSuchTarget:
      return bad(std::string(option) + ": the robot controller has no " + what + " (" + why + ")");
    case ProbeResult::Failed:
      std::fprintf(stderr,
                   "dressguard-bridge: warning: the robot controller did not answer a read of its %s (%s): it may "
                   "not be powered yet; until it answers, a stop cannot reach it\n",
                   what.c_str(), why.c_str());
      break;
    case ProbeResult::StopSet:
      std::fprintf(stderr, "dressguard-bridge: warning: the robot controller's %s (%s) says stop already, left from "
                   "an earlier run: the robot's next TrialStart clears it\n", what.c_str(),
                   robot.link().endpoint().spec.c_str());
      break;
    case ProbeResult::Clear: break;
  }
  return 0;
}

// The loop's real-time setup, before the CAN socket is opened and the loop runs: what is not had
// is said (the bridge still carries samples and stops, only with less margin), except a priority
// the command line asked for: 0, or 1 when that priority is not had.
int setup_loop_realtime(const RtRequest& request) {
  const RtOutcome had = setup_realtime(request);
  for (const std::string& why : had.warnings)
    std::fprintf(stderr, "dressguard-bridge: warning: real-time setup: %s\n", why.c_str());
  if (had.refusal.empty()) return 0;
  std::fprintf(stderr, "dressguard-bridge: --rt-priority %d: %s: not starting without it (--no-rt runs without "
               "real-time setup)\n", request.fifo_priority, had.refusal.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  // First: a SIGHUP or SIGPIPE at any later step of the start-up must not end the bridge (SIGTERM
  // and SIGINT keep their default action until the loop takes them: no stop is pending before it).
  ignore_hangup_and_broken_pipe();
  std::string iface = "can0", robot_spec;
  ModbusEndpoint sensor_ep, robot_ep;
  // The default sensor is the FT 300 on its fixed 19200 8N1 line: its data stream is the one way
  // to its 100 Hz (polling it gives about 60 readings/s, and every missed period is a lost sample).
  sensor_ep.spec = "rtu-stream:/dev/ttyUSB0";
  robot_ep.slave = 1;
  robot_ep.response_timeout_ms = 100;
  SensorMap map;
  StopTarget target;
  BridgeAppConfig cfg;
  RtRequest rt;
  bool no_rt = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::puts(kUsage);
      return 0;
    }
    if (a == "--input-registers") {
      map.input_registers = true;
      continue;
    }
    if (a == "--no-rt") {
      no_rt = true;
      continue;
    }
    if (!takes_value(a)) return bad("unknown option '" + a + "'");
    if (i + 1 >= argc) return bad(a + " needs a value");
    const std::string v = argv[++i];
    long n = 0;
    const bool is_int = to_int(v, n);
    if (a == "--interface") {
      if (const char* why = protocol::interface_name_error(v)) return bad("--interface: '" + v + "': " + why);
      iface = v;
    } else if (a == "--sensor") sensor_ep.spec = v;
    else if (a == "--robot") robot_spec = v;
    else if (a == "--force-scale" || a == "--torque-scale") {
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      if (!end || *end || !sane_scale(d)) return bad(a + ": '" + v + "' is not a number in 0.0001-10000");
      (a == "--force-scale" ? map.force_scale : map.torque_scale) = d;
    } else if (a == "--stop-register") {
      const auto eq = v.find('=');
      long addr = 0, val = 0;
      if (eq == std::string::npos || !to_int(v.substr(0, eq), addr) || !to_int(v.substr(eq + 1), val) || addr < 0 ||
          addr > 65535 || val < 0 || val > 65535)
        return bad("--stop-register: '" + v + "' is not ADDR=VALUE");
      // 0 is what the bridge writes when a TrialStart releases the stop: a stop of 0 would never show.
      if (val == 0) return bad("--stop-register: '" + v + "': the value 0 clears the stop (give 1-65535)");
      target = {false, static_cast<int>(addr), static_cast<int>(val)};
    } else {
      const Range* r = range_of(a);
      if (!is_int || n < r->lo || n > r->hi)
        return bad(a + ": '" + v + "' is not a whole number in " + std::to_string(r->lo) + "-" + std::to_string(r->hi));
      if (a == "--sensor-slave") sensor_ep.slave = static_cast<int>(n);
      else if (a == "--sensor-register") map.first_register = static_cast<int>(n);
      else if (a == "--timeout-ms") sensor_ep.response_timeout_ms = static_cast<int>(n);
      else if (a == "--period-ms") cfg.sample_period_ms = static_cast<int>(n);
      else if (a == "--robot-slave") robot_ep.slave = static_cast<int>(n);
      else if (a == "--stop-coil") target = {true, static_cast<int>(n), 1};
      else if (a == "--shutdown-grace-ms") cfg.shutdown_grace_ms = static_cast<int>(n);
      else if (a == "--rt-priority") {
        rt.fifo_priority = static_cast<int>(n);
        rt.priority_required = true;
      } else if (a == "--cpu") rt.cpu = static_cast<int>(n);
      else if (n != 0 && n < kLeastPredictorTimeoutMs)
        return bad(a + ": '" + v + "' is neither 0 (off) nor at least 200 (two of the predictor's 100 ms heartbeats)");
      else cfg.core.predictor_timeout_ms = static_cast<uint32_t>(n);
    }
  }
  // --no-rt beside a priority or a CPU asks for both: which one was meant is not for the bridge to guess.
  if (no_rt && (rt.priority_required || rt.cpu >= 0))
    return bad(std::string("--no-rt skips the real-time setup: ") + (rt.priority_required ? "--rt-priority" : "--cpu") +
               " cannot be given with it");
  // Both endpoints are checked now, not when the first stop must go out.
  EndpointParts sensor_parts;
  std::string stream_device;
  const bool stream = is_stream_spec(sensor_ep.spec);
  if (const std::string why = stream ? stream_spec_error(sensor_ep.spec, map, &stream_device)
                                     : parse_endpoint(sensor_ep.spec, &sensor_parts);
      !why.empty())
    return bad("--sensor: " + why);
  // The stream's line, for the checks below (its unit id, a --robot on the same device).
  if (stream) sensor_parts = EndpointParts{false, stream_device, ft300::kBaud, 'N'};
  // A serial line too slow for the period: every reading overruns the timer, and the sample
  // counter (it counts periods) tells the predictor of a lost sample after each.
  if (const double line_ms = stream ? 0.0 : rtu_reading_ms(sensor_parts); line_ms > cfg.sample_period_ms)
    std::fprintf(stderr,
                 "dressguard-bridge: warning: at %d baud one reading takes at least %.1f ms on the line, more "
                 "than --period-ms %d: the periods between readings carry no sample, and the predictor counts "
                 "them as lost (its bad-frame budget stops a trial; an FT 300's line is fixed at 19200 baud: "
                 "--sensor rtu-stream:DEVICE reads its 100 Hz stream)\n",
                 sensor_parts.number, line_ms, cfg.sample_period_ms);
  EndpointParts robot_parts;
  if (!robot_spec.empty())
    if (const std::string why = parse_endpoint(robot_spec, &robot_parts); !why.empty()) return bad("--robot: " + why);
  if (!robot_spec.empty() && same_serial_device(sensor_parts, robot_parts))
    return bad("--robot: '" + robot_parts.where + "' is the --sensor's serial device too (one line, two links)");
  for (const std::string& why :
       {unit_id_error("--sensor-slave", sensor_ep.slave, &sensor_parts),
        unit_id_error("--robot-slave", robot_ep.slave, robot_spec.empty() ? nullptr : &robot_parts)})
    if (!why.empty()) return bad(why);
  // Both are right for a bridge that only records; on a robot each leaves a way unguarded, so the
  // bridge says so once at start rather than only at the first stop.
  if (robot_spec.empty())
    std::fprintf(stderr,
                 "dressguard-bridge: warning: no --robot: a Stop frame is only logged, not written to the robot "
                 "controller (it must then act on CAN 0x080 itself)\n");
  if (cfg.core.predictor_timeout_ms == 0)
    std::fprintf(stderr,
                 "dressguard-bridge: warning: --predictor-timeout-ms 0: a predictor that goes silent or misses a "
                 "trial does not stop the robot (a deployment sets it, e.g. 300)\n");
  // Under systemd's Type=notify the unit is started when the loop runs, and WatchdogSec= restarts
  // a loop that stops (notify_socket.h). A manager that cannot be told is the deployment's error
  // (a unit without AF_UNIX): exit 2 now, not a start that times out and restarts for ever.
  service::NotifySocket notify = service::NotifySocket::from_environment();
  if (notify.requested() && !notify.connected()) {
    std::fprintf(stderr, "dressguard-bridge: %s\n", notify.error().c_str());
    return 2;
  }
  if (!notify.error().empty()) std::fprintf(stderr, "dressguard-bridge: warning: %s\n", notify.error().c_str());
  // A ping goes out at the first tick after it is due, and one tick can wait on the devices: a
  // connect and a read of the sensor, a connect and a write of the robot, each up to its response
  // timeout. The manager's limit (twice the ping period) holds only while that wait is shorter
  // than a ping period; past it a slow device, not a hung loop, would have the bridge killed.
  if (const int64_t ping_ms = notify.watchdog_period_ns() / 1000000; ping_ms > 0) {
    const int64_t longest_ms = 2 * int64_t{stream ? 0 : sensor_ep.response_timeout_ms} +
                               2 * int64_t{robot_spec.empty() ? 0 : robot_ep.response_timeout_ms} + cfg.sample_period_ms;
    if (longest_ms >= ping_ms)
      std::fprintf(stderr,
                   "dressguard-bridge: warning: one loop period can wait %lld ms on the sensor and the robot "
                   "(connect and answer, each up to its response timeout), not less than the watchdog's ping "
                   "period of %lld ms: set WatchdogSec= to more than %lld ms or shorten --timeout-ms, or slow "
                   "devices will have the service manager kill the bridge\n",
                   static_cast<long long>(longest_ms), static_cast<long long>(ping_ms),
                   static_cast<long long>(2 * longest_ms));
  }
  std::unique_ptr<RobotStopWriter> robot;
  if (!robot_spec.empty()) {
    robot_ep.spec = robot_spec;
    robot = std::make_unique<RobotStopWriter>(robot_ep, target);
    if (const int rc = probe_robot(*robot, target); rc != 0) return rc;
  }
  if (!no_rt)
    if (const int rc = setup_loop_realtime(rt); rc != 0) return rc;
  try {
    can::PortOptions opt;
    opt.ids.assign(std::begin(kBridgeReceives), std::end(kBridgeReceives));
    auto port = can::open_socketcan(iface, opt);
    std::unique_ptr<Sensor> sensor;
    Ft300Stream* ft300 = nullptr;  // to stop its stream at the end
    if (stream) {
      auto s = std::make_unique<Ft300Stream>(Ft300StreamConfig{stream_device, sensor_ep.slave});
      ft300 = s.get();
      sensor = std::move(s);
    } else {
      sensor = std::make_unique<ModbusSensor>(sensor_ep, map);
    }
    cfg.service = &notify;
    BridgeApp app(cfg, *sensor, robot.get(), *port);
    handle_signals(&app);
    if (stream)
      std::fprintf(stderr, "dressguard-bridge: %s -> %s, every frame\n", sensor_ep.spec.c_str(), iface.c_str());
    else
      std::fprintf(stderr, "dressguard-bridge: %s -> %s every %d ms\n", sensor_ep.spec.c_str(), iface.c_str(),
                   cfg.sample_period_ms);
    const int rc = app.run();
    handle_signals(nullptr);
    // After the robot's stop (run() wrote it): the sensor is left answering Modbus.
    if (ft300 && !ft300->stop_stream(1000))
      std::fprintf(stderr, "dressguard-bridge: warning: the FT 300's stream may still run: %s\n",
                   ft300->last_error().c_str());
    const auto& s = app.stats();
    std::fprintf(stderr,
                 "dressguard-bridge: readings=%llu frames=%llu send_failures=%llu sensor_errors=%llu reconnects=%llu "
                 "stops_written=%llu stop_write_failures=%llu releases_written=%llu release_write_failures=%llu "
                 "overruns=%llu (%llu periods) receive_failures=%llu error_frames=%llu\n",
                 (unsigned long long)s.readings.load(), (unsigned long long)s.frames_sent.load(),
                 (unsigned long long)s.send_failures.load(), (unsigned long long)s.sensor_errors.load(),
                 (unsigned long long)s.reconnects.load(), (unsigned long long)s.stops_written.load(),
                 (unsigned long long)s.stop_write_failures.load(), (unsigned long long)s.releases_written.load(),
                 (unsigned long long)s.release_write_failures.load(), (unsigned long long)s.overruns.load(),
                 (unsigned long long)s.periods_overrun.load(), (unsigned long long)s.receive_failures.load(),
                 (unsigned long long)s.error_frames.load());
    if (notify.failed_sends() > 0)
      std::fprintf(stderr, "dressguard-bridge: service manager: %llu notifications not sent (the last: %s)\n",
                   static_cast<unsigned long long>(notify.failed_sends()), std::strerror(notify.last_errno()));
    if (ft300)
      std::fprintf(stderr, "dressguard-bridge: stream frames=%llu crc_failures=%llu resyncs=%llu skipped_bytes=%llu\n",
                   (unsigned long long)ft300->stats().frames.load(),
                   (unsigned long long)ft300->stats().crc_failures.load(),
                   (unsigned long long)ft300->stats().resyncs.load(),
                   (unsigned long long)ft300->stats().skipped_bytes.load());
    return rc;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dressguard-bridge: %s\n", e.what());
    return 1;
  }
}
