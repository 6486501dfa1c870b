#!/usr/bin/env bash
# CPU time of an idle `hiperface simulate` (a pseudo-terminal nobody talks on) over
# SECONDS_IDLE seconds (default 10). The simulator sleeps in its read while nothing is
# due; the target is under 0.05 s of CPU in 10 s. Exits 1 above the target.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_IDLE=${SECONDS_IDLE:-10}
cargo build --release -q -p hiperface-conformance
target/release/hiperface simulate > /dev/null &
sim=$!
trap 'kill -INT $sim 2>/dev/null || true' EXIT
sleep "$SECONDS_IDLE"
read -r utime stime < <(cut -d')' -f2 "/proc/$sim/stat" | awk '{print $12, $13}')
cpu=$(python3 -c "import os; print(($utime + $stime) / os.sysconf('SC_CLK_TCK'))")
echo "idle simulate: ${cpu} s of CPU in ${SECONDS_IDLE} s"
python3 -c "import sys; sys.exit(0 if $cpu < 0.05 * $SECONDS_IDLE / 10 else 1)"
