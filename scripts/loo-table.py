#!/usr/bin/env python3
"""loo-table.py: the leave-one-out table of two seeds, with the run's provenance.

Reads the summaries that scripts/paper.sh -L writes (OUTDIR/loo.summary.txt:
one line a held-out part, e16 and TV of QS, PQS, the paper's simulator, the
best fit and the averaged prediction, the fitted values and the cost) for
seed 1 and seed 2, and the same two of an earlier run to set beside them, and
prints a Markdown table (under a line quoting the summaries' '#' lines, which
name the command, commit and date of each run): e16 per seed and their mean, the averaged
prediction's TV and each fold's CPU seconds, the earlier run's averaged e16,
and the count of held-out parts whose mean averaged e16 is worse than their
PQS. --note replaces the line above the table; with --doc and --tag the table goes between '<!-- TAG begin -->' and
'<!-- TAG end -->' of that file.

  scripts/loo-table.py --now S1 S2 --before B1 B2 [--note TEXT] [--doc FILE --tag TAG]

Python 3 standard library only.
"""
import argparse
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402

NAMES = {"insulator_cap": "insulator cap", "white_button": "white button",
         "rect_black_button": "rectangular black button",
         "square_black_button": "square black button"}


def summary(path, notes):
    rows = {}
    for line in open(path):
        if line.startswith("#"):
            notes.append("%s: %s" % (os.path.basename(path), line[1:].strip()))
            continue
        f = line.rstrip("\n").split("|")
        if len(f) < 12:
            continue
        cpu = re.search(r"([0-9.]+) s CPU", f[11])
        rows[f[0]] = {"qs": float(f[1]), "pqs": float(f[2]), "dyn": float(f[3]),
                      "best": float(f[4]), "avg": float(f[5]), "tv_avg": float(f[9]),
                      "cpu": float(cpu.group(1)) if cpu else float("nan")}
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--now", nargs=2, required=True, metavar="SUMMARY")
    ap.add_argument("--before", nargs=2, required=True, metavar="SUMMARY")
    ap.add_argument("--note", help="the line above the table (default: the summaries' "
                    "'#' lines, which name their command, commit and date)")
    ap.add_argument("--doc")
    ap.add_argument("--tag")
    a = ap.parse_args()
    notes = []
    s1, s2 = (summary(p, notes) for p in a.now)
    b1, b2 = (summary(p, notes) for p in a.before)
    out = ["The runs (the '#' lines of the summaries): " + "; ".join(notes) + "." if notes
           else "", ""] if a.note is None else [a.note, ""]
    out += [
           "| held out | QS | PQS | paper's Dyn | seed 1: best | avg | seed 2: best | avg "
           "| mean of the seeds: best | avg | avg TV, seeds 1 / 2 | CPU s, seeds 1 / 2 "
           "| before: avg, seeds 1 / 2 / mean |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    tot = {}
    worse = 0
    parts = [p for p in NAMES if p in s1 and p in s2]
    for p in parts:
        r1, r2 = s1[p], s2[p]
        mb, ma = (r1["best"] + r2["best"]) / 2, (r1["avg"] + r2["avg"]) / 2
        bm = (b1[p]["avg"] + b2[p]["avg"]) / 2 if p in b1 and p in b2 else float("nan")
        worse += ma > r1["pqs"]
        vals = {"qs": r1["qs"], "pqs": r1["pqs"], "dyn": r1["dyn"], "b1": r1["best"],
                "a1": r1["avg"], "b2": r2["best"], "a2": r2["avg"], "mb": mb, "ma": ma,
                "t1": r1["tv_avg"], "t2": r2["tv_avg"], "old1": b1[p]["avg"],
                "old2": b2[p]["avg"], "oldm": bm}
        for k, v in vals.items():
            tot[k] = tot.get(k, 0.0) + v / len(parts)
        out.append("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f "
                   "| %.1f / %.1f | %.1f / %.1f | %.1f / %.1f / %.1f |"
                   % (NAMES[p], r1["qs"], r1["pqs"], r1["dyn"], r1["best"], r1["avg"],
                      r2["best"], r2["avg"], mb, ma, r1["tv_avg"], r2["tv_avg"], r1["cpu"],
                      r2["cpu"], b1[p]["avg"], b2[p]["avg"], bm))
    t = tot
    out.append("| mean | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f "
               "| %.1f / %.1f | | %.1f / %.1f / %.1f |"
               % (t["qs"], t["pqs"], t["dyn"], t["b1"], t["a1"], t["b2"], t["a2"], t["mb"],
                  t["ma"], t["t1"], t["t2"], t["old1"], t["old2"], t["oldm"]))
    out.append("")
    out.append("Held-out parts whose averaged e16, as the mean of the two seeds, is worse "
               "than their PQS: %d of %d." % (worse, len(parts)))
    text = "\n".join(out) + "\n"
    if a.doc:
        script_util.put_between(a.doc, a.tag, text, "loo-table.py")
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
