#!/usr/bin/env bash
# scene-grid.sh: one of the paper's parts on a grid of scenes, its eq. (16)
# error at each, and the error summarised per restitution: what a fit's
# weighting can reach when it spreads its weight over the ranges.
#
#   scripts/scene-grid.sh [-n DROPS] [-i INITIAL] [-o DIR] PART
#
# PART is one of insulator_cap, white_button, rect_black_button,
# square_black_button (parts/PART.off). For mu in 0.15 0.3 0.45 0.6 0.75,
# restitution in 0.15 0.3 0.45 0.6 and height in 0.07 0.1 0.13 0.17 m (the
# paper's other values), runs DROPS (1600) drops with the initial mode INITIAL
# (stationary) and --group into DIR/g_MU_E_H.csv (kept: a run whose file is
# there is not made again), prints one line a scene (mu, restitution,
# height, e16 and TV in percent against the paper's physical column, the
# classes' probabilities), then per restitution the mean e16, the scenes
# whose e16 is below the part's PQS, and the mean probability of class 1.
# POSEDROP names the binary, as for paper.sh.
set -u
. "$(dirname "$0")/args.sh"
n=1600 initial=stationary outdir=results/grid part=
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -i) args_value "$@"; initial=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        --help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) args_die "unknown argument '$1'" ;;
        *) part=$1; shift ;;
    esac
done
case " insulator_cap white_button rect_black_button square_black_button " in
    *" $part "*) ;;
    *) args_die "expected one of insulator_cap, white_button, rect_black_button, \
square_black_button, got '$part'" ;;
esac
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${POSEDROP:-$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)}
[ -n "$bin" ] || { echo "scene-grid.sh: posedrop not built (run make)" >&2; exit 2; }
tables=
for t in "$here/../shared/data/paper-tables.csv" "$here/parts/paper-tables.csv"; do
    [ -f "$t" ] && { tables=$t; break; }
done
[ -n "$tables" ] || args_die "the paper's measured tables not found"
mkdir -p "$outdir" || exit 2
pqs=$("$bin" --group "$here/parts/$part.off" > "$outdir/static.csv" &&
      awk -F, -v part="$part" -v column=p_pqs -f "$here/scripts/eq16.awk" "$tables" \
          "$outdir/static.csv" | cut -d' ' -f1) || exit 1
echo "# scripts/scene-grid.sh -n $n -i $initial $part; $(git -C "$here" rev-parse --short HEAD); PQS e16 $pqs"
echo "mu restitution height e16 tv p_class..."
for mu in 0.15 0.3 0.45 0.6 0.75; do for e in 0.15 0.3 0.45 0.6; do for h in 0.07 0.1 0.13 0.17; do
    f=$outdir/g_${mu}_${e}_${h}.csv
    [ -s "$f" ] || "$bin" -n "$n" --group --initial "$initial" --mu "$mu" --restitution "$e" \
        -h "$h" "$here/parts/$part.off" > "$f" 2> /dev/null || { rm -f "$f"; exit 1; }
    echo "$mu $e $h $(awk -F, -v part="$part" -v column=p -f "$here/scripts/eq16.awk" "$tables" "$f") \
$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next } { printf "%.3f ", $c["p"] }' "$f")"
done; done; done | tee "$outdir/grid.txt"
awk -v pqs="$pqs" '{ k = $2; n[k]++; s[k] += $4; b[k] += $4 < pqs; p[k] += $6 }
    END { for (k in n) printf "restitution %s: mean e16 %.1f over %d scenes, %d below PQS (%.1f), mean p of class 1 %.3f\n",
                              k, s[k] / n[k], n[k], b[k], pqs, p[k] / n[k] }' "$outdir/grid.txt" | sort
