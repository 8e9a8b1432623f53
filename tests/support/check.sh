# check.sh: the counting checks of the shell tests (sourced, not run):
# check 'CONDITION' 'MESSAGE' evaluates the condition, counting it in
# passed or failed and printing "FAIL: MESSAGE" for a failure.
passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*"; }
check() { if eval "$1"; then ok; else bad "$2"; fi; }
