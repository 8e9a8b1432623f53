"""Shared helpers: the command built from the same tree, the shipped parts,
and the command's number formats, so that Python's numbers are compared
with the command's as printed."""
import csv
import io
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PARTS = ROOT / "parts"
CLI = Path(os.environ.get("POSEDROP_CLI", ROOT / "build" / "opt" / "posedrop"))

# The command prints normal components and static probabilities below this
# as 0 (PD_PRINT_ZERO, include/posedrop/tolerances.h).
PRINT_ZERO = 1e-12


def clean(x):
    return 0.0 if abs(x) < PRINT_ZERO else x


def g10(x):
    """A number as the command prints it: C's %.10g (Python's % formatting
    rounds correctly, as glibc's printf does)."""
    return "%.10g" % x


def g17(x):
    return "%.17g" % x


def run_cli(*args, check=True):
    """Runs the command; returns (rows as lists of strings, header, stderr)."""
    if not CLI.is_file():
        pytest.fail("%s is missing: run make in %s first" % (CLI, ROOT))
    proc = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    if check and proc.returncode != 0:
        pytest.fail("%s %s: exit %d\n%s" % (CLI, " ".join(map(str, args)), proc.returncode,
                                           proc.stderr))
    rows = list(csv.reader(io.StringIO(proc.stdout))) if proc.returncode == 0 else [[]]
    return rows[1:], rows[0], proc


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[1:], rows[0]


def pose_rows(poses, drops=None):
    """The command's pose rows (print_poses in src/cli/cli.c) from Python's arrays."""
    rows = []
    for i in range(len(poses)):
        n = poses.normal[i]
        row = [str(i + 1), g10(clean(n[0])), g10(clean(n[1])), g10(clean(n[2])),
               g10(poses.area[i]), g10(poses.height[i]), g10(clean(poses.p_qs[i])),
               g10(clean(poses.p_pqs[i]))]
        if drops is not None:
            row += [str(drops.n), str(drops.count[i]), g10(drops.p[i]), g10(drops.ci_lo[i]),
                    g10(drops.ci_hi[i]), str(drops.unsettled), str(int(drops.partial))]
        rows.append(row)
    return rows


# Every shipped part with the units its README gives.
SHIPPED = [("cap.off", "m"), ("button.off", "m"), ("block.stl", "mm"), ("hexnut.obj", "mm"),
           ("insulator_cap.off", "m"), ("white_button.off", "m"),
           ("rect_black_button.off", "m"), ("square_black_button.off", "m")]
