#!/bin/sh
# The binding's tests again with the extension and the library built with
# AddressSanitizer and UBSan, warnings as errors: the library from the
# archives of `make SANITIZE=1`, the extension compiled here into a temporary
# package that PYTHONPATH puts before the installed one. The sanitizer
# runtimes are preloaded, since the Python interpreter is not built with
# them; leak checking is off, as CPython keeps objects alive on purpose.
# Usage: python/check-sanitized.sh [PYTHON]  (default .venv/bin/python, with
# pytest and the test extras installed).
set -eu
cd "$(dirname "$0")/.."
py=${1:-.venv/bin/python}
cc=${CC:-cc}
make -j2 SANITIZE=1 build/opt-san/libposedrop.a build/opt-san/libposedrop-bullet.a
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/posedrop"
cp python/src/posedrop/*.py "$tmp/posedrop/"
include=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
suffix=$("$py" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# shellcheck disable=SC2046,SC2086
$cc -shared -fPIC -O1 -g -std=c11 -D_DEFAULT_SOURCE -Wall -Wextra -Werror \
    -Wno-missing-field-initializers -ffp-contract=off -pthread $san \
    -I"$include" -Iinclude python/ext/posedrop_module.c \
    build/opt-san/libposedrop-bullet.a build/opt-san/libposedrop.a \
    $(pkg-config --libs gsl ode ccd bullet) -lstdc++ -lm -o "$tmp/posedrop/_posedrop$suffix"
export LD_PRELOAD="$($cc -print-file-name=libasan.so) $($cc -print-file-name=libubsan.so)"
export ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export PYTHONPATH="$tmp"
"$py" -c 'import sys, posedrop._posedrop as m; sys.exit(not m.__file__.startswith(sys.argv[1]))' "$tmp"
"$py" -m pytest -q python/tests
