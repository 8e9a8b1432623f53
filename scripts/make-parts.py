#!/usr/bin/env python3
"""make-parts.py: generate the paper's four parts as closed OFF meshes.

The paper (Part Pose Statistics, section 6) gives only photographs and pose
counts of its four parts, so each is rebuilt here as a plausible simple shape
from a few named dimensions (millimetres; the OFF files are written in metres):

  parts/insulator_cap.off        closed-end cylindrical cup with a lip   (5 poses)
  parts/white_button.off         round cap on a smaller round stem       (4 poses)
  parts/rect_black_button.off    rectangular cap on a rectangular stem   (7 poses)
  parts/square_black_button.off  square cap on a stem with a flange      (12 poses)

Usage:
  scripts/make-parts.py                 write the four OFF files from DIMS below
  scripts/make-parts.py --set insulator_cap.H=14 change a dimension for this run
  scripts/make-parts.py --report        also print posedrop's QS per pose class
                                        against the paper's QS column
  scripts/make-parts.py --fit [PART..] [--save] [--min-tip DEG] [--pqs-weight W]
                                        search the FIT dimensions of each part
                                        (coarse grid, then Nelder-Mead) so that
                                        posedrop's grouped QS column matches the
                                        paper's, no pose class tipping over at
                                        less than DEG degrees (2); prints the
                                        fitted DIMS and writes the OFF files
                                        from them; --save also writes them into
                                        DIMS below; W > 0 adds W times the
                                        squared PQS residuals (0: QS only)

By default only the QS column is fitted (QS depends only on the hull and the
centre of mass); PQS and the dynamic columns stay out-of-sample predictions.
Python 3 standard library only.  posedrop must be built (make all).
"""

import argparse
import csv
import io
import itertools
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
POSEDROP = os.path.join(ROOT, "build", "opt", "posedrop")
EPSILON = "20"

# The paper's QS column (percent), Tables 1-4, in the paper's pose order
# (/work/shared/data/paper-tables.csv, column p_qs).
PAPER_QS = {
    "insulator_cap": [30.5, 37.3, 19.6, 8.3, 4.2],
    "white_button": [34.5, 39.9, 19.2, 6.3],
    "rect_black_button": [36.2, 16.0, 17.4, 8.1, 10.6, 7.5, 4.3],
    "square_black_button": [35.7, 17.5, 12.1, 7.2, 3.9, 5.6, 3.8, 4.2, 3.0,
                            2.6, 2.2, 2.1],
}
PAPER_PQS = {
    "insulator_cap": [46.5, 30.2, 19.8, 3.5, 0.0],
    "white_button": [48.8, 30.6, 20.5, 0.0],
    "rect_black_button": [47.3, 25.5, 17.0, 1.2, 4.5, 4.4, 0.0],
    "square_black_button": [46.6, 15.5, 17.0, 8.6, 1.6, 1.5, 3.9, 1.7, 2.3,
                            0.7, 0.0, 0.5],
}

# ---------------------------------------------------------------------------
# Dimensions (mm).  FIT names the dimensions the fit searches, with bounds;
# the others stay at the values given here.  DIMS holds the fitted values.

