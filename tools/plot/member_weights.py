#!/usr/bin/python3
"""What the committee's weights see (offline/calib/MEASUREMENTS.md, session 73): each member's
STC asked "good or missed?" on the other simulators' synthesized trials (what rule S weighs it by:
the simulators alone; here on all six others, where each test person's committee leaves that
person's simulator out) above the same STC on the other people's measured trials (what rule R
weighs it by, and what the vote is judged on), whole and at each cut. Where the two rows rank the
members alike, weights learnt from simulation alone help the vote on people: under each column
of the lower map, Spearman's rank correlation of the two rows' accuracies over the members.

usage: member_weights.py POOLED.json OUT.png
POOLED.json is what `bench_calib_pipeline pooled` writes (since session 73). One column of two
heat maps per force set, a row per member, the accuracy in % in each cell.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from pooled_stc import CUTS, read_run  # the same cuts and reading as the per-run plot
from figure_file import require_columns, save_figure  # a temporary file, then a rename

COLUMNS = ["whole"] + [f"{c:.2f} m" for c in CUTS]


def stem(path):
    return path.replace("\\", "/").split("/")[-1].removesuffix(".json")


def ranks(v):  # 1-based ranks, tied values sharing their mean rank
    order = sorted(range(len(v)), key=lambda i: v[i])
    r = [0.0] * len(v)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and v[order[j + 1]] == v[order[i]]:
            j += 1
        for k in range(i, j + 1):
            r[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return r


def spearman(a, b):  # Pearson's correlation of the ranks; None when either side has no spread
    ra, rb = ranks(a), ranks(b)
    ma, mb = sum(ra) / len(ra), sum(rb) / len(rb)
    sab = sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
    saa, sbb = sum((x - ma) ** 2 for x in ra), sum((y - mb) ** 2 for y in rb)
    return sab / (saa * sbb) ** 0.5 if saa > 0 and sbb > 0 else None


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    d = read_run(argv[1])
    if d is None:
        return 1
    sets = d["force_sets"]
    for s in sets:
        for key in ("single_on_other_simulators", "single_good_or_missed"):
            if key not in s:
                sys.stderr.write(f"{argv[1]}: force set '{s.get('forces')}' has no {key}\n")
                return 1
        for i, r in enumerate(s["single_on_other_simulators"]):
            require_columns(argv[1], r, ["calibration", "good_or_missed_accuracy_whole_and_cuts"],
                            f"the keys of '{s['forces']}' single_on_other_simulators {i}")
        for i, r in enumerate(s["single_good_or_missed"]):
            require_columns(argv[1], r, ["calibration", "accuracy_whole_and_cuts"],
                            f"the keys of '{s['forces']}' single_good_or_missed {i}")
    rows = [stem(r["calibration"]) for r in sets[0]["single_on_other_simulators"]]
    fig, axes = plt.subplots(2, len(sets), figsize=(4.6 * len(sets), 0.45 * len(rows) * 2 + 2.6), squeeze=False)
    image = None
    for col, s in enumerate(sets):
        simulated = {stem(r["calibration"]): r["good_or_missed_accuracy_whole_and_cuts"]
                     for r in s["single_on_other_simulators"]}
        measured = {stem(r["calibration"]): r["accuracy_whole_and_cuts"] for r in s["single_good_or_missed"]}
        for row, (what, acc) in enumerate([("on the other simulators' trials (rule S)", simulated),
                                           ("on the other people's measured trials", measured)]):
            ax = axes[row][col]
            grid = [[100 * a for a in acc[m]] for m in rows]
            image = ax.imshow(grid, cmap="RdYlGn", vmin=0, vmax=100, aspect="auto")
            for i, line in enumerate(grid):
                for j, v in enumerate(line):
                    ax.text(j, i, f"{v:.0f}", ha="center", va="center", fontsize=8)
            ax.set_xticks(range(len(COLUMNS)))
            labels = COLUMNS
            if row == 1:  # how alike the two maps rank the members, column by column
                rho = [spearman([simulated[m][c] for m in rows], [measured[m][c] for m in rows])
                       for c in range(len(COLUMNS))]
                labels = [f"{n}\n\u03c1 {r:+.2f}" if r is not None else f"{n}\n\u03c1 -" for n, r in zip(COLUMNS, rho)]
            ax.set_xticklabels(labels, fontsize=8)
            ax.set_yticks(range(len(rows)))
            ax.set_yticklabels(rows if col == 0 else [], fontsize=8)
            ax.set_title(f"{s['forces']}\n{what}", fontsize=9)
    fig.colorbar(image, ax=axes, shrink=0.6, label='right, asked "good or missed?" [%]')
    save_figure(fig, argv[2], dpi=110, bbox_inches="tight")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
