#!/usr/bin/env python3
"""What calling posedrop from Python costs, as ratios against the command.

1. Drops: `posedrop -n 2000 -j T parts/cap.off` against, in one Python
   process, Part.from_file + stable_poses + drop(2000, threads=T): the same
   work, minus the command's process start and printing.
2. Static estimate of a 20k-facet mesh: the command on an OFF file of the
   mesh against Part(vertices, faces).stable_poses() from numpy arrays (and
   from the file).

Each side is timed REPEAT times, alternating, and the medians compared,
both against the command's whole run and against its own clock (--format
json's wall_s, which leaves out its process start and printing). Prints the
ratios (Python over command); asserts nothing. Usage:
    python python/bench.py [--repeat N] [--threads T]
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import posedrop

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "build" / "opt" / "posedrop"


def bumpy_sphere(subdivisions=5, seed=1):
    """An icosphere (20 * 4**5 = 20480 triangles) with its radii jittered by
    up to 5%, so that many facets are unstable and the quasi-static graph
    has real work; 2 cm across."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid, nf = {}, []

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]
        for a, b, c in f:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    r = 1 + 0.05 * np.random.default_rng(seed).random(len(verts))
    return np.array(verts) * r[:, None] * 0.01, np.array(f, dtype=np.int32)


def clock(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def compare(label, command, python, repeat):
    """Runs the command (with --format json, to read its own clock) and the
    Python call alternately; prints the median times and the ratios."""
    whole, inner, mine = [], [], []
    for _ in range(repeat):
        t, out = clock(lambda: subprocess.run([str(CLI), "--format", "json", *map(str, command)],
                                              check=True, capture_output=True, text=True))
        whole.append(t)
        inner.append(json.loads(out.stdout)["posedrop"]["wall_s"])
        mine.append(clock(python)[0])
    c, i, p = (statistics.median(x) for x in (whole, inner, mine))
    print("%s (medians of %d)" % (label, repeat))
    print("    command %.4f s (%.4f-%.4f), of which its own clock %.4f s; python %.4f s "
          "(%.4f-%.4f)" % (c, min(whole), max(whole), i, p, min(mine), max(mine)))
    print("    ratio python / command %.3f, python / command's own clock %.3f" % (p / c, p / i))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    cap = ROOT / "parts" / "cap.off"
    print("posedrop %s, %s" % (posedrop.__version__, CLI))
    compare("2000 drops of parts/cap.off, %d threads: part, poses and drops" % args.threads,
            ["-n", 2000, "-j", args.threads, cap],
            lambda: posedrop.Part.from_file(cap).stable_poses().drop(2000, threads=args.threads),
            args.repeat)
    v, f = bumpy_sphere()
    with tempfile.TemporaryDirectory() as tmp:
        off = Path(tmp) / "sphere.off"
        with open(off, "w") as out:
            out.write("OFF\n%d %d 0\n" % (len(v), len(f)))
            np.savetxt(out, v, fmt="%.17g")
            np.savetxt(out, np.hstack([np.full((len(f), 1), 3), f]), fmt="%d")
        n = len(posedrop.Part(v, f).stable_poses())
        compare("static estimate of a %d-facet mesh (%d stable poses), python from numpy arrays"
                % (len(f), n), [off], lambda: posedrop.Part(v, f).stable_poses(), args.repeat)
        compare("the same, python reading the OFF file", [off],
                lambda: posedrop.Part.from_file(off).stable_poses(), args.repeat)


if __name__ == "__main__":
    main()
