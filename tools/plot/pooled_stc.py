#!/usr/bin/python3
"""Accuracy against travel of the pooled STC (paper VII: HMMs trained on the simulators of
several people, tested on a person none of them was calibrated on), beside each calibration's
own STC, the vote of those STCs (a committee; also with each STC's training shares as priors
and asked "good or missed?", offline/calib/MEASUREMENTS.md, session 26), the baseline classifier
on each calibration's 2-3 measured inputs, and the 1-nearest-neighbour classifier on the other
people's measured curves.

usage: pooled_stc.py POOLED.json OUT.png
POOLED.json is what `bench_calib_pipeline pooled` writes (DIR/pooled.json). One panel per force
set; "whole" is drawn at the right end, after the cuts. Where the file pairs the vote with the
1-NN (since session 43), each cut shows both accuracies' 95 % intervals and, at the bottom, the
trials only the vote / only the 1-NN got right with McNemar's exact p; above them, in red, the same
for the vote with each STC asked "good or missed?" (since session 71).
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import load_json, require_columns, save_figure  # a temporary file, then a rename

CUTS = [0.15, 0.20, 0.25, 0.30]
WHOLE_X = 0.35  # where "whole sequence" is drawn


def cuts_then_whole(v):  # the file holds whole first, then the cuts
    return [100 * a for a in v[1:] + v[:1]]


def read_run(path):
    """A file `bench_calib_pipeline pooled` wrote; None, the reason on stderr, when it has no
    force sets (every plot of such runs reads them this way). One that is not there or not JSON,
    or a force set without its name, ends the script naming the file."""
    d = load_json(path)
    if not d.get("force_sets"):
        sys.stderr.write(f"{path}: no force sets\n")
        return None
    for i, s in enumerate(d["force_sets"]):
        require_columns(path, s, ["forces"], f"the keys of force set {i}")
    return d


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    d = read_run(argv[1])
    if d is None:
        return 1
    require_columns(argv[1], d, ["sources", "per_height"], "its keys")
    sets = d["force_sets"]
    for s in sets:
        require_columns(argv[1], s, ["single", "single_accuracy_whole_and_cuts", "pooled_accuracy_whole_and_cuts",
                                     "pooled_equal_size_accuracy_whole_and_cuts", "one_nn_accuracy_at_cuts"],
                        f"the keys of force set '{s['forces']}'")
        for i, single in enumerate(s["single"]):
            require_columns(argv[1], single, ["accuracy_whole_and_cuts"], f"the keys of '{s['forces']}' single {i}")
    xs = CUTS + [WHOLE_X]
    fig, axes = plt.subplots(1, len(sets), figsize=(5.2 * len(sets), 4.6), sharey=True, squeeze=False)
    for ax, s in zip(axes[0], sets):
        for i, single in enumerate(s["single"]):
            ax.plot(xs, cuts_then_whole(single["accuracy_whole_and_cuts"]), color="0.75", lw=1,
                    label="one person's simulator" if i == 0 else None)
        ax.plot(xs, cuts_then_whole(s["single_accuracy_whole_and_cuts"]), color="0.45", lw=1.5, ls="--",
                label="one person's simulator, all trials")
        if "bc_accuracy_whole_and_cuts" in s:
            ax.plot(xs, cuts_then_whole(s["bc_accuracy_whole_and_cuts"]), color="tab:purple", lw=1.2, ls="-.",
                    label="BC: the 2-3 measured inputs, all")
        ax.plot(xs, cuts_then_whole(s["pooled_equal_size_accuracy_whole_and_cuts"]), color="tab:orange", lw=1.5,
                marker="s", ms=4, label="pooled, one set's size")
        ax.plot(xs, cuts_then_whole(s["pooled_accuracy_whole_and_cuts"]), color="tab:blue", lw=2.2, marker="o",
                ms=5, label="pooled simulators")
        if "vote_accuracy_whole_and_cuts" in s:
            ax.plot(xs, cuts_then_whole(s["vote_accuracy_whole_and_cuts"]), color="tab:red", lw=2.2, marker="D",
                    ms=5, label="vote of the simulators' STCs")
        if "vote_good_or_missed_against_one_nn_at_cuts" in s:  # files since session 71
            ax.plot(xs, cuts_then_whole(s["vote_good_or_missed_accuracy_whole_and_cuts"]), color="tab:red", lw=1.4,
                    ls=":", marker="D", mfc="white", ms=4, label="vote, each asked good or missed")
        if "vote_training_priors_good_or_missed_accuracy_whole_and_cuts" in s:
            ax.plot(xs, cuts_then_whole(s["vote_training_priors_good_or_missed_accuracy_whole_and_cuts"]),
                    color="darkred", lw=2.2, ls="--", marker="D", mfc="white", ms=5,
                    label="vote, training priors, good or missed")
        ax.plot(CUTS, [100 * a for a in s["one_nn_accuracy_at_cuts"]], color="tab:green", lw=1.5, ls=":", marker="^",
                ms=5, label="1-NN on other people's curves")
        # The vote against the 1-NN trial by trial (files since session 43): each accuracy's 95 %
        # Wilson interval, drawn just left (vote) and right (1-NN) of the cut, and McNemar's exact
        # p of the trials only one of them gets right.
        for pair in s.get("vote_against_one_nn_at_cuts", []):
            x = pair["cut"]
            for dx, key, right, colour in ((-0.004, "vote_interval", "vote_right", "tab:red"),
                                           (0.004, "one_nn_interval", "one_nn_right", "tab:green")):
                lo, hi = (100 * v for v in pair[key])
                mid = 100 * pair[right] / pair["trials"]
                ax.errorbar([x + dx], [mid], yerr=[[mid - lo], [hi - mid]], color=colour, lw=1, capsize=2,
                            fmt="none")
            ax.annotate(f"{pair['only_vote_right']}/{pair['only_one_nn_right']}\np {pair['mcnemar_exact_p']:.2f}",
                        (x, 3), ha="center", fontsize=7, color="0.3")
        # The vote asked "good or missed?" against the same 1-NN, above the plain vote's numbers.
        for pair in s.get("vote_good_or_missed_against_one_nn_at_cuts", []):
            ax.annotate(f"{pair['only_vote_right']}/{pair['only_one_nn_right']}\np {pair['mcnemar_exact_p']:.2f}",
                        (pair["cut"], 13), ha="center", fontsize=7, color="tab:red")
        ax.set_title(s["forces"], fontsize=10)
        ax.set_xticks(xs)
        ax.set_xticklabels([f"{c:.2f}" for c in CUTS] + ["whole"])
        ax.set_xlabel("travel at which the trial is cut [m]")
        ax.set_ylim(0, 102)
        ax.axvline((CUTS[-1] + WHOLE_X) / 2, color="0.85", lw=0.8)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("measured trials classified right [%]")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    if any("vote_against_one_nn_at_cuts" in s for s in sets):
        fig.text(0.01, 0.01, "bars: 95 % Wilson intervals of the vote (left) and the 1-NN (right); numbers at the "
                 "bottom: trials only the vote / only the 1-NN got right, McNemar's exact p (red, above: the vote asked "
                 "good or missed)", fontsize=7, color="0.3")
    n = len(d["sources"])
    term = ", each simulator's own error added (--discrepancy)" if d.get("discrepancy") else ""
    # The noise models are on unless the file says otherwise (files from before session 27 do not).
    term += "".join(f", no {what} noise" for key, what in (("arm_noise", "arm-height"), ("gown_noise", "gown"))
                    if d.get(key) is False)
    fig.suptitle(f"STCs on people no simulator was calibrated on: {n} calibrations, {d['per_height']} trials per "
                 f"height each{term}", fontsize=10)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    save_figure(fig, argv[2], dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
