#!/usr/bin/python3
"""Accuracy against travel distance of the calibration evaluation (issue 4, paper Fig. 10-11):
each participant's STC (with the forces its calibration supports, and with both forces when the
file holds it) and BC on the other participants' measured trials, their means, and the
1-nearest-neighbour baseline on force curves with the issue's reference figures.

usage: calib_eval.py OUT.png EVAL.json [EVAL2.json ...]
EVAL.json is what `bench_calib_pipeline eval` writes (DIR/eval.json); several runs (e.g. the
participants split over two processes) are merged, a participant appearing twice keeps its last
row. "whole" is drawn at the right end, after the cuts.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import load_json, require_columns, save_figure  # a temporary file, then a rename

CUTS = [0.15, 0.20, 0.25, 0.30]
ONE_NN_REFERENCE = [71, 83, 94, 100]
WHOLE_X = 0.35  # where "whole sequence" is drawn


def percent(accuracy):
    """An accuracy as a percentage; null (a model that failed to train, its row's stc_error or
    bc_error says why, or a cut that scored no trial: bench_calib_pipeline writes null since
    session 91, 0 before) is NaN, which the lines leave out."""
    return float("nan") if accuracy is None else 100 * accuracy


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    rows, one_nn = {}, None
    for path in argv[2:]:
        d = load_json(path)
        require_columns(path, d, ["participants", "one_nn_accuracy_at_cuts"], "its keys")
        for i, r in enumerate(d["participants"]):
            require_columns(path, r, ["participant", "stc_accuracy_whole_and_cuts", "bc_accuracy_whole_and_cuts"],
                            f"the keys of participant row {i}")
            rows[r["participant"]] = r
        one_nn = [percent(v) for v in d["one_nn_accuracy_at_cuts"]]
    if not rows:
        sys.stderr.write("no participants in the given files\n")
        return 1
    xs = CUTS + [WHOLE_X]

    def series(r, key):  # the file holds whole first, then the cuts
        v = [percent(a) for a in r[key]]
        return v[1:] + v[:1]

    panels = [("stc_accuracy_whole_and_cuts", "STC (trained on simulation)"),
              ("bc_accuracy_whole_and_cuts", "BC (trained on the 2-3 measured inputs)")]
    # Files since session 5 also hold the bivariate STC beside the one with the forces its
    # calibration supports (stc_forces); files from before hold one STC.
    if all("stc_both_forces_accuracy_whole_and_cuts" in r for r in rows.values()):
        panels = [("stc_accuracy_whole_and_cuts", "STC, forces its calibration supports"),
                  ("stc_both_forces_accuracy_whole_and_cuts", "STC, F_motion and F_vertical (paper)"),
                  panels[1]]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.2), sharey=True)
    for ax, (key, name) in zip(axes, panels):
        scored = [[] for _ in xs]  # per point, the participants' accuracies that are there
        for p in sorted(rows, key=int):
            ys = series(rows[p], key)
            for at, y in zip(scored, ys):
                if y == y:
                    at.append(y)
            ax.plot(xs, ys, color="0.75", lw=1)
            last = [(x, y) for x, y in zip(xs, ys) if y == y][-1:]  # the line's right end
            if last:
                ax.annotate(p, last[0], fontsize=7, color="0.5", xytext=(3, 0), textcoords="offset points")
        # The mean at each point of the participants scored there (a null is left out, not a 0),
        # and over how many.
        mean = [sum(at) / len(at) if at else float("nan") for at in scored]
        lo, hi = min(map(len, scored)), max(map(len, scored))
        over = f"{lo}" if lo == hi else f"{lo}-{hi}"
        ax.plot(xs, mean, marker="o", color="tab:blue", lw=2,
                label=f"mean of {over} participants" + ("" if lo == hi == len(rows) else f" scored (of {len(rows)})"))
        failed = sorted((p for p in rows if rows[p].get(key.split("_")[0] + "_error")), key=int)
        if failed:  # named on the panel, not a line at 0
            ax.text(0.02, 0.02, f"{key.split('_')[0].upper()} failed for {', '.join(failed)}", transform=ax.transAxes,
                    fontsize=7, color="tab:red")
        if one_nn:
            ax.plot(CUTS, one_nn, marker="s", color="tab:green", label="1-NN on measured curves (here)")
        ax.plot(CUTS, ONE_NN_REFERENCE, ls="--", color="tab:green", alpha=0.6, label="1-NN, issue's reference")
        ax.set_xticks(xs)
        ax.set_xticklabels([f"{c:.2f}" for c in CUTS] + ["whole"])
        ax.set_xlabel("travel distance of the end effector [m]")
        ax.set_title(name)
        ax.grid(True, alpha=0.3)
        ax.set_ylim(0, 102)
    axes[0].set_ylabel("accuracy on the other participants' trials [%]")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    save_figure(fig, argv[1], dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
