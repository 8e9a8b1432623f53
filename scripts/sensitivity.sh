#!/usr/bin/env bash
# sensitivity.sh: how each pose probability moves with the scene, one
# parameter at a time (the paper notes that only dynamic simulation can study
# this; epsilon is PQS's own parameter).
#
#   scripts/sensitivity.sh [-n DROPS] [-o DIR] [-- POSEDROP-OPTIONS...] PART
#
# Sweeps mu, restitution and drop height around the paper's scene with the
# impulse simulator (DROPS drops each, default 1000, pose classes grouped;
# initial poses the belt's long run, --initial stationary, which needs at
# least 10 (k + 1) drops for k stable poses),
# and epsilon with PQS; writes DIR/<part>-sensitivity.csv (parameter, value,
# pose, p, ci_lo, ci_hi) and a chart DIR/<part>-sensitivity.png and .svg:
# one panel per parameter, one line per pose class with its 95% band.
set -u
n=1000
outdir=results
opts=()
part=""
while [ $# -gt 0 ]; do
    case "$1" in
        -n) n=$2; shift 2 ;;
        -o) outdir=$2; shift 2 ;;
        --) shift; while [ $# -gt 1 ]; do opts+=("$1"); shift; done ;;
        --help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) part=$1; shift ;;
    esac
done
[ -n "$part" ] && [ -f "$part" ] || { echo "sensitivity.sh: give one PART file" >&2; exit 2; }
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)
[ -n "$bin" ] || { echo "sensitivity.sh: posedrop not built (run make)" >&2; exit 2; }
mkdir -p "$outdir" || exit 2
name=$(basename "${part%.*}")
csv="$outdir/$name-sensitivity.csv"
echo "parameter,value,pose,p,ci_lo,ci_hi" > "$csv"

# point PARAMETER VALUE COLUMN POSEDROP-ARGS...: the classes' rows of one run.
point() {
    local param=$1 value=$2 column=$3; shift 3
    "$bin" --group "${opts[@]}" "$@" "$part" 2>/dev/null | awk -F, -v OFS=, -v param="$param" \
        -v value="$value" -v column="$column" '
        NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { lo = ("ci_lo" in c) ? $c["ci_lo"] : $c[column]; hi = ("ci_hi" in c) ? $c["ci_hi"] : $c[column]
          print param, value, $c["pose"], $c[column], lo, hi }' >> "$csv"
}
for v in 0 0.1 0.2 0.3 0.5 0.8 1.2; do point mu "$v" p -n "$n" --initial stationary --mu "$v"; done
for v in 0 0.1 0.3 0.5 0.7 0.9; do point restitution "$v" p -n "$n" --initial stationary --restitution "$v"; done
for v in 0.01 0.03 0.06 0.12 0.25 0.5; do point height "$v" p -n "$n" --initial stationary -h "$v"; done
for v in 0 5 10 15 20 30 45; do point epsilon "$v" p_pqs --epsilon "$v"; done

command -v gnuplot >/dev/null 2>&1 || echo "sensitivity.sh: gnuplot is missing: installing the" \
    "Debian package gnuplot-nox with apt-get (scripts/install-deps.sh, through sudo when not root)" >&2
command -v gnuplot >/dev/null 2>&1 || "$here/scripts/install-deps.sh" gnuplot-nox ||
    { echo "sensitivity.sh: gnuplot missing; $csv written, no chart" >&2; exit 1; }
poses=$(awk -F, 'NR > 1 { print $3 }' "$csv" | sort -n -u | tr '\n' ' ')
for term in png svg; do
    gnuplot <<GP
set datafile separator ","
set terminal ${term} size 1100,800 noenhanced $( [ "$term" = png ] && echo "font ',10'" )
set output "$outdir/$name-sensitivity.${term}"
set multiplot layout 2,2 title "$name: pose probabilities against the scene (95% bands; pose classes)"
set ylabel "probability"
set yrange [0:1]
set grid
set key top right
array label[4] = ["friction mu ($n drops each)", "restitution e", "drop height, m", "PQS epsilon, degrees"]
array key[4] = ["mu", "restitution", "height", "epsilon"]
do for [k = 1:4] {
    set title label[k]
    set xlabel label[k]
    if (k == 3) { set logscale x } else { unset logscale x }
    plot for [p in "$poses"] "< grep '^".key[k].",' $csv | awk -F, '\$3 == ".p."'" \
         using 2:5:6 with filledcurves fs transparent solid 0.15 lc (p+0) notitle, \
         for [p in "$poses"] "< grep '^".key[k].",' $csv | awk -F, '\$3 == ".p."'" \
         using 2:4 with linespoints lc (p+0) title "pose ".p
}
unset multiplot
GP
done
echo "wrote $csv and $outdir/$name-sensitivity.png, .svg" >&2
