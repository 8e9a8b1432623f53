#!/usr/bin/env python3
"""referee-mujoco.py: the cross-check corpus on posedrop's three engines and on MuJoCo.

An outside referee for the engines' disagreements: the same parts dropped in
MuJoCo (its Python package, not a posedrop dependency) with the scene's
physical parameters, from the very releases posedrop drew, decided by the
same rule and grouped into the same pose classes as posedrop's --group.

  .venv/bin/python scripts/referee-mujoco.py [-n DROPS] [--seed S]
      [--parts a,b,...] [--engines impulse,...] [--steps K,...] [--mj-n M]
      [--check-n M] [--jobs J] [-o DIR] [-r] [--doc FILE]

The corpus (--parts picks some):
  bushing   flanged bushing: a stepped solid of revolution, 32-gon, mm:
            flange 20 dia x 3, body 12 dia x 15, no bore (written here from
            those dimensions)
  hexnut    parts/hexnut.obj (mm)
  box       1 x 2 x 3 cm box (parts/canonical/box_1x2x3.off)
  button    parts/white_button.off
  cap       parts/insulator_cap.off
  cube      1 cm cube (parts/canonical/cube.off) started resting on a face:
            posedrop's --initial stationary resting drops (on a face, turned
            at random about the vertical, tilted by the vibration, lowest
            point at the drop height); the figure is the share that ends on
            the face it started on

posedrop: each engine of --engines (impulse, ode, bullet; impulse always,
first: its trials give the releases) at its defaults (build/opt/posedrop; whatever --dt its
default is), -n DROPS, --seed S, --group, --trials (the releases and
outcomes). MuJoCo, for every drop, from the release posedrop recorded (the
orientation in --trials, lowest point at the scene's height, the belt's
velocity, no spin):
  - the part's mesh in metres with MuJoCo's exact volume inertia; MuJoCo
    collides its convex hull, as posedrop does;
  - each contact a push-only linear spring-dashpot with the scene's contact
    time T (the part's automatic one) and restitution e, in acceleration
    units (MuJoCo has no Hunt-Crossley law, which posedrop's three engines
    use; per contact in acceleration units a face of any number of points
    rebounds with e, as with that law; docs/engines-crosscheck.md): zeta from
    e = exp(-zeta g(zeta)), omega = g(zeta) / T, given to MuJoCo as solref
    (timeconst 1 / (zeta omega), dampratio zeta) with an impedance of 0.9999
    throughout (solimp), so that the contact's acceleration is the spring's;
  - Coulomb friction mu on an elliptic cone, and drilling friction as
    posedrop's stepping engines have it (condim 4, torsional coefficient
    (2/3) a mu, a = sqrt(R d): a corner of radius R = PD_CORNER_RADIUS_REL L
    sunk d = g / omega^2);
  - the first --mj-n releases (all by default; MuJoCo costs 10 to 100 times
    posedrop's engines per drop), in --jobs processes (1), each drop's
    outcome, release and CPU time written to DIR/mujoco.PART.T<K>.csv as it
    ends, so a run stopped early leaves what it did;
  - the step T / K for the first K of --steps (default 20,40, and 40,80 for
    the cube: "20,40;cube=40,80"): the table's; each further (finer) step
    runs the first --check-n releases (200) again, and the total variation
    between successive steps on those, against its noise, shows whether the
    table's step is converged (the resting cube's flat landings were not at
    T/20: docs/engines-crosscheck.md);
  - the drop is decided as posedrop's stepping engines decide it: the part
    lies on a stable pose's facet, tilted less than 1 degree, and its energy
    above that rest is below the least height it must rise to tip over one
    of the facet's edges (a lower bound of the basin's barrier, so a decided
    drop cannot leave); or it runs to posedrop's automatic time limit,
    100 (sqrt(L/g) + sqrt(2h/g)), unsettled.

-r reuses what DIR keeps: MuJoCo's drops from the same releases (they
depend on posedrop only through the release), and posedrop's runs made at
a commit whose src/ and include/ are this one's (neither with changes)
with the same command; so after the engines change, -r reruns posedrop's
engines and only the MuJoCo drops not yet made, and a stopped run resumes.
The posedrop runs' commands and commits go in the table's heading.

Writes DIR/referee.csv (part,engine,class,n,count,p,ci_lo,ci_hi,unsettled,
cpu_ms_per_drop), prints the corpus table in Markdown and, with --doc FILE,
puts it between the lines '<!-- referee-mujoco begin -->' and
'<!-- referee-mujoco end -->' of FILE with the command and commit.

Needs the mujoco package (not a posedrop dependency; outside make check):
  python3 -m venv .venv && .venv/bin/pip install mujoco numpy
"""
import argparse
import csv
import json
import math
import os
import resource
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT, rows  # noqa: E402

