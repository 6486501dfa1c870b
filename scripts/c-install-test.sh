#!/usr/bin/env bash
# The installed C library as a C project uses it (scripts/c-install.sh):
#   - installed into a temporary prefix: the layout (lib/libhiperface.{so,a},
#     include/hiperface/hiperface.h, lib/pkgconfig/hiperface.pc,
#     lib/cmake/hiperface/), the header the checked-in one;
#   - pkg-config alone: examples/c/tiny_encoder.c linked with the shared library
#     (--libs) and with the static one and its Libs.private, each run: PASSED;
#   - examples/cmake-firmware, copied out of the repository (it sees the prefix only),
#     configured with -DCMAKE_PREFIX_PATH=PREFIX, built and run by ctest, twice: the
#     library found with find_package(hiperface CONFIG) and with pkg_check_modules;
#   - and that the gate can fail: with the encoder's checksum slip
#     (-DTINY_ENCODER_DEFECT=ON) ctest fails, on 000:2.3.3; find_package refuses a
#     version the package is not compatible with, and a prefix with a file missing.
# Needs cargo-c, cmake (3.20 or later), pkg-config and a C compiler.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
for tool in cmake ctest pkg-config cc; do
    command -v "$tool" >/dev/null || { echo "$tool is not installed (apt-get install cmake pkg-config gcc)"; exit 2; }
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/hiperface-c-install.XXXXXX")
trap 'echo "(left for a look: $tmp)"' ERR
prefix=$tmp/prefix
log=$tmp/log
mkdir -p "$log"

echo "-- scripts/c-install.sh $prefix"
start=$(date +%s)
scripts/c-install.sh "$prefix"
echo "installed in $(( $(date +%s) - start )) s"
for f in lib/libhiperface.so lib/libhiperface.a include/hiperface/hiperface.h lib/pkgconfig/hiperface.pc \
    lib/cmake/hiperface/hiperfaceConfig.cmake lib/cmake/hiperface/hiperfaceConfigVersion.cmake; do
    [ -e "$prefix/$f" ] || { echo "PREFIX/$f was not installed"; find "$prefix"; exit 1; }
done
(cd "$prefix" && find . -type f -o -type l | sort | while read -r f; do
    if [ -L "$f" ]; then echo "  $f -> $(readlink "$f")"; else echo "  $f $(stat -c %s "$f") bytes"; fi
done)
cmp ffi/include/hiperface.h "$prefix/include/hiperface/hiperface.h" || { echo "the installed header is not ffi/include/hiperface.h"; exit 1; }
cat "$prefix/lib/pkgconfig/hiperface.pc"

echo "-- pkg-config alone: the shared library, then the static one with Libs.private"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
# shellcheck disable=SC2046 # pkg-config's output is words
cc -std=c11 -Wall -Wextra -Werror $(pkg-config --cflags hiperface) -o "$tmp/tiny_shared" \
    examples/c/tiny_encoder.c $(pkg-config --libs hiperface)
LD_LIBRARY_PATH=$(pkg-config --variable=libdir hiperface) "$tmp/tiny_shared" > "$log/pkg-shared.txt"
grep -q "^PASSED$" "$log/pkg-shared.txt" || { cat "$log/pkg-shared.txt"; echo "not PASSED"; exit 1; }
# The static library and what it needs (Libs.private), not -lhiperface (the .so).
# (The command of docs/src/from-c.md.)
static_libs=$(pkg-config --static --libs-only-l hiperface | sed 's/-lhiperface//')
# shellcheck disable=SC2046,SC2086
cc -std=c11 -Wall -Wextra -Werror $(pkg-config --cflags hiperface) -o "$tmp/tiny_static" \
    examples/c/tiny_encoder.c "$(pkg-config --variable=libdir hiperface)/libhiperface.a" $static_libs
if readelf -d "$tmp/tiny_static" | grep -q "libhiperface"; then echo "the static link needs libhiperface.so"; exit 1; fi
"$tmp/tiny_static" > "$log/pkg-static.txt"
grep -q "^PASSED$" "$log/pkg-static.txt" || { cat "$log/pkg-static.txt"; echo "not PASSED"; exit 1; }
echo "PASSED both (static link with: $static_libs)"

