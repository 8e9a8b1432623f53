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

# POSEDROP WORD...: posedrop's options among the words, in every form it
# accepts (getopt_long's): a long name or any prefix that starts no other
# name (an exact name first), with its value as the next word or after '=';
# a letter, with its value as the next word or glued to it (-n100). The
# names are those POSEDROP --help lists, a value shown by an upper-case word
# after the name ("--units U", "-n N"). Sets opt_names[i] and opt_values[i]
# (each option by its full name, and its value, "" for a flag), opt_words
# (the words that make the options, as given) and other_words (the rest:
# part files, or words posedrop will say what it makes of).
args_posedrop() {
    local bin=$1 name meta w v i
    shift
    local -a words=("$@")
    declare -gA takes=()
    while read -r name meta; do
        case "$meta" in [A-Z]*) takes[$name]=1 ;; *) takes[$name]=0 ;; esac
    done < <("$bin" --help 2>/dev/null | sed -n 's/^  \(-[-a-zA-Z0-9]*\) *\([^ ]*\).*/\1 \2/p')
    [ ${#takes[@]} -gt 0 ] || args_die "$bin --help lists no options"
    opt_names=() opt_values=() opt_words=() other_words=()
    for ((i = 0; i < ${#words[@]}; i++)); do
        w=${words[$i]}
        case "$w" in
            --?*=*) args_resolve "${w%%=*}"; v=${w#*=}
                [ "${takes[$name]}" = 1 ] || args_die "option '$name' takes no value"
                opt_words+=("$w") ;;
            --?*) args_resolve "$w"; v=""; opt_words+=("$w")
                if [ "${takes[$name]}" = 1 ]; then
                    [ $((i + 1)) -lt ${#words[@]} ] || args_die "option '$name' needs a value"
                    i=$((i + 1)); v=${words[$i]}; opt_words+=("$v")
                fi ;;
            -[!-]?*) args_resolve "${w:0:2}"; v=${w:2}
                [ "${takes[$name]}" = 1 ] || args_die "option '$name' takes no value"
                opt_words+=("$w") ;;
            -[!-]) args_resolve "$w"; v=""; opt_words+=("$w")
                if [ "${takes[$name]}" = 1 ]; then
                    [ $((i + 1)) -lt ${#words[@]} ] || args_die "option '$name' needs a value"
                    i=$((i + 1)); v=${words[$i]}; opt_words+=("$v")
                fi ;;
            *) other_words+=("$w"); continue ;;
        esac
        opt_names+=("$name"); opt_values+=("$v")
    done
}

# WORD -> sets name: the option of posedrop's (args_posedrop's takes) it names.
args_resolve() {
    local w=$1 c m=()
    if [ -n "${takes[$w]+x}" ]; then name=$w; return; fi
    case "$w" in
        --?*)
            for c in "${!takes[@]}"; do
                case "$c" in "$w"*) m+=("$c") ;; esac
            done
            [ ${#m[@]} -gt 0 ] || args_die "unknown option '$w' for posedrop"
            [ ${#m[@]} -eq 1 ] ||
                args_die "option '$w' is the start of more than one of posedrop's options' names"
            name=${m[0]} ;;
        *) args_die "unknown option '$w' for posedrop" ;;
    esac
}
