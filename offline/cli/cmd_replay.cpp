// dressguard replay: the predictor daemon's own code (predictor/core) run over a candump log.
#include <cstdio>
#include <memory>

#include "args.h"
#include "commands.h"
#if __has_include("replay.h")  // predictor/core is built once predictor/filter and models/ exist
#include "candump_log.h"
#include "dgm.h"
#include "files.h"
#include "replay.h"

namespace dressguard::cli {
namespace {

const char* kHelp =
    "usage: dressguard replay --model MODEL.dgm --log FILE.log [--config FILE] [--set KEY=VALUE] [--json]\n"
    "  Runs the predictor daemon's code (E2E checks, forward filter, stop policy, deadlines) on a\n"
    "  candump log without a bus and prints whether and when it would stop the robot, and why.\n"
    "  --model MODEL.dgm  outcome model; a model that does not load is reported (exit 2) unless\n"
    "                     --allow-model-error is given, which replays as the daemon would run\n"
    "                     without a model (every trial refused)\n"
    "  --log FILE.log     candump -l log (as written by candump or `dressguard export-candump`)\n"
    "  --config FILE      the daemon's config file (its predictor keys; others are ignored)\n"
    "  --set KEY=VALUE    override one predictor key, e.g. --set stop_threshold=0.95\n"
    "  --tick-ms N        the daemon's timer period (default 1)\n"
    "  --json             {stopped, stop_time, travel, reason, posteriors at the stop, ...}\n"
    "  Times are logical: stop_time = the deciding sample's index x the sample period; travel is\n"
    "  the commanded travel at that time (TrialStart's speed, the configured acceleration).";

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}

}  // namespace

int run_replay(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "allow-model-error"});
  if (args.has("help")) {
    std::puts(kHelp);
    return 0;
  }
  args.allow_only({"help", "json", "model", "log", "config", "set", "tick-ms", "allow-model-error"});
  const std::string model_path = args.require("model");
  const std::string log_path = args.require("log");
  std::string cfg_text;
  std::string cfg_name = "--set";
  if (auto c = args.get("config")) {
    cfg_text = read_file(*c);
    cfg_name = *c;
  }
  if (auto s = args.get("set")) cfg_text += "\n" + *s + "\n";
  predictor::PredictorConfig cfg;
  try {
    std::vector<predictor::ConfigEntry> others;  // the daemon's own keys: not replay's business
    cfg = predictor::parse_predictor_config(cfg_text, cfg_name, &others);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  const long tick_ms = args.integer("tick-ms", 1);
  if (tick_ms < 1) throw UsageError("--tick-ms must be >= 1");

  std::unique_ptr<model::OutcomeModel> m;
  std::string model_error;
  try {
    m = std::make_unique<model::OutcomeModel>(model::read_model(model_path));
  } catch (const model::ModelError& e) {
    if (!args.has("allow-model-error")) throw InputError(e.what());
    model_error = e.what();
  }
  std::vector<protocol::LoggedFrame> frames;
  try {
    frames = protocol::parse_candump_log(read_file(log_path), log_path);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  predictor::ReplayResult r;
  try {
    r = predictor::replay_frames(m.get(), cfg, frames, tick_ms * 1'000'000);
  } catch (const model::ModelError& e) {
    throw InputError(model_path + ": " + e.what());
  }
  std::vector<std::string> names;
  if (m)
    for (const auto& c : m->classes) names.push_back(c.name);
  while (names.size() < 3) names.push_back("class" + std::to_string(names.size()));

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
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "{\"trial_id\": %u, \"stopped\": %s, \"reason\": \"%s\", \"stop_sample\": %u, \"stop_time\": %.3f, "
                  "\"travel\": %.4f, \"log_time\": %.6f, \"f_motion\": %.3f, \"f_vertical\": %.3f, \"samples\": %u, "
                  "\"max_p_caught\": %.6f, \"posteriors\": {\"%s\": %.6f, \"%s\": %.6f, \"%s\": %.6f}}",
                  t.trial, t.stopped ? "true" : "false", t.stopped ? protocol::stop_reason_name(t.reason) : "none",
                  t.stop_sample, t.stop_time, t.travel, t.log_time, t.f_motion, t.f_vertical, t.samples, t.max_p_caught,
                  json_escape(names[0]).c_str(), t.p[0], json_escape(names[1]).c_str(), t.p[1],
                  json_escape(names[2]).c_str(), t.p[2]);
    return std::string(buf);
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
    if (!model_error.empty()) s += ", \"model_error\": \"" + json_escape(model_error) + "\"";
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
