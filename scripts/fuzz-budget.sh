#!/bin/sh
# Fuzzing as a measured budget: run every fuzz target for RUNS executions (default
# 10^7) or SECONDS seconds, print executions, executions per second and coverage per
# target, then minimise each corpus into fuzz/corpus/<target> (kept in the repository;
# conformance/tests/fuzz_corpus.rs replays it under a stable `cargo test`).
#
#   scripts/fuzz-budget.sh                      # 10^7 executions per target
#   RUNS=1000000 scripts/fuzz-budget.sh         # a smaller budget
#   SECONDS_PER_TARGET=600 scripts/fuzz-budget.sh
#   JOBS=2 scripts/fuzz-budget.sh               # targets in parallel
#
# Needs: rustup's nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
# A finding stops the script with exit 1; the crashing input is in fuzz/artifacts/.
set -eu
cd "$(dirname "$0")/.."
RUNS=${RUNS:-10000000}
JOBS=${JOBS:-1}
TARGETS=${TARGETS:-"request response datalink slave observer capture_wirelog capture_csv capture_sigrok report"}
LOGS=$(mktemp -d)
trap 'rm -rf "$LOGS"' EXIT

# Seeds from the golden vectors, added to whatever corpus there is.
cargo run -q -p hiperface-conformance --example fuzz_seeds >/dev/null
cd fuzz
# The model forbids `unsafe`: no sanitizer needed (-s none); optimised (-O) with
# overflow checks and debug assertions (-a): an overflow is a finding, as in `cargo test`.
cargo +nightly fuzz build -O -a -s none >/dev/null 2>&1 || cargo +nightly fuzz build -O -a -s none

budget() {
    if [ -n "${SECONDS_PER_TARGET:-}" ]; then
        echo "-max_total_time=$SECONDS_PER_TARGET"
    else
        echo "-runs=$RUNS"
    fi
}

run_one() {
    t=$1
    mkdir -p "corpus/$t"
    start=$(date +%s)
    if ! cargo +nightly fuzz run -O -a -s none "$t" "corpus/$t" -- "$(budget)" -print_final_stats=1 \
        >"$LOGS/$t.log" 2>&1; then
        echo "FINDING in $t: see fuzz/artifacts/$t and the log below" >&2
        tail -40 "$LOGS/$t.log" >&2
        return 1
    fi
    end=$(date +%s)
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$LOGS/$t.log" | grep -o '[0-9]*$' | tail -1)
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$LOGS/$t.log" | grep -o '[0-9]*$' | tail -1)
    cov=$(grep -o 'cov: [0-9]*' "$LOGS/$t.log" | tail -1 | grep -o '[0-9]*')
    ft=$(grep -o 'ft: [0-9]*' "$LOGS/$t.log" | tail -1 | grep -o '[0-9]*')
    echo "$t $execs $rate ${cov:-?} ${ft:-?} $((end - start))" >"$LOGS/$t.row"
}

failed=0
running=0
for t in $TARGETS; do
    run_one "$t" &
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait -n 2>/dev/null || wait || failed=1
        running=$((running - 1))
    fi
done
wait || failed=1
for t in $TARGETS; do [ -f "$LOGS/$t.row" ] || failed=1; done

echo "| target | executions | executions/s | coverage (edges) | features | wall s | corpus files (minimised) |"
echo "|---|---|---|---|---|---|---|"
for t in $TARGETS; do
    [ -f "$LOGS/$t.row" ] || continue
    # Minimise: keep only inputs that add coverage.
    cargo +nightly fuzz cmin -O -a -s none "$t" "corpus/$t" >/dev/null 2>&1 || true
    files=$(find "corpus/$t" -type f | wc -l)
    set -- $(cat "$LOGS/$t.row")
    echo "| $1 | $2 | $3 | $4 | $5 | $6 | $files |"
done
exit $failed