# PD_CORNER_RADIUS_REL (src/base/base_tol.h): the corner radius of a part of
# size L that the automatic contact time assumes.
CORNER_RADIUS_REL = 0.5e-3 / (0.01 * math.sqrt(3.0))
REST_TILT = math.radians(1.0)   # PD_TOL_REST_TILT
SOLIMP_D = 0.9999               # MuJoCo's highest impedance
CHECK_S = 1e-3                  # simulated seconds between rest checks

PARTS = {
    "bushing": (None, "mm", "uniform"),
    "hexnut": ("parts/hexnut.obj", "mm", "uniform"),
    "box": ("parts/canonical/box_1x2x3.off", "m", "uniform"),
    "button": ("parts/white_button.off", "m", "uniform"),
    "cap": ("parts/insulator_cap.off", "m", "uniform"),
    "cube": ("parts/canonical/cube.off", "m", "resting"),
}
# Cheapest in MuJoCo first, so that a run stopped early has the most parts.
ORDER = ["cube", "box", "bushing", "hexnut", "button", "cap"]
ENGINES = ["impulse", "ode", "bullet"]
PARTS_SEEN = {}
COMMIT = ["?", ""]
RUNS = []   # (part, engine, command, commit) of the posedrop runs in the table


# --- the part ----------------------------------------------------------------


def bushing(path, n=32, flange_d=20.0, flange_h=3.0, body_d=12.0, body_h=15.0):
    """The flanged bushing as an OFF in mm: two coaxial n-gon prisms, the
    flange below the body, one closed surface (the flange's top an annulus)."""
    rings = []
    for r, z in ((flange_d / 2, 0.0), (flange_d / 2, flange_h), (body_d / 2, flange_h),
                 (body_d / 2, flange_h + body_h)):
        rings.append([(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z)
                      for i in range(n)])
    v = [p for ring in rings for p in ring]
    f = [tuple(range(n - 1, -1, -1))]                       # bottom, facing -z
    # The flange's side, the annulus on its top (outer ring to inner, facing
    # +z) and the body's side, each between two successive rings.
    for k in range(3):
        a, b = k * n, (k + 1) * n
        f += [(a + i, a + (i + 1) % n, b + (i + 1) % n, b + i) for i in range(n)]
    f.append(tuple(range(3 * n, 4 * n)))                    # top, facing +z
    with open(path, "w") as o:
        o.write("# flanged bushing: flange %g dia x %g, body %g dia x %g, %d-gon, no bore\n"
                % (flange_d, flange_h, body_d, body_h, n))
        o.write("# units: millimetres; generated by scripts/referee-mujoco.py\n")
        o.write("OFF\n%d %d 0\n" % (len(v), len(f)))
        for p in v:
            o.write("%.17g %.17g %.17g\n" % p)
        for face in f:
            o.write("%d %s\n" % (len(face), " ".join(map(str, face))))


def read_mesh(path):
    """Vertices and triangles (fans of the polygons) of an OFF or OBJ file."""
    v, tri = [], []
    with open(path) as fh:
        text = [ln.split("#")[0].strip() for ln in fh]
    text = [ln for ln in text if ln]
    if path.endswith(".obj"):
        for ln in text:
            w = ln.split()
            if w[0] == "v":
                v.append(tuple(float(x) for x in w[1:4]))
            elif w[0] == "f":
                idx = [int(x.split("/")[0]) for x in w[1:]]
                idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                tri += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
        return v, tri
    words = " ".join(text).split()
    assert words[0] == "OFF", path
    nv, nf = int(words[1]), int(words[2])
    at = 4
    for _ in range(nv):
        v.append(tuple(float(x) for x in words[at:at + 3]))
        at += 3
    for _ in range(nf):
        k = int(words[at])
        idx = [int(x) for x in words[at + 1:at + 1 + k]]
        at += 1 + k
        tri += [(idx[0], idx[j], idx[j + 1]) for j in range(1, k - 1)]
    return v, tri


# --- posedrop ----------------------------------------------------------------


def run(cmd):
    return script_util.run(cmd, "referee-mujoco")


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


