#!/usr/bin/python3
"""Accuracy against travel distance (paper Fig. 6) from `dressguard classify --sweep`'s CSV.

usage: hmm_sweep.py SWEEP.csv OUT.png [SWEEP2.csv LABEL2 ...] [--title TEXT]
--title replaces the title (e.g. to say the trials were in the model's training: in-sample).
The CSV has columns travel_m,accuracy,correct,total (accuracy empty where no trial was scored:
left out; a file without one accuracy is refused, naming it). Extra CSV/label pairs add curves
(e.g. a simulation-trained and a measured-data-trained classifier on one plot).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import open_input, require_columns, save_figure


def read(path):
    xs, ys = [], []
    with open_input(path) as f:
        reader = csv.DictReader(f)
        require_columns(path, reader.fieldnames, ["travel_m", "accuracy"])
        for row in reader:
            if row["accuracy"] == "":  # a cut that left no trial scored has no accuracy
                continue
            xs.append(float(row["travel_m"]))
            ys.append(100.0 * float(row["accuracy"]))
    if not xs:  # an empty curve drew an empty figure and exited 0
        raise SystemExit(f"{path}: no cut with an accuracy (no rows, or no trial scored at any cut)")
    return xs, ys


def main(argv):
    title = "Outcome classification on truncated sequences"
    if "--title" in argv:
        k = argv.index("--title")
        if k + 1 >= len(argv):
            sys.stderr.write(__doc__)
            return 2
        title = argv[k + 1]
        argv = argv[:k] + argv[k + 2:]
    if len(argv) < 3 or len(argv) % 2 == 0:
        sys.stderr.write(__doc__)
        return 2
    curves = [(argv[1], "classifier")] + [(argv[i], argv[i + 1]) for i in range(3, len(argv), 2)]
    fig, ax = plt.subplots(figsize=(6, 4))
    for path, label in curves:
        xs, ys = read(path)
        ax.plot(xs, ys, marker="o", label=label)
    ax.set_xlabel("travel distance of the end effector [m]")
    ax.set_ylabel("accuracy [%]")
    ax.set_ylim(0, 100)
    ax.grid(True, alpha=0.3)
    ax.set_title(title, fontsize=10)
    if len(curves) > 1:
        ax.legend()
    fig.tight_layout()
    save_figure(fig, argv[2], dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
