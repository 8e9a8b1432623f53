#!/bin/sh
# Installs the Debian packages posedrop builds and tests with, when pkg-config
# (or, for the reference hull, the qhull command) cannot find them, and any
# further packages named as arguments that are not installed.
# Quiet and quick when everything is present. Uses sudo only when not root.
set -eu

missing=""
command -v pkg-config >/dev/null 2>&1 || missing="pkg-config"
check_pc() { # module package
    if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists "$1"; then
        missing="$missing $2"
    fi
}
check_pc gsl libgsl-dev
check_pc ode libode-dev
check_pc ccd libccd-dev
check_pc bullet libbullet-dev
check_pc qhull_r libqhull-dev
command -v qconvex >/dev/null 2>&1 || missing="$missing qhull-bin"
# A JSON parser for the test of --format json: Python's json module, or jq.
command -v python3 >/dev/null 2>&1 || command -v jq >/dev/null 2>&1 || missing="$missing jq"
# Packages a script asks for (e.g. gnuplot-nox for the cost-accuracy chart),
# or a group by its name: browser, what make check-browser renders with; mpi,
# OpenMPI's compiler wrappers and launcher (make MPI=1).
for arg in "$@"; do
    case "$arg" in
    python)
        # What `pip install ./python` builds with in a virtual environment
        # (docs/python.md), asked of python3 itself, which need not be Debian's.
        pkgs=""
        python3 -c 'import ensurepip, os, sys, sysconfig
sys.exit(not os.path.isfile(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' \
            2>/dev/null || pkgs="python3 python3-dev python3-venv"
        ;;
    browser) pkgs="chromium librsvg2-bin libxml2-utils fonts-dejavu-core python3" ;;
    mpi) pkgs="libopenmpi-dev openmpi-bin" ;;
    *[!a-z0-9+.-]* | [!a-z0-9]*)
        echo "install-deps.sh: '$arg' is not a Debian package name (nor python, browser or mpi)" >&2
        exit 2 ;;
    *) pkgs=$arg ;;
    esac
    for pkg in $pkgs; do
        dpkg -s "$pkg" >/dev/null 2>&1 || missing="$missing $pkg"
    done
done

[ -z "$missing" ] && exit 0

echo "posedrop: installing missing packages:$missing" >&2
if ! command -v apt-get >/dev/null 2>&1; then
    echo "posedrop: apt-get not found; install the equivalents of:$missing" >&2
    exit 1
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
        echo "posedrop: not root and no sudo; install as root:$missing" >&2
        exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing
