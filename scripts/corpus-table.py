#!/usr/bin/env python3
"""corpus-table.py: the cross-check corpus's agreement table, from engine-convergence.py's runs.

Reads the runs of scripts/engine-convergence.py in each DIR (DIR/convergence.csv
and DIR/README.txt, the command and commit of each run), keeps each part's
and engine's run at the engine's default step (k "auto"; the impulse
engine's k "-"; of several, the last DIR's), and prints in Markdown:

  - per part and stepping engine, the total variation (TV) to the impulse
    engine's run (and between the two stepping engines), its sampling noise (the 95th percentile of the TV two
    samples of these sizes drawn from one distribution show, by multinomial
    redraws from the two runs' pooled shares: what sampling alone gives
    were the engines to agree), the CPU seconds per drop of each engine, and the
    earlier figures of --earlier beside them;
  - per part, each engine's share of each class with its 95% Wilson
    interval's half-width.

The impulse engine's columns are cheap to rerun (seconds of CPU):

  scripts/engine-convergence.py -o results/corpus/impulse -n 1000 --engines impulse \\
      --parts flanged_bushing,hexnut,box_1x2x3cm,white_button,insulator_cap,cube_resting
  scripts/corpus-table.py results/corpus/ode results/corpus/bullet \\
      results/corpus/impulse --doc docs/engines-crosscheck.md

--earlier FILE (default docs/figures/corpus-earlier.csv): earlier TVs to
the impulse engine, part,engine,label,n,tv; one column per label, in the
file's order. --doc FILE puts the tables, with this command, its date and
the runs' commands and commits, between '<!-- corpus-table begin -->' and
'<!-- corpus-table end -->' of FILE.

Python 3 standard library only.
"""
import argparse
import csv
import importlib.util
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT  # noqa: E402

_spec = importlib.util.spec_from_file_location(
    "engine_convergence", os.path.join(ROOT, "scripts", "engine-convergence.py"))
ec = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ec)

ORDER = ["flanged_bushing", "hexnut", "box_1x2x3cm", "white_button", "insulator_cap",
         "cube_resting"]
LABEL = {"flanged_bushing": "flanged bushing", "hexnut": "parts/hexnut.obj (mm)",
         "box_1x2x3cm": "1 x 2 x 3 cm box", "white_button": "parts/white_button.off",
         "insulator_cap": "parts/insulator_cap.off",
         "cube_resting": "1 cm cube resting on a face"}
ENGINE = {"impulse": "impulse", "ode": "ODE", "bullet": "Bullet"}


def wilson_half(p, n, z=1.959963984540054):
    w = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return w


def pooled_noise(a, b):
    """The 95th percentile of the TV between two runs of a's and b's sizes
    drawn from their pooled shares."""
    pooled = {c: (a["n"] * a["p"].get(c, 0.0) + b["n"] * b["p"].get(c, 0.0)) / (a["n"] + b["n"])
              for c in set(a["p"]) | set(b["p"])}
    return ec.noise_tv(pooled, a["n"], b["n"], redraws=1000)


def load(dirs):
    """{(part, engine): run} at the default step, and the runs' provenance."""
    runs, prov = {}, []
    for d in dirs:
        table = os.path.join(d, "convergence.csv")
        if not os.path.exists(table):
            sys.exit("corpus-table.py: %s missing" % table)
        with open(table) as f:
            found = {}
            for r in csv.DictReader(f):
                if r["k"] not in ("auto", "-"):
                    continue
                key = (r["part"], r["engine"])
                run = found.setdefault(key, {"n": int(r["n"]), "cpu": float(r["cpu_s_per_drop"]),
                                             "unsettled": int(r["unsettled"]), "p": {}})
                run["p"][int(r["class"])] = float(r["p"])
            runs.update(found)
        readme = os.path.join(d, "README.txt")
        lines = open(readme).read().split("\n") if os.path.exists(readme) else []
        prov += [(lines[i][len("command: "):], lines[i + 1][len("commit: "):])
                 for i in range(len(lines) - 1)
                 if lines[i].startswith("command: ") and lines[i + 1].startswith("commit: ")]
    return runs, prov


def earlier(path):
    labels, tvs = [], {}
    if path and os.path.exists(path):
        with open(path) as f:
            for r in csv.DictReader(f):
                if r["label"] not in labels:
                    labels.append(r["label"])
                tvs[(r["part"], r["engine"], r["label"])] = (r["tv"], r["n"])
    return labels, tvs


