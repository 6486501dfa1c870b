#!/usr/bin/env bash
# Every Kani harness of the proofs crate, one at a time, with a time limit: prints a
# table (harness, result, its limit, seconds, peak memory) and exits 1 unless every
# harness is VERIFICATION SUCCESSFUL within its limit. A harness with no verdict
# within its limit is a failure, unless scripts/kani-budget.txt lists it as over the
# budget, with the reason; that file also gives the harnesses whose limit is not the
# default, each with the reason (lines `harness seconds reason` and `harness over
# reason`).
#
#   scripts/kani.sh                       every harness, 300 s each (or its own limit)
#   LIMIT=60 scripts/kani.sh checksum     the harnesses named (exactly), 60 s each
#                                         (or their own limit)
#   MEM_GB=8 scripts/kani.sh              address space per harness (default 8 GB: a
#                                         harness that needs more is out of budget)
#   scripts/kani.sh --false-assertion inductive_read_counter
#                                         with a claim every command breaks added to the
#                                         whole step (`cfg(false_assertion)`, see
#                                         proofs/src/inductive.rs; the three
#                                         `field_memory_*` have claims of their own): each
#                                         harness named must FAIL on its claim; the exit
#                                         status says whether all did
#
# Kani is installed the ordinary way (`cargo install --locked kani-verifier && cargo
# kani setup`); without it this script says so and exits 0 (the `cargo test` twins of
# every harness still run in CI).
#
# Kani 0.63 ships CBMC 6.6, which reads a field of one enum variant wrongly when
# another variant holds an array of more than 64 elements (model-checking/kani#2416,
# fixed with CBMC 6.8 in Kani 0.66): `Response::Data` holds 128 bytes, so
# `response_decoder` failed on replies that decode and re-encode correctly. CBMC
# models arrays up to --max-field-sensitivity-array-size elements field by field, where
# the bug does not arise; 136 covers the largest array a reply or request is built in
# (a frame, 135 bytes), and no more: the slave's data field table (255 statuses, 4080
# bytes of memory) stays one array, as field-by-field it multiplies the work of every
# copy of the slave. docs/src/design.md, "Kani" has the minimal reproduction.
set -uo pipefail
cd "$(dirname "$0")/.."
FALSE_ASSERTION=
if [ "${1:-}" = --false-assertion ]; then
    FALSE_ASSERTION=1
    shift
    [ $# -gt 0 ] || { echo "kani.sh --false-assertion: name the whole-step harnesses"; exit 2; }
    # Its own build directory: the codegen of the harnesses as they are stays.
    export RUSTFLAGS="${RUSTFLAGS:+$RUSTFLAGS }--cfg false_assertion" CARGO_TARGET_DIR=target/kani-false
fi
LIMIT=${LIMIT:-300}
MEM_GB=${MEM_GB:-8}
BUDGET=scripts/kani-budget.txt
# The budget file's entry for harness $1: "seconds reason" or "over reason" (empty if none).
budget_of() { awk -v h="$1" '$1 == h { $1 = ""; sub(/^ /, ""); print; exit }' "$BUDGET"; }
if ! cargo kani --version >/dev/null 2>&1; then
    echo "kani.sh: Kani is not installed (cargo install --locked kani-verifier && cargo kani setup); skipped"
    exit 0
fi
CBMC_ARGS=(--max-field-sensitivity-array-size 136)
# Kani's own options. Without assertion reachability checks: with them CBMC solves again
# for a witness of each reachable check after the first answer (the inductive harnesses:
# seven solver runs, 160 s, where the verdict took one), and what they add, that the
# harness's assertions are reached, is said by a `kani::cover!` where it is cheap (this
# script requires every cover SATISFIED) and by the twin under `cargo test` where it is
# not (the twin of an inductive harness fails unless most of its samples satisfy the
# harness's assumption, with the same function).
#
# The SAT solver: Kani's default is CaDiCaL, but Debian's CBMC is built without it and
# falls back to MiniSat. A harness that needs CaDiCaL says `#[kani::solver(cadical)]`
# (the whole-step harnesses: 31 s of solving where MiniSat took 51); where CBMC lacks
# it, this script runs the `cadical` program as an external solver for those harnesses
# (`--solver bin=cadical`). Not for all: run externally, CaDiCaL took 159 s for
# `request_round_trip_fixed` (MiniSat 84) and had no verdict for
# `request_round_trip_store_data` in 300 s (MiniSat 234).
#
# `-Z stubbing`: the whole-step harnesses of the data field commands replace the field
# memory's operations by stubs (`#[kani::stub]`; proofs/src/harnesses.rs, `field_memory_*`
# prove what the stubs assume). Harnesses without a stub are compiled as before.
#
# The codegen and every run take the same compile flags (KANI_ARGS, `-Z
# unstable-options -Z stubbing`): with any that differs the first run compiled the
# crate again (68 to 91 s counted as the first harness's).
KANI_ARGS=(--no-assertion-reach-checks -Z unstable-options -Z stubbing)
OUT=target/kani${FALSE_ASSERTION:+-false}
mkdir -p "$OUT"
echo 'int main(void) { int x; __CPROVER_assert(x != 1, "probe"); return 0; }' >"$OUT/solver-probe.c"
probe=$(cbmc "$OUT/solver-probe.c" --sat-solver cadical 2>&1 || true)
EXTERNAL_CADICAL=()
if grep -q "not available" <<<"$probe" && command -v cadical >/dev/null; then
    EXTERNAL_CADICAL=(--solver bin=cadical)
fi
# Every `#[kani::proof]` function of the proofs crate, in source order, each followed
# by " cadical" where it asks for CaDiCaL (`#[kani::solver(cadical)]`).
mapfile -t PROOFS < <(awk '/#\[kani::proof\]/ {p=1; c=0} p && /#\[kani::solver\(cadical\)\]/ {c=1} p && /fn [a-z_0-9]+\(/ {sub(/.*fn /,""); sub(/\(.*/,""); print $0 (c ? " cadical" : ""); p=0}' proofs/src/*.rs)
mapfile -t WANT_CADICAL < <(printf '%s\n' "${PROOFS[@]}" | awk '$2 == "cadical" {print $1}')
if [ $# -gt 0 ]; then
    HARNESSES=("$@")
else
    mapfile -t HARNESSES < <(printf '%s\n' "${PROOFS[@]}" | awk '{print $1}')
fi
echo "Kani: $(cargo kani --version 2>&1 | tail -1); CBMC: $(cbmc --version 2>&1 | head -1); ${KANI_ARGS[*]}; CaDiCaL for ${WANT_CADICAL[*]:-none}${EXTERNAL_CADICAL:+ (external)}; limit ${LIMIT} s per harness (the others' in $BUDGET) and ${MEM_GB} GB; $(date -u +%F)"
# Build once, so that each harness's time is its own verification.
start=$(date +%s)
cargo kani -p hiperface-proofs --only-codegen "${KANI_ARGS[@]}" >"$OUT/codegen.log" 2>&1 || { echo "codegen failed: $OUT/codegen.log"; exit 1; }
echo "codegen: $(($(date +%s) - start)) s"
printf '| %-22s | %-13s | %7s | %8s | %10s |\n|---|---|---|---|---|\n' harness result "limit s" seconds "peak MB"
status=0
over=()
for h in "${HARNESSES[@]}"; do
    log="$OUT/$h.log"
    read -r budget reason <<<"$(budget_of "$h")"
    limit=$LIMIT
    [[ "$budget" =~ ^[0-9]+$ ]] && limit=$budget
    solver=()
    for w in "${WANT_CADICAL[@]}"; do [ "$w" = "$h" ] && solver=("${EXTERNAL_CADICAL[@]}"); done
    (
        ulimit -v $((MEM_GB * 1024 * 1024))
        exec /usr/bin/time -f '%e %M' -o "$OUT/$h.time" timeout --signal=KILL "$limit" \
            cargo kani -p hiperface-proofs --exact --harness "harnesses::$h" "${KANI_ARGS[@]}" "${solver[@]}" \
            --cbmc-args "${CBMC_ARGS[@]}"
    ) >"$log" 2>&1
    rc=$?
    read -r secs kb < <(tail -1 "$OUT/$h.time" | grep -E '^[0-9.]+ [0-9]+$' || echo "? 0")
    if grep -qi 'out of memory\|std::bad_alloc' "$log"; then
        result="out of memory"
    elif grep -q 'Status: UNSATISFIABLE' "$log"; then
        # A cover no input reaches: the harness's assumptions leave nothing to check.
        result=VACUOUS
    elif grep -q 'VERIFICATION:- SUCCESSFUL' "$log" && [ $rc = 0 ]; then
        result=SUCCESSFUL
    elif grep -q 'VERIFICATION:- FAILED' "$log"; then
        result=FAILED
    elif [ $rc = 137 ] || [ $rc = 124 ]; then
        result="no verdict"
        kb=-1
    else
        result="error ($rc)"
    fi
    if [[ "$result" = "no verdict" || "$result" = "out of memory" ]] && [ "$budget" = over ]; then
        # Listed as over the budget, with the reason: reported, not a failure.
        result="no verdict (over budget)"
        over+=("$h: $reason")
    elif [ -n "$FALSE_ASSERTION" ]; then
        [ "$result" = FAILED ] && grep -q '^Failed Checks: .*false assertion: ' "$log" || status=1
    else
        [ "$result" = SUCCESSFUL ] || status=1
    fi
    mb=$([ "$kb" -ge 0 ] && echo $((kb / 1024)) || echo "-")
    printf '| %-22s | %-13s | %7s | %8s | %10s |\n' "$h" "$result" "$limit" "$secs" "$mb"
done
for o in "${over[@]}"; do echo "over budget ($BUDGET): $o"; done
exit $status
