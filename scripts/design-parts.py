#!/usr/bin/env python3
"""design-parts.py: the starting parts of docs/design.md's demonstrations
(OFF, millimetres), into parts/design/ (or DIR).

    scripts/design-parts.py [DIR]
    scripts/design-parts.py --bushing FLANGE_T BODY_L OUT.off


bushing.off: a flanged bushing, a stepped solid of revolution about z with a
32-gon section: a flange 20 mm across and 3 mm thick (z 0 to 3) under a body
12 mm across and 15 mm long (z 3 to 18); closed, outward-oriented, the flat
ends fanned from their centres.
prism3.off: a triangular prism, an equilateral triangle of 10 mm sides
extruded 10 mm along z (z -5 to 5): the five-sided die's blank.
--bushing writes one bushing of the given flange thickness and body length
(mm) instead: the design demonstration's independent rebuild.
Standard library only.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402


def write_off(path, verts, faces, comment):
    script_util.write_off(path, verts, faces, comment, "millimetres", "design-parts.py")


def bushing(n=32, flange_d=20.0, flange_t=3.0, body_d=12.0, body_l=15.0):
    z = [0.0, flange_t, flange_t, flange_t + body_l]
    r = [flange_d / 2, flange_d / 2, body_d / 2, body_d / 2]
    v = [(r[k] * math.cos(2 * math.pi * i / n), r[k] * math.sin(2 * math.pi * i / n), z[k])
         for k in range(4) for i in range(n)]
    bot, top = len(v), len(v) + 1
    v += [(0.0, 0.0, 0.0), (0.0, 0.0, z[3])]
    f = []
    for i in range(n):
        j = (i + 1) % n
        f.append((bot, j, i))
        for k in range(3):  # flange side, shoulder annulus, body side
            f.append((k * n + i, k * n + j, (k + 1) * n + j, (k + 1) * n + i))
        f.append((top, 3 * n + i, 3 * n + j))
    return v, f


def prism3(side=10.0, length=10.0):
    r = side / math.sqrt(3.0)
    v = [(r * math.cos(2 * math.pi * i / 3 + math.pi / 2),
          r * math.sin(2 * math.pi * i / 3 + math.pi / 2), z)
         for z in (-length / 2, length / 2) for i in range(3)]
    f = [(2, 1, 0), (3, 4, 5)] + [(i, (i + 1) % 3, 3 + (i + 1) % 3, 3 + i) for i in range(3)]
    return v, f


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--bushing":
        ft, bl = float(sys.argv[2]), float(sys.argv[3])
        v, f = bushing(flange_t=ft, body_l=bl)
        write_off(sys.argv[4], v, f, "flanged bushing: flange 20 mm dia x %g mm, body 12 mm dia "
                  "x %g mm, 32-gon" % (ft, bl))
        return
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "parts", "design")
    os.makedirs(out, exist_ok=True)
    v, f = bushing()
    write_off(os.path.join(out, "bushing.off"), v, f,
              "flanged bushing: flange 20 mm dia x 3 mm, body 12 mm dia x 15 mm, 32-gon")
    v, f = prism3()
    write_off(os.path.join(out, "prism3.off"), v, f,
              "triangular prism: equilateral 10 mm sides, 10 mm long")


if __name__ == "__main__":
    main()
