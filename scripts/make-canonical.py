#!/usr/bin/env python3
"""make-canonical.py: the canonical test parts in parts/canonical/ (OFF, metres).

    scripts/make-canonical.py [DIR]

Cube, boxes, a thin tile, thick coins (64-gon prisms at several thickness
ratios), the five Platonic solids, an L-bracket and a loaded die (a cube with
an off-centre cavity, so its centre of mass is off centre by geometry alone).
Every mesh is closed and outward-oriented; sizes are those of small parts (1-3
cm). Standard library only.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402


def write_off(path, verts, faces, comment):
    script_util.write_off(path, verts, faces, comment, "metres", "make-canonical.py")


def box(a, b, c, x0=0.0, y0=0.0, z0=0.0, inward=False):
    """Vertices and outward quads of an axis-aligned box centred at (x0,y0,z0)."""
    v = [(x0 + sx * a / 2, y0 + sy * b / 2, z0 + sz * c / 2)
         for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
    q = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    if inward:
        q = [tuple(reversed(f)) for f in q]
    return v, q


def prism(n, r, h):
    v = [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z)
         for z in (-h / 2, h / 2) for i in range(n)]
    faces = [tuple(reversed(range(n))), tuple(n + i for i in range(n))]
    faces += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    return v, faces


def hull_faces(verts):
    """Faces of a convex polyhedron (all points on the hull): brute force over
    triples, each plane's points ordered counter-clockwise seen from outside."""
    n, faces, seen = len(verts), [], set()
    sub = lambda p, q: (p[0] - q[0], p[1] - q[1], p[2] - q[2])
    cross = lambda p, q: (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])
    dot = lambda p, q: p[0] * q[0] + p[1] * q[1] + p[2] * q[2]
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                nrm = cross(sub(verts[j], verts[i]), sub(verts[k], verts[i]))
                if dot(nrm, nrm) < 1e-20:
                    continue
                d = [dot(nrm, sub(verts[m], verts[i])) for m in range(n)]
                if all(x <= 1e-9 for x in d) or all(x >= -1e-9 for x in d):
                    on = tuple(sorted(m for m in range(n) if abs(d[m]) <= 1e-9))
                    if on in seen:
                        continue
                    seen.add(on)
                    if not all(x <= 1e-9 for x in d):  # points above: nrm is inward
                        nrm = (-nrm[0], -nrm[1], -nrm[2])
                    c = [sum(verts[m][a] for m in on) / len(on) for a in range(3)]
                    u = sub(verts[on[0]], c)
                    w = cross(nrm, u)
                    ang = lambda m: math.atan2(dot(sub(verts[m], c), w), dot(sub(verts[m], c), u))
                    faces.append(tuple(sorted(on, key=ang)))
    return faces


def platonic():
    g = (1 + 5 ** 0.5) / 2
    t = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
    o = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    c = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    i = [p for s1 in (-1, 1) for s2 in (-1, 1) for p in ((0, s1, s2 * g), (s1, s2 * g, 0), (s2 * g, 0, s1))]
    d = c + [p for s1 in (-1, 1) for s2 in (-1, 1)
             for p in ((0, s1 / g, s2 * g), (s1 / g, s2 * g, 0), (s2 * g, 0, s1 / g))]
    return {"tetrahedron": t, "octahedron": o, "cube": c, "icosahedron": i, "dodecahedron": d}


def main():
    if len(sys.argv) > 2 or (len(sys.argv) == 2 and sys.argv[1].startswith("-")):
        print("make-canonical.py: expected at most one argument, the output directory "
              "(default parts/canonical), got " + " ".join(sys.argv[1:]), file=sys.stderr)
        sys.exit(2)
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "parts", "canonical")
    os.makedirs(out, exist_ok=True)
    cm = 0.01
    for name, (a, b, c) in {"cube": (1, 1, 1), "box_1x2x3": (1, 2, 3), "box_1x1x2": (1, 1, 2),
                            "tile_10x8x0.5": (10, 8, 0.5)}.items():
        v, f = box(a * cm, b * cm, c * cm)
        write_off(os.path.join(out, name + ".off"), v, f, "%s: %g x %g x %g cm" % (name, a, b, c))
    for ratio in (0.1, 0.25, 0.5, 1.0):
        v, f = prism(64, 1 * cm, 2 * cm * ratio)
        write_off(os.path.join(out, "coin_h%g.off" % ratio), v, f,
                  "coin: 64-gon prism, diameter 2 cm, height/diameter %g" % ratio)
    for name, pts in platonic().items():
        s = 1 * cm / max(math.sqrt(p[0] ** 2 + p[1] ** 2 + p[2] ** 2) for p in pts)
        v = [(p[0] * s, p[1] * s, p[2] * s) for p in pts]
        write_off(os.path.join(out, "platonic_" + name + ".off"), v, hull_faces(v),
                  "regular %s, circumradius 1 cm" % name)
    # L-bracket: an L profile 3 x 3 cm, 0.5 cm thick legs, extruded 2 cm.
    prof = [(0, 0), (3, 0), (3, 0.5), (0.5, 0.5), (0.5, 3), (0, 3)]
    n = len(prof)
    v = [(x * cm, y * cm, z * cm) for z in (0, 2) for (x, y) in prof]
    f = [tuple(reversed(range(n))), tuple(n + i for i in range(n))]
    f += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    # The profile is not convex: fan it from a corner that sees it all (0.5, 0.5).
    f = [(0, 3, 2, 1), (0, 5, 4, 3)] + [(n + 1, n + 2, n + 3, n + 0), (n + 3, n + 4, n + 5, n + 0)] + f[2:]
    write_off(os.path.join(out, "l_bracket.off"), v, f, "L-bracket: 3 x 3 cm legs 0.5 cm thick, 2 cm wide")
    # Loaded die: 1.6 cm cube with a 0.8 cm cavity near one face, so the
    # centre of mass sits 0.05 cm off centre towards the opposite face.
    v, f = box(1.6 * cm, 1.6 * cm, 1.6 * cm)
    vi, fi = box(0.8 * cm, 0.8 * cm, 0.8 * cm, 0, 0, 0.35 * cm, inward=True)
    write_off(os.path.join(out, "loaded_die.off"), v + vi, f + [tuple(i + 8 for i in q) for q in fi],
              "loaded die: 1.6 cm cube with a 0.8 cm cavity 0.35 cm above its centre")


if __name__ == "__main__":
    main()
