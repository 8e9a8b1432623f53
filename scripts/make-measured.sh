#!/usr/bin/env bash
# make-measured.sh: the paper's physical tests (parts/paper-tables.csv) as
# the measured-counts files posedrop fit and --measured read, one per
# rebuilt part: parts/<part>-measured.csv, pose,count with the poses numbered
# as 'posedrop --group' numbers the part's classes (scripts/measured.awk
# pairs them by rank of QS).
#
#   scripts/make-measured.sh [--check]
#
# --check writes nothing and exits 1 if a shipped file differs from what
# the tables and the current posedrop give (make check-readme runs it).
# POSEDROP names the binary (default build/opt/posedrop).
set -u
. "$(dirname "$0")/args.sh"
here=$(cd "$(dirname "$0")/.." && pwd)
check=0
case "${1:-}" in
    '') ;;
    --check) check=1 ;;
    --help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) args_die "unknown argument '$1'" ;;
esac
bin=${POSEDROP:-$here/build/opt/posedrop}
[ -x "$bin" ] || { echo "make-measured.sh: $bin not built (run make)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
for part in insulator_cap white_button rect_black_button square_black_button; do
    "$bin" --group "$here/parts/$part.off" > "$tmp/$part.grouped.csv" || exit 1
    awk -F, -v part="$part" -v tag=make-measured.sh -f "$here/scripts/measured.awk" \
        "$here/parts/paper-tables.csv" "$tmp/$part.grouped.csv" > "$tmp/$part-measured.csv" || exit 1
    shipped="$here/parts/$part-measured.csv"
    if [ $check = 1 ]; then
        cmp -s "$tmp/$part-measured.csv" "$shipped" ||
            { echo "make-measured.sh: $shipped differs from the tables (run scripts/make-measured.sh)" >&2; status=1; }
    else
        cp "$tmp/$part-measured.csv" "$shipped"
    fi
done
exit $status
