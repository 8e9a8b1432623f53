#!/usr/bin/env python3
"""engine-step-rebound.py: the rebound of one contact as ODE and Bullet step it.

The stepping engines stand for the scene's contact (restitution e, contact
time T) by the impulse engine's Hunt-Crossley law at every vertex below the
floor (src/engines/engine_contact.h). Scaled (time by 1 / omega, depth by
v0 / omega) one vertex's contact is s'' = -s (1 + chi s'), s(0) = 0,
s'(0) = 1, lasting tau; the engines step it at H = omega h = tau / k for k
steps a contact. Their contact rows (erp, cfm) push with k d + b d' at the
step's end rate, b = c + theta h k (c the damping at the step's start);
theta = 1 is the rows' documented form (the spring stepped implicitly),
theta = PD_ENGINE_SPRING_IMPLICIT (src/engines/engines_tol.h) the adapters'
since 2026-12-07 (the spring at the step's start). This prints, per e and k,
the rebound of each form over the approach speed: its mean and its worst
error over touches spread evenly over a step (PHASES of them), in Markdown,
with this command and the commit.

  scripts/engine-step-rebound.py [--doc FILE]

--doc FILE puts the table between '<!-- step-rebound begin -->' and
'<!-- step-rebound end -->' of FILE. Python 3 standard library only; a
second of CPU.
"""
import argparse
import math
import os
import re
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT  # noqa: E402

PHASES = 32
ES = [0.05, 0.3, 0.6, 0.9, 1.0]
KS = [10, 20, 40]


def tol_constant(name):
    text = open(os.path.join(ROOT, "src", "engines", "engines_tol.h")).read()
    m = re.search(r"#define %s ([0-9.eE+-]+)" % name, text)
    if not m:
        sys.exit("engine-step-rebound.py: %s not found in engines_tol.h" % name)
    return float(m.group(1))


def hc_chi(e):
    """The root in (0, 1/e) of ln((1 + chi) / (1 - chi e)) = chi (1 + e)."""
    if e >= 1.0:
        return 0.0
    lo, hi = 0.0, 1.0 / e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if math.log((1 + mid) / (1 - mid * e)) - mid * (1 + e) < 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def hc_tau(chi, n=4096):
    """The scaled contact's duration, RK4 and a linear crossing (1e-7)."""
    h, s, v, t = math.pi / n, 0.0, 1.0, 0.0

    def acc(s, v):
        f = s * (1 + chi * v)
        return -f if f > 0 else 0.0

    while True:
        a1 = acc(s, v)
        a2 = acc(s + 0.5 * h * v, v + 0.5 * h * a1)
        a3 = acc(s + 0.5 * h * (v + 0.5 * h * a1), v + 0.5 * h * a2)
        a4 = acc(s + h * (v + 0.5 * h * a2), v + h * a3)
        s1 = s + h * (v + h * (a1 + a2 + a3) / 6)
        v1 = v + h * (a1 + 2 * a2 + 2 * a3 + a4) / 6
        if s1 <= 0 and v1 < 0:
            return t + h * s / (s - s1)
        t, s, v = t + h, s1, v1


def stepped_rebound(chi, H, phase, theta):
    """One contact stepped as the engines' rows step it: the vertex touches
    phase of a step after the step's start; each step the row's force
    s + b u' (b = theta H + chi s, u' the rate at the step's end), at least
    0, then the depth from the new rate."""
    s, u, touched = -phase * H, 1.0, False
    for _ in range(100000):
        if s > 0:
            touched = True
            b = theta * H + chi * s
            u1 = (u - H * s) / (1 + H * b)
            if s + b * u1 >= 0:
                u = u1
        elif touched and u < 0:
            return -u
        s += H * u
    return float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--doc")
    a = ap.parse_args()
    theta = tol_constant("PD_ENGINE_SPRING_IMPLICIT")
    commit, dirty = script_util.commit_here()
    out = ["", "Made by `scripts/engine-step-rebound.py%s` on %s (commit %s%s): the scaled law "
           "stepped at k steps a contact, the touch at %d places spread over a step; rebound "
           "over the approach speed, mean and worst error over those touches." %
           (" --doc " + a.doc if a.doc else "", time.strftime("%Y-%m-%d"), commit, dirty, PHASES),
           "",
           "| e | k | implicit spring (theta 1): mean | worst error | spring at the step's start "
           "(theta %g): mean | worst error |" % theta,
           "|---|---|---|---|---|---|"]
    for e in ES:
        chi = hc_chi(e)
        tau = hc_tau(chi)
        for k in KS:
            cols = []
            for th in (1.0, theta):
                r = [stepped_rebound(chi, tau / k, (i + 0.5) / PHASES, th) for i in range(PHASES)]
                cols += ["%.4f" % (sum(r) / len(r)), "%.4f" % max(abs(x - e) for x in r)]
            out.append("| %g | %d | %s |" % (e, k, " | ".join(cols)))
    text = "\n".join(out) + "\n\n"
    if a.doc:
        script_util.put_between(a.doc, "step-rebound", text, "engine-step-rebound.py")
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
