#!/usr/bin/python3
"""Checks of tools/plot's pictures and errors (session 85's tools review, findings 5, 6 and 8).

usage: plot_checks.py CHECK SOURCE_DIR WORK_DIR
  legends     calib_overlay.py's residual and predict legends stand outside every panel (inside
              one they hid the residual's worst windows); standing's legend is outside the bars
              and no value label sits under the paper's mark
  threshold   stop_threshold_curve.py without caught logs draws no catches axis (it plotted every
              threshold at 0 catches) and says so; no label overlaps another or a tick label
  latency     predictor_latency.py draws every log2 bucket between the first and the last
              non-empty one (the empty ones at 0), so a tail stands at its distance, and the
              latencies beyond the histogram's range (bench_predictor's "[range, inf)" line) as a
              last bar of their own, counted in n
  bad_input   arm_parts.py and sim_forces.py on header-only CSVs exit 1 naming the file (no
              traceback); calib_eval.py draws an eval.json with null accuracies and early_cue.py
              a pooled file with null differences (a window without good or missed trials); the
              scripts that read through figure_file's load_json / require_columns exit 1 naming
              the file on one that is not there, not JSON, or lacks a column or key they read,
              and hmm_sweep.py refuses a sweep without one accuracy (it drew an empty figure,
              exit 0)
  sim_csv     sim_forces.py and arm_parts.py --trial draw `dressguard simulate`'s trial CSV, whose
              label and metadata columns (words among them) follow the five
Drawn in this process with the scripts' own functions; the figure is kept, not saved, where the
check reads it. Exits 1 naming what failed.
"""
import argparse
import csv
import glob
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

FAILED = []


def check(ok, what):
    if not ok:
        FAILED.append(what)


def load(src, name):
    """tools/plot/NAME.py as a module whose save_figure keeps the figure in module.figures."""
    sys.path.insert(0, os.path.join(src, "tools", "plot"))
    module = __import__(name)
    module.figures = []
    module.save_figure = lambda fig, path, **kw: module.figures.append(fig)
    return module


def extent(artist, fig):
    return artist.get_window_extent(fig.canvas.get_renderer())


def legends_outside_panels(fig, what):
    fig.canvas.draw()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    check(legends, f"{what}: no legend")
    for legend in legends:
        box = extent(legend, fig)
        for ax in fig.axes:
            check(not box.overlaps(ax.get_window_extent()), f"{what}: a legend covers a panel ({ax.get_title()})")
        check(fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1),
              f"{what}: a legend runs off the figure")


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def predict_prefix(work):
    """A `dressguard predict --out PREFIX` of two trials per height, the high arm's F_lateral
    with its worst windows (-0.8 N) at small travel, where the legend stood."""
    prefix = os.path.join(work, "predict")
    ids = {h: [f"s{k}-{h}-1" for k in (1, 2)] for h in ("high", "middle", "low")}
    write_csv(prefix + ".csv", ["trial_id", "height", "real_median", "objective", "gown", "discrepancy"],
              [[t, h, 1.0 + k, 0.8 + k, "reduced", "0"] for h in ids for k, t in enumerate(ids[h])])
    travel = [i / 100 for i in range(61)]
    write_csv(prefix + ".curves.csv", ["trial_id", "source", "travel", "f_motion", "f_vertical"],
              [[t, src, x, -8 * x * x - k, 0.3 * x] for h in ids for k, t in enumerate(ids[h])
               for src in ("measured", "simulated") for x in travel])
    forces = ("motion", "vertical", "lateral")
    header = ["height", "from", "to", "trials"] + [f"{k}_{a}" for a in forces
                                                   for k in ("measured", "spread", "simulated", "outside")]
    rows = []
    for h in ids:
        for i in range(12):
            a = i * 0.05
            sim = -0.8 if h == "high" and 0.25 <= a < 0.45 else 0.1
            rows.append([h, a, a + 0.05, 2] + [v for _ in forces for v in (0.1 * i, 0.05, sim, int(sim < 0))])
    write_csv(prefix + ".residual.csv", header, rows)
    return prefix


