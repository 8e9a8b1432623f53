#!/usr/bin/env bash
# fit-mirror.sh: does the fit's in-sample quality flatter it? On posedrop's
# six poses of the 1 x 2 x 3 cm box (--no-group), which come in mirror pairs
# of equal probability, counts that split the pairs unevenly (180, 140, 30,
# 20, 18, 12 of 400: no scene of the model is closer than TV 0.070) are
# fitted for friction and restitution at each seed, and the fitted scene is
# simulated again with 20,000 drops of another seed. Prints, per seed, the
# in-sample TV (the counts against p_best, from the fit's own drops), the
# fresh TV the fit reports (its own check: -n drops of a seed no evaluation
# used) and the TV of the 20,000 fresh drops, with the binary's commit; with
# two or more seeds, the columns' means over the seeds with their standard
# errors, and the mean of in-sample minus fresh (the fit's own check): the
# search's flattery, zero when its best point's drops are an honest draw.
#
#   scripts/fit-mirror.sh [-n DROPS] [-s "SEEDS"] [-o DIR]
#
# POSEDROP names the binary (default build/opt/posedrop; one without the
# fit's own fresh check prints - there).
set -u
. "$(dirname "$0")/args.sh"
n=300
seeds="1 2"
outdir=results/fit-mirror
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -s) args_value "$@"; seeds=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        --help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "fit-mirror.sh: $bin not built (run make)" >&2; exit 2; }
part=$here/parts/canonical/box_1x2x3.off
mkdir -p "$outdir" || exit 2
printf 'pose,count\n1,180\n2,140\n3,30\n4,20\n5,18\n6,12\n' > "$outdir/pairs.csv"
echo "fit-mirror.sh: $bin at $(git -C "$here" rev-parse --short HEAD 2>/dev/null), -n $n"
rows=
echo "seed | in-sample TV | fresh TV (fit's own check) | fresh TV (20000 drops)"
for s in $seeds; do
    case "$s" in *[!0-9]*|'') args_die "-s: expected whole numbers, got '$s'" ;; esac
    "$bin" fit --no-group --fit mu=0.1:0.8,restitution=0.05:0.7 -n "$n" --seed "$s" \
        --part "$part" --measured "$outdir/pairs.csv" --out "$outdir/fit.$s.scene" \
        --gof "$outdir/gof.$s.csv" > "$outdir/fit.$s.csv" 2> "$outdir/fit.$s.err" || {
        cat "$outdir/fit.$s.err" >&2; exit 1; }
    ins=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { d = $c["p_measured"] - $c["p_best"]; s += d < 0 ? -d : d } END { printf "%.3f", s / 2 }' \
        "$outdir/fit.$s.csv")
    own=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { if ("fresh_tv" in c) printf "%.3f", $c["fresh_tv"]; else printf "-" }' \
        "$outdir/gof.$s.csv")
    "$bin" --scene "$outdir/fit.$s.scene" -n 20000 --seed 99 "$part" > "$outdir/fresh.$s.csv" 2>/dev/null || exit 1
    big=$(awk -F, 'NR == FNR { if (FNR > 1) m[$1] = $2 / 400; next }
        FNR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { d = m[$1] - $c["p"]; s += d < 0 ? -d : d } END { printf "%.3f", s / 2 }' \
        "$outdir/pairs.csv" "$outdir/fresh.$s.csv")
    echo "$s | $ins | $own | $big"
    rows="$rows$ins $own $big
"
done
printf '%s' "$rows" | awk 'NF == 3 && $2 != "-" {
        n++; for (i = 1; i <= 3; i++) { s[i] += $i; q[i] += $i * $i }
        d = $1 - $2; sd += d; qd += d * d }
    function se(s, q) { return n > 1 ? sqrt((q - s * s / n) / (n - 1) / n) : 0 }
    END { if (n < 2) exit
        printf "mean of %d seeds | %.3f +- %.3f | %.3f +- %.3f | %.3f +- %.3f\n", n,
               s[1] / n, se(s[1], q[1]), s[2] / n, se(s[2], q[2]), s[3] / n, se(s[3], q[3])
        printf "in-sample minus fresh (own check): %.3f +- %.3f (mean +- standard error)\n",
               sd / n, se(sd, qd) }'
