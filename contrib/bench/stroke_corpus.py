#!/usr/bin/env python3
"""The stroke corpus: a public benchmark of the scalpel over a few hundred blade paths.

Each case is one run of build/lacerta on the slab of prm/square_pull.prm (0.1 x 0.1 x
0.02 m, hanging on two cubes) with a generated parameter file that includes that scene
and overrides the mesh resolution, the tissue state and the scalpel. The blade, a
segment spanning the slab's thickness, follows one of these paths (world coordinates):

    polygon    closed polygons of 3 to 8 corners: plunge at a corner, run round, pass
               the start along the last side, lift out               expect 2 pieces
    circle     closed Catmull-Rom circles (`Closed path = true`), one turn and an
               eighth, the blade spanning the slab from the start    expect 2
    eight      figure-eights: a bowtie polygon and a Catmull-Rom lemniscate, which
               cross themselves in the middle                        expect 3
    through    straight and bent cuts entering at one side of the slab and leaving
               at the opposite one                                   expect 2
    partial    enter from the side and stop inside, or plunge, run and lift out
               (lines, an L, a U that stops 8 mm short of closing)   expect 1
    aligned    paths through mesh vertices and along mesh planes (coordinates from
               the slab and Mesh/Box/Repetitions): a grid square, a diamond through
               cell diagonals, cuts along the planes x = 0 and y = 2.5 cm, corner to
               corner through the slab's diagonal, a plunged partial cut   1 or 2
    graze      the blade on a side face, 0.5 mm outside it, touching only a corner,
               or touching only the top face                         expect 1
    multi      strokes that enter and leave several times: a comb (in and back out
               along the same line, three times; 1), a wavy through-cut crossing the
               mesh plane x = 0 five times (2), and a zigzag across the bottom edge
               whose three excursions each cut a triangular cap off it (4)

at the resolutions 60 (2x2x3 hexahedra, five tetrahedra each), 640 (8x8x2, the
scene's), 2160 (12x12x3) and 5120 (16x16x4), in three tissue states: `still` (no
gravity, the cubes hold still, as tests/closed_circle_still.prm.in), `sagging`
(gravity, the cubes hold still, as prm/square_hole.prm; the stroke starts at 0.1 s)
and `pulled` (the cubes pull as in prm/square_pull.prm; the stroke starts at 0.25 s,
while they pull), at blade speeds of 0.1, 0.5, 2 and 5 cells (x spacing of the case's
mesh) per time step (keyframe times are whole steps, so the blade is at every corner
at a step's time), and with every keyframe shifted by 0 or 1e-13, 1e-11, 1e-9 m in x
and y (cut_ensemble.shift()). After the stroke the run goes on for --settle seconds.

Criteria, per case:
  topology   the run exited 0, it left the expected number of major pieces (a piece
             is major if its rest volume is at least --major of the total, from the
             summary line `mesh components N, rest volumes (m^3) ...`) and no
             fragments (the other pieces). For enclosing paths the line also shows
             the inner pieces' rest volumes over enclosed area x thickness (`inner`).
  time step  substeps of the last step / substeps of the step before the first step
             that cut (or of step 1 if nothing was cut) is at most 1.5.
Also reported, from statistics.csv: the wall ratio (median step_wall_s/mesh_size over
the steps after the last cutting step over the same median before the first one; `-`
if there is no step on one side) and the cost per cut step (median cut_step_wall_ms,
the whole blade motion: first contact, update and the force model's update, over
the steps with cut_tets > 0). Runs are not in test mode (which zeroes the wall-time
columns; the pieces do not depend on it), unless --test-mode.

Usage:

    contrib/bench/stroke_corpus.py build/lacerta --jobs 2          # the whole corpus
    contrib/bench/stroke_corpus.py build/lacerta --list            # the cases
    contrib/bench/stroke_corpus.py build/lacerta --filter '^circle' --keep /tmp/c
    contrib/bench/stroke_corpus.py build/lacerta --subset ctest --jobs 2 \\
        --expect tests/stroke_corpus.expected                      # the CTest test
    contrib/bench/stroke_corpus.py build/lacerta --subset ctest --jobs 2 \\
        --record tests/stroke_corpus.expected                      # re-record it

--record FILE writes `id major fragments` per case (`crash` for both if the run
failed); --expect FILE compares every case run with its line there and prints the
differences. The exit code is 1 if a run failed (non-zero exit, timeout) or --expect
found a difference, else 0 (failing criteria alone do not fail the program).
Needs python3 only.
"""

