#!/usr/bin/env bash
# check.sh: every command README.md gives, as written (make check-readme;
# .ci/run calls it).
#
# Reads README.md's ```sh and ```python blocks (a line ending in a backslash
# continues on the next). The set-up and test commands (the first block's
# and those of "From Python") must be lines of .ci/run, and the Python
# example must be in it whole: CI runs them as written. Every other command
# runs here, from a scratch directory that links to the checkout's top-level
# files (so the outputs the commands write stay out of the checkout), and
# must exit 0. Also: README.md has at most 200 lines, its sample output is
# what the Quick start's command prints, and the shipped measured-counts
# files are what scripts/make-measured.sh makes of the paper's tables.
# A negative control first shows that a failing command is seen.
# Last line "N passed, N failed"; exit status 1 on a failure.
set -u
cd "$(dirname "$0")/../.."
top=$(pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. tests/support/check.sh

# FILE -> "SECTION<TAB>LANG<TAB>COMMAND" per command, SECTION "top" before
# the first "## " heading (a python block is one record, its lines joined
# by \n).
commands() {
    awk '
        BEGIN { section = "top" } # before the first heading
        /^## / { section = substr($0, 4) }
        /^```(sh|python)$/ && !lang { lang = substr($0, 4); next }
        /^```$/ && lang {
            if (lang == "python") print section "\tpython\t" py
            lang = ""; py = ""; next
        }
        lang == "python" { py = py (py == "" ? "" : "\\n") $0; next }
        lang == "sh" {
            line = $0
            if (cmd != "") { sub(/^ +/, "", line); line = " " line }
            cmd = cmd line
            if (cmd ~ /\\$/) { sub(/ *\\$/, "", cmd); next }
            sub(/[ \t]+#.*$/, "", cmd)
            print section "\tsh\t" cmd
            cmd = ""
        }' "$1"
}

# Runs the commands of FILE that CI does not, from DIR; says which failed.
run_commands() { # FILE DIR
    local section lang cmd n=0 fails=0
    while IFS=$'\t' read -r section lang cmd; do
        [ "$lang" = sh ] || continue
        case "$section" in top | "From Python") continue ;; esac
        n=$((n + 1))
        echo "check-readme: $cmd" >&2
        if ! (cd "$2" && bash -o pipefail -c "$cmd") > "$tmp/cmd.$n.out" 2> "$tmp/cmd.$n.err"; then
            echo "'$cmd' failed: $(tail -n 3 "$tmp/cmd.$n.err")"
            fails=$((fails + 1))
        fi
    done < <(commands "$1")
    return $((fails > 0))
}

# The scratch directory: the checkout's top-level entries, linked.
mkdir "$tmp/run"
for f in "$top"/* "$top"/.ci; do ln -s "$f" "$tmp/run/"; done

# Negative control: a command that fails is reported.
printf '# x\n\n## A\n\n```sh\ntrue\nfalse   # fails\n```\n' > "$tmp/control.md"
check '! run_commands "$tmp/control.md" "$tmp/run" > /dev/null 2>&1' "a failing command in a README is not seen"
check '[ "$(commands "$tmp/control.md" | wc -l)" -eq 2 ]' "the control's two commands are not both read"

lines=$(wc -l < README.md)
check '[ "$lines" -le 200 ]' "README.md has $lines lines, more than 200"

ncmd=$(commands README.md | wc -l)
check '[ "$ncmd" -ge 10 ]' "only $ncmd commands read from README.md"
while IFS=$'\t' read -r section lang cmd; do
    case "$section" in top | "From Python") ;; *) continue ;; esac
    if [ "$lang" = python ]; then
        block=$(printf '%b' "$cmd")
        check '[[ "$(cat .ci/run)" == *"$block"* ]]' "README's Python example is not in .ci/run as written"
    else
        check 'grep -qxF -- "$cmd" .ci/run' "README's '$cmd' is not a line of .ci/run"
    fi
done < <(commands README.md)

# The sample output under Quick start: the first rows of its command.
sample=$(awk '/^## / { q = $0 == "## Quick start" }
    /^```/ { if (b) exit; fence = !fence; b = q && fence && $0 == "```"; next }
    b && $0 != "..." { print }' README.md)
bin=build/opt/posedrop
actual=$("$bin" parts/cap.off 2>/dev/null | head -n "$(printf '%s\n' "$sample" | wc -l)")
check '[ -n "$sample" ] && [ "$sample" = "$actual" ]' "README's sample output is not what '$bin parts/cap.off' prints: $actual"

check 'scripts/make-measured.sh --check' "the shipped measured-counts files are not the paper's tables"

run_commands README.md "$tmp/run" > "$tmp/failures" 2> "$tmp/progress"
check '[ ! -s "$tmp/failures" ]' "$(cat "$tmp/failures")"

echo "check-readme: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
