#!/usr/bin/env python3
"""bench-mujoco.py: the cost of a drop, posedrop's impulse engine against MuJoCo.

The same three parts dropped the same way on both, in one run, and the ratio
of their costs per drop:

  cube   1 cm cube
  box    1 x 2 x 3 cm box
  coin   32-gon prism, 2 cm across, 1 cm high (h/d 0.5)

Each part is released at rest in the paper's scene (lowest point 0.12 m above
the floor, a belt speed of 0.05 m/s along x, mu 0.3, e 0.3, g 9.81), in an
orientation uniform at random, and run until it rests.

posedrop: build/opt/posedrop (make all) with its defaults (impulse engine,
compliant contact with the auto contact time), -j 1, on OFF files written
here. Its cost per drop is the child's CPU time with -n N less that with
-n 1 (the part's build and static estimate), over N - 1, the least over
--passes runs.

MuJoCo: its Python package, dt 2 ms, its default (elliptic) friction cone at
mu 0.3,
soft contacts with the stiffest time constant MuJoCo allows at that step
(2 dt) and a damping ratio bisected here so that a flat drop of the cube
rebounds with e = 0.3 (the measured e is printed). Softer ones (time
constants of 6-20 ms, damping ratios of 0.23-0.37 for the same e) left every
drop rocking or spinning in a limit cycle, or unstable, over 20 s
(2026-11-27). Rest: linear speed and
the fastest point's speed from turning below 1 mm/s over 0.1 s (checked
every 10 steps; --rest-speed, --rest-time), or 20 s. The ratio scales with
how long MuJoCo runs, so the simulated seconds per drop of both are printed
too. Only mj_step's own CPU time is counted (the
Python checks between calls are not), each drop's least over --passes runs.
Both sides are timed in CPU seconds, which the machine's other work disturbs
less than wall-clock time.

Needs the mujoco package (not a posedrop dependency; outside make check):
  python3 -m venv .venv && .venv/bin/pip install mujoco numpy
  .venv/bin/python scripts/bench-mujoco.py        (or: make bench-mujoco)
"""
import argparse
import math
import os
import resource
import subprocess
import sys
import tempfile
import time

HEIGHT = 0.12
BELT = 0.05
MU = 0.3
E_TARGET = 0.3
G = 9.81
DT = 0.002
TIMECONST = 2 * DT  # MuJoCo's stiffest stable contact at this step
REST_SPEED = 1e-3   # m/s (--rest-speed)
REST_TIME = 0.1     # s (--rest-time)
CHECK_EVERY = 10    # steps
TIME_LIMIT = 20.0   # s

PARTS = ["cube", "box", "coin"]


def part_mesh(name):
    """Vertices (m, centred) and outward faces of a part."""
    if name in ("cube", "box"):
        a, b, c = (0.01, 0.01, 0.01) if name == "cube" else (0.01, 0.02, 0.03)
        v = [(x * a / 2, y * b / 2, z * c / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
        f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        return v, f
    n, r, h = 32, 0.01, 0.01
    ring = [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n)) for i in range(n)]
    v = [(x, y, -h / 2) for x, y in ring] + [(x, y, h / 2) for x, y in ring]
    f = [tuple(range(n - 1, -1, -1)), tuple(range(n, 2 * n))]
    f += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    return v, f


def write_off(path, v, f):
    with open(path, "w") as o:
        o.write("OFF\n%d %d 0\n" % (len(v), len(f)))
        for p in v:
            o.write("%.17g %.17g %.17g\n" % p)
        for face in f:
            o.write("%d %s\n" % (len(face), " ".join(map(str, face))))


