#!/usr/bin/env bash
# crosscheck.sh: the same drops on posedrop's impulse simulator, ODE and Bullet.
#
#   scripts/crosscheck.sh [-n DROPS] [-o DIR] [-- POSEDROP-OPTIONS...] PART...
#
# For each part, runs posedrop with the same scene, seed and drops on the three
# engines and writes DIR/crosscheck.csv with one row per part, pose and engine:
#   part,pose,engine,n,p,ci_lo,ci_hi,ms_per_drop,unsettled
# (ms_per_drop: wall-clock time of the whole run on all cores, divided by n).
# and prints a summary: for each pair of engines the total-variation distance
# between their distributions and a chi-square test of homogeneity (is the
# difference larger than sampling noise explains?), and the fraction of
# drops, started from identical states, that end in the same pose on both.
# Options after -- go to posedrop unchanged (e.g. --units mm, --mu 0.5,
# --group), in any form posedrop takes, the part files among or after them.
set -u
. "$(dirname "$0")/args.sh"
n=500
outdir=crosscheck-out
opts=()
parts=()
while [ $# -gt 0 ]; do
    case "$1" in
        --help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        --) shift; opts=("$@"); break ;;
        -*) args_die "unknown option '$1' (options for posedrop go after --)" ;;
        *) parts+=("$1"); shift ;;
    esac
done
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)
[ -n "$bin" ] || { echo "crosscheck.sh: posedrop not built (run make)" >&2; exit 2; }
# After --, posedrop's options as posedrop reads them (a flag takes no
# value), and the part files among them.
if [ ${#opts[@]} -gt 0 ]; then
    args_posedrop "$bin" "${opts[@]}"
    opts=("${opt_words[@]}")
    parts+=("${other_words[@]}")
fi
[ ${#parts[@]} -gt 0 ] || args_die "no part files given"
args_files "${parts[@]}"
mkdir -p "$outdir" || exit 2
csv="$outdir/crosscheck.csv"
echo "part,pose,engine,n,p,ci_lo,ci_hi,ms_per_drop,unsettled" > "$csv"
status=0
runs=0
start_s=$SECONDS
for part in "${parts[@]}"; do
    name=$(basename "${part%.*}")
    for engine in impulse ode bullet; do
        runs=$((runs + 1))
        echo "crosscheck.sh: $part on $engine, run $runs of $((3 * ${#parts[@]})), $((SECONDS - start_s)) s so far" >&2
        out="$outdir/$name.$engine.csv"
        start=$(date +%s.%N)
        if ! "$bin" "${opts[@]}" -n "$n" --engine "$engine" --trials "$outdir/$name.$engine.trials.csv" \
                "$part" > "$out" 2> "$outdir/$name.$engine.err"; then
            echo "crosscheck.sh: $part on $engine failed: $(head -n 1 "$outdir/$name.$engine.err")" >&2
            status=1
            continue
        fi
        end=$(date +%s.%N)
        ms=$(awk -v a="$start" -v b="$end" -v n="$n" 'BEGIN { printf "%.4g", 1000 * (b - a) / n }')
        # Columns by name, as posedrop's output contract asks.
        awk -F, -v OFS=, -v part="$name" -v engine="$engine" -v ms="$ms" '
            NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
            { print part, $c["pose"], engine, $c["n"], $c["p"], $c["ci_lo"], $c["ci_hi"], ms, $c["unsettled"] }
        ' "$out" >> "$csv"
    done
done

# Summary: pairs of engines per part.
awk -F, '
    function phi(x) { # standard normal CDF (Abramowitz and Stegun 7.1.26)
        t = 1 / (1 + 0.3275911 * (x < 0 ? -x : x) / sqrt(2))
        y = 1 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-x * x / 2)
        return x < 0 ? (1 - y) / 2 : (1 + y) / 2
    }
    function chisq_q(x, k) { # P(chi2_k > x) by the Wilson-Hilferty cube-root normal approximation
        if (k < 1) return 1
        return 1 - phi(((x / k) ^ (1 / 3) - (1 - 2 / (9 * k))) / sqrt(2 / (9 * k)))
    }
    NR == 1 { next }
    { # counts of settled drops per pose, and the distribution among them
      settled = $4 - $9
      cnt[$1, $3, $2] = $5 * $4; nn[$1, $3] = settled
      pp[$1, $3, $2] = settled > 0 ? $5 * $4 / settled : 0
      poses[$1, $2] = 1; parts[$1] = 1; engines[$1, $3] = 1 }
    END {
        split("impulse ode bullet", e, " ")
        for (part in parts)
            for (i = 1; i <= 3; i++) for (j = i + 1; j <= 3; j++) {
                a = e[i]; b = e[j]
                if (!((part, a) in engines) || !((part, b) in engines)) continue
                x2 = 0; k = 0
                for (pk in poses) {
                    split(pk, q, SUBSEP); if (q[1] != part) continue
                    ca = cnt[part, a, q[2]]; cb = cnt[part, b, q[2]]
                    tot = ca + cb
                    if (tot > 0) {
                        ea = tot * nn[part, a] / (nn[part, a] + nn[part, b]); eb = tot - ea
                        x2 += (ca - ea) ^ 2 / ea + (cb - eb) ^ 2 / eb; k++
                    }
                }
                tv = 0
                for (pk in poses) { split(pk, q, SUBSEP); if (q[1] != part) continue
                    d = pp[part, a, q[2]] - pp[part, b, q[2]]; tv += d < 0 ? -d : d }
                pv = chisq_q(x2, k - 1)
                printf "%s: %s vs %s: total variation %.3f, chi-square %.1f on %d dof, p = %.3g%s\n",
                       part, a, b, tv / 2, x2, k - 1, pv, pv < 0.001 ? "  DIFFERENT beyond sampling noise" : ""
            }
    }' "$csv"

# Per drop: the same initial state (same seed and index) on two engines.
for part in "${parts[@]}"; do
    name=$(basename "${part%.*}")
    for pair in "impulse ode" "impulse bullet" "ode bullet"; do
        set -- $pair
        ta="$outdir/$name.$1.trials.csv"; tb="$outdir/$name.$2.trials.csv"
        [ -s "$ta" ] && [ -s "$tb" ] || continue
        paste -d, "$ta" "$tb" | awk -F, -v part="$name" -v a="$1" -v b="$2" '
            NR == 1 { for (i = 1; i <= NF / 2; i++) c[$i] = i; half = NF / 2; next }
            { both = $(c["end"]) == "settled" && $(half + c["end"]) == "settled"
              if (both) { n++; same += $(c["pose"]) == $(half + c["pose"]) } }
            END { if (n) printf "%s: %s vs %s: %d of %d drops settled on both end in the same pose (%.1f%%)\n", part, a, b, same, n, 100 * same / n }'
    done
done
echo "wrote $csv" >&2
exit $status