DIMS = {
    "insulator_cap": {
        "R": 10.0,    # outer radius of the cup body
        "H": 17.113,    # overall height (closed top at z = H, open end at z = 0)
        "RL": 10.432,   # radius of the lip at the open end
        "t": 9.412,     # height of the lip
        "c": 5.965,     # 45-degree chamfer on the closed end's outer edge
        "w": 1.5,     # wall thickness (bore radius R - w)
        "tt": 2.0,    # thickness of the closed end
        "n": 32,      # sides of the polygons standing for its circles
    },
    "white_button": {
        "R": 10.0,    # cap radius
        "hc": 4.994,    # cap height
        "c": 1.0,     # chamfer on the cap's top edge
        "rs": 4.789,    # stem radius
        "hs": 7.816,    # stem length below the cap
        "n": 32,      # sides of the polygons standing for its circles
    },
    "rect_black_button": {
        "a": 16.0,    # cap length (x)
        "b": 10.587,     # cap width (y)
        "hc": 8.956,    # cap height
        "sa": 6.0,    # stem length (x)
        "sb": 4.521,    # stem width (y)
        "hs": 2.372,    # stem height below the cap
        "ta": 12.0,   # raised top (step) length (x)
        "tb": 6.884,    # raised top width (y)
        "ht": 1.226,    # raised top height
    },
    "square_black_button": {
        "a": 12.0,    # cap side (x and y)
        "k": 3.749,     # corner chamfer of the cap (octagonal outline)
        "hc": 2.177,    # cap height
        "sa": 3.014,    # stem length (x)
        "sb": 2.0,    # stem width (y)
        "hs": 3.787,    # stem height below the flange
        "fa": 6.361,    # flange length (x) between stem and cap
        "fb": 9.495,    # flange width (y)
        "hf": 1.503,    # flange thickness
    },
}

FIT = {
    "insulator_cap": [("H", 8.0, 30.0), ("RL", 10.3, 14.0), ("t", 0.5, 12.0),
                      ("c", 0.2, 6.0)],
    "white_button": [("hc", 2.0, 14.0), ("rs", 1.5, 5.0), ("hs", 2.0, 16.0)],
    "rect_black_button": [("b", 5.0, 15.0), ("hc", 2.0, 10.0),
                          ("hs", 2.0, 12.0), ("ht", 0.5, 4.0),
                          ("tb", 2.0, 9.0), ("sb", 2.0, 8.0)],
    "square_black_button": [("k", 0.5, 4.0), ("hc", 2.0, 10.0),
                            ("hs", 2.0, 12.0), ("hf", 0.5, 4.0),
                            ("sa", 3.0, 7.0), ("sb", 2.0, 6.0),
                            ("fa", 6.0, 10.0), ("fb", 6.0, 10.0)],
}

# Every pose the paper counts is a pose its real part rests in (Figure 2
# photographs the rectangular button in all seven), so none may be a knife
# edge: the fit penalises, TIP_WEIGHT per squared degree, each pose class
# whose tip angle (the tilt that brings the centre of mass over an edge of
# its support polygon) is below MIN_TIP degrees.  A QS-only fit without this
# parks poses on knife edges, where a facet just stable collects the QS of
# its neighbours but no dropped part can stay.
MIN_TIP = 2.0
TIP_WEIGHT = 100.0

# Order of the proper rotations about z that map each shape onto itself: two
# stable facets are one pose class when a rotation by a multiple of 2*pi/ORDER
# maps one's normal onto the other's.


def order_of(name, d):
    if name in ("insulator_cap", "white_button"):
        return int(d["n"])
    if name == "square_black_button" and abs(d["sa"] - d["sb"]) < 1e-12 \
            and abs(d["fa"] - d["fb"]) < 1e-12:
        return 4
    return 2


# ---------------------------------------------------------------------------
# Meshes: a part is a sequence of rings (closed polylines around the z axis,
# all with the same number of points and the same angular order).  Consecutive
# rings are joined by quads; a ring whose points coincide is a pole (joined by
# triangles); an end ring that is not a pole is closed by one polygon.


def circle(r, z, n):
    if r == 0.0:
        return [(0.0, 0.0, z)] * n
    return [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z)
            for i in range(n)]


def rect(sx, sy, z):
    hx, hy = sx / 2.0, sy / 2.0
    return [(hx, -hy, z), (hx, hy, z), (-hx, hy, z), (-hx, -hy, z)]


def octagon(sx, sy, k, z):
    """Rectangle sx by sy with its corners cut by k (k = 0: a rectangle with
    doubled corner points, so that it can be joined to an octagon)."""
    hx, hy = sx / 2.0, sy / 2.0
    return [(hx, -hy + k, z), (hx, hy - k, z), (hx - k, hy, z), (-hx + k, hy, z),
            (-hx, hy - k, z), (-hx, -hy + k, z), (-hx + k, -hy, z), (hx - k, -hy, z)]


