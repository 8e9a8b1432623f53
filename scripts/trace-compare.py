#!/usr/bin/env python3
"""trace-compare.py: where two engines' runs of the same drop part.

Reads two traces written by posedrop --trace (the same drop, --trace-drop,
on two engines) and lists each trace's contact episodes in order: a run of
rows with a hull vertex on or below the floor (the contacts column), its
start and end time, and the state after it (the first row after the
episode; the last row if the drop ended in contact). The episodes are
paired in order and the first pair whose outgoing velocity (centre of mass,
and the fastest point's angular part, |w| times the part's size) differs
by more than --tol of the approach speed is flagged: there the engines
part. Before the first contact both follow the same closed-form flight, so
a difference there is the flight's (or the release's), not the contact's.

Usage: scripts/trace-compare.py A.csv B.csv [--size L] [--tol 0.1] [--max 20]
  --size  the part's size in m, for the angular part (default: from the
          first row's height over its lowest vertex, a lower bound)
Python 3 standard library only.
"""

import argparse
import csv
import math
import sys


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in r:
            if k != "event":
                r[k] = float(r[k])
    return rows


def episodes(rows):
    out, i = [], 0
    while i < len(rows):
        if rows[i]["contacts"] > 0 and rows[i]["event"] != "release":
            j = i
            while j + 1 < len(rows) and rows[j + 1]["contacts"] > 0:
                j += 1
            # The impulse engine's impact rows carry the velocities after it.
            after = rows[j + 1] if j + 1 < len(rows) else rows[j]
            before = rows[i - 1] if i > 0 else rows[i]
            out.append((rows[i]["t"], rows[j]["t"], before, after))
            i = j + 1
        else:
            i += 1
    return out


def vec(r, k):
    return [r[k + "x"], r[k + "y"], r[k + "z"]]


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def diff(a, b):
    return [x - y for x, y in zip(a, b)]


def main():
    ap = argparse.ArgumentParser(description="where two engines' traces of one drop part")
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--size", type=float, default=0.0)
    ap.add_argument("--tol", type=float, default=0.1)
    ap.add_argument("--max", type=int, default=20)
    o = ap.parse_args()
    A, B = read(o.a), read(o.b)
    size = o.size or (A[0]["z"] + A[0]["depth"])
    ea, eb = episodes(A), episodes(B)
    print("# %s: %d rows, %d contact episodes, ends at %.6g s (%s)" %
          (o.a, len(A), len(ea), A[-1]["t"], A[-1]["event"]))
    print("# %s: %d rows, %d contact episodes, ends at %.6g s (%s)" %
          (o.b, len(B), len(eb), B[-1]["t"], B[-1]["event"]))
    print("episode,t_a,t_b,approach,dv_rel,dw_rel,vz_after_a,vz_after_b,parted")
    parted = None
    for k, (pa, pb) in enumerate(zip(ea, eb)):
        if k >= o.max:
            break
        approach = max(norm(vec(pa[2], "v")), norm(vec(pb[2], "v")), 1e-12)
        dv = norm(diff(vec(pa[3], "v"), vec(pb[3], "v"))) / approach
        dw = norm(diff(vec(pa[3], "w"), vec(pb[3], "w"))) * size / approach
        flag = parted is None and max(dv, dw) > o.tol
        if flag:
            parted = k
        print("%d,%.6g,%.6g,%.4g,%.3f,%.3f,%.4g,%.4g,%s" %
              (k + 1, pa[0], pb[0], approach, dv, dw, pa[3]["vz"], pb[3]["vz"],
               "yes" if flag else ""))
    if parted is None:
        print("# no pair of the first %d episodes parts beyond %.2g of the approach speed" %
              (min(len(ea), len(eb), o.max), o.tol))
    else:
        print("# they part at contact episode %d" % (parted + 1))


if __name__ == "__main__":
    sys.exit(main())