# The CMake project outside the repository: it and the encoder it compiles, copied.
src=$tmp/src
mkdir -p "$src/c"
cp -r examples/cmake-firmware "$src/"
cp examples/c/tiny_encoder.c "$src/c/"
for from in config pkg-config; do
    echo "-- examples/cmake-firmware with the library from $from: configure, build, ctest"
    build=$tmp/build-$from
    cmake -S "$src/cmake-firmware" -B "$build" -DCMAKE_PREFIX_PATH="$prefix" -DHIPERFACE_FROM="$from" \
        > "$log/configure-$from.txt" || { cat "$log/configure-$from.txt"; exit 1; }
    cmake --build "$build" > "$log/build-$from.txt" || { cat "$log/build-$from.txt"; exit 1; }
    ctest --test-dir "$build" --output-on-failure
    grep -q "<testcase" "$build/certify_encoder.junit.xml" || { echo "no JUnit test cases written"; exit 1; }
    # hiperface::hiperface is the static library, hiperface::shared and pkg-config's -l the shared one.
    needs_so=$(readelf -d "$build/certify_encoder" | grep -c "NEEDED.*libhiperface" || true)
    if [ "$from" = config ]; then
        [ "$needs_so" -eq 0 ] || { echo "hiperface::hiperface linked the shared library"; exit 1; }
        readelf -d "$build/certify_encoder_shared" | grep -q "NEEDED.*libhiperface.so" \
            || { echo "hiperface::shared did not link the shared library"; exit 1; }
    else
        [ "$needs_so" -eq 1 ] || { echo "pkg-config's target did not link the shared library"; exit 1; }
    fi
    # Nothing of the repository: the include path and the library are the prefix's.
    if grep -rq -- "$repo" "$build/CMakeFiles/certify_encoder.dir/flags.make" "$build/CMakeFiles/certify_encoder.dir/link.txt"; then
        echo "the build used files of the repository"; exit 1
    fi
done

echo "-- the gate can fail: the encoder with its checksum slip (expected: ctest fails, on 000:2.3.3)"
build=$tmp/build-defect
cmake -S "$src/cmake-firmware" -B "$build" -DCMAKE_PREFIX_PATH="$prefix" -DTINY_ENCODER_DEFECT=ON > "$log/configure-defect.txt"
cmake --build "$build" > "$log/build-defect.txt"
if ctest --test-dir "$build" --output-on-failure > "$log/ctest-defect.txt" 2>&1; then
    cat "$log/ctest-defect.txt"; echo "ctest passed with the defective encoder"; exit 1
fi
grep -E "tests passed|\*\*\*Failed" "$log/ctest-defect.txt"
echo "$(grep -c "FAIL \[000:2.3.3\]" "$log/ctest-defect.txt") findings FAIL [000:2.3.3], the first: $(grep -m1 "FAIL \[000:2.3.3\]" "$log/ctest-defect.txt")"
grep -q "FAIL \[000:2.3.3\]" "$log/ctest-defect.txt" || { echo "no FAIL on the checksum clause"; exit 1; }
grep -Eq "certify_encoder \.+\*+Failed" "$log/ctest-defect.txt" || { echo "the certify_encoder test did not fail"; exit 1; }

echo "-- find_package refuses what it must (expected: each configure fails)"
probe=$tmp/probe
mkdir -p "$probe"
refuses() { # refuses WHAT VERSION PREFIX
    printf 'cmake_minimum_required(VERSION 3.20)\nproject(probe NONE)\nfind_package(hiperface %s CONFIG REQUIRED)\n' "$2" \
        > "$probe/CMakeLists.txt"
    rm -rf "$probe/build"
    if cmake -S "$probe" -B "$probe/build" -DCMAKE_PREFIX_PATH="$3" > "$log/probe.txt" 2>&1; then
        cat "$log/probe.txt"; echo "find_package(hiperface $2) accepted $1"; exit 1
    fi
    echo "refused: $1"
}
version=$(pkg-config --modversion hiperface)
accepts() {
    printf 'cmake_minimum_required(VERSION 3.20)\nproject(probe NONE)\nfind_package(hiperface %s CONFIG REQUIRED)\n' "$1" \
        > "$probe/CMakeLists.txt"
    rm -rf "$probe/build"
    cmake -S "$probe" -B "$probe/build" -DCMAKE_PREFIX_PATH="$prefix" > "$log/probe.txt" 2>&1 \
        || { cat "$log/probe.txt"; echo "find_package(hiperface $1) refused version $version"; exit 1; }
}
accepts "$version"
accepts "${version%.*}"
accepts "0.0...<9"
refuses "version $version for a request of 1.0" 1.0 "$prefix"
refuses "version $version for a request of 0.2 (0.x: the minor version breaks)" 0.2 "$prefix"
cp -a "$prefix" "$tmp/broken"
rm "$tmp/broken/lib/libhiperface.a"
refuses "a prefix without libhiperface.a" "" "$tmp/broken"
grep -q "libhiperface.a is missing" "$log/probe.txt" || { cat "$log/probe.txt"; echo "not refused for the missing file"; exit 1; }

rm -rf "$tmp"
echo "C install passed"