class Part:
    """What posedrop says of the part: size, centre of mass, the automatic
    contact time, the stable poses' facets and their classes."""

    def __init__(self, exe, path, units, scene_opts):
        self.exe, self.path, self.units = exe, path, units
        j = json.loads(run([exe, "--format", "json", "-n", "1", "--units", units] + scene_opts
                           + [path]))
        self.size = j["part"]["size_m"]
        self.com = j["part"]["centre_of_mass_m"]
        self.scene = j["scene"]
        self.poses = rows(run([exe, "--units", units, path]))
        self.classes = rows(run([exe, "--group", "--units", units, path]))
        self.class_of = {}
        for c in self.classes:
            for m in c["members"].split():
                self.class_of[int(m)] = int(c["pose"])
        scale = {"m": 1.0, "cm": 0.01, "mm": 0.001}[units]
        v, self.tri = read_mesh(path)
        self.verts = [tuple(scale * x for x in p) for p in v]   # file frame, metres
        # Each pose's facet: outward normal n (file frame), height h of the
        # centre of mass above it, and the least height b it rises to when
        # tipped over one of the facet's edges.
        rel = [tuple(p[k] - self.com[k] for k in range(3)) for p in self.verts]
        self.facets = []
        for r in self.poses:
            n = (float(r["nx"]), float(r["ny"]), float(r["nz"]))
            h = float(r["height"])
            on = [p for p in rel if abs(dot(n, p) - h) < 1e-6 * self.size]
            self.facets.append((n, h, barrier(n, h, on)))


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def barrier(n, h, pts):
    """The least distance from the centre of mass (the origin) to an edge of
    the convex polygon pts on the plane n.x = h: the height the centre of
    mass rises to when the part tips over that edge. h when undefined."""
    if len(pts) < 3:
        return h
    c = [sum(p[k] for p in pts) / len(pts) for k in range(3)]
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = cross(n, a)
    s = math.sqrt(dot(u, u))
    u = tuple(x / s for x in u)
    w = cross(n, u)
    # The polygon's corners only: a vertex inside the facet (a fan's centre,
    # a bore's rim) is not on an edge the part can tip over.
    ring = hull2d(pts, c, u, w)
    best = math.inf
    for i in range(len(ring)):
        p, q = ring[i], ring[(i + 1) % len(ring)]
        d = sub(q, p)
        dd = dot(d, d)
        t = 0.0 if dd == 0 else max(0.0, min(1.0, -dot(p, d) / dd))
        x = tuple(p[k] + t * d[k] for k in range(3))
        best = min(best, math.sqrt(dot(x, x)))
    return best


