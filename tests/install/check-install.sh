#!/bin/sh
# make check-install (part of make check): posedrop as a user gets it.
# Installs into a temporary prefix and builds the library example
# (tests/install/example.c, the program README.md and docs/library.md show)
# with plain `pkg-config --cflags --libs posedrop`, the shared library; then
# against the static archive, and a Bullet run through libposedrop-bullet. Outputs are
# compared with the installed posedrop command on the same part and seed: the
# same library and seed give the same drops (exact). Also checks that the
# shared libraries export only the functions the installed headers declare,
# and that scripts/install-deps.sh asks apt-get for nothing when the
# dependencies are present.
#
# Environment: MAKE (the make that runs this, so the install is built with
# the caller's switches), CC, EXAMPLE_FLAGS (compile and link flags the
# build's own programs use: the sanitizers under SANITIZE=1, whose runtime
# must come first in a program loading a sanitized library).
# Prints one line per failed check and "check-install: N passed, N failed";
# exits non-zero when a check failed.
set -u
cd "$(dirname "$0")/../.."
MAKE=${MAKE:-make}
CC=${CC:-cc}
EXAMPLE_FLAGS=${EXAMPLE_FLAGS:-}
PART=parts/block.stl
DROPS=200
BULLET_DROPS=20

passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL check-install: $*"; }
check() { # description command...
    what=$1
    shift
    if "$@"; then ok; else fail "$what"; fi
}
finish() {
    echo "check-install: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
    exit $?
}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/posedrop-install.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

if ! $MAKE --no-print-directory install PREFIX="$prefix" >"$tmp/install.log" 2>&1; then
    cat "$tmp/install.log"
    fail "make install PREFIX=$prefix"
    finish
fi
ok

# The program docs/library.md shows is the one built here; README.md shows
# lines of it.
awk '/^## Example/ { e = 1 } e && /^```c$/ { p = 1; next } p && /^```$/ { exit } p' \
    docs/library.md >"$tmp/doc.c"
sed -n '/^#include/,$p' tests/install/example.c >"$tmp/example-body.c"
check "docs/library.md's example is tests/install/example.c" \
    sh -c "test -s '$tmp/doc.c' && cmp -s '$tmp/doc.c' '$tmp/example-body.c'"
awk '/^## Library/ { e = 1 } e && /^```c$/ { p = 1; next } p && /^```$/ { exit } p' \
    README.md >"$tmp/readme.c"
check "README.md's excerpt is lines of tests/install/example.c" \
    sh -c "test -s '$tmp/readme.c' && grep -Fxvf '$tmp/example-body.c' '$tmp/readme.c' | \
           { ! grep -q .; }"
check "make install put LICENSE and NOTICE in share/doc/posedrop" \
    test -s "$prefix/share/doc/posedrop/LICENSE" -a -s "$prefix/share/doc/posedrop/NOTICE"

export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
version=$(sed -n 's/^.define PD_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)$/\2/p' \
          include/posedrop/version.h | paste -sd.)
check "pkg-config --modversion posedrop is $version" \
    test "$(pkg-config --modversion posedrop 2>&1)" = "$version"

# The shared library, linked as the documentation says.
flags=$(pkg-config --cflags --libs posedrop) || fail "pkg-config --cflags --libs posedrop"
# shellcheck disable=SC2086
if ! $CC $EXAMPLE_FLAGS -o "$tmp/example" tests/install/example.c $flags 2>"$tmp/cc.log"; then
    cat "$tmp/cc.log"
    fail "cc example.c \$(pkg-config --cflags --libs posedrop)"
    finish