import argparse
import collections
import concurrent.futures
import csv
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cut_ensemble import settings_block, shift  # noqa: E402

SOURCE_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                           "..", ".."))
BASE_SCENE = os.path.join(SOURCE_DIR, "prm", "square_pull.prm")

RESOLUTIONS = {60: (2, 2, 3), 640: (8, 8, 2), 2160: (12, 12, 3), 5120: (16, 16, 4)}
SPEEDS = (0.1, 0.5, 2, 5)                      # cells (x spacing) per time step
SHIFTS = {0: (0, 0.0), 1e-13: (9, 1e-13), 1e-11: (13, 1e-11), 1e-9: (17, 1e-9)}
STROKE_START = {"still": 0.01, "sagging": 0.1, "pulled": 0.25}   # s
PLUNGE_STEPS = 10                              # steps to plunge in and to lift out
HANDLE_X, HANDLE_Y = 0.0374, 0.0126            # the cubes: |x| >= 0.0374, |y| <= 0.0126
OVERSHOOT = 0.006                              # a closed polygon passes its start by this
TIME_STEP_RATIO_LIMIT = 1.5

HOLD_STILL = """subsection Constraints
  subsection left cube
    subsection Moving handle
      set Displacement = 0; 0; 0
    end
  end
  subsection right cube
    subsection Moving handle
      set Displacement = 0; 0; 0
    end
  end
end
"""
TISSUE_SETTINGS = {
    "still": "subsection Body forces\n  set List of body forces =\nend\n" + HOLD_STILL,
    "sagging": HOLD_STILL,
    "pulled": "",
}

Slab = collections.namedtuple("Slab", "lo hi dt")
Grid = collections.namedtuple("Grid", "slab reps hx hy")
# points: (x, y) of the blade; plunge: start above the slab at points[0] and lift out
# at the end (else the blade waits at points[0] and stays at the end); closed: the
# points are one period of a `Closed path` Catmull-Rom loop; areas: the inner pieces'
# expected rest areas; zspan: (tail z, head z) if not spanning the slab; inside: the
# points must lie in the footprint, off the cubes.
Path = collections.namedtuple(
    "Path", "name kind expect areas points plunge closed zspan inside",
    defaults=((), (), False, False, None, True))
Case = collections.namedtuple("Case", "id path res tissue speed shift")
Result = collections.namedtuple(
    "Result", "case exit volumes major fragments substep_ratio wall_ratio cost seconds "
    "message")


# ---------------------------------------------------------------- the scene's slab


def scene_entry(text, name):
    """The numbers of the first `set <name> = a, b, c` in the scene text."""
    match = re.search(rf"^\s*set\s+{re.escape(name)}\s*=\s*(.*)$", text, re.MULTILINE)
    if not match:
        sys.exit(f"{BASE_SCENE}: no '{name}' entry")
    return [float(v) for v in match.group(1).split(",")]


def read_slab(scene):
    """The slab's corners and the time step of the base scene."""
    text = open(scene).read()
    return Slab(scene_entry(text, "Lower corner"), scene_entry(text, "Upper corner"),
                scene_entry(text, "Time step")[0])


def grid_of(slab, res):
    """The box mesh of @p res tetrahedra: repetitions and vertex spacings."""
    reps = RESOLUTIONS[res]
    return Grid(slab, reps, (slab.hi[0] - slab.lo[0]) / reps[0],
                (slab.hi[1] - slab.lo[1]) / reps[1])


# ---------------------------------------------------------------- path geometry


def shoelace(points):
    """The area enclosed by the polygon @p points."""
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1)
                   in zip(points, points[1:] + points[:1]))) / 2


def regular_polygon(n, radius, center=(0.0, 0.0), phase_deg=90.0):
    """The corners of a regular n-gon, counter-clockwise from the angle @p phase_deg."""
    return [(center[0] + radius * math.cos(math.radians(phase_deg) + 2 * math.pi * k / n),
             center[1] + radius * math.sin(math.radians(phase_deg) + 2 * math.pi * k / n))
            for k in range(n)]


