#!/usr/bin/env bash
# Mutants of the model under Kani: each mutant applied alone to a copy of the tree
# (target/kani-mutants/tree, its own build directory), then `scripts/kani.sh` with the
# harnesses named. A mutant is caught when one of them FAILs; a harness with no verdict
# within its limit does not catch it (kani.sh's "no verdict"). Prints a table (mutant,
# result per harness) and exits 1 if a mutant is not caught.
#
#   scripts/kani-mutants.sh 'FieldMemory::write' field_memory_any_write
#       the mutants cargo-mutants makes of model/src/slave/fields/memory.rs whose name matches
#       the regular expression (cargo mutants --list --re), against field_memory_any_write
#   scripts/kani-mutants.sh --sed 's/a/b/' 'name' field_memory_any_write
#       one mutant of model/src/slave/fields/memory.rs given as a sed expression (a mutant
#       cargo-mutants does not make: `+=` for `|=`), with its name
#   FILE=model/src/... LIMIT=... as for kani.sh
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
FILE=${FILE:-model/src/slave/fields/memory.rs}
WORK=target/kani-mutants
mkdir -p "$WORK"
declare -a NAMES DIFFS SEDS
if [ "${1:-}" = --sed ]; then
    SEDS=("$2")
    NAMES=("$3")
    shift 3
else
    re=$1
    shift
    cargo mutants --list --json --diff --file "$FILE" --re "$re" >"$WORK/list.json" 2>/dev/null ||
        { echo "kani-mutants.sh: cargo mutants --list failed"; exit 2; }
    i=0
    while IFS= read -r name; do
        NAMES+=("$name")
        python3 -c 'import json,sys; d=[m for m in json.load(open(sys.argv[1])) if m["file"]==sys.argv[2]]; sys.stdout.write(d[int(sys.argv[3])]["diff"])' \
            "$WORK/list.json" "$FILE" "$i" >"$WORK/mutant-$i.diff"
        DIFFS+=("$WORK/mutant-$i.diff")
        i=$((i + 1))
    done < <(python3 -c 'import json,sys; [print(m["name"]) for m in json.load(open(sys.argv[1])) if m["file"]==sys.argv[2]]' "$WORK/list.json" "$FILE")
fi
[ $# -gt 0 ] || { echo "kani-mutants.sh: name the harnesses"; exit 2; }
echo "${#NAMES[@]} mutant(s) of $FILE against $*; $(date -u +%F)"
status=0
for i in "${!NAMES[@]}"; do
    # A fresh copy of what git tracks, with the working tree's changes, then the mutant.
    rm -rf "$WORK/tree" && mkdir -p "$WORK/tree"
    git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$WORK/tree" 2>/dev/null
    if [ -n "${SEDS[$i]:-}" ]; then
        sed -i "${SEDS[$i]}" "$WORK/tree/$FILE"
    else
        patch -s "$WORK/tree/$FILE" <"${DIFFS[$i]}" || { echo "| ${NAMES[$i]} | does not apply |"; status=1; continue; }
    fi
    if cmp -s "$FILE" "$WORK/tree/$FILE"; then
        echo "| ${NAMES[$i]} | unchanged: not applied |"
        status=1
        continue
    fi
    out=$(cd "$WORK/tree" && CARGO_TARGET_DIR="$ROOT/$WORK/target" scripts/kani.sh "$@" 2>&1)
    # Kept per mutant, with each harness's log: the next mutant's tree replaces this one.
    printf '%s\n' "$out" >"$WORK/mutant-$i.out"
    rm -f "$WORK/mutant-$i-"*.log
    for h in "$@"; do cp "$WORK/tree/target/kani/$h.log" "$WORK/mutant-$i-$h.log" 2>/dev/null; done
    # The harnesses' rows of kani.sh's table (not its heading): name, result, seconds,
    # and the check that failed.
    results=$(grep -E '^\| [a-z_0-9]+ +\| ' <<<"$out" | grep -v '^| harness ' |
        awk -F'|' '{gsub(/ +/, " "); printf "%s:%s in%ss,", $2, $3, $5}')
    failed=$(cat "$WORK/mutant-$i-"*.log 2>/dev/null | grep -h '^Failed Checks: ' | sort -u | sed 's/^Failed Checks: //' | paste -sd ';' -)
    [ -n "$failed" ] && results="${results%,} (failed: $failed),"
    if grep -qE '^\| [a-z_0-9]+ +\| FAILED ' <<<"$out"; then
        verdict=caught
    else
        verdict="NOT caught"
        status=1
    fi
    echo "| ${NAMES[$i]} | $verdict | ${results%,} |"
done
exit $status
