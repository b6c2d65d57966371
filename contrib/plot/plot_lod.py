#!/usr/bin/env python3
"""Plot the speed-up of levels of detail against their error:

    python3 plot_lod.py scene-lod.csv [other-lod.csv ...] -o lod.png [--title TEXT]

One curve per CSV file (columns scene, end_time, growth, tetrahedra, speed_up, rms_error,
largest_error, frequency_ratio, as `lacerta-bench lod` writes them), each point a
growth of the query, labelled with it. Issue 17's targets are drawn as the regions they
ask for: at least 5 times faster within 5 % RMS error, at least 2 times within 2 %."""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read_curve(path):
    """The curve's label and its points (RMS error in %, speed-up, growth), in the
    order of the growth."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    rows.sort(key=lambda r: float(r["growth"]))
    points = [(100 * float(r["rms_error"]), float(r["speed_up"]), r["growth"]) for r in rows]
    return f"{rows[0]['scene']}, at t = {rows[0]['end_time']} s", points


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", nargs="+", help="CSV files of lacerta-bench lod")
    parser.add_argument("-o", "--output", required=True, help="the PNG file to write")
    parser.add_argument("--title", default="Level of detail: speed-up against error")
    args = parser.parse_args()

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for error, speed_up in ((5, 5), (2, 2)):
        ax.fill_between([0, error], speed_up, 100, color="tab:green", alpha=0.08, lw=0)
        ax.plot([0, error, error], [speed_up, speed_up, 100], color="tab:green",
                lw=0.8, ls=":")
        ax.annotate(f"{speed_up}x within {error} %", (error, speed_up),
                    textcoords="offset points", xytext=(4, -12), fontsize=8,
                    color="tab:green")
    top = 6
    for path in args.csv:
        scene, points = read_curve(path)
        xs = [p[0] for p in points]
        ys = [p[1] for p in points]
        top = max(top, max(ys) * 1.2)
        ax.plot(xs, ys, marker="o", label=scene)
        for x, y, growth in points:
            ax.annotate(f"g={growth}", (x, y), textcoords="offset points", xytext=(4, 4),
                        fontsize=7)
    ax.set_xlim(0, max(10, max(max(read_curve(p)[1])[0] for p in args.csv) * 1.15))
    ax.set_ylim(0, top)
    ax.set_xlabel("RMS displacement error against full resolution (%)")
    ax.set_ylabel("speed-up over full resolution")
    ax.set_title(args.title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()
