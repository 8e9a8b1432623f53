#!/usr/bin/env python3
"""engine-convergence.py: the stepping engines' pose classes against their step.

For each part and engine, runs posedrop's drops (--group, uniform starts, one
seed) at a series of steps given as steps per contact (dt = T / k, T the
scene's contact time for that part) and writes one CSV row per part, engine,
step and class:

  part,engine,k,dt,n,class,p,cpu_s_per_drop,unsettled

then a summary per part and engine: the total variation between successive
steps and its sampling noise (the TV two runs of the same distribution show
at these n, by multinomial redraws), and the TV to the impulse engine's run of
the same drops (engine "impulse", k ignored). k "auto" runs --dt auto.

The part cube_resting is the 1 cm cube (parts/canonical/cube.off) started
resting on a face (--initial stationary's resting drops, the uniform ones
left out, n of them kept): class 1 is the share that ends on the face it
started on, class 2 on another face; it is run only when --parts names it.

Usage:
  scripts/engine-convergence.py -o DIR [-n DROPS] [--seed S] [--engines ode,bullet]
      [--k 10,20,40] [--parts NAME,...] [--summary-only]

CPU seconds (user+sys of the posedrop process) are the cost; wall time is
not reported. The command line and the commit go in DIR/README.txt.
Python 3 standard library only; posedrop must be built (make all).
"""

import argparse
import csv
import io
import json
import math
import os
import random
import resource
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)



def corpus():
    """The cross-check corpus: name -> posedrop arguments for the part."""
    parts = os.path.join(ROOT, "parts")
    return {
        "flanged_bushing": ["--units", "mm", os.path.join(parts, "flanged_bushing.off")],
        "hexnut": ["--units", "mm", os.path.join(parts, "hexnut.obj")],
        "box_1x2x3cm": [os.path.join(parts, "canonical", "box_1x2x3.off")],
        "white_button": [os.path.join(parts, "white_button.off")],
        "insulator_cap": [os.path.join(parts, "insulator_cap.off")],
        "cube_resting": ["--initial", "stationary", os.path.join(parts, "canonical", "cube.off")],
    }


# Parts started resting on a pose: classes are "kept the pose" (1) or not (2).
RESTING = {"cube_resting"}


def posedrop():
    return os.environ.get("POSEDROP", os.path.join(ROOT, "build", "opt", "posedrop"))