fi
ok
needed=$(readelf -d "$tmp/example" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
check "the example needs libposedrop.so.${version%%.*}" \
    sh -c "echo '$needed' | grep -qx 'libposedrop.so.${version%%.*}'"
check "the example needs neither Bullet nor the C++ runtime itself" \
    sh -c "! echo '$needed' | grep -q -e Bullet -e 'libstdc++'"

# The reference: the installed command, same part, drops and (default) seed.
"$prefix/bin/posedrop" -n $DROPS $PART >"$tmp/cli.csv" 2>"$tmp/cli.err" ||
    fail "posedrop -n $DROPS $PART: $(cat "$tmp/cli.err")"
columns() { # file: pose,p_qs,p_pqs,count,p found by name in the header
    awk -F, '/^#/ { next }
        !h { for (i = 1; i <= NF; i++) c[$i] = i; h = 1; next }
        { print $c["pose"] "," $c["p_qs"] "," $c["p_pqs"] "," $c["count"] "," $c["p"] }' "$1"
}
columns "$tmp/cli.csv" >"$tmp/cli.cols"
check "the command printed poses" test -s "$tmp/cli.cols"

same_as_cli() { # label program: its output's columns equal the command's
    if ! LD_LIBRARY_PATH="$prefix/lib" "$2" $PART $DROPS >"$tmp/$1.csv" 2>"$tmp/$1.err"; then
        fail "$1 $PART $DROPS: $(cat "$tmp/$1.err")"
        return
    fi
    ok
    check "$1 prints the version it runs with ($version)" \
        grep -qx "# posedrop $version" "$tmp/$1.csv"
    columns "$tmp/$1.csv" >"$tmp/$1.cols"
    # Exact: one library, one seed, the same drops (posedrop's determinism).
    if cmp -s "$tmp/$1.cols" "$tmp/cli.cols"; then ok; else
        fail "$1's poses differ from the command's:"
        diff "$tmp/$1.cols" "$tmp/cli.cols" | head -10
    fi
    # QS probabilities sum to 1: 10 significant digits printed per pose.
    check "$1's p_qs sum to 1 within 1e-8" awk -F, -v n=0 \
        '{ s += $2; n++ } END { d = s - 1; exit !(n > 0 && d < 1e-8 && d > -1e-8) }' "$tmp/$1.cols"
}
same_as_cli example "$tmp/example"

# The static archive: named with -Bstatic, the dependencies from --static;
# --as-needed drops the shared library the second -lposedrop would add.
# shellcheck disable=SC2046,SC2086
if $CC $EXAMPLE_FLAGS -o "$tmp/example-static" tests/install/example.c \
    $(pkg-config --cflags posedrop) -Wl,--as-needed -Wl,-Bstatic -lposedrop -Wl,-Bdynamic \
    $(pkg-config --static --libs posedrop) 2>"$tmp/cc.log"; then
    ok
    check "the static example does not need libposedrop.so" \
        sh -c "! readelf -d '$tmp/example-static' | grep -q 'libposedrop'"
    same_as_cli example-static "$tmp/example-static"
else
    cat "$tmp/cc.log"
    fail "cc example.c with libposedrop.a"
fi

# Bullet through its own library, from a C program linked by the C compiler.
cat >"$tmp/bullet.c" <<'EOF'
#include <stdio.h>
#include <posedrop/posedrop.h>

int main(int argc, char **argv)
{
    (void)argc;
    pd_diag diag;
    pd_diag_init(&diag);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = PD_ENGINE_BULLET;
    o.ndrops = 20;
    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    pd_sim_result *drops = NULL;
    pd_status st = PD_OK;
#ifndef NO_REGISTER
    st = pd_bullet_register();
#endif
    if (st == PD_OK)
        st = pd_mesh_read(argv[1], NULL, &mesh, &diag);
    if (st == PD_OK)
        st = pd_part_build(mesh, NULL, &part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(part, NULL, &poses, &diag);
    if (st == PD_OK)
        st = pd_sim_run(part, poses, NULL, &o, &drops, &diag);
    if (st == PD_OK)
        for (int i = 0; i < poses->nposes; i++)
            printf("%d,%ld\n", i + 1, drops->count[i]);
    else
        fprintf(stderr, "%s: %s\n", pd_status_str(st), diag.message);
    pd_sim_result_free(drops);
    pd_static_result_free(poses);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return st != PD_OK;
}
EOF
# shellcheck disable=SC2046,SC2086
if $CC $EXAMPLE_FLAGS -o "$tmp/bullet" "$tmp/bullet.c" $(pkg-config --cflags --libs posedrop-bullet) \
    2>"$tmp/cc.log"; then
    ok
    if LD_LIBRARY_PATH="$prefix/lib" "$tmp/bullet" $PART >"$tmp/bullet.cols" 2>"$tmp/bullet.err"; then
        ok
        "$prefix/bin/posedrop" --engine bullet -n $BULLET_DROPS $PART 2>/dev/null |
            awk -F, '!h { for (i = 1; i <= NF; i++) c[$i] = i; h = 1; next }
                { print $c["pose"] "," $c["count"] }' >"$tmp/bullet-cli.cols"
        check "Bullet's counts from the library equal the command's (exact, same seed)" \
            cmp -s "$tmp/bullet.cols" "$tmp/bullet-cli.cols"
    else
        fail "the Bullet example: $(cat "$tmp/bullet.err")"
    fi
else
    cat "$tmp/cc.log"
    fail "cc bullet.c \$(pkg-config --cflags --libs posedrop-bullet)"
fi
# The same program without libposedrop-bullet: a status that says what to
# link, not a crash.
# shellcheck disable=SC2046,SC2086
if $CC $EXAMPLE_FLAGS -DNO_REGISTER -o "$tmp/no-bullet" "$tmp/bullet.c" \
    $(pkg-config --cflags --libs posedrop) 2>"$tmp/cc.log"; then
    LD_LIBRARY_PATH="$prefix/lib" "$tmp/no-bullet" $PART >"$tmp/no-bullet.out" 2>"$tmp/no-bullet.err"
    code=$?
    check "Bullet without libposedrop-bullet fails with status 1, not a crash (got $code)" \
        test "$code" -eq 1
    check "... saying: not available, link libposedrop-bullet" \
        sh -c "grep -q 'not available in this program' '$tmp/no-bullet.err' &&
               grep -q 'libposedrop-bullet' '$tmp/no-bullet.err' && test ! -s '$tmp/no-bullet.out'"
else
    cat "$tmp/cc.log"
    fail "cc bullet.c -DNO_REGISTER \$(pkg-config --cflags --libs posedrop)"
fi

# Each installed header compiles on its own, as C11 and as C++ (the cancel
# flag is std::atomic<int> there), also when wrapped in extern "C" (the
# typedef: a file of macros alone would be an empty translation unit).
CXX=${CXX:-c++}
alone=0
for h in "$prefix"/include/posedrop/*.h; do
    name=posedrop/$(basename "$h")
    printf '#include <%s>\ntypedef int not_empty;\n' "$name" >"$tmp/alone.c"
    $CC -std=c11 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$prefix/include" "$tmp/alone.c" \
        2>"$tmp/alone.log" || { alone=1; cat "$tmp/alone.log"; }
    printf 'extern "C" {\n#include <%s>\n}\n' "$name" >"$tmp/alone.cpp"
    $CXX -std=c++17 -Wall -Wextra -Werror -fsyntax-only -I"$prefix/include" "$tmp/alone.cpp" \
        2>"$tmp/alone.log" || { alone=1; cat "$tmp/alone.log"; }
done
check "every installed header compiles alone as C11 and as C++17" test $alone -eq 0
cat >"$tmp/cancel.cpp" <<'EOF'
#include <atomic>
#include <posedrop/posedrop.h>
int main()
{
    static std::atomic<int> stop(1);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.cancel = &stop;
    return o.cancel->load() == 1 ? 0 : 1;
}
EOF
# shellcheck disable=SC2086
if $CXX $EXAMPLE_FLAGS -std=c++17 -o "$tmp/cancel" "$tmp/cancel.cpp" \
    $(pkg-config --cflags --libs posedrop) 2>"$tmp/cc.log" &&
    LD_LIBRARY_PATH="$prefix/lib" "$tmp/cancel"; then
    ok
else
    cat "$tmp/cc.log"
    fail "a C++ program pointing the cancel flag at a std::atomic<int>"
fi

# Exported symbols: exactly the PD_API functions of the installed headers,
# pd_bullet_register in libposedrop-bullet, every other one in libposedrop.
sed -n 's/^PD_API [^(]*[ *]\(pd_[a-z0-9_]*\)(.*/\1/p' "$prefix"/include/posedrop/*.h | sort >"$tmp/api"
exported() { nm -D --defined-only "$1" | awk '$2 ~ /^[TtWiDdBbRr]$/ { print $3 }' | sort; }
exported "$prefix/lib/libposedrop.so" >"$tmp/exported"
exported "$prefix/lib/libposedrop-bullet.so" >"$tmp/exported-bullet"
grep -vx pd_bullet_register "$tmp/api" >"$tmp/api-core"
if cmp -s "$tmp/exported" "$tmp/api-core"; then ok; else
    fail "libposedrop.so exports other than the API (< exported, > declared):"
    diff "$tmp/exported" "$tmp/api-core" | head -10
fi
check "libposedrop-bullet.so exports pd_bullet_register only" \
    test "$(cat "$tmp/exported-bullet")" = pd_bullet_register
check "the headers declare at least 30 API functions (the sed found them)" \
    test "$(wc -l <"$tmp/api")" -ge 30

# install-deps.sh with everything present: no sudo, no apt-get. Stand-ins
# first on PATH record any call.
mkdir "$tmp/bin"
for tool in sudo apt-get; do
    printf '#!/bin/sh\necho "%s $*" >>"%s/calls"\n' "$tool" "$tmp" >"$tmp/bin/$tool"
    chmod +x "$tmp/bin/$tool"
done
PATH="$tmp/bin:$PATH" scripts/install-deps.sh >"$tmp/deps.log" 2>&1 ||
    fail "scripts/install-deps.sh: $(cat "$tmp/deps.log")"
if [ -e "$tmp/calls" ]; then
    fail "install-deps.sh ran, with the dependencies present: $(cat "$tmp/calls")"
else
    ok
fi
check "install-deps.sh is silent when nothing is missing" test ! -s "$tmp/deps.log"

finish
