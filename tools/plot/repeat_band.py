#!/usr/bin/python3
"""How far each calibrated simulator's trial moves when the arm moves: the scan behind
`synthesize --high-low repeat-band` (offline/calib/synthesis.h, locate_repeat_band). For the high
and the low arm, the eq. 3-5 distance (w = 20) between the noise-free trial at each offset from
the calibrated height and the calibrated height's own trial, one line per simulator; the dashed
line is the study's repeat distance of the calibrated trial's outcome (two measured repeats of one
person's trial), the shaded span the paper's +-1.5 cm noise. The band a synthesis draws from is
the part around 0 below the dashed line (thick). offline/calib/MEASUREMENTS.md, session 29.

usage: repeat_band.py SYNTH_DIR OUT.png
SYNTH_DIR holds one synthesis folder per simulator (as `bench_calib_pipeline pooled --synth`
writes them), each with .synth/repeat-band.json.
"""
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import save_figure  # a temporary file, then a rename


def load(root):
    bands = []
    for d in sorted(pathlib.Path(root).iterdir()):
        f = d / ".synth" / "repeat-band.json"
        if f.is_file():
            with open(f) as fh:
                bands.append((d.name, json.load(fh)))
    if not bands:
        raise SystemExit(f"repeat_band.py: no */.synth/repeat-band.json under {root} "
                         "(made by synthesize --high-low repeat-band)")
    return bands


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    bands = load(sys.argv[1])
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.6), sharey=True)
    cmap = plt.get_cmap("tab10")
    for ax, height in zip(axes, ["high", "low"]):
        ax.axvspan(-1.5, 1.5, color="0.93", zorder=0)
        tolerances = set()
        for i, (name, b) in enumerate(bands):
            h = b[height]
            xs = [100 * x for x in h["offsets_m"]] + [0.0]
            ys = h["distances"] + [0.0]
            pts = sorted(zip(xs, ys))
            c = cmap(i % 10)
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "-o", ms=3, lw=1, color=c,
                    label=f"{name} [{100 * h['lower_m']:+.2f}, {100 * h['upper_m']:+.2f}] cm")
            inside = [p for p in pts if 100 * h["lower_m"] - 1e-9 <= p[0] <= 100 * h["upper_m"] + 1e-9]
            ax.plot([p[0] for p in inside], [p[1] for p in inside], "-", lw=3.5, color=c, alpha=0.6)
            tolerances.add((h["tolerance"], h["at_calibrated"]))
        for tol, outcome in sorted(tolerances):
            ax.axhline(tol, ls="--", color="k", lw=1)
            ax.text(-1.45, tol, f" repeat distance ({outcome}) {tol:.3f}", va="bottom", fontsize=8)
        ax.set_yscale("symlog", linthresh=0.1)
        ax.set_xlabel("arm offset from the calibrated height [cm]")
        ax.set_title(f"{height} arm")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    axes[0].set_ylabel("eq. 3-5 distance to the calibrated height's trial")
    fig.suptitle("Which arm heights a calibrated simulator takes within a repeat's distance")
    fig.tight_layout()
    save_figure(fig, sys.argv[2], dpi=120)


if __name__ == "__main__":
    main()
