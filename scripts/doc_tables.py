#!/usr/bin/env python3
"""doc_tables.py: the small measured tables of docs/ that no other script
makes, each run again and put between its markers in its doc,
'<!-- table NAME begin -->' and '<!-- table NAME end -->', under a line
giving the commands and the commit they ran on (make figures runs it).

    scripts/doc_tables.py [-b POSEDROP] [--cheap] [NAME...]

Tables (all by default; --cheap: those --check makes again, seconds of
CPU in all):

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
  cube-sizes     docs/limits.md: cubes of 0.1 mm to 1000 km, 30 impulse
                 drops each: unsettled (compared), the slowest settled drop
                 in natural time units and CPU per drop (not). About 1 s.
  painter        docs/figures.md: the painter's order against a depth
                 buffer on the shipped non-convex parts, from make check's
                 own test (tests/unit/test_viz.c); compared exactly. About
                 10 s of CPU.
  symmetry-limit  docs/performance.md: posedrop with and without --group
                 on a regular 4000-gon prism, the symmetry search's worst
                 case within its limit: rows (compared) and CPU seconds (not).
                 Under 1 s of CPU.

Not cheap (make figures without CHEAP=1):

  settle-times   docs/limits.md: the slowest of 200 impulse drops in the
                 part's natural time units, ordinary parts of 1 mm to 1 m
                 and the shipped ones (maxima: not compared). About 3 s.
  tops           docs/limits.md: the 0.1 mm cube (200 drops) and the 1 mm
                 cube at 3000 rad/s (100): unsettled, the slowest drop, CPU
                 per drop. About 15 s of CPU.
  bench-drops    docs/performance.md: make bench's dynamic and ranges
                 sections as printed (timings: not compared). About 10 s of
                 CPU, more wall time on a busy machine.
  bench-batch    docs/batch.md: make bench's batch section (whole
                 processes, -j 2 and posedrop-mpi against -j 1).
                 About 10 s of CPU.
  python-bench   docs/python.md: python/bench.py, the command against the
                 same work from Python; PYTHON names a Python with the
                 posedrop module (default .venv/bin/python when there,
                 else python3). About 15 s of CPU.
  test-cost      docs/development.md: make check's suites, checks and CPU
                 seconds. About 90 s of CPU.
  fuzz           docs/cli-input.md: make fuzz, 60 s per target (builds the
                 fuzzers with clang first): executions per target. Eight
                 minutes of wall time whatever the load (libFuzzer's limit
                 is in wall time), with the build a few CPU minutes.

Each table also writes docs/figures/tables/NAME.csv: its command and
commit, a hash of the text it put in the doc, and the numbers behind the
table with their standard errors. --check (make check-figures) reads them
back: a doc's block that is not the text its table wrote (edited by hand)
fails; each cheap table is made again, and a number that moved beyond
z sqrt(se_old^2 + se_new^2) fails, z the two-sided 5% point shared by all
the numbers checked (Bonferroni); a number with no standard error (a
timing) is not compared. --self-test checks first that the check fails on
a moved number and on a hand edit, on a table of its own.

    scripts/doc_tables.py [-b POSEDROP] --check [--self-test] [NAME...]

Python 3 standard library only; posedrop must be built (make all).
"""
import csv
import hashlib
import io
import math
import os
import subprocess
import sys
import tempfile
import time
from statistics import NormalDist

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def commit():
    """The commit the tables ran on, marked when the code (anything outside
    docs/) differs from it."""
    run = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return "unknown"
    dirty = subprocess.run(["git", "-C", ROOT, "diff", "--quiet", "HEAD", "--", ".", ":!docs"])
    return run.stdout.strip() + (" with uncommitted changes" if dirty.returncode else "")


def posedrop(binary, args):
    """Runs posedrop with ARGS (part paths relative to the repository)."""
    cmd = [binary] + [os.path.join(ROOT, a) if a.startswith("parts/") else a for a in args]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: posedrop {' '.join(args)} failed: {run.stderr.strip()}")
    return run.stdout


