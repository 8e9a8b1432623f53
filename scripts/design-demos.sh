#!/usr/bin/env bash
# design-demos.sh: the four demonstrations of docs/design.md, each checked
# independently, into docs/figures/design/ (make figures runs it).
#
#   scripts/design-demos.sh [-j THREADS] [--only NAME] [--quick]
#
# die3: a cube stretched along z until each square face lands 1/3 and the
#       four sides together 1/3 (posedrop design, PQS then drops), beside
#       the QS design for the same target;
# loaded: a cube whose centre of mass moves along z until its bottom face
#       lands 50%;
# bushing: a flanged bushing whose flange-down share is maximised over its
#       flange's thickness and body's length, each 0.7 to 1.5 times;
# die5: a triangular prism stretched until its five faces are equally
#       likely, the QS and the drops' answers side by side.
# The independent check of each: the written part read back by the plain
# command (posedrop -n 20000 with a seed neither search used), and for the
# bushing the same part rebuilt from its dimensions by
# scripts/design-parts.py, and the range's corners dropped alike. Each demo
# writes NAME.csv (design's rows), NAME.log (its stderr), NAME.off (the
# part), NAME.check.csv (the fresh drops); summary.csv holds one row per
# target, with the command's cost, the commit and the date; summary.md the
# table docs/design.md links. sens.csv and sens.log: what each change moves
# on the bushing, per pose (exact QS/PQS derivatives, paired drops). Exits 1
# when a check misses its target. --quick runs every step with few drops
# into a scratch directory: a check of the script, not of the designs.
set -eu
. "$(dirname "$0")/args.sh"
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "design-demos.sh: $bin not built (run make)" >&2; exit 2; }
threads=1
only=""
quick=0
while [ $# -gt 0 ]; do
    case "$1" in
        -j) args_value "$@"; threads=$2; shift 2 ;;
        --only) args_value "$@"; only=$2; shift 2 ;;
        --quick) quick=1; shift ;;
        --help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) args_die "unknown argument '$1'" ;;
    esac
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out="$here/docs/figures/design"
# Drops: per refinement evaluation (-n), of each fresh check, of the
# bushing's grid points, and per side of the sensitivities.
n_design=40000 n_bushing=3000 check_n=20000 grid_n=5000 sens_n=2000
if [ "$quick" = 1 ]; then
    out="$tmp/out"
    n_design=400 n_bushing=200 check_n=400 grid_n=100 sens_n=100
fi
mkdir -p "$out"
# The commit, marked -dirty when the tree differs from it.
commit=$(git -C "$here" describe --always --dirty 2>/dev/null || echo unknown)
today=$(date -u +%Y-%m-%d)
check_seed=1001
summary="$out/summary.csv"
[ -n "$only" ] && [ -f "$summary" ] || \
    echo "demo,set,normals,target,p_check,ci_lo,ci_hi,met,design,cpu_s,static_ms,commit,date" > "$summary"
status=0

# design NAME ARGS...: runs posedrop design, keeps its rows and log.
design() {
    name=$1
    shift
    echo "design-demos.sh: $name: posedrop design $*" >&2
    "$bin" design -j "$threads" --check "$check_n" "$@" --out "$out/$name.off" \
        > "$out/$name.csv" 2> "$out/$name.log"
    printf '# posedrop design %s\n# commit %s, %s\n' "$*" "$commit" "$today" >> "$out/$name.log"
}

# cost NAME: the CPU seconds and the static stage's milliseconds per
# evaluation, from the log.
cost() {
    sed -n 's/.*cost: .*(\([0-9.e+-]*\) ms CPU each).*; \([0-9.]*\) s CPU in all.*/\2,\1/p' "$out/$1.log"
}

