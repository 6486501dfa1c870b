#!/usr/bin/env bash
# Every Kani harness of the proofs crate, with a time limit each: prints a table
# (harness, result, its limit, seconds, peak memory) and exits 1 unless every harness
# run is VERIFICATION SUCCESSFUL within its limit. A harness with no verdict within its
# limit is a failure, unless scripts/kani-budget.txt lists it as over the budget, with
# the reason; that file also gives the harnesses whose limit is not the default and
# the long ones CI takes a share of, each with the reason (lines `harness seconds
# reason`, `harness over reason`, `pattern share reason`).
#
#   scripts/kani.sh                       every harness, 300 s each (or its own limit)
#   scripts/kani.sh --ci                  CI's run: every harness but those over the
#                                         budget, and of the long ones (`share`) one
#                                         share in SHARES, chosen by the commit
#                                         (SHARE=k to choose it); two at a time
#   LIMIT=60 scripts/kani.sh checksum     the harnesses named (exactly), 60 s each
#                                         (or their own limit)
#   MEM_GB=8 scripts/kani.sh              address space per CBMC (default 8 GB: a
#                                         harness that needs more is out of budget)
#   JOBS=2 scripts/kani.sh                harnesses verified two at a time (default 1)
#   scripts/kani.sh --false-assertion inductive_read_counter
#                                         with a claim every command breaks added to the
#                                         whole step (`cfg(false_assertion)`, see
#                                         proofs/src/inductive/; the three
#                                         `field_memory_*` have claims of their own): each
#                                         harness named must FAIL on its claim; the exit
#                                         status says whether all did
#
# Kani is installed the ordinary way (`cargo install --locked kani-verifier && cargo
# kani setup`); without it this script says so and exits 0 (the `cargo test` twins of
# every harness still run in CI).
#
# One `cargo kani` run verifies many harnesses: Kani links the goto program of every
# harness of the crate at each run (0.7 to 1.4 s each, 53 harnesses), whichever it
# verifies, so a run per harness cost 36 to 75 s of linking each (CI, 2026-11-29: the
# trivial harnesses took 44 to 53 s, and the whole set no longer fitted CI's time).
# Harnesses are grouped by solver, one run per group; Kani's own
# `--harness-timeout` stops a CBMC at the group's limit, `ulimit -v` bounds each CBMC's
# address space, and each harness's peak memory is sampled from /proc every 0.2 s (a
# harness done sooner shows "-"). The first run builds the crate (its time is the whole
# run's, not a harness's: the seconds are CBMC's own, as Kani measures them).
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
CI=
case "${1:-}" in
--false-assertion)
    FALSE_ASSERTION=1
    shift
    [ $# -gt 0 ] || { echo "kani.sh --false-assertion: name the whole-step harnesses"; exit 2; }
    # Its own build directory: the codegen of the harnesses as they are stays.
    export RUSTFLAGS="${RUSTFLAGS:+$RUSTFLAGS }--cfg false_assertion" CARGO_TARGET_DIR=target/kani-false
    ;;
--ci)
    CI=1
    shift
    JOBS=${JOBS:-2}
    ;;
esac
LIMIT=${LIMIT:-300}
MEM_GB=${MEM_GB:-8}
JOBS=${JOBS:-1}
SHARES=${SHARES:-9}
BUDGET=scripts/kani-budget.txt
# What the budget file says of harness $1, from every line whose pattern matches it:
# "<seconds or -> <over or share or -> <reason of the over line>".
budget_of() {
    local pattern kind reason limit=- over=- why=
    while read -r pattern kind reason; do
        [[ -z "$pattern" || "$pattern" == \#* ]] && continue
        # shellcheck disable=SC2053 # the pattern is a glob on purpose
        [[ "$1" == $pattern ]] || continue
        case "$kind" in
        over) over=over why=$reason ;;
        share) [ "$over" = over ] || over=share ;;
        *) [[ "$kind" =~ ^[0-9]+$ ]] && limit=$kind ;;
        esac
    done <"$BUDGET"
    echo "$limit $over $why"
}
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
# unstable-options -Z stubbing`) and the same build directory: with any that differs a
# run compiles the crate again (68 to 91 s).
TARGET_DIR=$(realpath -m "${CARGO_TARGET_DIR:-target}")
KANI_ARGS=(--no-assertion-reach-checks -Z unstable-options -Z stubbing --target-dir "$TARGET_DIR")
OUT=target/kani${FALSE_ASSERTION:+-false}
mkdir -p "$OUT"
# CBMC and the solvers as `cargo kani` runs them: the `cargo-kani` that
# scripts/build-kani.sh installs puts its own on PATH (its `PATH=` line), not the shell's.
if ! command -v cbmc >/dev/null && command -v cargo-kani >/dev/null; then
    wrapped=$(sed -n 's/^PATH=\(.*\):\$PATH$/\1/p' "$(command -v cargo-kani)" | head -1)
    [ -n "$wrapped" ] && PATH="$wrapped:$PATH"