def revolve(profile, n):
    """Rings of a solid of revolution from an (r, z) profile."""
    return [circle(r, z, n) for r, z in profile]


def loft(rings):
    verts, index = [], []
    for ring in rings:
        # identical points of one ring are one vertex (a pole, or the doubled
        # corners of octagon(k=0)); the quads touching them become triangles
        ids, seen = [], {}
        for p in ring:
            if p not in seen:
                seen[p] = len(verts)
                verts.append(p)
            ids.append(seen[p])
        index.append(ids)
    faces = []
    m = len(rings[0])
    for a, b in zip(index, index[1:]):
        for i in range(m):
            j = (i + 1) % m
            quad = [a[i], a[j], b[j], b[i]]
            poly = []
            for v in quad:
                if v not in poly:
                    poly.append(v)
            if len(poly) >= 3:
                faces.append(poly)
    for ids, rev in ((index[0], True), (index[-1], False)):
        poly = [v for k, v in enumerate(ids) if v != ids[k - 1]]
        if len(poly) >= 3:
            faces.append(poly[::-1] if rev else poly)
    # orient outward: flip everything if the signed volume is negative
    if signed_volume(verts, faces) < 0:
        faces = [list(reversed(f)) for f in faces]
    return verts, faces


def signed_volume(verts, faces):
    vol = 0.0
    for f in faces:
        p0 = verts[f[0]]
        for k in range(1, len(f) - 1):
            p1, p2 = verts[f[k]], verts[f[k + 1]]
            vol += (p0[0] * (p1[1] * p2[2] - p1[2] * p2[1])
                    - p0[1] * (p1[0] * p2[2] - p1[2] * p2[0])
                    + p0[2] * (p1[0] * p2[1] - p1[1] * p2[0])) / 6.0
    return vol


def check_nested(outer, inner, what):
    """inner must lie strictly inside outer (both convex, counter-clockwise)."""
    m = len(outer)
    for i in range(m):
        x0, y0, _ = outer[i]
        x1, y1, _ = outer[(i + 1) % m]
        for x, y, _ in inner:
            if (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0) <= 1e-9:
                raise ValueError(what + ": inner outline not strictly inside")


# ---------------------------------------------------------------------------
# The four parts.  Each builder returns rings (mm) or raises ValueError when
# the dimensions do not make a valid shape.


def inside_profile(outer, r, z, margin):
    """(r, z) lies inside the closed (r, z) polygon outer (closed through the
    axis), at least margin from each of its edges."""
    poly = outer + [(0.0, outer[-1][1]), outer[0]]
    crossings = 0
    for (r0, z0), (r1, z1) in zip(poly, poly[1:]):
        if (z0 > z) != (z1 > z) and r < r0 + (z - z0) * (r1 - r0) / (z1 - z0):
            crossings += 1
        dr, dz = r1 - r0, z1 - z0
        L2 = dr * dr + dz * dz
        u = 0.0 if L2 == 0 else max(0.0, min(1.0, ((r - r0) * dr + (z - z0) * dz) / L2))
        if math.hypot(r - r0 - u * dr, z - z0 - u * dz) < margin and r0 + r1 > 0:
            return False
    return crossings % 2 == 1


def sides(d):
    n = d["n"]
    if n != int(n) or n < 3:
        raise ValueError("n: the number of sides must be a whole number >= 3")
    return int(n)


