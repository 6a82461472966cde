#!/usr/bin/python3
"""Force curves against travel for simulated (and measured) trials.

Usage: sim_forces.py OUT.png TRIAL[=LABEL] ... [--measured STUDY.txt[=LABEL] ...] [--title T]
  TRIAL: a trial CSV (t,travel,f_motion,f_lateral,f_vertical, then any further columns, such as
         simulate's label and metadata, which are skipped) as written by dressguard simulate
  --measured: the study's trial files (space separated: t position F_motion F_lateral F_vertical)
Two panels, F_motion and F_vertical against travel (the paper's X and Y); simulated solid,
measured dashed; with exactly one simulated and one measured trial, a third panel shows the
residual (simulated minus measured, on the measured travel grid)."""
import sys
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from figure_file import save_figure  # a temporary file, then a rename


def load(path):
    """Columns t, travel, f_motion, f_lateral, f_vertical of a trial CSV or a study file. A file
    without rows or with fewer columns is an error naming it (a header-only CSV failed with an
    IndexError far from its name). A CSV's columns after the five (simulate's label,height,...,
    words among them) are not read."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # numpy's "input contained no data"
            try:
                a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2, usecols=range(5))
            except ValueError:
                a = np.loadtxt(path, ndmin=2)
    except FileNotFoundError:
        sys.exit(f"sim_forces.py: {path}: no such file")
    except OSError as e:
        sys.exit(f"sim_forces.py: {path}: {e.strerror or e}")
    except ValueError as e:
        sys.exit(f"sim_forces.py: {path}: not a trial CSV or a study file ({e})")
    if a.shape[0] == 0 or a.shape[1] < 5:
        sys.exit(f"sim_forces.py: {path}: no rows of t, travel, f_motion, f_lateral, f_vertical "
                 f"({a.shape[0]} rows of {a.shape[1]} columns)")
    return a


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    out = args.pop(0)
    sims, meas, title = [], [], ""
    mode = "sim"
    while args:
        a = args.pop(0)
        if a == "--measured":
            mode = "meas"
            continue
        if a == "--title":
            title = args.pop(0)
            continue
        path, _, label = a.partition("=")
        (sims if mode == "sim" else meas).append((load(path), label or path.rsplit("/", 1)[-1]))
    residual = len(sims) == 1 and len(meas) == 1
    fig, axes = plt.subplots(1, 3 if residual else 2, figsize=(15 if residual else 11, 4.2))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (a, label) in enumerate(sims):
        axes[0].plot(a[:, 1], a[:, 2], color=colors[k % 10], label=label)
        axes[1].plot(a[:, 1], a[:, 4], color=colors[k % 10], label=label)
    for k, (a, label) in enumerate(meas):
        c = colors[(k + len(sims)) % 10] if not residual else "k"
        axes[0].plot(a[:, 1], a[:, 2], "--", color=c, label=label)
        axes[1].plot(a[:, 1], a[:, 4], "--", color=c, label=label)
    for ax, name in zip(axes, ["F_motion (X) [N]", "F_vertical (Y) [N]"]):
        ax.set_xlabel("travel [m]")
        ax.set_ylabel(name)
        ax.axhline(0, color="0.7", linewidth=0.8)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    if residual:
        s, m = sims[0][0], meas[0][0]
        grid = m[:, 1]
        keep = grid <= s[-1, 1]
        for col, name in ((2, "F_motion"), (4, "F_vertical")):
            r = np.interp(grid[keep], s[:, 1], s[:, col]) - m[keep, col]
            axes[2].plot(grid[keep], r, label=name)
        axes[2].axhline(0, color="0.7", linewidth=0.8)
        axes[2].set_xlabel("travel [m]")
        axes[2].set_ylabel("simulated - measured [N]")
        axes[2].set_title("residual (over the common travel)", fontsize=9)
        axes[2].legend(fontsize=7)
        axes[2].grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, out, dpi=110)


if __name__ == "__main__":
    main()
