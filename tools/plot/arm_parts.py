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
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from figure_file import save_figure  # a temporary file, then a rename


def read_rows(path, columns, what):
    """The CSV's rows (the trial CSV's '#' lines left out), each with `columns` as numbers; an
    empty file, a missing column or a word where a number goes is an error naming the file (a
    header-only file drew empty panels, or failed with a traceback)."""
    try:
        with open(path, newline="") as f:
            rows = [r for r in csv.DictReader(f) if not (r.get("t") or "").startswith("#")]
    except OSError as e:
        sys.exit(f"arm_parts.py: {path}: {e.strerror}")
    if not rows:
        sys.exit(f"arm_parts.py: {path}: no rows under the header ({what})")
    cols = columns(rows[0]) if callable(columns) else columns
    missing = [c for c in cols if c not in rows[0]]
    if missing or not cols:
        sys.exit(f"arm_parts.py: {path}: no column {', '.join(missing) or '<part>_fx'} ({what})")
    try:
        return [{c: float(r[c]) for c in cols} for r in rows]
    except (TypeError, ValueError):
        sys.exit(f"arm_parts.py: {path}: a row of {', '.join(cols)} that is not all numbers ({what})")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("arm_csv")
    p.add_argument("out")
    p.add_argument("--trial")
    a = p.parse_args()
    def arm_columns(first):
        parts = [k[:-3] for k in first if k.endswith("_fx")]
        return ["travel"] + [f"{p}_f{axis}" for p in parts for axis in "xz"] if parts else []

    rows = read_rows(a.arm_csv, arm_columns, "dressguard simulate's FILE.arm.csv")
    parts = [k[:-3] for k in rows[0] if k.endswith("_fx")]
    travel = [r["travel"] for r in rows]
    trial = read_rows(a.trial, ["travel", "f_motion", "f_vertical"], "a trial CSV") if a.trial else None
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    for col, (axis, name) in enumerate((("x", "along the pull (x) [N]"), ("z", "vertical (z) [N]"))):
        ax = axes[col]
        for k, part in enumerate(parts):
            ax.plot(travel, [r[f"{part}_f{axis}"] for r in rows], color=plt.cm.tab10(k), label=part)
        if trial:
            key = "f_motion" if axis == "x" else "f_vertical"
            ax.plot([r["travel"] for r in trial], [r[key] for r in trial], "k--", lw=1, label=f"gripper {key}")
        ax.set_xlabel("travel [m]")
        ax.set_ylabel(f"cloth's force on the arm, {name}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("which part of the arm carries the cloth's load")
    fig.tight_layout()
    save_figure(fig, a.out, dpi=100)


if __name__ == "__main__":
    main()
