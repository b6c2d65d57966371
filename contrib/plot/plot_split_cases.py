#!/usr/bin/env python3
"""Render the cases of the tetrahedron split table (doc/split-table.md).

Usage:
    lacerta-bench split --dump > split-dump.txt
    /usr/bin/python3 contrib/plot/plot_split_cases.py split-dump.txt doc/images

Needs matplotlib (Debian: python3-matplotlib). Writes doc/images/split-<case>.png for
every cut case and doc/images/split-refinements.png for the refinements R1-R6: an
exploded view of the children of one real split (each child moved away from the
parent's centre), coloured by the side of the cut, with the faces on the cut surface
in red and the crack-front points in black.
"""

import sys
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

SIDE_COLOUR = {1: "#4C72B0", -1: "#DD8452", 0: "#B0B0B0"}
CUT_COLOUR = "#C44E52"
DESCRIPTION = {
    "A": "complete, 3 cut edges: tetrahedron + prism",
    "B": "complete, 4 cut edges: two prisms",
    "A-v": "complete through a vertex: tetrahedron + pyramid",
    "A-vv": "complete through two vertices: two tetrahedra",
    "C": "partial, crack through 1 edge",
    "D": "partial, crack through 2 edges",
    "E": "partial, crack through 3 edges",
    "C-v": "partial, crack from a vertex",
    "D-v": "partial, crack through a vertex and an edge",
    "D-vv": "partial, crack along an edge",
}


def read_dump(path):
    cases = {}
    order = []
    current = None
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "case":
                current = {"parent": [], "children": []}
                cases[w[1]] = current
                order.append(w[1])
            elif w[0] == "parent":
                current["parent"].append(tuple(map(float, w[1:4])))
            elif w[0] == "child":
                side, cut_faces = int(w[1]), int(w[2])
                nodes = []
                for k in range(4):
                    kind = int(w[3 + 4 * k])
                    p = tuple(map(float, w[4 + 4 * k : 7 + 4 * k]))
                    nodes.append((kind, p))
                current["children"].append((side, cut_faces, nodes))
    return order, cases


def centre(points):
    n = len(points)
    return tuple(sum(p[k] for p in points) / n for k in range(3))


def draw_case(ax, case, title):
    parent = case["parent"]
    c = centre(parent)
    # Parent edges, in place.
    for i in range(4):
        for j in range(i + 1, 4):
            xs, ys, zs = zip(parent[i], parent[j])
            ax.plot(xs, ys, zs, color="#999999", linewidth=0.6, linestyle=":")
    explode = 0.7
    for side, cut_faces, nodes in case["children"]:
        pts = [p for _, p in nodes]
        cc = centre(pts)
        shift = tuple(explode * (cc[k] - c[k]) for k in range(3))
        moved = [tuple(p[k] + shift[k] for k in range(3)) for p in pts]
        for f in range(4):
            tri = [moved[k] for k in range(4) if k != f]
            on_cut = bool(cut_faces & (1 << f))
            poly = Poly3DCollection(
                [tri],
                facecolor=CUT_COLOUR if on_cut else SIDE_COLOUR[side],
                edgecolor="#333333",
                linewidths=0.5,
                alpha=0.85 if on_cut else 0.35,
            )
            ax.add_collection3d(poly)
        for (kind, _), p in zip(nodes, moved):
            if kind == 2:  # crack-front point
                ax.scatter([p[0]], [p[1]], [p[2]], color="black", s=10, depthshade=False)
    size = max(max(p[k] for p in parent) - min(p[k] for p in parent) for k in range(3))
    lo = [min(p[k] for p in parent) - 0.3 * size for k in range(3)]
    hi = [max(p[k] for p in parent) + 0.3 * size for k in range(3)]
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), zoom=1.35)
    ax.view_init(elev=22, azim=-55)
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    order, cases = read_dump(sys.argv[1])
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    for name in order:
        if name.startswith("R"):
            continue
        fig = plt.figure(figsize=(4.5, 4.5))
        ax = fig.add_subplot(projection="3d")
        n = len(cases[name]["children"])
        draw_case(ax, cases[name], "case %s: %d children\n%s" % (name, n, DESCRIPTION.get(name, "")))
        fig.tight_layout()
        fig.savefig(os.path.join(out, "split-%s.png" % name), dpi=90)
        plt.close(fig)
    refinements = [name for name in order if name.startswith("R")]
    fig = plt.figure(figsize=(9, 6))
    for k, name in enumerate(sorted(refinements)):
        ax = fig.add_subplot(2, 3, k + 1, projection="3d")
        n = len(cases[name]["children"])
        draw_case(ax, cases[name], "%s: %d cut edges, %d children" % (name, int(name[1:]), n))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "split-refinements.png"), dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main()