def binomial_se(p, n):
    """A share's standard error over n independent drops, kept off 0 at a
    share of 0 or 1 by one drop's worth of variance."""
    return math.sqrt(max(p * (1 - p), 1 / n) / n)


def interval_se(row):
    """A posedrop row's standard error from its own 95% interval (Wilson,
    or the resampled interval of --initial stationary)."""
    return (float(row["ci_hi"]) - float(row["ci_lo"])) / (2 * 1.959964)


def contact_time(binary):
    times = ["0", "1e-6", "1e-5", "3e-5", "1e-4", "2e-4", "3e-4", "5e-4", "1e-3"]
    cells, numbers = [], []
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
            # Each resting start's drop is independent of the others: binomial,
            # its variance kept off 0 at a share of 0 or 1 (one drop's worth).
            numbers.append((f"stays at {t}", stayed / started,
                            binomial_se(stayed / started, started)))
    head = "| contact_time (s) | " + " | ".join("0 (rigid)" if t == "0" else t for t in times) + " |"
    rule = "|---" * (len(times) + 1) + "|"
    body = "| stays on its face | " + " | ".join(cells) + " |"
    cmd = ("posedrop -n 1400 --initial stationary --seed 1 --contact-time T "
           "--transitions FILE parts/canonical/cube.off")
    return cmd, "\n".join([head, rule, body]), numbers


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
    numbers = []
    for label, est, budget in rows:
        row = []
        for part in parts:
            c = cells.get((est, budget, part))
            row.append(f"{c[0]:.3g} s, {c[1]:.1f}" if c else "-")
            if c:
                # Read from the kept file, not run: the same file gives the same numbers.
                numbers.append((f"{est} {budget} {part} e16", c[1], 0.0))
        out.append(f"| {label} | " + " | ".join(row) + " |")
    for label, ests in (("the paper: QS, PQS (< 1 s on a SPARC20)", ("paper_QS", "paper_PQS")),
                        ("the paper: dynamic simulation (about 2 h)", ("paper_dynamic",))):
        row = []
        for part in parts:
            row.append(", ".join(f"{v[1]:.1f}" for v in
                                 (next(c for k, c in cells.items() if k[0] == e and k[2] == part)
                                  for e in ests)))
        out.append(f"| {label} | " + " | ".join(row) + " |")
    return (f"{heads[0]} ({heads[1]}), docs/figures/cost-accuracy-mean.csv", "\n".join(out),
            numbers)


def hexnut_long_run(binary):
    """The hex nut's flat faces from uniform orientations and in the
    belt's long run."""
    out = ["| start | flat faces (95%) | sides (95%) | the command's warnings |",
           "|---|---|---|---|"]
    base = ["-n", "2000", "--group", "--units", "mm", "--seed", "1"]
    numbers = []
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
            numbers.append((f"{label}: {key}", float(r["p"]), interval_se(r)))
        warn = " ".join(run.stderr.split()) or "none"
        out.append(f"| {label} | {cells['flat']} | {cells['sides']} | {warn} |")
    return ("posedrop -n 2000 --group --units mm --seed 1 [--initial stationary] "
            "parts/hexnut.obj"), "\n".join(out), numbers


def bench(sections, what):
    """make bench's sections named, their output as it prints it: timings,
    each a ratio against a reference run in the same process, not compared
    by --check (a shared machine's times do not repeat)."""
    def make(binary):
        bench_bin = os.path.join(os.path.dirname(binary), "bench_posedrop")
        if not os.access(bench_bin, os.X_OK):
            sys.exit(f"doc_tables.py: {bench_bin} not built (make {os.path.relpath(bench_bin, ROOT)})")
        load = os.getloadavg()[0]
        run = subprocess.run([bench_bin] + sections, cwd=ROOT, capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"doc_tables.py: bench_posedrop {' '.join(sections)} failed: "
                     f"{run.stderr.strip()}")
        body = run.stdout.strip().splitlines()[1:]   # the banner names the version only
        text = ("```text\n" + "\n".join(body).strip("\n") + "\n```\n\n"
                f"{what} Load average {load:.1f} when it started (the machine's other work "
                "slows every time in it; the ratios, each against a run in the same process, "
                "move less).")
        return f"bench_posedrop {' '.join(sections)} (make bench BENCH='{' '.join(sections)}')", \
            text, []
    return make


