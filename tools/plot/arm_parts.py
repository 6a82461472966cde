#!/usr/bin/python3
"""Which part of the arm carries the cloth's load: `dressguard simulate`'s FILE.arm.csv.

Usage: arm_parts.py FILE.arm.csv OUT.png [--trial FILE.csv]

Two panels against travel: the cloth's force on each arm part along the pull (x, the drag the
arm takes; positive: the cloth pulls the part along with the gripper) and vertically (z;
negative: the cloth presses down on it). With --trial, the gripper's F_motion and F_vertical
from the trial CSV are drawn too (dashed), on the gripper's own sign convention.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from figure_file import save_figure  # a temporary file, then a rename


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("arm_csv")
    p.add_argument("out")
    p.add_argument("--trial")
    a = p.parse_args()
    rows = list(csv.DictReader(open(a.arm_csv, newline="")))
    parts = [k[:-3] for k in rows[0].keys() if k.endswith("_fx")] if rows else []
    travel = [float(r["travel"]) for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    for col, (axis, name) in enumerate((("x", "along the pull (x) [N]"), ("z", "vertical (z) [N]"))):
        ax = axes[col]
        for k, part in enumerate(parts):
            ax.plot(travel, [float(r[f"{part}_f{axis}"]) for r in rows], color=plt.cm.tab10(k), label=part)
        if a.trial:
            t = [r for r in csv.DictReader(open(a.trial, newline="")) if not r["t"].startswith("#")]
            key = "f_motion" if axis == "x" else "f_vertical"
            ax.plot([float(r["travel"]) for r in t], [float(r[key]) for r in t], "k--", lw=1,
                    label=f"gripper {key}")
        ax.set_xlabel("travel [m]")
        ax.set_ylabel(f"cloth's force on the arm, {name}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("which part of the arm carries the cloth's load")
    fig.tight_layout()
    save_figure(fig, a.out, dpi=100)


if __name__ == "__main__":
    main()
