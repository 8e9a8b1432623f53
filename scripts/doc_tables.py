#!/usr/bin/env python3
"""doc_tables.py: the small measured tables of docs/ that no other script
makes, each run again and put between its markers in its doc,
'<!-- table NAME begin -->' and '<!-- table NAME end -->', under a line
giving the commands and the commit they ran on (make figures runs it).

    scripts/doc_tables.py [-b POSEDROP] [NAME...]

Tables (all by default):

  contact-time   docs/contact.md: a 1 cm cube started resting on a face
                 (the belt's long run, --initial stationary: 1400 drops,
                 200 of them uniform, seed 1, --transitions), the share of
                 the resting starts that end on the face they started on,
                 at each contact time. About 2 s of CPU.
  hexnut-long-run  docs/uncertainty.md: the hex nut's flat faces from
                 uniform orientations and in the belt's long run, 2000
                 drops each. Under 1 s of CPU.
  cost-accuracy  docs/validation.md: CPU seconds and eq. (16) error per
                 estimator and part, from docs/figures/cost-accuracy-mean.csv
                 (scripts/cost-accuracy.sh; no runs here).

Python 3 standard library only; posedrop must be built (make all).
"""
import csv
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def commit():
    run = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True)
    return run.stdout.strip() if run.returncode == 0 else "unknown"


def posedrop(binary, args):
    """Runs posedrop with ARGS (part paths relative to the repository)."""
    cmd = [binary] + [os.path.join(ROOT, a) if a.startswith("parts/") else a for a in args]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: posedrop {' '.join(args)} failed: {run.stderr.strip()}")
    return run.stdout


def contact_time(binary):
    times = ["0", "1e-6", "1e-5", "3e-5", "1e-4", "2e-4", "3e-4", "5e-4", "1e-3"]
    cells = []
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "transitions.csv")
        for t in times:
            posedrop(binary, ["-n", "1400", "--initial", "stationary", "--seed", "1",
                              "--contact-time", t, "--transitions", path,
                              "parts/canonical/cube.off"])
            with open(path) as f:
                rows = [r for r in csv.DictReader(f) if r["from_pose"] != "0"]
            stayed = sum(int(r["count"]) for r in rows if r["from_pose"] == r["to_pose"])
            started = sum(int(r["count"]) for r in rows)
            cells.append(f"{100 * stayed / started:.1f}% of {started}")
    head = "| contact_time (s) | " + " | ".join("0 (rigid)" if t == "0" else t for t in times) + " |"
    rule = "|---" * (len(times) + 1) + "|"
    body = "| stays on its face | " + " | ".join(cells) + " |"
    cmd = ("posedrop -n 1400 --initial stationary --seed 1 --contact-time T "
           "--transitions FILE parts/canonical/cube.off")
    return cmd, "\n".join([head, rule, body])


def cost_accuracy(binary):
    """No runs: the table of docs/figures/cost-accuracy-mean.csv, which
    scripts/cost-accuracy.sh writes with its command and commit."""
    path = os.path.join(ROOT, "docs/figures/cost-accuracy-mean.csv")
    with open(path) as f:
        lines = f.read().splitlines()
    heads = [l[2:] for l in lines if l.startswith("# ")]
    if not heads:
        sys.exit(f"doc_tables.py: {path}: no '#' lines naming its command and commit")
    cells = {}
    for line in lines:
        if line.startswith("#"):
            continue
        part, est, budget, cpu, e16 = line.split(",")[:5]
        cells[(est, budget, part)] = (float(cpu), float(e16))
    parts = ["insulator_cap", "white_button", "rect_black_button", "square_black_button"]
    rows = [("QS", "QS", "0"), ("PQS", "PQS", "0")]
    rows += [(f"impulse, {n} drops", "impulse", n) for n in ("1000", "2000", "5000")]
    rows += [(f"ODE, dt {float(dt) * 1000:g} ms", "ODE", dt) for dt in ("0.002", "0.001", "0.0005")]
    rows += [(f"Bullet, dt {float(dt) * 1000:g} ms", "Bullet", dt)
             for dt in ("0.0021", "0.00104", "0.00052")]
    out = ["| estimator | cap | white button | rect. button | square button |",
           "|---|---|---|---|---|"]
    for label, est, budget in rows:
        row = []
        for part in parts:
            c = cells.get((est, budget, part))
            row.append(f"{c[0]:.3g} s, {c[1]:.1f}" if c else "-")
        out.append(f"| {label} | " + " | ".join(row) + " |")
    for label, ests in (("the paper: QS, PQS (< 1 s on a SPARC20)", ("paper_QS", "paper_PQS")),
                        ("the paper: dynamic simulation (about 2 h)", ("paper_dynamic",))):
        row = []
        for part in parts:
            row.append(", ".join(f"{v[1]:.1f}" for v in
                                 (next(c for k, c in cells.items() if k[0] == e and k[2] == part)
                                  for e in ests)))
        out.append(f"| {label} | " + " | ".join(row) + " |")
    return f"{heads[0]} ({heads[1]}), docs/figures/cost-accuracy-mean.csv", "\n".join(out)