def check_legends(src, work):
    overlay = load(src, "calib_overlay")
    prefix = predict_prefix(work)
    for mode in ("residual", "predict"):
        getattr(overlay, "plot_" + mode)(argparse.Namespace(prefix=prefix, out=os.path.join(work, mode + ".png")))
        fig = overlay.figures.pop()
        legends_outside_panels(fig, mode)
        if mode == "residual":
            check(len(fig.legends) == 1 and not any(ax.get_legend() for ax in fig.axes),
                  "residual: not one legend for all panels")
    cals = sorted(glob.glob(os.path.join(src, "models", "participant*.json")))
    overlay.plot_standing(argparse.Namespace(calibrations=cals, out=os.path.join(work, "standing.png")))
    fig = overlay.figures.pop()
    legends_outside_panels(fig, "standing")
    ax = fig.axes[0]
    marks = [line for line in ax.get_lines() if line.get_marker() == "v"]
    check(marks, "standing: the paper's marks are not drawn")
    half = 7 / 2 * fig.dpi / 72  # the marks' size, ms 7, in pixels
    for line in marks:
        for x, y in ax.transData.transform(line.get_xydata()):
            for text in ax.texts:
                box = extent(text, fig)
                hit = box.x0 - half < x < box.x1 + half and box.y0 - half < y < box.y1 + half
                check(not hit, f"standing: the paper's mark covers the label {text.get_text()}")


def points(caught, rows):
    """stop_threshold_curve's points: (threshold, stopped for nothing, catches) per row."""
    return [{"threshold": t, "stops": {"caught": [3 if caught else 0, 3 if caught else 0]},
             "stopped_for_nothing_per_100": x, "catches_stopped_per_100": c if caught else None,
             "median_lead_s": 0.5 if caught else None} for t, x, c in rows]


def labels_apart(fig, ax, what):
    fig.canvas.draw()
    ticks = [t for t in ax.get_xticklabels() + (ax.get_yticklabels() if ax.yaxis.get_visible() else [])
             if t.get_text()]
    boxes = [(t.get_text(), extent(t, fig)) for t in ax.texts if any(c.isdigit() for c in t.get_text())]
    check(boxes, f"{what}: no threshold labels")
    for i, (name, box) in enumerate(boxes):
        for tick in ticks:
            check(not box.overlaps(extent(tick, fig)), f"{what}: label {name!r} runs into tick label {tick.get_text()}")
        for other, box2 in boxes[i + 1:]:
            check(not box.overlaps(box2), f"{what}: labels {name!r} and {other!r} overlap")


def check_threshold(src, work):
    curve = load(src, "stop_threshold_curve")
    # The main job's measured pulls (no caught logs): 0.999 and 0.9999 share a point, 0.99 and
    # 0.95 and 0.8 and 0.7 are close pairs.
    rows = [(0.5, 38.7, 0), (0.7, 30.3, 0), (0.8, 28.9, 0), (0.9, 24.9, 0), (0.95, 18.1, 0), (0.99, 16.7, 0),
            (0.999, 12.5, 0), (0.9999, 12.5, 0)]
    fig = curve.draw(points(False, rows), 5, "default.dgm")
    ax = fig.axes[0]
    check(not ax.yaxis.get_visible(), "no caught logs: the catches axis is drawn")
    check(any("not measured" in t.get_text() for t in ax.texts), "no caught logs: no note that catches were not measured")
    labels_apart(fig, ax, "no caught logs")
    # Measured catches, some at 0 (a high threshold that stops none): their labels go above.
    fig = curve.draw(points(True, [(0.5, 30.0, 25.3), (0.9, 20.0, 25.3), (0.99, 8.0, 0.0), (0.999, 7.0, 0.0)]),
                     5, "m.dgm")
    check(fig.axes[0].yaxis.get_visible(), "caught logs: the catches axis is not drawn")
    labels_apart(fig, fig.axes[0], "caught logs")


