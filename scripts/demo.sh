#!/usr/bin/env bash
# demo.sh: make demo. Drops a part 2000 times and prints what a newcomer can
# read: its pose classes with the three estimates in percent, one sentence
# on what they mean, and where the report with the pictures is.
#
#   scripts/demo.sh POSEDROP PART [OUTDIR]
#
# Writes OUTDIR/<part>.csv and OUTDIR/<part>.html (default build/demo).
set -u
. "$(dirname "$0")/args.sh"
case "${1:-}" in
    --help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac
[ $# -ge 2 ] && [ $# -le 3 ] || args_die "expected POSEDROP PART [OUTDIR]"
bin=$1 part=$2 outdir=${3:-build/demo}
[ -x "$bin" ] || args_die "$bin: not an executable"
args_files "$part"
mkdir -p "$outdir" || exit 2
name=$(basename -- "${part%.*}")
csv="$outdir/$name.csv" html="$outdir/$name.html"
"$bin" --group -n 2000 -h 0.12 --report "$html" "$part" > "$csv" || exit
echo
echo "posedrop dropped $part 2000 times from 0.12 m onto a moving belt (the paper's"
echo "scene) and counted the pose each drop came to rest in, beside the quasi-static"
echo "(QS) and perturbed quasi-static (PQS) estimates, which take milliseconds:"
echo
awk -F, '
    NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i
              printf "  %-5s %5s %7s %7s %8s   %s\n", "class", "poses", "QS", "PQS", "drops", "95% interval"; next }
    { printf "  %-5s %5d %6.1f%% %6.1f%% %7.1f%%   %.1f%% to %.1f%%\n", $c["pose"],
             split($c["members"], m, " "), 100 * $c["p_qs"], 100 * $c["p_pqs"], 100 * $c["p"],
             100 * $c["ci_lo"], 100 * $c["ci_hi"] }' "$csv"
echo
echo "A class is the poses a rotation of the part maps onto each other (a round"
echo "part's sides), numbered by QS, most probable first. Pictures of each pose:"
echo "  $html (open it in a browser); the numbers as CSV: $csv"
