#!/bin/sh
# selfx-compare.sh [N [COMMIT]]: the self-crossing search of this tree against
# that of COMMIT (default 9f2cb89, the oriented-box tree before the
# surface-area tree) on N (default 20000) seeded random meshes, N/10 pairs of
# noisy spheres apart, and every mesh under parts/ (tests/selfx/compare.c).
# Exit 0 when every answer agrees.
set -e
n=${1:-20000}
commit=${2:-9f2cb89}
cd "$(dirname "$0")/.."
make -s build/opt/libposedrop.a
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
git show "$commit:src/mesh/mesh_selfx.c" > "$tmp/old_selfx.c"
cc -std=c11 -O2 -D_DEFAULT_SOURCE -Iinclude -Isrc -DPD_MESH_INTERNAL_H -include posedrop/mesh.h \
   -Dpd_mesh_self_crossing=old_self_crossing -c "$tmp/old_selfx.c" -o "$tmp/old.o"
cc -std=c11 -O2 -D_DEFAULT_SOURCE -Iinclude -Isrc tests/selfx/compare.c "$tmp/old.o" \
   build/opt/libposedrop.a -lgsl -lgslcblas -lm -pthread -o "$tmp/compare"
echo "# scripts/selfx-compare.sh $n $commit on $(git rev-parse --short HEAD)"
"$tmp/compare" "$n" parts/*.off parts/*.stl parts/*.obj parts/*/*.off 2>/dev/null