def check_latency(src, work):
    latency = load(src, "predictor_latency")
    text = os.path.join(work, "bench.txt")
    with open(text, "w") as f:
        f.write("e2e_hist_us [0, 2): 5\ne2e_hist_us [16, 32): 100\ne2e_hist_us [8192, 16384): 1\n")
    sys.argv = ["predictor_latency.py", text, "--out", os.path.join(work, "latency.png")]
    check(latency.main() == 0, "latency: the script failed")
    ax = latency.figures.pop().axes[0]
    names = [t.get_text() for t in ax.get_xticklabels()]
    want = ["0-2"] + [f"{2 ** k}-{2 ** (k + 1)}" for k in range(1, 14)]
    check(names == want, f"latency: buckets {names}, expected {want}")
    heights = [p.get_height() for p in ax.patches]
    check(sum(h > 0 for h in heights) == 3 and len(heights) == 14, f"latency: bar heights {heights}")
    # The overflow line: its own bar after the buckets (the old script dropped it and its count).
    with open(text, "w") as f:
        f.write("p_hist_us [16, 32): 90\np_hist_us [256, 512): 5\np_hist_us [409.6, inf): 5\n")
    check(latency.main() == 0, "latency with overflow: the script failed")
    ax = latency.figures.pop().axes[0]
    names = [t.get_text() for t in ax.get_xticklabels()]
    check(names[-1] == ">= 409.6" and names[-2] == "256-512", f"latency with overflow: buckets {names}")
    check(abs(ax.patches[-1].get_height() - 5.0) < 1e-9 and "n=100" in ax.get_title(),
          f"latency with overflow: last bar {ax.patches[-1].get_height()}% in '{ax.get_title()}'")


def run(src, script, *args):
    return subprocess.run(["/usr/bin/python3", os.path.join(src, "tools", "plot", script), *args],
                          capture_output=True, text=True)


