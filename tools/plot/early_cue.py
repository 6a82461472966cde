#!/usr/bin/python3
"""The early cue a classifier of cut sequences learns (good minus missed, mean force over
0.10-0.15 / 0.15-0.20 / 0.20-0.25 / 0.25-0.30 m of travel): each simulator's synthesized set
against the measured inputs of the person it was calibrated on. A point on the diagonal is a
simulator that teaches its person's cue; the grey band is the people's own (all 22 trials), the
cue a classifier of other people needs. One row per file (e.g. the bench run with and without the
discrepancy term), one panel per force. offline/calib/MEASUREMENTS.md, session 27.

usage: early_cue.py POOLED.json [POOLED2.json ...] OUT.png
POOLED.json is what `bench_calib_pipeline pooled` writes. A window where a set has no good or no
missed trial with a sample is null there (since session 91; 0 before) and is left out.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import load_json, require_columns, save_figure  # a temporary file, then a rename

FORCES = ["F_motion", "F_lateral", "F_vertical"]
WINDOWS = ["0.10-0.15 m", "0.15-0.20 m", "0.20-0.25 m", "0.25-0.30 m"]
COLOURS = ["#1b9e77", "#d95f02", "#7570b3", "#e7298a"]


def pairs(rows):
    """(simulator row, its person's inputs row) in the order the bench prints them."""
    people = None
    out = []
    for i, r in enumerate(rows):
        who = r["who"]
        if who.startswith("the people"):
            people = r
        elif "inputs" in who:
            if i == 0 or "inputs" in rows[i - 1]["who"]:
                raise ValueError(f"'{who}' does not follow a simulator's row")
            out.append((rows[i - 1], r))
    if people is None or not out:
        raise ValueError("no people's row or no simulator beside its person's inputs "
                         "(a bench from before session 27?)")
    return people, out


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    files, out_png = argv[1:-1], argv[-1]
    fig, axes = plt.subplots(len(files), 3, figsize=(13.5, 4.4 * len(files)), squeeze=False)
    for row, path in zip(axes, files):
        d = load_json(path)
        for i, r in enumerate(d.get("early_cue_good_minus_missed", [])):
            require_columns(path, r, ["who"] + FORCES, f"the keys of early_cue_good_minus_missed row {i}")
        try:
            people, sims = pairs(d.get("early_cue_good_minus_missed", []))
        except ValueError as e:
            sys.stderr.write(f"{path}: {e}\n")
            return 1
        term = "with the discrepancy term" if d.get("discrepancy") else "simulation alone"
        # As pooled_stc.py: the noise models are on unless the file says otherwise.
        term += "".join(f", no {what} noise" for key, what in (("arm_noise", "arm-height"), ("gown_noise", "gown"))
                        if d.get(key) is False)
        for ax, force in zip(row, FORCES):
            values = [v for s, p in sims + [(people, people)] for v in p[force] + s[force] if v is not None]
            lo, hi = (min(values), max(values)) if values else (-1.0, 1.0)
            pad = 0.1 * (hi - lo + 1e-9)
            lo, hi = lo - pad, hi + pad
            ax.plot([lo, hi], [lo, hi], color="black", lw=0.8)
            # (the person's, the simulator's) difference per window where both are there
            both = [[(p[force][w], s[force][w]) if p[force][w] is not None and s[force][w] is not None else None
                     for w in range(4)] for s, p in sims]
            for w in range(4):
                if people[force][w] is not None:
                    ax.axvspan(people[force][w] - 0.005, people[force][w] + 0.005, color=COLOURS[w], alpha=0.25)
                pts = [b[w] for b in both if b[w] is not None]
                ax.scatter([x for x, _ in pts], [y for _, y in pts], color=COLOURS[w], s=28, label=WINDOWS[w], zorder=3)
            for (s, p), b in zip(sims, both):
                name = p["who"].strip().split("'")[0].replace("participant ", "P")
                at = b[1] or next((xy for xy in b if xy is not None), None)  # the second window's point, else any
                if at is not None:
                    ax.annotate(name, at, fontsize=7, xytext=(3, 2), textcoords="offset points")
            ax.set_xlim(lo, hi)
            ax.set_ylim(lo, hi)
            ax.set_aspect("equal")
            ax.set_xlabel(f"{force}: the person's inputs, good - missed [N]")
            ax.set_ylabel("the simulator's synthesized set [N]")
            ax.set_title(f"{force}, {term}", fontsize=10)
            ax.grid(alpha=0.3)
        row[0].legend(fontsize=7, loc="upper left", title="window (bands: all people)", title_fontsize=7)
    fig.tight_layout()
    save_figure(fig, out_png, dpi=110)
    print(f"wrote {out_png}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
