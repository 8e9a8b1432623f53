#!/usr/bin/env python3
"""trust.py: how far a result of posedrop can be trusted, measured on the paper's parts.

For each of the paper's four parts (parts/insulator_cap.off, white_button,
rect_black_button, square_black_button), by pose class (--group), on the
paper's belt (--initial stationary, the paper's scene), -n drops (2000):

  sampling  the widest 95% interval (half-width, points) of the impulse
            engine's p;
  scene     with mu 0.2:0.6, restitution 0.1:0.5, height 0.08:0.16 m and
            contact time 0.3x:3x drawn per drop (docs/uncertainty.md's
            example), the largest move of a class between the lower and
            upper third of one parameter's range (--sensitivity);
  model     the largest range across the three engines on a class
            (--crosscheck: p_engine_max - p_engine_min), and on how many
            classes the engines' 95% intervals are apart;
  measured  the total variation between the impulse engine's p and the
            paper's physical tests (parts/paper-tables.csv, paired with
            posedrop's classes as scripts/measured.awk pairs them).

--runs DIR takes the three engines' runs from scripts/paper.sh's output
directory (the same drops: paper.sh runs each engine at seed 1 on the
belt, -n as given here) instead of running --crosscheck again: the stepping
engines' runs are most of the cost. The code that made them is paper.sh's
commit, not necessarily this one's.

Prints a table; --doc FILE puts it, with the command and commit, between
'<!-- trust-table begin -->' and '<!-- trust-table end -->' of FILE, and
--readme FILE a short paragraph between '<!-- trust begin -->' and
'<!-- trust end -->'.

  scripts/trust.py [-n DROPS] [--seed S] [--runs DIR] [--doc docs/validation.md]
      [--readme README.md]

Python 3 standard library only; posedrop must be built (make all).
"""
import argparse
import os
import sys
import tempfile
import textwrap
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT, rows  # noqa: E402
PARTS = ["insulator_cap", "white_button", "rect_black_button", "square_black_button"]
RANGES = ["--mu", "0.2:0.6", "--restitution", "0.1:0.5", "-h", "0.08:0.16",
          "--contact-time", "0.3x:3x"]


def run(cmd):
    return script_util.run(cmd, "trust.py")


RUN_COMMITS = set()   # --runs: the commits of the stepping engines' runs (paper.sh's)


def engines_from(runs, name, n, seed):
    """--crosscheck's rows rebuilt from make paper's three runs of the part
    (RUNS/NAME.ENGINE.csv, the same drops: --group, the belt, the seed it
    printed): p and its interval the impulse engine's, the engines' range
    and whether two engines' 95% intervals are apart."""
    got = {}
    for e in ("impulse", "ode", "bullet"):
        path = os.path.join(runs, "%s.%s.csv" % (name, e))
        if not os.path.exists(path):
            sys.exit("trust.py: %s missing (run scripts/paper.sh -o %s)" % (path, runs))
        text = open(path).read()
        got[e] = {r["pose"]: r for r in rows(text)}
        if e != "impulse":
            RUN_COMMITS.update(l.split()[2].rstrip(",") for l in text.splitlines()
                               if l.startswith("# commit "))
        if any(int(r["n"]) != n for r in got[e].values()):
            sys.exit("trust.py: %s is not of %d drops (give -n as paper.sh had it)" % (path, n))
    if seed != 1:
        sys.exit("trust.py: --runs: paper.sh's runs are of seed 1")
    xc = []
    for pose, r in got["impulse"].items():
        ps = [float(got[e][pose]["p"]) for e in got]
        lo = [float(got[e][pose]["ci_lo"]) for e in got]
        hi = [float(got[e][pose]["ci_hi"]) for e in got]
        xc.append(dict(r, p_engine_min=min(ps), p_engine_max=max(ps),
                       engines_disagree=int(min(hi) < max(lo))))
    return xc


