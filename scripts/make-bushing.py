#!/usr/bin/env python3
"""make-bushing.py: the flanged bushing of the engines' cross-check corpus.

A stepped solid of revolution about z, its circles as regular N-gons, in
millimetres (run posedrop with --units mm): a flange of diameter D1 and
height H1 under a body of diameter D2 and height H2, no bore. Only its
convex hull matters to posedrop's drops, but the mesh is the whole closed
solid. Python 3 standard library only.

Usage: scripts/make-bushing.py [OUT.off] [--sides N] [--flange D1xH1] [--body D2xH2]
Defaults: 32 sides, flange 20 x 3, body 12 x 15, to stdout.
"""

import argparse
import math
import sys


def dims(text):
    d, h = text.lower().split("x")
    return float(d), float(h)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", nargs="?")
    ap.add_argument("--sides", type=int, default=32)
    ap.add_argument("--flange", type=dims, default=(20.0, 3.0))
    ap.add_argument("--body", type=dims, default=(12.0, 15.0))
    a = ap.parse_args()
    n = a.sides
    (d1, h1), (d2, h2) = a.flange, a.body
    if n < 3 or min(d1, h1, d2, h2) <= 0 or d2 > d1:
        sys.exit("make-bushing.py: need at least 3 sides, positive sizes, body no wider than flange")
    # Four rings, bottom to top: flange bottom, flange top, body bottom
    # (on the flange's top face), body top.
    rings = [(d1 / 2, 0.0), (d1 / 2, h1), (d2 / 2, h1), (d2 / 2, h1 + h2)]
    verts = []
    for r, z in rings:
        for k in range(n):
            t = 2 * math.pi * k / n
            verts.append((r * math.cos(t), r * math.sin(t), z))
    faces = []

    def ring(i, k):
        return i * n + k % n

    faces.append([ring(0, k) for k in reversed(range(n))])  # bottom, facing -z
    # The flange's side, its top annulus (outer ring to inner: facing +z),
    # the body's side; each quad counterclockwise seen from outside.
    for i in range(3):
        for k in range(n):
            faces.append([ring(i, k), ring(i, k + 1), ring(i + 1, k + 1), ring(i + 1, k)])
    faces.append([ring(3, k) for k in range(n)])  # top, facing +z
    out = open(a.out, "w") if a.out else sys.stdout
    out.write("OFF\n# flanged bushing, mm: flange %g dia x %g, body %g dia x %g, %d-gon "
              "(scripts/make-bushing.py)\n" % (d1, h1, d2, h2, n))
    out.write("%d %d 0\n" % (len(verts), len(faces)))
    for v in verts:
        out.write("%.9g %.9g %.9g\n" % v)
    for f in faces:
        out.write("%d %s\n" % (len(f), " ".join(map(str, f))))


if __name__ == "__main__":
    main()
