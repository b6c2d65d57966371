#!/usr/bin/env python3
"""Markdown tables of an error-against-run-time study: python3 study_table.py study.csv

One table: a row per model and integrator (and time step), a column per Poisson ratio
with the relative L2 error and the wall time at every mesh ("err / err (s / s)", meshes
in increasing size); then, per Poisson ratio, the variants on the Pareto front (as
plot_study.py draws it), fastest first. The tables of doc/accuracy.md."""
import csv
import sys

from plot_study import pareto_front


def label(row):
    name = f'{row["model"]}, {row["integrator"]}'
    if float(row["time_step"]) > 0:
        name += f' {float(row["time_step"]):g} s'
    return name


def main():
    with open(sys.argv[1]) as f:
        rows = list(csv.DictReader(f))
    ratios = sorted({float(r.get("poisson_ratio") or 0) for r in rows})
    tets = sorted({int(r["tets"]) for r in rows})
    variants = list(dict.fromkeys(label(r) for r in rows))
    cell = {(label(r), float(r.get("poisson_ratio") or 0), int(r["tets"])): r for r in rows}

    print(f'| model, integrator | ' + " | ".join(f"ν = {nu:g}" for nu in ratios) + " |")
    print("|---" * (len(ratios) + 1) + "|")
    for v in variants:
        cells = []
        for nu in ratios:
            found = [cell.get((v, nu, n)) for n in tets]
            errors = " / ".join(f'{float(r["error_rel_l2"]):.3g}' for r in found if r)
            times = " / ".join(f'{float(r["wall_time_s"]):.2g}' for r in found if r)
            cells.append(f"{errors} ({times} s)" if errors else "-")
        print(f"| {v} | " + " | ".join(cells) + " |")
    print(f"\nMeshes: {' / '.join(str(n) for n in tets)} tetrahedra.\n")
    for nu in ratios:
        at = [r for r in rows if float(r.get("poisson_ratio") or 0) == nu]
        points = [(max(float(r["wall_time_s"]), 1e-6), float(r["error_rel_l2"])) for r in at]
        front = pareto_front(points)
        print(f"Pareto front at ν = {nu:g}: " + "; ".join(
            f'{label(at[i])} on {at[i]["tets"]} ({float(at[i]["wall_time_s"]):.2g} s, '
            f'{float(at[i]["error_rel_l2"]):.3g})' for i in front))
        print()


if __name__ == "__main__":
    main()
