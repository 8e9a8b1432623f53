#!/usr/bin/env python3
"""check_figures.py: reruns the cheap measured files behind docs/ and fails
when a number moved beyond what the drops' noise allows (make check-full).

    check_figures.py [-b POSEDROP] [--self-test] FILE...

Each FILE is a CSV of posedrop rows (pose,...,n,count,p,...) after '#'
lines, the first naming the command that made it ("# posedrop ARGS...",
part paths relative to the repository, other files to FILE's folder). The
command is run again in FILE's folder, without its output files and the
pictures' --measured, and each pose's p compared with the file's (rows
matched by their resting normal, not their number): moved when
|p_new - p_old| > z sqrt(v_old + v_new), z the two-sided 5% point
Bonferroni-shared by all the numbers checked (so that a rerun of unchanged
physics fails 5% of the time at most; the same code gives the same bytes
and never fails; --self-test first checks that a moved number fails and
a renumbered table passes, on controls made from a run of its own). v is the row's own 95% interval's half-width over 1.96,
squared (ci_lo, ci_hi: Wilson for drops from uniform orientations, the
resampled interval of --initial stationary, whose drops are not
independent), or p (1 - p) / n for a file without them. Standard library
only.
"""
import csv
import io
import math
import os
import shlex
import subprocess
import sys
import tempfile
from statistics import NormalDist


def read(text):
    lines = text.splitlines()
    heads = [l[2:] for l in lines if l.startswith("# ")]
    return heads, list(csv.DictReader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))


def normal(row):
    """A pose's resting normal, to 1e-6 (the CSV's 10 digits, well clear of
    round-off): what identifies a pose whatever its number."""
    return tuple(round(float(row[c]), 6) + 0.0 for c in ("nx", "ny", "nz"))


def variance(row):
    """The variance of a row's p: from its own 95% interval when it has one."""
    if row.get("ci_lo") not in (None, "") and row.get("ci_hi") not in (None, ""):
        return ((float(row["ci_hi"]) - float(row["ci_lo"])) / (2 * 1.959964)) ** 2
    p = float(row["p"])
    return p * (1 - p) / float(row["n"])


def check(binary, here, paths, quiet=False):
    """Reruns each file's command; returns (numbers compared, numbers moved)."""
    pairs = []
    for path in paths:
        with open(path) as f:
            heads, old = read(f.read())
        cmd = shlex.split(heads[0]) if heads else []
        if cmd[:1] != ["posedrop"]:
            sys.exit(f"check_figures.py: {path}: its first line names no posedrop command")
        # Its output files (--sensitivity, the pictures) are left as they are,
        # and so the measured distribution the pictures show.
        outputs = {"--sensitivity", "--trials", "--svg", "--chart", "--sphere", "--report",
                   "--transitions", "--measured"}
        kept = []
        for a in cmd[1:]:
            if kept and kept[-1] in outputs:
                kept.pop()
                continue
            kept.append(a)
        cmd = [binary] + [os.path.join(here, a) if a.startswith("parts/") else a for a in kept]
        run = subprocess.run(cmd, capture_output=True, text=True,
                             cwd=os.path.dirname(os.path.abspath(path)))
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
            pairs.append((path, a["pose"], float(a["p"]), variance(a), float(b["p"]),
                          variance(b)))
    z = NormalDist().inv_cdf(1 - 0.05 / (2 * max(len(pairs), 1)))
    moved = 0
    for path, pose, p0, v0, p1, v1 in pairs:
        sd = math.sqrt(max(v0 + v1, 1e-12))
        if abs(p1 - p0) > z * sd:
            moved += 1
            if not quiet:
                print(f"{path}: pose {pose}: p {p0:.4f} in the file, {p1:.4f} now: moved by "
                      f"{abs(p1 - p0) / sd:.1f} standard errors (limit {z:.2f}): rerun "
                      f"make figures and update the docs' words", file=sys.stderr)
    return len(pairs), moved


def self_test(binary, here):
    """The check's own controls, on a cheap run (1000 drops of the hex nut,
    a fraction of a second): the file as written passes, and so does the
    file with its rows renumbered; the file with one p moved by 8 standard
    errors of the comparison fails, and with it moved by 1 passes."""
    cmd = "posedrop -n 1000 --group --units mm parts/hexnut.obj"
    run = subprocess.run([binary] + [os.path.join(here, a) if a.startswith("parts/") else a
                                     for a in cmd.split()[1:]],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"check_figures.py: self-test: {cmd} failed: {run.stderr.strip()}")
    lines = run.stdout.splitlines()
    head, rows = lines[0], lines[1:]
    col = head.split(",")
    ip = col.index("p")

    def moved_by(k):
        # Row 1's p moved by k standard errors of the comparison, sqrt(2 v).
        f = rows[0].split(",")
        row = dict(zip(col, f))
        f[ip] = repr(float(row["p"]) + k * math.sqrt(2 * variance(row)))
        return [",".join(f)] + rows[1:]

    cases = [("as written", rows, 0), ("renumbered", renumbered(col, rows), 0),
             ("moved by 1 standard error", moved_by(1), 0),
             ("moved by 8 standard errors", moved_by(8), 1)]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "control.csv")
        for name, body, want in cases:
            with open(path, "w") as f:
                f.write(f"# {cmd}\n" + "\n".join([head] + body) + "\n")
            _, moved = check(binary, here, [path], quiet=True)
            if moved != want:
                sys.exit(f"check_figures.py: self-test: the control {name} gave {moved} "
                         f"moved numbers, not {want}")
    print(f"check_figures.py: self-test: {len(cases)} controls as expected")


def renumbered(col, rows):
    """The rows in reverse order, numbered 1, 2, ... again."""
    ipose = col.index("pose")
    out = []
    for k, r in enumerate(reversed(rows)):
        f = r.split(",")
        f[ipose] = str(k + 1)
        out.append(",".join(f))
    return out


def main():
    args = sys.argv[1:]
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    binary = os.path.join(here, "build/opt/posedrop")
    if args[:1] == ["-b"]:
        # Absolute: each file's run is made in that file's folder.
        binary, args = os.path.abspath(args[1]), args[2:]
    if args[:1] == ["--self-test"]:
        self_test(binary, here)
        args = args[1:]
        if not args:
            return
    n, moved = check(binary, here, args)
    print(f"check_figures.py: {n} numbers of {len(args)} files, {moved} moved")
    sys.exit(1 if moved else 0)


if __name__ == "__main__":
    main()
