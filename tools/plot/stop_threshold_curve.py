#!/usr/bin/python3
"""The stop rule's operating curve: what each stop threshold costs and buys at the study's mix.

The predictor stops the robot when P(caught) stays above `stop_threshold` for `stop_consecutive`
samples. The threshold is the deployer's choice. This tool replays the same candump logs
through the predictor's own code (`dressguard replay --logs DIR --set ... --json`) at each
threshold. It weights each outcome's stop rate by that outcome's share of the study's protocol:
360 pulls, 120 good at the high arm, 120 missed at the low arm, and 91 caught and 29 missed at
the middle arm (shared/data README). It reports, per 100 pulls:
  - stopped for nothing: good, low-arm missed and middle-arm missed pulls stopped for "caught"
    (stops for a fault or the hard limit are the rig's, not the threshold's, and are not counted);
  - catches stopped: the caught rate times 91 of 360.
A log's outcome is the end of its name (-good.log, -missed.log, -caught.log, as `export-candump`
names them). A missed log is a middle-arm miss when its name holds "middlemiss" (the study's
trial ids, e.g. s2-middlemiss-7-missed.log) and a low-arm miss otherwise. Logs of other names are
left out. From a --caught-logs folder only the caught logs count: the study recorded no caught
pull, so the caught ones are synthetic, and their folder's other trials are no measured mix.
Without caught logs the catches column is empty; an outcome without logs counts as never
stopped and is flagged. Every threshold is replayed with the model's own stop_consecutive
(`dressguard model show --json`) unless --consecutive N sets another.

usage: stop_threshold_curve.py OUT.png --model MODEL.dgm --logs DIR [--logs DIR ...]
           [--caught-logs DIR ...] [--dressguard BIN] [--consecutive N] [--thresholds T,T,...]
           [--json OUT.json]
models/README.md, "The stop rule on the real pulls".
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import save_figure  # a temporary file, then a rename

# The study's protocol (shared/data README): pulls of each kind out of 360.
PROTOCOL = {"good": 120, "low missed": 120, "middle missed": 29, "caught": 91}
TOTAL = sum(PROTOCOL.values())
DEFAULT_THRESHOLDS = "0.5,0.7,0.8,0.9,0.95,0.99,0.999,0.9999"


def kind_of(file, label):
    if label == "missed":
        return "middle missed" if "middlemiss" in file else "low missed"
    return label if label in ("good", "caught") else None


def replay(args, logs, threshold):
    cmd = [args.dressguard, "replay", "--model", args.model, "--logs", logs, "--set", f"stop_threshold={threshold}"]
    if args.consecutive is not None:  # else the model's own, as the daemon takes it
        cmd += ["--set", f"stop_consecutive={args.consecutive}"]
    cmd.append("--json")
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"stop_threshold_curve.py: {' '.join(cmd)} failed ({run.returncode}): "
                 f"{run.stderr.strip() or run.stdout.strip()}")
    return json.loads(run.stdout)["trials"]


def model_consecutive(args):
    """The model's own stop_consecutive (what replay and the daemon use without a setting)."""
    cmd = [args.dressguard, "model", "show", args.model, "--json"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"stop_threshold_curve.py: {' '.join(cmd)} failed ({run.returncode}): "
                 f"{run.stderr.strip() or run.stdout.strip()}")
    return json.loads(run.stdout)["stop_consecutive"]


