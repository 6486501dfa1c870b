#!/usr/bin/env bash
# Build the Kani this project's proofs were checked with, on a Debian bookworm x86-64
# machine (this project's machine kind), from source, and put `cargo kani` on PATH:
#
#   scripts/build-kani.sh                       # clones N1ark/kani from GitHub
#   KANI_SRC=/path/to/kani.git scripts/build-kani.sh   # a clone or bare mirror you have
#   KANI_DIR=$HOME/kani scripts/build-kani.sh   # where it is built (default ~/kani-build)
#   BIN_DIR=/opt/bin scripts/build-kani.sh      # where `cargo-kani` goes (default ~/.cargo/bin)
#
# Then `scripts/kani.sh` runs the harnesses (docs/src/verification.md). Not part of CI:
# CI runs `scripts/kani.sh --ci` where `cargo kani` is already installed (one build
# takes about 15 minutes on two cores). What it does, and why each step:
#
# 1. Kani 0.63.0 as N1ark/kani has it at 37fb6345 (KANI_COMMIT): the release the
#    book's figures were measured with. Its `charon` submodule is empty there; the
#    compiler names it only as an optional dependency (feature llbc, off by default),
#    but cargo reads every path dependency's manifest: a stub crate stands in.
# 2. The nightly toolchain Kani pins (its rust-toolchain.toml), through rustup.
# 3. `cargo build-dev -- --release`: Kani's own build of its compiler, driver and
#    library.
# 4. CBMC 6.6.0 and MiniSat from Debian trixie (Kani 0.63 checks for CBMC 6.6;
#    bookworm has 5.12), unpacked beside the build with trixie's own C library (CBMC
#    6.6 needs glibc 2.38; bookworm's is 2.36) and run through small wrappers: nothing
#    of the system is replaced. CaDiCaL from bookworm, as an external solver for the
#    harnesses that ask for it (trixie's CBMC is built without it).
# 5. A `cargo-kani` wrapper in ~/.cargo/bin that puts the wrappers on PATH.
#
# It ends with `cargo kani --version` and the wall time.
set -euo pipefail
KANI_SRC=${KANI_SRC:-https://github.com/N1ark/kani}
KANI_COMMIT=${KANI_COMMIT:-37fb6345}
KANI_DIR=${KANI_DIR:-$HOME/kani-build}
BIN_DIR=${BIN_DIR:-$HOME/.cargo/bin}
started=$(date +%s)

say() { echo "== $*"; }

# 1. The source.
if [ ! -d "$KANI_DIR/.git" ]; then
    say "cloning $KANI_SRC into $KANI_DIR"
    git clone -q --no-checkout "$KANI_SRC" "$KANI_DIR"
fi
git -C "$KANI_DIR" -c advice.detachedHead=false checkout -q "$KANI_COMMIT"
say "Kani at $(git -C "$KANI_DIR" rev-parse --short=8 HEAD)"
mkdir -p "$KANI_DIR/charon/charon/src"
[ -f "$KANI_DIR/charon/charon/Cargo.toml" ] ||
    printf '[package]\nname = "charon"\nversion = "0.1.62"\nedition = "2021"\n\n[lib]\npath = "src/lib.rs"\n' \
        > "$KANI_DIR/charon/charon/Cargo.toml"
[ -f "$KANI_DIR/charon/charon/src/lib.rs" ] || : > "$KANI_DIR/charon/charon/src/lib.rs"

# 2. The toolchain it pins.
toolchain=$(sed -n 's/^channel = "\(.*\)"/\1/p' "$KANI_DIR/rust-toolchain.toml")
say "toolchain $toolchain"
rustup toolchain install "$toolchain" --profile minimal \
    --component llvm-tools --component rustc-dev --component rust-src --component rustfmt

# 3. Kani.
say "building Kani (cargo build-dev --release)"
(cd "$KANI_DIR" && CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-2} cargo "+$toolchain" build-dev -- --release)

# 4. CBMC and MiniSat from trixie, with trixie's C library, beside the build.
root="$KANI_DIR/cbmc-root"
if [ ! -x "$root/usr/bin/cbmc" ]; then
    say "CBMC 6.6.0 and MiniSat from Debian trixie into $root"
    apt_dir=$(mktemp -d)
    mkdir -p "$apt_dir/lists/partial" "$apt_dir/archives/partial" "$KANI_DIR/debs"
    printf 'Types: deb\nURIs: http://deb.debian.org/debian\nSuites: trixie\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
        > "$apt_dir/trixie.sources"
    apt_opts=(-o "Dir::Etc::SourceList=/dev/null" -o "Dir::Etc::SourceParts=$apt_dir"
        -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::Cache::Archives=$apt_dir/archives"
        -o "Debug::NoLocking=1")
    apt-get "${apt_opts[@]}" -qq update
    (cd "$KANI_DIR/debs" && apt-get "${apt_opts[@]}" -qq download \
        cbmc minisat libc6 libstdc++6 libgcc-s1)
    for deb in "$KANI_DIR"/debs/*.deb; do dpkg-deb -x "$deb" "$root"; done
    rm -rf "$apt_dir"
fi
mkdir -p "$KANI_DIR/bin"
for tool in cbmc goto-analyzer goto-cc goto-harness goto-inspect goto-instrument goto-synthesizer symtab2gb minisat; do
    cat > "$KANI_DIR/bin/$tool" <<EOF
#!/bin/sh
# $tool from Debian trixie, run with trixie's own C library (scripts/build-kani.sh).
R=$root
exec \$R/usr/lib/x86_64-linux-gnu/ld-linux-x86-64.so.2 --library-path \$R/usr/lib/x86_64-linux-gnu:\$R/usr/lib \$R/usr/bin/$tool "\$@"
EOF
    chmod +x "$KANI_DIR/bin/$tool"
done
command -v cadical >/dev/null || {
    say "CaDiCaL from Debian bookworm"
    apt-get install -y -qq cadical >/dev/null
}

# 5. `cargo kani`: never over one this script did not write (FORCE=1 to replace it).
mkdir -p "$BIN_DIR"
if [ -e "$BIN_DIR/cargo-kani" ] && ! grep -q 'scripts/build-kani.sh' "$BIN_DIR/cargo-kani" && [ "${FORCE:-0}" != 1 ]; then
    echo "$BIN_DIR/cargo-kani exists and is not this script's: left as it is (FORCE=1 replaces it;" \
        "or BIN_DIR=another/dir)" >&2
    exit 1
fi
cat > "$BIN_DIR/cargo-kani" <<EOF
#!/bin/bash
# cargo-kani from the build in $KANI_DIR (scripts/build-kani.sh), with CBMC 6.6.0 from
# Debian trixie on PATH.
PATH=$KANI_DIR/bin:\$PATH
export PATH
exec $KANI_DIR/scripts/cargo-kani "\$@"
EOF
chmod +x "$BIN_DIR/cargo-kani"
PATH="$BIN_DIR:$PATH" cargo kani --version
say "built in $(( $(date +%s) - started )) s"