def build_insulator_cap(d):
    R, H, RL, t, c, w, tt = (d[k] for k in ("R", "H", "RL", "t", "c", "w", "tt"))
    if not (0 < c < R and RL > R and 0 < t < H - c and 0 < tt < H - 1.0
            and 0 < w < R):
        raise ValueError("insulator_cap: inconsistent dimensions")
    outer = [(0.0, H), (R - c, H), (R, H - c), (R, t), (RL, t), (RL, 0.0)]
    # the bore: radius R - w, its closed end tt below the top; where the
    # chamfer comes closer than the wall, the bore's corner is chamfered
    # parallel to it (a 45-degree line w inside the chamfer)
    rb, zb = R - w, H - tt
    k = R + H - c - w * math.sqrt(2.0)  # inner chamfer line r + z = k
    if rb + zb > k:
        inner = [(rb, 0.0), (rb, k - rb), (k - zb, zb), (0.0, zb)]
    else:
        inner = [(rb, 0.0), (rb, zb), (0.0, zb)]
    for r, z in inner[1:]:
        if r > 0 and not inside_profile(outer, r, z, 0.5 * w):
            raise ValueError("insulator_cap: the bore breaks through the wall")
    if inner[-2][0] <= 0 or k - rb <= 0:
        raise ValueError("insulator_cap: the bore breaks through the wall")
    return revolve(outer + inner, sides(d))


def build_white_button(d):
    R, hc, c, rs, hs = (d[k] for k in ("R", "hc", "c", "rs", "hs"))
    if not (0 <= c < min(hc, R - rs) and 0 < rs < R and hc > 0 and hs > 0):
        raise ValueError("white_button: inconsistent dimensions")
    top = hs + hc
    profile = [(0.0, top)]
    if c > 0:
        profile += [(R - c, top), (R, top - c)]
    else:
        profile += [(R, top)]
    profile += [(R, hs), (rs, hs), (rs, 0.0), (0.0, 0.0)]
    return revolve(profile, sides(d))


def build_rect_black_button(d):
    g = {k: d[k] for k in d}
    if not (0 < g["sa"] < g["a"] and 0 < g["sb"] < g["b"] and 0 < g["ta"] < g["a"]
            and 0 < g["tb"] < g["b"] and min(g["hc"], g["hs"], g["ht"]) > 0):
        raise ValueError("rect_black_button: inconsistent dimensions")
    z1 = g["hs"]
    z2 = z1 + g["hc"]
    z3 = z2 + g["ht"]
    stem0, stem1 = rect(g["sa"], g["sb"], 0.0), rect(g["sa"], g["sb"], z1)
    cap0, cap1 = rect(g["a"], g["b"], z1), rect(g["a"], g["b"], z2)
    top0, top1 = rect(g["ta"], g["tb"], z2), rect(g["ta"], g["tb"], z3)
    check_nested(cap0, stem1, "rect stem")
    check_nested(cap1, top0, "rect top")
    return [stem0, stem1, cap0, cap1, top0, top1]


def build_square_black_button(d):
    g = {k: d[k] for k in d}
    if not (0 < g["k"] < g["a"] / 2 and 0 < g["sa"] < g["fa"] and 0 < g["sb"] < g["fb"]
            and min(g["hc"], g["hs"], g["hf"]) > 0):
        raise ValueError("square_black_button: inconsistent dimensions")
    z1 = g["hs"]
    z2 = z1 + g["hf"]
    z3 = z2 + g["hc"]
    stem0, stem1 = octagon(g["sa"], g["sb"], 0.0, 0.0), octagon(g["sa"], g["sb"], 0.0, z1)
    fl0, fl1 = octagon(g["fa"], g["fb"], 0.0, z1), octagon(g["fa"], g["fb"], 0.0, z2)
    cap0, cap1 = octagon(g["a"], g["a"], g["k"], z2), octagon(g["a"], g["a"], g["k"], z3)
    check_nested(octagon(g["fa"], g["fb"], 1e-6, z1), octagon(g["sa"], g["sb"], 1e-6, z1),
                 "square stem")
    check_nested(cap0, octagon(g["fa"], g["fb"], 1e-6, z2), "square flange")
    return [stem0, stem1, fl0, fl1, cap0, cap1]


BUILDERS = {
    "insulator_cap": build_insulator_cap,
    "white_button": build_white_button,
    "rect_black_button": build_rect_black_button,
    "square_black_button": build_square_black_button,
}

