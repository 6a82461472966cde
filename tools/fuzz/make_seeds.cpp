// dg_fuzz_seeds KIND DIR: writes a fuzz target's seed corpus at test time.
//   dgm        fuzz_dgm: valid models of several shapes (1 class x 1 state, 2 x 5, 3 x 10, a
//              general topology, a format-version-3 one with its training conditions, a
//              format-version-2 one whose feature 1 is 'none'), each
//              with mode byte 0 (as is) and 1 (size and CRC repaired by the harness), plus a
//              truncated and a bit-flipped file;
//   predictor  fuzz_predictor: trials as the bus carries them (traffic.h): a good
//              trial, a caught one confirmed by its echo, the hard limit, a sensor timeout whose
//              stop must be resent, a burst of corrupted frames, no model, SIGTERM in a trial;
//   bridge     fuzz_bridge: readings and heartbeats across the millisecond clock's wrap, a stop
//              latched and released by a trial start, a predictor that falls silent, failed
//              reads around a stop, timer overruns between readings (one past the counter's cap);
//   candump    fuzz_candump: `candump -l` logs of each message of the protocol, with blank
//              lines, CRLF endings and a short frame; one as candump -l -x -d writes it on two
//              interfaces (padded names, R/T, a comment and a DROPCOUNT line), and one line each
//              of what stays refused (an error frame, a 29-bit id, a remote and a CAN FD frame);
//   inputs     fuzz_inputs: a dataset trial CSV, a study trial, an OBJ with every face form,
//              and each with a value that is not finite or an index out of range;
//   config     fuzz_config: the daemon's configuration with every key (as shipped), a --set
//              line, a remounted sensor, and values just outside their ranges.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "candump_log.h"
#include "dgm.h"
#include "traffic.h"

using namespace dressguard::model;