def past_start(corners):
    """Round the polygon and on past its start along the last side by OVERSHOOT."""
    (xl, yl), (x0, y0) = corners[-1], corners[0]
    length = math.hypot(x0 - xl, y0 - yl)
    return corners + [corners[0], (x0 + OVERSHOOT * (x0 - xl) / length,
                                   y0 + OVERSHOOT * (y0 - yl) / length)]


def closed_polygon(name, corners, kind="polygon", areas=None):
    """A polygon cut free: plunge at the first corner, round it, past the start."""
    return Path(name, kind, 2, areas or (shoelace(corners),), past_start(corners),
                plunge=True)


def circle(name, radius, center, n):
    """One period of a Catmull-Rom circle through n keyframes, from its bottom."""
    points = regular_polygon(n, radius, center, -90.0)
    return Path(name, "circle", 2, (math.pi * radius ** 2,), points, closed=True)


def lemniscate(name, a, b, n):
    """x = a cos(theta), y = b sin(theta) cos(theta): two lobes of 2ab/3 each."""
    points = [(a * math.cos(2 * math.pi * k / n),
               b * math.sin(2 * math.pi * k / n) * math.cos(2 * math.pi * k / n))
              for k in range(n)]
    return Path(name, "eight", 3, (2 * a * b / 3,) * 2, points, closed=True)


def bowtie(a, b):
    """The diagonals of a 2a x 2b rectangle and its left and right sides."""
    corners = [(-a, -b), (a, b), (a, -b), (-a, b)]
    return Path("eight-bowtie", "eight", 3, (a * b,) * 2, past_start(corners), plunge=True)


def caps(y_edge, outside, peak, xs):
    """A zigzag across the edge y = y_edge: out at xs[0], xs[2], ..., peaks at xs[1],
    xs[3], ...; returns the points and the areas of the triangles it cuts off."""
    points = [(x, outside if k % 2 == 0 else peak) for k, x in enumerate(xs)]
    areas = []
    for (xa, ya), (xp, yp), (xb, yb) in zip(points[0::2], points[1::2], points[2::2]):
        cross = [(x0 + (x1 - x0) * (y_edge - y0) / (y1 - y0), y_edge)
                 for (x0, y0), (x1, y1) in (((xa, ya), (xp, yp)), ((xb, yb), (xp, yp)))]
        areas.append(shoelace([cross[0], (xp, yp), cross[1]]))
    return points, tuple(areas)


def nearest_line(h, target):
    """The mesh plane (multiple of h from the centre 0) nearest to @p target."""
    return round(target / h) * h


# ---------------------------------------------------------------- the catalogue


def closed_paths():
    """Polygons of 3 to 8 corners, circles and figure-eights."""
    return [
        closed_polygon("poly3", regular_polygon(3, 0.026, (0.0, -0.004))),
        closed_polygon("poly4", [(-0.02, -0.02), (0.02, -0.02), (0.02, 0.02), (-0.02, 0.02)]),
        closed_polygon("poly4-diamond", regular_polygon(4, 0.026, (0.0, 0.0), 0.0)),
        closed_polygon("poly4-small", [(0.0, 0.01), (0.02, 0.01), (0.02, 0.03), (0.0, 0.03)]),
        closed_polygon("poly5", regular_polygon(5, 0.024)),
        closed_polygon("poly6", regular_polygon(6, 0.024, phase_deg=15.0)),
        closed_polygon("poly7", regular_polygon(7, 0.025, phase_deg=10.0)),
        closed_polygon("poly8", regular_polygon(8, 0.025, phase_deg=22.5)),
        circle("circle-r20", 0.02, (0.0, 0.0), 16),
        circle("circle-r15", 0.015, (0.008, 0.012), 16),
        circle("circle-r25", 0.025, (0.0, 0.0), 24),
        bowtie(0.025, 0.02),
        lemniscate("eight-lemniscate", 0.028, 0.045, 24),
    ]