def tables(runs, labels, tvs):
    out = []
    head = ["part", "engine"] + ["TV %s (n)" % x for x in labels] + [
        "TV now (n)", "noise", "beyond noise", "CPU s / drop: impulse, engine"]
    out.append("| " + " | ".join(head) + " |\n")
    out.append("|" + "---|" * len(head) + "\n")
    for part in ORDER:
        imp = runs.get((part, "impulse"))
        for engine in ("ode", "bullet"):
            r = runs.get((part, engine))
            old = []
            for x in labels:
                t = tvs.get((part, engine, x))
                old.append("%s (%s)" % t if t else "-")
            if r is None or imp is None:
                if any(c != "-" for c in old):
                    out.append("| %s | %s | %s | not run | | | |\n"
                               % (LABEL[part], ENGINE[engine], " | ".join(old)))
                continue
            t = ec.tv(r["p"], imp["p"])
            noise = pooled_noise(r, imp)
            out.append("| %s | %s | %s | %.3f (%d) | %.3f | %s | %.2g, %.2g |\n"
                       % (LABEL[part], ENGINE[engine], " | ".join(old), t, r["n"], noise,
                          "yes" if t > noise else "no", imp["cpu"], r["cpu"]))
        a, b = runs.get((part, "ode")), runs.get((part, "bullet"))
        if a and b:
            t, noise = ec.tv(a["p"], b["p"]), pooled_noise(a, b)
            out.append("| %s | Bullet to ODE | %s | %.3f (%d, %d) | %.3f | %s | |\n"
                       % (LABEL[part], " | ".join("-" for _ in labels), t, b["n"], a["n"], noise,
                          "yes" if t > noise else "no"))
    out.append("\nEach engine's share of each class (`--group` numbering, most probable "
               "first; the cube: 1 ended on the face it started on, 2 on another), "
               "with the 95% Wilson interval's half-width; unsettled drops are in no "
               "class:\n\n")
    out.append("| part | class | impulse | ODE | Bullet |\n|---|---|---|---|---|\n")
    for part in ORDER:
        have = {e: runs.get((part, e)) for e in ENGINE}
        if not any(have.values()):
            continue
        classes = sorted(set(c for r in have.values() if r for c in r["p"]))
        for c in classes:
            cells = []
            for e in ENGINE:
                r = have[e]
                if r is None:
                    cells.append("-")
                    continue
                p = r["p"].get(c, 0.0)
                cells.append("%.3f +- %.3f" % (p, wilson_half(p, r["n"])))
            out.append("| %s | %d | %s |\n" % (LABEL[part], c, " | ".join(cells)))
        lost = [str(have[e]["unsettled"]) if have[e] else "-" for e in ENGINE]
        if any(x not in ("0", "-") for x in lost):
            out.append("| %s | unsettled | %s |\n" % (LABEL[part], " | ".join(lost)))
    return "".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dirs", nargs="+", help="engine-convergence.py output directories")
    ap.add_argument("--earlier", default=os.path.join(ROOT, "docs", "figures",
                                                      "corpus-earlier.csv"))
    ap.add_argument("--doc", help="Markdown file to put the tables in, between the markers")
    a = ap.parse_args()
    runs, prov = load(a.dirs)
    labels, tvs = earlier(a.earlier)
    commit, changed = script_util.commit_here()
    cmd = "scripts/corpus-table.py " + " ".join(
        os.path.relpath(w, ROOT) if w.startswith(ROOT + "/") else w for w in sys.argv[1:])
    text = ["Made by `%s` on %s (commit %s%s) from these runs (CPU seconds are user + sys "
            "on one thread, on the shared 2-core machine):\n\n"
            % (cmd, time.strftime("%Y-%m-%d", time.gmtime()), commit, changed)]
    text += ["- `%s` (commit %s)\n" % (c, k) for c, k in prov]
    text.append("\nTotal variation between the impulse engine and each stepping engine at "
                "its default step (`--dt auto`), `--group`, seed 3; noise: the 95th "
                "percentile of the TV that sampling alone gives at these counts were the "
                "two engines to agree (redraws from their pooled shares); beyond noise: "
                "the TV is larger than that.\n\n")
    text.append(tables(runs, labels, tvs))
    text = "".join(text)
    sys.stdout.write(text)
    if a.doc:
        script_util.put_between(a.doc, "corpus-table", "\n" + text + "\n", "corpus-table.py")
    return 0


if __name__ == "__main__":
    sys.exit(main())
