#!/usr/bin/python3
"""Plots the end-to-end latency histograms that bench_predictor prints (lines
"<tag>_hist_us [lo, hi): count"), one panel per tag, log-scale bins in microseconds.

  bench_predictor > bench.txt            (or the VM test's output: ctest -R robot_vm_socketcan -V)
  tools/plot/predictor_latency.py bench.txt --out predictor_latency.png
"""
import argparse
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from figure_file import save_figure  # a temporary file, then a rename


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input", help="bench_predictor output ('-' for stdin)")
    ap.add_argument("--out", default="predictor_latency.png")
    args = ap.parse_args()
    text = sys.stdin.read() if args.input == "-" else open(args.input).read()
    hists = {}
    for tag, lo, hi, n in re.findall(r"(\w+)_hist_us \[(\d+), (\d+)\): (\d+)", text):
        hists.setdefault(tag, []).append((int(lo), int(hi), int(n)))
    if not hists:
        print(f"predictor_latency.py: no '<tag>_hist_us' lines in {args.input}", file=sys.stderr)
        return 2
    fig, axes = plt.subplots(1, len(hists), figsize=(5 * len(hists), 3.5), squeeze=False)
    for ax, (tag, rows) in zip(axes[0], sorted(hists.items())):
        total = sum(n for _, _, n in rows)
        ax.bar([f"{lo}-{hi}" for lo, hi, _ in rows], [100.0 * n / total for _, _, n in rows], color="tab:blue")
        ax.set_title(f"{tag} (n={total})")
        ax.set_xlabel("latency [us]")
        ax.set_ylabel("share [%]")
        ax.set_yscale("log")
        ax.tick_params(axis="x", rotation=60)
    fig.tight_layout()
    save_figure(fig, args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
