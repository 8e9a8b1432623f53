#!/usr/bin/env bash
# sensitivity.sh: how each pose class moves with the scene, from one run with
# ranges (docs/uncertainty.md) instead of a sweep per parameter.
#
#   scripts/sensitivity.sh [-n DROPS] [-i INITIAL] [-o DIR] [-- POSEDROP-OPTIONS...] PART
#
# One impulse run of DROPS drops (default 2000), pose classes grouped, with
# mu 0:1.2, restitution 0:0.9, drop height 0.01:0.5 m (log uniform) and the
# contact time 0.3x:3x auto (log uniform) each drawn anew for every drop;
# INITIAL (default uniform, the plain run's) is the initial mode, named on
# the chart; with stationary, the curves and indices use the drops started
# from uniform orientations. POSEDROP-OPTIONS come after the ranges, so they
# can change them (e.g. -- --mu 0.2:0.6). Writes DIR (default results/):
#   <part>-sensitivity.csv  posedrop --sensitivity: per class and parameter,
#                           the effect (p in the range's upper third less
#                           its lower) with its 95% interval, the thirds,
#                           the first-order index and interactions;
#   <part>-curves.csv       parameter,value,pose,n,p,ci_lo,ci_hi: the drops
#                           binned by the value they drew (8 bins of equal
#                           count), each class's share with its 95% interval,
#                           and PQS against epsilon (its own parameter);
#   <part>-sensitivity.png and .svg: one panel per parameter, a line per
#                           class with its band, each class's effect in the
#                           key. Unlike a sweep, each curve is averaged over
#                           the other parameters' ranges.
set -u
. "$(dirname "$0")/args.sh"
n=2000
initial=uniform
outdir=results
opts=()
part=""
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -i) args_value "$@"; initial=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        --) shift; while [ $# -gt 1 ]; do opts+=("$1"); shift; done ;;
        --help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) args_die "unknown option '$1' (options for posedrop go after --)" ;;
        *) [ -z "$part" ] || args_die "give one PART file, not '$part' and '$1'"; part=$1; shift ;;
    esac
done
[ -n "$part" ] || args_die "give one PART file"
args_files "$part"
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)
[ -n "$bin" ] || { echo "sensitivity.sh: posedrop not built (run make)" >&2; exit 2; }
# -i and the options after -- as posedrop reads them, on a static run of the
# part (milliseconds), so that a bad one is refused before the drops and
# before anything is written.
why=$("$bin" --initial "$initial" "${opts[@]}" "$part" 2>&1 >/dev/null) ||
    args_die "$(printf '%s' "$why" | head -n 1)"
mkdir -p "$outdir" || exit 2
name=$(basename "${part%.*}")
sens="$outdir/$name-sensitivity.csv"
curves="$outdir/$name-curves.csv"
trials="$outdir/$name-trials.csv"
out="$outdir/$name-run.csv"

"$bin" --group -n "$n" --initial "$initial" --mu 0:1.2 --restitution 0:0.9 -h 0.01:0.5:log \
    --contact-time 0.3x:3x "${opts[@]}" --sensitivity "$sens" --trials "$trials" "$part" \
    > "$out" || exit 1
# The stationary split: k ungrouped poses, m = n / (k + 1) drops started
# resting on each, interleaved with uniform ones from the first drop.
k=$("$bin" "${opts[@]}" "$part" | awk 'END { print NR - 1 }')

echo "parameter,value,pose,n,p,ci_lo,ci_hi" > "$curves"
# Every ranged column of the trials: drops sorted by the value, 8 bins of
# equal count, each class's share and its Wilson interval.
awk -F, -v OFS=, -v initial="$initial" -v k="$k" -v n="$n" '
    NR == 1 {
        for (i = 1; i <= NF; i++) c[$i] = i
        np = 0
        for (i = c["end"] + 1; i <= NF; i++) if ($i != "member" && $i != "partial") param[++np] = $i
        next
    }
    {
        d = $c["drop"] - 1; m = int(n / (k + 1))
        if (initial == "stationary" && d < (k + 1) * m && d % (k + 1) != 0) next
        if ($c["end"] != "settled") next
        rows++; pose[rows] = $c["pose"]; if ($c["pose"] > npose) npose = $c["pose"]
        for (j = 1; j <= np; j++) val[j, rows] = $c[param[j]]
    }
    function wilson(x, t, z,   p, den, mid, half) {
        p = x / t; den = 1 + z * z / t; mid = (p + z * z / (2 * t)) / den
        half = z * sqrt(p * (1 - p) / t + z * z / (4 * t * t)) / den
        lo = mid - half; hi = mid + half; if (lo < 0) lo = 0; if (hi > 1) hi = 1
    }
    END {
        for (j = 1; j <= np; j++) {
            # Rank by value (insertion into an index list sorted by value).
            delete ord
            for (r = 1; r <= rows; r++) {
                s = r
                while (s > 1 && val[j, ord[s - 1]] + 0 > val[j, r] + 0) { ord[s] = ord[s - 1]; s-- }
                ord[s] = r
            }
            for (b = 0; b < 8; b++) {
                first = int(b * rows / 8) + 1; last = int((b + 1) * rows / 8)
                if (last < first) continue
                delete cnt; sum = 0
                for (s = first; s <= last; s++) { cnt[pose[ord[s]]]++; sum += val[j, ord[s]] }
                t = last - first + 1
                for (p = 1; p <= npose; p++) {
                    wilson(cnt[p] + 0, t, 1.959963984540054)
                    printf "%s,%.6g,%d,%d,%.6g,%.6g,%.6g\n", param[j], sum / t, p, t, (cnt[p] + 0) / t, lo, hi
                }
            }
        }
    }' "$trials" >> "$curves"
