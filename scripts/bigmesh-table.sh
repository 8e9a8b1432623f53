#!/bin/sh
# bigmesh-table.sh [BIN] [DIR]: the static pipeline on the large meshes of
# scripts/make-big-meshes.py against qconvex on the same vertices, CPU
# seconds (user + sys) and peak RSS of each whole process (/usr/bin/time),
# as the rows of the table in docs/performance.md. Writes the meshes into
# DIR (default /tmp/bigmesh; about 500 MB, 1.2 GB with BIG=1) unless they are
# there. BIN: the posedrop to measure (default build/opt/posedrop).
# BIG=1 adds the 4-million-triangle sphere and icosphere, where a term
# that grows faster than n log n shows. qconvex is not run on the rod: on
# its 20,000-sided rings it ran over 20 minutes and was stopped.
# make figures writes its output to docs/figures/bigmesh.txt.
# A second table: CPU seconds of each stage of the static pipeline on the
# 2-million-triangle meshes (tests/bench/stages.c, built against the
# libposedrop.a beside BIN).
set -e
cd "$(dirname "$0")/.."
bin=${1:-build/opt/posedrop}
dir=${2:-/tmp/bigmesh}
mkdir -p "$dir"
gen() {
    [ -s "$dir/$1.off" ] || scripts/make-big-meshes.py $2 "$dir/$1.off"
    [ -s "$dir/$1.pts" ] || scripts/make-big-meshes.py points "$dir/$1.off" "$dir/$1.pts"
}
meshes="hull latlong400k latlong pair ico rod"
gen hull "hull 10000"
gen latlong400k "latlong 447"
gen latlong "latlong 1000"
gen pair "pair 707"
gen ico "icosphere 316"
gen rod "rod 20000 50"
if [ "${BIG:-0}" = 1 ]; then
    gen latlong4m "latlong 1414"
    gen ico4m "icosphere 447"
    meshes="$meshes latlong4m ico4m"
fi
measure() { # the command's CPU seconds and peak MB
    /usr/bin/time -f "%U %S %M" -o "$dir/time" "$@" > /dev/null 2> "$dir/err" || true
    awk '{printf "%.2f s, %d MB", $1 + $2, $3 / 1024}' "$dir/time"
}
echo "# BIG=${BIG:-0} scripts/bigmesh-table.sh $bin $dir on $(git rev-parse --short HEAD), $(date -u +%Y-%m-%d), load $(cut -d' ' -f1 /proc/loadavg)"
echo "| mesh | triangles | posedrop --com 0,0,0 | qconvex TI | ratio |"
echo "|---|---|---|---|---|"
for m in $meshes; do
    nt=$(sed -n 2p "$dir/$m.off" | cut -d' ' -f2)
    p=$(measure "$bin" --com 0,0,0 "$dir/$m.off")
    if [ "$m" = rod ]; then
        q="not run"
        r="-"
    else
        q=$(measure qconvex TI "$dir/$m.pts")
        r=$(echo "$p $q" | awk '{printf "%.1fx", $1 / $5}')
    fi
    echo "| $m | $nt | $p | $q | $r |"
done
echo
echo "CPU seconds per stage (tests/bench/stages.c against $(dirname "$bin")/libposedrop.a):"
echo
echo "| mesh | reading | weld | hull | orientation | mass | check | whole |"
echo "|---|---|---|---|---|---|---|---|"
cc -std=c11 -O2 -Iinclude tests/bench/stages.c "$(dirname "$bin")/libposedrop.a" -lgsl -lgslcblas \
   -lm -pthread -lstdc++ -o "$dir/stages"
for m in latlong pair ico rod; do
    "$dir/stages" "$dir/$m.off" 2> /dev/null
done
