#!/usr/bin/env python3
"""make-big-meshes.py: write the large test meshes of docs/performance.md.

The meshes are generated rather than shipped (a 2-million-triangle OFF file
is about 100 MB). Each is closed, consistently oriented and does not cross
itself; every random draw comes from a fixed seed, so the same command
writes the same bytes.

  latlong   a latitude-longitude sphere of m x m vertices plus two poles,
            each vertex at a random radius in [0.5, 1]: star-shaped about
            the origin (a radial graph over the sphere, so it cannot cross
            itself), most vertices inside the hull, many long thin
            triangles, as in a noisy scan. 2 m^2 triangles.
  pair      two latlong spheres of m, the second after the first in the
            random stream and moved 2.5 along x: they do not meet, and
            no point is faced by every triangle (the part is not
            star-shaped), so the self-crossing check cannot settle it
            before its search. 4 m^2 triangles.
  icosphere an icosahedron with each face cut into k x k triangles, the
            vertices pushed onto the unit sphere and then to a radius
            1 + 0.01 u, u uniform in [-1, 1] (1% radial noise). 20 k^2
            triangles.
  rod       a rod of n sides and k rings along its length (radius 0.05,
            length 1, centred on the origin; the inner rings' radii pulled
            in at random by up to 0.1%), caps fanned about one corner, turned off the axes
            by 0.7 rad about (1, 2, 3): long thin side triangles across
            every axis. 2 n k + 2 (n - 2) triangles.
  hull      the convex hull (qconvex Qt) of p random points on the unit
            sphere: about 2 p triangles, all vertices on the hull.

Usage:
  scripts/make-big-meshes.py latlong M OUT.off [--seed S]
  scripts/make-big-meshes.py pair M OUT.off [--seed S]
  scripts/make-big-meshes.py icosphere K OUT.off [--seed S]
  scripts/make-big-meshes.py rod N K OUT.off [--seed S]
  scripts/make-big-meshes.py hull P OUT.off [--seed S]
  scripts/make-big-meshes.py points IN.off OUT.txt   qconvex input of a mesh's vertices

Sizes used in docs/performance.md: latlong 1000 (2,000,000 triangles),
pair 707 (1,999,396), icosphere 316 (1,997,120), rod 20000 50 (2,039,996), hull 10000 (~20,000).
Python 3 standard library only.
"""

import math
import random
import subprocess
import sys


def write_off(path, verts, tris):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(verts), len(tris)))
        f.write("".join("%.17g %.17g %.17g\n" % v for v in verts))
        f.write("".join("3 %d %d %d\n" % t for t in tris))


def latlong(m, seed, rng=None):
    rng = rng or random.Random(seed)
    verts = []
    for i in range(m):
        th = math.pi * (i + 1) / (m + 1)
        st, ct = math.sin(th), math.cos(th)
        for j in range(m):
            ph = 2.0 * math.pi * j / m
            r = 0.5 + 0.5 * rng.random()
            verts.append((r * st * math.cos(ph), r * st * math.sin(ph), r * ct))
    north, south = m * m, m * m + 1
    verts.append((0.0, 0.0, 0.5 + 0.5 * rng.random()))
    verts.append((0.0, 0.0, -(0.5 + 0.5 * rng.random())))
    tris = []
    for j in range(m):
        jn = (j + 1) % m
        tris.append((north, j, jn))
    for i in range(m - 1):
        a, b = i * m, (i + 1) * m
        for j in range(m):
            jn = (j + 1) % m
            tris.append((a + j, b + j, b + jn))
            tris.append((a + j, b + jn, a + jn))
    a = (m - 1) * m
    for j in range(m):
        jn = (j + 1) % m
        tris.append((south, a + jn, a + j))
    return verts, tris


def pair(m, seed):
    rng = random.Random(seed)
    v1, t1 = latlong(m, seed, rng)
    v2, t2 = latlong(m, seed, rng)
    n = len(v1)
    return (v1 + [(x + 2.5, y, z) for (x, y, z) in v2],
            t1 + [(a + n, b + n, c + n) for (a, b, c) in t2])


ICO_V = None


def icosahedron():
    p = (1.0 + math.sqrt(5.0)) / 2.0
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p),
         (0, -1, -p), (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return v, f


def icosphere(k, seed):
    rng = random.Random(seed)
    iv, faces = icosahedron()
    verts, index = [], {}

    def vid(key, pos):
        # key: a point of the subdivision named by its barycentric integers
        # over the icosahedron's vertices, so that faces sharing an edge share
        # its points.
        if key not in index:
            n = math.sqrt(pos[0] ** 2 + pos[1] ** 2 + pos[2] ** 2)
            r = 1.0 + 0.01 * (2.0 * rng.random() - 1.0)
            index[key] = len(verts)
            verts.append((r * pos[0] / n, r * pos[1] / n, r * pos[2] / n))
        return index[key]

    tris = []
    for (a, b, c) in faces:
        grid = {}
        for i in range(k + 1):
            for j in range(k + 1 - i):
                w = (k - i - j, i, j)
                key = tuple(sorted(((a, w[0]), (b, w[1]), (c, w[2]))))
                key = tuple(x for x in key if x[1] != 0)
                pos = tuple((w[0] * iv[a][d] + w[1] * iv[b][d] + w[2] * iv[c][d]) / k
                            for d in range(3))
                grid[i, j] = vid(key, pos)
        for i in range(k):
            for j in range(k - i):
                tris.append((grid[i, j], grid[i + 1, j], grid[i, j + 1]))
                if i + j + 1 < k:
                    tris.append((grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]))
    return verts, tris


