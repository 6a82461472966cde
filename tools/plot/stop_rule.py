#!/usr/bin/python3
"""What a stop policy costs and buys: for each model, the share of the replayed pulls of each
outcome that the predictor stopped for 'caught', and where (travel at the stop). Stops on good
and missed pulls end a pull for nothing; stops on caught pulls are what the rule is for.
models/README.md, "The stop rule on the real pulls".

usage: stop_rule.py OUT.png NAME=REPLAY.json [NAME=REPLAY.json ...]
Each REPLAY.json is the output of `dressguard replay --model M --logs DIR --json`.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from figure_file import save_figure  # a temporary file, then a rename

ORDER = ["good", "missed", "caught", "unlabelled"]


def load(arg):
    name, _, path = arg.partition("=")
    if not path:
        sys.exit(f"stop_rule.py: '{arg}' is not NAME=REPLAY.json")
    try:
        with open(path) as fh:
            data = json.load(fh)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"stop_rule.py: {path}: {e}")
    if "outcomes" not in data or "trials" not in data:
        sys.exit(f"stop_rule.py: {path}: not the output of `dressguard replay --logs DIR --json`")
    return name, data


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    out, runs = argv[1], [load(a) for a in argv[2:]]
    labels = [l for l in ORDER if any(l in d["outcomes"] for _, d in runs)]
    fig, (ax_share, ax_travel) = plt.subplots(1, 2, figsize=(11, 4.2))
    width = 0.8 / len(runs)
    for k, (name, data) in enumerate(runs):
        xs, shares, notes = [], [], []
        for i, label in enumerate(labels):
            row = data["outcomes"].get(label)
            if not row or not row["trials"]:
                continue
            xs.append(i + (k - (len(runs) - 1) / 2) * width)
            shares.append(100.0 * row["caught_stops"] / row["trials"])
            notes.append(f"{row['caught_stops']}/{row['trials']}")
        bars = ax_share.bar(xs, shares, width, label=name)
        for b, note in zip(bars, notes):
            ax_share.annotate(note, (b.get_x() + b.get_width() / 2, b.get_height()), ha="center", va="bottom", fontsize=8)
        for i, label in enumerate(labels):
            travel = [t["travel"] for t in data["trials"] if t["label"] == label and t["reason"] == "caught"]
            x = i + (k - (len(runs) - 1) / 2) * width
            ax_travel.plot([x] * len(travel), travel, "o", color=bars.patches[0].get_facecolor() if bars.patches else None,
                           alpha=0.7, label=name if i == 0 else None)
    for ax in (ax_share, ax_travel):
        ax.set_xticks(range(len(labels)))
        ax.set_xlim(-0.6, len(labels) - 0.4)
        ax.set_xticklabels(labels)
        ax.set_xlabel("outcome of the pull")
    ax_share.set_ylabel("pulls stopped for 'caught' [%]")
    ax_share.set_ylim(0, 130)
    ax_share.legend(fontsize=8, loc="upper center", ncol=2)
    ax_travel.set_ylabel("travel at the stop [m]")
    ax_travel.set_ylim(0, 0.9)
    fig.suptitle("predictor's stop rule on replayed pulls (dressguard replay --logs)")
    fig.tight_layout()
    save_figure(fig, out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv)