def open_paths():
    """Through-cuts, partial strokes, grazing strokes and multiple entries."""
    cap_points, cap_areas = caps(-0.05, -0.058, -0.025,
                                 [-0.045, -0.03, -0.015, 0.0, 0.015, 0.03, 0.045])
    wave = [(0.006 * (-1) ** k if 0 < k < 8 else 0.0, -0.06 + 0.015 * k) for k in range(9)]
    comb = []
    for x in (-0.03, 0.0, 0.03):
        comb += [(x, -0.06), (x, -0.03), (x, -0.06)]
    return [
        Path("through-x", "through", 2, points=[(0.004, -0.06), (0.004, 0.06)]),
        Path("through-y", "through", 2, points=[(-0.06, 0.027), (0.06, 0.027)]),
        Path("through-diag", "through", 2, points=[(-0.06, -0.03), (0.06, 0.03)]),
        Path("through-bent", "through", 2,
             points=[(0.0, -0.06), (0.01, -0.01), (-0.01, 0.02), (0.0, 0.06)]),
        Path("partial-side", "partial", 1, points=[(0.005, -0.06), (0.005, 0.0)]),
        Path("partial-diag", "partial", 1, points=[(0.06, -0.045), (0.02, -0.02)]),
        Path("partial-line", "partial", 1, points=[(-0.02, 0.0), (0.02, 0.005)], plunge=True),
        Path("partial-L", "partial", 1, plunge=True,
             points=[(-0.02, -0.02), (0.02, -0.02), (0.02, 0.02)]),
        Path("partial-U", "partial", 1, plunge=True,
             points=[(-0.02, -0.02), (0.02, -0.02), (0.02, 0.02), (-0.02, 0.02),
                     (-0.02, -0.012)]),
        Path("graze-face", "graze", 1, points=[(-0.06, -0.05), (0.06, -0.05)]),
        Path("graze-near", "graze", 1, points=[(-0.06, -0.0505), (0.06, -0.0505)]),
        Path("graze-corner", "graze", 1, points=[(0.04, -0.06), (0.06, -0.04)]),
        Path("graze-top", "graze", 1, points=[(-0.03, 0.0), (0.03, 0.0)], zspan="top"),
        Path("multi-comb", "multi", 1, points=comb),
        Path("multi-wave-through", "multi", 2, points=wave),
        Path("multi-caps", "multi", 1 + len(cap_areas), cap_areas, cap_points),
    ]


def aligned_paths(grid):
    """Paths through the vertices and along the planes of @p grid's box mesh."""
    hx, hy = grid.hx, grid.hy
    kx, ky = round(0.025 / hx), round(0.025 / hy)
    paths = [
        Path("grid-through-x0", "aligned", 2, points=[(0.0, -0.06), (0.0, 0.06)]),
        Path("grid-diagonal", "aligned", 2, points=[(-0.06, -0.06), (0.06, 0.06)]),
    ]
    if kx < 1 or ky < 1:
        return paths     # the 2 x 2 grid has no interior plane but x = 0 and y = 0
    x, y = kx * hx, ky * hy
    square = [(-x, -y), (x, -y), (x, y), (-x, y)]
    diamond = [(0.0, -y), (x, 0.0), (0.0, y), (-x, 0.0)]
    return paths + [
        closed_polygon("grid-square", square, kind="aligned"),
        closed_polygon("grid-diamond", diamond, kind="aligned"),
        Path("grid-through-y", "aligned", 2,
             points=[(-0.06, nearest_line(hy, 0.025)), (0.06, nearest_line(hy, 0.025))]),
        Path("grid-partial", "aligned", 1, points=[(0.0, -y), (0.0, y)], plunge=True),
    ]


def inside_footprint(point, slab, margin=0.003):
    """@p point lies in the slab's footprint by @p margin and off the two cubes."""
    x, y = point
    return (slab.lo[0] + margin <= x <= slab.hi[0] - margin
            and slab.lo[1] + margin <= y <= slab.hi[1] - margin
            and not (abs(x) >= HANDLE_X - margin and abs(y) <= HANDLE_Y + margin))


def paths_for(grid):
    """Every path on @p grid, checked to stay in the footprint where it must."""
    paths = closed_paths() + open_paths() + aligned_paths(grid)
    for path in paths:
        inner = path.points if (path.plunge or path.closed) else ()
        if not all(inside_footprint(p, grid.slab) for p in inner):
            sys.exit(f"path {path.name} leaves the slab's footprint or meets a cube")
    return paths