def rod(n, k, seed):
    rng = random.Random(seed)
    ax = (1.0 / math.sqrt(14.0), 2.0 / math.sqrt(14.0), 3.0 / math.sqrt(14.0))
    th = 0.7
    co, si = math.cos(th), math.sin(th)

    def turn(p):
        d = ax[0] * p[0] + ax[1] * p[1] + ax[2] * p[2]
        cx = (ax[1] * p[2] - ax[2] * p[1], ax[2] * p[0] - ax[0] * p[2],
              ax[0] * p[1] - ax[1] * p[0])
        return tuple(p[i] * co + cx[i] * si + ax[i] * d * (1.0 - co) for i in range(3))

    verts = []
    for e in range(k + 1):
        for i in range(n):
            a = 2.0 * math.pi * i / n
            # The inner rings pulled in by up to 0.1% of the radius: a hull
            # of many rings of cocircular points, all on the cylinder, is
            # degenerate for any hull program (qconvex took 424 s on the
            # exact one of 20000 x 50), and that is not what is measured.
            r = 0.05 * (1.0 - (1e-3 * rng.random() if 0 < e < k else 0.0))
            verts.append(turn((e / k - 0.5, r * math.cos(a), r * math.sin(a))))
    tris = []
    for e in range(k):
        for i in range(n):
            j = (i + 1) % n
            a, b = e * n, (e + 1) * n
            tris.append((a + i, a + j, b + j))
            tris.append((a + i, b + j, b + i))
    top = k * n
    for i in range(1, n - 1):
        tris.append((0, i + 1, i))
        tris.append((top, top + i, top + i + 1))
    return verts, tris


def hull(p, seed):
    rng = random.Random(seed)
    pts = []
    while len(pts) < p:
        x = [rng.gauss(0.0, 1.0) for _ in range(3)]
        n = math.sqrt(sum(c * c for c in x))
        if n > 1e-9:
            pts.append(tuple(c / n for c in x))
    text = "3\n%d\n" % p + "".join("%.17g %.17g %.17g\n" % q for q in pts)
    out = subprocess.run(["qconvex", "Qt", "i"], input=text, capture_output=True, text=True,
                         check=True).stdout.split("\n")
    nf = int(out[0])
    tris = [tuple(int(x) for x in line.split()) for line in out[1:1 + nf]]
    # qconvex's "i" lists each facet's vertices clockwise seen from outside
    # for a 3-d hull; turn them to the counter-clockwise order OFF expects,
    # checked against the outward direction (the origin is inside).
    fixed = []
    for (a, b, c) in tris:
        u = [pts[b][d] - pts[a][d] for d in range(3)]
        v = [pts[c][d] - pts[a][d] for d in range(3)]
        nrm = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        out_dir = sum(nrm[d] * pts[a][d] for d in range(3))
        fixed.append((a, b, c) if out_dir > 0 else (a, c, b))
    return pts, fixed


def points(inp, outp):
    with open(inp) as f:
        f.readline()
        nv = int(f.readline().split()[0])
        lines = [f.readline() for _ in range(nv)]
    with open(outp, "w") as f:
        f.write("3\n%d\n" % nv)
        f.write("".join(lines))


def main(argv):
    seed = 20261207
    if "--seed" in argv:
        i = argv.index("--seed")
        seed = int(argv[i + 1])
        del argv[i:i + 2]
    if len(argv) < 3:
        sys.exit(__doc__)
    kind = argv[1]
    if kind == "latlong" and len(argv) == 4:
        write_off(argv[3], *latlong(int(argv[2]), seed))
    elif kind == "pair" and len(argv) == 4:
        write_off(argv[3], *pair(int(argv[2]), seed))
    elif kind == "icosphere" and len(argv) == 4:
        write_off(argv[3], *icosphere(int(argv[2]), seed))
    elif kind == "rod" and len(argv) == 5:
        write_off(argv[4], *rod(int(argv[2]), int(argv[3]), seed))
    elif kind == "hull" and len(argv) == 4:
        write_off(argv[3], *hull(int(argv[2]), seed))
    elif kind == "points" and len(argv) == 4:
        points(argv[2], argv[3])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
