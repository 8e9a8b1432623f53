#!/usr/bin/env python3
"""paper-doc.py: make paper's tables into a Markdown file, with the command and commit.

Runs scripts/paper.sh with the arguments given after '--' (its drops on the
impulse engine, ODE and Bullet at their defaults, beside the paper's columns)
and puts its output, in a code block under a line naming the command, the
date, the commit and the CPU seconds the runs took, between
'<!-- TAG begin -->' and '<!-- TAG end -->' of FILE.

  scripts/paper-doc.py --doc docs/validation.md [--tag paper-tables]
      [--txt docs/figures/paper.txt] -- -n 1000 -o DIR

--txt FILE also writes the output as it is, under a '#' line naming the
command and commit, as make figures writes docs/figures/paper.txt.
--partial writes FILE (not --txt's) even when paper.sh failed, saying so:
with paper.sh -T, the tables of the runs made so far, '-' for the others.

POSEDROP names the binary as for paper.sh. Python 3 standard library only.
"""
import argparse
import os
import resource
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import script_util  # noqa: E402
from script_util import ROOT  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--doc", required=True)
    ap.add_argument("--tag", default="paper-tables")
    ap.add_argument("--txt")
    ap.add_argument("--partial", action="store_true",
                    help="write the tables even when paper.sh failed (with -T: a run "
                    "missing prints '-'), saying so")
    ap.add_argument("args", nargs="*", help="paper.sh's arguments (after --)")
    a = ap.parse_args()
    commit, changed = script_util.commit_here()
    p = subprocess.run([os.path.join(ROOT, "scripts", "paper.sh")] + a.args,
                       stdout=subprocess.PIPE, text=True)
    if p.returncode != 0 and not a.partial:
        sys.exit("paper-doc.py: scripts/paper.sh %s failed (status %d); %s left as it was"
                 % (" ".join(a.args), p.returncode, a.doc))
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    cmd = "scripts/paper-doc.py " + " ".join(sys.argv[1:])
    note = ("" if p.returncode == 0 else
            " paper.sh said runs were missing or failed: their columns are '-'.")
    text = ("Made by `%s` (POSEDROP=%s) on %s (commit %s%s); %.0f CPU seconds in this call "
            "(runs kept by -r or -T not counted; each run's own at the end).%s\n\n"
            "```\n%s```\n" % (cmd, os.environ.get("POSEDROP", "the newest build"),
                              time.strftime("%Y-%m-%d", time.gmtime()), commit, changed,
                              r.ru_utime + r.ru_stime, note, p.stdout))
    sys.stdout.write(text)
    if a.txt and p.returncode == 0:
        with open(a.txt, "w") as f:
            f.write("# scripts/paper.sh %s (POSEDROP=%s; scripts/paper-doc.py), commit %s%s, %s\n%s"
                    % (" ".join(a.args), os.environ.get("POSEDROP", "the newest build"), commit,
                       changed, time.strftime("%Y-%m-%d", time.gmtime()), p.stdout))
    script_util.put_between(a.doc, a.tag, "\n" + text + "\n", "paper-doc.py")
    return 0


if __name__ == "__main__":
    sys.exit(main())
