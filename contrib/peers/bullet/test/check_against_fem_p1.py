#!/usr/bin/env python3
"""Checks the Bullet peer against FEM P1 on the same mesh.

Usage: check_against_fem_p1.py study.csv peer_bullet.csv [tolerance]

Both files have the study's columns, poisson_ratio last. For every mesh size (tets) and
Poisson ratio of the peer, its relative L2 error against the study's FEM P2 reference
must lie within `tolerance` (relative, default 0.03) of FEM P1's on the same mesh at the
same ratio: both are P1 linear elasticity on the same tetrahedra with the same loads.
Exit 1 otherwise.
"""
import csv
import sys


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    study, peer = rows(sys.argv[1]), rows(sys.argv[2])
    tolerance = float(sys.argv[3]) if len(sys.argv) == 4 else 0.03
    p1 = {(r["tets"], float(r["poisson_ratio"])): float(r["error_rel_l2"])
          for r in study if r["model"] == "fem p1"}
    if not peer:
        sys.exit(f"{sys.argv[2]}: no rows")
    failed = False
    for r in peer:
        if "poisson_ratio" not in r:
            sys.exit(f"{sys.argv[2]}: no poisson_ratio column")
        key = (r["tets"], float(r["poisson_ratio"]))
        if key not in p1:
            sys.exit(f"{sys.argv[1]}: no FEM P1 row on {key[0]} tetrahedra at "
                     f"Poisson ratio {key[1]}")
        bullet, reference = float(r["error_rel_l2"]), p1[key]
        deviation = abs(bullet - reference) / reference
        ok = deviation <= tolerance
        failed |= not ok
        print(f"{r['tets']} tets, nu {key[1]}: bullet {bullet:.4f}, fem p1 {reference:.4f}, "
              f"relative difference {deviation:.4f} "
              f"({'within' if ok else 'OUTSIDE'} {tolerance})")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