DESCRIPTION = {
    "insulator_cap": "insulator cap: closed-end cylindrical cup (hollow, wall w), "
                     "chamfered closed end, lip at the open end; an n-sided solid of revolution",
    "white_button": "large white stereo pushbutton: solid round cap with a chamfered "
                    "top edge on a smaller round stem; an n-sided solid of revolution",
    "rect_black_button": "rectangular black stereo button: rectangular cap with a "
                         "raised top step on a smaller rectangular stem",
    "square_black_button": "square black stereo button: square cap with cut corners "
                           "on a rectangular flange and a rectangular stem",
}


def write_off(path, name, d, verts, faces):
    lines = ["OFF"]
    lines.insert(0, "# units: metres; generated by scripts/make-parts.py from (mm): "
                 + ", ".join("%s=%g" % (k, d[k]) for k in d))
    lines.insert(0, "# " + DESCRIPTION[name])
    lines.append("%d %d 0" % (len(verts), len(faces)))
    for x, y, z in verts:
        lines.append(" ".join(fmt(v * 1e-3) for v in (x, y, z)))
    for f in faces:
        lines.append(" ".join(str(v) for v in [len(f)] + f))
    with open(path, "w") as fp:
        fp.write("\n".join(lines) + "\n")


def fmt(v):
    s = "%.12g" % v
    return "0" if s in ("-0", "0") or abs(v) < 1e-15 else s


def make(name, d, path):
    verts, faces = loft(BUILDERS[name](d))
    write_off(path, name, d, verts, faces)


# ---------------------------------------------------------------------------
# posedrop and pose classes


def run_posedrop(path):
    out = subprocess.run([POSEDROP, "--epsilon", EPSILON, path], check=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         universal_newlines=True).stdout
    return list(csv.DictReader(io.StringIO(out)))


def same(a, b, rel=1e-6):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def group(rows, order):
    """Pose classes: rows whose facets are images of each other under the
    part's rotations about z (multiples of 2*pi/order).  Members of a class
    also agree in height and area to a relative 1e-6 (checked)."""
    classes = []
    for r in rows:
        n = (float(r["nx"]), float(r["ny"]), float(r["nz"]))
        placed = False
        for c in classes:
            m = c["normal"]
            if abs(n[2] - m[2]) > 1e-6:
                continue
            for k in range(order):
                a = 2 * math.pi * k / order
                x = m[0] * math.cos(a) - m[1] * math.sin(a)
                y = m[0] * math.sin(a) + m[1] * math.cos(a)
                if abs(x - n[0]) < 1e-6 and abs(y - n[1]) < 1e-6:
                    if not (same(float(r["height"]), c["height"])
                            and same(float(r["area"]), c["area"])):
                        raise RuntimeError("symmetric facets differ in height/area")
                    c["members"].append(int(r["pose"]))
                    c["qs"] += 100 * float(r["p_qs"])
                    c["pqs"] += 100 * float(r["p_pqs"])
                    placed = True
                    break
            if placed:
                break
        if not placed:
            classes.append({"normal": n, "height": float(r["height"]),
                            "area": float(r["area"]), "members": [int(r["pose"])],
                            "qs": 100 * float(r["p_qs"]), "pqs": 100 * float(r["p_pqs"])})
    classes.sort(key=lambda c: -c["qs"])
    return classes


def centroid(verts, faces):
    """Centre of mass of the closed mesh at uniform density."""
    vol, c = 0.0, [0.0, 0.0, 0.0]
    for f in faces:
        p0 = verts[f[0]]
        for k in range(1, len(f) - 1):
            p1, p2 = verts[f[k]], verts[f[k + 1]]
            v = signed_volume([p0, p1, p2], [[0, 1, 2]])
            vol += v
            for i in range(3):
                c[i] += v * (p0[i] + p1[i] + p2[i]) / 4.0
    return [x / vol for x in c]


