#!/usr/bin/env python3
"""How robust a scalpel scene's outcome is: runs the scene several times with the blade's
keyframes shifted by a tiny, different amount each time, and reports the pieces each
run leaves.

A shift of 1e-13 m changes nothing a user could see, only the last bits of the blade's
positions; a cut whose outcome (number of pieces, the piece it should cut free) changes
with it rests on rounding ties (doc/cutting.md, "Limits"). Usage:

    contrib/bench/cut_ensemble.py build/lacerta prm/square_hole.prm
    contrib/bench/cut_ensemble.py build/lacerta prm/square_hole.prm --runs 20 \
        --set 'Cut/Snap fraction=0.1' --end-time 1.1

Run 0 is the scene unchanged. Runs 1-4 shift every keyframe's tail and head by 1-4
delta along x, runs 5-8 by 1-4 delta along -x, runs 9-16 repeat that with delta along
y as well, runs 17-24 with 2 delta along y, and so on (shift()). Each run is the
scene in test mode with the statistics postprocessor only, in a temporary directory
(--keep DIR keeps the parameter files, run<k>.prm, to rerun one).
A piece is "major" if it holds at least --major of the total rest volume; the others
are fragments. Needs python3 only.
"""

import argparse
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile


def read_keyframes(path):
    """The value of the scene file's `set Keyframes =` entry (continuation lines joined)."""
    text = open(path).read().replace("\\\n", " ")
    match = re.search(r"^\s*set\s+Keyframes\s*=\s*(.*)$", text, re.MULTILINE)
    if not match:
        sys.exit(f"{path}: no 'set Keyframes' entry (only scalpel scenes can be perturbed)")
    frames = []
    for frame in match.group(1).split(";"):
        values = [float(v) for v in frame.split(",") if v.strip()]
        if len(values) != 7:
            sys.exit(f"{path}: a keyframe has {len(values)} values instead of 7: {frame!r}")
        frames.append(values)
    return frames


def shift(run, delta):
    """The (dx, dy) of run number @p run: 0 for run 0, distinct multiples of delta."""
    if run == 0:
        return 0.0, 0.0
    sign = 1 if (run - 1) // 4 % 2 == 0 else -1
    return sign * ((run - 1) % 4 + 1) * delta, ((run - 1) // 8) * delta


def settings_block(assignment):
    """`Sub/section/Entry=value` as nested prm subsections."""
    path, _, value = assignment.partition("=")
    parts = [p.strip() for p in path.split("/")]
    if not value.strip() or not parts[-1]:
        sys.exit(f"--set {assignment!r}: expected 'Subsection/Entry=value'")
    lines = [f"subsection {p}" for p in parts[:-1]]
    lines.append(f"set {parts[-1]} = {value.strip()}")
    lines += ["end"] * (len(parts) - 1)
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("lacerta", help="the lacerta executable")
    parser.add_argument("scene", help="a scene with a scalpel (subsection Tool/Scalpel)")
    parser.add_argument("--runs", type=int, default=10, help="number of runs (default 10)")
    parser.add_argument("--delta", type=float, default=1e-13,
                        help="shift step in metres (default 1e-13)")
    parser.add_argument("--end-time", type=float, help="override the scene's End time")
    parser.add_argument("--major", type=float, default=0.01,
                        help="volume fraction from which a piece is major (default 0.01)")
    parser.add_argument("--keep", metavar="DIR",
                        help="write the runs' parameter files and output into DIR and keep them")
    parser.add_argument("--jobs", type=int, default=1, help="runs at once (default 1)")
    parser.add_argument("--set", action="append", default=[],
                        help="an extra setting 'Subsection/Entry=value' (repeatable)")
    args = parser.parse_args()
    if args.jobs < 1 or args.runs < 1 or not args.delta > 0 or not 0 < args.major < 1:
        sys.exit("--runs and --jobs must be positive, --delta positive, --major in (0, 1)")

    scene = os.path.abspath(args.scene)
    lacerta = os.path.abspath(args.lacerta)
    frames = read_keyframes(scene)
    outcomes = {}
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cut_ensemble") as scratch:
        work = os.path.abspath(args.keep) if args.keep else scratch
        prms = []
        for run in range(args.runs):
            dx, dy = shift(run, args.delta)
            shifted = [[f[0], f[1] + dx, f[2] + dy, f[3], f[4] + dx, f[5] + dy, f[6]]
                       for f in frames]
            keyframes = "; \\\n    ".join(", ".join(repr(v) for v in f) for f in shifted)
            prm = os.path.join(work, f"run{run}.prm")
            with open(prm, "w") as out:
                out.write(f"include {scene}\n")
                out.write("subsection Tool\nsubsection Scalpel\n")
                out.write(f"set Keyframes = {keyframes}\nend\nend\n")
                out.write("set Test mode = true\n")
                out.write(f"set Output directory = {os.path.join(work, f'out{run}')}\n")
                out.write("subsection Postprocess\nset List of postprocessors = statistics\n"
                          "end\n")
                if args.end_time is not None:
                    out.write(f"set End time = {args.end_time!r}\n")
                for assignment in args.set:
                    out.write(settings_block(assignment) + "\n")
            prms.append(prm)
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            results = list(pool.map(
                lambda prm: subprocess.run([lacerta, prm], capture_output=True, text=True),
                prms))
        for run, result in enumerate(results):
            dx, dy = shift(run, args.delta)
            summary = re.search(r"mesh components (\d+), rest volumes \(m\^3\)([-0-9.e+ ]*)",
                                result.stdout)
            if result.returncode != 0 or not summary:
                message = (result.stdout + result.stderr).strip().splitlines()
                outcomes[run] = None
                print(f"run {run:3d} (dx {dx:+.1e}, dy {dy:+.1e}): failed (exit "
                      f"{result.returncode}): {message[-1] if message else ''}")
                continue
            volumes = sorted(float(v) for v in summary.group(2).split())
            total = sum(volumes)
            major = [v for v in volumes if v >= args.major * total]
            outcomes[run] = (len(volumes), major)
            print(f"run {run:3d} (dx {dx:+.1e}, dy {dy:+.1e}): {len(volumes)} components, "
                  f"{len(major)} major ({' '.join(f'{v:.4g}' for v in major)} m^3), "
                  f"{len(volumes) - len(major)} fragments")
    done = [o for o in outcomes.values() if o is not None]
    counts = {}
    for n_components, major in done:
        key = (len(major), n_components - len(major))
        counts[key] = counts.get(key, 0) + 1
    print(f"{len(done)} of {args.runs} runs finished; outcomes (major pieces, fragments): "
          + ", ".join(f"{k[0]} major + {k[1]} fragments: {n}" for k, n in sorted(counts.items())))
    clean = sum(1 for n, major in done if n == len(major))
    print(f"runs without fragments: {clean} of {args.runs}")


if __name__ == "__main__":
    main()