for v in 0 5 10 15 20 30 45; do
    "$bin" --group "${opts[@]}" --epsilon "$v" "$part" 2>/dev/null | awk -F, -v OFS=, -v value="$v" '
        NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { print "epsilon", value, $c["pose"], "", $c["p_pqs"], $c["p_pqs"], $c["p_pqs"] }' >> "$curves"
done

command -v gnuplot >/dev/null 2>&1 || echo "sensitivity.sh: gnuplot is missing: installing the" \
    "Debian package gnuplot-nox with apt-get (scripts/install-deps.sh, through sudo when not root)" >&2
command -v gnuplot >/dev/null 2>&1 || "$here/scripts/install-deps.sh" gnuplot-nox ||
    { echo "sensitivity.sh: gnuplot missing; $sens and $curves written, no chart" >&2; exit 1; }
params=$(awk -F, 'NR > 1 && !seen[$1]++ { printf "%s ", $1 }' "$curves")
npanel=$(echo $params | wc -w)
poses=$(awk -F, 'NR > 1 { print $3 }' "$curves" | sort -n -u | tr '\n' ' ')
drops=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "n") col = i } NR == 2 { print $col }' "$out")
# Each class's effect per parameter in points, for the keys: "pose 2 (+12
# pts)"; columns by name.
keys=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
                { printf "%s:%s:%+.0f ", $c["parameter"], $c["pose"], 100 * $c["effect"] }' "$sens")
cols=$(( npanel > 2 ? 3 : npanel ))
rowsn=$(( (npanel + cols - 1) / cols ))
for term in png svg; do
    gnuplot <<GP
set datafile separator ","
set terminal ${term} size $((cols * 420)),$((rowsn * 330 + 40)) noenhanced $( [ "$term" = png ] && echo "font ',9'" )
set output "$outdir/$name-sensitivity.${term}"
set multiplot layout $rowsn,$cols title "$name: pose classes over the scene's ranges, one run of $drops drops, initial $initial (95% bands; in the key: the effect, upper third less lower, in points)"
set ylabel "probability"
set yrange [0:1]
set grid
set key top right
keys = "$keys"
array label[7] = ["mu", "restitution", "height", "contact_time", "belt_speed", "vibration", "tumble"]
array unit[7] = ["friction mu", "restitution e", "drop height, m", "contact time, s", "belt speed, m/s", "vibration, deg", "tumble, rad/s"]
effect_of(p, par) = (pos = strstrt(keys, par.":".p.":"), pos ? int(real(substr(keys, pos + strlen(par.":".p.":"), pos + strlen(par.":".p.":") + 3))) : 0)
do for [par in "$params"] {
    xl = par
    do for [i = 1:7] { if (label[i] eq par) { xl = unit[i] } }
    if (par eq "epsilon") { xl = "PQS epsilon, degrees (static)" }
    set title xl
    set xlabel xl
    if (par eq "height" || par eq "contact_time") { set logscale x } else { unset logscale x }
    plot for [p in "$poses"] "< grep '^".par.",' $curves | awk -F, '\$3 == ".p."'" \
         using 2:6:7 with filledcurves fs transparent solid 0.15 lc (p+0) notitle, \
         for [p in "$poses"] "< grep '^".par.",' $curves | awk -F, '\$3 == ".p."'" \
         using 2:5 with linespoints lc (p+0) \
         title (par eq "epsilon" ? "pose ".p : sprintf("pose %s (%+d pts)", p, effect_of(p, par)))
}
unset multiplot
GP
done
rm -f "$trials"
echo "wrote $sens, $curves and $outdir/$name-sensitivity.png, .svg (initial $initial)" >&2
