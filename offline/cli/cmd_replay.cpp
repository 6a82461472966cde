// dressguard replay: the predictor daemon's own code (predictor/core) run over a candump log.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>

#include "args.h"
#include "commands.h"
#if __has_include("replay.h")  // predictor/core is built once predictor/filter and models/ exist
#include "candump_log.h"
#include "dgm.h"
#include "files.h"
#include "json.h"
#include "replay.h"

namespace dressguard::cli {
namespace {

const char* kHelp =
    "usage: dressguard replay --model MODEL.dgm (--log FILE.log | --logs DIR) [--config FILE] [--set KEY=VALUE] [--json]\n"
    "  Runs the predictor daemon's code (E2E checks, forward filter, stop policy, deadlines) on a\n"
    "  candump log without a bus and prints whether and when it would stop the robot, and why.\n"
    "  --model MODEL.dgm  outcome model; a model that does not load is reported (exit 2) unless\n"
    "                     --allow-model-error is given, which replays as the daemon would run\n"
    "                     without a model (every trial refused)\n"
    "  --log FILE.log     candump -l log (as written by candump or `dressguard export-candump`)\n"
    "  --logs DIR         every *.log in DIR, in name order, and a table of the stops per outcome:\n"
    "                     a name ending in -good.log, -missed.log or -caught.log (as export-candump\n"
    "                     --data names them) is that outcome, any other is 'unlabelled'. What a\n"
    "                     stop policy costs (good and missed pulls stopped) against what it buys\n"
    "                     (caught pulls stopped, and how long before their own end)\n"
    "  --config FILE      the daemon's config file (its predictor keys and tick_ms; the daemon's\n"
    "                     other keys are ignored)\n"
    "  --set KEY=VALUE    override one predictor key, after --config's; repeat it for several,\n"
    "                     e.g. --set stop_threshold=0.99 --set stop_consecutive=10\n"
    "  --tick-ms N        the daemon's timer period [ms] (default: the config's tick_ms, else 1;\n"
    "                     1..sensor_timeout_ms, as in the daemon)\n"
    "  --json             {stopped, stop_time, travel, reason, posteriors at the stop, ...}\n"
    "  Times are logical: stop_time = the deciding sample's index x the sample period; travel is\n"
    "  the commanded travel at that time (TrialStart's speed, the configured acceleration).";

std::vector<protocol::LoggedFrame> load_log(const std::string& path) {
  try {
    return protocol::parse_candump_log(read_file(path), path);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

// The outcome a log's file name carries ("<id>-<label>.log", export-candump --data's naming).
std::string label_of(const std::filesystem::path& log) {
  const std::string stem = log.stem().string();
  for (const char* l : {"good", "missed", "caught"}) {
    const std::string tail = std::string("-") + l;
    if (stem.size() > tail.size() && stem.compare(stem.size() - tail.size(), tail.size(), tail) == 0) return l;
  }
  return "unlabelled";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// One outcome's row of the --logs table. A stop's lead is the time from the deciding sample to
// the trial's last sample (for a caught trial: how long before its own end, the rig's 10 N stop).
struct StopTally {
  int logs = 0, trials = 0, caught_stops = 0, other_stops = 0;
  std::vector<double> travel, lead;
};

// --logs DIR: every log of the folder through `replay`, one line each, then the stops per outcome.
int replay_folder(const std::string& dir,
                  const std::function<predictor::ReplayResult(const std::vector<protocol::LoggedFrame>&)>& replay,
                  double sample_period_s, bool json) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) throw InputError(dir + ": not a folder of candump logs");
  std::vector<fs::path> logs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".log") logs.push_back(e.path());
  if (logs.empty()) throw InputError(dir + ": no *.log file in it");
  std::sort(logs.begin(), logs.end());
  std::map<std::string, StopTally> tally;
  std::string json_logs;
  for (const auto& log : logs) {
    const auto frames = load_log(log.string());
    const auto r = replay(frames);
    std::map<uint16_t, uint16_t> trial_samples;  // by trial id, from its TrialEnd frame
    for (const auto& lf : frames)
      if (protocol::TrialEnd e; protocol::decode(lf.frame, e)) trial_samples[e.trial_id] = e.samples;
    const std::string label = label_of(log);
    auto& row = tally[label];
    ++row.logs;
    std::string line = log.filename().string() + " (" + label + "):";
    for (const auto& t : r.trials) {
      ++row.trials;
      // The samples the trial went on for after the deciding one (its TrialEnd's count; without
      // one, the log's last sample).
      const auto end = trial_samples.find(t.trial);
      const double n = end != trial_samples.end() ? end->second : t.samples;
      const double lead = std::max(0.0, n - 1 - static_cast<double>(t.stop_sample)) * sample_period_s;
      char buf[256];
      if (t.stopped && t.reason == protocol::StopReason::Caught) {
        ++row.caught_stops;
        row.travel.push_back(t.travel);
        row.lead.push_back(lead);
        std::snprintf(buf, sizeof buf, " trial %u STOP (caught) at %.3f m, %.2f s before its end;", t.trial, t.travel, lead);
      } else if (t.stopped) {
        ++row.other_stops;
        std::snprintf(buf, sizeof buf, " trial %u STOP (%s) at %.3f m;", t.trial, protocol::stop_reason_name(t.reason), t.travel);
      } else {
        std::snprintf(buf, sizeof buf, " trial %u no stop (max P(caught) %.3f);", t.trial, t.max_p_caught);
      }
      line += buf;
      char jb[256];
      std::snprintf(jb, sizeof jb,
                    "\"trial_id\": %u, \"stopped\": %s, \"reason\": \"%s\", \"travel\": %.4f, \"lead\": %.2f, "
                    "\"max_p_caught\": %.6f}",
                    t.trial, t.stopped ? "true" : "false", t.stopped ? protocol::stop_reason_name(t.reason) : "none",
                    t.stopped ? t.travel : 0.0, t.stopped ? lead : 0.0, t.max_p_caught);
      json_logs += std::string(json_logs.empty() ? "" : ", ") + "{\"file\": " + json_string(log.filename().string()) +
                   ", \"label\": \"" + label + "\", " + jb;
    }
    if (!json) std::printf("%s\n", line.c_str());
  }
  if (json) {
    std::string s = "{\"trials\": [" + json_logs + "], \"outcomes\": {";
    bool first = true;
    for (const auto& [label, row] : tally) {
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "%s\"%s\": {\"logs\": %d, \"trials\": %d, \"caught_stops\": %d, \"other_stops\": %d, "
                    "\"median_stop_travel\": %.4f, \"median_lead\": %.2f}",
                    first ? "" : ", ", label.c_str(), row.logs, row.trials, row.caught_stops, row.other_stops,
                    median(row.travel), median(row.lead));
      s += buf;
      first = false;
    }
    std::printf("%s}}\n", s.c_str());
    return 0;
  }
  std::printf("\n%-11s %6s %14s %12s %21s %20s\n", "outcome", "trials", "caught stops", "other stops",
              "median stop travel", "median lead [s]");
  for (const auto& [label, row] : tally) {
    std::printf("%-11s %6d %8d (%3.0f%%) %12d", label.c_str(), row.trials, row.caught_stops,
                row.trials ? 100.0 * row.caught_stops / row.trials : 0.0, row.other_stops);
    if (row.caught_stops)
      std::printf(" %19.3f m %20.2f\n", median(row.travel), median(row.lead));
    else
      std::printf(" %21s %20s\n", "-", "-");
  }
  return 0;
}

}  // namespace

