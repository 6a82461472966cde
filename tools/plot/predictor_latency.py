#!/usr/bin/python3
"""Plots the end-to-end latency histograms that bench_predictor prints (lines
"<tag>_hist_us [lo, hi): count"), one panel per tag, log-scale bins in microseconds; the
empty bins between the first and the last non-empty one are drawn (at zero), so a tail's
distance from the body shows. The latencies beyond the histogram's range (the line
"<tag>_hist_us [range, inf): count", since session 91; before, they were in the last bucket)
are the last bar, ">= range".

  bench_predictor > bench.txt            (or the VM test's output: ctest -R robot_vm_socketcan -V)
  tools/plot/predictor_latency.py bench.txt --out predictor_latency.png
"""
import argparse
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from figure_file import open_input, save_figure  # a temporary file, then a rename


def every_bucket(rows):
    """rows ((lo, hi, count), the non-empty buckets bench_predictor prints) with every bucket
    between the first and the last filled in at count 0: drawn as adjacent categories, a tail
    bucket such as [8192, 16384) stood right beside [16, 32) (session 85's tools review,
    finding 8). The buckets are bench_predictor's: [0, 2), then [2^k, 2^(k+1))."""
    given = {lo: (hi, n) for lo, hi, n in rows}
    out, lo, last = [], min(given), max(given)
    while lo <= last:
        hi, n = given.get(lo, (max(2 * lo, 2), 0))
        out.append((lo, hi, n))
        lo = hi
    if not set(given) <= {lo for lo, _, _ in out}:  # not the doubling buckets: as printed
        return sorted(rows)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input", help="bench_predictor output ('-' for stdin)")
    ap.add_argument("--out", default="predictor_latency.png")
    args = ap.parse_args()
    if args.input == "-":
        text = sys.stdin.read()
    else:
        with open_input(args.input) as f:
            text = f.read()
    hists, beyond = {}, {}
    for tag, lo, hi, n in re.findall(r"(\w+)_hist_us \[(\d+), (\d+)\): (\d+)", text):
        hists.setdefault(tag, []).append((int(lo), int(hi), int(n)))
    for tag, cap, n in re.findall(r"(\w+)_hist_us \[([0-9.]+), inf\): (\d+)", text):
        beyond[tag] = (float(cap), int(n))
        hists.setdefault(tag, [])
    if not hists:
        print(f"predictor_latency.py: no '<tag>_hist_us' lines in {args.input}", file=sys.stderr)
        return 2
    fig, axes = plt.subplots(1, len(hists), figsize=(5 * len(hists), 3.5), squeeze=False)
    for ax, (tag, rows) in zip(axes[0], sorted(hists.items())):
        rows = every_bucket(rows) if rows else []
        bars = [(f"{lo}-{hi}", n, "tab:blue") for lo, hi, n in rows]
        if tag in beyond:  # at or beyond the histogram's range, apart: not a bucket of known width
            cap, n = beyond[tag]
            bars.append((f">= {cap:g}", n, "tab:red"))
        total = sum(n for _, n, _ in bars)
        if total == 0:
            print(f"predictor_latency.py: {args.input}: every '{tag}_hist_us' bucket is empty", file=sys.stderr)
            return 1
        ax.bar([name for name, _, _ in bars], [100.0 * n / total for _, n, _ in bars],
               color=[colour for _, _, colour in bars])
        ax.set_title(f"{tag} (n={total})")
        ax.set_xlabel("latency [us]")
        ax.set_ylabel("share [%]")
        ax.set_yscale("log")
        # Room below the smallest share, so that a one-sample tail is a bar, not a sliver.
        ax.set_ylim(bottom=min(100.0 * n / total for _, n, _ in bars if n) / 3)
        ax.tick_params(axis="x", rotation=60)
    fig.tight_layout()
    save_figure(fig, args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