def fuzz(binary):
    """make fuzz's executions per target, 60 s each: what the readers took
    without a crash. Not compared (a rate depends on the machine)."""
    run = subprocess.run(["make", "--no-print-directory", "fuzz", "FUZZ_SECONDS=60"], cwd=ROOT,
                         capture_output=True, text=True)
    rows = [l.split() for l in run.stdout.splitlines() if l.startswith("fuzz ")]
    if run.returncode != 0 or not rows:
        sys.exit(f"doc_tables.py: make fuzz failed:\n{run.stdout[-2000:]}{run.stderr[-2000:]}")
    out = ["| target | result | executions | per second |", "|---|---|---|---|"]
    for r in rows:
        # fuzz TARGET ok: N executions in S s, R per second (log FILE)
        out.append(f"| {r[1]} | {r[2].rstrip(':')} | {r[3]} | {r[8]} |")
    return "make fuzz FUZZ_SECONDS=60", "\n".join(out), []


def symmetry_limit(binary):
    """The symmetry search's worst case within PD_SYMMETRY_MAX_PAIRS: a
    regular 4000-gon prism (8000 vertices at one radius), with and without
    --group: the classes (exact) and the CPU seconds (not compared)."""
    n = 4000
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "prism4000.off")
        with open(path, "w") as f:
            f.write(f"OFF\n{2 * n} {4 * n - 4} 0\n")
            for z in (0.0, 0.01):
                for k in range(n):
                    a = 2 * math.pi * k / n
                    f.write(f"{0.02 * math.cos(a)!r} {0.02 * math.sin(a)!r} {z}\n")
            for k in range(1, n - 1):
                f.write(f"3 0 {k + 1} {k}\n3 {n} {n + k} {n + k + 1}\n")
            for k in range(n):
                j = (k + 1) % n
                f.write(f"3 {k} {j} {n + j}\n3 {k} {n + j} {n + k}\n")
        cells, numbers = [], []
        for opts in ([], ["--group"]):
            before = os.times()
            run = subprocess.run([binary] + opts + [path], capture_output=True, text=True)
            after = os.times()
            if run.returncode != 0:
                sys.exit(f"doc_tables.py: posedrop {' '.join(opts)} on the prism failed: "
                         f"{run.stderr.strip()}")
            cpu = (after.children_user - before.children_user
                   + after.children_system - before.children_system)
            rows = len(run.stdout.strip().splitlines()) - 1
            cells.append(f"| `posedrop {' '.join(opts + ['prism4000.off'])}` | {rows} | {cpu:.2f} s |")
            numbers.append((f"rows {' '.join(opts) or 'plain'}", float(rows), 0.0))
    return ("posedrop [--group] prism4000.off (a regular 4000-gon prism, 4 cm across, "
            "1 cm high, written by the script)",
            "\n".join(["| command | rows | CPU |", "|---|---:|---:|"] + cells), numbers)


def write_off(path, vertices, faces):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(vertices)} {len(faces)} 0\n")
        for v in vertices:
            f.write(" ".join(repr(float(c)) for c in v) + "\n")
        for t in faces:
            f.write(f"{len(t)} " + " ".join(str(i) for i in t) + "\n")


def box_off(path, a, b, c):
    v = [(x, y, z) for x in (0, a) for y in (0, b) for z in (0, c)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    write_off(path, v, faces)


def prism_off(path, n, r, h):
    v = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), z)
         for z in (0.0, h) for k in range(n)]
    faces = [tuple(reversed(range(n))), tuple(range(n, 2 * n))]
    faces += [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]
    write_off(path, v, faces)


