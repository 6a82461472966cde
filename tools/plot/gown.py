#!/usr/bin/python3
"""Picture of the placed gown: three orthographic views of the world frame W (z up, the gripper
moves along +x) and a 3-D view. Grasped vertices orange, the sleeve opening the arm enters blue,
its lower half (paper Fig. 3b, used for the outcome label) red, other boundary loops dark grey,
the arm's spheres and tapered capsules as outlines, the upper jaw and the grasp box as boxes.

usage: /usr/bin/python3 tools/plot/gown.py SCENE.json OUT.png
SCENE.json is written by `dressguard gown --dump FILE` (or --picture, which calls this script).
"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from figure_file import save_figure  # a temporary file, then a rename

VIEWS = [("side (x-z)", 0, 2), ("top (x-y)", 0, 1), ("front (y-z), looking along -x", 1, 2)]


def tangent_lines(c1, r1, c2, r2):
    """The two outer tangents of circles (c1, r1), (c2, r2): the outline of a tapered capsule."""
    d = np.linalg.norm(c2 - c1)
    if d <= abs(r1 - r2) + 1e-9:
        return []
    u = (c2 - c1) / d
    perp = np.array([-u[1], u[0]])
    s = (r1 - r2) / d
    lines = []
    for sign in (1, -1):
        n = u * s + sign * perp * math.sqrt(max(0.0, 1 - s * s))
        lines.append((c1 + r1 * n, c2 + r2 * n))
    return lines


def box_outline(center, half, i, j):
    x0, x1 = center[i] - half[i], center[i] + half[i]
    y0, y1 = center[j] - half[j], center[j] + half[j]
    return [x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        s = json.load(f)
    x = np.array(s["x"])
    tri = np.array(s["triangles"])
    grasp = np.array(s["grasp"], dtype=int)
    lower = np.array(s["sleeve_lower_half"], dtype=int)
    loops = s["boundary_loops"]
    sleeve = s["sleeve_loop"]
    arm = s["arm"]
    spheres = [(np.array(arm[k]), arm["r_" + k]) for k in ("fist", "wrist", "elbow", "shoulder")]
    capsules = [(1, 2), (2, 3)]  # wrist-elbow (forearm), elbow-shoulder (upper arm)
    gb, jaw = s["grasp_box"], s["upper_jaw"]

    fig = plt.figure(figsize=(16, 11))
    for k, (title, i, j) in enumerate(VIEWS):
        ax = fig.add_subplot(2, 2, k + 1)
        ax.triplot(x[:, i], x[:, j], tri, lw=0.08, color="0.6")
        for li, loop in enumerate(loops):
            p = x[loop + loop[:1]]
            ax.plot(p[:, i], p[:, j], color="tab:blue" if li == sleeve else "0.25", lw=1.6 if li == sleeve else 0.8)
        ax.plot(x[grasp, i], x[grasp, j], ".", color="tab:orange", ms=3, label=f"grasped ({len(grasp)})")
        ax.plot(x[lower, i], x[lower, j], "o", color="tab:red", ms=3, label="sleeve opening, lower half")
        for c, r in spheres:
            ax.add_patch(plt.Circle((c[i], c[j]), r, fill=False, color="tab:green", lw=1))
        for a, b in capsules:
            (ca, ra), (cb, rb) = spheres[a], spheres[b]
            for p, q in tangent_lines(ca[[i, j]], ra, cb[[i, j]], rb):
                ax.plot([p[0], q[0]], [p[1], q[1]], color="tab:green", lw=1)
        half_jaw = [0.5 * v for v in jaw["size"]]
        ax.plot(*box_outline(jaw["center"], half_jaw, i, j), color="k", lw=1.2)
        ax.plot(*box_outline(gb["center"], gb["half_extent"], i, j), "--", color="tab:orange", lw=1)
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.set_xlabel("xyz"[i] + "_W [m]")
        ax.set_ylabel("xyz"[j] + "_W [m]")
        if k == 0:
            ax.legend(loc="lower right", fontsize=8)
    ax = fig.add_subplot(2, 2, 4, projection="3d")
    ax.plot_trisurf(x[:, 0], x[:, 1], x[:, 2], triangles=tri, color="0.85", edgecolor="none", alpha=0.6)
    sl = loops[sleeve]
    p = x[sl + sl[:1]]
    ax.plot(p[:, 0], p[:, 1], p[:, 2], color="tab:blue", lw=2)
    ax.scatter(x[grasp, 0], x[grasp, 1], x[grasp, 2], color="tab:orange", s=4)
    ax.scatter(x[lower, 0], x[lower, 1], x[lower, 2], color="tab:red", s=6)
    pts = np.array([c for c, _ in spheres])
    ax.plot(pts[1:, 0], pts[1:, 1], pts[1:, 2], color="tab:green", lw=3)
    lo, hi = np.minimum(x.min(0), pts.min(0)), np.maximum(x.max(0), pts.max(0))
    mid, span = 0.5 * (lo + hi), 0.5 * (hi - lo).max()
    ax.set_xlim(mid[0] - span, mid[0] + span)
    ax.set_ylim(mid[1] - span, mid[1] + span)
    ax.set_zlim(mid[2] - span, mid[2] + span)
    ax.set_xlabel("x_W")
    ax.set_ylabel("y_W")
    ax.set_zlabel("z_W")
    ax.view_init(elev=20, azim=-60)
    ax.set_title("3-D (arm axis green)")
    state = s.get("state", "placed")
    fig.suptitle(f"gown {state}: {len(x)} vertices, {len(tri)} triangles; {s['frame']}")
    fig.tight_layout()
    save_figure(fig, sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
