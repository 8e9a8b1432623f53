#!/usr/bin/env python3
"""cube-first-contact.py: the resting cube's first landing on every engine and in MuJoCo.

The cross-check corpus's resting cube (parts/canonical/cube.off, posedrop's
--initial stationary drops that start resting on a face: tilted by up to the
scene's vibration, lowest point at the drop height) either lands back on the
face it started on or tips. For the first N such releases of seed S this
script traces each drop's first contact on posedrop's engines (--trace, one
run per drop) and in MuJoCo at several steps (scripts/referee-mujoco.py's
model: the same release, law, friction and decision), and reports per engine:

  - the rebound: the centre's vertical speed after the first contact
    episode over the speed it arrived with;
  - the spin about a horizontal axis after it, |w_h| (rad/s);
  - the drops whose first flight after it turns the cube past 45 degrees,
    |w_h| 2 v_z / g > pi / 4: it then comes down nearer another face than
    its own (the flight's closed form, the spin constant in flight);
  - the drops that end on the face they started on.

and the closed forms that frame them: the energy a cube of side a resting on
a face needs to tip over an edge, (sqrt(2) - 1) m g a / 2, against the m g h
the drop gives it.

  .venv/bin/python scripts/cube-first-contact.py [-n N] [--seed S]
      [--engines impulse,ode,bullet] [--steps 20,40,80,160] [--doc FILE]

--doc FILE puts the table, with the command and commit, between
'<!-- cube-first-contact begin -->' and '<!-- cube-first-contact end -->'.
Needs the mujoco package (python3 -m venv .venv && .venv/bin/pip install
mujoco numpy) and make all.
"""
import argparse
import csv
import importlib.util
import math
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT  # noqa: E402


def load(name, file):
    spec = importlib.util.spec_from_file_location(name, os.path.join(ROOT, "scripts", file))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


REF = load("referee_mujoco", "referee-mujoco.py")
TRC = load("trace_compare", "trace-compare.py")   # its trace reader
CUBE = os.path.join(ROOT, "parts", "canonical", "cube.off")


def first_episode(rows):
    """The approach speed and the row after the first contact episode (the
    impulse engine's first row in contact is the flight's end, the stepping
    engines' the first step in contact: the faster of it and the row before)."""
    i = next(k for k, r in enumerate(rows) if r["contacts"] > 0 and r["event"] != "release")
    # The landing ends at the first row after it with the centre rising and
    # no vertex in contact (a corner may leave the floor before the face
    # lands), or, on the impulse engine, at the impact whose row (the state
    # after it, a vertex still at the floor) has the centre rising.
    j = next((k for k in range(i + 1, len(rows)) if rows[k]["vz"] > 0 and (
        rows[k]["contacts"] == 0 or rows[k]["event"] in ("impact", "compliant"))),
        len(rows) - 1)
    return max(-rows[i - 1]["vz"], -rows[i]["vz"]), rows[j]


