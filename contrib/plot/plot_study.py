#!/usr/bin/env python3
"""Plot an error-against-run-time study: python3 plot_study.py study.csv study.png

Log-log relative L2 error against wall time, one marker per model and one colour per
integrator; the Pareto front (no other variant is both faster and more accurate) is
drawn as a line. Written by `lacerta` in `set Mode = study`."""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def pareto_front(points):
    """Indices of the points no other point beats in both time and error."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], float("inf")
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def main():
    source, target = sys.argv[1], sys.argv[2]
    with open(source) as f:
        rows = list(csv.DictReader(f))
    # Zero times (test mode) cannot go on a log axis: give them a floor.
    points = [(max(float(r["wall_time_s"]), 1e-6), max(float(r["error_rel_l2"]), 1e-12))
              for r in rows]
    markers = {"springs": "o", "fitted springs": "s", "fem p1": "^", "fem p2": "D"}
    integrators = sorted({r["integrator"] for r in rows})
    colours = {name: plt.cm.tab10(i % 10) for i, name in enumerate(integrators)}

    fig, ax = plt.subplots(figsize=(7, 5))
    seen = set()
    for r, (t, e) in zip(rows, points):
        label = f'{r["model"]}, {r["integrator"]}'
        ax.scatter(t, e, marker=markers.get(r["model"], "x"), color=colours[r["integrator"]],
                   label=None if label in seen else label, s=40)
        seen.add(label)
        ax.annotate(r["tets"], (t, e), fontsize=6, xytext=(3, 3), textcoords="offset points")
    front = pareto_front(points)
    ax.plot([points[i][0] for i in front], [points[i][1] for i in front], "k--", lw=1,
            label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative L2 nodal error against FEM P2 reference")
    ax.set_title("Error against run time (labels: tetrahedra)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(target, dpi=120)


if __name__ == "__main__":
    main()
