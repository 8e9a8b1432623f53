#!/usr/bin/env bash
# paper.sh: reproduce Tables 1-4 of Goldberg, Mirtich et al. with posedrop's
# columns beside the paper's.
#
#   scripts/paper.sh [-n DROPS] [-i INITIAL] [-t CONTACT_TIME] [-e ENGINES] [-o DIR] [-d PAPER_TABLES_CSV] [-r | -T]
#   scripts/paper.sh -L [-f SPEC] [-n DROPS] [-i INITIAL] [-m EVALS] [-p POINTS] [-s SEED]
#                       [-P JOBS] [-H PART] [-t CONTACT_TIME] [-o DIR]
#
# For each of the paper's four parts (parts/<name>.off, rebuilt from the
# paper's photographs; parts/README.md), runs posedrop's QS and PQS and the
# three engines with the paper's scene (2000 drops from 0.12 m, belt 0.05 m/s,
# mu = restitution = 0.3, vibration 1.5 degrees, the belt's initial poses:
# INITIAL is stationary by default, the long run of the estimated pose-to-pose
# chain, or bootstrap, the paper's own running estimate, for comparison;
# CONTACT_TIME, s, the duration of one contact (posedrop's default when not
# given; 0: the rigid model): --contact-time),
# grouped into pose classes as the paper counts them, writes the CSVs under DIR
# (default results/; each engine's starts with '#' lines giving its command
# and the commit it ran on; -r keeps a run whose CSV is already there, whole,
# of DROPS drops, as an interrupted run or one run apart left it: it cannot
# tell the other options, so give the same; -T runs nothing and prints the
# tables of the runs there, '-' for a run missing) and prints a legend, then each table: the paper's QS, PQS, dynamic and
# physical columns, posedrop's QS, PQS, impulse, ODE and Bullet, then the
# eq. (16) error of every column against the physical tests and the total
# variation distance beside it (eq. 16 weights by the measured p, so mass on
# poses never observed costs nothing there; total variation counts it).
# posedrop's classes are matched to the paper's poses by rank of their QS
# probability on both sides, the column the parts were fitted on (the paper
# numbers its poses by physical frequency). -e runs only ENGINES (comma-
# separated, of impulse, ode and bullet; the others' columns print '-'):
# make figures runs the impulse engine alone, as ODE and Bullet at their
# automatic step cost 0.2-0.6 s of CPU per drop of the cap.
#
# -L: leave-one-out cross-validation of the calibration (posedrop fit,
# docs/calibration.md). The paper's physical counts (its percentages times
# its trials) become pose,count files in posedrop's class numbering (the QS
# rank pairing above); for each part, the scene parameters SPEC (default
# mu=0.1:0.8,restitution=0.05:0.7,height=0.06:0.2; 'initial' among them fits
# the initial mode too: three searches, about the stationary start's cost)
# are fitted to the other three parts and the fourth is predicted: at the best fit and averaged over
# the likelihood-weighted values, with its 95% interval. Prints each held-out part's table (the paper's
# columns, posedrop's QS and PQS, the two predictions), then e16 and TV per
# part with the fitted values of each fold. DROPS (default 400) are simulated
# per part and evaluation, INITIAL (default stationary) is the initial mode
# when it is not fitted, EVALS (25) and POINTS (8) bound the search and the
# weighting, SEED (1) is the drops' seed of every evaluation; JOBS (2) folds
# run at once, one thread each when more than one; -H PART runs the one fold
# that holds PART out (insulator_cap, white_button, rect_black_button,
# square_black_button).
#
# POSEDROP names the binary (default: the newest build/*/posedrop, which after
# a sanitizer check is the sanitized one: give build/opt/posedrop for timings).
set -u
. "$(dirname "$0")/args.sh"
n=2000
initial=stationary
contact_time=
outdir=results
tables=""
loo=0
spec=mu=0.1:0.8,restitution=0.05:0.7,height=0.06:0.2
evals=25
points=8
n_given=
seed=1
jobs=2
held=
engines=impulse,ode,bullet
reuse=0
tables_only=0
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; n_given=1; shift 2 ;;
        -i) args_value "$@"; initial=$2; shift 2 ;;
        -L) loo=1; shift ;;
        -r) reuse=1; shift ;;
        -T) tables_only=1; reuse=1; shift ;;
        -f) args_value "$@"; spec=$2; shift 2 ;;
        -m) args_value "$@"; args_count -m "$2"; evals=$2; shift 2 ;;
        -p) args_value "$@"; args_count -p "$2"; points=$2; shift 2 ;;
        -t) args_value "$@"; contact_time=$2; shift 2 ;;
        -e) args_value "$@"; engines=$2; shift 2 ;;
        -s) args_value "$@"; seed=$2; shift 2 ;;
        -P) args_value "$@"; args_count -P "$2"; jobs=$2; shift 2 ;;
        -H) args_value "$@"; held=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        -d) args_value "$@"; tables=$2; shift 2 ;;
        --help) sed -n '2,48p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
