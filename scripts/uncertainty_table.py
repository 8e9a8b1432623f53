#!/usr/bin/env python3
"""uncertainty_table.py: the table of docs/uncertainty.md, "Measured", from
the files scripts/uncertainty.sh writes (standard library only).

    uncertainty_table.py DIR PART...

For each PART (a name: DIR/PART-ranged.csv, the output of the ranged run;
DIR/PART-sensitivity.csv, its --sensitivity; DIR/PART-sweeps.csv,
scripts/sweeps.sh's) one row per pose class of at least 1%: its p over the
ranges and, per parameter, the effect the ranged run gives (95% bootstrap
interval) beside the sweeps' (the class's p at the range's upper-third
centre less at its lower-third centre, interpolated linearly between the
five swept values, with its 95% binomial interval), in points. Prints
Markdown on stdout.
"""
import csv
import glob
import math
import shlex
import sys

PARAMS = [("mu", "friction"), ("restitution", "restitution"), ("height", "height"),
          ("contact_time", "contact time")]
# The thirds' centres, 1/6 and 5/6 of the range, between the five values at
# 0, 1/4, 1/2, 3/4, 1 of it: p(5/6) - p(1/6) = (2/3)(p3 - p1) + (1/3)(p4 - p0).
WEIGHTS = [-1 / 3, -2 / 3, 0, 2 / 3, 1 / 3]
NAMES = {"insulator_cap": "insulator cap", "white_button": "white button",
         "rect_black_button": "rect. black button", "hexnut": "hex nut"}


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def header(path):
    with open(path) as f:
        return [line[2:].strip() for line in f if line.startswith("#")]


def sweep_effect(sweeps, param, pose):
    pts = [r for r in sweeps if r["parameter"] == param and r["pose"] == pose]
    pts.sort(key=lambda r: float(r["value"]))
    if len(pts) != 5:
        return None
    e = sum(w * float(r["p"]) for w, r in zip(WEIGHTS, pts))
    var = sum(w * w * float(r["p"]) * (1 - float(r["p"])) / float(r["n"])
              for w, r in zip(WEIGHTS, pts))
    return e, 1.96 * math.sqrt(var)


def main():
    d, parts = sys.argv[1], sys.argv[2:]
    print("| part | class | p over the ranges (95%) | " +
          " | ".join(label for _, label in PARAMS) + " |")
    print("|---|---|---|" + "---|" * len(PARAMS))
    notes = []
    for part in parts:
        out = rows(f"{d}/{part}-ranged.csv")
        sens = {(r["pose"], r["parameter"]): r for r in rows(f"{d}/{part}-sensitivity.csv")}
        sweeps = rows(f"{d}/{part}-sweeps.csv")
        notes += header(f"{d}/{part}-sweeps.csv")[:2]
        for r in out:
            p = float(r["p"])
            if p < 0.01:
                continue
            cells = []
            for key, _ in PARAMS:
                s = sens[(r["pose"], key)]
                e, lo, hi = (100 * float(s[k]) for k in ("effect", "effect_lo", "effect_hi"))
                moved = lo > 0 or hi < 0
                text = f"{e:+.1f} ({lo:+.1f}, {hi:+.1f})"
                if moved:
                    text = f"**{text}**"
                sw = sweep_effect(sweeps, key, r["pose"])
                if sw:
                    text += f"; sweeps {100 * sw[0]:+.1f} ± {100 * sw[1]:.1f}"
                if s["interacts"]:
                    text += f"; with {s['interacts']}"
                cells.append(text)
            print(f"| {NAMES.get(part, part)} | {r['pose']} | {p:.3f} ({float(r['ci_lo']):.3f}-"
                  f"{float(r['ci_hi']):.3f}) | " + " | ".join(cells) + " |")
    print()
    for part in parts:
        for line in header(f"{d}/{part}-ranged.csv"):
            print(f"    {line}")
    for line in notes:
        print(f"    {line}")
    confirm(d, parts)


def confirm(d, parts):
    """The sweeps of one parameter with another held in one third of its
    range (PART-sweeps-PARAM-at-*.csv): their effect beside the ranged run's
    effect in each third of the other parameter."""
    files = [(part, f) for part in parts
             for f in sorted(glob.glob(f"{d}/{part}-sweeps-*-at-*.csv"))]
    if not files:
        return
    print()
    print("| part | class | parameter | swept with | sweeps | ranged run, in the lower / middle "
          "/ upper third of the other |")
    print("|---|---|---|---|---|---|")
    notes = []
    for part, f in files:
        cmd = shlex.split(header(f)[0])
        notes += header(f)[:2]
        param = cmd[cmd.index("-p") + 1]
        held = cmd[cmd.index("--") + 1:-1]
        other = held[0].lstrip("-")
        sens = {(r["pose"], r["parameter"]): r for r in rows(f"{d}/{part}-sensitivity.csv")}
        sweeps = rows(f)
        for r in rows(f"{d}/{part}-ranged.csv"):
            if float(r["p"]) < 0.01:
                continue
            sw = sweep_effect(sweeps, param, r["pose"])
            s = sens[(r["pose"], param)]
            if s["interacts"] == other:
                thirds = " / ".join(f"{100 * float(s[k]):+.1f}" for k in
                                    ("effect_in_low", "effect_in_middle", "effect_in_high"))
            else:
                thirds = f"no interaction with {other} flagged"
            label = dict(PARAMS)[param]
            print(f"| {NAMES.get(part, part)} | {r['pose']} | {label} | {' '.join(held)} | "
                  f"{100 * sw[0]:+.1f} ± {100 * sw[1]:.1f} | {thirds} |")
    print()
    for line in notes:
        print(f"    {line}")


if __name__ == "__main__":
    main()
