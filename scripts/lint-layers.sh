#!/bin/sh
# Fails when a file under src/ includes a header of a layer above its own, or
# of a sibling layer it does not build on. The layers, lowest first; a folder
# may include its own headers, the public API and those of the folders
# listed after it in LOWER. (make lint; docs/development.md)
set -eu
cd "$(dirname "$0")/.."

[ $# -eq 0 ] || { echo "lint-layers.sh: takes no arguments (it checks every file under src/)" >&2; exit 2; }
lower() {
    case "$1" in
    base)      echo "" ;;
    mesh)      echo "base" ;;
    hull)      echo "base" ;;
    part)      echo "base mesh hull" ;;
    static)    echo "base hull part" ;;
    symmetry)  echo "base hull part static" ;;
    dynamics)  echo "base hull part" ;;
    impact)    echo "base" ;;
    settle)    echo "base hull part static dynamics" ;;
    contact)   echo "base hull part dynamics settle" ;;
    engines)   echo "base hull part dynamics" ;;
    sim)       echo "base mesh hull part static symmetry dynamics impact settle contact engines" ;;
    fit)       echo "base" ;; # the calibration: the public API (drops, pose classes), base's GSL door
    design)    echo "base static" ;; # changes to the part: the public API, the static estimators' derivatives
    viz)       echo "base" ;; # the pictures: the public API, base's helpers
    cli)       echo "base viz" ;; # the public API, base/number.h (linked in directly), the pictures
    *)         echo "?" ;;
    esac
}

bad=0
for f in $(find src -name '*.c' -o -name '*.h' -o -name '*.cpp' | sort); do
    layer=$(echo "$f" | cut -d/ -f2)
    allowed=$(lower "$layer")
    if [ "$allowed" = "?" ]; then
        echo "$f: folder '$layer' is not in the layer table of $0"
        bad=1
        continue
    fi
    for inc in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f"); do
        dir=${inc%%/*}
        [ "$dir" = "$inc" ] && { echo "$f: includes \"$inc\" without its folder"; bad=1; continue; }
        [ "$dir" = posedrop ] || [ "$dir" = "$layer" ] && continue
        case " $allowed " in
        *" $dir "*) ;;
        *) echo "$f: layer '$layer' includes \"$inc\" from '$dir', which is not below it"; bad=1 ;;
        esac
    done
done
[ $bad -eq 0 ] && echo "lint: layers clean"
exit $bad
