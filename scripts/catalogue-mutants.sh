#!/usr/bin/env bash
# What a PASS proves: the catalogue measured against defective encoders and masters
# (docs/src/verification.md, "What a PASS proves"). Builds the runner, checks that the
# mutants compiled in are cargo-mutants' own (its list of the same files), certifies
# every mutant of every family, prints the table and compares the survivors with
# mutants/survivors.toml: exit 1 on a survivor not listed or a listed one now told.
#   scripts/catalogue-mutants.sh                     everything (about 3 minutes on 2 cores)
#   scripts/catalogue-mutants.sh --family wire       one family (encoder, wire, master)
#   scripts/catalogue-mutants.sh --every 20          a sample
#   scripts/catalogue-mutants.sh --ids 12,40 --family encoder --verbose
# One mutant by hand: target/release/catalogue-mutants diff --ids 12 (beside the
# conformant encoder on random streams), list --family master, baseline.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p hiperface-mutants
if command -v cargo-mutants >/dev/null 2>&1; then
    target/release/catalogue-mutants cross-check
else
    echo "cargo-mutants is not installed: the cross-check with its list is skipped (cargo install --locked cargo-mutants)"
fi
exec target/release/catalogue-mutants run "$@"
