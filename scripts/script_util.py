"""script_util.py: what the Python scripts that run posedrop share (not a script).

run(): a command's standard output, or the script's end with its message;
rows(): CSV text as dicts, columns by name; git(): a git command's output in
the repository; put_between(): a generated block into a Markdown file
between '<!-- TAG begin -->' and '<!-- TAG end -->' lines.
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd, tag):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit("%s: %s failed: %s" % (tag, " ".join(cmd), p.stderr.strip()))
    return p.stdout


def rows(text):
    # Lines starting '#' are provenance (scripts/paper.sh heads its runs with
    # their command and commit), not rows.
    return list(csv.DictReader(l for l in text.splitlines() if not l.startswith("#")))


def git(*args):
    return subprocess.run(["git", "-C", ROOT] + list(args), stdout=subprocess.PIPE,
                          stderr=subprocess.DEVNULL, text=True).stdout.strip()


def commit_here():
    """The commit checked out, and ', with changes' when tracked files other
    than the documents the scripts write into (docs/, README.md) differ."""
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!docs",
                  ":!README.md")
    return git("rev-parse", "--short", "HEAD"), ", with changes" if changed else ""


def put_between(path, tag, text, who):
    begin, end = "<!-- %s begin -->\n" % tag, "<!-- %s end -->\n" % tag
    doc = open(path).read()
    i, j = doc.find(begin), doc.find(end)
    if i < 0 or j < i:
        sys.exit("%s: %s has no '%s' ... '%s' lines" % (who, path, begin.strip(), end.strip()))
    with open(path, "w") as f:
        f.write(doc[:i + len(begin)] + text + doc[j:])