def hull2d(pts, c, u, w):
    """The convex hull of points on a plane (axes u, w about c), in order."""
    key = sorted(set((dot(sub(p, c), u), dot(sub(p, c), w), i) for i, p in enumerate(pts)))

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def half(seq):
        out = []
        for q in seq:
            while len(out) >= 2 and turn(out[-2], out[-1], q) <= 0:
                out.pop()
            out.append(q)
        return out[:-1]

    ring = half(key) + half(key[::-1])
    return [pts[q[2]] for q in ring]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def same_code(commit):
    """Whether posedrop's code (src/, include/) is now what it was at
    commit, both without changes. The Makefile's flags change no result
    (no -ffast-math; -ffp-contract=off), and a recipe's edit should not
    redo the runs."""
    if COMMIT[1] or commit.endswith(", with changes"):
        return False
    p = subprocess.run(["git", "-C", ROOT, "diff", "--quiet", commit, "HEAD", "--", "src",
                        "include"], stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
    return p.returncode == 0


def posedrop_engine(part, name, engine, n, seed, initial, outdir, reuse):
    """Drops on one engine: the trials (release, outcome), CPU ms per drop and
    the run's record (command, commit). With reuse, a run kept in outdir with
    the same command, from a commit whose code is this one's (no changes),
    is read back."""
    trials = os.path.join(outdir, "trials.%s.%s.csv" % (name, engine))
    meta = trials[:-len(".csv")] + ".json"
    cmd = [part.exe, "-n", str(n), "--seed", str(seed), "--engine", engine, "--units",
           part.units, "--initial", initial, "--trials", trials, part.path]
    shown = "posedrop " + " ".join(
        os.path.relpath(w, ROOT) if w.startswith(ROOT + "/") else w for w in cmd[1:])
    if reuse and os.path.exists(meta) and os.path.exists(trials):
        m = json.load(open(meta))
        if m["command"] == shown and same_code(m["commit"]):
            sys.stderr.write("referee-mujoco: %s on %s: the kept run (%s)\n"
                             % (name, engine, m["commit"]))
            return rows(open(trials).read()), m["cpu_ms_per_drop"], m
    sys.stderr.write("referee-mujoco: %s on %s, %d drops\n" % (name, engine, n))
    c0 = child_cpu()
    run(cmd)
    cpu = child_cpu() - c0
    m = {"command": shown, "commit": COMMIT[0] + COMMIT[1],
         "cpu_ms_per_drop": 1000.0 * cpu / n}
    with open(meta, "w") as f:
        json.dump(m, f)
    return rows(open(trials).read()), m["cpu_ms_per_drop"], m


# --- MuJoCo ------------------------------------------------------------------


def contact_law(T, e):
    """zeta and omega of a push-only spring-dashpot lasting T and rebounding
    with e (docs/engines-crosscheck.md, as pd_engine_contact_law)."""
    e = max(e, 0.01)

    def g(z):
        if z < 1:
            return (math.pi - 2 * math.asin(z)) / math.sqrt(1 - z * z)
        if z == 1:
            return 2.0
        return 2 * math.acosh(z) / math.sqrt(z * z - 1)

    lo, hi = 0.0, 50.0   # e falls as zeta rises
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if math.exp(-mid * g(mid)) > e:
            lo = mid
        else:
            hi = mid
    z = 0.5 * (lo + hi)
    return z, g(z) / T


def mjcf(part, dt):
    sc = part.scene
    T, e, mu, grav = sc["contact_time_s"], sc["restitution"], sc["mu"], sc["gravity_m_s2"]
    zeta, omega = contact_law(T, e)
    sink = grav / omega ** 2
    torsion = (2.0 / 3.0) * mu * math.sqrt(CORNER_RADIUS_REL * part.size * sink)
    verts = " ".join("%.17g %.17g %.17g" % p for p in part.verts)
    faces = " ".join("%d %d %d" % t for t in part.tri)
    return """<mujoco>
  <compiler angle="radian"/>
  <option timestep="%.17g" gravity="0 0 %.17g" cone="elliptic">
    <flag energy="enable"/>
  </option>
  <asset><mesh name="m" vertex="%s" face="%s" inertia="exact"/></asset>
  <default><geom condim="4" friction="%.17g %.17g 0" solref="%.17g %.17g"
    solimp="%g %g 0.001 0.5 2" margin="0"/></default>
  <worldbody>
    <geom type="plane" size="0 0 1"/>
    <body name="part"><freejoint/><geom type="mesh" mesh="m" density="1000"/></body>
  </worldbody>
</mujoco>""" % (dt, -grav, verts, faces, mu, torsion, 1.0 / (zeta * omega), zeta, SOLIMP_D,
                SOLIMP_D)


class Referee:
    def __init__(self, mujoco, part, dt):
        import numpy
        self.mj, self.np, self.part, self.dt = mujoco, numpy, part, dt
        self.model = mujoco.MjModel.from_xml_string(mjcf(part, dt))
        self.data = mujoco.MjData(self.model)
        self.mass = self.model.body_mass[1]
        sc = part.scene
        self.g, self.h, self.v = sc["gravity_m_s2"], sc["height_m"], sc["belt_speed_m_s"]
        self.limit = 100 * (math.sqrt(part.size / self.g) + math.sqrt(2 * self.h / self.g))
        self.every = max(1, int(round(CHECK_S / dt)))
        self.stable = [(i, f) for i, f in enumerate(part.facets) if f[2] > f[1]]
        self.cos_tilt = math.cos(REST_TILT)

    def release(self, q):
        """The data at the release q (file frame to world, w x y z): lowest
        point at the drop height, the belt's velocity, no spin."""
        mj, np, d = self.mj, self.np, self.data
        mj.mj_resetData(self.model, d)
        mat = np.zeros(9)
        mj.mju_quat2Mat(mat, np.asarray(q, dtype=float))
        low = min(mat[6] * x + mat[7] * y + mat[8] * z for x, y, z in self.part.verts)
        d.qpos[0:3] = (0.0, 0.0, self.h - low)
        d.qpos[3:7] = q
        d.qvel[:] = 0.0
        d.qvel[0] = self.v
        return d

    def drop(self, q):
        """Pose number (1-based) the release q rests in, or 0 at the time
        limit; and the simulated time."""
        mj, d = self.mj, self.release(q)
        mg = self.mass * self.g
        while d.time < self.limit:
            mj.mj_step(self.model, d, self.every)
            R = d.xmat[1]
            zc = d.xipos[1][2]
            energy = d.energy[1]
            for i, (n, h, b) in self.stable:
                down = -(R[6] * n[0] + R[7] * n[1] + R[8] * n[2])
                if down > self.cos_tilt and energy + mg * (zc - h) < mg * (b - h):
                    return i + 1, d.time
        return 0, d.time


def law_check(mujoco, exe):
    """The contact law as MuJoCo realises it: the 1 cm cube (its automatic
    contact time T, e 0.3) striking the floor flat at 1 m/s without gravity,
    at T / K for several K: the rebound over the approach speed and how long
    the floor pushed, over T. Markdown."""
    part = Part(exe, os.path.join(ROOT, "parts/canonical/cube.off"), "m", [])
    T, e = part.scene["contact_time_s"], part.scene["restitution"]
    out = ["The law as MuJoCo realises it here: the 1 cm cube (T = %.3g s, e = %g) striking "
           "the floor flat at 1 m/s, gravity off, rebound speed over approach speed and the "
           "time the floor pushed over T, at steps of T / K:\n\n" % (T, e),
           "| K | 10 | 20 | 40 | 80 |\n", "|---|---|---|---|---|\n"]
    got = []
    for K in (10, 20, 40, 80):
        ref = Referee(mujoco, part, T / K)
        m, d = ref.model, ref.data
        m.opt.gravity[2] = 0.0
        mujoco.mj_resetData(m, d)
        d.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
        d.qpos[2] = 0.005 + 1e-4
        d.qvel[2] = -1.0
        t_in = t_out = None
        while d.time < 20 * T and t_out is None:
            mujoco.mj_step(m, d)
            pushing = d.efc_force.size > 0 and d.efc_force.max() > 0
            if pushing and t_in is None:
                t_in = d.time
            if t_in is not None and not pushing and d.qvel[2] > 0:
                t_out = d.time
        got.append((d.qvel[2], (t_out - t_in) / T if t_out else float("nan")))
    out.append("| rebound / approach | %s |\n" % " | ".join("%.4f" % g[0] for g in got))
    out.append("| duration / T | %s |\n" % " | ".join("%.3f" % g[1] for g in got))
    return "".join(out)


# --- statistics and the table -------------------------------------------------


def wilson(k, n, z=1.959963984540054):
    if n == 0:
        return 0.0, 0.0
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    w = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, c - w), min(1.0, c + w)