case " insulator_cap white_button rect_black_button square_black_button " in
    *" $held "*) ;;
    *) [ -z "$held" ] || args_die "-H: expected one of insulator_cap, white_button, \
rect_black_button, square_black_button, got '$held'" ;;
esac
for e in ${engines//,/ }; do
    case "$e" in impulse|ode|bullet) ;; *) args_die "-e: expected impulse, ode or bullet, got '$e'" ;; esac
done
case "$seed" in
    *[!0-9]*) args_die "-s: expected a whole number, got '$seed'" ;;
esac
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${POSEDROP:-$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1)}
[ -n "$bin" ] || { echo "paper.sh: posedrop not built (run make)" >&2; exit 2; }
if [ -z "$tables" ]; then
    for t in "$here/../shared/data/paper-tables.csv" "$here/parts/paper-tables.csv"; do
        [ -f "$t" ] && { tables=$t; break; }
    done
fi
[ -f "$tables" ] || args_die "the paper's measured tables not found (give -d FILE)"
# -i and -t as posedrop reads them, on a static run of one part (milliseconds),
# so that a bad value is refused once, before any drop.
why=$("$bin" --initial "$initial" ${contact_time:+--contact-time "$contact_time"} \
    "$here/parts/cap.off" 2>&1 >/dev/null) || args_die "$(printf '%s' "$why" | head -n 1)"
mkdir -p "$outdir" || exit 2
if [ "$loo" = 1 ]; then
    [ -n "$n_given" ] || n=400
    exec "$here/scripts/paper-loo.sh" "$bin" "$tables" "$outdir" "$spec" "$n" "$initial" "$evals" \
        "$points" "$seed" "$jobs" "$held" ${contact_time:+"$contact_time"}
fi
# What the tables' blocks and rows are, so that the output reads without
# docs/validation.md.
cat <<EOF
Tables 1-4 of Goldberg, Mirtich et al., "Part Pose Statistics: Estimators and
Experiments", with posedrop's columns beside the paper's; every figure in percent.
  left block, the paper's:  QS and PQS estimates, Dyn its dynamic simulation,
                            Phys the physical tests (the reference)
  right block, posedrop's:  QS and PQS estimates, and $n drops (initial $initial)
                            on posedrop's impulse engine, ODE and Bullet ('-': not run)
  pose  numbered as the paper numbers them (by physical frequency); posedrop's
        pose classes are paired with them by rank of their QS probability
  e16   the paper's eq. (16) error against the physical tests: the sum over poses
        of p_phys |p - p_phys| (0: exact; mass on poses never seen costs nothing)
  TV    total-variation distance from the physical tests: half the sum of
        |p - p_phys|, mass on poses never seen included