def drops_run(binary, path, n, extra=()):
    """N impulse drops of PATH (-j 1, seed 1) with --trials: the trial
    rows, the part's size (m) and the CPU seconds of the run (its own
    cpu_s, part build included)."""
    with tempfile.TemporaryDirectory() as tmp:
        trials = os.path.join(tmp, "trials.csv")
        run = subprocess.run([binary, "-n", str(n), "-j", "1", "--seed", "1", "--format", "json",
                              "--trials", trials] + list(extra) + [path],
                             capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"doc_tables.py: posedrop on {path} failed: {run.stderr.strip()}")
        with open(trials) as f:
            rows = list(csv.DictReader(f))

    def field(name):
        return float(run.stdout.split(f'"{name}": ', 1)[1].split(",", 1)[0].rstrip("}"))
    return rows, field("size_m"), field("cpu_s")


def cube_sizes(binary):
    """Cubes from 0.1 mm to 1000 km, 30 impulse drops each in the default
    scene: how many settle, the slowest in the part's natural time units
    (sqrt(L/g) + sqrt(2h/g), of which the automatic time limit is 100),
    and the CPU per drop (not compared)."""
    out = ["| cube edge | h / L | unsettled of 30 | slowest settled drop, natural units | "
           "CPU per drop |", "|---|---:|---:|---:|---:|"]
    numbers = []
    with tempfile.TemporaryDirectory() as tmp:
        for edge in ("1e-4", "1e-3", "1e-2", "1e-1", "1", "10", "100", "1e3", "1e6"):
            path = os.path.join(tmp, f"cube{edge}.off")
            L = float(edge)
            box_off(path, L, L, L)
            rows, size, cpu = drops_run(binary, path, 30)
            unit = math.sqrt(size / 9.81) + math.sqrt(2 * 0.12 / 9.81)
            settled = [float(r["time"]) for r in rows if r["end"] == "settled"]
            unsettled = len(rows) - len(settled)
            slow = f"{max(settled) / unit:.1f}" if settled else "-"
            out.append(f"| {edge} m | {0.12 / L:.3g} | {unsettled} | {slow} | "
                       f"{1e3 * cpu / len(rows):.3g} ms |")
            numbers.append((f"unsettled {edge}", unsettled / len(rows),
                            binomial_se(unsettled / len(rows), len(rows))))
    return ("posedrop -n 30 -j 1 --seed 1 --trials FILE cubeL.off (cubes written by the script; "
            "h / L: the drop height over the edge)", "\n".join(out), numbers)


def settle_times(binary):
    """The slowest of 200 uniform impulse drops, in the part's natural time
    units, on ordinary parts and the shipped ones: what the automatic time
    limit's 100 units leave as margin. Maxima have no standard error: not
    compared."""
    out = ["| part | slowest of 200, natural units | margin to the limit (100 units) |",
           "|---|---:|---:|"]
    with tempfile.TemporaryDirectory() as tmp:
        parts = []
        for edge, name in ((1e-3, "1 mm"), (1e-2, "1 cm"), (1e-1, "10 cm"), (1.0, "1 m")):
            box_off(os.path.join(tmp, f"cube{edge}.off"), edge, edge, edge)
            parts.append((f"cube {name}", os.path.join(tmp, f"cube{edge}.off")))
            box_off(os.path.join(tmp, f"box{edge}.off"), edge, 2 * edge, 3 * edge)
            parts.append((f"1 x 2 x 3 box, edge {name}", os.path.join(tmp, f"box{edge}.off")))
            prism_off(os.path.join(tmp, f"prism{edge}.off"), 32, edge, edge)
            parts.append((f"32-gon prism, h = d/2, radius {name}",
                          os.path.join(tmp, f"prism{edge}.off")))
        for name in ("cap", "insulator_cap", "white_button", "rect_black_button",
                     "square_black_button"):
            parts.append((f"`{name}.off`", os.path.join(ROOT, "parts", name + ".off")))
        for label, path in parts:
            rows, size, _ = drops_run(binary, path, 200)
            unit = math.sqrt(size / 9.81) + math.sqrt(2 * 0.12 / 9.81)
            slow = max(float(r["time"]) for r in rows if r["end"] == "settled") / unit
            out.append(f"| {label} | {slow:.1f} | {100 / slow:.1f} |")
    return ("posedrop -n 200 -j 1 --seed 1 --trials FILE PART (the largest settled time over "
            "sqrt(size/g) + sqrt(2h/g), size the bounding-box diagonal)", "\n".join(out), [])


