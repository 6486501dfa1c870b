#!/usr/bin/env bash
# The C library installed as C users expect it, into PREFIX:
#   PREFIX/lib/libhiperface.so (and its versioned names), PREFIX/lib/libhiperface.a
#   PREFIX/include/hiperface/hiperface.h        the checked-in header (cbindgen's)
#   PREFIX/lib/pkgconfig/hiperface.pc           Libs.private: what the static library needs
#   PREFIX/lib/cmake/hiperface/hiperfaceConfig.cmake, hiperfaceConfigVersion.cmake
#                                               find_package(hiperface CONFIG): the
#                                               imported target hiperface::hiperface
# Built with the c-release profile (size-optimised, LTO; Cargo.toml) by cargo-c
# (`cargo cinstall`; its configuration: [package.metadata.capi] in ffi/Cargo.toml).
# Needs cargo-c: cargo install --locked cargo-c --version 0.10.24
# (0.10.24 is the newest release that builds with rustc 1.95).
#   scripts/c-install.sh PREFIX
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: $0 PREFIX" >&2; exit 2; }
mkdir -p "$1"
prefix=$(cd "$1" && pwd)
cd "$(dirname "$0")/.."
if ! cargo cinstall --version >/dev/null 2>&1; then
    echo "cargo-c is not installed: cargo install --locked cargo-c --version 0.10.24" >&2
    exit 2
fi
cargo cinstall --locked -p hiperface-ffi --profile c-release --prefix "$prefix" --libdir lib

# The installed header is the checked-in one, byte for byte.
cmp ffi/include/hiperface.h "$prefix/include/hiperface/hiperface.h"

# The CMake package, which cargo-c does not write: the static library's link
# dependencies are the pkg-config file's Libs.private (cargo-c's, from rustc's
# native-static-libs), so that both ways of finding the library link it alike.
pc="$prefix/lib/pkgconfig/hiperface.pc"
static_libs=$(sed -n 's/^Libs.private: *//p' "$pc")
[ -n "$static_libs" ] || { echo "$pc has no Libs.private" >&2; exit 1; }
cmake_libs=$(for l in $static_libs; do case "$l" in -l*) printf '%s;' "${l#-l}" ;; *) printf '%s;' "$l" ;; esac; done)
cmake_libs=${cmake_libs%;}
version=$(sed -n 's/^Version: *//p' "$pc")
pointer=$(getconf LONG_BIT)
mkdir -p "$prefix/lib/cmake/hiperface"
sed -e "s|@HIPERFACE_STATIC_LIBS@|$static_libs|" -e "s|@HIPERFACE_STATIC_LIBS_CMAKE@|$cmake_libs|" \
    ffi/cmake/hiperfaceConfig.cmake.in > "$prefix/lib/cmake/hiperface/hiperfaceConfig.cmake"
sed -e "s|@HIPERFACE_VERSION@|$version|" -e "s|@HIPERFACE_SIZEOF_VOID_P@|$((pointer / 8))|" \
    ffi/cmake/hiperfaceConfigVersion.cmake.in > "$prefix/lib/cmake/hiperface/hiperfaceConfigVersion.cmake"
echo "hiperface $version installed in $prefix"