# --- posedrop ----------------------------------------------------------------


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def posedrop_cpu(exe, off, n, seed):
    c0 = child_cpu()
    p = subprocess.run([exe, "-n", str(n), "-j", "1", "--seed", str(seed), off],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    c = child_cpu() - c0
    if p.returncode != 0:
        sys.exit("bench-mujoco: %s failed: %s" % (exe, p.stderr.strip()))
    rows = [r.split(",") for r in p.stdout.strip().splitlines()]
    col = rows[0].index("unsettled")  # the same count on every pose's row
    return c, int(rows[1][col])


def posedrop_per_drop(exe, off, n, passes, seed):
    best_n = best_1 = math.inf
    unset = 0
    for _ in range(passes):
        c, unset = posedrop_cpu(exe, off, n, seed)
        best_n = min(best_n, c)
        best_1 = min(best_1, posedrop_cpu(exe, off, 1, seed)[0])
    return max(best_n - best_1, 0.0) / (n - 1), unset


# --- MuJoCo ------------------------------------------------------------------


def mjcf(name, v, f, dampratio):
    verts = " ".join("%.17g %.17g %.17g" % p for p in v)
    if name == "coin":
        asset = '<asset><mesh name="m" vertex="%s"/></asset>' % verts
        geom = '<geom type="mesh" mesh="m"/>'
    else:
        xs = [max(abs(p[k]) for p in v) for k in range(3)]
        asset = ""
        geom = '<geom type="box" size="%.17g %.17g %.17g"/>' % tuple(xs)
    return """<mujoco>
  <option timestep="%g" gravity="0 0 %g"/>
  %s
  <default><geom friction="%g 0 0" solref="%g %.17g" condim="3"/></default>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body name="part"><freejoint/>%s</body>
  </worldbody>
</mujoco>""" % (DT, -G, asset, MU, TIMECONST, dampratio, geom)


def lowest(mujoco, model, data, verts, quat):
    import numpy
    mat = numpy.zeros(9)
    mujoco.mju_quat2Mat(mat, numpy.asarray(quat, dtype=float))
    return min(mat[6] * x + mat[7] * y + mat[8] * z for x, y, z in verts)


def mj_release(mujoco, model, data, verts, quat):
    mujoco.mj_resetData(model, data)
    data.qpos[3:7] = quat
    data.qpos[0:3] = (0.0, 0.0, HEIGHT - lowest(mujoco, model, data, verts, quat))
    data.qvel[:] = 0.0
    data.qvel[0] = BELT


def flat_rebound(mujoco, dampratio):
    """e of the cube dropped flat from HEIGHT: rebound over approach speed."""
    v, f = part_mesh("cube")
    model = mujoco.MjModel.from_xml_string(mjcf("cube", v, f, dampratio))
    data = mujoco.MjData(model)
    mj_release(mujoco, model, data, v, [1.0, 0.0, 0.0, 0.0])
    data.qvel[0] = 0.0
    approach, touched = 0.0, False
    for _ in range(2000):
        vz = data.qvel[2]
        if data.ncon > 0:
            touched = True
        if not touched:
            approach = -vz
        elif data.ncon == 0 and vz > 0:
            return vz / approach
        mujoco.mj_step(model, data)
    return 0.0


def tune_dampratio(mujoco):
    lo, hi = 0.01, 2.0  # e falls as the damping ratio rises
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        if flat_rebound(mujoco, mid) > E_TARGET:
            lo = mid
        else:
            hi = mid
    d = 0.5 * (lo + hi)
    return d, flat_rebound(mujoco, d)


def uniform_quats(n, seed):
    import random
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        q = [rng.gauss(0, 1) for _ in range(4)]
        s = math.sqrt(sum(x * x for x in q))
        out.append([x / s for x in q])
    return out


def posedrop_sim_time(exe, off, n, seed, tmp):
    """Mean simulated seconds per drop (the trials' time column), untimed."""
    trials = os.path.join(tmp, "trials.csv")
    subprocess.run([exe, "-n", str(n), "-j", "1", "--seed", str(seed), "--trials", trials, off],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    with open(trials) as f:
        rows = [r.split(",") for r in f.read().strip().splitlines()]
    col = rows[0].index("time")
    return sum(float(r[col]) for r in rows[1:]) / (len(rows) - 1)


def mj_drops(mujoco, name, dampratio, quats, passes, rest_speed, rest_time):
    """Least mj_step seconds per drop over passes (all drops; the settled
    ones alone), mean steps, unsettled."""
    v, f = part_mesh(name)
    model = mujoco.MjModel.from_xml_string(mjcf(name, v, f, dampratio))
    data = mujoco.MjData(model)
    rmax = max(math.sqrt(x * x + y * y + z * z) for x, y, z in v)
    need = max(1, int(round(rest_time / (CHECK_EVERY * DT))))
    best = [math.inf] * len(quats)
    steps = unset = 0
    settled = [True] * len(quats)
    for p in range(passes):
        for i, q in enumerate(quats):
            mj_release(mujoco, model, data, v, q)
            spent, quiet, nstep = 0.0, 0, 0
            while True:
                t0 = time.process_time()
                mujoco.mj_step(model, data, CHECK_EVERY)
                spent += time.process_time() - t0
                nstep += CHECK_EVERY
                qv = data.qvel
                lin = math.sqrt(qv[0] ** 2 + qv[1] ** 2 + qv[2] ** 2)
                ang = math.sqrt(qv[3] ** 2 + qv[4] ** 2 + qv[5] ** 2) * rmax
                quiet = quiet + 1 if max(lin, ang) < rest_speed else 0
                if quiet >= need:
                    break
                if nstep * DT >= TIME_LIMIT:
                    if p == 0:
                        unset += 1
                        settled[i] = False
                    break
            best[i] = min(best[i], spent)
            if p == 0:
                steps += nstep
    ok = [t for t, s in zip(best, settled) if s]
    return sum(best) / len(best), sum(ok) / max(len(ok), 1), steps / len(quats), unset


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--posedrop", default="build/opt/posedrop")
    ap.add_argument("-n", type=int, default=2000, help="posedrop drops per part (2000)")
    ap.add_argument("--mj-drops", type=int, default=200, help="MuJoCo drops per part (200)")
    ap.add_argument("--passes", type=int, default=3, help="timed passes, least taken (3)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--parts", default=",".join(PARTS))
    ap.add_argument("--rest-speed", type=float, default=REST_SPEED,
                    help="MuJoCo's rest: speeds below this, m/s (%g)" % REST_SPEED)
    ap.add_argument("--rest-time", type=float, default=REST_TIME,
                    help="MuJoCo's rest: for this long, s (%g)" % REST_TIME)
    a = ap.parse_args()
    try:
        import mujoco
    except ImportError:
        sys.stderr.write(
            "bench-mujoco: the mujoco Python package is not installed; install it outside the tree\n"
            "or in the git-ignored .venv:\n"
            "  python3 -m venv .venv && .venv/bin/pip install mujoco numpy\n"
            "  .venv/bin/python scripts/bench-mujoco.py\n")
        return 2
    if not os.access(a.posedrop, os.X_OK):
        sys.stderr.write("bench-mujoco: %s not found: run make all first\n" % a.posedrop)
        return 2
    parts = a.parts.split(",")
    for p in parts:
        if p not in PARTS:
            sys.stderr.write("bench-mujoco: unknown part %r (cube, box, coin)\n" % p)
            return 2
    load = os.getloadavg()
    print("bench-mujoco: posedrop %s -j 1 (%d drops) against MuJoCo %s (%d drops), least of %d passes"
          % (a.posedrop, a.n, mujoco.__version__, a.mj_drops, a.passes))
    print("load average %.1f %.1f %.1f on %d cores" % (load + (os.cpu_count(),)))
    dampratio, e = tune_dampratio(mujoco)
    print("MuJoCo: dt %g s, solref %g %.4f (timeconst, dampratio), default solimp; flat cube drop e = %.3f"
          % (DT, TIMECONST, dampratio, e))
    quats = uniform_quats(a.mj_drops, a.seed)
    print("columns: posedrop's CPU us per drop and its unsettled drops; MuJoCo's over all its drops")
    print("and over its settled ones alone, its mean steps and unsettled drops; the ratios (MuJoCo /")
    print("posedrop) for both")
    print("%-5s %12s %6s %12s %12s %9s %8s %8s %8s" % ("part", "posedrop us", "unset", "mujoco us",
                                                     "mj settled", "mj steps", "mj unset", "ratio",
                                                     "settled"))
    sim_times = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in parts:
            off = os.path.join(tmp, name + ".off")
            write_off(off, *part_mesh(name))
            pd, pd_unset = posedrop_per_drop(a.posedrop, off, a.n, a.passes, a.seed)
            pd_sim = posedrop_sim_time(a.posedrop, off, a.n, a.seed, tmp)
            mj, mj_ok, mj_steps, mj_unset = mj_drops(mujoco, name, dampratio, quats, a.passes,
                                                     a.rest_speed, a.rest_time)
            sim_times.append((name, pd_sim, mj_steps * DT))
            ratio = "%7.1fx %7.1fx" % (mj / pd, mj_ok / pd) if pd > 0 else "      -       -"
            print("%-5s %12.1f %6d %12.1f %12.1f %9.0f %8d %s" % (name, 1e6 * pd, pd_unset, 1e6 * mj,
                                                                1e6 * mj_ok, mj_steps, mj_unset, ratio))
            sys.stdout.flush()
    print("simulated seconds per drop, each to its own end (posedrop: decided; MuJoCo: rest as above):")
    for name, pd_sim, mj_sim in sim_times:
        print("%-5s posedrop %.3f s, MuJoCo %.3f s" % (name, pd_sim, mj_sim))
    load = os.getloadavg()
    print("load average at the end %.1f %.1f %.1f" % load)
    return 0


if __name__ == "__main__":
    sys.exit(main())
