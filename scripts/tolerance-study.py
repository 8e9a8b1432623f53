#!/usr/bin/env python3
"""tolerance-study.py: the impulse engine's numerical tolerances, each tightened and loosened.

The impulse engine's tolerances are compile-time constants (src/*/..._tol.h,
include/posedrop/tolerances.h), deliberately not settings. This script
builds, for each tolerance of TOLS and each factor of --factors (default 0.1
and 10), a posedrop whose only change is that constant times the factor (a
copy of src/, include/ and the Makefile with the one #define edited, built
from a copy of build/opt so that only what includes the header recompiles),
drops each part of the corpus below on it, and compares the pose classes
(--group) with the default build's on the same releases (same seed):

  - each class's share, and the total variation (TV) to the default;
  - its noise bound: the 95th percentile of the TV when each drop whose
    outcome differs between the two runs has its pair of outcomes swapped
    at random (the two runs are paired, drop by drop; if the tolerance
    only reshuffled chaotic outcomes within one distribution, the pairs
    would be exchangeable, so a TV above this bound is a real shift);
  - the drops whose outcome changed, and the CPU seconds per drop.

  scripts/tolerance-study.py [-n DROPS] [--seed S] [--tols A,B] [--parts a,b]
      [--factors 0.1,10] [-o DIR] [-r] [--doc FILE]

Parts: bushing (parts/flanged_bushing.off, mm, from scripts/make-bushing.py),
hexnut (parts/hexnut.obj, mm), button (parts/white_button.off); uniform
starts, the default scene. Runs go to DIR/runs/ (default
results/tolerances), one trials file per variant and part with its command
and commit in DIR/runs/NAME.json; -r reuses the runs already there (only
the missing ones are built and run), so the table can be remade without
rebuilding. --doc FILE puts the tables between '<!-- tolerance-study begin -->'
and '<!-- tolerance-study end -->' of FILE, with this command, its date and
the runs' commits. Needs make all first (build/opt). Python 3 standard
library only.
"""
import argparse
import csv
import json
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT  # noqa: E402

# (header, macro, what it bounds): the integrators' error, event location and
# rest detection of the impulse engine.
TOLS = [
    ("src/dynamics/dynamics_tol.h", "PD_TOL_IMPACT_REL",
     "impact search: height of the lowest vertex at the found impact"),
    ("src/impact/impact_tol.h", "PD_TOL_IMPACT_ODE_REL",
     "collision law: sliding ODE's local error (rk8pd)"),
    ("src/impact/impact_tol.h", "PD_TOL_IMPACT_EVENT_REL",
     "collision law: stick, maximum compression, end of restitution"),
    ("src/contact/contact_tol.h", "PD_TOL_PHASE_ODE_REL",
     "contact phases: integrator's local error (rkck)"),
    ("src/contact/contact_tol.h", "PD_TOL_PHASE_EVENT_REL",
     "contact phases: hand-over before an event"),
    ("src/contact/contact_tol.h", "PD_TOL_PHASE_SLIP_REL",
     "contact phases: slip at which a phase ends"),
    ("src/contact/contact_tol.h", "PD_COMPLIANT_E_TOL",
     "compliant impacts: rebound error that sets the step"),
    ("src/contact/contact_tol.h", "PD_COMPLIANT_SWEEP_TOL",
     "compliant impacts: friction sweeps' convergence"),
    ("src/sim/sim_tol.h", "PD_TOL_APPROACH_REL",
     "rest: slower approach is resting, not colliding"),
    ("src/sim/sim_tol.h", "PD_REST_TURN_REL",
     "rest: energy a rest step's return may add"),
    ("include/posedrop/tolerances.h", "PD_TOL_REST_FALL_REL",
     "rest: fall per rest step, and the energy test's margin"),
]

PARTS = {
    "bushing": ["--units", "mm", "parts/flanged_bushing.off"],
    "hexnut": ["--units", "mm", "parts/hexnut.obj"],
    "button": ["parts/white_button.off"],
}
LABEL = {"bushing": "flanged bushing", "hexnut": "hex nut", "button": "white button"}


def say(msg):
    sys.stderr.write("tolerance-study: %s\n" % msg)
    sys.stderr.flush()


def define_re(macro):
    return re.compile(r"^#define %s ([0-9.eE+-]+)[ \t]*$" % re.escape(macro), re.M)


def default_value(header, macro):
    text = open(os.path.join(ROOT, header)).read()
    found = define_re(macro).findall(text)
    if len(found) != 1:
        sys.exit("tolerance-study: %s: expected one '#define %s NUMBER' line, found %d"
                 % (header, macro, len(found)))
    return float(found[0])