# check NAME SETS DESIGN [ARGS...]: drops the written part afresh and
# compares each set of poses (SETS: rows nx,ny,nz,set,p, p on the set's
# first row, empty: reported only) with the fresh drops' count summed over
# the poses of those normals, and its 95% Wilson interval. Only a miss of the
# drops' design fails the script: the QS designs are shown missing. A symmetric
# part's poses of one set differ only by sampling noise (a box's two caps),
# so the change can set only their sum: the sets are what is checked.
check() {
    name=$1 sets=$2 label=$3
    shift 3
    "$bin" -n "$check_n" --seed "$check_seed" -j "$threads" "$@" "$out/$name.off" \
        > "$out/$name.check.csv"
    c=$(cost "$name")
    awk -F, -v demo="$name" -v label="$label" -v cost="$c" -v commit="$commit" -v date="$today" '
        FNR == 1 { for (i = 1; i <= NF; i++) col[FILENAME, $i] = i; next }
        FILENAME == ARGV[1] { tn++; tx[tn] = $col[FILENAME, "nx"]; ty[tn] = $col[FILENAME, "ny"];
                              tz[tn] = $col[FILENAME, "nz"]; ts[tn] = $col[FILENAME, "set"];
                              if (!(ts[tn] in tp)) { tp[ts[tn]] = $col[FILENAME, "p"]; order[++ns] = ts[tn] }
                              next }
        { rows++; nx[rows] = $col[FILENAME, "nx"]; ny[rows] = $col[FILENAME, "ny"];
          nz[rows] = $col[FILENAME, "nz"]; cnt[rows] = $col[FILENAME, "count"]; n = $col[FILENAME, "n"] }
        END {
            bad = 0
            for (t = 1; t <= tn; t++) {
                best = -1; bd = 1e9
                for (r = 1; r <= rows; r++) {
                    d = (nx[r] - tx[t])^2 + (ny[r] - ty[t])^2 + (nz[r] - tz[t])^2
                    if (d < bd) { bd = d; best = r }
                }
                if (bd < 1e-6) k[ts[t]] += cnt[best]
                names[ts[t]] = names[ts[t]] (names[ts[t]] == "" ? "" : " ") "(" tx[t] " " ty[t] " " tz[t] ")"
            }
            z = 1.959963984540054
            for (i = 1; i <= ns; i++) {
                s = order[i]; p = k[s] / n
                c = p + z * z / (2 * n); h = z * sqrt(p * (1 - p) / n + z * z / (4 * n * n)); w = 1 + z * z / n
                lo = (c - h) / w; hi = (c + h) / w
                met = tp[s] == "" ? "" : (tp[s] + 0 >= lo && tp[s] + 0 <= hi) ? 1 : 0
                if (met == "0" && label == "drops") bad = 1
                printf "%s,%s,%s,%s,%.5f,%.5f,%.5f,%s,%s,%s,%s,%s\n", demo, s, names[s], tp[s], p, lo,
                       hi, met, label, cost, commit, date
            }
            exit bad
        }' "$sets" "$out/$name.check.csv" >> "$summary" || status=1
}

# com NAME: the --com a written part with a moved centre of mass needs.
com() {
    sed -n 's/.*drop it with --com \([^ ]*\)$/\1/p' "$out/$1.log"
}

if [ -z "$only" ] || [ "$only" = die3 ]; then
    t="$out/die3.target.csv"
    printf 'nx,ny,nz,p\n0,0,1,0.3333333333\n0,0,-1,0.3333333333\n1,0,0,0.0833333333\n-1,0,0,0.0833333333\n0,1,0,0.0833333333\n0,-1,0,0.0833333333\n' > "$t"
    printf 'nx,ny,nz,set,p\n0,0,1,caps,0.6666666667\n0,0,-1,caps,\n1,0,0,sides,0.3333333333\n-1,0,0,sides,\n0,1,0,sides,\n0,-1,0,sides,\n' > "$tmp/die3.sets"
    design die3 -n "$n_design" --vary scale_z=0.1:3 --target "$t" parts/canonical/cube.off
    check die3 "$tmp/die3.sets" drops
    design die3-qs --model qs -n 0 --check 0 --vary scale_z=0.1:3 --target "$t" parts/canonical/cube.off
    check die3-qs "$tmp/die3.sets" qs
fi

if [ -z "$only" ] || [ "$only" = loaded ]; then
    t="$out/loaded.target.csv"
    printf 'nx,ny,nz,p\n0,0,-1,0.5\n' > "$t"
    printf 'nx,ny,nz,set,p\n0,0,-1,bottom,0.5\n' > "$tmp/loaded.sets"
    design loaded -n "$n_design" --vary com_z=-0.0035:0.0035 --target "$t" parts/canonical/cube.off
    check loaded "$tmp/loaded.sets" drops --com "$(com loaded)"
fi