def outcome_table(part, outcomes, resting, starts):
    """{class: count} over the drops, or for a resting start the drops that
    end on the pose they started on (class 1) and elsewhere (class 2)."""
    counts = {}
    for i, pose in enumerate(outcomes):
        if pose == 0:
            continue
        k = (1 if pose == starts[i] else 2) if resting else part.class_of[pose]
        counts[k] = counts.get(k, 0) + 1
    return counts


def tvn(a, na, b, nb):
    """Total variation between two count tables of na and nb drops."""
    keys = set(a) | set(b)
    return 0.5 * sum(abs(a.get(k, 0) / na - b.get(k, 0) / nb) for k in keys)


def noise_tv(a, na, b, nb, redraws=1000, seed=1):
    """The 95th percentile of the TV between two samples of na and nb drops
    drawn from the two count tables' pooled shares: what sampling alone
    gives were the two to agree."""
    import random
    rng = random.Random(seed)
    keys = sorted(set(a) | set(b))
    w = [a.get(k, 0) + b.get(k, 0) for k in keys]
    if sum(w) == 0:
        return 0.0
    out = []
    for _ in range(redraws):
        x, y = rng.choices(keys, w, k=na), rng.choices(keys, w, k=nb)
        out.append(0.5 * sum(abs(x.count(k) / na - y.count(k) / nb) for k in keys))
    out.sort()
    return out[int(0.95 * len(out))]