def variant_name(macro, factor):
    return "default" if macro is None else "%s-x%g" % (macro, factor)


def build_variant(header, macro, factor, outdir):
    """A posedrop with macro times factor; its path under outdir/bin."""
    name = variant_name(macro, factor)
    exe = os.path.join(outdir, "bin", name, "posedrop")
    if os.path.exists(exe):
        return exe
    work = os.path.join(outdir, "build-tmp")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "build"))
    for x in ("src", "include", "Makefile"):
        src = os.path.join(ROOT, x)
        if os.path.isdir(src):
            shutil.copytree(src, os.path.join(work, x), symlinks=True)
        else:
            shutil.copy2(src, os.path.join(work, x))
    # The built objects with their times, so that make rebuilds only what
    # includes the edited header.
    shutil.copytree(os.path.join(ROOT, "build", "opt"), os.path.join(work, "build", "opt"),
                    symlinks=True)
    path = os.path.join(work, header)
    text = open(path).read()
    value = default_value(header, macro) * factor
    text, k = define_re(macro).subn("#define %s %.17g" % (macro, value), text)
    assert k == 1
    with open(path, "w") as f:
        f.write(text)
    say("building %s (%s = %.3g)" % (name, macro, value))
    p = subprocess.run(["make", "-C", work, "build/opt/posedrop"], stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("tolerance-study: building %s failed:\n%s" % (name, p.stdout[-3000:]))
    os.makedirs(os.path.dirname(exe), exist_ok=True)
    with open(os.path.join(os.path.dirname(exe), "build.log"), "w") as f:
        f.write(p.stdout)
    shutil.copy2(os.path.join(work, "build", "opt", "posedrop"), exe)
    shutil.rmtree(work)
    return exe


def cpu_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_part(exe, name, part, n, seed, outdir, reuse):
    """The classes of each drop (0 unsettled) and the CPU seconds per drop."""
    runs = os.path.join(outdir, "runs")
    os.makedirs(runs, exist_ok=True)
    trials = os.path.join(runs, "%s.%s.trials.csv" % (name, part))
    meta = os.path.join(runs, "%s.%s.json" % (name, part))
    if not (reuse and os.path.exists(meta) and os.path.exists(trials)
            and json.load(open(meta))["n"] == n and json.load(open(meta))["seed"] == seed):
        args = ["-n", str(n), "--seed", str(seed), "--group", "-j", "1", "--trials", trials] + [
            os.path.join(ROOT, w) if w.startswith("parts/") else w for w in PARTS[part]]
        c0 = cpu_children()
        script_util.run([exe] + args, "tolerance-study")
        cpu = cpu_children() - c0
        commit, changed = script_util.commit_here()
        with open(meta, "w") as f:
            json.dump({"variant": name, "part": part, "n": n, "seed": seed,
                       "command": "posedrop " + " ".join(
                           os.path.relpath(w, ROOT) if w.startswith(ROOT + "/") else w
                           for w in args),
                       "commit": commit + changed, "cpu_s_per_drop": cpu / n}, f)
    m = json.load(open(meta))
    with open(trials) as f:
        out = [int(r["pose"]) if r["end"] == "settled" else 0 for r in csv.DictReader(f)]
    return out, m


def shares(outcomes):
    n = len(outcomes)
    c = {}
    for x in outcomes:
        c[x] = c.get(x, 0) + 1
    return {k: v / n for k, v in c.items()}


def tv(a, b):
    pa, pb = shares(a), shares(b)
    return 0.5 * sum(abs(pa.get(k, 0.0) - pb.get(k, 0.0)) for k in set(pa) | set(pb))


def paired_noise(a, b, redraws=2000, seed=1):
    """95th percentile of the TV between a and b with each discordant pair
    of outcomes swapped at random."""
    rng = random.Random(seed)
    pairs = [(x, y) for x, y in zip(a, b) if x != y]
    n = len(a)
    out = []
    for _ in range(redraws):
        d = {}
        for x, y in pairs:
            if rng.random() < 0.5:
                x, y = y, x
            d[x] = d.get(x, 0) + 1
            d[y] = d.get(y, 0) - 1
        out.append(0.5 * sum(abs(v) for v in d.values()) / n)
    out.sort()
    return out[int(0.95 * len(out))] if out else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-n", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--tols", default="", help="macros to vary (default: all of TOLS)")
    ap.add_argument("--parts", default=",".join(PARTS))
    ap.add_argument("--factors", default="0.1,10")
    ap.add_argument("-o", default=os.path.join(ROOT, "results", "tolerances"))
    ap.add_argument("-r", action="store_true", help="reuse the runs already in -o")
    ap.add_argument("--doc")
    a = ap.parse_args()
    tols = [t for t in TOLS if not a.tols or t[1] in a.tols.split(",")]
    if a.tols and len(tols) != len(a.tols.split(",")):
        sys.exit("tolerance-study: unknown tolerance in %s (%s)"
                 % (a.tols, ", ".join(t[1] for t in TOLS)))
    parts = a.parts.split(",")
    for p in parts:
        if p not in PARTS:
            sys.exit("tolerance-study: unknown part %r (%s)" % (p, ", ".join(PARTS)))
    factors = [float(x) for x in a.factors.split(",")]
    base = os.path.join(ROOT, "build", "opt", "posedrop")
    if not os.access(base, os.X_OK):
        sys.exit("tolerance-study: %s not built (make all)" % base)
    res = {}
    for part in parts:
        say("%s on the default build" % part)
        res[("default", part)] = run_part(base, "default", part, a.n, a.seed, a.o, a.r)
    for header, macro, _ in tols:
        for f in factors:
            name = variant_name(macro, f)
            need = [p for p in parts if not (a.r and os.path.exists(
                os.path.join(a.o, "runs", "%s.%s.json" % (name, p))))]
            exe = build_variant(header, macro, f, a.o) if need else None
            for part in parts:
                say("%s on %s" % (part, name))
                res[(name, part)] = run_part(exe, name, part, a.n, a.seed, a.o, a.r)
    text = tables(res, tols, parts, factors, a)
    sys.stdout.write(text)
    if a.doc:
        script_util.put_between(a.doc, "tolerance-study", "\n" + text + "\n", "tolerance-study")
    return 0