# ---------------------------------------------------------------- cases


def case_id(path, res, tissue, speed, delta):
    return f"{path.name}.{res}.{tissue}.v{speed:g}.s{delta:g}"


def make_cases(slab):
    """The corpus: every path in three tissues, four speeds and at 60 tetrahedra;
    shifted paths where rounding ties may decide; a few paths on the finer meshes."""
    cases = {}

    def add(path, res, tissue, speed=0.5, delta=0):
        cid = case_id(path, res, tissue, speed, delta)
        cases[cid] = Case(cid, path, res, tissue, speed, delta)

    for path in paths_for(grid_of(slab, 640)):
        for tissue in TISSUE_SETTINGS:
            add(path, 640, tissue)
        for speed in (0.1, 2, 5):
            add(path, 640, "still", speed)
        deltas = (1e-13, 1e-11, 1e-9) if path.kind in ("aligned", "graze") else (1e-13,)
        for delta in deltas:
            add(path, 640, "sagging", delta=delta)
    for path in paths_for(grid_of(slab, 60)):
        add(path, 60, "still")
        add(path, 60, "sagging")
    fine = ("poly4", "poly7", "circle-r20", "eight-bowtie", "through-x", "partial-U",
            "grid-square", "grid-diagonal", "multi-caps")
    for path in paths_for(grid_of(slab, 2160)):
        if path.name in fine:
            add(path, 2160, "still")
    for path in paths_for(grid_of(slab, 5120)):
        if path.name in fine[:4]:
            add(path, 5120, "still")
    return list(cases.values())


# The CTest regression subset: fast cases (60 and 640 tetrahedra), every family.
CTEST_SUBSET = (
    "poly3.60.still.v0.5.s0",
    "poly4.640.still.v0.5.s0",
    "poly6.640.sagging.v0.5.s1e-13",
    "poly8.640.still.v2.s0",
    "circle-r20.640.still.v0.5.s0",
    "circle-r15.60.sagging.v0.5.s0",
    "eight-bowtie.640.still.v0.5.s0",
    "eight-lemniscate.640.still.v2.s0",
    "through-x.640.pulled.v0.5.s0",
    "through-diag.60.still.v0.5.s0",
    "partial-side.640.sagging.v0.5.s0",
    "partial-U.640.still.v0.5.s0",
    "grid-square.640.still.v0.5.s0",
    "grid-diagonal.60.still.v0.5.s0",
    "grid-through-x0.640.sagging.v0.5.s1e-09",
    "graze-face.640.still.v0.5.s0",
    "graze-corner.640.still.v0.5.s0",
    "graze-top.640.still.v0.5.s0",
    "multi-comb.640.still.v0.5.s0",
    "multi-wave-through.640.sagging.v0.5.s0",
    "multi-caps.640.still.v0.5.s0",
)


# ---------------------------------------------------------------- keyframes


def blade_span(slab, zspan):
    """(tail z, head z) while cutting, and while above the slab."""
    top, bottom = slab.hi[2], slab.lo[2]
    above = (top + 0.04, top + 0.02)
    if zspan == "top":
        return (top + 0.03, top), above
    # Below the slab by more than the coarsest slab sags (2.5 cm at 60 tetrahedra
    # by 0.1 s): the blade spans the tissue wherever it cuts.
    return (top + 0.01, bottom - 0.05), above


def steps_for(a, b, step_length):
    """Whole steps to move from @p a to @p b at @p step_length per step (at least 1)."""
    return max(1, round(math.hypot(b[0] - a[0], b[1] - a[1]) / step_length))


def timed_points(case, grid):
    """[(t, (x, y), z span)] of the stroke and the time its blade stops moving."""
    path, dt = case.path, grid.slab.dt
    span, above = blade_span(grid.slab, path.zspan)
    step_length = case.speed * grid.hx
    steps = round(STROKE_START[case.tissue] / dt)
    if path.closed:
        chord = max(math.dist(a, b) for a, b in zip(path.points, path.points[1:]))
        per = steps_for((0, 0), (chord, 0), step_length)
        frames = [((steps + per * k) * dt, p, span) for k, p in enumerate(path.points)]
        return frames, (steps + math.ceil(1.125 * len(path.points)) * per) * dt
    frames = []
    if path.plunge:
        frames.append(((steps - PLUNGE_STEPS) * dt, path.points[0], above))
    frames.append((steps * dt, path.points[0], span))
    for a, b in zip(path.points, path.points[1:]):
        steps += steps_for(a, b, step_length)
        frames.append((steps * dt, b, span))
    if path.plunge:
        steps += PLUNGE_STEPS
        frames.append((steps * dt, path.points[-1], above))
    return frames, steps * dt


