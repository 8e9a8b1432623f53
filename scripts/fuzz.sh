#!/bin/sh
# fuzz.sh SECONDS TARGET...: runs each libFuzzer target built by make fuzz
# (build/fuzz/fuzz_TARGET) for SECONDS, from its seeds (parts/ and
# tests/fuzz/seeds/TARGET), keeping what it finds in build/fuzz/corpus/TARGET,
# and prints executions per second and in total per target. A crash (or a
# leak, a sanitizer report, a hang beyond 10 s) fails the run; its input is
# left in build/fuzz/ as crash-TARGET-*: copy it to tests/fuzz/regressions/
# TARGET/ so that make check replays it from then on.
set -eu
cd "$(dirname "$0")/.."
die() { echo "fuzz.sh: $1 (usage: scripts/fuzz.sh SECONDS TARGET...)" >&2; exit 2; }
[ $# -ge 2 ] || die "expected a number of seconds and at least one target"
case $1 in '' | *[!0-9]* | 0*) die "SECONDS: expected a whole number from 1, got '$1'" ;; esac
seconds=$1
shift
for t in "$@"; do
    [ -x "build/fuzz/fuzz_$t" ] || die "no target '$t' built in build/fuzz/ (make fuzz-build)"
done
status=0
for t in "$@"; do
    corpus=build/fuzz/corpus/$t
    mkdir -p "$corpus"
    seeds=""
    case $t in
    off) seeds="parts parts/canonical" ;;
    stl|obj|part) seeds="parts parts/canonical" ;;
    esac
    [ -d tests/fuzz/seeds/$t ] && seeds="$seeds tests/fuzz/seeds/$t"
    [ -d tests/fuzz/regressions/$t ] && seeds="$seeds tests/fuzz/regressions/$t"
    log=build/fuzz/$t.log
    # Inputs up to 64 KiB: larger than every seed, small enough to run fast.
    # shellcheck disable=SC2086
    if build/fuzz/fuzz_$t -max_total_time="$seconds" -max_len=65536 -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=build/fuzz/crash-$t- \
        "$corpus" $seeds >"$log" 2>&1; then
        result=ok
    else
        result=FAILED
        status=1
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    printf 'fuzz %-6s %s: %s executions in %s s, %s per second (log %s)\n' "$t" "$result" \
        "${runs:-?}" "$seconds" "${rate:-?}" "$log"
    [ "$result" = ok ] || grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -5
done
exit $status
