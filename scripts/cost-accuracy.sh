#!/usr/bin/env bash
# cost-accuracy.sh: what accuracy costs in time, per estimator, on the paper's
# four parts.
#
#   scripts/cost-accuracy.sh [-o DIR] [-s SEEDS] [-d PAPER_TABLES_CSV] [--chart-only]
#
# Runs QS and PQS, the impulse simulator at n = 50 ... 5000 drops with SEEDS
# seeds (default 3), and ODE and Bullet at three time steps (1000 drops), all
# with the paper's scene and the belt's long run as initial poses (--initial
# stationary; budgets below its 10 (k + 1) drops for k poses are skipped),
# grouped into pose classes; records CPU seconds (user + system, all threads) and the eq. (16)
# error (and total variation) against the physical tests in
# DIR/cost-accuracy.csv (default results/; '#' lines first give the command
# and the commit it ran on), and draws error against time on a
# log axis, one series per estimator, error bars over seeds, in
# DIR/cost-accuracy.png and .svg (gnuplot; installed if missing), beside the
# paper's own points (its errors at its reported times on a SPARC20: QS and
# PQS "less than a second", dynamic simulation "approximately two hours").
# --chart-only redraws from an existing DIR/cost-accuracy.csv.
set -u
. "$(dirname "$0")/args.sh"
outdir=results
seeds=3
tables=""
chart_only=0
while [ $# -gt 0 ]; do
    case "$1" in
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        -s) args_value "$@"; args_count -s "$2"; seeds=$2; shift 2 ;;
        -d) args_value "$@"; tables=$2; shift 2 ;;
        --chart-only) chart_only=1; shift ;;
        --help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
here=$(cd "$(dirname "$0")/.." && pwd)
# POSEDROP names the binary (make figures passes the optimised build's);
# otherwise the newest one built.
bin=${POSEDROP:-$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)}
[ -n "$bin" ] || { echo "cost-accuracy.sh: posedrop not built (run make)" >&2; exit 2; }
if [ -z "$tables" ]; then
    for t in "$here/../shared/data/paper-tables.csv" "$here/parts/paper-tables.csv"; do
        [ -f "$t" ] && { tables=$t; break; }
    done
fi
[ -f "$tables" ] || { echo "cost-accuracy.sh: the paper's tables not found (give -d FILE)" >&2; exit 2; }
mkdir -p "$outdir" || exit 2
csv="$outdir/cost-accuracy.csv"
tmp="$outdir/.cost-run.csv"
TIMEFORMAT='%3U %3S'

# Progress on stderr, one line per run: runs in all (two static runs, the
# impulse budgets for each seed, three time steps each for ODE and Bullet,
# per part) and the wall clock so far.
total=$((4 * (2 + 7 * seeds + 3 + 3)))
done_runs=0
start_s=$SECONDS

# run PART ESTIMATOR BUDGET SEED COLUMN POSEDROP-ARGS...: one row of the CSV.
run() {
    local part=$1 est=$2 budget=$3 seed=$4 column=$5; shift 5
    done_runs=$((done_runs + 1))
    printf 'cost-accuracy.sh: run %d of %d (%s, %s, budget %s, seed %s), %d s so far\n' \
        "$done_runs" "$total" "$part" "$est" "$budget" "$seed" $((SECONDS - start_s)) >&2
    local t
    t=$( { time "$bin" --group "$@" "$here/parts/$part.off" > "$tmp" 2>/dev/null; } 2>&1 ) || return 1
    local cpu; cpu=$(echo "$t" | awk '{ print $1 + $2 }')
    local err; err=$(awk -F, -v part="$part" -v column="$column" -f "$here/scripts/eq16.awk" "$tables" "$tmp")
    echo "$part,$est,$budget,$seed,$cpu,${err% *},${err#* }" >> "$csv"
}

# The CSV starts with what made it: the command, the commit, the date.
if [ "$chart_only" = 0 ]; then
    {
        echo "# scripts/cost-accuracy.sh -s $seeds"
        echo "# commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)," \
            "$(date -u +%Y-%m-%d)"
        echo "part,estimator,budget,seed,cpu_s,e16,tv"
    } > "$csv"
fi
for part in insulator_cap white_button rect_black_button square_black_button; do
    [ "$chart_only" = 1 ] && break
    run "$part" QS 0 1 p_qs || { done_runs=$((done_runs + total / 4 - 1)); continue; }
    run "$part" PQS 0 1 p_pqs
    for n in 50 100 200 500 1000 2000 5000; do
        for s in $(seq 1 "$seeds"); do
            run "$part" impulse "$n" "$s" p -n "$n" --seed "$s" --initial stationary
        done
    done
    for dt in 0.002 0.001 0.0005; do
        run "$part" ODE "$dt" 1 p -n 1000 --engine ode --dt "$dt" --initial stationary
    done
    for dt in 0.0021 0.00104 0.00052; do
        run "$part" Bullet "$dt" 1 p -n 1000 --engine bullet --dt "$dt" --initial stationary
    done
done
rm -f "$tmp"