def tops(binary):
    """Small cubes that end spinning on a corner (tops): unsettled drops
    (compared) and CPU per drop (not)."""
    out = ["| part | drops | unsettled | slowest drop, simulated s | CPU per drop |",
           "|---|---:|---:|---:|---:|"]
    numbers = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, edge, n, extra in (("cube 0.1 mm", 1e-4, 200, []),
                                      ("cube 1 mm, tumble 3000 rad/s", 1e-3, 100,
                                       ["--tumble", "3000"])):
            path = os.path.join(tmp, "cube.off")
            box_off(path, edge, edge, edge)
            rows, _, cpu = drops_run(binary, path, n, extra)
            unsettled = sum(r["end"] != "settled" for r in rows)
            out.append(f"| {label} | {n} | {unsettled} | {max(float(r['time']) for r in rows):.0f} | "
                       f"{1e3 * cpu / n:.3g} ms |")
            numbers.append((f"unsettled {label}", unsettled / n, binomial_se(unsettled / n, n)))
    return ("posedrop -n N -j 1 --seed 1 [--tumble 3000] --trials FILE cube.off (cubes written "
            "by the script)", "\n".join(out), numbers)


def python_bench(binary):
    """python/bench.py's ratios, as it prints them: needs the posedrop
    module installed in the Python that $PYTHON names (default the
    git-ignored .venv's when there, as make bench-mujoco, else python3;
    docs/python.md says how to install it). Timings: not compared."""
    venv = os.path.join(ROOT, ".venv/bin/python")
    py = os.environ.get("PYTHON") or (venv if os.access(venv, os.X_OK) else "python3")
    load = os.getloadavg()[0]
    run = subprocess.run([py, os.path.join(ROOT, "python/bench.py"), "--repeat", "7"], cwd=ROOT,
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: {py} python/bench.py failed (is the posedrop module installed "
                 f"in it? set PYTHON): {run.stderr.strip()[-1500:]}")
    body = [l for l in run.stdout.strip().splitlines() if not l.startswith("posedrop ")]
    text = ("```text\n" + "\n".join(body) + "\n```\n\n"
            f"Load average {load:.1f} when it started; times are wall clock, medians of 7.")
    return "python python/bench.py --repeat 7", text, []


def painter(binary):
    """The painter's order against a depth buffer on the shipped non-convex
    parts, as tests/unit/test_viz.c measures it in every make check (its
    notes, PD_TEST_VERBOSE=1): each part's worst and mean share of a pose's
    pixels that show another face's shade. Deterministic: compared exactly
    (as printed, to 0.01%)."""
    test_bin = os.path.join(os.path.dirname(binary), "test_posedrop")
    if not os.access(test_bin, os.X_OK):
        sys.exit(f"doc_tables.py: {test_bin} not built (make {os.path.relpath(test_bin, ROOT)})")
    run = subprocess.run([test_bin, "viz"], cwd=ROOT, capture_output=True, text=True,
                         env=dict(os.environ, PD_TEST_VERBOSE="1"))
    notes = [l for l in (run.stdout + run.stderr).splitlines()
             if l.startswith("viz: painter's order vs depth buffer, parts/")]
    if run.returncode != 0 or not notes:
        sys.exit(f"doc_tables.py: test_posedrop viz failed or printed no notes:\n"
                 f"{run.stdout[-1500:]}{run.stderr[-1500:]}")
    out = ["| part | poses | triangles | worst pose | mean over poses |",
           "|---|---:|---:|---:|---:|",
           "| cube, box, icosahedron (convex: checked exact) | | | 0 | 0 |"]
    numbers = []
    for l in notes:
        # viz: painter's order vs depth buffer, PART: N poses, T triangles, worst W%, mean M% ...
        part, rest = l.split("buffer, ", 1)[1].split(": ", 1)
        f = rest.replace(",", "").split()
        poses, tris, worst, mean = f[0], f[2], f[5].rstrip("%"), f[7].rstrip("%")
        out.append(f"| `{part[len('parts/'):]}` | {poses} | {tris} | {worst}% | {mean}% |")
        numbers += [(f"{part} worst", float(worst), 0.0), (f"{part} mean", float(mean), 0.0)]
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop viz (tests/unit/test_viz.c, 160 x 160 "
            "pixel centres)", "\n".join(out), numbers)


def test_cost(binary):
    """make check's test suites (the runner as make test runs it, -j2,
    without the build): checks and CPU seconds. Not compared."""
    test_bin = os.path.join(os.path.dirname(binary), "test_posedrop")
    if not os.access(test_bin, os.X_OK):
        sys.exit(f"doc_tables.py: {test_bin} not built (make {os.path.relpath(test_bin, ROOT)})")
    load = os.getloadavg()[0]
    before = os.times()
    run = subprocess.run([test_bin, "-j2"], cwd=ROOT, capture_output=True, text=True)
    after = os.times()
    last = [l for l in run.stdout.splitlines() if l.endswith(" failed") and "suite" not in l]
    if run.returncode != 0 or not last:
        sys.exit(f"doc_tables.py: test_posedrop failed:\n{run.stdout[-1500:]}{run.stderr[-1500:]}")
    user = after.children_user - before.children_user
    system = after.children_system - before.children_system
    text = (f"| suites | checks | CPU (user + system) |\n|---|---:|---:|\n"
            f"| make check's, two at a time | {last[-1].split()[0]} | {user + system:.0f} s "
            f"({user:.0f} + {system:.0f}) |\n\nLoad average {load:.1f} when it started.")
    return "build/opt/test_posedrop -j2 (make test)", text, []


# name: (doc, function, cheap). A cheap table (seconds of CPU, or read from
# kept files) is made again by --check and its numbers compared.
TABLES = {"contact-time": ("docs/contact.md", contact_time, True),
          "hexnut-long-run": ("docs/uncertainty.md", hexnut_long_run, True),
          "cost-accuracy": ("docs/validation.md", cost_accuracy, True),
          "symmetry-limit": ("docs/performance.md", symmetry_limit, True),
          "painter": ("docs/figures.md", painter, True),
          "cube-sizes": ("docs/limits.md", cube_sizes, True),
          "settle-times": ("docs/limits.md", settle_times, False),
          "tops": ("docs/limits.md", tops, False),
          "bench-drops": ("docs/performance.md", bench(["dynamic", "ranges"], (
              "In turn: a drop's cost on each part (the median of 400 drops each timed "
              "alone, and the mean over a whole run); what each scene effect costs against "
              "the plain scene; two threads against one; and ranges against fixed values "
              "(a range of zero width runs the fixed scene's very drops, so its ratio is "
              "what drawing the values adds).")), False),
          "bench-batch": ("docs/batch.md", bench(["batch"], (
              "Whole processes: the command with -j 2, and posedrop-mpi on two ranks when "
              "built, against -j 1, each output compared with -j 1's.")), False),
          "fuzz": ("docs/cli-input.md", fuzz, False),
          "test-cost": ("docs/development.md", test_cost, False),
          "python-bench": ("docs/python.md", python_bench, False)}
SIDECARS = "docs/figures/tables"


def markers(name):
    return f"<!-- table {name} begin -->", f"<!-- table {name} end -->"


def block(text, name, doc):
    """The text between a table's markers in a doc's TEXT."""
    begin, end = markers(name)
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        sys.exit(f"doc_tables.py: {doc}: expected one '{begin}' before one '{end}'")
    return text[text.index(begin) + len(begin):text.index(end)]


def digest(text):
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def put(root, doc, name, text):
    """Puts TEXT between NAME's markers in DOC; returns the block as written."""
    path = os.path.join(root, doc)
    with open(path) as f:
        s = f.read()
    block(s, name, doc)
    begin, end = markers(name)
    inner = "\n" + text + "\n"
    s = s[:s.index(begin) + len(begin)] + inner + s[s.index(end):]
    with open(path + ".tmp", "w") as f:
        f.write(s)
    os.replace(path + ".tmp", path)
    return inner


def write_sidecar(path, name, doc, cmd, inner, numbers):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path + ".tmp", "w") as f:
        f.write(f"# scripts/doc_tables.py {name}: {cmd}\n")
        f.write(f"# commit {commit()}, {time.strftime('%Y-%m-%d', time.gmtime())}; "
                f"{doc}, block {digest(inner)}\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["number", "value", "se"])
        for key, value, se in numbers:
            w.writerow([key, repr(value), "" if se is None else repr(se)])
    os.replace(path + ".tmp", path)


def read_sidecar(path):
    """(the block's hash, {number: (value, se)}) of a table's side file."""
    with open(path) as f:
        lines = f.read().splitlines()
    heads = [l for l in lines if l.startswith("# ")]
    if len(heads) < 2 or " block " not in heads[1]:
        sys.exit(f"doc_tables.py: {path}: no '# commit ..., DOC, block HASH' line")
    rows = csv.DictReader(io.StringIO("\n".join(l for l in lines if not l.startswith("#"))))
    return heads[1].rsplit(" block ", 1)[1].strip(), {
        r["number"]: (float(r["value"]), None if r["se"] == "" else float(r["se"])) for r in rows}


def check(root, binary, names, quiet=False):
    """Returns the failures: hand-edited blocks, then numbers moved beyond
    their interval (Bonferroni over every number compared)."""
    failures, pairs = [], []
    for name in names:
        doc, make, cheap = TABLES[name]
        side = os.path.join(root, SIDECARS, name + ".csv")
        if not os.path.exists(side):
            failures.append(f"{doc}: table {name}: no {SIDECARS}/{name}.csv (run make figures)")
            continue
        want, old = read_sidecar(side)
        with open(os.path.join(root, doc)) as f:
            if digest(block(f.read(), name, doc)) != want:
                failures.append(f"{doc}: table {name} is not the text doc_tables.py wrote "
                                f"(edited by hand?): run scripts/doc_tables.py {name}")
        if not cheap:
            continue
        _, _, numbers = make(binary)
        new = {k: (v, se) for k, v, se in numbers}
        if set(new) != set(old):
            failures.append(f"{doc}: table {name}: its numbers are now "
                            f"{sorted(set(new) ^ set(old))} apart from the file's: rerun it")
            continue
        for k, (v0, se0) in old.items():
            v1, se1 = new[k]
            if se0 is not None and se1 is not None:
                pairs.append((doc, name, k, v0, se0, v1, se1))
    z = NormalDist().inv_cdf(1 - 0.05 / (2 * max(len(pairs), 1)))
    for doc, name, k, v0, se0, v1, se1 in pairs:
        sd = math.sqrt(se0 ** 2 + se1 ** 2)
        # Exact numbers (read from kept files) may differ by round-off only.
        if abs(v1 - v0) > max(z * sd, 1e-12 * max(1.0, abs(v0))):
            failures.append(f"{doc}: table {name}: '{k}' {v0:.6g} in the doc, {v1:.6g} now"
                            + (f", {abs(v1 - v0) / sd:.1f} standard errors (limit {z:.2f})"
                               if sd > 0 else " (an exact number)")
                            + ": rerun make figures and update the doc's words")
    if not quiet:
        print(f"doc_tables.py: --check: {len(names)} tables, {len(pairs)} numbers compared, "
              f"{len(failures)} failures", file=sys.stderr)
    return failures


def static_control(binary):
    """A control for the self-test: the hex nut's static classes, exact
    numbers (standard error 0), as the tables read from kept files or from
    deterministic tests are."""
    out = posedrop(binary, ["--group", "--units", "mm", "parts/hexnut.obj"])
    rows = list(csv.DictReader(out.splitlines()))
    return ("posedrop --group --units mm parts/hexnut.obj", out,
            [(f"p_qs {r['pose']}", float(r["p_qs"]), 0.0) for r in rows])


def self_test(binary):
    """The check's controls on copies of two tables (under 1 s): the hex
    nut's drops, whose numbers have standard errors, and its static
    classes, exact numbers. As written passes; a number with a standard
    error moved by 1 standard error of the comparison passes, by 8 fails;
    an exact number moved by 1e-9 of itself fails; the block edited by hand
    fails."""
    saved = dict(TABLES)
    TABLES["control-exact"] = ("docs/control.md", static_control, True)
    TABLES["control-drops"] = ("docs/control.md", hexnut_long_run, True)

    def moved(numbers, k):
        key, v, se = numbers[0]
        return [(key, v + k, se)] + numbers[1:]

    cases = []
    for name in ("control-drops", "control-exact"):
        cmd, text, numbers = TABLES[name][1](binary)
        se = numbers[0][2]
        cases += [(name, f"{name}: as written", cmd, text, numbers, None, 0),
                  (name, f"{name}: edited by hand", cmd, text, numbers, ("0.", "0.9"), 1)]
        if se > 0:
            cases += [(name, f"{name}: moved by 1 standard error", cmd, text,
                       moved(numbers, math.sqrt(2) * se), None, 0),
                      (name, f"{name}: moved by 8 standard errors", cmd, text,
                       moved(numbers, 8 * math.sqrt(2) * se), None, 1)]
        else:
            cases += [(name, f"{name}: an exact number moved by 1e-9 of itself", cmd, text,
                       moved(numbers, 1e-9 * max(abs(numbers[0][1]), 1e-3)), None, 1)]
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for name, label, cmd, text, nums, edit, want in cases:
                doc = TABLES[name][0]
                begin, end = markers(name)
                os.makedirs(os.path.join(tmp, os.path.dirname(doc)), exist_ok=True)
                with open(os.path.join(tmp, doc), "w") as f:
                    f.write(f"text\n{begin}\n{end}\nmore\n")
                inner = put(tmp, doc, name, text)
                write_sidecar(os.path.join(tmp, SIDECARS, name + ".csv"), name, doc, cmd, inner,
                              nums)
                if edit:
                    with open(os.path.join(tmp, doc)) as f:
                        s = f.read()
                    with open(os.path.join(tmp, doc), "w") as f:
                        f.write(s.replace(edit[0], edit[1], 1))
                got = len(check(tmp, binary, [name], quiet=True))
                if got != want:
                    sys.exit(f"doc_tables.py: self-test: the control '{label}' gave {got} "
                             f"failures, not {want}")
    finally:
        TABLES.clear()
        TABLES.update(saved)
    print(f"doc_tables.py: self-test: {len(cases)} controls as expected", file=sys.stderr)


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
    cheap_only = args[:1] == ["--cheap"]
    if cheap_only:
        args = args[1:]
    checking = args[:1] == ["--check"]
    if checking:
        args = args[1:]
        if args[:1] == ["--self-test"]:
            self_test(binary)
            args = args[1:]
    for name in args:
        if name not in TABLES:
            usage(f"no table '{name}' (tables: {', '.join(TABLES)})")
    names = args or [n for n in TABLES if TABLES[n][2] or not cheap_only]
    if checking:
        failures = check(ROOT, binary, names)
        for f in failures:
            print(f"doc_tables.py: {f}", file=sys.stderr)
        sys.exit(1 if failures else 0)
    for name in names:
        doc, make, _ = TABLES[name]
        cmd, table, numbers = make(binary)
        made = (f"Made by `scripts/doc_tables.py {name}` on {time.strftime('%Y-%m-%d', time.gmtime())} "
                f"(commit {commit()}): `{cmd}`.\n\n")
        inner = put(ROOT, doc, name, made + table)
        write_sidecar(os.path.join(ROOT, SIDECARS, name + ".csv"), name, doc, cmd, inner, numbers)
        print(f"doc_tables.py: {doc}: table {name}", file=sys.stderr)


if __name__ == "__main__":
    main()
