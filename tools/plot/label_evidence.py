#!/usr/bin/python3
"""What decided each synthesized label (paper V-A): for every trial that stopped before the end
of travel, how far the sleeve opening's lower half ended behind the elbow centre (forearm side)
and past it, from the labels.csv that `dressguard synthesize` writes beside its manifest. The
rule takes the larger of the two: good at 7 cm or less (the shaded square), else caught. A
simulator whose trials sit on the square's edge has labels that the noise models decide.
offline/calib/MEASUREMENTS.md, session 31.

usage: label_evidence.py OUT.png [--margin M] NAME=SET_DIR [NAME=SET_DIR ...]
  --margin M   also draw the band build-model --label-margin M leaves out (metres)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import save_figure  # a temporary file, then a rename

RULE = 0.07  # [m] kGoodLabelDistance (offline/core/haptic.h)
COLOURS = {"good": "tab:green", "caught": "tab:red"}


def load(arg):
    name, _, folder = arg.partition("=")
    if not folder:
        sys.exit(f"label_evidence.py: '{arg}' is not NAME=SET_DIR")
    path = os.path.join(folder, "labels.csv")
    points = []
    try:
        with open(path, newline="") as fh:
            for n, row in enumerate(csv.DictReader(fh), start=2):
                if row.get("label") in (None, "missed"):
                    continue
                if not row.get("d_behind_m") or not row.get("d_ahead_m"):
                    continue  # a marker from before the evidence was kept
                try:
                    points.append((float(row["d_behind_m"]), float(row["d_ahead_m"]), row["label"]))
                except ValueError:
                    sys.exit(f"label_evidence.py: {path}:{n}: d_behind_m or d_ahead_m is not a number")
    except OSError as e:
        sys.exit(f"label_evidence.py: {path}: {e}")
    return name, points


def main(argv):
    args = argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    out = args.pop(0)
    margin = 0.0
    if args and args[0] == "--margin":
        if len(args) < 2:
            sys.exit(__doc__)
        margin = float(args[1])
        args = args[2:]
    sets = [load(a) for a in args]
    if not sets:
        sys.exit(__doc__)
    cols = min(4, len(sets))
    rows = (len(sets) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 3.3 * rows), squeeze=False)
    for ax, (name, points) in zip(axes.flat, sets):
        ax.add_patch(plt.Rectangle((0, 0), 100 * RULE, 100 * RULE, color="0.9", zorder=0))
        if margin > 0:  # where max(behind, past) is within the margin of 7 cm: an L around the square
            lo, hi = 100 * (RULE - margin), 100 * (RULE + margin)
            band = dict(color="tab:orange", alpha=0.25, zorder=0, lw=0)
            ax.add_patch(plt.Rectangle((0, lo), hi, hi - lo, **band))
            ax.add_patch(plt.Rectangle((lo, 0), hi - lo, lo, **band))
        for label, colour in COLOURS.items():
            xs = [100 * b for b, a, l in points if l == label]
            ys = [100 * a for b, a, l in points if l == label]
            ax.scatter(xs, ys, s=12, color=colour, label=f"{label} ({len(xs)})", alpha=0.7)
        ax.set_title(f"{name}: {len(points)} stopped", fontsize=9)
        ax.set_xlabel("behind the elbow [cm]", fontsize=8)
        ax.set_ylabel("past the elbow [cm]", fontsize=8)
        top = max([12.0] + [100 * max(b, a) + 1 for b, a, _ in points])
        ax.set_xlim(-0.5, top)
        ax.set_ylim(-0.5, top)
        ax.legend(fontsize=7, loc="upper right")
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[len(sets):]:
        ax.axis("off")
    fig.suptitle("synthesized trials that stopped early\n(grey: good by the 7 cm rule)", fontsize=9)
    fig.tight_layout()
    save_figure(fig, out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv)
