#!/usr/bin/env python3
"""Draws one frame of the bouncing-cube scene (the JSON of `bpaccel-bench scene`) as a PNG."""
import pathlib
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from json_input import parse_and_read  # noqa: E402

COLOURS = {"sphere": "tab:blue", "box": "tab:orange", "cylinder": "tab:green", "capsule": "tab:red"}


def rotation(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def surface(ax, pts, colour):
    """pts: 3 x U x V grid in world coordinates."""
    ax.plot_surface(pts[0], pts[1], pts[2], color=colour, linewidth=0, shade=True, alpha=0.9)


def draw(ax, obj):
    kind, pos, rot = obj["shape"], np.array(obj["position"]), rotation(obj["rotation"])
    he = obj["half_extents"]
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 14), np.linspace(0, np.pi, 8))
    if kind == "sphere":
        r = he[0]
        local = np.array([r * np.cos(u) * np.sin(v), r * np.sin(u) * np.sin(v), r * np.cos(v)])
    elif kind in ("cylinder", "capsule"):
        r, h = he[0], he[1]
        t = np.linspace(-h, h, 6)
        uu, tt = np.meshgrid(np.linspace(0, 2 * np.pi, 14), t)
        local = np.array([r * np.cos(uu), tt, r * np.sin(uu)])  # Bullet's Y-up cylinder and capsule
        if kind == "capsule":
            for end in (-h, h):
                cap = np.array([r * np.cos(u) * np.sin(v), end + r * np.cos(v), r * np.sin(u) * np.sin(v)])
                surface(ax, np.einsum("ij,jkl->ikl", rot, cap) + pos[:, None, None], COLOURS[kind])
    else:
        corners = np.array([[sx * he[0], sy * he[1], sz * he[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        world = corners @ rot.T + pos
        faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
        ax.add_collection3d(Poly3DCollection([world[f] for f in faces], facecolor=COLOURS[kind], edgecolor="k",
                                             linewidths=0.2, alpha=0.9))
        return
    surface(ax, np.einsum("ij,jkl->ikl", rot, local) + pos[:, None, None], COLOURS[kind])


def main() -> int:
    args, (edge, objects, frame) = parse_and_read("render_scene", __doc__, "results/scene.json", "--out",
                                                  "results/scene.png", ("cube_edge", "objects", "frame"))
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    for obj in objects:
        draw(ax, obj)
    for a in (0, edge):  # the cube's edges
        for b in (0, edge):
            ax.plot([0, edge], [a, a], [b, b], "k-", lw=0.6)
            ax.plot([a, a], [0, edge], [b, b], "k-", lw=0.6)
            ax.plot([a, a], [b, b], [0, edge], "k-", lw=0.6)
    ax.set_xlim(0, edge)
    ax.set_ylim(0, edge)
    ax.set_zlim(0, edge)
    ax.set_box_aspect((1, 1, 1))
    ax.set_title(f"{len(objects)} objects bouncing in a cube of edge {edge:.1f}, frame {frame}\n"
                 "spheres blue, boxes orange, cylinders green, capsules red", fontsize=9)
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"render_scene: wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
