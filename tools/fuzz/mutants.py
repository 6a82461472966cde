#!/usr/bin/python3
"""Checks that the robot side's fuzz targets can fail: puts one fault at a time into a copy of
the core they drive (predictor/core/predictor_core.cpp for fuzz_predictor,
firmware-bridge/core/bridge_core.cpp for fuzz_bridge): a line of a rule changed, as a slip in
review would change it. It builds the fuzz target against the copy and runs it from the seed
corpus. Every fault must be reported (a broken rule or a sanitizer report) within the time
given; the unchanged source must run clean for as long.

usage: tools/fuzz/mutants.py predictor|bridge BUILD_DIR [--seconds S] [--only NAME]
  BUILD_DIR   a configured build with dg_fuzz_seeds built (e.g. build/release)
Needs clang++ with libFuzzer (Debian: clang, libclang-rt-14-dev). About 30 s of compiling per
fault on one core of a 2-core VM (fuzz_bridge's sources: a few seconds). Exit 0 when every
fault is caught and the clean run is clean.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

SRC = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# name, the line as it is, the line with the fault.
PREDICTOR_FAULTS = [
    ("a lost trial start charged to the running trial",
     "if (!checked(chk_start_, f, now_ns, lost, false)) return;",
     "if (!checked(chk_start_, f, now_ns, lost, true)) return;"),
    ("a bad-frames stop names the sample before the one that decided",
     "  // Logical time: the sensor's counter, lost samples included (the first sample of a trial is 0).\n"
     "  if (samples_started_) decision_.sample += 1 + lost;\n",
     "  charge_bad(lost, now_ns);\n"
     "  if (decision_.state != PredictorState::InTrial) return;\n"
     "  if (samples_started_) decision_.sample += 1 + lost;\n"),
    ("a stop confirmed after its trial's end stays latched",
     "if (trial_ended_ && decision_.state == PredictorState::Stopped) decision_.state = rest_state();",
     ""),
    ("a trial end without a model rests in idle",
     "    decision_.state = rest_state();\n}",
     "    decision_.state = PredictorState::Idle;\n}"),
    ("hard limit ignored",
     "if (std::fabs(rig[0]) > cfg_.hard_limit_n || std::fabs(rig[2]) > cfg_.hard_limit_n) {",
     "if (false && (std::fabs(rig[0]) > cfg_.hard_limit_n || std::fabs(rig[2]) > cfg_.hard_limit_n)) {"),
    ("bias not removed",
     "rig[k] = cfg_.mount.sign[k] * fs[cfg_.mount.axis[k]] - cfg_.mount.bias[k];",
     "rig[k] = cfg_.mount.sign[k] * fs[cfg_.mount.axis[k]];"),
    ("mount axes ignored",
     "rig[k] = cfg_.mount.sign[k] * fs[cfg_.mount.axis[k]] - cfg_.mount.bias[k];",
     "rig[k] = cfg_.mount.sign[k] * fs[k] - cfg_.mount.bias[k];"),
    ("timeout at >= instead of >",
     "now_ns - last_sample_ns_ > cfg_.sensor_timeout_ns",
     "now_ns - last_sample_ns_ >= cfg_.sensor_timeout_ns"),
    ("k + 1 samples needed",
     "if (++consecutive_ >= consecutive_needed_)",
     "if (++consecutive_ > consecutive_needed_)"),
    ("latch released before the echo",
     "(decision_.state == PredictorState::Stopped && !stop_pending_))",
     "decision_.state == PredictorState::Stopped)"),
    ("retry one period late",
     "if (stop_pending_ && now_ns - stop_sent_ns_ >= cfg_.stop_retry_ns) {",
     "if (stop_pending_ && now_ns - stop_sent_ns_ > cfg_.stop_retry_ns) {"),
    ("echo matched without its counter",
     "if (!stop_pending_ || f.id != stop_frame_.id || f.data[1] != stop_frame_.data[1]) return;",
     "if (!stop_pending_ || f.id != stop_frame_.id) return;"),
    ("an unconfirmed stop carried into the next trial",
     "stop_pending_ = false;\n  trial_ended_ = false;\n  decision_ = Decision{};",
     "trial_ended_ = false;\n  decision_ = Decision{};"),
    ("a young stop dropped silently",
     "if (stop_pending_ && !unconfirmed) {",
     "if (false) {"),
    ("a young stop refuses the next trial",
     "const bool unconfirmed = stop_pending_ && now_ns - stop_decided_ns_ >= cfg_.stop_retry_ns;",
     "const bool unconfirmed = stop_pending_;"),
    ("bad-frame budget at >= instead of >",
     "bad_score_ > static_cast<int64_t>(cfg_.bad_frame_budget) * cfg_.bad_frame_weight)",
     "bad_score_ >= static_cast<int64_t>(cfg_.bad_frame_budget) * cfg_.bad_frame_weight)"),
    ("an accepted sample does not drain the bad-frame budget",
     "if (bad_score_ > 0) --bad_score_;",
     ""),
    ("lost frames not charged to the budget",
     "      if (charge_lost) charge_bad(lost, now_ns);\n      return true;",
     "      return true;"),
    ("the budget not emptied at a trial start",
     "  bad_score_ = 0;\n  samples_started_ = false;",
     "  samples_started_ = false;"),
    ("a late frame counted as repeated",
     "case E2EStatus::Late: count(StatusCounter::Late); break;",
     "case E2EStatus::Late: count(StatusCounter::Repeated); break;"),
    ("a status page with its first counter twice",
     "const uint32_t v0 = counters_[2 * p], v1 = counters_[2 * p + 1];",
     "const uint32_t v0 = counters_[2 * p], v1 = counters_[2 * p];"),
    ("posteriors truncated, not rounded",
     "m.p[c] = static_cast<uint8_t>(std::lround(filter_->posterior(c) * 255.0));",
     "m.p[c] = static_cast<uint8_t>(filter_->posterior(c) * 255.0);"),
    ("the heartbeat reports the model as loaded",
     "static_cast<uint8_t>(filter_ ? 1 : 0), decision_.trial,",
     "static_cast<uint8_t>(1), decision_.trial,"),
    ("SIGTERM does not stop",
     "if (decision_.state == PredictorState::InTrial) stop(StopReason::Shutdown, now_ns);",
     "(void)now_ns;"),
    ("stop frame with a fixed reason",
     "stop_frame_ = protocol::encode(protocol::Stop{0, r,",
     "stop_frame_ = protocol::encode(protocol::Stop{0, StopReason::Caught,"),
    ("lost frames not counted in the sample index",
     "if (samples_started_) decision_.sample += 1 + lost;",
     "if (samples_started_) decision_.sample += 1;"),
    ("an allocation per sample",
     "void Predictor::on_force(const Frame& f, int64_t now_ns) noexcept {\n  uint32_t lost = 0;",
     "void Predictor::on_force(const Frame& f, int64_t now_ns) noexcept {\n  uint32_t lost = 0;\n"
     "  { std::vector<int> v(100); asm volatile(\"\" :: \"r\"(v.data()) : \"memory\"); }"),
    ("a trial starting after SIGTERM runs",
     "  shutting_down_ = true;\n",
     ""),
]

BRIDGE_FAULTS = [
    ("a repeated stop dropped",
     "if (protocol::e2e_crc(protocol::data_id_of(protocol::MsgId::Stop), f.data) != f.data[0] || !protocol::decode(f, s)) {",
     "if (true) {"),
    ("asked to stop again while latched",
     "if (c.stop_cause != StopCause::None) return BridgeAction::None;  // already latched",
     ""),
    ("released by a trial start that fails E2E",
     "if (protocol::accepted(checker.check(f, lost))) return true;",
     "return true;"),
    ("a sensor lost reported Ok",
     "return c.sensor_ok ? protocol::BridgeState::Ok : protocol::BridgeState::SensorLost;",
     "return protocol::BridgeState::Ok;"),
    ("silence at >= instead of >",
     "return static_cast<uint32_t>(now_ms - then) > ms;",
     "return static_cast<uint32_t>(now_ms - then) >= ms;"),
    ("silence stops again while latched",
     "if (timeout > 0 && c.stop_cause == StopCause::None) {",
     "if (timeout > 0) {"),
    ("heartbeat due compared without the wrap",
     "if (static_cast<int32_t>(now_ms - c.next_heartbeat_ms) < 0) return 0;",
     "if (now_ms < c.next_heartbeat_ms) return 0;"),
    ("the torque frame with a counter of its own",
     "out[1] = protocol::encode(protocol::FtTorque{n,",
     "out[1] = protocol::encode(protocol::FtTorque{c.sample_counter.next(),"),
    ("a reading releases the latch",
     "  c.sensor_ok = true;\n",
     "  c.sensor_ok = true;\n  c.stop_cause = StopCause::None;\n"),
    ("sensor errors wrap past 255",
     "if (c.sensor_errors < 255) ++c.sensor_errors;",
     "++c.sensor_errors;"),
    ("a reconnect not counted",
     "if (c.reconnects < 0xFFFF) ++c.reconnects;",
     ""),
    ("uptime from the clock, not from the start",
     "const uint32_t up = (now_ms - c.start_ms) / 1000;",
     "const uint32_t up = now_ms / 1000;"),
    ("a trial start releases a stop not yet written",
     "if (c.stop_cause != StopCause::None && !c.stop_written) return BridgeAction::None;",
     ""),
    ("a restarted robot controller's trial starts discarded as late",
     "    c.trial_checker.reset();\n",
     ""),
    ("a restarted predictor's heartbeats discarded as late",
     "if (silent_since(now_ms, c.last_predictor_ms)) c.predictor_hb_checker.reset();",
     ""),
    ("the predictor's state not taken from its heartbeat",
     "        c.predictor_state = hb.state;\n",
     ""),
    ("a shutdown stops the robot outside a trial",
     "if (c.stop_cause != StopCause::None || c.predictor_state != protocol::PredictorState::InTrial)",
     "if (c.stop_cause != StopCause::None)"),
    ("a trial's guard not taken from the heartbeat",
     "        note_guard(c, hb, now_ms);\n",
     ""),
    ("an unguarded trial not stopped",
     "else if (c.trial_running && !c.trial_guarded &&",
     "else if (false && c.trial_running && !c.trial_guarded &&"),
    ("another trial's id guards this one",
     "const bool guards = hb.trial_id == c.trial_id && (",
     "const bool guards = ("),
    ("any trial's end ends the running one",
     "if (m.trial_id == c.trial_id) c.trial_running = false;",
     "c.trial_running = false;"),
    ("a guard lost does not restart its clock",
     "if (!guards && c.trial_guarded) c.unguarded_since_ms = now_ms;",
     ""),
    ("a corrupted predictor heartbeat heard",
     "if (!protocol::accepted(c.predictor_hb_checker.check(f, lost))) {",
     "if (false) {"),
    ("a failed read does not advance the sample counter",
     "  bridge_on_periods_missed(c, 1);\n",
     ""),
    ("missed periods not put on the sample counter",
     "c.sample_counter.value = static_cast<uint8_t>(c.sample_counter.value + c.periods_missed);",
     ""),
    ("missed periods kept after a reading",
     "  c.periods_missed = 0;\n",
     ""),
    ("missed periods past the cap (read as a late frame)",
     "c.periods_missed += periods < room ? periods : room;",
     "c.periods_missed += periods;"),
    ("a trial start does not clear the robot's stop",
     "return BridgeAction::ReleaseRobot;",
     "return BridgeAction::None;"),
    ("the robot's stop cleared while a stop not yet written stands",
     "if (c.stop_cause != StopCause::None && !c.stop_written) return BridgeAction::None;",
     "if (c.stop_cause != StopCause::None && !c.stop_written) return BridgeAction::ReleaseRobot;"),
]

# target: (the core the faults go into, the other sources, include folders, the faults)
TARGETS = {
    "predictor": ("predictor/core/predictor_core.cpp",
                  ["tools/fuzz/fuzz_predictor.cpp", "firmware-bridge/protocol/dg_protocol.cpp", "models/dgm.cpp",
                   "predictor/filter/forward_filter.cpp", "predictor/filter/emission_update.cpp"],
                  ["tools/fuzz", "tests/predictor", "predictor/core", "firmware-bridge/protocol", "models",
                   "predictor/filter"],
                  PREDICTOR_FAULTS),
    "bridge": ("firmware-bridge/core/bridge_core.cpp",
               ["tools/fuzz/fuzz_bridge.cpp", "firmware-bridge/protocol/dg_protocol.cpp"],
               ["tools/fuzz", "firmware-bridge/core", "firmware-bridge/protocol"],
               BRIDGE_FAULTS),
}


def build(core_path, sources, includes, out):
    cmd = ["clang++", "-std=c++20", "-g", "-O1", "-fno-omit-frame-pointer", "-fsanitize=fuzzer,address,undefined",
           "-fno-sanitize-recover=undefined"] + ["-I" + os.path.join(SRC, d) for d in includes] + \
          [os.path.join(SRC, s) for s in sources] + [core_path, "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(f"mutants: clang++ failed for {core_path}:\n{r.stderr}\n")
        return False
    return True


def fuzz(binary, kind, seeds_tool, work, seconds):
    corpus = os.path.join(work, "corpus")
    r = subprocess.run([seeds_tool, kind, corpus], capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(f"mutants: {seeds_tool} failed: {r.stderr}\n")
        return None, 0.0
    t0 = time.monotonic()
    r = subprocess.run([binary, "-seed=1", "-max_len=8192", f"-max_total_time={seconds}", "-runs=100000000",
                        "-artifact_prefix=" + work + "/", corpus], capture_output=True, text=True)
    dt = time.monotonic() - t0
    m = re.search(r"rule broken at operation \d+: (.*)", r.stderr) or \
        re.search(r"ERROR: (\w+Sanitizer: [^\n]*)", r.stderr)
    if r.returncode == 0:
        return "", dt
    return (m.group(1) if m else f"exit {r.returncode}"), dt


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("target", choices=sorted(TARGETS))
    ap.add_argument("build_dir")
    ap.add_argument("--seconds", type=int, default=60)
    ap.add_argument("--only")
    a = ap.parse_args()
    seeds_tool = os.path.join(a.build_dir, "tools", "fuzz", "dg_fuzz_seeds")
    if not os.access(seeds_tool, os.X_OK):
        sys.stderr.write(f"mutants: {seeds_tool} not found: build dg_fuzz_seeds first\n")
        return 2
    core_file, sources, includes, faults = TARGETS[a.target]
    original = open(os.path.join(SRC, core_file)).read()
    runs = [("none (the source as it is)", None, None)] + faults
    if a.only:
        runs = [r for r in runs if a.only in r[0]]
    failures = 0
    with tempfile.TemporaryDirectory(prefix="dg-mutants-") as tmp:
        for i, (name, old, new) in enumerate(runs):
            work = os.path.join(tmp, str(i))
            os.makedirs(work)
            text = original
            if old is not None:
                if original.count(old) != 1:
                    sys.stderr.write(f"mutants: '{name}': the line is not once in {core_file}: {old!r}\n")
                    return 2
                text = original.replace(old, new)
            core = os.path.join(work, os.path.basename(core_file))
            with open(core, "w") as f:
                f.write(text)
            binary = os.path.join(work, "fuzz_" + a.target)
            if not build(core, sources, includes, binary):
                return 2
            found, dt = fuzz(binary, a.target, seeds_tool, work, a.seconds)
            if found is None:
                return 2
            ok = (found == "") if old is None else (found != "")
            failures += not ok
            verdict = "ok" if ok else "FAILED"
            what = found if found else f"clean for {dt:.0f} s"
            print(f"{verdict:6} {name:45} {dt:6.1f} s  {what}", flush=True)
    print(f"{len(runs) - failures} of {len(runs)} as expected")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