int run_replay(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "allow-model-error"});
  if (args.has("help")) {
    std::puts(kHelp);
    return 0;
  }
  args.allow_only({"help", "json", "model", "log", "logs", "config", "set", "tick-ms", "allow-model-error"});
  const std::string model_path = args.require("model");
  if (args.has("log") == args.has("logs")) throw UsageError("give exactly one of --log FILE.log or --logs DIR");
  const std::string cfg_name = args.get("config").value_or("");
  predictor::PredictorConfig cfg;
  std::vector<predictor::ConfigEntry> others;  // the daemon's own keys: replay takes tick_ms from them
  try {
    // As the daemon reads them: the file, then the --set lines; errors name the line or "--set N".
    cfg = predictor::parse_config_with_sets(cfg_name.empty() ? std::string() : read_file(cfg_name), cfg_name,
                                            args.all("set"), &others);
    for (const auto& e : others) {
      // A typo (stop_treshold) would otherwise replay the default policy without a word.
      const auto& keys = predictor::kDaemonConfigKeys;
      if (std::find_if(std::begin(keys), std::end(keys), [&](const char* k) { return e.key == k; }) == std::end(keys))
        throw InputError(e.where + ": unknown key '" + e.key + "'");
    }
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  // The daemon's timer period: the config's tick_ms (the last given), unless --tick-ms says
  // otherwise. The sensor deadline is judged on each tick, so the same file must tick alike here.
  long tick_ms = 1;
  try {
    for (const auto& e : others)
      if (e.key == "tick_ms") tick_ms = predictor::config_whole_number(e, 1, predictor::max_tick_ms(cfg));
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  tick_ms = args.integer("tick-ms", tick_ms);
  if (tick_ms < 1 || tick_ms > predictor::max_tick_ms(cfg))
    throw UsageError("--tick-ms must be in 1-" + std::to_string(predictor::max_tick_ms(cfg)) +
                     " (no longer than sensor_timeout_ms)");

  std::unique_ptr<model::OutcomeModel> m;
  std::string model_error;
  try {
    m = std::make_unique<model::OutcomeModel>(model::read_model(model_path));
  } catch (const model::ModelError& e) {
    if (!args.has("allow-model-error")) throw InputError(e.what());
    model_error = e.what();
  }
  if (m) {  // the daemon's check (predictor_core.h): a model trained at another rate is refused
    const predictor::PeriodCheck period = predictor::check_model_period(*m, model_path, cfg.sample_period_s);
    if (period.verdict == predictor::PeriodVerdict::Differs) throw InputError(period.message);
    if (period.verdict == predictor::PeriodVerdict::Unknown)
      std::fprintf(stderr, "replay: warning: %s\n", period.message.c_str());
  }
  auto replay = [&](const std::vector<protocol::LoggedFrame>& frames) {
    try {
      return predictor::replay_frames(m.get(), cfg, frames, tick_ms * 1'000'000);
    } catch (const model::ModelError& e) {
      throw InputError(model_path + ": " + e.what());
    }
  };
  std::vector<std::string> names;
  if (m)
    for (const auto& c : m->classes) names.push_back(c.name);
  while (names.size() < 3) names.push_back("class" + std::to_string(names.size()));

  if (auto dir = args.get("logs")) return replay_folder(*dir, replay, cfg.sample_period_s, args.has("json"));

  const std::string log_path = *args.get("log");
  const predictor::ReplayResult r = replay(load_log(log_path));

  // The first trial that stopped (or the first trial) is the headline.
  const predictor::ReplayTrial* head = nullptr;
  for (const auto& t : r.trials)
    if (t.stopped) {
      head = &t;
      break;
    }
  if (!head && !r.trials.empty()) head = &r.trials.front();
  auto counters_json = [&] {
    std::string s = "{";
    for (size_t c = 0; c < r.counters.size(); ++c) {
      s += std::string(c ? ", " : "") + "\"" + protocol::status_counter_name(static_cast<protocol::StatusCounter>(c)) +
           "\": " + std::to_string(r.counters[c]);
    }
    return s + "}";
  };
  auto trial_json = [&](const predictor::ReplayTrial& t) {
    // The class names are the model's (up to 65,536 bytes each, models/FORMAT.md): appended, not
    // printed into the fixed buffer, which holds only the numbers.
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "{\"trial_id\": %u, \"stopped\": %s, \"reason\": \"%s\", \"stop_sample\": %u, \"stop_time\": %.3f, "
                  "\"travel\": %.4f, \"log_time\": %.6f, \"f_motion\": %.3f, \"f_vertical\": %.3f, \"samples\": %u, "
                  "\"max_p_caught\": %.6f, \"posteriors\": {",
                  t.trial, t.stopped ? "true" : "false", t.stopped ? protocol::stop_reason_name(t.reason) : "none",
                  t.stop_sample, t.stop_time, t.travel, t.log_time, t.f_motion, t.f_vertical, t.samples, t.max_p_caught);
    std::string s = buf;
    for (size_t c = 0; c < 3; ++c) {
      std::snprintf(buf, sizeof buf, ": %.6f", t.p[c]);
      s += (c ? ", " : "") + json_string(names[c]) + buf;
    }
    return s + "}}";
  };
  if (args.has("json")) {
    std::string s = "{";
    if (head) {
      const std::string tj = trial_json(*head);
      s += tj.substr(1, tj.size() - 2) + ", ";
    } else {
      s += "\"stopped\": false, \"reason\": \"none\", ";
    }
    s += "\"trials\": [";
    for (size_t i = 0; i < r.trials.size(); ++i) s += (i ? ", " : "") + trial_json(r.trials[i]);
    s += "], \"frames\": " + std::to_string(r.frames) + ", \"counters\": " + counters_json();
    if (!model_error.empty()) s += ", \"model_error\": " + json_string(model_error);
    std::printf("%s}\n", s.c_str());
    return 0;
  }
  if (!model_error.empty()) std::printf("model did not load: %s\n", model_error.c_str());
  std::printf("%s: %zu frames, %zu trial(s)\n", log_path.c_str(), r.frames, r.trials.size());
  for (const auto& t : r.trials) {
    if (t.stopped)
      std::printf("  trial %u: STOP (%s) at sample %u, t = %.2f s, travel %.3f m; F_motion %.2f N, F_vertical %.2f N; "
                  "P(%s) %.3f P(%s) %.3f P(%s) %.3f\n",
                  t.trial, protocol::stop_reason_name(t.reason), t.stop_sample, t.stop_time, t.travel, t.f_motion,
                  t.f_vertical, names[0].c_str(), t.p[0], names[1].c_str(), t.p[1], names[2].c_str(), t.p[2]);
    else
      std::printf("  trial %u: no stop (%u samples, max P(caught) %.3f)\n", t.trial, t.samples, t.max_p_caught);
  }
  std::printf("  counters:");
  for (size_t c = 0; c < r.counters.size(); ++c)
    if (r.counters[c]) std::printf(" %s=%u", protocol::status_counter_name(static_cast<protocol::StatusCounter>(c)), r.counters[c]);
  std::printf("\n");
  return 0;
}

}  // namespace dressguard::cli
#else
namespace dressguard::cli {
int run_replay(int, char**) { throw UsageError("replay is not built: this build has no predictor core (predictor/filter, models)"); }
}  // namespace dressguard::cli
#endif