def check_bad_input(src, work):
    arm, trial = os.path.join(work, "header-only.arm.csv"), os.path.join(work, "header-only.csv")
    write_csv(arm, ["t", "travel", "elbow_fx", "elbow_fy", "elbow_fz"], [])
    write_csv(trial, ["t", "travel", "f_motion", "f_lateral", "f_vertical"], [])
    good_arm = os.path.join(work, "good.arm.csv")
    write_csv(good_arm, ["t", "travel", "elbow_fx", "elbow_fy", "elbow_fz"], [[0.01, 0.001, 0.1, 0, -0.1]])
    png = os.path.join(work, "out.png")
    for what, r, name in [("arm_parts.py on a header-only arm.csv", run(src, "arm_parts.py", arm, png), arm),
                          ("arm_parts.py --trial on a header-only trial",
                           run(src, "arm_parts.py", good_arm, png, "--trial", trial), trial),
                          ("sim_forces.py on a header-only trial", run(src, "sim_forces.py", png, trial), trial)]:
        check(r.returncode == 1 and name in r.stderr and "Traceback" not in r.stderr,
              f"{what}: exit {r.returncode}, stderr {r.stderr.strip()!r}")
    ev = os.path.join(work, "eval.json")
    with open(ev, "w") as f:
        json.dump({"participants": [
            {"participant": "1", "stc_accuracy_whole_and_cuts": [0.9, None, 0.6, 0.7, 0.8],
             "bc_accuracy_whole_and_cuts": [0.8, 0.5, 0.6, 0.7, 0.8]},
            {"participant": "4", "stc_accuracy_whole_and_cuts": [None, 0.4, 0.5, 0.9, 1.0],
             "bc_accuracy_whole_and_cuts": [0.7, 0.6, 0.6, 0.8, 0.9]}],
            "one_nn_accuracy_at_cuts": [0.7, None, 0.9, 1.0]}, f)
    out = os.path.join(work, "eval.png")
    r = run(src, "calib_eval.py", out, ev)
    check(r.returncode == 0 and os.path.exists(out), f"calib_eval.py on null accuracies: exit {r.returncode}, "
          f"stderr {r.stderr.strip()!r}")
    # A window where a set has no good or no missed trial: null since session 91 (it was 0); a
    # TypeError comparing None before early_cue.py skipped them.
    cue = os.path.join(work, "cue-nulls.json")
    with open(cue, "w") as f:
        row = lambda who, v: {"who": who, "F_motion": v, "F_lateral": [0.1, -0.1, 0.2, 0.1], "F_vertical": [0.1] * 4}
        json.dump({"early_cue_good_minus_missed": [row("the people (measured)", [0.3, 0.2, None, 0.1]),
                                                   row("p4", [0.2, None, 0.1, 0.1]),
                                                   row("  participant 4's inputs", [None] * 4)]}, f)
    out = os.path.join(work, "cue.png")
    r = run(src, "early_cue.py", cue, out)
    check(r.returncode == 0 and os.path.exists(out), f"early_cue.py on null differences: exit {r.returncode}, "
          f"stderr {r.stderr.strip()!r}")
    # Each a KeyError, JSONDecodeError or FileNotFoundError traceback before (session 91's review,
    # finding F), and the empty sweep an empty figure with exit 0.
    def text(name, content):
        path = os.path.join(work, name)
        with open(path, "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))
        return path
    not_json, missing = text("not.json", "{ not json\n"), os.path.join(work, "no-such-file")
    empty_sweep = text("empty-sweep.csv", "travel_m,accuracy,correct,total\n0.15,,0,0\n")
    cases = [
        ("hmm_sweep.py", [text("no-acc.csv", "travel_m,correct,total\n0.1,3,4\n"), png], "no-acc.csv: no accuracy"),
        ("hmm_sweep.py", [empty_sweep, png], "empty-sweep.csv: no cut with an accuracy"),
        ("predictor_latency.py", [missing, "--out", png], "no-such-file: cannot read it"),
        ("predictor_latency.py", [text("zero.txt", "e2e_hist_us [0, 2): 0\n"), "--out", png], "zero.txt: every"),
        ("sim_scene.py", [text("no-frames.json", {}), png], "no-frames.json: no frames"),
        ("calib_eval.py", [png, not_json], "not.json: not JSON"),
        ("calib_eval.py", [png, text("no-rows.json", {"participants": [{"participant": "1"}],
                                                      "one_nn_accuracy_at_cuts": [1, 1, 1, 1]})],
         "no-rows.json: no stc_accuracy_whole_and_cuts"),
        ("calib_overlay.py", ["fit", text("c.curves.csv", "trial_id,height,source,travel\ns4-good-3,high,measured,0.1\n"),
                              "--out", png], "c.curves.csv: no f_motion"),
        ("pooled_stc.py", [text("set.json", {"sources": [], "per_height": 3, "force_sets": [{"forces": "F_motion"}]}), png],
         "set.json: no single"),
        ("committee_draws.py", [text("no-seed.json", {"force_sets": [{"forces": "F_motion", **{
            k: [1, 1, 1, 1, 1] for k in ("vote_accuracy_whole_and_cuts", "vote_good_or_missed_accuracy_whole_and_cuts")}}]}),
                                png], "no-seed.json: no seed"),
        ("member_weights.py", [not_json, png], "not.json: not JSON"),
        ("early_cue.py", [text("cue.json", {"early_cue_good_minus_missed": [{"F_motion": [0, 0, 0, 0]}]}), png],
         "cue.json: no who"),
    ]
    for script, args, want in cases:
        r = run(src, script, *args)
        check(r.returncode == 1 and want in r.stderr and "Traceback" not in r.stderr,
              f"{script} {' '.join(os.path.basename(a) for a in args)}: exit {r.returncode}, stderr {r.stderr.strip()!r}")


def check_sim_csv(src, work):
    trial = os.path.join(work, "trial.csv")
    header = ["t", "travel", "f_motion", "f_lateral", "f_vertical", "label", "height", "speed", "arm_offset", "seed"]
    write_csv(trial, header, [[0.01 * k, 0.001 * k, -0.1 * k, 0.01, 0.05 * k, "missed", "low", 0.1, 0, 7]
                              for k in range(1, 6)])
    arm = os.path.join(work, "trial.arm.csv")
    write_csv(arm, ["t", "travel", "elbow_fx", "elbow_fy", "elbow_fz"],
              [[0.01 * k, 0.001 * k, 0.1, 0, -0.1] for k in range(1, 6)])
    forces, loads = os.path.join(work, "forces.png"), os.path.join(work, "arm.png")
    for what, r, png in [("sim_forces.py", run(src, "sim_forces.py", forces, trial), forces),
                         ("arm_parts.py --trial", run(src, "arm_parts.py", arm, loads, "--trial", trial), loads)]:
        check(r.returncode == 0 and os.path.exists(png),
              f"{what} on simulate's CSV with its label columns: exit {r.returncode}, stderr {r.stderr.strip()!r}")


def main(argv):
    checks = {"legends": check_legends, "threshold": check_threshold, "latency": check_latency,
              "bad_input": check_bad_input, "sim_csv": check_sim_csv}
    if len(argv) != 4 or argv[1] not in checks:
        sys.exit(__doc__)
    os.makedirs(argv[3], exist_ok=True)
    checks[argv[1]](argv[2], argv[3])
    for f in FAILED:
        print(f)
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
