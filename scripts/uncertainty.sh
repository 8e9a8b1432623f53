#!/usr/bin/env bash
# uncertainty.sh: the measured table of docs/uncertainty.md: what friction,
# restitution, the drop height and the contact time move, from one ranged
# run per part beside one-at-a-time sweeps (make figures runs it).
#
#   scripts/uncertainty.sh [-n DROPS] [-s SWEEP_DROPS] [-k] [-o DIR]
#
# The insulator cap, the white button, the rectangular black button
# (parts/*.off) and parts/hexnut.obj (in mm), pose classes, the impulse
# engine, seed 1: DROPS drops (default 8000) with mu 0.2:0.6, restitution
# 0.1:0.5, height 0.08:0.16 m and contact time 0.3x:3x (log uniform), and
# scripts/sweeps.sh with SWEEP_DROPS drops (default 8000) per value. Writes
# DIR (default docs/figures/uncertainty): <part>-ranged.csv (the run's
# output after '#' lines naming its command and commit),
# <part>-sensitivity.csv, <part>-sweeps.csv and table.md, the table
# (scripts/uncertainty_table.py), which replaces the one between the
# uncertainty-table markers in docs/uncertainty.md; and the sweeps that
# check an effect another parameter's value decides (below). POSEDROP
# names the binary (default build/opt/posedrop). -k keeps the sweeps
# already in DIR (their files name the commit they ran on). About 14 CPU
# minutes (measured 2026-12-07: 650 s for the four parts, 130 s for the
# second sweep).
set -eu
. "$(dirname "$0")/args.sh"
n=8000
ns=8000
keep=0
here=$(cd "$(dirname "$0")/.." && pwd)
dir=$here/docs/figures/uncertainty
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -s) args_value "$@"; args_count -s "$2"; ns=$2; shift 2 ;;
        -o) args_value "$@"; dir=$2; shift 2 ;;
        -k) keep=1; shift ;;
        --help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "uncertainty.sh: $bin not built (run make)" >&2; exit 2; }
# The ranged runs run in DIR: the binary by its absolute path (make passes a relative one).
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
export POSEDROP="$bin"
mkdir -p "$dir"
commit=$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)
ranges=(--mu 0.2:0.6 --restitution 0.1:0.5 -h 0.08:0.16 --contact-time 0.3x:3x)
names=()
for spec in insulator_cap.off white_button.off rect_black_button.off "hexnut.obj --units mm"; do
    set -- $spec
    file=parts/$1; shift
    name=${file#parts/}; name=${name%.*}
    names+=("$name")
    cmd=(posedrop -n "$n" --group "$@" "${ranges[@]}" --sensitivity "$name-sensitivity.csv" "$file")
    {
        echo "# ${cmd[*]}"
        echo "# commit $commit, $(date -u +%Y-%m-%d)"
        (cd "$dir" && "$bin" "${cmd[@]:1:${#cmd[@]}-2}" "$here/$file")
    } > "$dir/$name-ranged.csv"
    [ "$keep" = 1 ] && [ -f "$dir/$name-sweeps.csv" ] ||
        "$here/scripts/sweeps.sh" -n "$ns" -o "$dir/$name-sweeps.csv" -- "$@" "$here/$file"
done
# Where a ranged effect lives in part of another parameter's range (the
# white button's contact time moves it only at high friction), the sweep of
# that parameter again with the other held at the centre of that third:
# <part>-sweeps-<parameter>-at-<option><value>.csv.
confirm=("white_button.off contact_time --mu 0.5333")
for spec in "${confirm[@]}"; do
    set -- $spec
    file=parts/$1; param=$2; shift 2
    name=${file#parts/}; name=${name%.*}
    at=$(printf '%s' "$*" | tr -d ' -')
    out="$dir/$name-sweeps-$param-at-$at.csv"
    [ "$keep" = 1 ] && [ -f "$out" ] ||
        "$here/scripts/sweeps.sh" -n "$ns" -p "$param" -o "$out" -- "$@" "$here/$file"
done
python3 "$here/scripts/uncertainty_table.py" "$dir" "${names[@]}" > "$dir/table.md"
doc=$here/docs/uncertainty.md
awk -v table="$dir/table.md" '
    /<!-- uncertainty-table end -->/ { skip = 0 }
    !skip { print }
    /<!-- uncertainty-table begin -->/ { while ((getline line < table) > 0) print line; skip = 1 }
' "$doc" > "$doc.tmp" && mv "$doc.tmp" "$doc"
