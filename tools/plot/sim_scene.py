#!/usr/bin/python3
"""Pictures of a simulated trial (dressguard simulate's FILE.scene.json): the gown, the arm and
the gripper at the start of the pull, 5 cm of travel after first contact with the arm, and at
the end; three 3-D panels and a side view; and the sleeve opening seen from the fist at the
start and after contact,
with the fist at each of the three arm heights (where the rim hangs decides the outcome before
any force does). Usage: sim_scene.py SCENE.json OUT.png"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from figure_file import load_json, require_columns, save_figure  # a temporary file, then a rename


def round_cone_mesh(a, ra, b, rb, n=18, m=10):
    """Surface points of a round cone as a (rings x n) grid for plot_surface."""
    a, b = np.array(a), np.array(b)
    d = b - a
    L = np.linalg.norm(d)
    rings = []
    if L < 1e-9:
        u = np.array([1.0, 0, 0])
    else:
        u = d / L
    v = np.cross(u, [0, 0, 1.0])
    if np.linalg.norm(v) < 1e-6:
        v = np.cross(u, [0, 1.0, 0])
    v /= np.linalg.norm(v)
    w = np.cross(u, v)
    th = np.linspace(0, 2 * np.pi, n)
    # hemisphere at a, cylinder-ish body, hemisphere at b
    for s in np.linspace(-np.pi / 2, 0, m):
        c = a + ra * np.sin(s) * u
        r = ra * np.cos(s)
        rings.append(c[None, :] + r * (np.cos(th)[:, None] * v + np.sin(th)[:, None] * w))
    for s in np.linspace(0, np.pi / 2, m):
        c = b + rb * np.sin(s) * u
        r = rb * np.cos(s)
        rings.append(c[None, :] + r * (np.cos(th)[:, None] * v + np.sin(th)[:, None] * w))
    P = np.array(rings)
    return P[:, :, 0], P[:, :, 1], P[:, :, 2]


def draw(ax, sc, frame, title):
    X = np.array(frame["x"]).reshape(-1, 3)
    tris = np.array(sc["tris"])
    poly = Poly3DCollection(X[tris], facecolor=(0.55, 0.7, 0.9, 0.55), edgecolor=(0.2, 0.3, 0.5, 0.15), linewidth=0.1)
    ax.add_collection3d(poly)
    for c in sc["arm"]:
        xs, ys, zs = round_cone_mesh(c["a"], c["ra"], c["b"], c["rb"])
        ax.plot_surface(xs, ys, zs, color=(0.9, 0.65, 0.5), alpha=0.9, linewidth=0, shade=True)
    if sc.get("support"):  # the support under the gown (sim/trial.h support_depth)
        c = sc["support"]
        xs, ys, zs = round_cone_mesh(c["a"], c["ra"], c["b"], c["rb"])
        ax.plot_surface(xs, ys, zs, color=(0.6, 0.6, 0.6), alpha=0.6, linewidth=0, shade=True)
    op = np.array(sc["opening"], dtype=int)
    if len(op):
        ax.scatter(X[op, 0], X[op, 1], X[op, 2], color="red", s=4)
    g = np.array(sc["grip"]) + np.array([frame["travel"], 0, 0])
    h = np.array(sc["jaw_half"])
    for dz in (h[2] + 0.005, -h[2] - 0.005):
        xx = [g[0] - h[0], g[0] + h[0], g[0] + h[0], g[0] - h[0], g[0] - h[0]]
        yy = [g[1] - h[1], g[1] - h[1], g[1] + h[1], g[1] + h[1], g[1] - h[1]]
        ax.plot(xx, yy, [g[2] + dz] * 5, color="k", linewidth=1.5)
    ax.set_xlim(-0.8, 0.9)
    ax.set_ylim(-0.6, 0.6)
    ax.set_zlim(-1.2, 0.2)
    ax.set_box_aspect((1.7, 1.2, 1.4))
    ax.view_init(elev=12, azim=-60)
    ax.set_xlabel("x (motion) [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title, fontsize=9)


def side(ax, sc, frame):
    """Side view (x-z), the arm as circles and outlines, the gripper as its jaw box."""
    X = np.array(frame["x"]).reshape(-1, 3)
    tris = np.array(sc["tris"])
    ax.triplot(X[:, 0], X[:, 2], tris, color=(0.3, 0.45, 0.7), linewidth=0.15)
    for c, colour in [(c, "peru") for c in sc["arm"]] + ([(sc["support"], "grey")] if sc.get("support") else []):
        for p, r in ((c["a"], c["ra"]), (c["b"], c["rb"])):
            ax.add_patch(plt.Circle((p[0], p[2]), r, fill=False, color=colour, linewidth=1.5))
        ax.plot([c["a"][0], c["b"][0]], [c["a"][2] + c["ra"], c["b"][2] + c["rb"]], color=colour)
        ax.plot([c["a"][0], c["b"][0]], [c["a"][2] - c["ra"], c["b"][2] - c["rb"]], color=colour)
    op = np.array(sc["opening"], dtype=int)
    if len(op):
        ax.plot(X[op, 0], X[op, 2], ".", color="red", markersize=3)
    g = np.array(sc["grip"]) + np.array([frame["travel"], 0, 0])
    h = np.array(sc["jaw_half"])
    ax.add_patch(plt.Rectangle((g[0] - h[0], g[2] - h[2]), 2 * h[0], 2 * h[2], color="k"))
    ax.set_aspect("equal")
    ax.set_xlim(-1.0, 1.0)
    ax.set_ylim(-1.0, 0.45)
    ax.set_xlabel("x (motion) [m]")
    ax.set_ylabel("z [m]")


def from_fist(ax, sc, frame, title):
    """The gown near the opening seen from the fist (y-z, looking along -x): the cloth within
    0.25 m behind the opening's front, the opening in red, this trial's fist solid and the three
    heights' nominal fists dashed."""
    X = np.array(frame["x"]).reshape(-1, 3)
    op = np.array(sc["opening"], dtype=int)
    front = X[op, 0].max() if len(op) else X[:, 0].max()
    near = (X[:, 0] > front - 0.25) & (X[:, 0] <= front + 0.01)
    ax.scatter(X[near, 1], X[near, 2], s=1, c=X[near, 0], cmap="Blues", vmin=front - 0.3, vmax=front)
    if len(op):
        loop = np.r_[op, op[:1]]
        ax.plot(X[loop, 1], X[loop, 2], ".-", color="red", markersize=3, linewidth=0.8)
    fist = sc["arm"][1]  # the fist's sphere (offline/sim: elbow, fist, ...)
    ax.add_patch(plt.Circle((fist["a"][1], fist["a"][2]), fist["ra"], fill=False, color="peru", linewidth=2))
    for z, name in zip(sc.get("arm_axis_z", []), ("high", "middle", "low")):
        ax.add_patch(plt.Circle((0, z), fist["ra"], fill=False, color="gray", linestyle="--", linewidth=0.8))
        ax.text(fist["ra"] + 0.01, z, name, fontsize=7, color="gray", va="center")
    ax.set_aspect("equal")
    ax.set_xlim(-0.3, 0.3)
    ax.set_ylim(-0.4, 0.3)
    ax.set_xlabel("y (lateral) [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(title, fontsize=9)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sc = load_json(sys.argv[1])
    require_columns(sys.argv[1], sc, ["frames", "tris", "arm", "opening", "grip", "jaw_half", "samples", "height",
                                      "arm_offset", "label", "travel", "d_max"], "its keys")
    frames = sc["frames"]
    if not frames:
        sys.exit("sim_scene.py: no frames in " + sys.argv[1])
    for i, f in enumerate(frames):
        require_columns(sys.argv[1], f, ["t", "travel", "x"], f"the keys of frame {i}")
    start = min(frames, key=lambda f: abs(f["t"]))
    ct = sc.get("contact_t", -1)
    samples = np.array(sc["samples"]) if sc["samples"] else np.zeros((0, 5))
    # contact: the frame nearest 5 cm of travel after the first arm contact (summary field), where
    # the sleeve has taken the arm and the picture shows how; else the middle frame
    ctr = sc.get("contact_travel", -1)
    later = [f for f in frames if f["t"] > 0]
    if ctr is not None and ctr >= 0 and later:
        contact = min(later, key=lambda f: abs(f["travel"] - ctr - 0.05))
    else:
        contact = later[len(later) // 2] if later else start
    end = frames[-1]
    fig = plt.figure(figsize=(21, 10))
    for k, (f, name) in enumerate([(start, "start of the pull"), (contact, "5 cm after contact" if ctr is not None and ctr >= 0 and later else "middle"), (end, "end")]):
        ax = fig.add_subplot(2, 4, k + 1, projection="3d")
        draw(ax, sc, f, f"{name}: t = {f['t']:.2f} s, travel = {f['travel']:.3f} m")
        side(fig.add_subplot(2, 4, k + 5), sc, f)
    from_fist(fig.add_subplot(2, 4, 4), sc, start, "from the fist: start of the pull")
    from_fist(fig.add_subplot(2, 4, 8), sc, contact, f"from the fist: travel {contact['travel']:.3f} m")
    fig.suptitle(f"simulated trial, {sc['height']} arm (offset {sc['arm_offset']:+.3f} m): "
                 f"{sc['label']}, travel {sc['travel']:.3f} m, d_max {sc['d_max']:.3f} m")
    fig.tight_layout()
    save_figure(fig, sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