def point(args, threshold):
    """Stops and trials per kind at one threshold, over every --logs folder."""
    tally = {k: [0, 0] for k in PROTOCOL}
    leads = []  # seconds between each caught stop of a caught pull and that pull's own end
    folders = [(d, False) for d in args.logs] + [(d, True) for d in args.caught_logs]
    for logs, caught_only in folders:
        for t in replay(args, logs, threshold):
            k = kind_of(t["file"], t["label"])
            if k is None or (caught_only and k != "caught"):
                continue
            tally[k][1] += 1
            stopped = bool(t["stopped"]) and t["reason"] == "caught"
            tally[k][0] += stopped
            if stopped and k == "caught" and t.get("lead") is not None:
                leads.append(t["lead"])
    rate = {k: (s / n if n else None) for k, (s, n) in tally.items()}
    nothing = sum(100.0 * PROTOCOL[k] / TOTAL * (rate[k] or 0.0)
                  for k in ("good", "low missed", "middle missed"))
    catches = None if rate["caught"] is None else 100.0 * PROTOCOL["caught"] / TOTAL * rate["caught"]
    return {"threshold": threshold, "stops": tally, "stopped_for_nothing_per_100": nothing,
            "catches_stopped_per_100": catches,
            "median_lead_s": statistics.median(leads) if leads else None}