def keyframes_text(frames, case):
    """The `Keyframes` value, every keyframe shifted by the case's (dx, dy)."""
    dx, dy = shift(*SHIFTS[case.shift])
    return "; \\\n    ".join(
        ", ".join(repr(v) for v in (round(t, 12), x + dx, y + dy, zt, x + dx, y + dy, zh))
        for t, (x, y), (zt, zh) in frames)


def prm_text(case, grid, work, args):
    """The parameter file of @p case."""
    frames, stop = timed_points(case, grid)
    end = stop if case.path.closed else stop + args.settle
    reps = ", ".join(str(r) for r in grid.reps)
    lines = [f"include {BASE_SCENE}",
             f"set End time = {round(end, 12)!r}",
             f"set Test mode = {'true' if args.test_mode else 'false'}",
             f"set Output directory = {os.path.join(work, case.id)}",
             f"subsection Mesh\nsubsection Box\nset Repetitions = {reps}\nend\nend",
             TISSUE_SETTINGS[case.tissue],
             "subsection Tool\nset Type = scalpel\nsubsection Scalpel",
             f"set Interpolation = {'catmull-rom' if case.path.closed else 'linear'}",
             f"set Closed path = {'true' if case.path.closed else 'false'}",
             f"set Keyframes = {keyframes_text(frames, case)}",
             "end\nend",
             "subsection Postprocess\nset List of postprocessors = statistics\nend"]
    lines += [settings_block(a) for a in args.set]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- running and measuring


def read_statistics(directory):
    """statistics.csv as a list of rows of floats (without the initial row 0)."""
    with open(os.path.join(directory, "statistics.csv")) as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return [r for r in rows if r["step"] > 0]


def substep_ratio(rows):
    """Substeps of the last step over those of the step before the first cut."""
    first = next((k for k, r in enumerate(rows) if r["cut_tets"] > 0), 1)
    return rows[-1]["substeps"] / rows[max(first - 1, 0)]["substeps"]


def wall_ratio(rows):
    """Median step_wall_s/mesh_size after the last cut over the median before the first."""
    cut = [k for k, r in enumerate(rows) if r["cut_tets"] > 0]
    if not cut:
        return None
    before = [r["step_wall_s"] / r["mesh_size"] for r in rows[:cut[0]]]
    after = [r["step_wall_s"] / r["mesh_size"] for r in rows[cut[-1] + 1:]]
    if not before or not after or statistics.median(before) <= 0:
        return None
    return statistics.median(after) / statistics.median(before)


def cut_cost(rows):
    """Median cost of a cut step over the steps that cut: cut_step_wall_ms (the whole
    blade motion: first contact, update, force model), update_wall_ms from binaries
    that do not write it."""
    column = "cut_step_wall_ms" if rows and "cut_step_wall_ms" in rows[0] else "update_wall_ms"
    costs = [r[column] for r in rows if r["cut_tets"] > 0]
    return statistics.median(costs) if any(costs) else None     # all 0 in test mode


def summary_volumes(stdout):
    """The rest volumes of the summary line, or None."""
    match = re.search(r"mesh components (\d+), rest volumes \(m\^3\)([-0-9.e+ ]*)", stdout)
    return sorted(float(v) for v in match.group(2).split()) if match else None