namespace {
OutcomeModel make(int classes, int states, bool general) {
  OutcomeModel m;
  m.tool_version = "seed";
  m.created = "2026-01-01T00:00:00Z";
  m.source_dataset = "seed";
  m.training_summary = "seed";
  const char* names[] = {"good", "missed", "caught"};
  for (int c = 0; c < classes; ++c) {
    ClassHmm h;
    h.name = names[c];
    h.n_states = states;
    h.initial.assign(states, 0.0);
    h.initial[0] = 1.0;
    h.transition.assign(states * states, 0.0);
    for (int i = 0; i < states; ++i) {
      if (i == states - 1) {
        h.transition[i * states + i] = 1.0;
      } else if (general && i > 0) {
        h.transition[i * states + i - 1] = 0.25, h.transition[i * states + i] = 0.5, h.transition[i * states + i + 1] = 0.25;
      } else {
        h.transition[i * states + i] = 0.75, h.transition[i * states + i + 1] = 0.25;
      }
    }
    for (int j = 0; j < states; ++j) {
      GaussianEmission e;
      e.mean[0] = 0.5 * j - c;
      e.mean[1] = std::sin(j + c);
      e.cov[0][1] = e.cov[1][0] = 0.25;
      h.emission.push_back(e);
    }
    h.log_prior = -std::log(static_cast<double>(classes));
    m.classes.push_back(h);
  }
  double z = 0;
  for (auto& h : m.classes) z += std::exp(h.log_prior);
  for (auto& h : m.classes) h.log_prior -= std::log(z);
  return m;
}

bool write_file(const std::filesystem::path& p, const std::vector<uint8_t>& b) {
  std::ofstream o(p, std::ios::binary);
  o.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  o.close();
  if (!o) std::fprintf(stderr, "dg_fuzz_seeds: cannot write %s\n", p.c_str());
  return static_cast<bool>(o);
}

bool put(const std::filesystem::path& p, uint8_t mode, const std::vector<uint8_t>& b) {
  std::vector<uint8_t> m{mode};
  m.insert(m.end(), b.begin(), b.end());
  return write_file(p, m);
}

template <typename Writer>
int write_seeds(const std::filesystem::path& dir, const std::vector<std::pair<std::string, Writer>>& seeds) {
  bool ok = true;
  for (const auto& [name, w] : seeds) ok &= write_file(dir / name, w.bytes);
  if (!ok) return 1;
  std::printf("wrote %zu seeds into %s\n", seeds.size(), dir.c_str());
  return 0;
}

int write_texts(const std::filesystem::path& dir, const std::vector<std::pair<std::string, std::string>>& seeds) {
  bool ok = true;
  for (const auto& [name, text] : seeds) ok &= write_file(dir / name, std::vector<uint8_t>(text.begin(), text.end()));
  if (!ok) return 1;
  std::printf("wrote %zu seeds into %s\n", seeds.size(), dir.c_str());
  return 0;
}

int dgm_seeds(const std::filesystem::path& dir) {
  int k = 0;
  bool ok = true;
  for (auto [c, s, g] : {std::tuple{1, 1, false}, std::tuple{2, 5, false}, std::tuple{3, 10, false},
                         std::tuple{2, 4, true}, std::tuple{3, 4, false}, std::tuple{2, 3, false}}) {
    auto m = make(c, s, g);
    if (k == 4) {  // format version 3: the training conditions after the stop policy
      m.sample_period_s = 0.01;
      m.speed_min_m_s = 0.1;
      m.speed_max_m_s = 0.3;
    }
    if (k == 5) m.features.axis[1] = kAxisNone;  // format version 2 (offset 0 and scale 1 already)
    const auto b = encode_model(m);
    ok &= put(dir / ("valid" + std::to_string(k) + "_raw"), 0, b);
    ok &= put(dir / ("valid" + std::to_string(k) + "_fixed"), 1, b);
    auto t = b;
    t.resize(t.size() / 2);
    ok &= put(dir / ("truncated" + std::to_string(k)), 0, t);
    auto f = b;
    f[f.size() / 3] ^= 0x40;
    ok &= put(dir / ("flipped" + std::to_string(k)), 1, f);
    ++k;
  }
  if (!ok) return 1;
  std::printf("wrote %d seeds into %s\n", 4 * k, dir.c_str());
  return 0;
}

int predictor_seeds(const std::filesystem::path& dir) {
  using dressguard::fuzz::TrafficOp;
  using dressguard::fuzz::TrafficWriter;
  // The daemon's defaults (predictor_core.h), "caught" at class index 1: hard limit 10 N, budget
  // 5 x 20, E2E max delta 3, timeout 50 ms, stop retry 2 ms, periodic frames every 100 ms.
  const uint8_t defaults[dressguard::fuzz::kTrafficHeader] = {8, 0, 0, 0, 0, 0, 8, 4, 19, 2, 40, 1, 95};
  uint8_t no_model[dressguard::fuzz::kTrafficHeader];
  std::copy(std::begin(defaults), std::end(defaults), no_model);
  no_model[0] = 0;
  const auto samples = [](TrafficWriter& w, int n, double motion, double vertical) {
    for (int i = 0; i < n; ++i) {
      w.force(motion, 0.0, vertical);
      w.tick();
    }
  };
  std::vector<std::pair<std::string, TrafficWriter>> seeds;
  {
    TrafficWriter w(defaults);  // good: light drag throughout, then the trial's end
    w.start(1);
    samples(w, 60, -2.0, 0.0);
    w.end();
    seeds.emplace_back("good", w);
  }
  {
    TrafficWriter w(defaults);  // caught: the drag rises to the caught class's; the echo confirms
    w.start(2);
    samples(w, 20, -2.0, 0.0);
    samples(w, 20, -6.0, -1.0);
    w.op(TrafficOp::StopEcho, 0, {0});
    w.end();
    w.start(3);
    samples(w, 5, -2.0, 0.0);
    seeds.emplace_back("caught", w);
  }
  {
    TrafficWriter w(defaults);  // the hard limit on the vertical axis
    w.start(4);
    for (int i = 0; i <= 12; ++i) w.force(-2.0, 0.0, -1.0 * i);
    seeds.emplace_back("hard_limit", w);
  }
  {
    TrafficWriter w(defaults);  // the sensor goes quiet; the stop fails twice and is resent
    w.start(5);
    samples(w, 5, -2.0, 0.0);
    w.op(TrafficOp::TxFail, 0, {2});
    w.op(TrafficOp::Wait, 0, {60});
    for (int i = 0; i < 5; ++i) w.tick(1);
    w.op(TrafficOp::StopEcho, 0, {0});
    seeds.emplace_back("timeout", w);
  }
  {
    TrafficWriter w(defaults);  // a hard-limit stop never confirmed; the next trial refused
    w.start(9);
    samples(w, 3, -2.0, 0.0);
    w.op(TrafficOp::TxFail, 0, {7});
    w.force(-12.0, 0.0, 0.0);
    w.tick(1);
    w.start(10);
    w.tick(1);
    w.op(TrafficOp::StopEcho, 0, {0});
    w.end();
    w.start(11);
    samples(w, 3, -2.0, 0.0);
    seeds.emplace_back("unconfirmed", w);
  }
  {
    TrafficWriter w(defaults);  // a burst of corrupted frames between good ones
    w.start(6);
    samples(w, 5, -2.0, 0.0);
    for (int i = 0; i < 8; ++i) w.op(TrafficOp::Force, 5, {0x20, 0xEC, 0, 0, 0, 0, 0});
    seeds.emplace_back("bad_frames", w);
  }
  {
    TrafficWriter w(no_model);  // no model: every trial refused
    w.start(7);
    samples(w, 3, -2.0, 0.0);
    w.op(TrafficOp::StopEcho, 0, {0});
    w.end();
    seeds.emplace_back("no_model", w);
  }
  {
    TrafficWriter w(defaults);  // SIGTERM in a trial, then bus errors and kernel drops
    w.start(8);
    samples(w, 3, -2.0, 0.0);
    w.op(TrafficOp::KernelDrops, 0, {3});
    w.op(TrafficOp::BusError, 0, {4});
    w.op(TrafficOp::Heartbeat, 0);
    w.op(TrafficOp::Shutdown, 0);
    w.tick(2);
    w.start(9);  // a trial that starts during the shutdown's grace: refused
    samples(w, 3, -2.0, 0.0);
    seeds.emplace_back("shutdown", w);
  }
  return write_seeds(dir, seeds);
}
int bridge_seeds(const std::filesystem::path& dir) {
  using dressguard::fuzz::BridgeOp;
  using dressguard::fuzz::BridgeWriter;
  // No predictor timeout, 100 ms heartbeats, the clock 2 s before it wraps; and with a 152 ms
  // predictor timeout (a multiple of the 4 ms steps, so that a tick lands on it exactly).
  const uint8_t plain[dressguard::fuzz::kBridgeHeader] = {0, 99, 0x30, 0xF8, 0xFF, 0xFF};
  const uint8_t guarded[dressguard::fuzz::kBridgeHeader] = {142, 99, 0x30, 0xF8, 0xFF, 0xFF};
  const auto readings = [](BridgeWriter& w, int n, double fx) {
    for (int i = 0; i < n; ++i) {
      w.reading(fx, 0.1, -0.5, 0.01);
      w.tick();
    }
  };
  std::vector<std::pair<std::string, BridgeWriter>> seeds;
  {
    BridgeWriter w(plain);  // readings every 8 ms for 4 s: the clock wraps half-way
    readings(w, 500, -2.0);
    seeds.emplace_back("wrap", w);
  }
  {
    BridgeWriter w(plain);  // a stop, repeated, a corrupted one, then a trial start releases it
    readings(w, 20, -2.0);
    w.op(BridgeOp::Stop, 1, {0, 1, 7});
    w.op(BridgeOp::Stop, 1, {1, 1, 7});
    w.op(BridgeOp::Stop, 1, {0x20, 1, 7});
    readings(w, 20, -6.0);
    w.op(BridgeOp::StopWritten, 1);
    w.op(BridgeOp::TrialStart, 1, {0, 8});
    readings(w, 20, -2.0);
    seeds.emplace_back("stop_release", w);
  }
  {
    BridgeWriter w(guarded);  // the predictor's heartbeat every 40 ms, then silence, a tick every 4 ms
    for (int i = 0; i < 20; ++i) {
      w.op(BridgeOp::PredictorHeartbeat, 10, {0, 0});
      w.tick();
    }
    for (int i = 0; i < 45; ++i) w.tick(1);
    w.op(BridgeOp::StopWritten, 1);
    w.op(BridgeOp::TrialStart, 1, {0, 2});
    w.op(BridgeOp::PredictorHeartbeat, 1, {0, 0});
    w.tick(1);
    seeds.emplace_back("silent_predictor", w);
  }
  {
    BridgeWriter w(plain);  // failed reads, a reconnect, a stop while the sensor is lost
    w.op(BridgeOp::SensorError, 5);
    w.tick(10);
    w.op(BridgeOp::Reconnect, 1);
    readings(w, 5, -1.0);
    w.op(BridgeOp::SensorError, 5);
    w.op(BridgeOp::Stop, 1, {0, 2, 3});
    w.tick(10);
    w.op(BridgeOp::TrialStart, 1, {0, 4});
    w.op(BridgeOp::Wait, 0, {30});
    readings(w, 3, -1.0);
    w.op(BridgeOp::Wait, 0, {30});
    seeds.emplace_back("sensor_lost", w);
  }
  {
    BridgeWriter w(plain);  // the predictor in a trial (state bit 4), then the bridge shuts down
    readings(w, 10, -2.0);
    w.op(BridgeOp::PredictorHeartbeat, 1, {0x10, 0});
    readings(w, 10, -2.0);
    w.op(BridgeOp::Shutdown, 1);
    w.op(BridgeOp::StopWritten, 1);
    w.op(BridgeOp::Shutdown, 1);
    seeds.emplace_back("shutdown_in_trial", w);
  }
  {
    BridgeWriter w(guarded);  // trial 5 guarded from its second heartbeat, then the predictor idle
    for (int i = 0; i < 5; ++i) {  // (restarted), guarded again, ended; trial 6 never guarded
      w.op(BridgeOp::PredictorHeartbeat, 10, {0, 4});
      w.tick();
    }
    w.op(BridgeOp::TrialStart, 1, {0, 5});
    for (int i = 0; i < 30; ++i) {
      w.op(BridgeOp::PredictorHeartbeat, 10, {static_cast<uint8_t>(i > 0 && (i < 10 || i > 20) ? 0x10 : 0), 5});
      w.tick();
    }
    w.op(BridgeOp::TrialEnd, 1, {0, 5});
    w.op(BridgeOp::TrialStart, 1, {0, 6});
    for (int i = 0; i < 30; ++i) {
      w.op(BridgeOp::PredictorHeartbeat, 10, {0, 5});
      w.tick();
    }
    seeds.emplace_back("unguarded_trial", w);
  }
  {
    BridgeWriter w(plain);  // a sensor that keeps failing: its error count saturates at 255
    for (int i = 0; i < 300; ++i) w.op(BridgeOp::SensorError, 1);
    w.tick(1);
    w.op(BridgeOp::Reconnect, 1);
    readings(w, 3, -1.0);
    seeds.emplace_back("sensor_errors", w);
  }
  {
    BridgeWriter w(plain);  // the port's timer overran: 1 and 3 periods, a failed read, 200 periods
    readings(w, 5, -1.0);
    w.op(BridgeOp::PeriodsMissed, 1, {1});
    readings(w, 2, -1.0);
    w.op(BridgeOp::PeriodsMissed, 3, {3});
    w.op(BridgeOp::SensorError, 1);
    readings(w, 2, -1.0);
    w.op(BridgeOp::PeriodsMissed, 15, {200});
    readings(w, 3, -1.0);
    seeds.emplace_back("overruns", w);
  }
  return write_seeds(dir, seeds);
}
int candump_seeds(const std::filesystem::path& dir) {
  namespace p = dressguard::protocol;
  const p::Frame frames[] = {
      p::encode(p::TrialStart{0, 1, 100, p::HeightClass::High}), p::encode(p::FtForce{0, -200, 10, -50}),
      p::encode(p::FtTorque{0, 1, -2, 3}), p::encode(p::Stop{0, p::StopReason::Caught, 240, 1, 57}),
      p::encode(p::HeartbeatBridge{3, p::BridgeState::Ok, 0, 1, 12}),
      p::encode(p::HeartbeatPredictor{4, p::PredictorState::InTrial, 1, 1, 12}),
      p::encode(p::Posteriors{5, 57, {10, 5, 240}, p::PredictorState::Stopped}),
      p::encode(p::TrialEnd{0, 1, 58, p::TrialEndReason::StoppedByPredictor})};
  std::string all, crlf;
  int64_t t = 1700000000000100;
  for (const auto& f : frames) {
    const std::string line = p::format_candump_line(t, "vcan0", f);
    all += line + "\n";
    crlf += line + "\r\n\n";
    t += 10000;
  }
  p::Frame shorty;
  shorty.id = 0x080;
  all += p::format_candump_line(t, "can0", shorty) + "\n";
  const std::string two_ifaces =
      "# candump -l -x -d can0 vcan0\n"
      "(1700000000.000100)  can0 100#A5010A00F6FF3200 R\n"
      "DROPCOUNT: dropped 2 CAN frames on 'can0' socket (total drops 2)\n"
      "(1700000000.000200) vcan0 080#0102030405 T\n";
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"trial.log", all},
      {"crlf.log", crlf},
      {"two_ifaces.log", two_ifaces},
      {"error_frame.log", "(1700000000.000100) vcan0 20000040#0000000000000000\n"},
      {"len8_dlc.log", "(1700000000.000100) vcan0 100#A5010A00F6FF3200_C\n"},
      {"extended.log", "(1700000000.000100) vcan0 12345678#00\n"},
      {"remote.log", "(1700000000.000100) vcan0 100#R\n"},
      {"fd.log", "(1700000000.000100) vcan0 100##1A5\n"}};
  return write_texts(dir, seeds);
}
int input_seeds(const std::filesystem::path& dir) {
  // The first byte chooses the reader (fuzz_inputs.cpp): 0 trial CSV, 1 study trial, 2 OBJ.
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"trial.csv", std::string(1, '\0') + "t,travel,f_motion,f_lateral,f_vertical\n0.00,0.000,-0.10,0.01,0.02\n"
                                          "0.01,0.001,-0.20,0.00,0.05\n0.02,0.002,-0.31,-0.01,0.08\n"},
      {"study.txt", "\x01" "0.00 0.000 -0.10 0.01 0.02\n0.01 0.001 -0.2 0.0 0.05\n0.02 0.002 -0.3 0.0 0.07\n"},
      {"gown.obj", "\x02" "# a square and its fan\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\n"
                   "f 1 2 3\nf 2/1 4/1 3/1\nf 1//1 2//1 4//1\nf -1 -2 -3\nf 1 2 4 3\n"},
      // In metres: the first line as gown.h's kObjMetresHeader (to_obj) writes it.
      {"metres.obj", "\x02# dressguard gown mesh, world frame W (z up, gripper moves along +x), metres\n"
                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n"},
      // Values the readers must refuse, as strtod and from_chars would otherwise take them.
      {"nan.csv", std::string(1, '\0') + "t,travel,f_motion,f_lateral,f_vertical\n0.00,0.000,nan,0.01,0.02\n"},
      {"inf.txt", "\x01" "0.00 0.000 -0.10 inf 0.02\n"},
      {"nan.obj", "\x02" "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"}};
  return write_texts(dir, seeds);
}
int config_seeds(const std::filesystem::path& dir) {
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"shipped.conf",
       "# dressguard-predictor configuration\ninterface = can0\nmodel = /usr/share/dressguard/default.dgm\n"
       "# stop_threshold = 0.9\n# stop_consecutive = 5\nhard_limit_n = 10   # the study's limit\n"
       "sensor_timeout_ms = 50\nbad_frame_budget = 5\nbad_frame_weight = 20\nmax_delta_counter = 3\n"
       "mount_axes = x y z\nmount_bias = 0 0 0\nsample_period_ms = 10\nacceleration_m_s2 = 1\ntick_ms = 1\n"
       "stop_retry_ms = 2\nstatus_period_ms = 100\nheartbeat_period_ms = 100\nposteriors_period_ms = 100\n"
       "rt_priority = 80\ncpu = -1\nmlock = 1\nlog_level = info\n"},
      {"set.conf", "stop_threshold=0.95\nstop_consecutive=100000\nsensor_timeout_ms=200\n"},
      {"remounted.conf", "mount_axes = -z +y x\r\nmount_bias = 0.5 -1.25 12\r\n"},
      {"ranges.conf", "stop_consecutive = 1000001\nsensor_timeout_ms = 600000.001\nmax_delta_counter = 128\n"
                      "bad_frame_budget = 2.5\nmount_axes = x x z\nmount_bias = 0 0 1000.5\n"}};
  return write_texts(dir, seeds);
}
}  // namespace

int main(int argc, char** argv) {
  const std::string kind = argc == 3 ? argv[1] : "";
  if (kind != "dgm" && kind != "predictor" && kind != "bridge" && kind != "candump" && kind != "inputs" && kind != "config") {
    std::fprintf(stderr, "usage: dg_fuzz_seeds dgm|predictor|bridge|candump|inputs|config DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[2];
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "dg_fuzz_seeds: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    return 1;
  }
  if (kind == "dgm") return dgm_seeds(dir);
  if (kind == "candump") return candump_seeds(dir);
  if (kind == "inputs") return input_seeds(dir);
  if (kind == "config") return config_seeds(dir);
  return kind == "predictor" ? predictor_seeds(dir) : bridge_seeds(dir);
}