def hull_2d(points):
    """Convex hull of 2-D points, counter-clockwise (monotone chain)."""
    pts = sorted(set(points))
    if len(pts) < 3:
        return pts
    cross = lambda o, a, b: (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def tip_angle(verts, com, n):
    """Degrees the part must tilt, resting on the facet with outward normal n,
    before its centre of mass passes over an edge of the support polygon (the
    hull vertices in the facet's plane): atan(distance to the nearest edge /
    height of the centre of mass).  0 is a knife edge."""
    dot = lambda a, b: a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    size = max(max(v[i] for v in verts) - min(v[i] for v in verts) for i in range(3))
    top = max(dot(n, v) for v in verts)
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = (a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0])
    u = [x / math.sqrt(dot(u, u)) for x in u]
    w = (n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0])
    poly = hull_2d([(round(dot(u, v), 9), round(dot(w, v), 9)) for v in verts
                    if top - dot(n, v) < 1e-6 * size])
    q = (dot(u, com), dot(w, com))
    dist = min(((b[0] - p[0]) * (q[1] - p[1]) - (b[1] - p[1]) * (q[0] - p[0]))
               / math.hypot(b[0] - p[0], b[1] - p[1]) for p, b in zip(poly, poly[1:] + poly[:1]))
    return math.degrees(math.atan2(dist, top - dot(n, com)))


def evaluate(name, d, tmpdir):
    path = os.path.join(tmpdir, name + ".off")
    verts, faces = loft(BUILDERS[name](d))
    write_off(path, name, d, verts, faces)
    classes = group(run_posedrop(path), order_of(name, d))
    com = centroid(verts, faces)
    for c in classes:
        c["tip"] = tip_angle(verts, com, c["normal"])
    return classes


def match(name, classes):
    """Pair pose classes with the paper's poses by QS rank: the pairing of two
    sorted lists that minimises the squared error.  Returns, per paper pose
    (paper numbering), the class (or None) and the residual."""
    paper = PAPER_QS[name]
    by_rank = sorted(range(len(paper)), key=lambda i: -paper[i])
    pairs = [None] * len(paper)
    for rank, i in enumerate(by_rank):
        pairs[i] = classes[rank] if rank < len(classes) else None
    return pairs


def cost(name, classes, pqs_weight, min_tip):
    """Squared QS residuals in the QS-rank pairing, plus pqs_weight times the
    squared PQS residuals in the same pairing (PQS too depends only on the
    hull and the centre of mass), plus TIP_WEIGHT times the squared shortfall,
    in degrees, of each class's tip angle below min_tip, plus 1000 per missing
    or extra class."""
    pairs = match(name, classes)
    sse = sum((p - (c["qs"] if c else 0.0)) ** 2 for p, c in zip(PAPER_QS[name], pairs))
    sse += pqs_weight * sum((p - (c["pqs"] if c else 0.0)) ** 2
                            for p, c in zip(PAPER_PQS[name], pairs))
    sse += sum(c["qs"] ** 2 + pqs_weight * c["pqs"] ** 2 for c in classes[len(pairs):])
    sse += TIP_WEIGHT * sum(max(0.0, min_tip - c["tip"]) ** 2 for c in classes)
    if len(classes) != len(PAPER_QS[name]):
        sse += 1000.0 * abs(len(classes) - len(PAPER_QS[name]))
    return sse


# ---------------------------------------------------------------------------
# Fit: coarse grid over the FIT dimensions, then Nelder-Mead (bounded by
# clamping into the box) from the best grid points.


def objective(name, base, names, x, tmpdir, memo, pqs_weight, min_tip):
    key = tuple(round(v, 6) for v in x)
    if key in memo:
        return memo[key]
    d = dict(base)
    d.update(zip(names, x))
    try:
        val = cost(name, evaluate(name, d, tmpdir), pqs_weight, min_tip)
    except (ValueError, subprocess.CalledProcessError):
        val = 1e9
    memo[key] = val
    return val


