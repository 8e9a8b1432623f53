#!/usr/bin/env bash
# figures.sh: the pictures of docs/figures.md, into docs/figures/ (make figures).
#
#   scripts/figures.sh [--chart-only] [-d PAPER_TABLES_CSV]
#
# The insulator cap of the paper (parts/insulator_cap.off), its pose classes
# as the paper counts them (--group): the gallery, the chart against the
# paper's physical tests and the gauss-sphere map, from 2000 drops with the
# paper's scene and the belt's long run as initial poses (as scripts/paper.sh
# runs them); then the cost-accuracy chart of scripts/cost-accuracy.sh (its
# CSVs kept beside it; several minutes). --chart-only redraws that chart from
# the kept CSV instead of rerunning it. The paper numbers its poses by
# physical frequency: its poses are paired with posedrop's classes by rank of
# QS on both sides, as scripts/eq16.awk does, to write the measured file
# (scripts/measured.awk). Last, the design demonstrations of docs/design.md
# (scripts/design-demos.sh, into docs/figures/design/).
set -eu
. "$(dirname "$0")/args.sh"
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/docs/figures"
tables=""
cost_args=""
while [ $# -gt 0 ]; do
    case "$1" in
        --chart-only) cost_args="--chart-only"; shift ;;
        -d) args_value "$@"; tables=$2; shift 2 ;;
        --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
bin=${POSEDROP:-$here/build/opt/posedrop}
export POSEDROP="$bin"
[ -x "$bin" ] || { echo "figures.sh: $bin not built (run make)" >&2; exit 2; }
if [ -z "$tables" ]; then
    for t in "$here/../shared/data/paper-tables.csv" "$here/parts/paper-tables.csv"; do
        [ -f "$t" ] && { tables=$t; break; }
    done
fi
[ -f "$tables" ] || { echo "figures.sh: the paper's tables not found (give -d FILE)" >&2; exit 2; }
mkdir -p "$out"
part="$here/parts/insulator_cap.off"
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT

# The paper's physical column in posedrop's class numbering.
"$bin" --group "$part" > "$tmp"
awk -F, -v part=insulator_cap -v tag=figures.sh -f "$here/scripts/measured.awk" \
    "$tables" "$tmp" > "$out/insulator_cap.measured.csv"

"$bin" --group -n 2000 --initial stationary --seed 1 \
    --svg "$out/cap-gallery.svg" --chart "$out/cap-chart.svg" --sphere "$out/cap-sphere.svg" \
    --measured "$out/insulator_cap.measured.csv" "$part" > "$out/cap.csv"
# What made them and when: the command and the commit it ran on.
{
    echo "cap-gallery.svg, cap-chart.svg, cap-sphere.svg, cap.csv (scripts/figures.sh):"
    echo "posedrop --group -n 2000 --initial stationary --seed 1 --svg cap-gallery.svg" \
        "--chart cap-chart.svg --sphere cap-sphere.svg --measured insulator_cap.measured.csv" \
        "parts/insulator_cap.off > cap.csv"
    echo "commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)," \
        "$(date -u +%Y-%m-%d)"
} > "$out/cap.provenance.txt"
echo "figures.sh: wrote $out/cap-gallery.svg, cap-chart.svg, cap-sphere.svg (rows: cap.csv)" >&2

# shellcheck disable=SC2086
"$here/scripts/cost-accuracy.sh" -o "$out" -d "$tables" $cost_args

# The design demonstrations of docs/design.md (tens of minutes of CPU).
"$here/scripts/design-demos.sh"
