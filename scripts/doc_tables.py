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
  rigid-limit    docs/contact.md: the compliant law at T = 1e-7 s against
                 its limit law and Poisson's, from make check's own test
                 (tests/unit/test_compliant.c's notes); compared exactly.
                 About 8 s of CPU.
  lasting-depth  docs/contact.md: the deepest lasting contact and energy
                 rise over make check's drops of four parts, from the same
                 test run as rigid-limit; compared exactly.
  fit-mirror     docs/calibration.md: scripts/fit-mirror.sh on ten seeds
                 (the fit's in-sample TV against fresh drops); the means
                 compared with the seeds' standard errors. About 20 s of CPU.
  topple-rules   docs/readings.md: --topple edge against the default on
                 every shipped part (static estimates); exact. Under 1 s.
  compliant-checks  docs/contact.md: what make check measures of the
                 compliant law (the law against an independent integration,
                 random impacts' energy, flat landings, Housner's rocking
                 block, the drops at half the tolerances), from the same test
                 run as rigid-limit; compared exactly.
  sphere-map     docs/figures.md: the gauss-sphere map against rays on the
                 insulator cap, from the same test run as painter; exact.
  pyramid-sums   docs/limits.md: the flat pyramids' probability sums
                 against the bound's round-off term, from make check's own
                 test (tests/unit/test_limits.c's note); exact. Under 1 s.
  tie-spread     docs/method.md: a 32-gon prism written with 6, 7 and 17
                 significant digits, the spread of its sides' QS
                 probabilities (what the tie tolerance stands above); exact.
                 Under 1 s.
  crn-coverage   docs/calibration.md: the fit's coverage test of make
                 check (tests/unit/test_fit.c's note); compared exactly.
                 About 2 s of CPU.

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
  bench-engines  docs/performance.md: make bench's engines section (the
                 three engines' cost per drop, the stepping engines against
                 their step). Several CPU minutes.
  bench-mujoco   docs/performance.md: scripts/bench-mujoco.py and whether
                 the goal of 40 times MuJoCo's speed is met; needs mujoco in
                 PYTHON (as python-bench). About 11 s of CPU.
  trimesh        docs/python.md: scripts/trimesh-table.py, posedrop's
                 stable poses against trimesh's; needs posedrop, trimesh and
                 pytest in PYTHON. About 2 s of CPU.
  extreme-scenes docs/engines-crosscheck.md: test_engine_extreme.c's rod,
                 flake and cube under its four scenes on the three engines,
                 10 drops each: unsettled drops. About 2 CPU minutes.
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

Records: blocks between '<!-- record NAME begin -->' and '<!-- record NAME
end -->' whose numbers were measured once and are not remade (hours of
CPU, or code that has changed since); each opens with a line giving the
command and the commit and date it was measured on (RECORDS below), and its
side file the hash of its text: --check (with no NAME) fails on a hand
edit. After a new measurement, edit the block and its RECORDS entry, then

    scripts/doc_tables.py --record NAME...

Python 3 standard library only; posedrop must be built (make all).
"""
import csv
import functools
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
    (sqrt(L/g) + sqrt(2h/g), of which the automatic time limit is 100)
    and the most collisions in a drop (maxima: not compared), and the CPU
    per drop (not compared)."""
    out = ["| cube edge | h / L | unsettled of 30 | slowest settled drop, natural units (s) | "
           "the time limit, 100 units | most collisions in a drop | CPU per drop |",
           "|---|---:|---:|---:|---:|---:|---:|"]
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
            slow = f"{max(settled) / unit:.1f} ({max(settled):.3g} s)" if settled else "-"
            out.append(f"| {edge} m | {0.12 / L:.3g} | {unsettled} | {slow} | "
                       f"{100 * unit:.4g} s | {max(int(r['collisions']) for r in rows)} | "
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
    (compared), the slowest drop and the most collisions (maxima: not
    compared) and CPU per drop (not)."""
    out = ["| part | drops | unsettled | slowest drop, simulated s | most collisions in a drop "
           "| CPU per drop |", "|---|---:|---:|---:|---:|---:|"]
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
                       f"{max(int(r['collisions']) for r in rows)} | {1e3 * cpu / n:.3g} ms |")
            numbers.append((f"unsettled {label}", unsettled / n, binomial_se(unsettled / n, n)))
    return ("posedrop -n N -j 1 --seed 1 [--tumble 3000] --trials FILE cube.off (cubes written "
            "by the script)", "\n".join(out), numbers)


def python_bench(binary):
    """python/bench.py's ratios, as it prints them: needs the posedrop
    module installed in the Python that $PYTHON names (default the
    git-ignored .venv's when there, as make bench-mujoco, else python3;
    docs/python.md says how to install it). Timings: not compared."""
    py = venv_python()
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
    notes = [l for l in test_notes(binary, "viz")
             if l.startswith("viz: painter's order vs depth buffer, parts/")]
    if not notes:
        sys.exit("doc_tables.py: no painter's-order notes in test_posedrop viz")
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


@functools.lru_cache(maxsize=None)
def test_notes(binary, suite):
    """make check's suite SUITE run alone with its notes (PD_TEST_VERBOSE=1):
    the lines it prints."""
    test_bin = os.path.join(os.path.dirname(binary), "test_posedrop")
    if not os.access(test_bin, os.X_OK):
        sys.exit(f"doc_tables.py: {test_bin} not built (make {os.path.relpath(test_bin, ROOT)})")
    run = subprocess.run([test_bin, suite], cwd=ROOT, capture_output=True, text=True,
                         env=dict(os.environ, PD_TEST_VERBOSE="1"))
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: test_posedrop {suite} failed:\n{run.stdout[-1500:]}"
                 f"{run.stderr[-1500:]}")
    return tuple((run.stdout + run.stderr).splitlines())


def note_numbers(lines, start, pattern):
    """The numbers PATTERN (a regular expression) finds in the one note
    that starts with START."""
    import re
    hits = [l for l in lines if l.startswith(start)]
    m = re.search(pattern, hits[0]) if len(hits) == 1 else None
    if not m:
        sys.exit(f"doc_tables.py: no note '{start}' matching '{pattern}' in the test's output")
    return [float(g) for g in m.groups()]


def rigid_limit(binary):
    """docs/contact.md's rigid limit: the compliant law at T = 1e-7 s against
    its limit law and Poisson's, as tests/unit/test_compliant.c measures it
    in every make check (its notes). Deterministic: compared exactly (as
    printed, two digits)."""
    notes = test_notes(binary, "compliant")
    num = r"([-0-9.e+]+)"
    (f8, _, s8, _, _, _, s32, s64, f64, lawp_f, lawp_s, _) = note_numbers(
        notes, "compliant: rigid limit at T = 1e-7 s vs Poisson",
        rf"frictionless {num} over {num}, sliding {num} over {num} .*step {num} and {num}; "
        rf".*sliding: {num} and {num} \(frictionless {num} at a 64th\); the limit law vs "
        rf"Poisson, frictionless {num}, sliding {num}; .*within {num} of")
    stop_n, st8, st32, lp_lo, lp_hi, _ = note_numbers(
        notes, "compliant: limit law where the slip stops",
        rf"{num} cases, compliant within {num} \(an 8th.*, {num} \(a 32nd\); the limit law vs "
        rf"Poisson {num} to {num}; .*impact.c {num}")
    strikes = []
    for l in notes:
        if l.startswith("compliant: rigid limit vs Poisson on "):
            n, part = l.split(" on ", 1)[1].split(" lone-corner strikes of ")
            part, rest = part.split(":", 1)
            worst, mean = note_numbers([l], l[:30], rf"up to {num} .*, centre's velocity {num}")
            strikes.append((os.path.basename(part), int(n), worst, mean))
    if not strikes:
        sys.exit("doc_tables.py: no lone-corner strike notes in test_posedrop compliant")
    real = "; ".join(f"{p} ({n}): up to {w:.2g}, {100 * m:.2g}% of the corner's approach "
                     f"speed on average" for p, n, w, m in strikes)
    out = ["| compared | frictionless | sliding fast in 3-D (random bodies) | slip stopping "
           f"(closed form, {stop_n:.0f} cases) | real strikes (lone corners) |",
           "|---|---|---|---|---|",
           f"| compliant, a 64th of its step, against its limit law | {f64:.2g} | {s64:.2g} "
           f"({s32:.2g} at a 32nd) | {st32:.2g} at a 32nd, {st8:.2g} at an 8th | |",
           f"| its limit law against Poisson's (impact.c) | {lawp_f:.2g} | up to {lawp_s:.2g} | "
           f"{lp_lo:.2g} to {lp_hi:.2g} | |",
           f"| compliant, an eighth of its step, against Poisson's | {f8:.2g} | {s8:.2g} | | "
           f"{real} |"]
    numbers = [("frictionless 64th vs limit", f64), ("sliding 64th vs limit", s64),
               ("sliding 32nd vs limit", s32), ("stops 32nd", st32), ("stops 8th", st8),
               ("limit vs Poisson frictionless", lawp_f), ("limit vs Poisson sliding", lawp_s),
               ("stops limit vs Poisson lo", lp_lo), ("stops limit vs Poisson hi", lp_hi),
               ("frictionless 8th vs Poisson", f8), ("sliding 8th vs Poisson", s8)]
    numbers += [(f"strikes {p} worst", w) for p, _, w, _ in strikes]
    # The test's random bodies and strikes come from fixed seeds: exact, but
    # for the frictionless limit law against Poisson's, round-off (not
    # compared).
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop compliant (tests/unit/test_compliant.c: "
            "test_rigid_limit, test_rigid_limit_stops, test_rigid_limit_strikes)",
            "\n".join(out),
            [(k, v, None if k == "limit vs Poisson frictionless" else 0.0) for k, v in numbers])


def sphere_map(binary):
    """docs/figures.md: the gauss-sphere map against rays on the insulator
    cap, as tests/unit/test_viz.c's test_sphere_map measures it in every
    make check (its note; the same run as painter's), with the rim's chords'
    gap and band from the arcs' step (src/viz/viz_const.h). Deterministic:
    compared exactly."""
    num = r"([-0-9.e+]+)"
    wrong, n, rim = note_numbers(
        test_notes(binary, "viz"), "viz: sphere map:",
        rf"{num} of {num} random directions in another facet's region, {num} in the rim's chords")
    import re
    with open(os.path.join(ROOT, "src/viz/viz_const.h")) as f:
        step = float(re.search(r"#define VIZ_ARC_STEP_DEG ([0-9.]+)", f.read()).group(1))
    gap = 1 - math.cos(math.radians(step) / 2)
    band = math.sqrt(2 * gap)
    text = ("| random directions (insulator cap) | in another facet's region (on region sides) "
            "| in the rim's chords | arcs' points at most | their gap from the arc | "
            "the rim's band |\n|---:|---:|---:|---:|---:|---:|\n"
            f"| {n:.0f} | {wrong:.0f} | {rim:.0f} | {step:g} deg | {gap:.2g} of the radius | "
            f"\\|z\\| < {band:.2g} |")
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop viz (tests/unit/test_viz.c, "
            "test_sphere_map; VIZ_ARC_STEP_DEG in src/viz/viz_const.h)", text,
            [("directions", n, 0.0), ("another region", wrong, 0.0), ("rim", rim, 0.0)])


def compliant_checks(binary):
    """docs/contact.md: what make check measures of the compliant law
    (tests/unit/test_compliant.c's notes; the same run as rigid-limit's):
    the law against an independent integration, random impacts' energy,
    flat landings, Housner's rocking block, and the drops at half the
    integration tolerances. Deterministic: compared exactly (as printed)."""
    import re
    notes = test_notes(binary, "compliant")
    num = r"([-0-9.e+]+)"
    e_err, t_err = note_numbers(notes, "compliant: law vs independent integration",
                                rf"e {num}, T {num} relative")
    n_imp, worst = note_numbers([l for l in notes if " random impacts, " in l], "compliant: ",
                                rf"{num} random impacts, energy change at most {num} of the start")
    out = ["| checked | measured | bound |", "|---|---|---|",
           f"| the law's rebound and duration against an independent dimensional integration | "
           f"e {e_err:.2g}, T {t_err:.2g} relative at worst | 1e-6 |",
           f"| {n_imp:.0f} random single-vertex impacts of random bodies (100000 under "
           f"`--full`) | energy change at most {worst:.3g} of the start | no rise |"]
    numbers = [("law e", e_err, None), ("law T", t_err, None), ("impacts", n_imp, 0.0),
               ("impacts energy", worst, 0.0)]
    def matches(pattern):
        return [m for m in (re.match(pattern, l) for l in notes) if m]

    flats = matches(rf"compliant: flat landing on (\d+) contacts: rebound off e by {num}, "
                    rf"{num} at half")
    numbers += [(f"flat {m.group(1)}", float(m.group(2)), 0.0) for m in flats]
    out.append("| flat landings (rebound off e, no spin to round-off) | " + "; ".join(
        f"{m.group(1)} contacts: {float(m.group(2)):.2g} ({float(m.group(3)):.2g} at half the "
        f"step)" for m in flats) + " | PD_COMPLIANT_E_TOL, first order at half the step |")
    blocks = matches(rf"compliant: Housner block alpha (\d+) deg: rate ratio {num}, "
                     rf"closed form {num}")
    numbers += [(f"housner {m.group(1)}", float(m.group(2)), 0.0) for m in blocks]
    out.append("| Housner's rocking block, rate ratio against 1 - 1.5 sin^2 alpha | " + "; ".join(
        f"{m.group(1)} deg: {float(m.group(2)):.3f} against {float(m.group(3)):.3f}"
        for m in blocks) + " | 2% |")
    drops = matches(rf"compliant: parts/(\S+), (\d+) drops at tolerance scale 1 and 0.5: "
                    rf"chi-square {num} on (\d+) dof, p {num}; unsettled (\d+), (\d+)")
    numbers += [(f"{m.group(1)} p", float(m.group(5)), 0.0) for m in drops]
    out.append("| pose distributions at half of every integration tolerance (chi-square "
               "homogeneity; depth and energy: the table of lasting contacts) | " + "; ".join(
                   f"`{m.group(1)}` {m.group(2)} drops, p {m.group(5)}, unsettled {m.group(6)} "
                   f"and {m.group(7)}" for m in drops) + " | p > 0.01, every drop settled |")
    if len(flats) != 2 or len(blocks) != 3 or not drops:
        sys.exit("doc_tables.py: missing flat-landing, Housner or drop notes in "
                 "test_posedrop compliant")
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop compliant (tests/unit/test_compliant.c: "
            "test_law_closed_form, test_energy_random_impacts, test_flat_landings, "
            "test_housner, test_convergence)",
            "\n".join(out), numbers)


def pyramid_sums(binary):
    """docs/limits.md: how far the flat pyramids' probabilities sum off 1,
    against the bound's second term DBL_EPSILON L/h, as
    tests/unit/test_limits.c's test_flat_pyramids measures it in every make
    check (its note). Deterministic: compared exactly."""
    num = r"([-0-9.e+]+)"
    answered, refused, worst = note_numbers(
        test_notes(binary, "limits"), "limits: flat pyramids:",
        rf"{num} answered, {num} refused; probability sums off 1 by at most {num} of")
    text = ("| pyramids of 3 to 64 sides, h/r 1e-7 to 1e-3 | answered (both topple rules) | "
            "refused | sums off 1 at most, in DBL_EPSILON L/h |\n|---|---:|---:|---:|\n"
            f"| make check's sweep | {answered:.0f} | {refused:.0f} | {worst:.2g} |")
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop limits (tests/unit/test_limits.c, "
            "test_flat_pyramids)", text,
            [("answered", answered, 0.0), ("refused", refused, 0.0), ("worst", worst, 0.0)])


def tie_spread(binary):
    """docs/method.md: a regular 32-gon prism (circumradius 1, height 1)
    written with 6, 7 and 17 significant digits: the spread of its 32 sides'
    QS probabilities (largest minus smallest over their mean), what the tie
    tolerance must stand above. Deterministic: compared exactly."""
    out = ["| coordinates printed with | sides' QS probabilities spread by (relative) |",
           "|---|---:|"]
    numbers = []
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "prism.off")
        n = 32
        v = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), z)
             for z in (0.0, 1.0) for k in range(n)]
        faces = [tuple(reversed(range(n))), tuple(range(n, 2 * n))]
        faces += [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]
        for digits in (6, 7, 17):
            with open(path, "w") as f:
                f.write(f"OFF\n{len(v)} {len(faces)} 0\n")
                for p in v:
                    f.write(" ".join(f"{c:.{digits}g}" for c in p) + "\n")
                for t in faces:
                    f.write(f"{len(t)} " + " ".join(str(i) for i in t) + "\n")
            rows = list(csv.DictReader(posedrop(binary, [path]).splitlines()))
            sides = [float(r["p_qs"]) for r in rows if abs(float(r["nz"])) < 0.5]
            if len(sides) != n:
                sys.exit(f"doc_tables.py: the 32-gon prism at {digits} digits has "
                         f"{len(sides)} side poses")
            spread = (max(sides) - min(sides)) / (sum(sides) / n)
            out.append(f"| {digits} significant digits | {spread:.2g} |")
            numbers.append((f"{digits} digits", float(f"{spread:.2g}"), 0.0))
    return ("posedrop PRISM.off, a regular 32-gon prism of circumradius and height 1 written "
            "by the script with 6, 7 and 17 significant digits", "\n".join(out), numbers)


def extreme_scenes(binary):
    """tests/unit/test_engine_extreme.c's parts and scenes from the command,
    10 drops each at the default limits: drops left unsettled, and failed
    (an unsettled count of 10 drops has a binomial error; compared)."""
    parts = (("1 m x 1 cm x 1 cm rod", (1.0, 0.01, 0.01)),
             ("1 x 1 x 0.01 mm flake", (1e-3, 1e-3, 1e-5)),
             ("1 mm cube", (1e-3, 1e-3, 1e-3)))
    scenes = (("mu 10", ["--mu", "10"]), ("e 0", ["--restitution", "0"]),
              ("e 1", ["--restitution", "1"]), ("e 1, mu 0", ["--restitution", "1", "--mu", "0"]))
    out = ["| part, scene | impulse | ode | bullet |", "|---|---|---|---|"]
    numbers, failed = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for label, dims in parts:
            path = os.path.join(tmp, "part.off")
            box_off(path, *dims)
            for scene, opts in scenes:
                cells = []
                for engine in ("impulse", "ode", "bullet"):
                    rows, _, _ = drops_run(binary, path, 10, ["--engine", engine] + opts)
                    unsettled = sum(r["end"] != "settled" for r in rows)
                    failed += sum(r["end"] == "failed" for r in rows)
                    cells.append(str(unsettled))
                    numbers.append((f"{label}, {scene}, {engine}", unsettled / 10,
                                    binomial_se(unsettled / 10, 10)))
                out.append(f"| {label}, {scene} | " + " | ".join(cells) + " |")
    out += ["", f"Failed drops in all: {failed}."]
    return ("posedrop -n 10 -j 1 --seed 1 --engine E [--mu 10 | --restitution 0 | --restitution 1 "
            "[--mu 0]] --trials FILE PART (boxes written by the script)", "\n".join(out), numbers)


def lasting_depth(binary):
    """docs/contact.md: the deepest lasting contact and the largest energy
    rise over make check's drops of tests/unit/test_compliant.c's
    test_convergence (its notes; the same run as rigid-limit's).
    Deterministic: compared exactly."""
    import re
    out = ["| part | drops | deepest lasting contact | energy rise at most | unsettled |",
           "|---|---:|---:|---:|---:|"]
    numbers = []
    for l in test_notes(binary, "compliant"):
        m = re.match(r"compliant: (\S+), (\d+) drops at tolerance scale 1 and 0.5: .*unsettled "
                     r"(\d+), (\d+); lasting contact depth at most ([-0-9.e+]+) L; energy rise "
                     r"at most ([-0-9.e+]+) L", l)
        if m:
            part, n, u1, u2, depth, rise = m.groups()
            out.append(f"| `{part[len('parts/'):]}` | {n} | {depth} L | {rise} L | {u1}, {u2} |")
            numbers += [(f"{part} depth", float(depth), 0.0), (f"{part} rise", float(rise), 0.0)]
    if not numbers:
        sys.exit("doc_tables.py: no lasting-contact notes in test_posedrop compliant")
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop compliant (tests/unit/test_compliant.c, "
            "test_convergence: the automatic contact time, tolerance scales 1 and 0.5)",
            "\n".join(out), numbers)


def topple_rules(binary):
    """docs/readings.md: the static estimate under --topple edge against the
    default (descent) on every shipped part: the same CSV byte for byte, or
    the largest difference of a pose's QS probability. Exact."""
    out = ["| part | poses | `--topple edge` and the default | largest QS difference |",
           "|---|---:|---|---:|"]
    numbers = []
    for name in sorted(os.listdir(os.path.join(ROOT, "parts"))):
        if not name.endswith((".off", ".obj", ".stl")):
            continue
        path = "parts/" + name
        units = ["--units", "mm"] if name.endswith((".obj", ".stl")) else []
        a = posedrop(binary, units + [path])
        b = posedrop(binary, units + ["--topple", "edge", path])
        ra, rb = list(csv.DictReader(a.splitlines())), list(csv.DictReader(b.splitlines()))
        diff = (max(abs(float(x["p_qs"]) - float(y["p_qs"])) for x, y in zip(ra, rb))
                if len(ra) == len(rb) else float("nan"))
        same = "the same CSV" if a == b else (
            "the same poses" if len(ra) == len(rb) else "different poses")
        out.append(f"| `{name}` | {len(ra)} | {same} | {diff:.3g} |")
        numbers.append((f"{name} same", float(a == b), 0.0))
    return ("posedrop [--units mm] [--topple edge] PART, each shipped part (the .obj and .stl "
            "in mm)", "\n".join(out), numbers)


def crn_coverage(binary):
    """docs/calibration.md: the fit's coverage test as make check runs it
    (tests/unit/test_fit.c, its note): intervals covering the truth, of
    200, and their mean width. Deterministic: compared exactly."""
    num = r"([-0-9.e+]+)"
    covered, n, bound, width = note_numbers(
        test_notes(binary, "fit"), "CRN coverage:",
        rf"{num} of {num} \(bound {num}\), mean width {num}")
    text = (f"| intervals covering the truth | bound (3 standard deviations below 95%) | "
            f"mean width |\n|---:|---:|---:|\n| {covered:.0f} of {n:.0f} | {bound:g} | "
            f"{width:.3f} |")
    return ("PD_TEST_VERBOSE=1 build/opt/test_posedrop fit (tests/unit/test_fit.c, the "
            "coverage test)", text, [("covered", covered, 0.0), ("width", width, 0.0)])


def venv_python():
    """The Python that $PYTHON names, else the git-ignored .venv's when
    there (as make bench-mujoco), else python3."""
    venv = os.path.join(ROOT, ".venv/bin/python")
    return os.environ.get("PYTHON") or (venv if os.access(venv, os.X_OK) else "python3")


def bench_mujoco(binary):
    """scripts/bench-mujoco.py's table as it prints it, and whether the
    goal of 40 times MuJoCo's speed per drop is met on each part (by the
    ratio over all MuJoCo's drops and over its settled ones). Needs the
    mujoco package in $PYTHON (make bench-mujoco's .venv). Timings: not
    compared."""
    py = venv_python()
    run = subprocess.run([py, os.path.join(ROOT, "scripts/bench-mujoco.py"), "--posedrop",
                          os.path.relpath(binary, ROOT)], cwd=ROOT, capture_output=True,
                         text=True)
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: {py} scripts/bench-mujoco.py failed (is mujoco installed in "
                 f"it? set PYTHON): {run.stderr.strip()[-1500:]}")
    lines = run.stdout.strip().splitlines()
    met, unmet = [], []
    for l in lines:
        f = l.split()
        if len(f) == 9 and f[-1].endswith("x") and f[-2].endswith("x"):
            ratios = (float(f[-2][:-1]), float(f[-1][:-1]))
            (met if min(ratios) >= 40 else unmet).append(f"{f[0]} ({f[-2]}, {f[-1]} settled)")
    if not met and not unmet:
        sys.exit("doc_tables.py: scripts/bench-mujoco.py printed no ratios")
    text = ("```text\n" + "\n".join(lines) + "\n```\n\n"
            f"The goal of 40 times MuJoCo's speed per drop, by both ratios: met on "
            f"{', '.join(met) or 'no part'}; not met on {', '.join(unmet) or 'no part'}.")
    return "python scripts/bench-mujoco.py (make bench-mujoco)", text, []


def trimesh_table(binary):
    """scripts/trimesh-table.py: posedrop.compute_stable_poses against
    trimesh's. Needs the posedrop module, trimesh and pytest in $PYTHON.
    Deterministic but for its timings (not compared)."""
    py = venv_python()
    run = subprocess.run([py, os.path.join(ROOT, "scripts/trimesh-table.py")], cwd=ROOT,
                         capture_output=True, text=True)
    if run.returncode != 0 or "#numbers" not in run.stdout:
        sys.exit(f"doc_tables.py: {py} scripts/trimesh-table.py failed (are posedrop, trimesh "
                 f"and pytest installed in it? set PYTHON): {run.stderr.strip()[-1500:]}")
    text, nums = run.stdout.split("#numbers\n", 1)
    numbers = [(k, float(v), float(se)) for k, v, se in
               (l.rsplit(",", 2) for l in nums.strip().splitlines())]
    return "python scripts/trimesh-table.py", text.strip(), numbers


def fit_mirror(binary):
    """scripts/fit-mirror.sh on ten seeds: the fit's in-sample TV against its
    own fresh check and 20,000 fresh drops, on the box's mirror pairs.
    Deterministic for a binary (the fit's drops come from its seed); a
    mean's standard error is the seeds' spread, so the means are compared
    with it."""
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run([os.path.join(ROOT, "scripts/fit-mirror.sh"), "-s",
                              "1 2 3 4 5 6 7 8 9 10", "-o", tmp], cwd=ROOT, capture_output=True,
                             text=True, env=dict(os.environ, POSEDROP=binary))
    if run.returncode != 0:
        sys.exit(f"doc_tables.py: scripts/fit-mirror.sh failed: {run.stderr.strip()[-1500:]}")
    out = ["| seed | in-sample TV | its own fresh check (300 drops) | fresh TV, 20,000 drops |",
           "|---|---|---|---|"]
    numbers, insample = [], []
    for l in run.stdout.splitlines():
        f = [c.strip() for c in l.split("|")]
        if len(f) == 4 and f[0].isdigit():
            out.append(f"| {' | '.join(f)} |")
            insample.append(float(f[1]))
        elif l.startswith("mean of "):
            out.append(f"| mean | {' | '.join(f[1:])} |")
            for name, cell in zip(("in-sample", "own fresh check", "fresh 20000"), f[1:]):
                v, se = (float(x) for x in cell.split("+-"))
                numbers.append((f"mean {name}", v, se))
        elif l.startswith("in-sample minus fresh"):
            diff = l.split(": ", 1)[1]
            v, se = (float(x) for x in diff.split("(")[0].split("+-"))
            numbers.append(("in-sample minus own check", v, se))
    if len(out) != 13 or len(numbers) != 4:
        sys.exit(f"doc_tables.py: scripts/fit-mirror.sh printed an unexpected table:\n"
                 f"{run.stdout[-1500:]}")
    v, se = numbers[-1][1:]
    out += ["", f"In-sample minus the fit's own fresh check: {v:.3f} +- {se:.3f} "
            f"({'within' if abs(v) <= 2 * se else 'beyond'} two standard errors of zero). "
            f"The lowest in-sample TV {min(insample):.3f}; {sum(x < 0.070 for x in insample)} "
            f"of the 10 seeds below the 0.070 that no scene of the model can beat."]
    return ('scripts/fit-mirror.sh -s "1 2 3 4 5 6 7 8 9 10"', "\n".join(out), numbers)


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
          "bench-engines": ("docs/performance.md", bench(["engines"], (
              "Each engine's cost per drop on the same parts and scene, and the stepping "
              "engines against their step.")), False),
          "bench-mujoco": ("docs/performance.md", bench_mujoco, False),
          "rigid-limit": ("docs/contact.md", rigid_limit, True),
          "crn-coverage": ("docs/calibration.md", crn_coverage, True),
          "topple-rules": ("docs/readings.md", topple_rules, True),
          "lasting-depth": ("docs/contact.md", lasting_depth, True),
          "compliant-checks": ("docs/contact.md", compliant_checks, True),
          "sphere-map": ("docs/figures.md", sphere_map, True),
          "pyramid-sums": ("docs/limits.md", pyramid_sums, True),
          "tie-spread": ("docs/method.md", tie_spread, True),
          "extreme-scenes": ("docs/engines-crosscheck.md", extreme_scenes, False),
          "trimesh": ("docs/python.md", trimesh_table, False),
          "fit-mirror": ("docs/calibration.md", fit_mirror, True),
          "fuzz": ("docs/cli-input.md", fuzz, False),
          "test-cost": ("docs/development.md", test_cost, False),
          "python-bench": ("docs/python.md", python_bench, False)}
SIDECARS = "docs/figures/tables"

# Records: blocks of a doc, between '<!-- record NAME begin -->' and
# '<!-- record NAME end -->', whose numbers were measured once and are not
# remade by make figures (hours of CPU, or code that has changed since).
# Each opens with a line naming the command, the commit and the date of the
# measurement; its side file docs/figures/tables/NAME.csv holds them with a
# hash of the block, so that --check fails on a hand edit. After measuring
# again: edit the block's text, set its entry here, and run
# `scripts/doc_tables.py --record NAME`. name: (doc, command, when: the
# commit and the date).
RECORDS = {
    "contact-sweeps": (
        "docs/contact.md", "the compliant steps of the coin and the insulator cap "
        "traced, the sweeps' contraction and their stops at the cap of 32 counted (an "
        "experimental build; no script kept)",
        "on 2026-11-28 (first recorded in commit 05efb3e)"),
    "figures-report-words": (
        "docs/figures.md", "posedrop -n 1000 --group --mu 0.2:0.6 --report r.html "
        "parts/insulator_cap.off, the report's words on poses 2 and 4",
        "on 2026-12-07 at commit 1044ecc"),
    "xc-corpus-reading": (
        "docs/engines-crosscheck.md", "the corpus table's runs above (scripts/engine-convergence.py "
        "--k auto, kept in docs/figures/corpus/) read against 165ca49's in "
        "docs/figures/corpus-earlier.csv, and their CPU seconds",
        "on 2026-12-07 at d17ddd1's engines (first recorded in commit 95e8773)"),
    "xc-halving": (
        "docs/engines-crosscheck.md", "scripts/engine-convergence.py --k 40 with the commands "
        "the paragraph gives, runs kept in docs/figures/corpus/conv40*/",
        "on 2026-12-07 at b96ba9f (165ca49's engines), d17ddd1 and 5e62da6 (first recorded "
        "in commits 5e62da6 and 1af9231)"),
    "contact-top-spin": (
        "docs/contact.md", "posedrop -n 30 on cubes of 1e-7 to 1e6 m (limits.md's cube table of "
        "that day), the 0.1 mm cube's unsettled drops traced",
        "on 2026-11-26 (first recorded in commit 67d36e5)"),
    "contact-limit-checks": (
        "docs/contact.md", "the sizes of tests/unit/test_compliant.c's rigid-limit tests (10 "
        "bodies of 40 impacts; slips stopped at 0.15, 0.45 and 0.75 of the impact), as the "
        "code gives them",
        "on 2026-11-28 (first recorded in commit d704941)"),
    "xc-referee-model": (
        "docs/engines-crosscheck.md", "scripts/referee-mujoco.py on the cube started resting "
        "on a face, MuJoCo at T/20 and T/40",
        "on 2026-12-07 (first recorded in commit 91fa0ec)"),
    "validation-flat-rest": (
        "docs/validation.md", "tests/unit/test_flat_rest.c's drops with and without the early "
        "decision, their collisions counted (an experimental build; no script kept)",
        "on 2026-11-23 (first recorded in commit d704941)"),
    "limits-height": (
        "docs/limits.md", "posedrop -n 2 -j 1 cube.off, cubes of 1 mm, 0.1 mm and 10 um "
        "written by hand, the CPU seconds of each whole run",
        "on 2026-12-07 under a load of about 10 (first recorded in commit 7507e8b)"),
    "limits-corpus": (
        "docs/limits.md", "tests/unit/test_hard_parts.c's corpus with its trial records "
        "printed (an experimental build; no script kept)",
        "on 2026-11-27 (first recorded in commit 91aa1c1)"),
    "limits-tops": (
        "docs/limits.md", "posedrop -n 200 (100) -j 1 --seed 1 --trials FILE on cubes of "
        "0.1 mm and 0.03 mm, drops traced one by one, and callgrind on the phases' "
        "integrators (experimental builds; no script kept)",
        "on 2026-11-27 (first recorded in commit 175182f)"),
    "limits-spike": (
        "docs/limits.md", "posedrop on parts/square_black_button.off with the corner moved "
        "(the file tests/unit/test_part.c mutates), before and after the refit",
        "on 2026-11-27 (first recorded in commit 03f0188)"),
    "limits-crossing": (
        "docs/limits.md", "an experimental harness against the sort and sweep of axis-aligned "
        "boxes it replaced (no script kept)", "on 2026-11-27 (first recorded in commit 732c595)"),
    "limits-stepping": (
        "docs/limits.md", "tests/unit/test_hard_parts.c's failing cases on ODE and Bullet, "
        "drops stepped and printed one by one (PD_TEST_VERBOSE=1)",
        "on 2026-11-27 (first recorded in commit 6077063)"),
    "contact-strikes": (
        "docs/contact.md", "an experimental build's strike sampler (no script kept; "
        "tests/unit/test_compliant.c's test_rigid_limit_strikes is its small form)",
        "on 2026-11-28 (first recorded in commit 1035b5d)"),
    "engines-model": (
        "docs/engines.md", "tests/unit/test_engine_contact.c, test_engine_ode.c, "
        "test_engine_bullet.c and test_hard_parts.c (PD_TEST_VERBOSE=1), and the runs of "
        "engines-crosscheck.md that each row names",
        "from 2026-11-27 to 2026-12-07, each row on the engines of its day (the table as of "
        "commit d17ddd1)"),
    "fit-mirror-before": (
        "docs/calibration.md", 'scripts/fit-mirror.sh -s "1 2 3 4 5 6 7 8 9 10" with the '
        "binary of commit e8d8523 (the search on its own drops)", "at commit e8d8523 on 2026-12-07"),
    "fit-coverage": (
        "docs/calibration.md", "PD_TEST_VERBOSE=1 build/opt/test_posedrop --full fit (340 s "
        "of CPU)", "on 2026-12-07, with the discrepancy's change (first recorded in commit "
        "119e480)"),
    "fit-tempering": (
        "docs/calibration.md", "PD_TEST_VERBOSE=1 build/opt/test_posedrop fit (the coverage "
        "test) with the tempering, the Dirichlet-multinomial and the weighting on S/4 drops",
        "on 2026-12-07 (first recorded in commit 5cff1f7)"),
    "contact-limits": (
        "docs/contact.md", "the runs each item names: a cube's and a 32-gon coin's flat "
        "landings (contact duration), posedrop -n 20000 on parts/canonical/coin_h0.25.off "
        "with --trials (the longest drop), and 4000 drops before and after the rest step's fix; "
        "the compliant impact's steps counted in an instrumented build",
        "on 2026-11-26 (commits f21fb18 and 36195ce) and 2026-11-27 (the steps, commit "
        "e86ff11)"),
    "contact-slip-onset": (
        "docs/contact.md", "posedrop -n 200 -j 1 --seed 1 --trials FILE on a 0.1 mm cube, drops "
        "traced one by one (experimental builds), and paired runs of the cube, box, coin and "
        "cap before and after the slip onset", "on 2026-11-27 (first recorded in commits "
        "d1177b3 and 175182f)"),
    "contact-auto-before": (
        "docs/contact.md", "posedrop -n 200 on a 1 m x 1 mm needle, and 2000 (600) uniform drops "
        "of the cube, box, coin and the paper's parts, before and after the volume entered the "
        "automatic contact time", "on 2026-11-27 (first recorded in commit 19f10f0)"),
    "contact-resting-before": (
        "docs/contact.md", "the contact-time table's resting cube (600 drops) on the rigid model "
        "before the compliant one, on ODE at 1 ms, Bullet and MuJoCo (scripts/referee-mujoco.py "
        "of that day)", "on 2026-11-26 (first recorded in commit f21fb18)"),
    "limits-outside-range": (
        "docs/limits.md", "posedrop on cubes of 1e-89 m to 1e308 m written by hand, before the "
        "size range was enforced", "on 2026-11-26 (first recorded in commit fa7f553)"),
    "limits-stepping-golden": (
        "docs/limits.md", "the golden test's four parts, 3000 drops each on ODE and Bullet "
        "before and after the drilling friction, the margin and Bullet's mass unit",
        "on 2026-11-27 (first recorded in commit 04daf37)"),
    "limits-roundoff": (
        "docs/limits.md", "flat pyramids turned and moved off the origin through the part build, "
        "their second moments' most negative over the largest (an experimental build; no "
        "script kept)", "on 2026-11-27 (first recorded in commit d41caf7)"),
    "limits-rolling": (
        "docs/limits.md", "Tabor's estimate worked from the scene's parameters; Housner's ratio "
        "of the 64-gon coin's corner landings as measured for contact.md's known limits",
        "on 2026-11-26 (the ratio, commit 36195ce) and 2026-11-27 (first recorded in commit "
        "175182f)"),
    "calibration-cost": (
        "docs/calibration.md", "scripts/paper.sh -L on the paper's four parts, both seeds, its "
        "folds' CPU seconds, evaluations and drops (validation.md's leave-one-out), on each "
        "version of the fit the text names", "on 2026-12-07 (the first figures at commit "
        "0cdda07; the earlier at 119e480 and 5cff1f7)"),
    "readings-topple-before": (
        "docs/readings.md", "posedrop [--topple edge] on parts/square_black_button.off as "
        "shipped before its refit", "on 2026-11-27 (first recorded in commit 446b3d9; first "
        "seen on 2026-11-26)"),
    "readings-eq2": (
        "docs/readings.md", "the paper's route of eq. (1)-(3) implemented in double precision "
        "against the closed form, on right isosceles triangles (no script kept)",
        "on 2026-11-26 (first recorded in commit 8f24208)"),
    "design-demos": (
        "docs/design.md", "scripts/design-demos.sh (docs/figures/design/summary.md; tens of "
        "CPU minutes)", "at commits bba359c and 61b4a6f (the bushing) on 2026-12-07"),
    "xc-contact-steps": (
        "docs/engines-crosscheck.md", "tests/unit/test_engine_contact.c's corner strike (a 1 cm "
        "cube, 0.5 m/s) at each step, under the linear law of that day (replaced since), and "
        "on ODE under the pulling formula", "on 2026-11-26 (first recorded in commit ab5ee7b)"),
    "xc-rod-depth": (
        "docs/engines-crosscheck.md", "posedrop -n 100 --engine ode [--contact-time 0.03] on "
        "a 1 m x 3.3 mm rod written by hand, before and after the depth rule",
        "on 2026-11-27 (first recorded in commit c5e6782)"),
    "xc-extreme-before": (
        "docs/engines-crosscheck.md", "tests/unit/test_engine_extreme.c's parts and scenes, "
        "10 drops each, on the ODE and Bullet adapters before their fixes",
        "on 2026-11-26 (first recorded in commits ab5ee7b and 7a47f8f)"),
    "xc-ode-units": (
        "docs/engines-crosscheck.md", "posedrop --engine ode on the parts and sizes named, 300 "
        "drops each, before and after the adapter's units (tests/unit/test_engine_ode.c)",
        "on 2026-11-26 (first recorded in commit ab5ee7b)"),
    "xc-floor-contacts": (
        "docs/engines-crosscheck.md", "posedrop --engine ode|bullet on the flake, the rod and "
        "the parts named, before and after the adapters' floor contacts "
        "(tests/unit/test_engine_extreme.c's scenes)", "on 2026-11-26 (first recorded in "
        "commits ab5ee7b and 7a47f8f)"),
    "xc-gyroscopic": (
        "docs/engines-crosscheck.md", "Bullet's free flight and the flake's bounce at e 1 with "
        "the explicit and the implicit gyroscopic term (tests/unit/test_engine_bullet.c)",
        "on 2026-11-26 (first recorded in commit 7a47f8f)"),
    "xc-box-trace": (
        "docs/engines-crosscheck.md", "posedrop -n 1 --seed 3 --group --engine E [--dt H] "
        "--trace FILE --trace-drop 0 parts/canonical/box_1x2x3.off, 165ca49's engines",
        "on 2026-12-07 (first recorded in commit 69f232e)"),
    "xc-white-button": (
        "docs/engines-crosscheck.md", "posedrop -n 600 --seed 5 (6, 7) [--engine ode|bullet] "
        "[--dt 1e-5] parts/white_button.off, on main ebdd1fe and on the two fixes' builds; "
        "an experimental strike harness on the stepping engines and the impulse engine's laws "
        "(no script kept)", "on 2026-11-28 (first recorded in commit 1035b5d)"),
    "xc-lone-vertex": (
        "docs/engines-crosscheck.md", "posedrop -n 6000 --seed 5 parts/white_button.off on "
        "experimental builds (not committed), and the strike harness of the record above on "
        "the same generator", "on 2026-11-28 (first recorded in commit d704941)"),
    "xc-white-button-drops": (
        "docs/engines-crosscheck.md", "posedrop -n 600 --seed 5 (6, 7) parts/white_button.off "
        "on the impulse engine (with Stronge's law, a contact time of 3.3e-4 s, no friction) "
        "and on ODE after the first fix; the engines' law on test_engine_contact.c's cube "
        "strike", "on 2026-11-28 (first recorded in commit 1035b5d)"),
    "xc-convergence": (
        "docs/engines-crosscheck.md", "scripts/engine-convergence.py -o DIR -n 300 --engines "
        "impulse,ode --k 10,20,40,80 (and --engines bullet), and 1000 drops per engine at the "
        "old default steps", "at commit 9f2cb89 on 2026-12-07"),
    "xc-contact-points": (
        "docs/engines-crosscheck.md", "posedrop -n 300 --seed 3 --group --engine ode at T / 20 "
        "on parts/flanged_bushing.off with up to 64 contact points (an experimental build, not "
        "committed); --trace and scripts/trace-compare.py on the white button's drop 0",
        "on 2026-12-07 (first recorded in commit d5ebddd)"),
    "xc-disc": (
        "docs/engines-crosscheck.md", "PD_TEST_VERBOSE=1 build/opt/test_posedrop engine_contact "
        "(test_face_and_edge)", "at commit e6e11fa on 2026-12-07, before the Hunt-Crossley law"),
    "xc-referee-reading": (
        "docs/engines-crosscheck.md", "scripts/referee-mujoco.py -n 400 --mj-n 400 --check-n "
        "100 --parts cube,box,hexnut,bushing (the table above, read); MuJoCo's CPU per drop "
        "from its runs", "at commit 76c56d0 on 2026-12-07 (first recorded in commit 3afe403)"),
    "xc-bushing-traces": (
        "docs/engines-crosscheck.md", "scripts/referee-mujoco.py on the bushing (600 MuJoCo "
        "drops at T/20, 200 at T/40); scripts/engine-convergence.py -n 4000 --seed S --engines "
        "impulse --parts flanged_bushing; posedrop -n 3 --seed 3 --units mm --trace FILE "
        "--trace-drop 2 and scripts/trace-compare.py", "on 2026-12-07 at commits e6e11fa and "
        "ba38651 (first recorded in commits 96ad014 and 291121b)"),
    "xc-law-fix": (
        "docs/engines-crosscheck.md", "PD_TEST_VERBOSE=1 build/opt/test_posedrop engine_contact "
        "(test_face_and_edge); scripts/engine-convergence.py -n 1000 (400) --engines impulse,ode "
        "--k auto (80) --parts flanged_bushing; the trace of drop 2 at T/200",
        "at commit ba38651 on 2026-12-07 (first recorded in commit 534feac)"),
    "xc-corpus-new-law": (
        "docs/engines-crosscheck.md", "scripts/engine-convergence.py -o DIR -n 1000 --engines "
        "impulse,ode,bullet --k auto --parts hexnut,box_1x2x3cm",
        "at commit ba38651 on 2026-12-07 (first recorded in commit 3cc882a)"),
    "xc-step-rebound-before": (
        "docs/engines-crosscheck.md", "the first contact of the bushing's drop 2 on ODE at T/20 "
        "and T/200 and on the impulse engine (the record of the law's fix)",
        "at commit ba38651 on 2026-12-07 (first recorded in commit b96ba9f)"),
    "xc-step-rebound-after": (
        "docs/engines-crosscheck.md", "PD_TEST_VERBOSE=1 build/opt/test_posedrop engine_contact "
        "with the spring at the step's start and with the implicit spring; the laws' omega T "
        "under load; test_hard_parts.c's drops", "on 2026-12-07 (first recorded in commit "
        "b96ba9f)"),
    "xc-resting-cube": (
        "docs/engines-crosscheck.md", "posedrop -n 1169 --seed 3 --initial stationary on "
        "parts/canonical/cube.off on each engine, scripts/referee-mujoco.py at T/20 to T/160, "
        "and --trace of drop 11 on every engine", "on 2026-12-07 (first recorded in commit "
        "91fa0ec; the hold at b331935)"),
    "xc-resting-cube-reading": (
        "docs/engines-crosscheck.md", "the runs of the record above and the corpus table's "
        "(the resting cube's rows)", "on 2026-12-07 (first recorded in commit 91fa0ec)"),
    "xc-tolerance-reading": (
        "docs/engines-crosscheck.md", "scripts/tolerance-study.py -n 4000 (the table above, "
        "read)", "on 2026-12-07 (first recorded in commit 91fa0ec)"),
    "xc-cap-belt": (
        "docs/engines-crosscheck.md", "posedrop --initial stationary parts/insulator_cap.off on "
        "ODE (shard 2 of 99, seed 1, d17ddd1's engines), --trace and scripts/trace-compare.py "
        "on its first landing, and two experimental ODE builds (every vertex kept; the force "
        "moved to the nearest kept point) at T/20 to T/200", "on 2026-12-07 (first recorded in "
        "commit 3b26d30)"),
    "xc-flange-down": (
        "docs/engines-crosscheck.md", "the runs each row names: posedrop --group --units mm "
        "parts/flanged_bushing.off on each engine, scripts/referee-mujoco.py, "
        "scripts/engine-convergence.py", "on 2026-12-07 (first recorded in commit 96ad014)"),
}


def record_header(name):
    doc, cmd, when = RECORDS[name]
    return (f"Measured {when}: `{cmd}`. A record of that code, not remade by `make figures` "
            f"(`scripts/doc_tables.py --check` fails on an edit of it).")


def record(name):
    """Puts the record's header line over its block's text (replacing the
    one there) and writes its side file."""
    doc = RECORDS[name][0]
    with open(os.path.join(ROOT, doc)) as f:
        body = block(f.read(), name, doc, "record").strip("\n")
    if body.startswith("Measured "):
        body = body.split("\n\n", 1)[1] if "\n\n" in body else ""
    inner = put(ROOT, doc, name, record_header(name) + "\n\n" + body, "record")
    write_sidecar(os.path.join(ROOT, SIDECARS, name + ".csv"), name, doc, RECORDS[name][1],
                  inner, [])
    print(f"doc_tables.py: {doc}: record {name}", file=sys.stderr)


def check_records(root, names):
    """A record whose block is not the text its side file hashed, or whose
    header is not its entry's, was edited by hand."""
    failures = []
    for name in names:
        doc = RECORDS[name][0]
        side = os.path.join(root, SIDECARS, name + ".csv")
        if not os.path.exists(side):
            failures.append(f"{doc}: record {name}: no {SIDECARS}/{name}.csv "
                            f"(run scripts/doc_tables.py --record {name})")
            continue
        want, _ = read_sidecar(side)
        with open(os.path.join(root, doc)) as f:
            inner = block(f.read(), name, doc, "record")
        if digest(inner) != want or not inner.startswith("\n" + record_header(name)):
            failures.append(f"{doc}: record {name} is not the text its side file hashed "
                            f"(edited by hand?): a record changes with a new measurement, "
                            f"then scripts/doc_tables.py --record {name}")
    return failures


def markers(name, kind="table"):
    return f"<!-- {kind} {name} begin -->", f"<!-- {kind} {name} end -->"


def block(text, name, doc, kind="table"):
    """The text between a table's (or a record's) markers in a doc's TEXT."""
    begin, end = markers(name, kind)
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        sys.exit(f"doc_tables.py: {doc}: expected one '{begin}' before one '{end}'")
    return text[text.index(begin) + len(begin):text.index(end)]


def digest(text):
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def put(root, doc, name, text, kind="table"):
    """Puts TEXT between NAME's markers in DOC; returns the block as written."""
    path = os.path.join(root, doc)
    with open(path) as f:
        s = f.read()
    block(s, name, doc, kind)
    begin, end = markers(name, kind)
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
        # A record: as written passes, a number in it edited by hand fails.
        RECORDS["control-record"] = ("docs/control.md", "posedrop parts/hexnut.obj",
                                     "at commit 0000000 on 2026-01-01")
        for edit, want in ((None, 0), (("0.", "0.9"), 1)):
            with tempfile.TemporaryDirectory() as tmp:
                doc = "docs/control.md"
                begin, end = markers("control-record", "record")
                os.makedirs(os.path.join(tmp, "docs"))
                with open(os.path.join(tmp, doc), "w") as f:
                    f.write(f"text\n{begin}\n{end}\nmore\n")
                inner = put(tmp, doc, "control-record",
                            record_header("control-record") + "\n\np 0.25, 0.75", "record")
                write_sidecar(os.path.join(tmp, SIDECARS, "control-record.csv"),
                              "control-record", doc, "", inner, [])
                if edit:
                    with open(os.path.join(tmp, doc)) as f:
                        text = f.read()
                    with open(os.path.join(tmp, doc), "w") as f:
                        f.write(text.replace(edit[0], edit[1]))
                got = len(check_records(tmp, ["control-record"]))
                if got != want:
                    sys.exit(f"doc_tables.py: self-test: the record control "
                             f"'{'edited' if edit else 'as written'}' gave {got} failures, "
                             f"not {want}")
            cases.append(edit)
    finally:
        TABLES.clear()
        TABLES.update(saved)
        RECORDS.pop("control-record", None)
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
    if args[:1] == ["--record"]:
        for name in args[1:]:
            if name not in RECORDS:
                usage(f"no record '{name}' (records: {', '.join(RECORDS)})")
        for name in args[1:] or RECORDS:
            record(name)
        return
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
        if not args:
            edited = check_records(ROOT, list(RECORDS))
            failures += edited
            print(f"doc_tables.py: --check: {len(RECORDS)} records, {len(edited)} edited by hand",
                  file=sys.stderr)
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
