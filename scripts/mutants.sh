#!/usr/bin/env bash
# Mutation testing of the model with cargo-mutants (configuration: .cargo/mutants.toml:
# the model's and the proofs crate's tests, the `mutants` profile).
#   scripts/mutants.sh                  every mutant of model/src (hours on 2 cores)
#   scripts/mutants.sh --shard 3/16     one shard
#   scripts/mutants.sh --iterate        skip what an earlier run in mutants.out caught
#   scripts/mutants.sh --in-diff d.diff only mutants in a change
set -euo pipefail
cd "$(dirname "$0")/.."
command -v cargo-mutants >/dev/null 2>&1 || cargo install --locked cargo-mutants
exec cargo mutants -j "${JOBS:-2}" "$@"
