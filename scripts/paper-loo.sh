#!/usr/bin/env bash
# paper-loo.sh: the leave-one-out mode of scripts/paper.sh (-L), which
# describes it and passes its arguments:
#
#   paper-loo.sh BIN TABLES OUTDIR SPEC DROPS INITIAL EVALS POINTS SEED JOBS HELD [CONTACT_TIME]
#
# For each of the paper's four parts (or HELD alone, when not empty), fits
# SPEC to the other three parts' physical counts (posedrop fit) and predicts
# the fourth; prints its table and at the end e16 and TV per held-out part
# with the fitted values. JOBS folds run at once, each on one thread when
# JOBS > 1 (the folds are independent, and a fold's evaluations of a few
# hundred drops keep one thread busier than two).
set -u
bin=$1 tables=$2 outdir=$3 spec=$4 n=$5 initial=$6 evals=$7 points=$8 seed=$9 jobs=${10}
held_only=${11} contact_time=${12:-}
here=$(cd "$(dirname "$0")/.." && pwd)
parts="insulator_cap white_button rect_black_button square_black_button"
folds=${held_only:-$parts}
status=0
threads=()
[ "$jobs" -gt 1 ] && threads=(-j 1)
scene="$outdir/loo.base.scene"
{ echo "initial = $initial"; [ -n "$contact_time" ] && echo "contact_time = $contact_time"; } > "$scene"
for part in $parts; do
    "$bin" --group "$here/parts/$part.off" > "$outdir/$part.static.csv" || exit 1
    awk -F, -v part="$part" -v tag=paper.sh -f "$here/scripts/measured.awk" \
        "$tables" "$outdir/$part.static.csv" > "$outdir/$part.measured.csv" || exit 1
done
summary="$outdir/loo.summary.txt"
: > "$summary"
fit_fold() { # held
    local held=$1 part args=()
    for part in $parts; do
        [ "$part" = "$held" ] && continue
        args+=(--part "$here/parts/$part.off" --measured "$outdir/$part.measured.csv")
    done
    "$bin" fit --fit "$spec" -n "$n" --max-evals "$evals" --points "$points" --seed "$seed" \
        "${threads[@]}" --scene "$scene" "${args[@]}" --predict "$here/parts/$held.off" \
        --params "$outdir/loo.$held.params.csv" --out "$outdir/loo.$held.scene" \
        > "$outdir/loo.$held.csv" 2> "$outdir/loo.$held.err"
    echo $? > "$outdir/loo.$held.status"
}
running=0
for held in $folds; do
    if [ "$running" -ge "$jobs" ]; then
        wait -n
        running=$((running - 1))
    fi
    fit_fold "$held" &
    running=$((running + 1))
