// dressguard-predictor: the real-time predictor daemon. See predictor/README.md.
#include <net/if.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <string>
#include <vector>

#include "daemon.h"
#include "dgm.h"
#include "notify_socket.h"

using namespace dressguard;
using namespace dressguard::predictor;

namespace {

const char* kUsage =
    "usage: dressguard-predictor [--config FILE] [--interface IF] [--model MODEL.dgm] [options]\n"
    "  Runs the outcome HMMs' forward filter on the F/T samples of a CAN bus and sends a stop\n"
    "  frame when 'caught' becomes likely, the force exceeds the hard limit, or the sensor fails.\n"
    "  --config FILE        key = value file (see predictor/daemon/dressguard-predictor.conf)\n"
    "  --interface IF       SocketCAN interface (default can0; config key 'interface')\n"
    "  --model FILE         outcome model (.dgm); one that does not load refuses every trial\n"
    "  --set KEY=VALUE      override one config key (repeatable)\n"
    "  --no-rt              skip mlockall, SCHED_FIFO and CPU affinity\n"
    "  --latency-report     print the processing-latency histogram summary at exit\n"
    "  --help               this text\n"
    "Config keys: interface, model, rt_priority (80; 0 = none), cpu (-1), mlock (1), rt_required (0;\n"
    "1: a real-time step that fails ends the daemon, exit 1), tick_ms (1), log_level (info), and the\n"
    "predictor's: stop_threshold, stop_consecutive, hard_limit_n, sensor_timeout_ms, bad_frame_budget,\n"
    "bad_frame_weight, max_delta_counter, status_period_ms, heartbeat_period_ms, posteriors_period_ms,\n"
    "stop_retry_ms, sample_period_ms, acceleration_m_s2, mount_axes, mount_bias.\n"
    "Signals: SIGTERM and SIGINT shut down (a running trial is stopped first); SIGHUP and SIGPIPE are\n"
    "ignored from the start on: the config and model are read at start only, a change takes a restart.\n"
    "Service manager: with NOTIFY_SOCKET set (systemd, Type=notify) it sends READY=1 when it listens,\n"
    "WATCHDOG=1 every half WATCHDOG_USEC from its loop's ticks, and STOPPING=1 when it shuts down.\n"
    "Exit codes: 0 clean shutdown (SIGTERM/SIGINT), 1 runtime error (the interface gone, a stop not\n"
    "confirmed on the bus when the daemon exited, a real-time step failed with rt_required = 1),\n"
    "2 bad arguments or config, or a NOTIFY_SOCKET that cannot be reached.";

std::string read_text(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error(path + ": cannot open (" + std::strerror(errno) + ")");
  std::string s;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  const bool failed = std::ferror(f);
  const int err = errno;
  std::fclose(f);
  if (failed) throw std::runtime_error(path + ": cannot read (" + std::strerror(err) + ")");  // a folder, say
  return s;
}

// The model named by a config entry. A relative path in the file is the file's neighbour: under
// systemd the working directory is /, so read against it the same file named another model by
// hand than under the unit (none: every trial refused). One on --set is the shell's, as --model's.
std::string model_path_of(const ConfigEntry& e, const std::string& config_path) {
  const std::filesystem::path model(e.value);
  const bool in_file = !config_path.empty() && e.where.rfind(config_path + ":", 0) == 0;
  if (!in_file || e.value.empty() || model.is_absolute()) return e.value;
  return (std::filesystem::path(config_path).parent_path() / model).string();
}

// A SocketCAN interface name as the kernel takes it, 1 to IFNAMSIZ - 1 characters; else an
// error naming `what`. An empty one failed only at the socket (exit 1, a runtime error the unit
// restarts), and a longer one was cut short and could name another interface.
std::string interface_name(const std::string& what, const std::string& name) {
  if (!name.empty() && name.size() < IFNAMSIZ) return name;
  throw std::runtime_error(what + ": '" + name + "' is not an interface name (1 to " + std::to_string(IFNAMSIZ - 1) +
                           " characters)");
}

// The real-time setup, each failed step logged. False when one failed and `required` (the
// config's rt_required): a predictor that would run without the real time it was deployed with
// (a unit that lost its capabilities) ends before it listens, rather than with a warning.
bool realtime_ready(const RtOptions& rt, bool required, spdlog::logger& log) {
  const auto failures = setup_realtime(rt);
  const auto level = required ? spdlog::level::critical : spdlog::level::warn;
  for (const auto& f : failures) log.log(level, "real-time setup: {}", f);
  if (!required || failures.empty()) return true;
  log.critical("rt_required = 1: not starting without real time (--no-rt skips the setup)");
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  // First: a SIGHUP or SIGPIPE at any later step of the start-up must not end the daemon (SIGTERM
  // and SIGINT keep their default action until the loop takes them: no trial runs before it).
  ignore_hangup_and_broken_pipe();
  std::string config_path, iface_arg, model_arg;
  bool iface_given = false;
  std::vector<std::string> sets;
  bool no_rt = false, latency_report = false, rt_required = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "dressguard-predictor: %s needs a value (see --help)\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::puts(kUsage);
      return 0;
    } else if (a == "--config") {
      config_path = value();
    } else if (a == "--interface") {
      iface_arg = value();
      iface_given = true;
    } else if (a == "--model") {
      model_arg = value();
    } else if (a == "--set") {
      sets.push_back(value());
    } else if (a == "--no-rt") {
      no_rt = true;
    } else if (a == "--latency-report") {
      latency_report = true;
    } else {
      std::fprintf(stderr, "dressguard-predictor: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }

  auto log = spdlog::stderr_color_mt("predictor");
  log->set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");

  PredictorConfig cfg;
  std::string iface = "can0", model_path;
  RtOptions rt;
  DaemonOptions dopt;
  try {
    // The file, then the --set lines: later entries win; errors name the file's line or "--set N".
    std::vector<ConfigEntry> others;
    cfg = parse_config_with_sets(config_path.empty() ? std::string() : read_text(config_path), config_path, sets,
                                 &others);
    for (const auto& e : others) {
      const std::string& where = e.where;
      auto integer = [&](long lo, long hi) { return config_whole_number(e, lo, hi); };
      if (e.key == "interface") iface = interface_name(where + ": interface", e.value);
      else if (e.key == "model") model_path = model_path_of(e, config_path);
      else if (e.key == "rt_priority") rt.fifo_priority = static_cast<int>(integer(0, 99));
      else if (e.key == "cpu") rt.cpu = static_cast<int>(integer(-1, 4095));
      else if (e.key == "mlock") rt.lock_memory = integer(0, 1) != 0;
      else if (e.key == "rt_required") rt_required = integer(0, 1) != 0;
      else if (e.key == "tick_ms") dopt.tick_ns = integer(1, max_tick_ms(cfg)) * 1000000;
      else if (e.key == "log_level") {
        // spdlog turns a name it does not know into "off": a typo would silence every error.
        const auto level = spdlog::level::from_str(e.value);
        if (level == spdlog::level::off && e.value != "off")
          throw std::runtime_error(where + ": log_level: '" + e.value +
                                   "' is not trace, debug, info, warn, error, critical or off");
        log->set_level(level);
      } else throw std::runtime_error(where + ": unknown key '" + e.key + "'");
    }
    if (iface_given) iface = interface_name("--interface", iface_arg);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dressguard-predictor: %s\n", e.what());
    return 2;
  }
  if (!model_arg.empty()) model_path = model_arg;
  if (dopt.tick_ns <= 0) {
    std::fprintf(stderr, "dressguard-predictor: tick_ms must be >= 1\n");
    return 2;
  }

  // A model that does not load is not a reason to exit: the daemon stays up and refuses every
  // trial with a ModelError stop, so the robot cannot run unguarded.
  std::unique_ptr<model::OutcomeModel> model;
  std::vector<std::string> names;
  if (model_path.empty()) {
    log->error("no model configured: every trial will be stopped (model_error)");
  } else {
    try {
      model = std::make_unique<model::OutcomeModel>(model::read_model(model_path));
      for (const auto& c : model->classes) names.push_back(c.name);
      if (model->class_index("caught") < 0) throw model::ModelError(model_path + ": no class named 'caught'");
      log->info("model {}: {} classes, stop when P(caught) > {} for {} samples", model_path, names.size(),
                model->stop_threshold, model->stop_consecutive);
    } catch (const std::exception& e) {
      log->error("model did not load: {}; every trial will be stopped (model_error)", e.what());
      model.reset();
    }
  }
  // A model trained at another sensor rate is the deployer's error, as a bad config is: exit 2
  // before listening (a model that does not load is the robot's, and keeps the daemon up).
  if (model) {
    const predictor::PeriodCheck period = predictor::check_model_period(*model, model_path, cfg.sample_period_s);
    if (period.verdict == predictor::PeriodVerdict::Differs) {
      std::fprintf(stderr, "dressguard-predictor: %s\n", period.message.c_str());
      return 2;
    }
    if (period.verdict == predictor::PeriodVerdict::Unknown) log->warn("{}", period.message);
  }

  // Under systemd's Type=notify the unit is started when the loop runs, and WatchdogSec= restarts
  // a loop that stops ticking (notify_socket.h).
  service::NotifySocket notify = service::NotifySocket::from_environment();
  if (notify.requested() && !notify.connected()) {
    // The manager would never hear READY=1: a start that times out and restarts for ever. The
    // deployment's error (a unit without AF_UNIX), as a bad config is: exit 2, not restarted.
    std::fprintf(stderr, "dressguard-predictor: %s\n", notify.error().c_str());
    return 2;
  }
  if (!notify.error().empty()) log->warn("{}", notify.error());
  if (notify.connected())
    log->info("service manager notified (ready at the loop's start{})",
              notify.watchdog_period_ns() > 0
                  ? ", watchdog ping every " + std::to_string(notify.watchdog_period_ns() / 1000000) + " ms"
                  : std::string());
  dopt.service = &notify;

  try {
    static EventQueue events;  // 4096 events: static storage, not on the stack
    EventLogger logger(events, log, names, &notify);  // before the RT setup: it must not inherit SCHED_FIFO
    // Before the sockets: with rt_required, a step that fails ends the daemon before it listens.
    if (!no_rt && !realtime_ready(rt, rt_required, *log)) return 1;
    can::PortOptions rx_opt;
    rx_opt.ids = PredictorDaemon::receive_ids();
    rx_opt.receive_buffer = 1 << 20;  // ~1.5 s of a saturated 1 Mbit/s bus: a late thread loses nothing
    can::PortOptions stop_opt;
    stop_opt.ids = {protocol::id_of(protocol::MsgId::Stop)};
    stop_opt.receive_own = true;
    // Controller error frames come to every socket that asks: only the receive socket does, so
    // that one bus-off is counted and logged once.
    stop_opt.error_frames = false;
    auto rx = can::open_socketcan(iface, rx_opt);
    auto stop_port = can::open_socketcan(iface, stop_opt);
    if (rx->receive_buffer() < rx_opt.receive_buffer)
      log->warn("receive buffer {} bytes, not the {} asked: a late loop thread loses frames sooner; grant "
                "CAP_NET_ADMIN (SO_RCVBUFFORCE) or raise net.core.rmem_max",
                rx->receive_buffer(), rx_opt.receive_buffer);
    PredictorDaemon daemon(model.get(), cfg, *rx, *stop_port, events, dopt);
    handle_signals(&daemon);
    // The unit's status line until the first trial (the logging thread keeps it from then on).
    // At most 1000 bytes: systemd drops a message of 4096 or more (a model path may be long).
    notify.notify(("STATUS=listening on " + iface +
                   (model ? ", model " + model_path : std::string(", no model: every trial refused")))
                      .substr(0, 1000)
                      .c_str());
    log->info("listening on {} (threshold {}, k {}, hard limit {} N, sensor timeout {} ms)", iface,
              daemon.predictor().threshold(), daemon.predictor().consecutive(), cfg.hard_limit_n,
              cfg.sensor_timeout_ns / 1000000);
    int rc = daemon.run();
    handle_signals(nullptr);
    logger.stop();
    if (daemon.predictor().stop_pending()) {
      const auto& d = daemon.predictor().decision();
      log->error("the stop of trial {} ({}) was not confirmed on the bus when the daemon exited: the robot may not be "
                 "stopped", d.trial, protocol::stop_reason_name(d.reason));
      rc = 1;
    }
    std::string counters;
    for (int c = 0; c < static_cast<int>(protocol::StatusCounter::Count); ++c)
      counters += std::string(c ? " " : "") + protocol::status_counter_name(static_cast<protocol::StatusCounter>(c)) + "=" +
                  std::to_string(daemon.predictor().counter(static_cast<protocol::StatusCounter>(c)));
    // Not a status counter (the status pages have no free field): reported here only.
    counters += " speed_outside_training=" + std::to_string(daemon.predictor().trials_outside_training_speeds());
    log->info("shutting down: {}", counters);
    // Off the loop: it only counts (a full manager queue loses a ping, not the loop its time).
    if (notify.failed_sends() > 0)
      log->warn("service manager: {} notifications not sent (the last: {})", notify.failed_sends(),
                std::strerror(notify.last_errno()));
    if (latency_report) {
      const auto& h = daemon.processing();
      const auto& hs = daemon.processing_with_stop();
      log->info("processing latency (frame read to decision): n={} median={} ns p99.9={} ns max={} ns, {} at or "
                "beyond {} ns", h.count(), h.quantile(0.5), h.quantile(0.999), h.max(), h.overflow(), h.range_ns());
      log->info("processing latency with the stop frame sent: n={} median={} ns max={} ns, {} at or beyond {} ns",
                hs.count(), hs.quantile(0.5), hs.max(), hs.overflow(), hs.range_ns());
    }
    log->flush();
    return rc;
  } catch (const std::exception& e) {
    log->critical("{}", e.what());
    return 1;
  }
}