if [ -z "$only" ] || [ "$only" = bushing ]; then
    t="$out/bushing.target.csv"
    printf 'nx,ny,nz\n0,0,-1\n' > "$t"
    design bushing --units mm --vary 'stretch_z@0:3=0.7:1.5,stretch_z@3:18=0.7:1.5' \
        --maximise "$t" -n "$n_bushing" --max-evals 24 parts/design/bushing.off
    printf 'nx,ny,nz,set,p\n0,0,-1,flange_down,\n' > "$tmp/bushing.sets"
    check bushing "$tmp/bushing.sets" drops --units mm
    # The same part rebuilt from its dimensions, and the range's corners and
    # the part as given, each dropped afresh.
    s=$(sed -n 's/.*stretch_z@[0-9:]* = \([0-9.e+-]*\): .*/\1/p' "$out/bushing.log" | tr '\n' ' ')
    set -- $s
    python3 "$here/scripts/design-parts.py" --bushing "$(awk -v s="$1" 'BEGIN{printf "%.12g", 3*s}')" \
        "$(awk -v s="$2" 'BEGIN{printf "%.12g", 15*s}')" "$tmp/rebuilt.off"
    "$bin" --units mm "$tmp/rebuilt.off" > "$tmp/rebuilt.csv"
    "$bin" --units mm "$out/bushing.off" > "$tmp/written.csv"
    echo "corner,flange_t,body_l,p_flange_down,ci_lo,ci_hi,p_qs_rebuilt,p_qs_written" > "$out/bushing.corners.csv"
    printf 'rebuilt,%s,%s,,,,%s,%s\n' "$(awk -v s="$1" 'BEGIN{printf "%.12g", 3*s}')" \
        "$(awk -v s="$2" 'BEGIN{printf "%.12g", 15*s}')" \
        "$(awk -F, '$4 < -0.999 {print $7}' "$tmp/rebuilt.csv")" \
        "$(awk -F, '$4 < -0.999 {print $7}' "$tmp/written.csv")" >> "$out/bushing.corners.csv"
    for fb in 2.1,10.5 2.1,22.5 4.5,10.5 4.5,22.5 3,15; do
        ft=${fb%,*} bl=${fb#*,}
            python3 "$here/scripts/design-parts.py" --bushing "$ft" "$bl" "$tmp/c.off"
            "$bin" --units mm -n "$grid_n" --seed "$check_seed" -j "$threads" "$tmp/c.off" \
                | awk -F, -v ft="$ft" -v bl="$bl" 'NR > 1 && $4 < -0.999 {
                      printf "grid,%s,%s,%s,%s,%s,,\n", ft, bl, $11, $12, $13 }' \
                >> "$out/bushing.corners.csv"
    done
    # What each change moves on the bushing as given, per pose.
    "$bin" design --units mm -j "$threads" --group \
        --vary 'stretch_z@0:3=0.7:1.5,stretch_z@3:18=0.7:1.5,com_z=-1:1' \
        --sensitivity "$out/sens.csv" --sensitivity-drops "$sens_n" parts/design/bushing.off \
        2> "$out/sens.log"
fi

if [ -z "$only" ] || [ "$only" = die5 ]; then
    t="$out/die5.poses.csv"
    r3=0.8660254038
    printf 'nx,ny,nz\n0,0,1\n0,0,-1\n0,-1,0\n%s,0.5,0\n-%s,0.5,0\n' "$r3" "$r3" > "$t"
    printf 'nx,ny,nz,set,p\n0,0,1,ends,0.4\n0,0,-1,ends,\n0,-1,0,sides,0.6\n%s,0.5,0,sides,\n-%s,0.5,0,sides,\n' \
        "$r3" "$r3" > "$tmp/die5.sets"
    design die5 --units mm -n "$n_design" --vary scale_z=0.2:3 --equalise "$t" parts/design/prism3.off
    check die5 "$tmp/die5.sets" drops --units mm
    design die5-qs --units mm --model qs -n 0 --check 0 --vary scale_z=0.2:3 --equalise "$t" \
        parts/design/prism3.off
    check die5-qs "$tmp/die5.sets" qs --units mm
fi

# The table docs/design.md links: one row per checked set, with each
# demo's answer (the change's value from its log) and cost.
{
    echo "# The design demonstrations"
    echo
    echo "Written by scripts/design-demos.sh at commit $commit on $today (CPU seconds, one"
    echo "thread). p_check: $check_n fresh drops of the written part (seed $check_seed), 95% Wilson interval."
    echo
    echo "| demo | design | change found | set of poses | target | p_check [95%] | met | CPU s | static ms/eval |"
    echo "|---|---|---|---|---|---|---|---|---|"
    awk -F, -v dir="$out" 'NR > 1 {
        lf = dir "/" $1 ".log"; change = ""
        while ((getline line < lf) > 0)
            if (line ~ /design: (scale|stretch|com)_[xyz][^ ]* = /) {
                sub(/^.*design: /, "", line); sub(/: the .*$/, "", line)
                change = change (change == "" ? "" : "; ") line
            }
        close(lf)
        printf "| %s | %s | %s | %s %s | %s | %s [%s, %s] | %s | %s | %s |\n", $1, $9, change, $2,
               $3, $4 == "" ? "max" : $4, $5, $6, $7, $8 == "" ? "-" : $8, $10, $11 }' "$summary"
    if [ -f "$out/bushing.corners.csv" ]; then
        echo
        echo "The bushing's flange-down share at the corners and the middle of its"
        echo "range (flange thickness, body length, mm; $grid_n fresh drops each), and the written"
        echo "part's QS against the same part rebuilt from its dimensions:"
        echo
        echo "| point | flange mm | body mm | p flange-down [95%] | p_qs rebuilt | p_qs written |"
        echo "|---|---|---|---|---|---|"
        awk -F, 'NR > 1 { printf "| %s | %s | %s | %s [%s, %s] | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8 }' \
            "$out/bushing.corners.csv"
    fi
} > "$out/summary.md"
[ "$quick" = 1 ] && cat "$out/summary.md" "$out/sens.log" >&2
echo "design-demos.sh: wrote $summary and $out/summary.md" >&2
exit $status