done
wait
for held in $folds; do
    [ "$(cat "$outdir/loo.$held.status")" = 0 ] || { cat "$outdir/loo.$held.err" >&2; status=1; continue; }
    # The held-out part's classes with posedrop's QS and PQS and the two
    # predictions, in the form eq16.awk reads.
    awk -F, '
        FNR == 1 { delete col; for (i = 1; i <= NF; i++) col[$i] = i; next }
        FILENAME == ARGV[1] { qs[$col["pose"]] = $col["p_qs"]; pqs[$col["pose"]] = $col["p_pqs"]; k = $col["pose"]; next }
        $col["role"] == "predicted" { best[$col["pose"]] = $col["p_best"]; avg[$col["pose"]] = $col["p"]
                                      lo[$col["pose"]] = $col["ci_lo"]; hi[$col["pose"]] = $col["ci_hi"] }
        END {
            print "pose,p_qs,p_pqs,p_best,p,ci_lo,ci_hi"
            for (c = 1; c <= k; c++) printf "%d,%s,%s,%s,%s,%s,%s\n", c, qs[c], pqs[c], best[c], avg[c], lo[c], hi[c]
        }' "$outdir/$held.static.csv" "$outdir/loo.$held.csv" > "$outdir/loo.$held.grouped.csv"
    # The table by the paper's pose numbers (eq16.awk's pairing, by QS rank).
    awk -F, -v part="$held" '
        FNR == 1 { delete col; for (i = 1; i <= NF; i++) col[$i] = i; next }
        FILENAME == ARGV[1] {
            if ($col["part"] == part) { n++; ph[n] = $col["p_physical"]; pq[n] = $col["p_qs"]
                pp[n] = $col["p_pqs"]; pd[n] = $col["p_dynamic"]; trials = $col["physical_trials"] }
            next
        }
        { k++; qs[k] = $col["p_qs"]; pqs[k] = $col["p_pqs"]; b[k] = $col["p_best"]; a[k] = $col["p"]
          lo[k] = $col["ci_lo"]; hi[k] = $col["ci_hi"] }
        END {
            for (i = 1; i <= n; i++) pr[i] = i
            for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
                if (pq[pr[j]] > pq[pr[i]]) { t = pr[i]; pr[i] = pr[j]; pr[j] = t }
            for (i = 1; i <= k; i++) ord[i] = i
            for (i = 1; i <= k; i++) for (j = i + 1; j <= k; j++)
                if (qs[ord[j]] > qs[ord[i]]) { t = ord[i]; ord[i] = ord[j]; ord[j] = t }
            for (r = 1; r <= n; r++) rank_of[pr[r]] = r
            printf "\n%s held out (%d physical trials; fitted to the other three)\n", part, trials
            printf "%4s | %6s %6s %6s %6s | %6s %6s %7s %7s %15s\n", "pose", "QS", "PQS", "Dyn", "Phys",
                   "QS", "PQS", "best", "avg", "avg 95%"
            for (p = 1; p <= n; p++) {
                c = ord[rank_of[p]]
                printf "%4d | %6.1f %6.1f %6.1f %6.1f | %6.1f %6.1f %7.1f %7.1f %6.1f - %5.1f\n", p,
                       pq[p], pp[p], pd[p], ph[p], 100 * qs[c], 100 * pqs[c], 100 * b[c], 100 * a[c],
                       100 * lo[c], 100 * hi[c]
            }
        }' "$tables" "$outdir/loo.$held.grouped.csv"
    e() { awk -F, -v part="$held" -v column="$1" -f "$here/scripts/eq16.awk" "$tables" \
              "$outdir/loo.$held.grouped.csv"; }
    # The paper's own simulator, its e16 from its dynamic column.
    dyn=$(awk -F, -v part="$held" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        $c["part"] == part { s += $c["p_physical"] * ($c["p_dynamic"] > $c["p_physical"] ? $c["p_dynamic"] - $c["p_physical"] : $c["p_physical"] - $c["p_dynamic"]) }
        END { printf "%.1f", s / 100 }' "$tables")
    fitted=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
        { x = $c["unit"] == "auto" ? "x" : ""
          printf "%s%s %.3g%s [%.3g%s, %.3g%s]", sep, $1, $2, x, $3, x, $4, x; sep = "; " }' \
        "$outdir/loo.$held.params.csv")
    mode=$(sed -n 's/.*: fit: initial \([a-z]*\): maximised.*/\1/p' "$outdir/loo.$held.err")
    fitted="$fitted${mode:+; initial $mode}"
    cost=$(sed -n 's/.*: fit: \([0-9]* evaluations, [0-9]* drops simulated\).*; \(.*\) s wall, \(.*\) s CPU/\1, \2 s wall, \3 s CPU/p' \
        "$outdir/loo.$held.err")
    read -r eqs tqs <<< "$(e p_qs)"
    read -r epqs tpqs <<< "$(e p_pqs)"
    read -r ebest tbest <<< "$(e p_best)"
    read -r eavg tavg <<< "$(e p)"
    printf '%s|%s|%s|%s|%s|%s|%s|%s|%s|%s|%s|%s\n' "$held" "$eqs" "$epqs" "$dyn" "$ebest" "$eavg" \
        "$tqs" "$tpqs" "$tbest" "$tavg" "$fitted" "$cost" >> "$summary"
done
printf '\nleave-one-out: each part predicted from a scene fitted to the other three (fit %s,\n' "$spec"
printf '%s drops per part and evaluation, initial %s when not fitted, seed %s); e16 and TV in percent\n' \
    "$n" "$initial" "$seed"
awk -F'|' '
    BEGIN { printf "%-20s | %5s %5s %5s %6s %6s | %5s %5s %6s %6s | %s\n", "held out", "QS", "PQS",
            "Dyn", "best", "avg", "TV QS", "PQS", "best", "avg", "fitted (95%)" }
    { printf "%-20s | %5.1f %5.1f %5.1f %6.1f %6.1f | %5.1f %5.1f %6.1f %6.1f | %s\n", $1, $2, $3, $4,
             $5, $6, $7, $8, $9, $10, $11
      for (c = 2; c <= 10; c++) s[c] += $c; m++
      worse += $5 > $3; cost[m] = $12 }
    END {
        printf "%-20s | %5.1f %5.1f %5.1f %6.1f %6.1f | %5.1f %5.1f %6.1f %6.1f |\n", "mean", s[2] / m,
               s[3] / m, s[4] / m, s[5] / m, s[6] / m, s[7] / m, s[8] / m, s[9] / m, s[10] / m
        printf "held-out parts whose best-fit e16 is worse than their PQS: %d of %d\n", worse, m
        for (i = 1; i <= m; i++) printf "fold %d: %s\n", i, cost[i]
    }' "$summary"
exit $status
