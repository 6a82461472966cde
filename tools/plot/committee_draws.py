#!/usr/bin/python3
"""The committee's vote (each simulator's STC votes on the people it was not calibrated on;
offline/calib/MEASUREMENTS.md, sessions 26 and 71) from several runs of `bench_calib_pipeline
pooled` side by side: how far the vote moves between synthesis draws and set sizes (another
seed, or `--indices`, a smaller block of the same cached sets), against the 1-nearest-neighbour
classifier on the other people's measured curves.

usage: committee_draws.py POOLED.json [POOLED.json ...] OUT.png
Each POOLED.json is a file the bench wrote; each is labelled by its seeds, the trials per height
its STCs trained on, its --indices and, where the runs' members differ, the files it holds beyond
those every run holds. One panel per force set and per vote (the paper's rule; each STC asked
"good or missed?"; where every run has them, the same question decided by the members' weights,
rule S from the simulators alone and rule R from the other people's measured trials, session 73,
and by the members' answer models, rule C, session 74); a line per run, the 1-NN in black with
its 95 % interval at each cut, from the first file (every run of one set of calibrations faces
the same trials). The whole sequence is drawn right of the cuts.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from pooled_stc import CUTS, WHOLE_X, cuts_then_whole, read_run  # as the per-run plot
from figure_file import require_columns, save_figure  # a temporary file, then a rename
VOTES = [("vote_accuracy_whole_and_cuts", "vote_against_one_nn_at_cuts", "vote (the paper's rule)"),
         ("vote_good_or_missed_accuracy_whole_and_cuts", "vote_good_or_missed_against_one_nn_at_cuts",
          'vote, each STC asked "good or missed?"')]
# Drawn when every run has them (runs before session 73 do not; rule C's, before session 74): the
# weighted votes and rule C's, same question.
WEIGHTED = [("vote_weighted_simulated_good_or_missed_accuracy_whole_and_cuts",
             "vote_weighted_simulated_good_or_missed_against_one_nn_at_cuts",
             'good or missed, weighted by the simulators (rule S)'),
            ("vote_weighted_measured_good_or_missed_accuracy_whole_and_cuts",
             "vote_weighted_measured_good_or_missed_against_one_nn_at_cuts",
             'good or missed, weighted by measured trials (rule R)'),
            ("vote_answer_models_simulated_good_or_missed_accuracy_whole_and_cuts",
             "vote_answer_models_simulated_good_or_missed_against_one_nn_at_cuts",
             "good or missed, answer models (rule C)")]


def members(d):  # the calibration files' stems, the committee's members
    return {s["calibration"].replace("\\", "/").split("/")[-1].removesuffix(".json") for s in d.get("sources", [])}


def label_of(d, shared):
    seed = d["seed"]
    seeds = ",".join(str(int(s)) for s in seed) if isinstance(seed, list) else str(int(seed))
    text = f"seed {seeds}, {d['per_height']} per height"
    if d.get("indices"):
        text += f" (trials {','.join(d['indices'])})"
    if shared is not None:  # the runs' members differ: name what this one adds to the shared ones
        extra = sorted(members(d) - shared)
        text += ", " + (" + ".join(extra) if extra else f"the {len(shared)} shared only")
    return text


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    runs = []
    for path in argv[1:-1]:
        d = read_run(path)
        if d is None:
            return 1
        require_columns(path, d, ["seed", "per_height"], "its keys")
        for key, pairing, _ in VOTES:
            for s in d["force_sets"]:
                if key not in s or len(s[key]) != 5:
                    sys.stderr.write(f"{path}: force set '{s.get('forces')}' has no {key} (whole and 4 cuts)\n")
                    return 1
        runs.append(d)
    # Where the runs' members differ (another file of one person, or one left out), each label
    # names the files it holds beyond those every run holds.
    shared = set.intersection(*(members(d) for d in runs))
    same = all(members(d) == shared for d in runs)
    runs = [(label_of(d, None if same else shared), d) for d in runs]
    votes = VOTES + [w for w in WEIGHTED
                     if all(w[0] in s and len(s[w[0]]) == 5 for _, d in runs for s in d["force_sets"])]
    names = [s["forces"] for s in runs[0][1]["force_sets"]]
    fig, axes = plt.subplots(len(votes), len(names), figsize=(5 * len(names), 4.2 * len(votes)), squeeze=False,
                             sharey=True)
    xs = CUTS + [WHOLE_X]
    for row, (key, pairing, title) in enumerate(votes):
        for col, name in enumerate(names):
            ax = axes[row][col]
            for label, d in runs:
                sets = {s["forces"]: s for s in d["force_sets"]}
                if name not in sets:
                    continue
                ax.plot(xs, cuts_then_whole(sets[name][key]), "o-", lw=1.2, ms=4, label=label)
            ref = {s["forces"]: s for s in runs[0][1]["force_sets"]}[name]
            nn = ref.get("one_nn_accuracy_at_cuts")
            if nn:
                ax.plot(CUTS, [100 * a for a in nn], "ks--", lw=1.5, ms=5, label="1-NN on people's curves")
            for p in ref.get(pairing, []):
                lo, hi = p["one_nn_interval"]
                ax.plot([p["cut"]] * 2, [100 * lo, 100 * hi], "k-", lw=0.8, alpha=0.5)
            ax.set_xticks(xs)
            ax.set_xticklabels([f"{c:.2f}" for c in CUTS] + ["whole"])
            ax.set_ylim(0, 105)
            ax.grid(alpha=0.3)
            ax.set_title(f"{name}: {title}", fontsize=9)
            if col == 0:
                ax.set_ylabel("right of the measured trials [%]")
            if row == len(votes) - 1:
                ax.set_xlabel("travel cut [m]")
    # One legend for all panels, under them, so that no line is hidden behind it.
    handles, labels = axes[0][0].get_legend_handles_labels()
    rows = (len(labels) + 2) // 3
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=3)
    fig.tight_layout(rect=(0, 0.035 * rows * 2 / len(votes), 1, 1))
    save_figure(fig, argv[-1], dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