def nelder_mead(f, x0, lo, hi, step, iters=200, tol=1e-4):
    clamp = lambda x: [min(max(v, a), b) for v, a, b in zip(x, lo, hi)]
    n = len(x0)
    pts = [clamp(x0)]
    for i in range(n):
        x = list(x0)
        x[i] += step[i] if x[i] + step[i] <= hi[i] else -step[i]
        pts.append(clamp(x))
    vals = [f(p) for p in pts]
    for _ in range(iters):
        order = sorted(range(n + 1), key=lambda i: vals[i])
        pts = [pts[i] for i in order]
        vals = [vals[i] for i in order]
        if abs(vals[-1] - vals[0]) < tol and max(
                max(abs(a - b) for a, b in zip(p, pts[0])) for p in pts) < 1e-3:
            break
        cen = [sum(p[i] for p in pts[:-1]) / n for i in range(n)]
        refl = clamp([c + (c - w) for c, w in zip(cen, pts[-1])])
        fr = f(refl)
        if fr < vals[0]:
            exp = clamp([c + 2 * (c - w) for c, w in zip(cen, pts[-1])])
            fe = f(exp)
            pts[-1], vals[-1] = (exp, fe) if fe < fr else (refl, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = refl, fr
        else:
            con = clamp([c + 0.5 * (w - c) for c, w in zip(cen, pts[-1])])
            fc = f(con)
            if fc < vals[-1]:
                pts[-1], vals[-1] = con, fc
            else:
                for i in range(1, n + 1):
                    pts[i] = clamp([a + 0.5 * (b - a) for a, b in zip(pts[0], pts[i])])
                    vals[i] = f(pts[i])
    best = min(range(n + 1), key=lambda i: vals[i])
    return pts[best], vals[best]


def fit(name, base, grid_n, starts, tmpdir, pqs_weight, min_tip):
    """Grid and Nelder-Mead over the continuous FIT dimensions, once for each
    combination of the discrete ones (those given as a list of values)."""
    cont = [p for p in FIT[name] if len(p) == 3]
    disc = [p for p in FIT[name] if len(p) == 2]
    names = [p[0] for p in cont]
    lo = [p[1] for p in cont]
    hi = [p[2] for p in cont]
    best_d, best_v, nev = dict(base), math.inf, 0
    for values in itertools.product(*[p[1] for p in disc]):
        b = dict(base)
        b.update(zip([p[0] for p in disc], values))
        memo = {}
        f = lambda x: objective(name, b, names, x, tmpdir, memo, pqs_weight, min_tip)
        axes = [[a + (h - a) * (i + 0.5) / grid_n for i in range(grid_n)]
                for a, h in zip(lo, hi)]
        grid = sorted(((f(list(x)), list(x)) for x in itertools.product(*axes)),
                      key=lambda t: t[0])
        step = [(h - a) / grid_n for a, h in zip(lo, hi)]
        for v0, x0 in grid[:starts]:
            x, v = nelder_mead(f, x0, lo, hi, step)
            x, v = nelder_mead(f, x, lo, hi, [st / 4 for st in step])
            if v < best_v:
                best_v = v
                best_d = dict(b)
                best_d.update((k, round(xv, 3)) for k, xv in zip(names, x))
        nev += len(memo)
    return best_d, nev


# ---------------------------------------------------------------------------


def report(name, d, tmpdir):
    classes = evaluate(name, d, tmpdir)
    pairs = match(name, classes)
    sq = lambda col, paper: sum((p - (c[col] if c else 0.0)) ** 2 for p, c in zip(paper, pairs))
    print("%s: %d pose classes (paper: %d); sum of squared residuals: QS %.2f, PQS %.2f;"
          " smallest tip angle %.2f degrees"
          % (name, len(classes), len(PAPER_QS[name]), sq("qs", PAPER_QS[name]),
             sq("pqs", PAPER_PQS[name]), min(c["tip"] for c in classes)))
    print("| paper pose | facet class (normal) | facets | tip (deg) | paper QS | posedrop QS "
          "| residual | paper PQS | posedrop PQS |")
    print("|---|---|---|---|---|---|---|---|---|")
    for i, c in enumerate(pairs):
        if c is None:
            print("| %d | (none) | 0 | - | %.1f | 0 | %+.1f | %.1f | 0 |"
                  % (i + 1, PAPER_QS[name][i], -PAPER_QS[name][i], PAPER_PQS[name][i]))
            continue
        print("| %d | (%.3f, %.3f, %.3f) | %d | %.2f | %.1f | %.1f | %+.1f | %.1f | %.1f |"
              % (i + 1, c["normal"][0], c["normal"][1], c["normal"][2], len(c["members"]),
                 c["tip"], PAPER_QS[name][i], c["qs"], c["qs"] - PAPER_QS[name][i],
                 PAPER_PQS[name][i], c["pqs"]))
    for c in classes[len(pairs):]:
        print("| - | (%.3f, %.3f, %.3f) | %d | %.2f | - | %.1f | - | - | %.1f |"
              % (c["normal"][0], c["normal"][1], c["normal"][2], len(c["members"]),
                 c["tip"], c["qs"], c["pqs"]))
    print()


def save_dims(dims):
    """Rewrite the values of the DIMS block of this script (comments kept)."""
    path = os.path.abspath(__file__)
    out, part, inside = [], None, False
    with open(path) as fp:
        for line in fp:
            if line.startswith("DIMS = {"):
                inside = True
            elif inside and line.startswith("}"):
                inside = False
            elif inside:
                m = re.match(r'    "(\w+)": \{', line)
                if m:
                    part = m.group(1)
                m = re.match(r'(        "(\w+)": )([-0-9.e]+)(,.*)$', line, re.S)
                if m and part in dims:
                    line = "%s%r%s" % (m.group(1), dims[part][m.group(2)], m.group(4))
            out.append(line)
    with open(path, "w") as fp:
        fp.write("".join(out))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fit", nargs="*", metavar="PART",
                    help="fit these parts (all when none is named)")
    ap.add_argument("--set", action="append", default=[], metavar="PART.DIM=MM",
                    help="override a dimension, e.g. insulator_cap.H=14")
    ap.add_argument("--save", action="store_true",
                    help="with --fit: write the fitted values into DIMS in this script")
    ap.add_argument("--report", action="store_true",
                    help="print posedrop's grouped QS against the paper's")
    ap.add_argument("--pqs-weight", type=float, default=0.0,
                    help="weight of the squared PQS residuals beside the QS ones "
                         "(0, the default: QS only; docs/validation.md)")
    ap.add_argument("--min-tip", type=float, default=MIN_TIP,
                    help="smallest tip angle, degrees, a stable pose may have (%g)" % MIN_TIP)
    ap.add_argument("--grid", type=int, default=None,
                    help="grid points per dimension (8; 3 for the black buttons, "
                         "whose 6 and 8 dimensions would make 8 too many)")
    ap.add_argument("--starts", type=int, default=3,
                    help="Nelder-Mead starts from the best grid points (3)")
    ap.add_argument("--outdir", default=os.path.join(ROOT, "parts"))
    args = ap.parse_args()

    dims = {k: dict(v) for k, v in DIMS.items()}
    for s in args.set:
        key, val = s.split("=")
        part, dim = key.split(".")
        if part not in dims or dim not in dims[part]:
            ap.error("unknown dimension " + key)
        dims[part][dim] = float(val)

    with tempfile.TemporaryDirectory() as tmpdir:
        if args.fit is not None:
            for name in args.fit or list(DIMS):
                if name not in DIMS:
                    ap.error("unknown part " + name)
                grid = args.grid or (3 if len(FIT[name]) > 4 else 8)
                dims[name], nev = fit(name, dims[name], grid, args.starts, tmpdir,
                                       args.pqs_weight, args.min_tip)
                print("%s: fitted after %d evaluations: %r" % (name, nev, dims[name]),
                      file=sys.stderr)
            print("DIMS = {")
            for name in DIMS:
                print('    "%s": %r,' % (name, dims[name]))
            print("}")
            if args.save:
                save_dims(dims)
        for name in DIMS:
            make(name, dims[name], os.path.join(args.outdir, name + ".off"))
        if args.report or args.fit is not None:
            for name in DIMS:
                report(name, dims[name], tmpdir)


if __name__ == "__main__":
    main()
