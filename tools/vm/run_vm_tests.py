#!/usr/bin/python3
"""The SocketCAN test: boots Debian's kernel (PREEMPT_RT flavour) in qemu-system-x86_64 once and
runs every scenario of tools/vm/vm_tests.sh on a real kernel CAN stack (vcan0), then decodes the
recorded frames and asserts on them by their payloads' counters (logical time):

  clean     every caught trial is stopped for "caught" before the rig's 10 N limit (margin
            reported), no good or missed trial is stopped, the isolated-fault trial is not
            stopped, the corrupted burst is a bad_frames stop, and the daemon's counters (in its
            status frames and its shutdown log) count every injected fault exactly;
  hardlimit the hard limit stops at the first sample above 10 N;
  gap       a silent sensor is a sensor_timeout stop, one deadline after the last sample;
  nomodel   a model that does not load refuses the trial;
  unconfirmed  stop frames dropped on their way out (tc; vcan echo=1, so no echo): the stop is
            retried, never sent into the next trial, and that trial is refused
            (stop_unconfirmed) once the way out is clear;
  bridge    the firmware bridge on vcan0 against Modbus TCP peers (dg_modbus_emulator as the
            FT 300, a force past the limit, and as the robot controller): its readings reach the
            bus E2E-protected at about 100 Hz, the predictor stops the trial the robot starts at
            its first sample (hard limit), and the bridge takes that Stop frame from the bus and
            writes the robot's stop coil;
  latency   end to end through the kernel (probe send -> stop frame received), a histogram.
Every scenario ends with SIGTERM: the daemon must exit 0.

  run_vm_tests.py --build BUILD_DIR --source SOURCE_DIR --model MODEL.dgm [--cache DIR] [--kvm]

Exit 0 pass, 1 fail, 77 skip (no qemu, no busybox-static, or the kernel package cannot be had).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77
SENSOR_TIMEOUT_S = 0.200   # the deadline vm_tests.sh gives the daemon (the VM's clock jumps)
TICK_S = 0.001             # its timer
VM_SLACK_S = 0.100         # emulated CPU (TCG) scheduling: not a real-time measurement


def crc8_h2f(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x2F) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def parse_frame(line):
    m = re.match(r"\((\d+)\.(\d{6})\) (\S+) ([0-9A-Fa-f]{3})#([0-9A-Fa-f]*)", line.strip())
    if not m:
        return None
    t = int(m.group(1)) + int(m.group(2)) / 1e6
    return t, int(m.group(4), 16), bytes.fromhex(m.group(5))


def e2e_ok(can_id, data):
    if len(data) != 8:
        return False
    did = 0xD000 | can_id
    return crc8_h2f(bytes([did & 0xFF, did >> 8]) + data[1:]) == data[0]


def protect(can_id, payload):
    """A protocol frame as cansend takes it: CRC, then counter and payload (7 bytes)."""
    did = 0xD000 | can_id
    crc = crc8_h2f(bytes([did & 0xFF, did >> 8]) + payload)
    return f"{can_id:03X}#" + (bytes([crc]) + payload).hex().upper()


BRIDGE_TRIAL = 77  # the bridge scenario's trial id (TrialStart: counter 0, 100 mm/s, middle arm)


def i16(d, o):
    return int.from_bytes(d[o:o + 2], "little", signed=True)


def u16(d, o):
    return int.from_bytes(d[o:o + 2], "little")


STOP_REASONS = {1: "caught", 2: "hard_limit", 3: "sensor_timeout", 4: "bad_frames", 5: "model_error", 6: "shutdown",
                7: "stop_unconfirmed"}
COUNTERS = ["corrupted", "repeated", "wrong_sequence", "lost_frames", "late", "bad_length", "kernel_drops",
            "timeouts", "tx_retries", "tx_errors", "samples", "stops"]


def log_facts(path):
    """Trial id, samples per TrialEnd, first sample above 10 N (identity mount) of a test log."""
    facts = {"trial": None, "samples": None, "first_over": None}
    index = -1
    with open(path) as f:
        for line in f:
            fr = parse_frame(line)
            if not fr:
                continue
            _, cid, d = fr
            if cid == 0x180:
                facts["trial"] = u16(d, 2)
            elif cid == 0x181:
                facts["samples"] = u16(d, 4)
            elif cid == 0x100:
                index += 1
                if facts["first_over"] is None and (abs(i16(d, 2)) > 1000 or abs(i16(d, 6)) > 1000):
                    facts["first_over"] = index
    return facts


def sections(console):
    out = {}
    for m in re.finditer(r"DG-VM-BEGIN (\S+)\r?\n(.*?)DG-VM-END \1", console, re.S):
        out[m.group(1)] = m.group(2).replace("\r", "")
    return out


def heard_by_manager(text):
    """dg_notify_listen's summary: each message kind (count, sender, longest gap) in the order
    they first came, and the listener's exit and the daemon's pid that vm_tests.sh appended."""
    out = {"kinds": []}
    for line in text.splitlines():
        m = re.match(r"(\S+) count=(\d+) pid=(\d+) first_ms=(\d+)(?: max_gap_ms=(\d+))?( other_senders)?$", line)
        if m:
            k = {"message": m.group(1), "count": int(m.group(2)), "pid": m.group(3), "other": bool(m.group(6))}
            if m.group(5):
                k["max_gap_ms"] = int(m.group(5))
            out["kinds"].append(k)
        m = re.match(r"status_(first|last) (.*)$", line)
        if m:
            out["status_" + m.group(1)] = m.group(2)
        m = re.match(r"listener_exit (\d+) daemon_pid (\d+)", line)
        if m:
            out["listener_exit"], out["daemon_pid"] = m.group(1), m.group(2)
    return out


def stops_in(rec):
    stops = []
    for line in rec.splitlines():
        fr = parse_frame(line)
        if fr and fr[1] == 0x080:
            t, _, d = fr
            stops.append({"t": t, "ok": e2e_ok(0x080, d), "reason": STOP_REASONS.get(d[2], str(d[2])),
                          "p_caught": d[3] / 255.0, "trial": u16(d, 4), "sample": u16(d, 6)})
    return stops


def first_stop_per_trial(stops):
    out = {}
    for s in stops:
        out.setdefault(s["trial"], s)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--cache", default=None)
    ap.add_argument("--timeout", type=int, default=300)
    ap.add_argument("--kvm", action="store_true", help="use KVM instead of software emulation (TCG); needs working (nested) KVM: on the build VM it hangs")
    ap.add_argument("--keep-console", default=None, help="write the VM's console output here")
    args = ap.parse_args()
    qemu = shutil.which("qemu-system-x86_64")
    if not qemu:
        print("SKIP: qemu-system-x86_64 is not installed (tools/install-deps.sh installs qemu-system-x86)")
        return SKIP
    cache = args.cache or os.path.join(args.source, "build", "vm")
    logs_dir = os.path.join(args.source, "tests", "data", "robot")
    bins = [os.path.join(args.build, "predictor", "daemon", "dressguard-predictor"),
            os.path.join(args.build, "tools", "bench", "bench_predictor"),
            os.path.join(args.build, "firmware-bridge", "dressguard-bridge"),
            os.path.join(args.build, "tests", "robot", "dg_modbus_emulator"),
            os.path.join(args.build, "tests", "robot", "dg_notify_listen")]
    for b in bins:
        if not os.path.exists(b):
            print(f"FAIL: {b} not built")
            return 1
    fails = []

    def check(cond, what):
        print(("  ok    " if cond else "  FAIL  ") + what)
        if not cond:
            fails.append(what)

    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "data")
        os.makedirs(os.path.join(data, "logs"))
        for f in sorted(os.listdir(logs_dir)):
            shutil.copy(os.path.join(logs_dir, f), os.path.join(data, "logs", f))
        shutil.copy(args.model, os.path.join(data, "model.dgm"))
        with open(os.path.join(data, "bridge-trial-start.txt"), "w") as f:
            trial_start = bytes([0]) + BRIDGE_TRIAL.to_bytes(2, "little") + (100).to_bytes(2, "little") + bytes([1, 0])
            f.write(protect(0x180, trial_start) + "\n")
        # Per run: the release and sanitize builds share the kernel cache, not their initramfs.
        initrd = os.path.join(tmp, "initramfs.gz")
        cmd = [os.path.join(args.source, "tools", "vm", "build_initramfs.sh"), "--cache", cache, "--out", initrd,
               "--data", data, "--script", os.path.join(args.source, "tools", "vm", "vm_tests.sh")]
        for b in bins:
            cmd += ["--bin", b]
        t0 = time.time()
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode == SKIP:
            print("SKIP: " + (r.stderr.strip() or "no kernel package"))
            return SKIP
        if r.returncode != 0:
            print("FAIL: initramfs build failed:\n" + r.stderr)
            return 1
        kernel = r.stdout.strip().splitlines()[-1]
        print(f"initramfs built in {time.time() - t0:.1f} s; kernel {os.path.basename(kernel)}")
        accel = ["-accel", "kvm", "-cpu", "host"] if args.kvm else ["-accel", "tcg"]
        qcmd = [qemu, "-m", "768", "-smp", "2", "-nographic", "-no-reboot", *accel, "-kernel", kernel, "-initrd", initrd,
                "-append", "console=ttyS0 panic=-1 quiet loglevel=3"]
        t0 = time.time()
        try:
            q = subprocess.run(qcmd, capture_output=True, text=True, timeout=args.timeout, errors="replace")
            console = q.stdout
        except subprocess.TimeoutExpired as e:
            console = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
            fails.append(f"VM did not finish within {args.timeout} s")
        boot_s = time.time() - t0
    if args.keep_console:
        with open(args.keep_console, "w") as f:
            f.write(console)
    print(f"VM ran {boot_s:.1f} s ({'KVM' if args.kvm else 'software emulation'})")
    m = re.search(r"DG-VM: kernel (\S+) (.*)", console)
    check(m is not None, "the VM booted Debian's kernel: " + (m.group(1) + " " + m.group(2).strip() if m else "no"))
    # The RT flavour is the one asked for; the generic one is fetch_kernel.sh's fallback when the
    # archive lacks it. Either way the booted kernel must be the flavour its release names.
    if m:
        rt_release, rt_booted = "-rt-" in m.group(1), "PREEMPT_RT" in m.group(2)
        check(rt_release == rt_booted, f"the kernel's release and build agree on PREEMPT_RT ({rt_booted})")
        if not rt_booted:
            print("  NOTE  generic kernel (linux-image-rt-amd64 could not be had): not a PREEMPT_RT run")
    check("DG-VM: done" in console, "the in-VM script ran to its end")
    check("DG-VM: insmod" not in console, "can, can-raw, can-dev, vcan loaded")
    late = re.findall(r"scenario (\S+): daemon not listening", console)
    check(not late, "every scenario's daemon was listening before the play" + (f" (not: {', '.join(late)})" if late else ""))
    sec = sections(console)
    check("scenario unconfirmed: tc" not in console, "unconfirmed: tc dropped 0x080 on its way out of vcan0")
    played = re.findall(r"PLAYFAIL (.*)", console)
    check(not played, "every log was played" + (f" (not: {'; '.join(p.strip() for p in played)})" if played else ""))
    for name in ("clean", "hardlimit", "gap", "nomodel", "unconfirmed", "bridge", "latency"):
        m = re.search(rf"DG-VM: \[[\d.]+\] scenario {name} daemon_exit (\d+)", console)
        check(m is not None and m.group(1) == "0", f"{name}: the daemon exited 0 on SIGTERM")
        check("shutting down" in sec.get(f"{name}.log", ""), f"{name}: clean shutdown logged")

    # --- the service manager's socket (Type=notify, WatchdogSec=0.4 as a unit would set them) ---
    gaps = []
    for name in ("clean", "hardlimit", "gap", "nomodel", "unconfirmed", "bridge", "latency", "bridge-app"):
        heard = heard_by_manager(sec.get(f"{name}.notify", ""))
        who = "the bridge" if name == "bridge-app" else f"{name}: the daemon"
        daemon = heard.get("daemon_pid")
        ran = daemon is not None and heard.get("listener_exit") == "0"
        check(ran, f"{who}: the notify listener ran" +
              ("" if ran else f" ({sec.get(name + '.notify', 'no section').strip()[-300:]})"))
        kinds = heard.get("kinds", [])
        said = {k["message"]: k for k in kinds}
        # A status line may come first (the predictor's "listening on", set before its loop runs).
        order = [k["message"] for k in kinds if k["message"] != "STATUS="]
        check(bool(order) and order[0] == "READY=1" and said["READY=1"]["count"] == 1,
              f"{who} said READY=1 once, before any ping or STOPPING ({[k['message'] for k in kinds]})")
        check("STOPPING=1" in said and said["STOPPING=1"]["count"] == 1, f"{who} said STOPPING=1 once at SIGTERM")
        check("WATCHDOG=1" in said, f"{who} fed its watchdog ({said.get('WATCHDOG=1', {}).get('count', 0)} pings)")
        check(all(k["pid"] == daemon and not k["other"] for k in kinds) and set(said) <= {"READY=1", "WATCHDOG=1",
                                                                                          "STOPPING=1", "STATUS="},
              f"{who}: every message from its own process ({daemon}), none other")
        if name == "bridge-app":
            # What the line says of the sensor is the state when the bridge last spoke: under
            # emulation with two test suites beside it, the in-VM Modbus peer has answered a
            # last poll too late ("sensor not connected; ... Connection timed out", session 92),
            # which the bridge reports as it should. The stop it wrote must be counted either way.
            last = heard.get("status_last", "")
            check(re.match(r"sensor (ok|failing|not connected); stops written [1-9]", last) is not None,
                  f"the bridge's last status line counts the stop it wrote ('{last}')")
        else:
            # The unit's status line: where it listens until the first trial, then the trials.
            first = heard.get("status_first", "")
            check(first.startswith("listening on vcan0, ") and
                  ("no model" in first) == (name == "nomodel"),
                  f"{who}'s first status line says where it listens ('{first}')")
            if name in ("clean", "hardlimit"):
                last = heard.get("status_last", "")
                counted = re.match(r"(idle|trial \d+ (running|stopped: \w+)); trials [1-9]\d*, stopped \d+", last)
                check(counted is not None, f"{who}'s last status line counts its trials ('{last}')")
        if "WATCHDOG=1" in said and "max_gap_ms" in said["WATCHDOG=1"]:
            gaps.append(f"{name} {said['WATCHDOG=1']['max_gap_ms']}")
    # Not asserted: the emulated VM's clock jumps when the host deschedules it (see the 200 ms
    # sensor deadline); a systemd watchdog at 0.4 s would fire at a gap above 400 ms.
    print(f"  watchdog pings' longest gap (ms; due every 200): {', '.join(gaps)}")

    facts = {f: log_facts(os.path.join(logs_dir, f)) for f in os.listdir(logs_dir)}

    # --- clean trials and isolated faults ---
    rec = sec.get("clean.rec", "")
    check(rec.count("#") > 100, f"clean: the bus was recorded ({rec.count('#')} frames)")
    stops = stops_in(rec)
    check(all(s["ok"] for s in stops), f"clean: every stop frame passes its E2E CRC ({len(stops)} frames)")
    first = first_stop_per_trial(stops)
    # The trials the bus carried (TrialStart 0x180 and TrialEnd 0x181, by trial id): a trial that
    # never reached the daemon must not pass as "not stopped".
    starts, ends = set(), set()
    for line in rec.splitlines():
        fr = parse_frame(line)
        if fr and fr[1] in (0x180, 0x181) and len(fr[2]) == 8:
            (starts if fr[1] == 0x180 else ends).add(u16(fr[2], 2))
    margins = []
    for f, fa in sorted(facts.items()):
        if not f.startswith("syn2-") and not f.startswith("fault-isolated") and not f.startswith("fault-burst"):
            continue
        s = first.get(fa["trial"])
        check(fa["trial"] in starts and fa["trial"] in ends, f"{f}: trial {fa['trial']} started and ended on the bus")
        if f.endswith("-caught.log"):
            ok = s is not None and s["reason"] == "caught" and s["sample"] < fa["samples"]
            margin = (fa["samples"] - s["sample"]) * 0.01 if s else float("nan")
            margins.append(margin)
            check(ok, f"{f}: stopped ({s['reason'] if s else 'none'}) at sample {s['sample'] if s else '-'}, "
                      f"{margin:.2f} s before the 10 N limit (sample {fa['samples']})")
        elif f.endswith("-expect-bad_frames.log"):
            check(s is not None and s["reason"] == "bad_frames", f"{f}: bad_frames stop ({s['reason'] if s else 'none'})")
        else:
            check(s is None, f"{f}: not stopped" + (f" (stopped: {s['reason']} at {s['sample']})" if s else ""))
    if margins:
        print(f"  caught trials: smallest margin before the 10 N limit {min(margins):.2f} s, largest {max(margins):.2f} s")
    # Counters from the daemon's shutdown line and from its status frames' pages.
    m = re.search(r"shutting down: (.*)", sec.get("clean.log", ""))
    counters = dict((k, int(v)) for k, v in re.findall(r"(\w+)=(\d+)", m.group(1))) if m else {}
    pages = {}
    for line in rec.splitlines():
        fr = parse_frame(line)
        if fr and fr[1] == 0x300 and e2e_ok(0x300, fr[2]):
            d = fr[2]
            pages[d[2]] = (u16(d, 4), u16(d, 6))
    status = {}
    check(len(pages) == 6, f"clean: all 6 status pages seen ({sorted(pages)})")
    for p, (v0, v1) in pages.items():
        if 2 * p + 1 < len(COUNTERS):
            status[COUNTERS[2 * p]], status[COUNTERS[2 * p + 1]] = v0, v1
    print(f"  daemon counters: {counters}")
    # Injected: isolated log --corrupt 50,300 (2 frames each) --drop 120 --repeat 200 --delay 250:2;
    # burst log --corrupt 100..107 (2 frames each). See tools/vm/make_test_logs.sh.
    expected = {"corrupted": 4 + 16, "repeated": 2, "late": 2, "wrong_sequence": 2, "lost_frames": 8 + 16,
                "bad_length": 0, "timeouts": 0, "stops": 4}
    for k, v in expected.items():
        check(counters.get(k) == v, f"clean: counter {k} = {counters.get(k)} (injected: {v})")
        check(status.get(k) == counters.get(k), f"clean: status frames report {k} = {status.get(k)}")
    drops = re.findall(r"DROPCOUNT: rx (\d+)", rec)
    print(f"  candump -d drop reports: {len(drops)}; kernel drops counted by the daemon: {counters.get('kernel_drops')}")

    # --- hard limit ---
    rec = sec.get("hardlimit.rec", "")
    hl = [f for f in facts if "expect-hard_limit" in f][0]
    s = first_stop_per_trial(stops_in(rec)).get(facts[hl]["trial"])
    check(s is not None and s["reason"] == "hard_limit" and s["sample"] == facts[hl]["first_over"],
          f"hardlimit: stop at the first sample above 10 N ({facts[hl]['first_over']}): "
          f"{(s['reason'], s['sample']) if s else 'none'}")
    # Kernel timestamps (candump) of the deciding force frame and the stop frame.
    frames = [parse_frame(l) for l in rec.splitlines()]
    forces = [fr for fr in frames if fr and fr[1] == 0x100]
    if s and s["sample"] < len(forces):
        print(f"  hardlimit: deciding frame in -> stop frame out on vcan0 (candump timestamps): "
              f"{(s['t'] - forces[s['sample']][0]) * 1e6:.0f} us")

    # --- silent sensor ---
    rec = sec.get("gap.rec", "")
    gp = [f for f in facts if "expect-sensor_timeout" in f][0]
    s = first_stop_per_trial(stops_in(rec)).get(facts[gp]["trial"])
    frames = [parse_frame(l) for l in rec.splitlines()]
    forces = [fr for fr in frames if fr and fr[1] == 0x100]
    check(s is not None and s["reason"] == "sensor_timeout" and s["sample"] == 150,
          f"gap: sensor_timeout stop at sample 150: {(s['reason'], s['sample']) if s else 'none'}")
    if s:
        before = [fr for fr in forces if fr[0] <= s["t"]]
        silent = s["t"] - before[-1][0] if before else float("nan")
        check(SENSOR_TIMEOUT_S <= silent <= SENSOR_TIMEOUT_S + TICK_S + VM_SLACK_S,
              f"gap: stop {silent * 1e3:.1f} ms after the last sample (deadline {SENSOR_TIMEOUT_S * 1e3:.0f} ms, "
              f"+{VM_SLACK_S * 1e3:.0f} ms allowed for the emulated CPU)")

    # --- no model ---
    s = stops_in(sec.get("nomodel.rec", ""))
    check(len(s) >= 1 and s[0]["reason"] == "model_error", f"nomodel: model_error stop ({s[0]['reason'] if s else 'none'})")

    # --- stop frames that never reach the bus ---
    s = stops_in(sec.get("unconfirmed.rec", ""))
    first, second = facts[hl]["trial"], facts["syn2-good-0-good.log"]["trial"]
    check(len(s) >= 1 and all(x["ok"] and x["trial"] == second and x["reason"] == "stop_unconfirmed" for x in s),
          f"unconfirmed: on the bus only trial {second}'s refusal (stop_unconfirmed): "
          f"{sorted(set((x['trial'], x['reason']) for x in s)) or 'no stop'}")
    check(not any(x["trial"] == first for x in s), f"unconfirmed: trial {first}'s stop never reached the bus")
    m = re.search(r"shutting down: (.*)", sec.get("unconfirmed.log", ""))
    uc = dict((k, int(v)) for k, v in re.findall(r"(\w+)=(\d+)", m.group(1))) if m else {}
    check(uc.get("tx_retries", 0) >= 10, f"unconfirmed: the unechoed stop was retried ({uc.get('tx_retries')} retries)")

    # --- the firmware bridge on SocketCAN ---
    rec = sec.get("bridge.rec", "")
    blog = sec.get("bridge-app.log", "")
    frames = [fr for fr in (parse_frame(l) for l in rec.splitlines()) if fr]
    forces = [fr for fr in frames if fr[1] == 0x100]
    # The bridge polls every 10 ms (about 300 readings in the 3 s), but the VM's CPU is emulated:
    # with two test suites beside it, readings came every 26.6 ms (median) and 89 reached the bus.
    # What is checked is that readings flow and are protected, not the poll rate: a tenth of it.
    check(len(forces) >= 30 and all(e2e_ok(0x100, fr[2]) for fr in forces),
          f"bridge: its readings on vcan0, E2E-protected ({len(forces)} FtForce frames in about 3 s)")
    check(all(i16(fr[2], 2) == 1200 for fr in forces), "bridge: each carries the sensor's Fx, 1200 counts (12.00 N)")
    if len(forces) > 10:
        gaps = sorted(b[0] - a[0] for a, b in zip(forces, forces[1:]))
        print(f"  bridge: readings every {gaps[len(gaps) // 2] * 1e3:.1f} ms (median; the sensor is polled every 10 ms)")
    hbs = [fr for fr in frames if fr[1] == 0x700 and e2e_ok(0x700, fr[2])]
    check(len(hbs) >= 10, f"bridge: its heartbeat on vcan0 ({len(hbs)} frames)")
    s = first_stop_per_trial(stops_in(rec)).get(BRIDGE_TRIAL)
    check(s is not None and s["ok"] and s["reason"] == "hard_limit" and s["sample"] == 0,
          f"bridge: the predictor stopped trial {BRIDGE_TRIAL} at its first sample (hard limit): "
          f"{(s['reason'], s['sample']) if s else 'none'}")
    check(hbs and hbs[-1][2][2] == 2, "bridge: its last heartbeat says stop latched")
    check("stop frame from the predictor: hard_limit" in blog and "stop written to the robot controller" in blog,
          "bridge: took the Stop frame from vcan0 and wrote the robot's stop coil")
    check("has not guarded" not in blog and "no heartbeat from the predictor" not in blog,
          "bridge: the predictor's heartbeat guarded the trial (no stop of the bridge's own)")
    # Its own file: one shared with the scenario's predictor lost lines to the other's writes.
    strays = [l for l in blog.splitlines() if l.strip() and not l.startswith("dressguard-bridge: ")
              and not re.match(r"bridge_exit \d+$", l)]
    check(not strays, "bridge: its log holds its own lines only" + (f" (not: {strays[:3]})" if strays else ""))
    # On failure, the exit status and the bridge's last words: the console keeps only its tail.
    bexit = re.search(r"^bridge_exit (\d+)", blog, re.M)
    check(bexit is not None and bexit.group(1) == "0",
          "bridge: exited 0 on SIGTERM" + ("" if bexit and bexit.group(1) == "0" else
                                          f" (exit {bexit.group(1) if bexit else 'not recorded'}; its log ends:\n    "
                                          + "\n    ".join(blog.strip().splitlines()[-8:]) + ")"))

    # --- latency ---
    lat = sec.get("latency.out", "")
    print("  " + "\n  ".join(l for l in lat.splitlines() if l.strip()))
    m = re.search(r"(\d+) trials, (\d+) without a stop", lat)
    check(m is not None and m.group(1) == "1000" and m.group(2) == "0",
          "latency: every probe trial got its stop frame" + (f" ({m.group(2)} of {m.group(1)} without)" if m else " (no result)"))
    m = re.search(r"e2e_socketcan: n=(\d+)", lat)
    check(m is not None and m.group(1) == "1000", f"latency: 1000 latencies measured ({m.group(1) if m else 'none'})")
    check(re.search(r"^bench_exit 0$", lat, re.M) is not None, "latency: the probe exited 0")
    m = re.search(r"processing latency \(frame read to decision\): n=(\d+) median=(\d+) ns p99.9=(\d+) ns", sec.get("clean.log", ""))
    if m:
        print(f"  daemon processing in the VM (clean scenario): n={m.group(1)} median={m.group(2)} ns p99.9={m.group(3)} ns")

    print(f"{len(fails)} failure(s)")
    if fails and not args.keep_console:
        print("---- console tail ----")
        print(console[-4000:])
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
