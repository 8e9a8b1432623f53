#!/usr/bin/env python3
"""check_figures.py: reruns the cheap measured files behind docs/ and fails
when a number moved beyond what the drops' noise allows (make check-full).

    check_figures.py [-b POSEDROP] FILE...

Each FILE is a CSV of posedrop rows (pose,...,n,count,p,...) after '#'
lines, the first naming the command that made it ("# posedrop ARGS...",
part paths relative to the repository). The
command is run again, without its output files, and each pose's p
compared with the file's (rows matched by their resting normal, not their
number): moved when
|p_new - p_old| > z sqrt(v_old + v_new), v = p (1 - p) / n, z the two-sided
5% point Bonferroni-shared by all the numbers checked (so that a rerun of
unchanged physics fails 5% of the time at most; the same code gives the
same bytes and never fails). Standard library only.
"""
import csv
import io
import math
import os
import shlex
import subprocess
import sys
from statistics import NormalDist


def read(text):
    lines = text.splitlines()
    heads = [l[2:] for l in lines if l.startswith("# ")]
    return heads, list(csv.DictReader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))


def normal(row):
    """A pose's resting normal, to 1e-6 (the CSV's 10 digits, well clear of
    round-off): what identifies a pose whatever its number."""
    return tuple(round(float(row[c]), 6) + 0.0 for c in ("nx", "ny", "nz"))


def main():
    args = sys.argv[1:]
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    binary = os.path.join(here, "build/opt/posedrop")
    if args[:1] == ["-b"]:
        binary, args = args[1], args[2:]
    pairs = []
    for path in args:
        with open(path) as f:
            heads, old = read(f.read())
        cmd = shlex.split(heads[0])
        if cmd[0] != "posedrop":
            sys.exit(f"check_figures.py: {path}: its first line names no posedrop command")
        # Its output files (--sensitivity, the pictures) are left as they are.
        outputs = {"--sensitivity", "--trials", "--svg", "--chart", "--sphere", "--report",
                   "--transitions"}
        kept = []
        for a in cmd[1:]:
            if kept and kept[-1] in outputs:
                kept.pop()
                continue
            kept.append(a)
        cmd = [binary] + [os.path.join(here, a) if a.startswith("parts/") else a for a in kept]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"check_figures.py: {path}: {' '.join(cmd)} failed: {run.stderr.strip()}")
        _, new = read(run.stdout)
        if len(old) != len(new):
            sys.exit(f"check_figures.py: {path}: {len(new)} rows now, {len(old)} in the file")
        # A row is the same pose (class) when its resting normal is: the
        # numbering follows the probabilities and may change while no
        # number moves (classes numbered most probable first, for one).
        by_normal = {normal(b): b for b in new}
        for a in old:
            b = by_normal.get(normal(a))
            if b is None:
                sys.exit(f"check_figures.py: {path}: pose {a['pose']}'s normal "
                         f"({a['nx']}, {a['ny']}, {a['nz']}) is no pose's now")
            pairs.append((path, a["pose"], float(a["p"]), float(a["n"]), float(b["p"]),
                          float(b["n"])))
    z = NormalDist().inv_cdf(1 - 0.05 / (2 * max(len(pairs), 1)))
    moved = 0
    for path, pose, p0, n0, p1, n1 in pairs:
        sd = math.sqrt(max(p0 * (1 - p0) / n0 + p1 * (1 - p1) / n1, 1e-12))
        if abs(p1 - p0) > z * sd:
            moved += 1
            print(f"{path}: pose {pose}: p {p0:.4f} in the file, {p1:.4f} now: moved by "
                  f"{abs(p1 - p0) / sd:.1f} standard errors (limit {z:.2f}): rerun "
                  f"make figures and update the docs' words", file=sys.stderr)
    print(f"check_figures.py: {len(pairs)} numbers of {len(args)} files, {moved} moved")
    sys.exit(1 if moved else 0)


if __name__ == "__main__":
    main()