def measure(exe, name, n, seed, tmp, runs):
    part = os.path.join(ROOT, "parts", name + ".off")
    base = [exe, "--group", "--initial", "stationary", "-n", str(n), "--seed", str(seed)]
    if runs:
        xc = engines_from(runs, name, n, seed)
    else:
        xc = rows(run(base + ["--crosscheck", part]))
    sens_file = os.path.join(tmp, name + ".sens.csv")
    run(base + RANGES + ["--sensitivity", sens_file, part])
    sens = rows(open(sens_file).read())
    grouped = os.path.join(tmp, name + ".grouped.csv")
    with open(grouped, "w") as f:
        f.write(run([exe, "--group", part]))
    meas = rows(run(["awk", "-F,", "-v", "part=" + name, "-v", "tag=trust.py", "-f",
                     os.path.join(ROOT, "scripts/measured.awk"),
                     os.path.join(ROOT, "parts/paper-tables.csv"), grouped]))
    total = sum(int(r["count"]) for r in meas)
    m = {int(r["pose"]): int(r["count"]) / total for r in meas}
    half = max((float(r["ci_hi"]) - float(r["ci_lo"])) / 2 for r in xc)
    spread = max(float(r["p_engine_max"]) - float(r["p_engine_min"]) for r in xc)
    apart = sum(int(r["engines_disagree"]) for r in xc)
    shift, which = max((abs(float(r["p_high"]) - float(r["p_low"])), r["parameter"])
                       for r in sens)
    tv = 0.5 * sum(abs(float(r["p"]) - m.get(int(r["pose"]), 0.0)) for r in xc)
    return {"part": name, "classes": len(xc), "half": half, "shift": shift, "which": which,
            "spread": spread, "apart": apart, "tv": tv}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--posedrop", default=os.path.join(ROOT, "build/opt/posedrop"))
    ap.add_argument("-n", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--doc")
    ap.add_argument("--readme")
    ap.add_argument("--runs", help="make paper's output directory (scripts/paper.sh -o DIR, "
                    "the same -n): its three engines' runs instead of --crosscheck's")
    a = ap.parse_args()
    if not os.access(a.posedrop, os.X_OK):
        sys.exit("trust.py: %s not found: run make all first" % a.posedrop)
    commit, dirty = script_util.commit_here()
    with tempfile.TemporaryDirectory() as tmp:
        res = []
        for name in PARTS:
            sys.stderr.write("trust.py: %s\n" % name)
            res.append(measure(a.posedrop, name, a.n, a.seed, tmp, a.runs))
    cmd = "scripts/trust.py " + " ".join(sys.argv[1:])
    when = time.strftime("%Y-%m-%d", time.gmtime())
    made = "Made by `%s` on %s (commit %s%s%s)." % (
        cmd.strip(), when, commit, dirty,
        "; ODE's and Bullet's runs made by `scripts/paper.sh` at commit %s"
        % ", ".join(sorted(RUN_COMMITS)) if RUN_COMMITS else "")
    lines = [made + " Points are percentage points of a class's probability; %d drops "
             "per run, the paper's belt (`--initial stationary`), seed %d.\n\n" % (a.n, a.seed),
             "| part | classes | sampling: widest 95% interval, +- | scene: largest move "
             "over a range (parameter) | model: widest range across engines | classes "
             "with engines apart | TV to the physical tests |\n",
             "|---|---|---|---|---|---|---|\n"]
    for r in res:
        lines.append("| %s | %d | %.1f | %.1f (%s) | %.1f | %d | %.1f |\n"
                     % (r["part"], r["classes"], 100 * r["half"], 100 * r["shift"], r["which"],
                        100 * r["spread"], r["apart"], 100 * r["tv"]))
    table = "".join(lines)
    sys.stdout.write(table)

    def span(key):
        lo, hi = min(100 * r[key] for r in res), max(100 * r[key] for r in res)
        return "%.0f" % hi if "%.0f" % lo == "%.0f" % hi else "%.0f to %.0f" % (lo, hi)

    apart = sum(r["apart"] for r in res)
    classes = sum(r["classes"] for r in res)
    para = ("**How far to trust p.** On the paper's four parts (`scripts/trust.py`, %s, "
            "commit %s%s%s; %d drops, its belt): the 95%% intervals reach %s points either "
            "side (more drops narrow them); the scene's plausible ranges move a class by up "
            "to %s points (`--sensitivity`); the three engines differ by up to %s points, "
            "beyond their intervals on %d of %d classes (`--crosscheck`); the physical tests "
            "are %s%% away in total variation ([docs/validation.md](docs/validation.md)). "
            "Differences below these are not findings.\n"
            % (when, commit, dirty,
               "; ODE and Bullet from `paper.sh` at %s" % ", ".join(sorted(RUN_COMMITS))
               if RUN_COMMITS else "", a.n, span("half"), span("shift"), span("spread"), apart,
               classes, span("tv")))
    para = "\n".join(textwrap.wrap(para, 78, break_long_words=False, break_on_hyphens=False)) + "\n"
    sys.stdout.write("\n" + para)
    if a.doc:
        script_util.put_between(a.doc, "trust-table", table, "trust.py")
    if a.readme:
        script_util.put_between(a.readme, "trust", para, "trust.py")
    return 0


if __name__ == "__main__":
    sys.exit(main())