def place_labels(fig, ax, labels, downwards):
    """Each (x, y) point's label beside it, above or, where downwards(y), below, pushed a row
    further out until it overlaps no label placed before it and no tick label."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ticks = ax.get_xticklabels() + (ax.get_yticklabels() if ax.yaxis.get_visible() else [])
    taken = [t.get_window_extent(renderer) for t in ticks if t.get_visible() and t.get_text()]
    for (x, y), names in sorted(labels.items()):
        down = downwards(y)
        for row in range(12):
            off = 6 + 9 * row
            text = ax.annotate("\n".join(names), (x, y), textcoords="offset points", xytext=(3, -off if down else off),
                               va="top" if down else "bottom", fontsize=7)
            box = text.get_window_extent(renderer)
            if not any(box.overlaps(t) for t in taken):
                break
            text.remove()
        else:
            text = ax.annotate("\n".join(names), (x, y), textcoords="offset points", xytext=(3, 6), fontsize=7)
        taken.append(text.get_window_extent(renderer))


def draw(points, consecutive, model, own=False):
    """The operating curve: catches stopped against pulls stopped for nothing per 100 pulls, one
    point per threshold, labelled with it (and the caught stops' median lead). Without caught logs
    the catches were not measured: the thresholds lie along the one axis that was, with a note;
    a catches axis at 0 read as a rule that stops no catch (session 85's tools review, finding 6).
    own: consecutive is the model's own stop_consecutive (no --consecutive), and the title says so."""
    caught = points[0]["stops"]["caught"][1] > 0
    xs = [q["stopped_for_nothing_per_100"] for q in points]
    top = 100 * PROTOCOL["caught"] / TOTAL
    if caught:
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        ys = [q["catches_stopped_per_100"] for q in points]
        ax.plot(xs, ys, "o-", color="tab:red")
        ax.axhline(top, color="grey", ls=":", lw=1)
        ax.set_ylabel(f"catches stopped per 100 pulls (of {top:.1f})")
        ax.set_ylim(0, top * 1.08)
        ax.grid(alpha=0.3)
    else:
        fig, ax = plt.subplots(figsize=(6.4, 2.6))
        ys = [0.0] * len(points)
        ax.plot(xs, ys, "o", color="tab:red", clip_on=False, zorder=3)
        ax.set_ylim(0, 1)
        ax.yaxis.set_visible(False)
        for side in ("left", "right", "top"):
            ax.spines[side].set_visible(False)
        ax.grid(axis="x", alpha=0.3)
        ax.text(0.5, 1.0, "catches stopped: not measured (no caught logs; the study recorded no caught pull,\n"
                "--caught-logs adds synthetic ones)", transform=ax.transAxes, ha="center", va="top", fontsize=8,
                color="0.3")
    ax.set_xlabel("pulls stopped for nothing per 100 (good, low and middle misses)")
    whose = " (the model's)" if own else ""
    ax.set_title(f"stop rule: P(caught) > threshold for {consecutive} samples{whose}\n"
                 f"{os.path.basename(model)}, weighted by the study's protocol (360 pulls)", fontsize=10)
    ax.set_xlim(left=0, right=max(xs + [1.0]) * 1.12)
    fig.tight_layout()
    # Thresholds that land on the same point share one label.
    labels = {}
    for q, x, y in zip(points, xs, ys):
        lead = "" if q["median_lead_s"] is None else f" ({q['median_lead_s']:.2f} s)"
        labels.setdefault((x, y), []).append(f"{q['threshold']:g}{lead}")
    # Below a point only where the curve leaves room above the x axis's tick labels.
    place_labels(fig, ax, labels, lambda y: caught and y > 0.3 * top)
    return fig


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out")
    p.add_argument("--model", required=True)
    p.add_argument("--logs", action="append", required=True)
    p.add_argument("--caught-logs", action="append", default=[])
    p.add_argument("--dressguard", default=os.path.join(os.path.dirname(__file__), "..", "..", "build",
                                                       "release", "offline", "cli", "dressguard"))
    p.add_argument("--consecutive", type=int, default=None,
                   help="stop_consecutive at every threshold (default: the model's own)")
    p.add_argument("--thresholds", default=DEFAULT_THRESHOLDS)
    p.add_argument("--json", dest="json_out")
    args = p.parse_args()
    for path, what in [(args.model, "model"), (args.dressguard, "dressguard binary")]:
        if not os.path.isfile(path):
            sys.exit(f"stop_threshold_curve.py: {path}: no such {what}")
    try:
        thresholds = [float(t) for t in args.thresholds.split(",")]
    except ValueError:
        sys.exit(f"stop_threshold_curve.py: --thresholds '{args.thresholds}' is not a comma-separated list of numbers")
    if not thresholds or any(not 0.0 < t < 1.0 for t in thresholds) or (args.consecutive is not None
                                                                          and args.consecutive < 1):
        sys.exit("stop_threshold_curve.py: every threshold must lie in (0, 1) and --consecutive be at least 1")

    own = args.consecutive is None
    consecutive = model_consecutive(args) if own else args.consecutive
    points = [point(args, t) for t in sorted(thresholds)]
    counts = points[0]["stops"]
    missing = [k for k in ("good", "low missed", "middle missed") if counts[k][1] == 0]
    print(f"stop_consecutive {consecutive}" + (" (the model's)" if own else " (--consecutive)"))
    print(f"{'threshold':>10}  {'good':>7} {'low miss':>8} {'mid miss':>8} {'caught':>7}   "
          f"stopped for nothing / 100   catches stopped / 100 (of {100 * PROTOCOL['caught'] / TOTAL:.0f})"
          f"   median lead [s]")
    for q in points:
        s = q["stops"]
        cell = lambda k: f"{s[k][0]}/{s[k][1]}" if s[k][1] else "-"
        catches = "-" if q["catches_stopped_per_100"] is None else f"{q['catches_stopped_per_100']:.1f}"
        lead = "-" if q["median_lead_s"] is None else f"{q['median_lead_s']:.2f}"
        print(f"{q['threshold']:>10g}  {cell('good'):>7} {cell('low missed'):>8} {cell('middle missed'):>8} "
              f"{cell('caught'):>7}   {q['stopped_for_nothing_per_100']:>25.1f}   {catches:>21}   {lead:>16}")
    if missing:
        print(f"no logs of: {', '.join(missing)} (counted as never stopped)")
    if counts["caught"][1] == 0:
        print("no caught logs: no catches column (the study recorded no caught pull; --caught-logs adds synthetic ones)")

    fig = draw(points, consecutive, args.model, own)
    save_figure(fig, args.out, dpi=120)
    print(f"wrote {args.out}")
    if args.json_out:
        with open(args.json_out + ".tmp", "w") as fh:
            json.dump({"model": args.model, "consecutive": consecutive,
                       "consecutive_from": "model" if own else "--consecutive", "protocol": PROTOCOL,
                       "points": points}, fh, indent=1)
        os.replace(args.json_out + ".tmp", args.json_out)


if __name__ == "__main__":
    main()
