#!/usr/bin/env bash
# The same device gets the same verdicts on an idle and on a busy machine.
#
# Certifies each master (the reference master, HX-M conformant, HX-M with each defect
# switch) and each slave (the simulator, HX-1) RUNS times on an idle machine and RUNS
# times with three busy loops on the cores, and prints one line per run: the verdict
# of every scenario or case, and how often a scenario was run again. Exits 1 when a
# device's verdicts differ between any two of its runs.
#
#   RUNS=5 scripts/verdicts-under-load.sh                 # everything
#   LOADS=busy BUILD=1 RUNS=10 MASTERS=reference SLAVES="sim hx-1" scripts/verdicts-under-load.sh
#   MASTERS="reference receive-idle" SLAVES="" RUNS=2 scripts/verdicts-under-load.sh
#   LOADS=busy OUT=target/vul-busy scripts/verdicts-under-load.sh   # the busy half only
#
# The idle and the busy halves can be run apart (LOADS) into separate directories
# (OUT) and compared afterwards with `scripts/verdicts-under-load.sh compare DIR...`.
# The command is copied before the runs, so rebuilding meanwhile changes nothing.
#
# The busy half runs three busy loops; with BUILD=1 also a cargo build of the workspace
# in a loop at normal priority (a copy of HEAD in $OUT/build-tree, its own target
# directory). SLAVES may name HX-3 and HX-4 (`hx-3`, `hx-4`, the blind trials' slaves) and
# HX-1, HX-3 or HX-4 with a defect switch as `hx-1:NAME`, `hx-3:dNN`, `hx-4:dNN` (its own case
# must FAIL in every run), and `sim-link` for `hiperface simulate` reached through a symbolic link
# to its pseudo-terminal. MASTERS may name HX-M3 and HX-M4 (`hx-m3`, `hx-m4`, the masters
# of the blind trials) and their sealed defects as `hx-m3:dNN`, `hx-m4:dNN`. Each line gives the run's exit code, and ends with what the harness measured of the line
# itself: the pseudo-terminal's delivery (the probe beside the line, line::delivery), and
# how much of the processors the hypervisor took during the run (steal), where it says.
#
# The device under test is protected from the load as a real device is (it runs with
# `chrt -f`, a real-time priority: a drive's or an encoder's firmware has a processor of
# its own): a peer the load starves is really late on the wire. The harness is not.
# Not part of `cargo test`: it takes RUNS x 2 x about 45 s per device.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-5}
LOADS=${LOADS:-"idle busy"}
OUT=${OUT:-target/verdicts-under-load}
MASTERS=${MASTERS-"reference hx-m talks-during-init settings-window no-pause gap-in-request wrong-checksum \
ignores-warning ignores-sync-fault retries-forever no-reset-wait no-retry ignores-extended-type-label no-baud \
sparse-poll naive-poll late-default receive-idle"}
SLAVES=${SLAVES-"sim hx-1"}

# The runs of one device (lines "load vector  | runs: ..." on stdin): print them under
# "== NAME: same|DIFFERENT verdicts in N runs"; status 1 when they differ.
judge() {
    local runs distinct
    runs=$(cat)
    distinct=$(echo "$runs" | cut -c7- | sed 's/  | .*//' | sort -u | wc -l)
    echo "== $1: $([ "$distinct" = 1 ] && echo same || echo DIFFERENT) verdicts in $(echo "$runs" | wc -l) runs"
    echo "$runs"
    [ "$distinct" = 1 ]
}