def run(args):
    """posedrop's stdout and the CPU seconds it took (user + sys)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([posedrop()] + args, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit("engine-convergence.py: posedrop %s failed: %s" % (" ".join(args), p.stderr))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return p.stdout, p.stderr, cpu


def contact_time(part_args):
    args = list(part_args)
    if "--initial" in args:   # one drop is too few for a stationary start
        del args[args.index("--initial"):args.index("--initial") + 2]
    out, _, _ = run(["-n", "1", "-j", "1", "--format", "json"] + args)
    return json.loads(out)["scene"]["contact_time_s"]


def classes(out):
    """{class: share} and the unsettled drops of a posedrop output."""
    rows = list(csv.DictReader(io.StringIO(out)))
    return {int(r["pose"]): float(r["p"]) for r in rows}, int(rows[0]["unsettled"])


def resting_run(n, extra, part_args, outdir):
    """Drops started resting: posedrop's --initial stationary run's drop i
    (from 0) is uniform when i mod (k + 1) is 0 and starts resting on pose
    i mod (k + 1) otherwise, k stable poses; the first n resting ones are
    kept. {1: share ending on the pose it started on, 2: elsewhere}, the
    unsettled among them and the CPU seconds per drop run."""
    k1 = len(list(csv.DictReader(io.StringIO(run(part_args)[0])))) + 1
    # A whole number of rounds: drops past the last whole round of k + 1
    # start uniform (pd_stationary_start), not resting.
    ndrops = k1 * max(-(-n // (k1 - 1)), 10)
    trials = os.path.join(outdir, "trials.tmp.csv")
    _, _, cpu = run(["-n", str(ndrops), "--trials", trials] + extra + part_args)
    rows = list(csv.DictReader(open(trials)))
    os.remove(trials)
    kept = [r for i, r in enumerate(rows) if i % k1 != 0][:n]
    starts = [i % k1 for i in range(len(rows)) if i % k1 != 0][:n]
    lost = sum(1 for r in kept if int(r["pose"]) == 0)
    same = sum(1 for r, s in zip(kept, starts) if int(r["pose"]) == s)
    return {1: same / n, 2: (n - same - lost) / n}, lost, cpu / ndrops


def tv(p, q):
    keys = set(p) | set(q)
    return 0.5 * sum(abs(p.get(k, 0.0) - q.get(k, 0.0)) for k in keys)


def noise_tv(p, n1, n2, redraws=400, seed=1):
    """The 95th percentile of the TV between two samples of sizes n1, n2
    drawn from p: what sampling alone gives."""
    rng = random.Random(seed)
    keys = sorted(p)
    weights = [max(p[k], 0.0) for k in keys]
    if sum(weights) <= 0:
        return 0.0
    out = []
    for _ in range(redraws):
        a = rng.choices(keys, weights, k=n1)
        b = rng.choices(keys, weights, k=n2)
        pa = {k: a.count(k) / n1 for k in keys}
        pb = {k: b.count(k) / n2 for k in keys}
        out.append(tv(pa, pb))
    out.sort()
    return out[int(0.95 * len(out))]


def main():
    ap = argparse.ArgumentParser(description="the stepping engines' convergence in the step")
    ap.add_argument("-o", dest="outdir", required=True)
    ap.add_argument("-n", type=int, default=300)
    ap.add_argument("--seed", default="3")
    ap.add_argument("--engines", default="ode,bullet")
    ap.add_argument("--k", default="10,20,40")
    ap.add_argument("--parts", default="")
    ap.add_argument("--summary-only", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    parts = corpus()
    names = a.parts.split(",") if a.parts else [x for x in parts if x not in RESTING]
    table = os.path.join(a.outdir, "convergence.csv")
    if not a.summary_only:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip()
        with open(os.path.join(a.outdir, "README.txt"), "a") as f:
            f.write("command: %s\ncommit: %s\n" % (" ".join(sys.argv), commit))
        new = not os.path.exists(table)
        with open(table, "a", newline="") as f:
            w = csv.writer(f)
            if new:
                w.writerow(["part", "engine", "k", "dt", "n", "class", "p", "cpu_s_per_drop",
                            "unsettled"])
            for name in names:
                pa = parts[name]
                T = contact_time(pa)
                base = ["-n", str(a.n), "-j", "1", "--seed", a.seed, "--group"]
                for engine in a.engines.split(","):
                    for k in ["-"] if engine == "impulse" else a.k.split(","):
                        if engine == "impulse":
                            dt, extra = 0.0, []
                        elif k == "auto":
                            dt, extra = 0.0, ["--engine", engine, "--dt", "auto"]
                        else:
                            dt = T / float(k)
                            extra = ["--engine", engine, "--dt", "%.9g" % dt]
                        if name in RESTING:
                            shares, lost, per = resting_run(
                                a.n, ["-j", "1", "--seed", a.seed] + extra, pa, a.outdir)
                        else:
                            out, _, cpu = run(base + extra + pa)
                            shares, lost = classes(out)
                            per = cpu / a.n
                        for c, p in sorted(shares.items()):
                            w.writerow([name, engine, k, "%.6g" % dt, a.n, c, "%.6g" % p,
                                        "%.4g" % per, lost])
                        f.flush()
                        print("engine-convergence.py: %s %s k=%s done, %.4g s CPU per drop" %
                              (name, engine, k, per), file=sys.stderr)
    summarize(table)


def summarize(table):
    runs = {}
    order = []
    with open(table) as f:
        for r in csv.DictReader(f):
            key = (r["part"], r["engine"], r["k"])
            if key not in runs:
                runs[key] = {"n": int(r["n"]), "cpu": float(r["cpu_s_per_drop"]), "p": {},
                             "unsettled": int(r["unsettled"])}
                order.append(key)
            runs[key]["p"][int(r["class"])] = float(r["p"])
    print("part,engine,k,n,cpu_s_per_drop,unsettled,tv_prev,noise95_prev,tv_impulse,noise95_impulse,"
          "classes")
    prev = None
    for key in order:
        part, engine, k = key
        r = runs[key]
        tvp = noisep = tvi = noisei = ""
        if prev and prev[0] == part and prev[1] == engine:
            q = runs[prev]
            tvp = "%.3f" % tv(r["p"], q["p"])
            noisep = "%.3f" % noise_tv(r["p"], r["n"], q["n"])
        imp = [x for x in order if x[0] == part and x[1] == "impulse"]
        if imp and engine != "impulse":
            q = runs[imp[0]]
            tvi = "%.3f" % tv(r["p"], q["p"])
            noisei = "%.3f" % noise_tv(r["p"], r["n"], q["n"])
        cls = " ".join("%d:%.3f" % (c, p) for c, p in sorted(r["p"].items()))
        print("%s,%s,%s,%d,%.4g,%d,%s,%s,%s,%s,%s" % (part, engine, k, r["n"], r["cpu"],
                                                       r["unsettled"], tvp, noisep, tvi, noisei, cls))
        prev = key


if __name__ == "__main__":
    main()