def hexnut_long_run(binary):
    """The hex nut's flat faces from uniform orientations and in the
    belt's long run."""
    out = ["| start | flat faces (95%) | sides (95%) | the command's warnings |",
           "|---|---|---|---|"]
    base = ["-n", "2000", "--group", "--units", "mm", "--seed", "1"]
    for label, extra in (("uniform orientations", []),
                         ("the belt's long run (`--initial stationary`)", ["--initial", "stationary"])):
        cmd = [binary] + base + extra + [os.path.join(ROOT, "parts/hexnut.obj")]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"doc_tables.py: {' '.join(cmd)} failed: {run.stderr.strip()}")
        cells = {}
        for r in csv.DictReader(run.stdout.splitlines()):
            key = "flat" if abs(abs(float(r["nz"])) - 1) < 1e-9 else "sides"
            cells[key] = (f"{float(r['p']):.3f} ({float(r['ci_lo']):.3f}-"
                          f"{float(r['ci_hi']):.3f})")
        warn = " ".join(run.stderr.split()) or "none"
        out.append(f"| {label} | {cells['flat']} | {cells['sides']} | {warn} |")
    return ("posedrop -n 2000 --group --units mm --seed 1 [--initial stationary] "
            "parts/hexnut.obj"), "\n".join(out)


TABLES = {"contact-time": ("docs/contact.md", contact_time),
          "hexnut-long-run": ("docs/uncertainty.md", hexnut_long_run),
          "cost-accuracy": ("docs/validation.md", cost_accuracy)}


def put(doc, name, text):
    begin, end = f"<!-- table {name} begin -->", f"<!-- table {name} end -->"
    path = os.path.join(ROOT, doc)
    with open(path) as f:
        s = f.read()
    if s.count(begin) != 1 or s.count(end) != 1 or s.index(begin) > s.index(end):
        sys.exit(f"doc_tables.py: {doc}: expected one '{begin}' before one '{end}'")
    s = s[:s.index(begin) + len(begin)] + "\n" + text + "\n" + s[s.index(end):]
    with open(path + ".tmp", "w") as f:
        f.write(s)
    os.replace(path + ".tmp", path)


def usage(why):
    print(f"doc_tables.py: {why} (see doc_tables.py --help)", file=sys.stderr)
    sys.exit(2)


def main():
    args = sys.argv[1:]
    binary = os.path.join(ROOT, "build/opt/posedrop")
    if args[:1] == ["-b"]:
        if len(args) < 2:
            usage("-b needs a value")
        binary, args = os.path.abspath(args[1]), args[2:]
    if args[:1] == ["--help"]:
        print(__doc__.strip())
        return
    for name in args:
        if name not in TABLES:
            usage(f"no table '{name}' (tables: {', '.join(TABLES)})")
    for name in args or list(TABLES):
        doc, make = TABLES[name]
        cmd, table = make(binary)
        made = (f"Made by `scripts/doc_tables.py {name}` on {time.strftime('%Y-%m-%d', time.gmtime())} "
                f"(commit {commit()}): `{cmd}`.\n\n")
        put(doc, name, made + table)
        print(f"doc_tables.py: {doc}: table {name}", file=sys.stderr)


if __name__ == "__main__":
    main()