# Compare the runs of each device across result directories: same or DIFFERENT.
if [ "${1:-}" = compare ]; then
    shift
    status=0
    for f in $(for d in "$@"; do ls "$d"/*.txt 2>/dev/null; done | xargs -n1 basename | sort -u); do
        case "$f" in hx1.path | hx3.path | hx4.path) continue ;; esac
        for d in "$@"; do [ -f "$d/$f" ] && cat "$d/$f"; done | judge "${f%.txt}" || status=1
    done
    exit $status
fi

cargo build --release -q -p hiperface-conformance
git worktree remove --force "$OUT/build-tree" 2>/dev/null || true
rm -rf "$OUT"; mkdir -p "$OUT"; git worktree prune
cp target/release/hiperface "$OUT/hiperface"
H=$(cd "$OUT" && pwd)/hiperface

busy() {  # start three busy loops (and with BUILD=1 a build loop); their PIDs in BUSY
    BUSY=()
    for _ in 1 2 3; do (while :; do :; done) & BUSY+=($!); done
    if [ "${BUILD:-0}" = 1 ]; then
        [ -d "$OUT/build-tree" ] || git worktree add -q --detach "$OUT/build-tree" HEAD
        (while :; do
            CARGO_TARGET_DIR="$OUT/build-target" cargo build --release -q \
                --manifest-path "$OUT/build-tree/Cargo.toml" -p hiperface-conformance >/dev/null 2>&1
            touch "$OUT/build-tree/model/src/lib.rs"
        done) & BUSY+=($!)
    fi
}
calm() {
    for p in "${BUSY[@]:-}"; do pkill -P "$p" 2>/dev/null || true; kill "$p" 2>/dev/null || true; done
    pkill -f "manifest-path $OUT/build-tree" 2>/dev/null || true
    BUSY=()
}
trap calm EXIT

# One line: every unit's verdict, in order, and the units run more than once.
vector() {
    python3 - "$1" <<'PY'
import json, sys
try:
    r = json.load(open(sys.argv[1]))
except OSError:
    print("NO-REPORT (the run did not start: see its log)")
    sys.exit(0)
units = r.get("scenarios") or r.get("cases") or []
short = {"PASS": "PASS", "NON-STRICT": "NONS", "FAIL": "FAIL", "NOT-APPLICABLE": "N/A",
         "NOT-EXERCISED": "NOTX", "UNKNOWN": "UNKN", "ERROR": "ERR"}
v = " ".join(short.get(u["verdict"], u["verdict"]) for u in units)
again = [f'{u["id"]}x{u.get("attempts", 1)}' for u in units if u.get("attempts", 1) > 1]
d = r.get("delivery") or {}
probe = "  | line: %.1f ms (probe: %s writes, %s > 1 ms, latest %.1f ms)" % (
    r.get("line_late_us", 0) / 1000, d.get("samples", 0), d.get("over_1ms", 0), d.get("max_us", 0) / 1000) if d else ""
ratio = ""
if r.get("needed_ms"):
    ratio = "  | wall %.2fx" % (r["wall_time_ms"] / r["needed_ms"])
steal = (r.get("run_info") or {}).get("steal")
if steal:
    ratio += "  | steal %.1f %%" % (100.0 * steal["steal_ms"] / max(steal["processor_ms"], 1))
try:
    rc = open(sys.argv[1].rsplit("/", 1)[0] + ".rc").read().strip()
except OSError:
    rc = "?"
print(v + " exit " + rc + ("  | runs: " + ",".join(again) if again else "") + probe + ratio)
PY
}

master_exec() {
    case "$1" in
        reference) echo "chrt -f 50 $H master --port {port}" ;;
        hx-m) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hx_master.py {port}" ;;
        # HX-M3, the master of the blind trial, conformant or with a sealed defect (hx-m3:d15).
        hx-m3) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hxm3_master.py {port}" ;;
        hx-m3:*) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hxm3_master.py {port} --defect ${1#hx-m3:}" ;;
        # HX-M4, the drive for a legacy encoder of the second master trial (its profile below).
        hx-m4) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hxm4_master.py {port}" ;;
        hx-m4:*) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hxm4_master.py {port} --defect ${1#hx-m4:}" ;;
        *) echo "chrt -f 50 python3 $PWD/conformance/tests/independent/hx_master.py {port} --defect $1" ;;
    esac
}

certify_master() {  # name, report dir
    local extra=()
    [ "$1" = talks-during-init ] && extra=(--profile "$(cd "$OUT" && pwd)/long-init.toml")
    case "$1" in hx-m4*) extra=(--profile "$PWD/conformance/tests/independent/hxm4.toml") ;; esac
    local rc=0
    "$H" certify master --exec "$(master_exec "$1")" --report "$2" "${extra[@]}" > "$2.log" 2>&1 || rc=$?
    echo "$rc" > "$2.rc"
}

certify_slave() {  # name, report dir
    local defect=()
    case "$1" in hx-1:* | hx-3:* | hx-4:*) defect=(--defect "${1#hx-?:}") ;; esac
    case "$1" in
        sim) local rc=0
            chrt -f 50 "$H" certify slave --port sim --report "$2" >"$2.log" 2>&1 || rc=$?
            echo "$rc" > "$2.rc" ;;
        sim-link)  # the simulator of `hiperface simulate` reached through a symbolic link
            local rc=0 sim
            rm -f "$OUT/sim.path" "$OUT/sim-link"
            (chrt -f 50 "$H" simulate --port pty > "$OUT/sim.path" 2>/dev/null) &
            sim=$!
            for _ in $(seq 50); do [ -s "$OUT/sim.path" ] && break; sleep 0.1; done
            ln -s "$(head -1 "$OUT/sim.path")" "$OUT/sim-link"
            "$H" certify slave --port "$OUT/sim-link" --allow-writes --allow-counter-change --allow-adjustment \
                --report "$2" >"$2.log" 2>&1 || rc=$?
            echo "$rc" > "$2.rc"
            kill "$sim" 2>/dev/null || true; wait "$sim" 2>/dev/null || true
            ;;
        hx-1* | hx-3* | hx-4*)  # HX-1, HX-3 (a blind trial's slave, which also has 6Bh) or HX-4
            local peer=hx1 more=() power_up=0.3
            case "$1" in
                hx-3*) peer=hx3 more=(--allow-adjustment) ;;
                # A legacy device: past its initialization and window of default settings.
                hx-4*) peer=hx4 power_up=1.2 ;;
            esac
            rm -f "$OUT/$peer.path"
            # In a session of its own (the pipe's `sleep` included), ended as a group below.
            setsid bash -c 'sleep 600 | chrt -f 50 python3 "$@"' _ "conformance/tests/independent/${peer}_slave.py" \
                --pty "${defect[@]}" > "$OUT/$peer.path" &
            local hx=$!
            for _ in $(seq 50); do [ -s "$OUT/$peer.path" ] && break; sleep 0.1; done
            sleep "$power_up"
            local rc=0
            "$H" certify slave --port "$(head -1 "$OUT/$peer.path")" --profile "conformance/tests/independent/$peer.toml" \
                --allow-writes --allow-counter-change "${more[@]}" --report "$2" >"$2.log" 2>&1 || rc=$?
            echo "$rc" > "$2.rc"
            kill -- -"$hx" 2>/dev/null || true; wait "$hx" 2>/dev/null || true
            ;;
    esac
}

# An encoder with the longest initialization 000:T9 allows (200 ms) for talks-during-init,
# so that the interpreter's start-up does not carry its first request past it.
"$H" export-profile SRS50 | sed 's/^init_ms = .*/init_ms = 200/' > "$OUT/long-init.toml"
"$H" check-profile "$OUT/long-init.toml" > /dev/null

status=0
for kind in master slave; do
    devices=$([ $kind = master ] && echo "$MASTERS" || echo "$SLAVES")
    for d in $devices; do
        : > "$OUT/$kind-$d.txt"
        for load in $LOADS; do
            for i in $(seq "$RUNS"); do
                [ $load = busy ] && busy
                "certify_$kind" "$d" "$OUT/$kind-$d-$load-$i"
                calm
                printf '%-5s %s\n' "$load" "$(vector "$OUT/$kind-$d-$load-$i/report.json")" >> "$OUT/$kind-$d.txt"
            done
        done
        judge "$kind $d" < "$OUT/$kind-$d.txt" || status=1
    done
done
calm
git worktree remove --force "$OUT/build-tree" 2>/dev/null || true
exit $status
