// dressguard export-candump: trials (simulated or measured) -> candump logs of the CAN protocol,
// as the firmware bridge and the robot would have put them on the bus, with optional faults.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "args.h"
#include "candump_log.h"
#include "commands.h"
#include "dataset.h"
#include "dg_protocol.h"
#include "files.h"
#include "json.h"

namespace dressguard::cli {
namespace {

namespace proto = dressguard::protocol;

const char* kHelp =
    "usage: dressguard export-candump (--data DATASET | --trial CSV) --out FILE.log|DIR [options]\n"
    "  Writes the CAN frames of each trial as a candump log (`candump -l` format, replayable with\n"
    "  canplayer and `dressguard replay`): TrialStart, per sample an FtForce and an FtTorque frame\n"
    "  (same alive counter; torques 0: the trials carry forces only), TrialEnd.\n"
    "  --data DATASET     every trial of a dataset folder; --out is then a folder and each log is\n"
    "                     named <trial_id>-<label>.log (the outcome in the file name)\n"
    "  --trial CSV        one trial CSV (t,travel,f_motion,f_lateral,f_vertical); --out FILE.log\n"
    "  --speed M/S        speed for --trial (default 0.1); --height high|middle|low (default middle)\n"
    "  --only ID[,ID..]   with --data: only these trial ids\n"
    "  --iface NAME       interface name in the log (default vcan0; 1-15 characters, no whitespace)\n"
    "  --trial-id N       TrialStart's trial number (default 1; --data numbers trials from N, the\n"
    "                     last at most 65535)\n"
    "  --start S          timestamp of the first frame [s] (default 1700000000; from 0, and the\n"
    "                     last frame by 9000000000 s, the latest a log may carry)\n"
    "  --counter-start N  first alive counter of the F/T frames (default 0)\n"
    "  --rig-limit N      end the trial like the study's rig: the first sample with |F_motion| or\n"
    "                     |F_vertical| above N newtons is not sent and the trial ends there\n"
    "                     (TrialEnd reason 'robot force limit'); 0 sends every sample (default 10)\n"
    "  --mount AXES       sensor axes for the rig's motion/lateral/vertical (default 'x y z'; the\n"
    "                     inverse of the daemon's mount_axes)\n"
    "  Faults, by 0-based sample index in the trial (comma-separated lists):\n"
    "  --corrupt I,..     flip one payload bit in both frames of sample I (CRC mismatch)\n"
    "  --drop I,..        do not send sample I (both frames)\n"
    "  --repeat I,..      send sample I's frames twice\n"
    "  --delay I:D,..     send sample I's frames after sample I+D's\n"
    "  --gap I:MS         the sensor goes silent at sample I for MS milliseconds (samples in the\n"
    "                     gap are never sent), then resumes\n"
    "  --json             print a machine-readable summary (per log: samples, limit sample)";

std::vector<long> index_list(const std::optional<std::string>& s, const char* what) {
  std::vector<long> out;
  if (!s) return out;
  std::stringstream in(*s);
  std::string tok;
  while (std::getline(in, tok, ',')) {
    try {
      size_t used = 0;
      const long v = std::stol(tok, &used);
      if (used != tok.size() || v < 0) throw std::invalid_argument(tok);
      out.push_back(v);
    } catch (const std::exception&) {
      throw UsageError(std::string("--") + what + ": '" + tok + "' is not a sample index");
    }
  }
  return out;
}

std::vector<std::pair<long, long>> pair_list(const std::optional<std::string>& s, const char* what) {
  std::vector<std::pair<long, long>> out;
  if (!s) return out;
  std::stringstream in(*s);
  std::string tok;
  while (std::getline(in, tok, ',')) {
    const auto colon = tok.find(':');
    try {
      if (colon == std::string::npos) throw std::invalid_argument(tok);
      const long a = std::stol(tok.substr(0, colon)), b = std::stol(tok.substr(colon + 1));
      if (a < 0 || b <= 0) throw std::invalid_argument(tok);
      out.emplace_back(a, b);
    } catch (const std::exception&) {
      throw UsageError(std::string("--") + what + ": '" + tok + "' is not I:N with I >= 0, N > 0");
    }
  }
  return out;
}

struct ExportOptions {
  std::string iface = "vcan0";
  int64_t start_us = 1700000000LL * 1000000;
  uint8_t counter_start = 0;
  double rig_limit = 10.0;
  int axis_of_sensor[3] = {0, 1, 2};  // sensor axis i carries rig axis axis_of_sensor[i]
  double sign_of_sensor[3] = {1, 1, 1};
  std::set<long> corrupt, drop, repeat;
  std::map<long, long> delay;  // sample -> samples of delay
  long gap_at = -1, gap_ms = 0;
};

struct ExportSummary {
  size_t samples_sent = 0;
  long limit_sample = -1;  // index of the first sample above the rig limit (not sent), -1 none
  size_t frames = 0;
  int64_t last_us = 0;     // the last frame's timestamp
};

ExportSummary export_trial(const HapticSequence& trial, uint16_t trial_id, const ExportOptions& o, std::string& out) {
  ExportSummary sum;
  struct Timed {
    int64_t t_us;
    long order;
    proto::Frame f;
  };
  std::vector<Timed> frames;
  long order = 0;
  auto emit = [&](int64_t t, const proto::Frame& f) { frames.push_back({t, order++, f}); };
  const auto& s = trial.samples;
  const int64_t t0 = o.start_us;
  const double first_t = s.empty() ? 0.0 : s.front().t;
  auto time_of = [&](size_t i) { return t0 + 10000 + static_cast<int64_t>(std::llround((s[i].t - first_t) * 1e6)); };
  const auto height = trial.height == ArmHeight::High ? proto::HeightClass::High
                      : trial.height == ArmHeight::Low ? proto::HeightClass::Low
                                                       : proto::HeightClass::Middle;
  emit(t0, proto::encode(proto::TrialStart{0, trial_id, static_cast<uint16_t>(std::lround(trial.speed * 1000.0)), height}));
  uint8_t counter = o.counter_start;
  int64_t gap_shift = 0;
  long gap_end = -1;
  size_t n_send = s.size();
  for (size_t i = 0; i < s.size(); ++i) {
    if (o.rig_limit > 0 && (std::fabs(s[i].f_motion) > o.rig_limit || std::fabs(s[i].f_vertical) > o.rig_limit)) {
      sum.limit_sample = static_cast<long>(i);
      n_send = i;
      break;
    }
  }
  int64_t last_t = t0;
  for (size_t i = 0; i < n_send; ++i) {
    const long li = static_cast<long>(i);
    const uint8_t c = counter++;
    if (li == o.gap_at) {
      gap_end = li + std::max<long>(1, o.gap_ms / 10);
      gap_shift = 0;
    }
    if (gap_end >= 0 && li < gap_end) continue;  // the sensor is silent: these samples never exist on the bus
    if (o.drop.count(li)) continue;
    const double rig[3] = {s[i].f_motion, s[i].f_lateral, s[i].f_vertical};
    int16_t sensor[3];
    for (int a = 0; a < 3; ++a)
      sensor[a] = proto::to_counts(o.sign_of_sensor[a] * rig[o.axis_of_sensor[a]], proto::kForceCountsPerNewton);
    proto::Frame force = proto::encode(proto::FtForce{c, sensor[0], sensor[1], sensor[2]});
    proto::Frame torque = proto::encode(proto::FtTorque{c, 0, 0, 0});
    if (o.corrupt.count(li)) {  // one payload bit each: only the E2E CRC can tell
      force.data[5] ^= 0x08;
      torque.data[3] ^= 0x40;
    }
    int64_t t = time_of(i) + gap_shift;
    if (auto d = o.delay.find(li); d != o.delay.end()) {
      const size_t later = std::min(s.size() - 1, i + static_cast<size_t>(d->second));
      t = time_of(later) + 200;  // after sample I+D's frames
    }
    emit(t, force);
    emit(t + 100, torque);
    if (o.repeat.count(li)) {
      emit(t + 300, force);
      emit(t + 400, torque);
    }
    ++sum.samples_sent;
    last_t = std::max(last_t, t + 400);
  }
  const bool limited = sum.limit_sample >= 0;
  emit(last_t + 10000, proto::encode(proto::TrialEnd{0, trial_id, static_cast<uint16_t>(n_send),
                                                     limited ? proto::TrialEndReason::RobotForceLimit
                                                             : proto::TrialEndReason::Completed}));
  std::stable_sort(frames.begin(), frames.end(),
                   [](const Timed& a, const Timed& b) { return a.t_us != b.t_us ? a.t_us < b.t_us : a.order < b.order; });
  for (const auto& f : frames) out += proto::format_candump_line(f.t_us, o.iface, f.f) + "\n";
  sum.frames = frames.size();
  sum.last_us = frames.back().t_us;
  return sum;
}

}  // namespace

int run_export_candump(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json"});
  if (args.has("help")) {
    std::puts(kHelp);
    return 0;
  }
  args.allow_only({"help", "json", "data", "trial", "out", "speed", "height", "only", "iface", "trial-id", "start",
                   "counter-start", "rig-limit", "mount", "corrupt", "drop", "repeat", "delay", "gap"});
  if (args.has("data") == args.has("trial")) throw UsageError("give exactly one of --data DATASET or --trial CSV");
  const std::string out = args.require("out");
  ExportOptions o;
  // What is written must read back (dressguard replay, canplayer): the reader's own rules for the
  // interface name and the timestamps (--start's upper bound is checked per trial, below).
  o.iface = args.get("iface").value_or("vcan0");
  if (const char* bad = proto::interface_name_error(o.iface))
    throw UsageError("--iface '" + o.iface + "': " + bad);
  const double start = args.number("start", 1700000000.0);
  if (!(start >= 0 && start <= static_cast<double>(proto::kMaxLogSeconds)))
    throw UsageError("--start must be in 0.." + std::to_string(proto::kMaxLogSeconds) + " s (a log's timestamps)");
  o.start_us = static_cast<int64_t>(std::llround(start * 1e6));
  const long cs = args.integer("counter-start", 0);
  if (cs < 0 || cs > 255) throw UsageError("--counter-start must be 0..255");
  o.counter_start = static_cast<uint8_t>(cs);
  o.rig_limit = args.number("rig-limit", 10.0);
  if (o.rig_limit < 0) throw UsageError("--rig-limit must be >= 0");
  if (auto m = args.get("mount")) {
    // "x y z" style: token k is the sensor axis that carries rig axis k.
    std::istringstream in(*m);
    std::string tok;
    int k = 0;
    while (in >> tok) {
      if (k == 3) throw UsageError("--mount takes three axes");
      double sign = 1;
      if (tok[0] == '-' || tok[0] == '+') {
        sign = tok[0] == '-' ? -1 : 1;
        tok = tok.substr(1);
      }
      if (tok != "x" && tok != "y" && tok != "z") throw UsageError("--mount: '" + tok + "' is not x, y or z");
      o.axis_of_sensor[tok[0] - 'x'] = k;
      o.sign_of_sensor[tok[0] - 'x'] = sign;
      ++k;
    }
    if (k != 3) throw UsageError("--mount takes three axes");
  }
  for (long v : index_list(args.get("corrupt"), "corrupt")) o.corrupt.insert(v);
  for (long v : index_list(args.get("drop"), "drop")) o.drop.insert(v);
  for (long v : index_list(args.get("repeat"), "repeat")) o.repeat.insert(v);
  for (auto [i, d] : pair_list(args.get("delay"), "delay")) o.delay[i] = d;
  if (auto g = pair_list(args.get("gap"), "gap"); !g.empty()) {
    if (g.size() > 1) throw UsageError("--gap takes one I:MS");
    o.gap_at = g[0].first;
    o.gap_ms = g[0].second;
  }
  long trial_id = args.integer("trial-id", 1);
  if (trial_id < 0 || trial_id > 65535) throw UsageError("--trial-id must be 0..65535");

  std::vector<HapticSequence> trials;
  bool one_file = false;
  if (auto csv = args.get("trial")) {
    HapticSequence t;
    t.id = std::filesystem::path(*csv).stem().string();
    t.samples = read_trial_csv(*csv);
    t.speed = args.number("speed", 0.1);
    if (t.speed <= 0) throw UsageError("--speed must be positive");
    const auto h = parse_arm_height(args.get("height").value_or("middle"));
    if (!h) throw UsageError("--height must be high, middle or low");
    t.height = *h;
    trials.push_back(std::move(t));
    one_file = true;
  } else {
    Dataset ds = load_dataset(*args.get("data"));
    std::set<std::string> only;
    if (auto ids = args.get("only")) {
      std::stringstream in(*ids);
      std::string tok;
      while (std::getline(in, tok, ',')) only.insert(tok);
    }
    for (auto& t : ds.trials)
      if (only.empty() || only.count(t.id)) trials.push_back(std::move(t));
    if (!only.empty() && trials.size() != only.size()) throw UsageError("--only names a trial id that is not in the dataset");
  }
  // TrialStart and TrialEnd carry the id in 16 bits: a wrapped id would name another trial than
  // the log's name and --json say.
  if (trial_id + static_cast<long>(trials.size()) - 1 > 65535)
    throw UsageError("--trial-id " + std::to_string(trial_id) + " with " + std::to_string(trials.size()) +
                     " trials numbers past 65535 (a trial id is 16 bits): at most " +
                     std::to_string(65536 - static_cast<long>(trials.size())));
  // Everything is built in memory first, then written atomically: no half-written logs.
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  std::string json = "{\"logs\": [";
  for (size_t k = 0; k < trials.size(); ++k) {
    const auto& t = trials[k];
    if (t.samples.empty()) throw InputError("trial " + t.id + " has no samples");
    std::string text;
    const auto sum = export_trial(t, static_cast<uint16_t>(trial_id + static_cast<long>(k)), o, text);
    // The reader takes timestamps up to kMaxLogSeconds (a replay's nanoseconds fit an int64_t).
    if (sum.last_us / 1000000 > proto::kMaxLogSeconds) {
      const int64_t length_us = sum.last_us - o.start_us, latest_us = proto::kMaxLogSeconds * 1000000 + 999999;
      const int64_t max_start_us = latest_us - length_us;
      if (max_start_us < 0) throw InputError("trial " + t.id + " lasts longer than a log's timestamps can reach");
      char buf[200];
      std::snprintf(buf, sizeof buf, "--start must be at most %lld.%06lld for trial %s (%lld.%06lld s of frames; "
                    "a log's timestamps end at %lld s)",
                    static_cast<long long>(max_start_us / 1000000), static_cast<long long>(max_start_us % 1000000),
                    t.id.c_str(), static_cast<long long>(length_us / 1000000),
                    static_cast<long long>(length_us % 1000000), static_cast<long long>(proto::kMaxLogSeconds));
      throw UsageError(buf);
    }
    std::filesystem::path p = out;
    if (!one_file) {
      const std::string label = t.label ? std::string(outcome_name(*t.label)) : "unlabelled";
      p = std::filesystem::path(out) / (t.id + "-" + label + ".log");
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, ", \"trial_id\": %ld, \"samples\": %zu, \"limit_sample\": %ld, \"frames\": %zu}",
                  trial_id + static_cast<long>(k), sum.samples_sent, sum.limit_sample, sum.frames);
    json += (k ? ", " : "") + std::string("{\"file\": ") + json_string(p.string()) + ", \"trial\": " +
            json_string(t.id) + buf;
    if (!args.has("json"))
      std::printf("%s: %zu samples, %zu frames%s\n", p.string().c_str(), sum.samples_sent, sum.frames,
                  sum.limit_sample >= 0 ? (", rig limit at sample " + std::to_string(sum.limit_sample)).c_str() : "");
    files.emplace_back(p, std::move(text));
  }
  for (const auto& [p, text] : files) write_file_atomic(p, text);
  if (args.has("json")) std::printf("%s]}\n", json.c_str());
  return 0;
}

}  // namespace dressguard::cli
