#!/usr/bin/env bash
# sweeps.sh: one-at-a-time sweeps, the check on what a ranged run says each
# parameter moves (docs/uncertainty.md).
#
#   scripts/sweeps.sh [-n DROPS] [-o FILE] [-p PARAMETER]... [-- POSEDROP-OPTIONS...] PART
#
# For each of mu, restitution, the drop height and the contact time, DROPS
# drops (default 4000) at each of 5 values evenly spread over the range
# docs/uncertainty.md uses (mu 0.2-0.6, restitution 0.1-0.5, height
# 0.08-0.16 m, contact time 0.3-3x auto, evenly in log), the other
# parameters at their defaults (or as POSEDROP-OPTIONS set them), pose
# classes grouped, the impulse engine. -p sweeps only the PARAMETERs named
# (mu, restitution, height, contact_time).
# Writes FILE (default results/<part>-sweeps.csv):
#   parameter,value,pose,n,count,p,ci_lo,ci_hi
# after two '#' lines giving the command and the commit it ran on.
# POSEDROP names the binary (default build/opt/posedrop).
set -u
. "$(dirname "$0")/args.sh"
n=4000
out=""
opts=()
only=" "
part=""
while [ $# -gt 0 ]; do
    case "$1" in
        -n) args_value "$@"; args_count -n "$2"; n=$2; shift 2 ;;
        -o) args_value "$@"; out=$2; shift 2 ;;
        -p) args_value "$@"
            case "$2" in mu|restitution|height|contact_time) only="$only$2 " ;;
                *) args_die "-p: expected mu, restitution, height or contact_time, got '$2'" ;; esac
            shift 2 ;;
        --) shift; while [ $# -gt 1 ]; do opts+=("$1"); shift; done ;;
        --help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) args_die "unknown option '$1' (options for posedrop go after --)" ;;
        *) [ -z "$part" ] || args_die "give one PART file, not '$part' and '$1'"; part=$1; shift ;;
    esac
done
[ -n "$part" ] || args_die "give one PART file"
args_files "$part"
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "sweeps.sh: $bin not built (run make)" >&2; exit 2; }
name=$(basename "$part"); name=${name%.*}
[ -n "$out" ] || { mkdir -p results; out=results/$name-sweeps.csv; }
commit=$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)
tmp=$(mktemp) || exit 2
trap 'rm -f "$tmp" "$tmp.run"' EXIT
{
    ponly=""
    for p in $only; do ponly="$ponly -p $p"; done
    printf "# scripts/sweeps.sh -n %s%s%s %s\n" "$n" "$ponly" "${opts[*]:+ -- ${opts[*]}}" "${part#"$here"/}"
    printf '# commit %s, %s\n' "$commit" "$(date -u +%Y-%m-%d)"
    echo "parameter,value,pose,n,count,p,ci_lo,ci_hi"
} > "$tmp"
# A zero-width range is the fixed value (docs/cli.md); it takes the contact
# time's multiples of auto, which a fixed value does not.
sweep() { # option key values...
    local opt=$1 key=$2; shift 2
    [ "$only" = " " ] || case "$only" in *" $key "*) ;; *) return 0 ;; esac
    for v in "$@"; do
        "$bin" -n "$n" --group "${opts[@]}" "$opt" "$v:$v" "$part" > "$tmp.run" ||
            { echo "sweeps.sh: posedrop failed at $key = $v" >&2; exit 1; }
        awk -F, -v key="$key" -v val="${v%x}" '
            NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
            { printf "%s,%s,%s,%s,%s,%s,%s,%s\n", key, val, $c["pose"], $c["n"], $c["count"],
                     $c["p"], $c["ci_lo"], $c["ci_hi"] }' "$tmp.run" >> "$tmp"
    done
}
sweep --mu mu 0.2 0.3 0.4 0.5 0.6
sweep --restitution restitution 0.1 0.2 0.3 0.4 0.5
sweep -h height 0.08 0.1 0.12 0.14 0.16
sweep --contact-time contact_time 0.3x 0.5477x 1x 1.826x 3x
mv "$tmp" "$out"
