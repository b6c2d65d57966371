#!/usr/bin/env python3
"""Plot an error-against-run-time study:

    python3 plot_study.py study.csv study.png [--extra peer.csv ...] [--title TEXT]

Log-log relative L2 error against wall time, one marker per model and one colour per
integrator, one panel per Poisson ratio (column poisson_ratio; a CSV without it is one
panel); each panel's Pareto front (no other variant of the panel is both faster and
more accurate) is drawn as a dashed line. Extra CSV files with the same columns (a peer
code's runs on the same problem, e.g. contrib/peers/) are drawn as their own model
series, labelled with their model and file name, and take part in the Pareto front.
Written by `lacerta` in `set Mode = study`."""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

MARKERS = {"springs": "o", "fitted springs": "s", "volume springs": "v",
           "corotated fem": "P", "fem p1": "^", "fem p2": "D"}
EXTRA_MARKERS = ["*", "X", "h", "p", "<", ">"]


def pareto_front(points):
    """Indices of the points no other point beats in both time and error."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], float("inf")
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def read_rows(path, series=None):
    """The rows of a study CSV; @p series names the model series of an extra file."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["series"] = series if series else r["model"]
        r["extra"] = series is not None
    return rows


def panel_key(row):
    """The Poisson ratio of a row, or None if its file has no such column."""
    value = row.get("poisson_ratio")
    return float(value) if value not in (None, "") else None


def draw_panel(ax, rows, markers, colours):
    # Zero times (test mode) cannot go on a log axis: give them a floor.
    points = [(max(float(r["wall_time_s"]), 1e-6), max(float(r["error_rel_l2"]), 1e-12))
              for r in rows]
    seen = set()
    for r, (t, e) in zip(rows, points):
        label = f'{r["series"]}, {r["integrator"]}'
        ax.scatter(t, e, marker=markers[r["series"]], color=colours[r["integrator"]],
                   label=None if label in seen else label, s=60 if r["extra"] else 40,
                   edgecolors="k" if r["extra"] else None)
        seen.add(label)
        ax.annotate(r["tets"], (t, e), fontsize=6, xytext=(3, 3),
                    textcoords="offset points")
    front = pareto_front(points)
    ax.plot([points[i][0] for i in front], [points[i][1] for i in front], "k--", lw=1,
            label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.grid(True, which="both", alpha=0.3)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", help="study.csv written by lacerta")
    parser.add_argument("target", help="the picture to write (png)")
    parser.add_argument("--extra", action="append", default=[], metavar="CSV",
                        help="another CSV with the same columns, drawn as its own series")
    parser.add_argument("--title", default="Error against run time",
                        help="the figure's title (the problem)")
    arguments = parser.parse_args()

    rows = read_rows(arguments.source)
    for path in arguments.extra:
        name = os.path.splitext(os.path.basename(path))[0]
        for r in read_rows(path, series=""):
            r["series"] = f'{r["model"]} ({name})'
            rows.append(r)

    series = list(dict.fromkeys(r["series"] for r in rows))
    extra = [s for s in series if s not in MARKERS]
    markers = dict(MARKERS)
    markers.update({s: EXTRA_MARKERS[i % len(EXTRA_MARKERS)] for i, s in enumerate(extra)})
    integrators = sorted({r["integrator"] for r in rows})
    colours = {name: plt.cm.tab10(i % 10) for i, name in enumerate(integrators)}

    keys = sorted({panel_key(r) for r in rows}, key=lambda k: (k is not None, k or 0))
    fig, axes = plt.subplots(1, len(keys), figsize=(6 * len(keys) + 2.2, 5), sharey=True,
                             squeeze=False)
    for ax, key in zip(axes[0], keys):
        draw_panel(ax, [r for r in rows if panel_key(r) == key], markers, colours)
        if key is not None:
            ax.set_title(f"Poisson ratio {key:g}")
    axes[0][0].set_ylabel("relative L2 nodal error against FEM P2 reference")
    # One legend for all panels: every series of any panel, once.
    legend = {}
    for ax in axes[0]:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            legend.setdefault(label, handle)
    fig.legend(legend.values(), legend.keys(), loc="center right", fontsize=7)
    fig.suptitle(f"{arguments.title} (labels: tetrahedra)")
    fig.tight_layout(rect=(0, 0, 1 - 2.2 / (6 * len(keys) + 2.2), 1))
    fig.savefig(arguments.target, dpi=110)


if __name__ == "__main__":
    main()