EOF
status=0
runs=0
commit=$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)
nengines=$(echo "$engines" | tr ',' '\n' | grep -c .)
start_s=$SECONDS
for part in insulator_cap white_button rect_black_button square_black_button; do
    file="$here/parts/$part.off"
    [ -f "$file" ] || { echo "paper.sh: $file missing" >&2; status=1; continue; }
    "$bin" --group "$file" > "$outdir/$part.static.csv" || { status=1; continue; }
    for engine in impulse ode bullet; do
        case ",$engines," in *",$engine,"*) ;; *) continue ;; esac
        runs=$((runs + 1))
        if [ "$reuse" = 1 ] && awk -F, -v n="$n" '
                /^#/ { next }
                !ncol { ncol = NF; for (i = 1; i <= NF; i++) c[$i] = i; next }
                { rows++; if ($c["n"] != n || $c["partial"] != 0) bad = 1 }
                END { exit !(rows > 0 && !bad) }' "$outdir/$part.$engine.csv" 2>/dev/null; then
            echo "paper.sh: $part on $engine, run $runs of $((4 * nengines)): kept $outdir/$part.$engine.csv" >&2
            continue
        fi
        if [ "$tables_only" = 1 ]; then
            echo "paper.sh: $part on $engine: no whole run of $n drops in $outdir (-T: none made)" >&2
            rm -f "$outdir/$part.$engine.seconds"
            status=1
            continue
        fi
        rm -f "$outdir/$part.$engine.csv" "$outdir/$part.$engine.seconds"
        echo "paper.sh: $part on $engine, run $runs of $((4 * nengines)), $((SECONDS - start_s)) s so far" >&2
        args=(--group -n "$n" --initial "$initial" ${contact_time:+--contact-time "$contact_time"}
              --engine "$engine")
        # CPU seconds (user + sys, all threads): wall time says more of the
        # machine's other load than of the run.
        TIMEFORMAT='%3U %3S'
        { time { printf '# posedrop %s parts/%s.off\n# commit %s, %s\n' "${args[*]}" "$part" "$commit" \
                   "$(date -u +%Y-%m-%d)"
                 "$bin" "${args[@]}" "$file"; } \
            > "$outdir/$part.$engine.csv" 2> "$outdir/$part.$engine.err" || status=1; } \
            2> "$outdir/$part.$engine.time"
        awk '{ printf "%.3f\n", $1 + $2 }' "$outdir/$part.$engine.time" > "$outdir/$part.$engine.seconds"
    done
    # One table: paper columns by pose number, posedrop's by class rank in QS.
    awk -F, -v part="$part" -v outdir="$outdir" -v initial="$initial" -v engines="$engines" -v n="$n" '
        function load(file, key,    line, i, c, k) {
            k = 0
            while ((getline line < file) > 0) {
                if (line ~ /^#/) continue
                split(line, f, ",")
                if (!c["pose"]) { for (i = 1; i in f; i++) c[f[i]] = i; continue }
                k++
                qs[key, k] = f[c["p_qs"]]; pqs[key, k] = f[c["p_pqs"]]
                dyn[key, k] = ("p" in c) ? f[c["p"]] : ""
            }
            close(file); delete c
            return k
        }
        # Ranks of the classes by descending QS (ties by class number).
        function rank(key, k,    i, j, t) {
            for (i = 1; i <= k; i++) order[key, i] = i
            for (i = 1; i <= k; i++) for (j = i + 1; j <= k; j++)
                if (qs[key, order[key, j]] > qs[key, order[key, i]]) {
                    t = order[key, i]; order[key, i] = order[key, j]; order[key, j] = t }
        }
        BEGIN {
            ks = load(outdir "/" part ".static.csv", "s"); rank("s", ks)
            split("impulse ode bullet", eng, " ")
            for (e = 1; e <= 3; e++) {
                ran[e] = index("," engines ",", "," eng[e] ",") > 0
                ke[e] = ran[e] ? load(outdir "/" part "." eng[e] ".csv", eng[e]) : 0; rank(eng[e], ke[e])
            }
            # An engine not asked for, or a run missing or cut short, has no
            # column: "-", not zeros.
            for (c = 1; c <= 5; c++) have[c] = c < 3 || (ran[c - 2] && whole(outdir "/" part "." eng[c - 2] ".csv"))
        }
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        $col["part"] == part {
            np++; p = $col["pose"]
            paper[p, 1] = $col["p_qs"] / 100; paper[p, 2] = $col["p_pqs"] / 100
            paper[p, 3] = $col["p_dynamic"] / 100; phys[p] = $col["p_physical"] / 100
            trials = $col["physical_trials"]
        }
        END {
            # The paper numbers its poses by physical frequency: pair its QS
            # ranks with ours (the pairing the QS fit was made under).
            for (i = 1; i <= np; i++) prank[i] = i
            for (i = 1; i <= np; i++) for (j = i + 1; j <= np; j++)
                if (paper[prank[j], 1] > paper[prank[i], 1]) { t = prank[i]; prank[i] = prank[j]; prank[j] = t }
            for (r = 1; r <= np; r++) rank_of[prank[r]] = r
            printf "\n%s (%d physical trials; posedrop: %d pose classes, paper: %d; initial %s)\n", part, trials, ks, np, initial
            printf "%4s | %-27s | %s\n", "", "the paper", "posedrop"
            printf "%4s | %6s %6s %6s %6s | %6s %6s %7s %6s %6s\n", "pose", "QS", "PQS", "Dyn", "Phys",
                   "QS", "PQS", "impulse", "ODE", "Bullet"
            for (p = 1; p <= np; p++) {
                r = rank_of[p]
                ours[p, 1] = r <= ks ? qs["s", order["s", r]] : 0
                ours[p, 2] = r <= ks ? pqs["s", order["s", r]] : 0
                # The engines rank their own classes by QS too: same order.
                for (e = 1; e <= 3; e++) ours[p, 2 + e] = r <= ke[e] ? dyn[eng[e], order[eng[e], r]] : 0
                printf "%4d | %6.1f %6.1f %6.1f %6.1f |", p,
                       100 * paper[p, 1], 100 * paper[p, 2], 100 * paper[p, 3], 100 * phys[p]
                for (c = 1; c <= 5; c++) printf " %s", cell(c, 100 * ours[p, c])
                printf "\n"
            }
            # Mass posedrop puts on classes beyond the paper count goes to TV.
            for (c = 1; c <= 5; c++) { extra[c] = 0 }
            for (p = np + 1; p <= ks; p++) {
                extra[1] += qs["s", order["s", p]]; extra[2] += pqs["s", order["s", p]]
                for (e = 1; e <= 3; e++) if (p <= ke[e]) extra[2 + e] += dyn[eng[e], order[eng[e], p]]
            }
            printf "%4s |", "e16"
            for (c = 1; c <= 3; c++) printf " %6.1f", err16(paper, c, np)
            printf " %6s |", "-"
            for (c = 1; c <= 5; c++) printf " %s", cell(c, err16(ours, c, np))
            printf "\n%4s |", "TV"
            for (c = 1; c <= 3; c++) printf " %6.1f", tv(paper, c, np, 0)
            printf " %6s |", "-"
            for (c = 1; c <= 5; c++) printf " %s", cell(c, tv(ours, c, np, extra[c]))
            printf "\n"
        }
        function err16(a, c, n,    p, s) { s = 0; for (p = 1; p <= n; p++) s += phys[p] * abs(a[p, c] - phys[p]); return 100 * s }
        function tv(a, c, n, rest,    p, s) { s = rest; for (p = 1; p <= n; p++) s += abs(a[p, c] - phys[p]); return 50 * s }
        function abs(x) { return x < 0 ? -x : x }
        function cell(c, v,    w) { w = c == 3 ? 7 : 6; return have[c] ? sprintf("%" w ".1f", v) : sprintf("%" w "s", "-") }
        # A run of n drops, whole: rows, each of n drops and not partial.
        function whole(file,    line, f, c, i, rows, bad) {
            while ((getline line < file) > 0) {
                if (line ~ /^#/) continue
                split(line, f, ",")
                if (!c["pose"]) { for (i = 1; i in f; i++) c[f[i]] = i; continue }
                rows++
                if (f[c["n"]] != n || f[c["partial"]] != 0) bad = 1
            }
            close(file)
            return rows > 0 && !bad
        }
    ' "$tables" | tee "$outdir/$part.table.txt"
done
printf '\nCPU seconds per run (user + sys, %d drops):' "$n"
for part in insulator_cap white_button rect_black_button square_black_button; do
    for engine in impulse ode bullet; do
        [ -f "$outdir/$part.$engine.seconds" ] && printf ' %s/%s %s' "$part" "$engine" "$(cat "$outdir/$part.$engine.seconds")"
    done
done
printf '\n'
exit $status
