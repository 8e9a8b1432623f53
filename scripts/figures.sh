#!/usr/bin/env bash
# figures.sh: the pictures of docs/figures.md, into docs/figures/ (make figures).
#
#   scripts/figures.sh [--chart-only | --cheap] [-d PAPER_TABLES_CSV]
#
# The insulator cap of the paper (parts/insulator_cap.off), its pose classes
# as the paper counts them (--group): the gallery, the chart against the
# paper's physical tests and the gauss-sphere map, from 2000 drops with the
# paper's scene and the belt's long run as initial poses (as scripts/paper.sh
# runs them); make paper's tables on the impulse engine (paper.txt, its runs
# in paper/); then the cost-accuracy chart of scripts/cost-accuracy.sh (its
# CSVs kept beside it; several minutes). --chart-only redraws that chart from
# the kept CSV instead of rerunning it. The paper numbers its poses by
# physical frequency: parts/insulator_cap-measured.csv pairs its poses with
# posedrop's classes by rank of QS on both sides. Last, the design demonstrations of docs/design.md
# (scripts/design-demos.sh, into docs/figures/design/). --cheap makes only
# the cap's pictures and paper.txt (about 17 s of CPU): what make
# check-figures reruns.
set -eu
. "$(dirname "$0")/args.sh"
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/docs/figures"
tables=""
cost_args=""
cheap=0
while [ $# -gt 0 ]; do
    case "$1" in
        --chart-only) cost_args="--chart-only"; shift ;;
        --cheap) cheap=1; shift ;;
        -d) args_value "$@"; tables=$2; shift 2 ;;
        --help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "figures.sh: $bin not built (run make)" >&2; exit 2; }
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")   # cap.csv is made from the checkout
export POSEDROP="$bin"
if [ -z "$tables" ]; then
    for t in "$here/../shared/data/paper-tables.csv" "$here/parts/paper-tables.csv"; do
        [ -f "$t" ] && { tables=$t; break; }
    done
fi
[ -f "$tables" ] || { echo "figures.sh: the paper's tables not found (give -d FILE)" >&2; exit 2; }
mkdir -p "$out"

# cap.csv starts with what made it and when (the command, the commit it ran
# on), as make check-figures reads it back. The paper's physical counts in
# posedrop's class numbering are parts/insulator_cap-measured.csv
# (scripts/make-measured.sh; make check-readme keeps it current).
cmd=(--group -n 2000 --initial stationary --seed 1 --svg docs/figures/cap-gallery.svg
     --chart docs/figures/cap-chart.svg --sphere docs/figures/cap-sphere.svg
     --measured parts/insulator_cap-measured.csv parts/insulator_cap.off)
{
    echo "# posedrop ${cmd[*]}"
    echo "# commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)," \
        "$(date -u +%Y-%m-%d); the rows of cap-gallery.svg, cap-chart.svg and cap-sphere.svg"
    (cd "$here" && "$bin" "${cmd[@]}")
} > "$out/cap.csv.tmp"
mv "$out/cap.csv.tmp" "$out/cap.csv"
rm -f "$out/cap.provenance.txt" "$out/insulator_cap.measured.csv"
echo "figures.sh: wrote $out/cap-gallery.svg, cap-chart.svg, cap-sphere.svg (rows: cap.csv)" >&2

# make paper's tables on the impulse engine (ODE's and Bullet's columns at
# their automatic step are CPU-hours: not here), with the runs' CSVs, each
# starting with its command and commit, for make check-figures.
paper_tmp=$(mktemp -d)
{
    echo "# scripts/paper.sh -e impulse (scripts/figures.sh), commit" \
        "$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u +%Y-%m-%d)"
    "$here/scripts/paper.sh" -e impulse -d "$tables" -o "$paper_tmp"
} > "$out/paper.txt.tmp"
mkdir -p "$out/paper"
cp "$paper_tmp"/*.impulse.csv "$out/paper/"
rm -rf "$paper_tmp"
mv "$out/paper.txt.tmp" "$out/paper.txt"

[ "$cheap" = 0 ] || exit 0
# shellcheck disable=SC2086
"$here/scripts/cost-accuracy.sh" -o "$out" -d "$tables" $cost_args

# The design demonstrations of docs/design.md (tens of minutes of CPU).
"$here/scripts/design-demos.sh"
