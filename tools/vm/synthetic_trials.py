#!/usr/bin/python3
"""Synthetic sleeve-pulling trials for the robot-side tests (not the physics simulator's output).

Writes a dataset folder (manifest.csv + one CSV per trial, offline/core/dataset.h) with trials
whose force signatures follow the study's description (shared/data/README.md):
  good    high arm: light drag until the sleeve is on the forearm (~0.3 m), then a steady rise
          to -5 N near 0.54 m and a steep one to the rig's -10 N stop near 0.62 m; vertical ~0;
  missed  low arm: the hand misses; drag grows to about -4.5 N over the 0.85 m travel,
          vertical slope about -2 N/m;
  caught  middle arm: the hand catches (~0.2-0.3 m) and the drag rises fast, the gown pulling the
          arm down (vertical falling with the drag).
Each trial varies its catch point, slopes and vertical scale, plus 0.02 N white noise and a slow
0.1 N wobble (the study's noise is about 0.017 N). Deterministic for a given --seed.

  synthetic_trials.py --out DIR [--per-class N] [--seed S]
"""
import argparse
import csv
import math
import os
import random


def travel(t, v, a=1.0):
    tr = v / a
    return 0.5 * a * t * t if t < tr else v * v / (2 * a) + v * (t - tr)


def piecewise(x, pts):
    """Linear interpolation through (x, y) points; constant past the ends."""
    if x <= pts[0][0]:
        return pts[0][1]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return pts[-1][1]


def trial(label, rng, speed):
    j = lambda lo, hi: rng.uniform(lo, hi)
    if label == "good":
        on = j(0.27, 0.33)
        mid = on + j(0.21, 0.26)
        end = mid + j(0.06, 0.09)
        fm = [(0, 0), (on, -j(0.3, 0.5)), (mid, -j(4.5, 5.5)), (end, -11.0)]
        vs = j(-0.3, 0.3)
        fv = lambda x, f: vs * x - (0.08 * (-f - 5) if f < -5 else 0.0)
        x_end = 0.85
    elif label == "missed":
        fm_end = j(4.0, 5.0)
        fm = [(0, 0), (0.1, -j(0.1, 0.3)), (0.85, -fm_end)]
        slope = j(-2.4, -1.6)
        fv = lambda x, f: slope * x
        x_end = 0.85
    else:
        catch = j(0.18, 0.30)
        rise = j(0.15, 0.22)
        fm = [(0, 0), (catch, -j(0.3, 0.6)), (catch + 0.4 * rise, -j(2.5, 3.5)), (catch + rise, -11.0)]
        scale = j(0.8, 1.1)
        fv = lambda x, f: -scale * max(0.0, -f - 1.0)
        x_end = 0.85
    rows = []
    phase = rng.uniform(0, 2 * math.pi)
    t = 0.0
    while True:
        x = travel(t, speed)
        if x > x_end:
            break
        f = piecewise(x, fm)
        wobble = 0.1 * math.sin(2 * math.pi * 0.7 * t + phase)
        m = f + wobble + rng.gauss(0, 0.02)
        v = fv(x, f) + 0.5 * wobble + rng.gauss(0, 0.02)
        rows.append((t, x, m, rng.gauss(0, 0.05), v))
        if f <= -10.5:  # past the rig's 10 N stop: the trial is over
            break
        t += 0.01
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--per-class", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    os.makedirs(args.out, exist_ok=True)
    heights = {"good": "high", "missed": "low", "caught": "middle"}
    manifest = []
    for label in ("good", "missed", "caught"):
        for k in range(args.per_class):
            speed = 0.1 if k % 2 == 0 else 0.15
            rows = trial(label, rng, speed)
            tid = f"syn{args.seed}-{label}-{k}"
            with open(os.path.join(args.out, tid + ".csv"), "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["t", "travel", "f_motion", "f_lateral", "f_vertical"])
                for r in rows:
                    w.writerow([f"{r[0]:.4f}", f"{r[1]:.6f}", f"{r[2]:.6f}", f"{r[3]:.6f}", f"{r[4]:.6f}"])
            manifest.append([tid, "", heights[label], speed, label, tid + ".csv"])
    with open(os.path.join(args.out, "manifest.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["trial_id", "participant", "height", "speed", "label", "file"])
        w.writerows(manifest)
    print(f"wrote {len(manifest)} synthetic trials to {args.out}")


if __name__ == "__main__":
    main()
