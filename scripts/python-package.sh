#!/usr/bin/env bash
# The Python package as a user gets it: build the wheel (maturin, abi3: one wheel for
# every CPython >= 3.9), install it into a fresh venv, run its tests (pytest; a bench
# against HX-1 over a pseudo-terminal with pyserial) and its benchmark.
# Needs python3 with venv and pip, PyPI for maturin, pytest and pyserial, and the
# release `hiperface` command (built here if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/python
rm -rf "$out/venv" "$out/wheels"
mkdir -p "$out"
python3 -m venv "$out/venv"
py="$out/venv/bin/python"
"$py" -m pip install -q --upgrade pip >/dev/null
"$py" -m pip install -q "maturin>=1.5,<2" "pytest>=7" "pyserial>=3.5"
[ -x target/release/hiperface ] || cargo build -q --release -p hiperface-conformance
(cd python && "../$out/venv/bin/maturin" build --release --quiet -o "../$out/wheels")
"$py" -m pip install -q "$out"/wheels/hiperface-*.whl
# Run from outside the source tree, so that the installed package is the one tested.
(cd "$out" && HIPERFACE_BIN="$PWD/../release/hiperface" "venv/bin/python" -m pytest -q ../../python/tests)
echo "-- bench (figures for the record, not a gate)"
"$py" python/benches/bench.py vectors 1
echo "Python package passed"