def run_case(case, lacerta, grid, work, args):
    """Runs @p case and measures it."""
    prm = os.path.join(work, case.id + ".prm")
    with open(prm, "w") as out:
        out.write(prm_text(case, grid, work, args))
    start = time.monotonic()
    try:
        done = subprocess.run([lacerta, prm], capture_output=True, text=True, cwd=work,
                              timeout=args.timeout)
        code, output = done.returncode, done.stdout + done.stderr
    except subprocess.TimeoutExpired:
        code, output = "timeout", f"timeout after {args.timeout} s"
    seconds = time.monotonic() - start
    volumes = summary_volumes(output) if code == 0 else None
    if volumes is None:
        lines = output.strip().splitlines()
        return Result(case, code if code != 0 else "no summary", None, None, None, None,
                      None, None, seconds, lines[-1] if lines else "")
    major = [v for v in volumes if v >= args.major * sum(volumes)]
    rows = read_statistics(os.path.join(work, case.id))
    return Result(case, 0, volumes, major, len(volumes) - len(major), substep_ratio(rows),
                  wall_ratio(rows), cut_cost(rows), seconds, "")


# ---------------------------------------------------------------- reporting


def topology_ok(r):
    return r.exit == 0 and len(r.major) == r.case.path.expect and r.fragments == 0


def time_ok(r):
    return r.exit == 0 and r.substep_ratio <= TIME_STEP_RATIO_LIMIT


def inner_text(r, thickness):
    """The inner pieces' volumes over enclosed area x thickness, or '-'."""
    areas = r.case.path.areas
    if not areas or r.major is None or len(r.major) < 2:
        return "-"
    got = r.major[:min(len(areas), len(r.major) - 1)]
    return ",".join(f"{v / (a * thickness):.3f}" for v, a in zip(got, sorted(areas)))


def number(value, form):
    return "-" if value is None else format(value, form)


HEADER = (f"{'case':44s} {'kind':8s} {'res':>5s} {'tissue':8s} {'speed':>5s} "
          f"{'shift':>6s} {'exp/got':>7s} {'frag':>4s} {'subst':>6s} {'wall':>6s} "
          f"{'cost_ms':>8s} {'run_s':>6s}  {'inner':12s} verdict")


def case_line(r, thickness):
    c = r.case
    got = "-" if r.major is None else str(len(r.major))
    verdict = ("CRASH " + str(r.exit) + ": " + r.message if r.exit != 0 else
               ("ok" if topology_ok(r) else "TOPOLOGY")
               + ("" if time_ok(r) else " TIME-STEP"))
    return (f"{c.id:44s} {c.path.kind:8s} {c.res:5d} {c.tissue:8s} {c.speed:5g} "
            f"{c.shift:>6g} {c.path.expect:>3d}/{got:<3s} {number(r.fragments, 'd'):>4s} "
            f"{number(r.substep_ratio, '.3g'):>6s} {number(r.wall_ratio, '.3g'):>6s} "
            f"{number(r.cost, '.3g'):>8s} {r.seconds:6.1f}  {inner_text(r, thickness):12s} "
            f"{verdict}")


def rate(n, total):
    return f"{n}/{total} ({100 * n / total:.1f}%)" if total else "0/0"


def print_summary(results):
    ran = [r for r in results if r.exit == 0]
    costs = [r.cost for r in ran if r.cost is not None]
    walls = [r.wall_ratio for r in ran if r.wall_ratio is not None]
    ratios = [r.substep_ratio for r in ran]
    print(f"\n{len(results)} cases, {len(results) - len(ran)} failed to run")
    print(f"topology pass rate: {rate(sum(map(topology_ok, ran)), len(results))}")
    print(f"time-step pass rate (substep ratio <= {TIME_STEP_RATIO_LIMIT}): "
          f"{rate(sum(map(time_ok, ran)), len(results))}")
    print(f"total fragments: {sum(r.fragments for r in ran)} "
          f"(in {sum(1 for r in ran if r.fragments)} cases)")
    if ratios:
        print(f"substep ratio: median {statistics.median(ratios):.3g}, max {max(ratios):.3g}")
    if walls:
        print(f"wall ratio: median {statistics.median(walls):.3g}, max {max(walls):.3g} "
              f"({len(walls)} cases with steps before and after the cut)")
    if costs:
        print(f"cost per cut step (ms): median {statistics.median(costs):.3g}, "
              f"max {max(costs):.3g}")
    print("failing topology: " + " ".join(r.case.id for r in ran if not topology_ok(r)))
    print("failing time step: " + " ".join(r.case.id for r in ran if not time_ok(r)))
    print("failed to run: " + " ".join(r.case.id for r in results if r.exit != 0))


def outcome(r):
    return ("crash", "crash") if r.exit != 0 else (str(len(r.major)), str(r.fragments))