def tables(res, tols, parts, factors, a):
    commit, changed = script_util.commit_here()
    cmd = "scripts/tolerance-study.py " + " ".join(
        os.path.relpath(w, ROOT) if w.startswith(ROOT + "/") else w for w in sys.argv[1:])
    commits = sorted(set(m["commit"] for _, m in res.values()))
    out = ["Made by `%s` on %s (commit %s%s) from runs on commit%s %s; %d uniform drops per "
           "run, seed %d, `--group`, default scene. Each row is a build whose only change "
           "is that tolerance times the factor; TV: total variation to the default build's "
           "classes on the same releases; noise: the 95th percentile of that TV with each "
           "drop whose outcome changed given its two outcomes in random order (a TV above "
           "it is a shift, not a reshuffle); changed: drops ending in another class than "
           "on the default build; CPU: seconds of user + sys per drop on one thread, on "
           "the shared 2-core machine (under load; ratios to the default are what "
           "count).\n\n"
           % (cmd.strip(), time.strftime("%Y-%m-%d", time.gmtime()), commit, changed,
              "s" if len(commits) > 1 else "", ", ".join(commits), a.n, a.seed)]
    for part in parts:
        d, dm = res[("default", part)]
        classes = sorted(set(x for (v, p), (o, _) in res.items() if p == part for x in o))
        head = ["tolerance", "value"] + [("class %d" % c) if c else "unsettled"
                                         for c in classes] + ["TV", "noise", "changed",
                                                              "CPU ms / drop"]
        out.append("%s (%s):\n\n" % (LABEL[part], " ".join(PARTS[part])))
        out.append("| " + " | ".join(head) + " |\n|" + "---|" * len(head) + "\n")

        def row(label, value, o, m):
            s = shares(o)
            cells = ["%.3f" % s.get(c, 0.0) for c in classes]
            if o is d:
                extra = ["-", "-", "-"]
            else:
                t, nz = tv(o, d), paired_noise(o, d)
                ch = sum(1 for x, y in zip(o, d) if x != y)
                # (t and nz are sums of the same counts over n, rounded
                # apart: a shift is a TV above the bound by a drop at least.)
                shift = t > nz + 0.5 / len(d)
                extra = ["%.3f%s" % (t, " **shift**" if shift else ""), "%.3f" % nz,
                         "%d" % ch]
            return "| %s | %s | %s | %s | %.3g |\n" % (
                label, value, " | ".join(cells), " | ".join(extra),
                1000 * m["cpu_s_per_drop"])
        out.append(row("(default build)", "", d, dm))
        for header, macro, _ in tols:
            v0 = default_value(header, macro)
            for f in factors:
                o, m = res[(variant_name(macro, f), part)]
                out.append(row("`%s` x %g" % (macro, f), "%.3g" % (v0 * f), o, m))
        out.append("\n")
    out.append("What each tolerance bounds:\n\n")
    out += ["- `%s` (`%s`, %.3g): %s\n" % (macro, header, default_value(header, macro), what)
            for header, macro, what in tols]
    return "".join(out)


if __name__ == "__main__":
    sys.exit(main())
