# args.sh: the command-line checks the bash scripts here share (sourced, not
# run). A bad argument is refused with one line on stderr naming the script
# and what was expected, exit status 2, before the script creates anything.
#
#   . "$(dirname "$0")/args.sh"; args_prog=NAME
#   -o) args_value "$@"; outdir=$2; shift 2 ;;

args_prog=${args_prog:-$(basename "$0")}

args_die() { # message
    echo "$args_prog: $1 (see $args_prog --help)" >&2
    exit 2
}

# OPTION VALUE...: OPTION has a value, and it does not look like another
# option (none of the scripts' values starts with '-').
args_value() {
    [ $# -ge 2 ] && [ -n "$2" ] && [ "${2#-}" = "$2" ] || args_die "$1 needs a value"
}

# OPTION VALUE: VALUE is a whole number of at least 1.
args_count() {
    case "$2" in
        '' | *[!0-9]* | 0 | 0*) args_die "$1: expected a whole number from 1, got '$2'" ;;
    esac
}

# FILE...: each exists and is a readable file (a part, a table).
args_files() {
    local f
    for f in "$@"; do
        case "$f" in
            -*) args_die "'$f' is not a file: options go before the files" ;;
        esac
        [ -f "$f" ] && [ -r "$f" ] || args_die "$f: no such readable file"
    done
}