def record(results, path):
    with open(path, "w") as out:
        out.write("# stroke_corpus.py: case, major pieces, fragments\n")
        for r in results:
            out.write(f"{r.case.id} {' '.join(outcome(r))}\n")


def expect(results, path):
    """Compares with the recorded outcomes; returns the number of differences."""
    recorded = {}
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            cid, major, fragments = line.split()
            recorded[cid] = (major, fragments)
    differences = 0
    for r in results:
        want = recorded.get(r.case.id)
        if want != outcome(r):
            differences += 1
            print(f"expect: {r.case.id}: recorded "
                  + (f"{want[0]} major, {want[1]} fragments" if want else "nothing")
                  + f", got {outcome(r)[0]} major, {outcome(r)[1]} fragments")
    print(f"expect: {differences} differences from {path} in {len(results)} cases")
    return differences


# ---------------------------------------------------------------- main


def parse_arguments():
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="See the module docstring (head of this file) for the paths and criteria.")
    parser.add_argument("lacerta", help="the lacerta executable")
    parser.add_argument("--jobs", type=int, default=1, help="runs at once (default 1)")
    parser.add_argument("--filter", metavar="REGEX", help="only cases whose id matches")
    parser.add_argument("--subset", choices=["ctest"], help="the CTest regression subset")
    parser.add_argument("--list", action="store_true", help="list the cases and stop")
    parser.add_argument("--keep", metavar="DIR", help="keep parameter files and output here")
    parser.add_argument("--record", metavar="FILE", help="write `id major fragments`")
    parser.add_argument("--expect", metavar="FILE", help="compare with a --record file")
    parser.add_argument("--major", type=float, default=0.01,
                        help="volume fraction from which a piece is major (default 0.01)")
    parser.add_argument("--settle", type=float, default=0.025,
                        help="seconds run after the stroke (default 0.025)")
    parser.add_argument("--timeout", type=float, default=900, help="seconds per run")
    parser.add_argument("--test-mode", action="store_true",
                        help="run in test mode (wall ratio and cost become '-')")
    parser.add_argument("--set", action="append", default=[],
                        help="an extra setting 'Subsection/Entry=value' (repeatable)")
    args = parser.parse_args()
    if args.jobs < 1 or not 0 < args.major < 1 or args.settle < 0:
        sys.exit("--jobs must be positive, --major in (0, 1), --settle >= 0")
    return args


def select_cases(cases, args):
    if args.subset == "ctest":
        by_id = {c.id: c for c in cases}
        cases = [by_id[cid] for cid in CTEST_SUBSET]
    if args.filter:
        cases = [c for c in cases if re.search(args.filter, c.id)]
    return cases


def estimated_cost(case, slab):
    """Tetrahedra x steps, to start the longest runs first."""
    return case.res * timed_points(case, grid_of(slab, case.res))[1] / slab.dt


def run_all(cases, slab, args, work):
    lacerta = os.path.abspath(args.lacerta)
    order = sorted(cases, key=lambda c: -estimated_cost(c, slab))
    results = {}
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = {pool.submit(run_case, c, lacerta, grid_of(slab, c.res), work, args): c
                   for c in order}
        for k, future in enumerate(concurrent.futures.as_completed(futures), 1):
            r = future.result()
            results[r.case.id] = r
            print(f"[{k}/{len(cases)}] {r.case.id} {r.seconds:.1f} s", file=sys.stderr,
                  flush=True)
    return [results[c.id] for c in cases]


def main():
    args = parse_arguments()
    slab = read_slab(BASE_SCENE)
    cases = select_cases(make_cases(slab), args)
    if args.list:
        for c in cases:
            print(f"{c.id:44s} {c.path.kind:8s} expect {c.path.expect}")
        print(f"{len(cases)} cases")
        return 0
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="stroke_corpus") as scratch:
        results = run_all(cases, slab, args, os.path.abspath(args.keep or scratch))
    print(HEADER)
    thickness = slab.hi[2] - slab.lo[2]
    for r in results:
        print(case_line(r, thickness))
    print_summary(results)
    if args.record:
        record(results, args.record)
    differences = expect(results, args.expect) if args.expect else 0
    return 1 if differences or any(r.exit != 0 for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