def posedrop_first(exe, engine, i, k1, seed, tmp):
    """The first contact of drop i on engine, and the pose it ended in."""
    n = max(k1 * 10, k1 * (i // k1 + 1))
    trace = os.path.join(tmp, "trace.csv")
    trials = os.path.join(tmp, "trials.csv")
    script_util.run([exe, "-n", str(n), "--seed", str(seed), "--engine", engine,
                     "--initial", "stationary", "--trace", trace, "--trace-drop", str(i),
                     "--trials", trials, "-j", "1", CUBE], "cube-first-contact")
    rows = TRC.read(trace)
    pose = int(list(csv.DictReader(open(trials)))[i]["pose"])
    vin, after = first_episode(rows)
    return vin, after["vz"], math.hypot(after["wx"], after["wy"]), pose


def mujoco_first(ref, q):
    """The same from the release q in MuJoCo, and the pose the drop ends in."""
    mj, m, d = ref.mj, ref.model, ref.release(q)
    vin = None
    while True:
        v = float(d.qvel[2])
        mj.mj_step(m, d)
        if d.ncon > 0 and vin is None:
            vin = -v
        if vin is not None and d.ncon == 0 and d.qvel[2] > 0:
            break
    # A free joint's angular velocity is in the body's frame.
    R = d.xmat[1].reshape(3, 3)
    w = R @ d.qvel[3:6]
    vout = float(d.qvel[2])
    pose, _ = ref.drop(q)
    return vin, vout, math.hypot(w[0], w[1]), pose


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--posedrop", default=os.path.join(ROOT, "build/opt/posedrop"))
    ap.add_argument("-n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--engines", default="impulse,ode,bullet")
    ap.add_argument("--steps", default="20,40,80,160")
    ap.add_argument("--doc")
    a = ap.parse_args()
    import mujoco
    commit, changed = script_util.commit_here()
    part = REF.Part(a.posedrop, CUBE, "m", [])
    sc = part.scene
    g, h, T = sc["gravity_m_s2"], sc["height_m"], sc["contact_time_s"]
    k1 = len(part.poses) + 1
    drops = [i for i in range(10 * k1 * (a.n // (k1 - 1) + 1)) if i % k1][:a.n]
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        # The releases, from the impulse engine's trials (every engine's are the same).
        trials = os.path.join(tmp, "releases.csv")
        ndrops = k1 * (drops[-1] // k1 + 1)
        script_util.run([a.posedrop, "-n", str(max(ndrops, 10 * k1)), "--seed", str(a.seed),
                         "--initial", "stationary", "--trials", trials, CUBE],
                        "cube-first-contact")
        rel = list(csv.DictReader(open(trials)))
        for engine in a.engines.split(","):
            c0 = time.process_time()
            got = [posedrop_first(a.posedrop, engine, i, k1, a.seed, tmp) for i in drops]
            results.append((engine, got))
            sys.stderr.write("cube-first-contact: %s done (%.0f s)\n"
                             % (engine, time.process_time() - c0))
        for K in [int(k) for k in a.steps.split(",")]:
            ref = REF.Referee(mujoco, part, T / K)
            got = [mujoco_first(ref, tuple(float(rel[i][c]) for c in ("qw", "qx", "qy", "qz")))
                   for i in drops]
            results.append(("MuJoCo T/%d" % K, got))
            sys.stderr.write("cube-first-contact: MuJoCo T/%d done\n" % K)
    a_side = 0.01   # the canonical cube's side, m
    barrier = (math.sqrt(2) - 1) * g * a_side / 2
    cmd = "scripts/cube-first-contact.py " + " ".join(sys.argv[1:])
    out = ["Made by `%s` on %s (commit %s%s); MuJoCo %s.\n\n"
           % (cmd.strip(), time.strftime("%Y-%m-%d", time.gmtime()), commit, changed,
              mujoco.__version__),
           "The 1 cm cube started resting on a face (seed %d, the first %d releases that "
           "start resting; h = %g m, T = %g s, e = %g, mu = %g, vibration %.3g degrees): "
           "the energy to tip over an edge, (sqrt(2) - 1) g a / 2 = %.4f J/kg, is %.1f "
           "times below the g h = %.3f J/kg of the fall, so energy alone allows a tip; "
           "what decides is the spin the first landing leaves, a flight of 2 v_z / g "
           "turning the cube by |w_h| 2 v_z / g (past 45 degrees: 'turns past'). "
           "Means over the drops, the largest spin, and the counts:\n\n"
           % (a.seed, a.n, h, T, sc["restitution"], sc["mu"],
              math.degrees(sc["vibration_rad"]), barrier, g * h / barrier, g * h),
           "| engine | rebound v_z / approach | spin after, mean (rad/s) | largest | "
           "turns past 45 degrees | ends on its face |\n|---|---|---|---|---|---|\n"]
    for name, got in results:
        reb = sum(vo / vi for vi, vo, _, _ in got) / len(got)
        wm = sum(w for _, _, w, _ in got) / len(got)
        wx = max(w for _, _, w, _ in got)
        past = sum(1 for _, vo, w, _ in got if w * 2 * max(vo, 0.0) / g > math.pi / 4)
        kept = sum(1 for (_, _, _, p), i in zip(got, drops) if p == i % k1)
        out.append("| %s | %.3f | %.2f | %.2f | %d of %d | %d of %d |\n"
                   % (name, reb, wm, wx, past, len(got), kept, len(got)))
    text = "".join(out)
    sys.stdout.write(text)
    if a.doc:
        script_util.put_between(a.doc, "cube-first-contact", "\n" + text + "\n",
                                "cube-first-contact")
    return 0


if __name__ == "__main__":
    sys.exit(main())