# Mean and spread over seeds per (part, estimator, budget), then the chart.
grep '^#' "$csv" > "$outdir/cost-accuracy-mean.csv"
awk -F, '/^#/ || $1 == "part" { next } { k = $1 FS $2 FS $3; n[k]++; t[k] += $5; e[k] += $6; e2[k] += $6 * $6 }
    END { for (k in n) { m = e[k] / n[k]; v = e2[k] / n[k] - m * m
          printf "%s,%.6g,%.6g,%.6g\n", k, t[k] / n[k], m, sqrt(v > 0 ? v : 0) } }' "$csv" |
    sort -t, -k1,1 -k2,2 -k4,4g >> "$outdir/cost-accuracy-mean.csv"
# The paper's own points: its columns' eq. (16) errors at its reported times.
for part in insulator_cap white_button rect_black_button square_black_button; do
    awk -F, -v part="$part" 'NR == 1 { print "pose,p_qs,p_pqs,p" }
        $1 == part { print $2 "," $3 / 100 "," $4 / 100 "," $5 / 100 }' "$tables" > "$tmp"
    for c in "p_qs paper_QS 1" "p_pqs paper_PQS 1" "p paper_dynamic 7200"; do
        set -- $c
        e=$(awk -F, -v part="$part" -v column="$1" -f "$here/scripts/eq16.awk" "$tables" "$tmp")
        echo "$part,$2,0,$3,${e% *},0" >> "$outdir/cost-accuracy-mean.csv"
    done
done
rm -f "$tmp"
if ! command -v gnuplot >/dev/null 2>&1; then
    echo "cost-accuracy.sh: gnuplot is missing: installing the Debian package gnuplot-nox with" \
         "apt-get (scripts/install-deps.sh, through sudo when not root)" >&2
    "$here/scripts/install-deps.sh" gnuplot-nox ||
        { echo "cost-accuracy.sh: gnuplot missing; $csv written, no chart" >&2; exit 1; }
fi
for term in png svg; do
    gnuplot <<GP
set datafile separator ","
set terminal ${term} size 1300,1000 noenhanced $( [ "$term" = png ] && echo "font ',10'" )
set output "$outdir/cost-accuracy.${term}"
set multiplot title "What accuracy costs: eq. (16) error against the physical tests vs CPU time (paper's four parts)"
set logscale x
set format x "%g"
set xlabel "CPU seconds (all threads)"
set ylabel "eq. (16) error, %"
set grid
# The four panels above one key for all of them, in a strip of its own at
# the bottom: a key under each panel overlapped its x axis's title.
set key off
set size 0.5, 0.42
parts = "insulator_cap white_button rect_black_button square_black_button"
do for [i = 1:4] {
    p = word(parts, i)
    set origin 0.5 * ((i - 1) % 2), 0.12 + 0.42 * (1 - (i - 1) / 2)
    set title p
    plot "< grep '^".p.",QS,' $outdir/cost-accuracy-mean.csv" using 4:5 with points pt 7 ps 1.5 lc 1, \
         "< grep '^".p.",PQS,' $outdir/cost-accuracy-mean.csv" using 4:5 with points pt 5 ps 1.5 lc 2, \
         "< grep '^".p.",impulse,' $outdir/cost-accuracy-mean.csv" using 4:5:6 with yerrorlines pt 9 lc 3, \
         "< grep '^".p.",ODE,' $outdir/cost-accuracy-mean.csv" using 4:5 with linespoints pt 11 lc 4, \
         "< grep '^".p.",Bullet,' $outdir/cost-accuracy-mean.csv" using 4:5 with linespoints pt 13 lc 5, \
         "< grep '^".p.",paper_QS,' $outdir/cost-accuracy-mean.csv" using 4:5 with points pt 6 ps 2 lc rgb "black", \
         "< grep '^".p.",paper_PQS,' $outdir/cost-accuracy-mean.csv" using 4:5 with points pt 4 ps 2 lc rgb "black", \
         "< grep '^".p.",paper_dynamic,' $outdir/cost-accuracy-mean.csv" using 4:5 with points pt 8 ps 2 lc rgb "black"
}
# The key: the same series with no points, on a bare plot.
set origin 0, 0
set size 1, 0.11
unset title
unset xlabel
unset ylabel
unset logscale
unset grid
unset border
unset tics
set xrange [0:1]
set yrange [0:1]
set key center center horizontal maxcols 4 font ',10' spacing 1.3 width 1
plot NaN with points pt 7 ps 1.5 lc 1 title "QS", \
     NaN with points pt 5 ps 1.5 lc 2 title "PQS", \
     NaN with linespoints pt 9 lc 3 title "impulse (n = 50..5000, +-1 sd over seeds)", \
     NaN with linespoints pt 11 lc 4 title "ODE (dt 2, 1, 0.5 ms)", \
     NaN with linespoints pt 13 lc 5 title "Bullet (dt 2.1, 1.04, 0.52 ms)", \
     NaN with points pt 6 ps 2 lc rgb "black" title "paper QS (<1 s, SPARC20)", \
     NaN with points pt 4 ps 2 lc rgb "black" title "paper PQS (<1 s)", \
     NaN with points pt 8 ps 2 lc rgb "black" title "paper dynamic (~2 h)"
unset multiplot
GP
done
echo "wrote $csv, $outdir/cost-accuracy.png and .svg" >&2