def tv(a, b, n):
    keys = set(a) | set(b)
    return 0.5 * sum(abs(a.get(k, 0) - b.get(k, 0)) for k in keys) / n


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--posedrop", default=os.path.join(ROOT, "build/opt/posedrop"))
    ap.add_argument("-n", type=int, default=1000, help="drops per engine and part (1000)")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--parts", default=",".join(ORDER))
    ap.add_argument("--engines", default=",".join(ENGINES),
                    help="posedrop's engines to run beside MuJoCo (impulse,ode,bullet; "
                    "impulse is always run, first)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="processes for MuJoCo's drops (1)")
    ap.add_argument("--steps", default="20,40;cube=40,80",
                    help="MuJoCo's steps per contact time: the table's, then finer ones "
                    "(K,K,... for every part, then ;PART=K,K,... for one part) "
                    "for the convergence check (20,40;cube=40,80)")
    ap.add_argument("--mj-n", type=int,
                    help="MuJoCo drops per part at the table's step: the first of the "
                    "releases (default: all -n)")
    ap.add_argument("--check-n", type=int, default=200,
                    help="releases the finer steps run again (200)")
    ap.add_argument("-o", default="referee-out", help="output directory (referee-out)")
    ap.add_argument("-r", action="store_true",
                    help="reuse the runs kept in -o: MuJoCo's drops from the same releases, "
                    "posedrop's runs made with this code and the same command")
    ap.add_argument("--doc", help="Markdown file to put the table in, between the markers")
    ap.add_argument("--doc-tag", default="referee-mujoco",
                    help="the markers' name (referee-mujoco): several runs, several tables")
    ap.add_argument("--law", action="store_true",
                    help="only the contact law's check (a flat strike of the cube), into "
                    "--doc between the referee-law markers")
    a = ap.parse_args()
    names = a.parts.split(",")
    why = ["unknown part %r (%s)" % (x, ", ".join(PARTS)) for x in names if x not in PARTS]
    engines = ["impulse"] + [e for e in a.engines.split(",") if e != "impulse"]
    why += ["unknown engine %r (%s)" % (e, ", ".join(ENGINES)) for e in engines
            if e not in ENGINES]
    ENGINES[:] = engines
    if not os.access(a.posedrop, os.X_OK):
        why.append("%s not found: run make all first" % a.posedrop)
    try:
        import mujoco
    except ImportError:
        why.append("the mujoco Python package is not installed:\n"
                   "  python3 -m venv .venv && .venv/bin/pip install mujoco numpy")
    if why:
        sys.stderr.write("".join("referee-mujoco: %s\n" % w for w in why))
        return 2
    if a.law:
        COMMIT[:] = script_util.commit_here()
        text = ("Made by `scripts/referee-mujoco.py --law` on %s (commit %s%s); MuJoCo %s.\n\n"
                % (time.strftime("%Y-%m-%d", time.gmtime()), COMMIT[0], COMMIT[1],
                   mujoco.__version__) + law_check(mujoco, a.posedrop))
        sys.stdout.write(text)
        if a.doc:
            script_util.put_between(a.doc, "referee-law", "\n" + text + "\n", "referee-mujoco")
        return 0
    steps = parse_steps(a.steps, names)
    # The code that ran: the commit at the start, and whether the tree
    # differed from it.
    COMMIT[:] = script_util.commit_here()
    os.makedirs(a.o, exist_ok=True)
    out_rows, table = [], []
    for name in names:
        path, units, initial = PARTS[name]
        if path is None:
            path = os.path.join(a.o, "flanged_bushing.off")
            bushing(path)
        else:
            path = os.path.join(ROOT, path)
        resting = initial == "resting"
        init = "stationary" if resting else "uniform"
        part = Part(a.posedrop, path, units, [])
        PARTS_SEEN[name] = part
        # A stationary run's drop i (from 0) is uniform when i mod (k + 1) is
        # 0 and starts resting on pose i mod (k + 1) otherwise (sim.h), in
        # whole rounds of k + 1 (the drops past the last whole round start
        # uniform); the resting ones are kept, n of them (at least 10 resting
        # on each pose, as posedrop asks).
        k1 = len(part.poses) + 1
        ndrops = k1 * max(-(-a.n // (k1 - 1)), 10) if resting else a.n
        keep = [i for i in range(ndrops) if not resting or i % k1 != 0][:a.n]
        starts = [i % k1 for i in range(ndrops)]
        results = {}
        releases = None
        for engine in ENGINES:
            tr, ms, m = posedrop_engine(part, name, engine, ndrops, a.seed, init, a.o, a.r)
            RUNS.append((name, engine, m["command"], m["commit"]))
            if releases is None:
                releases = [tuple(float(t[c]) for c in ("qw", "qx", "qy", "qz")) for t in tr]
            outcomes = [int(tr[i]["pose"]) for i in keep]
            results[engine] = (outcomes, ms)
        for s, K in enumerate(steps[name]):
            dt = part.scene["contact_time_s"] / K
            ref = Referee(mujoco, part, dt)
            these = keep[:a.mj_n or len(keep)] if s == 0 else keep[:a.check_n]
            sys.stderr.write("referee-mujoco: %s on MuJoCo, dt = T/%d = %.3g s, %d drops\n"
                             % (name, K, dt, len(these)))
            log = os.path.join(a.o, "mujoco.%s.T%d.csv" % (name, K))
            outcomes, ms = mujoco_drops(ref, [releases[i] for i in these], these, a.jobs, log,
                                        a.r)
            results["mujoco" if s == 0 else "mujoco %d" % s] = (outcomes, ms)
        st = [starts[i] for i in keep]
        n = len(keep)
        counts = {e: outcome_table(part, o, resting, st) for e, (o, _) in results.items()}
        n_of = {e: len(o) for e, (o, _) in results.items()}
        classes = [1] if resting else sorted(set(part.class_of.values()))
        for e, (o, ms) in results.items():
            unsettled = sum(1 for x in o if x == 0)
            for c in classes:
                cnt = counts[e].get(c, 0)
                lo, hi = wilson(cnt, n_of[e])
                out_rows.append([name, e, c, n_of[e], cnt, cnt / n_of[e], lo, hi, unsettled, ms])
        table.append((name, resting, classes, counts, results, n, st, steps[name]))
        # After each part, so that a run stopped half way leaves what it did.
        write_csv(os.path.join(a.o, "referee.csv"), out_rows)
        text = markdown(table, steps, a)
        if a.doc:
            script_util.put_between(a.doc, a.doc_tag, "\n" + text + "\n", "referee-mujoco")
    sys.stdout.write(text)
    return 0


_WORKER = {}


def _worker_init(part, dt):
    import mujoco
    _WORKER["ref"] = Referee(mujoco, part, dt)


def _worker_drop(q):
    c0 = time.process_time()
    pose = _WORKER["ref"].drop(q)[0]
    return pose, 1000.0 * (time.process_time() - c0)


def mujoco_drops(ref, qs, index, jobs, log, reuse):
    """The outcome of each release in qs (drops index), in order, in jobs
    processes, and the CPU ms per drop; each written to log
    (drop,pose,qw,qx,qy,qz,cpu_ms) as it ends. With reuse, the drops the log
    already holds from the same release (MuJoCo's drops depend on posedrop
    only through it) are read back and only the others run."""
    kept = {}
    if reuse and os.path.exists(log):
        with open(log) as f:
            for r in csv.DictReader(f):
                if "qw" in r and r["cpu_ms"]:
                    kept[int(r["drop"])] = (tuple(float(r[c]) for c in ("qw", "qx", "qy", "qz")),
                                            int(r["pose"]), float(r["cpu_ms"]))
    old = {i: kept[i] for i, q in zip(index, qs)
           if i in kept and max(abs(x - y) for x, y in zip(kept[i][0], q)) < 1e-15}
    todo = [(i, q) for i, q in zip(index, qs) if i not in old]
    if old:
        sys.stderr.write("referee-mujoco: %d drops kept in %s, %d to run\n"
                         % (len(old), log, len(todo)))
    got = {}
    with open(log, "w") as f:
        f.write("drop,pose,qw,qx,qy,qz,cpu_ms\n")

        def put(i, q, pose, ms):
            got[i] = (pose, ms)
            f.write("%d,%d,%s,%.6g\n" % (i, pose, ",".join("%.17g" % x for x in q), ms))
            f.flush()
        # Every drop kept stays in the log (those not asked for this time too).
        for i, (q, pose, ms) in sorted(kept.items()):
            if i in old or i not in index:
                put(i, q, pose, ms)
        if jobs <= 1:
            for i, q in todo:
                c0 = time.process_time()
                pose = ref.drop(q)[0]
                put(i, q, pose, 1000.0 * (time.process_time() - c0))
        elif todo:
            import multiprocessing
            ctx = multiprocessing.get_context("fork")
            with ctx.Pool(jobs, _worker_init, (ref.part, ref.dt)) as pool:
                for (i, q), (pose, ms) in zip(todo, pool.imap(_worker_drop,
                                                              [q for _, q in todo],
                                                              chunksize=4)):
                    put(i, q, pose, ms)
    out = [got[i][0] for i in index]
    return out, sum(got[i][1] for i in index) / len(index)


def write_csv(path, out_rows):
    with open(path, "w") as f:
        f.write("part,engine,class,n,count,p,ci_lo,ci_hi,unsettled,cpu_ms_per_drop\n")
        for r in out_rows:
            f.write("%s,%s,%d,%d,%d,%.6g,%.6g,%.6g,%d,%.4g\n" % tuple(r))


def parse_steps(text, names):
    """{part: [K, ...]} from 'K,K,...' for every part, then ';PART=K,K' for
    one part."""
    words = text.split(";")
    try:
        default = [int(k) for k in words[0].split(",")]
        out = {x: default for x in names}
        for w in words[1:]:
            name, ks = w.split("=")
            if name not in PARTS:
                raise ValueError(name)
            out[name] = [int(k) for k in ks.split(",")]
    except ValueError:
        sys.exit("referee-mujoco: --steps %r: expected K,K,...[;PART=K,K,...]" % text)
    return out


def swap_noise(a, b, part, resting, st, redraws=2000, seed=1):
    """95th percentile of the TV between paired outcomes a and b when each
    pair that differs is put in random order: the TV a step that only
    reshuffled chaotic outcomes within one distribution would show."""
    import random
    rng = random.Random(seed)
    diff = [(x, y, s) for x, y, s in zip(a, b, st) if x != y]
    out = []
    for _ in range(redraws):
        ca, cb = {}, {}
        for x, y, s in diff:
            if rng.random() < 0.5:
                x, y = y, x
            for pose, c in ((x, ca), (y, cb)):
                if pose:
                    k = (1 if pose == s else 2) if resting else part.class_of[pose]
                    c[k] = c.get(k, 0) + 1
        out.append(tv(ca, cb, len(a)))
    out.sort()
    return out[int(0.95 * len(out))] if out else 0.0


def markdown(table, steps, a):
    fine = "mujoco"
    cols = ENGINES + [fine]
    label = {"impulse": "impulse", "ode": "ODE", "bullet": "Bullet", fine: "MuJoCo"}
    lines = []
    cmd = "scripts/referee-mujoco.py " + " ".join(
        w if not w.startswith(ROOT + "/") else os.path.relpath(w, ROOT) for w in sys.argv[1:])
    lines.append("Made by `%s` on %s (commit %s%s), %s UTC; MuJoCo %s.\n\n"
                 % (cmd.strip(), time.strftime("%Y-%m-%d", time.gmtime()), COMMIT[0],
                    COMMIT[1], time.strftime("%H:%M", time.gmtime()),
                    __import__("mujoco").__version__))
    if RUNS:
        lines.append("posedrop's runs: %s.\n\n" % "; ".join(
            "%s on %s: `%s` (commit %s)" % r for r in RUNS))
    lines.append("Share of each pose class (posedrop's `--group` numbering) over %d drops "
                 "per engine (MuJoCo: the first %d of them) from the same releases (seed %d), "
                 "with the 95%% Wilson "
                 "interval's half-width; the cube: the share that ends on the face it "
                 "started resting on. MuJoCo at the step of its row 'MuJoCo step' (T the "
                 "part's automatic contact time). TV: total variation from MuJoCo; noise: the "
                 "95th percentile of the TV that sampling alone gives at these counts were "
                 "the engine and MuJoCo to agree (redraws from their pooled shares), a TV "
                 "above it marked *. Unsettled drops are in no class.\n\n"
                 % (a.n, a.mj_n or a.n, a.seed))
    lines.append("| part | class | " + " | ".join(label[c] for c in cols) + " |\n")
    lines.append("|---|---|" + "---|" * len(cols) + "\n")
    for name, resting, classes, counts, results, n, st, ks in table:
        for c in classes:
            cells = []
            for e in cols:
                k, ne = counts[e].get(c, 0), len(results[e][0])
                lo, hi = wilson(k, ne)
                cells.append("%.3f +- %.3f" % (k / ne, (hi - lo) / 2))
            lines.append("| %s | %s | %s |\n" % (name, "same face" if resting else c,
                                                  " | ".join(cells)))
        nf = len(results[fine][0])
        tvs = []
        for e in ENGINES:
            t = tvn(counts[e], n, counts[fine], nf)
            z = noise_tv(counts[e], n, counts[fine], nf)
            tvs.append("%.3f%s (noise %.3f)" % (t, "*" if t > z else "", z))
        tvs.append("-")
        uns = [str(sum(1 for x in results[e][0] if x == 0)) for e in cols]
        ms = ["%.3g" % results[e][1] for e in cols]
        lines.append("| %s | TV to MuJoCo | %s |\n" % (name, " | ".join(tvs)))
        lines.append("| %s | unsettled | %s |\n" % (name, " | ".join(uns)))
        lines.append("| %s | CPU ms per drop | %s |\n" % (name, " | ".join(ms)))
        lines.append("| %s | MuJoCo step | %s | T/%d |\n"
                     % (name, " | ".join("" for _ in ENGINES), ks[0]))
    if all(len(r[7]) < 2 for r in table):
        return "".join(lines)
    lines.append("\nMuJoCo's step against the contact time T, on the first %d releases: "
                 "the total variation between successive steps, the drops whose outcome "
                 "changed, and the TV's noise bound: its 95th percentile when each pair of "
                 "outcomes that differs is put in random order (what a step that only "
                 "reshuffled chaotic outcomes would show); a TV above it marked *.\n\n"
                 % a.check_n)
    lines.append("| part | steps | TV | noise | outcomes changed |\n|---|---|---|---|---|\n")
    for name, resting, classes, counts, results, n, st, ks in table:
        part = PARTS_SEEN[name]
        for i in range(len(ks) - 1):
            ea = "mujoco" if i == 0 else "mujoco %d" % i
            oa, ob = results[ea][0], results["mujoco %d" % (i + 1)][0]
            k = min(len(oa), len(ob))
            ca = outcome_table(part, oa[:k], resting, st[:k])
            cb = outcome_table(part, ob[:k], resting, st[:k])
            t = tv(ca, cb, k)
            z = swap_noise(oa[:k], ob[:k], part, resting, st[:k])
            changed = sum(1 for x, y in zip(oa, ob) if x != y)
            lines.append("| %s | T/%d to T/%d | %.3f%s | %.3f | %d of %d |\n"
                         % (name, ks[i], ks[i + 1], t, "*" if t > z else "", z, changed, k))
    return "".join(lines)


if __name__ == "__main__":
    sys.exit(main())