fi
echo 'int main(void) { int x; __CPROVER_assert(x != 1, "probe"); return 0; }' >"$OUT/solver-probe.c"
probe=$(cbmc "$OUT/solver-probe.c" --sat-solver cadical 2>&1 || true)
EXTERNAL_CADICAL=
if grep -q "not available" <<<"$probe" && command -v cadical >/dev/null; then
    EXTERNAL_CADICAL=1
fi
# Every `#[kani::proof]` function of the proofs crate, in source order, each followed
# by " cadical" where it asks for CaDiCaL (`#[kani::solver(cadical)]`).
mapfile -t PROOFS < <(awk '/#\[kani::proof\]/ {p=1; c=0} p && /#\[kani::solver\(cadical\)\]/ {c=1} p && /fn [a-z_0-9]+\(/ {sub(/.*fn /,""); sub(/\(.*/,""); print $0 (c ? " cadical" : ""); p=0}' proofs/src/*.rs)
mapfile -t WANT_CADICAL < <(printf '%s\n' "${PROOFS[@]}" | awk '$2 == "cadical" {print $1}')
SKIPPED=()
if [ $# -gt 0 ]; then
    HARNESSES=("$@")
    known=" $(printf '%s ' "${PROOFS[@]%% *}")"
    for h in "${HARNESSES[@]}"; do
        [[ "$known" == *" $h "* ]] || { echo "kani.sh: no harness $h in proofs/src"; exit 2; }
    done
else
    mapfile -t HARNESSES < <(printf '%s\n' "${PROOFS[@]}" | awk '{print $1}')
fi
SHARE_NOTE=
if [ -n "$CI" ]; then
    # CI's run: none over the budget, and one share of the long ones, chosen by the
    # commit so that consecutive commits prove different shares.
    if [ -z "${SHARE:-}" ]; then
        hash=$(git rev-parse --short=7 HEAD 2>/dev/null || echo 0)
        SHARE=$((16#$hash % SHARES))
    fi
    chosen=()
    n=0
    for h in "${HARNESSES[@]}"; do
        read -r _ kind _ <<<"$(budget_of "$h")"
        if [ "$kind" = over ]; then
            SKIPPED+=("$h (over the budget)")
        elif [ "$kind" = share ]; then
            if [ $((n % SHARES)) = "$SHARE" ]; then chosen+=("$h"); else SKIPPED+=("$h (share $((n % SHARES)))"); fi
            n=$((n + 1))
        else
            chosen+=("$h")
        fi
    done
    HARNESSES=("${chosen[@]}")
    SHARE_NOTE="; CI: share $SHARE of $SHARES of the long harnesses ($n), none over the budget"
fi
echo "Kani: $(cargo kani --version 2>&1 | tail -1); CBMC: $(cbmc --version 2>&1 | head -1); ${KANI_ARGS[*]:0:5}; CaDiCaL for ${WANT_CADICAL[*]:-none}${EXTERNAL_CADICAL:+ (external)}; limit ${LIMIT} s per harness (the others' in $BUDGET) and ${MEM_GB} GB; ${JOBS} at a time${SHARE_NOTE}; $(date -u +%F)"
start=$(date +%s)

# The groups: harnesses with the same solver, verified by one `cargo kani` each (two
# runs at most: each links every harness's goto program again). Kani stops a CBMC at
# the group's longest limit; a harness whose own limit is shorter and that took longer
# is reported as over its limit, whatever its verdict.
declare -A GROUP GROUP_OF LIMIT_OF GROUP_LIMIT
for h in "${HARNESSES[@]}"; do
    read -r budget _ _ <<<"$(budget_of "$h")"
    limit=$LIMIT
    [[ "$budget" =~ ^[0-9]+$ ]] && limit=$budget
    LIMIT_OF[$h]=$limit
    ext=default
    for w in "${WANT_CADICAL[@]}"; do [ "$w" = "$h" ] && [ -n "$EXTERNAL_CADICAL" ] && ext=cadical; done
    GROUP[$ext]+="$h "
    GROUP_OF[$h]=$ext
    [ "${GROUP_LIMIT[$ext]:-0}" -ge "$limit" ] || GROUP_LIMIT[$ext]=$limit
done

# Each CBMC's peak resident memory (VmHWM), by harness: the goto file CBMC reads is
# named after the harness's mangled name, which ends in `<length><name>.out`.
PEAKS="$OUT/peaks.txt"
: >"$PEAKS"
sample_peaks() {
    local pid cmd name kb
    while :; do
        for pid in $(pgrep -f -- '9harnesses.*--json-ui'); do
            cmd=$(tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline") || continue
            name=$(grep -oE '9harnesses[0-9]+[a-z_0-9]+\.out' <<<"$cmd" | head -1 | sed -E 's/^9harnesses[0-9]+//; s/\.out$//')
            kb=$(awk '/^VmHWM:/ {print $2}' 2>/dev/null "/proc/$pid/status")
            [ -n "$name" ] && [ -n "$kb" ] && echo "$name $kb" >>"$PEAKS"
        done
        sleep 0.2
    done
}
sample_peaks &
SAMPLER=$!
trap 'kill $SAMPLER 2>/dev/null' EXIT

RESULTS="$TARGET_DIR/result_output_dir"
rm -rf "$RESULTS" "$OUT"/run-*.log
for ext in "${!GROUP[@]}"; do
    limit=${GROUP_LIMIT[$ext]}
    read -r -a hs <<<"${GROUP[$ext]}"
    args=()
    for h in "${hs[@]}"; do args+=(--harness "harnesses::$h"); done
    [ "$ext" = cadical ] && args+=(--solver bin=cadical)
    # Kani verifies in parallel only with its terse output; the files it writes per
    # harness (--output-into-files) are the regular output either way.
    [ "$JOBS" -gt 1 ] && args+=(-j "$JOBS" --output-format=terse)
    # The group's own bound: every harness at its limit, one after another, and the
    # linking; Kani stops each CBMC at the limit long before.
    whole=$((limit * ${#hs[@]} + 600))
    (
        ulimit -v $((MEM_GB * 1024 * 1024))
        exec timeout --signal=KILL "$whole" cargo kani -p hiperface-proofs --exact "${args[@]}" \
            "${KANI_ARGS[@]}" --harness-timeout "${limit}s" --output-into-files \
            --cbmc-args "${CBMC_ARGS[@]}"
    ) >"$OUT/run-$ext.log" 2>&1
done
kill $SAMPLER 2>/dev/null

printf '| %-22s | %-13s | %7s | %8s | %10s |\n|---|---|---|---|---|\n' harness result "limit s" seconds "peak MB"
status=0
over=()
for h in "${HARNESSES[@]}"; do
    limit=${LIMIT_OF[$h]}
    read -r _ kind reason <<<"$(budget_of "$h")"
    file="$RESULTS/harnesses::$h"
    text=$(sed 's/\x1b\[[0-9;]*m//g' "$file" 2>/dev/null)
    log="$OUT/$h.log"
    printf '%s\n' "$text" >"$log"
    secs=$(grep -oE '^Verification Time: [0-9.]+' <<<"$text" | awk '{printf "%.2f", $3}')
    if [ -z "$text" ]; then
        result="error (no result)"
    elif grep -q 'CBMC timed out' <<<"$text"; then
        result="no verdict"
        secs=">${GROUP_LIMIT[${GROUP_OF[$h]}]}"
    elif grep -q 'run out of memory' <<<"$text" ||
        { grep -q 'CBMC failed with status' <<<"$text" && grep -qi 'out of memory\|std::bad_alloc' "$OUT"/run-*.log; }; then
        result="out of memory"
    elif grep -q 'Status: UNSATISFIABLE' <<<"$text"; then
        # A cover no input reaches: the harness's assumptions leave nothing to check.
        result=VACUOUS
    elif awk -v s="${secs:-0}" -v l="$limit" 'BEGIN {exit !(s > l)}'; then
        # Verified within the group's limit but past its own.
        result="no verdict"
    elif grep -q 'VERIFICATION:- SUCCESSFUL' <<<"$text"; then
        result=SUCCESSFUL
    elif grep -q 'VERIFICATION:- FAILED' <<<"$text"; then
        result=FAILED
    else
        result=error
    fi
    if [[ "$result" = "no verdict" || "$result" = "out of memory" ]] && [ "$kind" = over ]; then
        # Listed as over the budget, with the reason: reported, not a failure.
        result="no verdict (over budget)"
        over+=("$h: $reason")
    elif [ -n "$FALSE_ASSERTION" ]; then
        [ "$result" = FAILED ] && grep -q '^Failed Checks: .*false assertion: ' <<<"$text" || status=1
    else
        [ "$result" = SUCCESSFUL ] || status=1
    fi
    kb=$(awk -v h="$h" '$1 == h && $2 > m {m = $2} END {print m + 0}' "$PEAKS")
    mb=$([ "$kb" -gt 0 ] && echo $((kb / 1024)) || echo "-")
    printf '| %-22s | %-13s | %7s | %8s | %10s |\n' "$h" "$result" "$limit" "${secs:--}" "$mb"
done
for o in "${over[@]}"; do echo "over budget ($BUDGET): $o"; done
for s in "${SKIPPED[@]}"; do echo "not in this run: $s"; done
if [ ! -d "$RESULTS" ]; then
    echo "no harness was verified; the end of the first run's log ($OUT):"
    tail -20 "$(ls "$OUT"/run-*.log | head -1)"
fi
echo "whole run: $(($(date +%s) - start)) s"
exit $status
