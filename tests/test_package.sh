#!/usr/bin/env bash
# The installed package as outside users get it, static and shared: this build is installed into
# one scratch prefix, and the other kind (BUILD_SHARED_LIBS flipped, library and command only) is
# built from the same sources and installed into another. In each, the README's own lines, copied
# verbatim from README.md, build consumers that are then run:
#   - `cc app.c $(pkg-config --cflags --libs rsmooth)` and the rsmooth-io line (no --static, no
#     extra -l: a static install's .pc must name what its archives need);
#   - the README's find_package block (tests/package/CMakeLists.txt includes it), with a host that
#     defines CL_TARGET_OPENCL_VERSION 200 and calls clCreateCommandQueueWithProperties
#     (app_cl.c, -Werror); app_cl.c is also compiled through pkg-config's flags.
# The installed command starts from either prefix (--version, a smoothing with --device
# reference) with no LD_LIBRARY_PATH, and again after the shared prefix is moved elsewhere, where
# the moved .pc files still build the README's consumer.
# Usage: test_package.sh BUILD_DIR SOURCE_DIR [C_COMPILER] [WERROR] [SHARED (0/1)]
set -euo pipefail
build_dir=$(cd "$1" && pwd)
source_dir=$(cd "$2" && pwd)
compiler=${3:-cc}
werror=${4:-OFF}
this_shared=${5:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset LD_LIBRARY_PATH PKG_CONFIG_PATH CMAKE_PREFIX_PATH

fail() {
    echo "FAIL: $*" >&2
    exit 1
}

# --- the README's lines -----------------------------------------------------------------------
readme=$source_dir/README.md
mapfile -t pc_lines < <(grep -E '^cc app(_io)?\.c \$\(pkg-config --cflags --libs rsmooth(-io)?\)' "$readme")
[ ${#pc_lines[@]} -eq 2 ] ||
    fail "README.md: expected the 2 lines 'cc app.c \$(pkg-config ...)', found ${#pc_lines[@]}"
awk '/^```cmake$/ { inside = 1; next } inside && /^```$/ { exit } inside' "$readme" \
    >"$work/readme.cmake"
grep -q '^find_package(rsmooth' "$work/readme.cmake" ||
    fail "README.md: no \`\`\`cmake block with find_package(rsmooth ...)"
echo "README's pkg-config lines:"
printf '  %s\n' "${pc_lines[@]}"
echo "README's CMake lines:"
sed 's/^/  /' "$work/readme.cmake"

# A small mesh for the command.
cat >"$work/octahedron.obj" <<'EOF'
v 1 0 0
v -1 0 0
v 0 1 0
v 0 -1 0
v 0 0 1.1
v 0 0 -1
f 1 3 5
f 3 2 5
f 2 4 5
f 4 1 5
f 3 1 6
f 2 3 6
f 4 2 6
f 1 4 6
EOF

# The command in PREFIX starts and smooths, with no help from the environment.
check_command() { # PREFIX LABEL
    local out
    out=$(env -u LD_LIBRARY_PATH "$1/bin/rsmooth" --version) || fail "$2: $1/bin/rsmooth --version exited $?"
    echo "$2: bin/rsmooth --version: $out"
    rm -f "$work/smoothed.obj"
    env -u LD_LIBRARY_PATH "$1/bin/rsmooth" "$work/octahedron.obj" -o "$work/smoothed.obj" \
        --device reference >/dev/null 2>"$work/command.err" ||
        fail "$2: bin/rsmooth --device reference exited $?: $(cat "$work/command.err")"
    [ "$(grep -c '^v ' "$work/smoothed.obj")" -eq 6 ] || fail "$2: the smoothed mesh lost vertices"
    echo "$2: bin/rsmooth smoothed a mesh (--device reference)"
}

# The README's pkg-config lines, each in its own directory with its source as app.c / app_io.c.
check_pkg_config() { # PREFIX KIND LABEL
    local prefix=$1 kind=$2 label=$3 pcdir libdir line src dir
    pcdir=$(dirname "$(find "$prefix" -name rsmooth.pc | head -1)")
    libdir=$(dirname "$pcdir")
    [ -f "$pcdir/rsmooth-io.pc" ] || fail "$label: no rsmooth-io.pc beside rsmooth.pc"
    echo "$label: pkg-config --libs rsmooth-io: $(PKG_CONFIG_PATH=$pcdir pkg-config --libs rsmooth-io)"
    for line in "${pc_lines[@]}"; do
        src=$(sed -E 's/^cc ([a-z_]+\.c) .*/\1/' <<<"$line")
        dir=$work/$label-${src%.c}
        mkdir -p "$dir"
        cp "$source_dir/tests/package/$src" "$dir/"
        (cd "$dir" && PKG_CONFIG_PATH=$pcdir bash -eu -c "$line") ||
            fail "$label: the README's line failed: $line"
        if [ "$kind" = shared ]; then
            readelf -d "$dir/a.out" | grep -q "NEEDED.*librsmooth" ||
                fail "$label: $src does not use the shared library"
            LD_LIBRARY_PATH=$libdir "$dir/a.out" || fail "$label: $src built by '$line' failed"
        else
            ! readelf -d "$dir/a.out" | grep -q "NEEDED.*librsmooth" ||
                fail "$label: $src needs a shared librsmooth from a static install"
            "$dir/a.out" || fail "$label: $src built by '$line' failed"
        fi
    done
}

check_install() { # PREFIX KIND
    local prefix=$1 kind=$2 libdir cl_ok=0
    libdir=$(dirname "$(dirname "$(find "$prefix" -name rsmooth.pc | head -1)")")
    if [ "$kind" = shared ]; then
        ls "$libdir"/librsmooth.so.* "$libdir"/librsmooth_io.so.* >/dev/null ||
            fail "$kind: no shared libraries in $libdir"
        local soname
        soname=$(readelf -d "$libdir/librsmooth.so" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
        echo "$kind: soname $soname"
        local major minor
        major=$(sed -n 's/^#define RSMOOTH_VERSION_MAJOR \([0-9]*\).*/\1/p' "$prefix/include/rsmooth.h")
        minor=$(sed -n 's/^#define RSMOOTH_VERSION_MINOR \([0-9]*\).*/\1/p' "$prefix/include/rsmooth.h")
        if [ "$major" = 0 ]; then
            [ "$soname" = "librsmooth.so.0.$minor" ] || fail "$kind: soname $soname, not librsmooth.so.0.$minor"
        else
            [ "$soname" = "librsmooth.so.$major" ] || fail "$kind: soname $soname, not librsmooth.so.$major"
        fi
    else
        [ -f "$libdir/librsmooth.a" ] && [ -f "$libdir/librsmooth_io.a" ] ||
            fail "$kind: no static libraries in $libdir"
    fi
    check_command "$prefix" "$kind"
    check_pkg_config "$prefix" "$kind" "$kind"

    # rsmooth_cl.h with the host's OpenCL version, compiled through pkg-config's flags.
    PKG_CONFIG_PATH=$libdir/pkgconfig cc -std=c11 -Wall -Wextra -Werror -c \
        "$source_dir/tests/package/app_cl.c" -o "$work/$kind-app_cl.o" \
        $(PKG_CONFIG_PATH=$libdir/pkgconfig pkg-config --cflags rsmooth) ||
        fail "$kind: app_cl.c (CL_TARGET_OPENCL_VERSION 200) does not compile with rsmooth.pc's flags"
    echo "$kind: app_cl.c (OpenCL 2.0, rsmooth_cl.h) compiles with pkg-config's flags"

    # The README's find_package block.
    cmake -S "$source_dir/tests/package" -B "$work/$kind-cmake" -DCMAKE_PREFIX_PATH="$prefix" \
        -DRSMOOTH_README_CMAKE="$work/readme.cmake" >"$work/cmake.log" 2>&1 ||
        { cat "$work/cmake.log"; fail "$kind: the README's find_package block does not configure"; }
    cmake --build "$work/$kind-cmake" >"$work/cmake.log" 2>&1 ||
        { cat "$work/cmake.log"; fail "$kind: the README's find_package consumers do not build"; }
    "$work/$kind-cmake/app" || fail "$kind: find_package app failed"
    "$work/$kind-cmake/app_io" || fail "$kind: find_package app_io failed"
    if [ -x "$work/$kind-cmake/app_cl" ]; then
        "$work/$kind-cmake/app_cl" || fail "$kind: find_package app_cl failed"
    else
        echo "$kind: no OpenCL loader to link (FindOpenCL): app_cl compiled through pkg-config only"
    fi
}

# --- this build, and the other kind -----------------------------------------------------------
if [ "$this_shared" = 1 ]; then
    this=shared other=static other_flag=OFF
else
    this=static other=shared other_flag=ON
fi
cmake --install "$build_dir" --prefix "$work/$this" >/dev/null
echo "== $this install (this build) in $work/$this"
check_install "$work/$this" "$this"

echo "== $other install (built here: BUILD_SHARED_LIBS=$other_flag)"
cmake -S "$source_dir" -B "$work/build-$other" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_COMPILER="$compiler" -DBUILD_SHARED_LIBS=$other_flag -DRSMOOTH_BUILD_TESTS=OFF \
    -DRSMOOTH_WERROR="$werror" >"$work/other.log" 2>&1 ||
    { cat "$work/other.log"; fail "$other: configure failed"; }
cmake --build "$work/build-$other" -j 2 --target rsmooth_cli rsmooth_io >"$work/other.log" 2>&1 ||
    { cat "$work/other.log"; fail "$other: build failed"; }
cmake --install "$work/build-$other" --prefix "$work/$other" >/dev/null
check_install "$work/$other" "$other"

# --- the shared prefix moved ------------------------------------------------------------------
mkdir -p "$work/elsewhere"
mv "$work/shared" "$work/elsewhere/moved"
echo "== shared install moved to $work/elsewhere/moved"
check_command "$work/elsewhere/moved" "moved shared"
check_pkg_config "$work/elsewhere/moved" shared "moved-shared"
echo "installed package: static and shared, the README's pkg-config and find_package lines built and ran"
