#!/bin/sh
# bigmesh-table.sh [BIN] [DIR]: the static pipeline on the large meshes of
# scripts/make-big-meshes.py against qconvex on the same vertices, CPU
# seconds (user + sys) and peak RSS of each whole process (/usr/bin/time),
# as the rows of the table in docs/performance.md. Writes the meshes into
# DIR (default /tmp/bigmesh; about 400 MB) unless they are there.
# BIN: the posedrop to measure (default build/opt/posedrop).
set -e
cd "$(dirname "$0")/.."
bin=${1:-build/opt/posedrop}
dir=${2:-/tmp/bigmesh}
mkdir -p "$dir"
gen() {
    [ -s "$dir/$1.off" ] || scripts/make-big-meshes.py $2 "$dir/$1.off"
    [ -s "$dir/$1.pts" ] || scripts/make-big-meshes.py points "$dir/$1.off" "$dir/$1.pts"
}
gen hull "hull 10000"
gen latlong400k "latlong 447"
gen latlong "latlong 1000"
gen ico "icosphere 316"
gen rod "rod 20000 50"
measure() { # the command's CPU seconds and peak MB
    /usr/bin/time -f "%U %S %M" -o "$dir/time" "$@" > /dev/null 2> "$dir/err" || true
    awk '{printf "%.2f s, %d MB", $1 + $2, $3 / 1024}' "$dir/time"
}
echo "# scripts/bigmesh-table.sh $bin on $(git rev-parse --short HEAD), $(date -u +%Y-%m-%d), load $(cut -d' ' -f1 /proc/loadavg)"
echo "| mesh | posedrop --com 0,0,0 | qconvex |"
echo "|---|---|---|"
for m in hull latlong400k latlong ico rod; do
    p=$(measure "$bin" --com 0,0,0 "$dir/$m.off")
    q=$(measure qconvex TI "$dir/$m.pts")
    echo "| $m | $p | $q |"
done
