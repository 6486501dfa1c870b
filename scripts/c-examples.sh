#!/usr/bin/env bash
# The C API as C code uses it: build the static library, compile the examples with
# the system's C compiler (warnings are errors) and run them.
#   tiny_encoder            a tiny C encoder graded by the oracle: every reply PASSes
#   tiny_encoder --defect   its checksum slip: FAILed, with the checksum clause
#   garbage                 every function fed nulls, short buffers and random bytes,
#                           under AddressSanitizer and UBSan: status codes, no crash
#   bench                   exchanges graded per second (printed)
set -euo pipefail
cd "$(dirname "$0")/.."
CC=${CC:-cc}
cargo build -q -p hiperface-ffi --release
out=target/c-examples
mkdir -p "$out"
lib=target/release/libhiperface.a
flags=(-std=c11 -Wall -Wextra -Werror -Iffi/include)
libs=("$lib" -lpthread -ldl -lm)
"$CC" "${flags[@]}" -o "$out/tiny_encoder" examples/c/tiny_encoder.c "${libs[@]}"
"$CC" "${flags[@]}" -O2 -o "$out/bench" examples/c/bench.c "${libs[@]}"
"$CC" "${flags[@]}" -g -fsanitize=address,undefined -fno-sanitize-recover=all -o "$out/garbage" examples/c/garbage.c "${libs[@]}"
echo "-- tiny_encoder"
"$out/tiny_encoder"
echo "-- tiny_encoder --defect (expected to FAIL on the checksum, 000:2.3.3)"
if "$out/tiny_encoder" --defect > "$out/defect.txt"; then
    cat "$out/defect.txt"; echo "the defective encoder was not failed"; exit 1
fi
cat "$out/defect.txt"
grep -q "FAIL \[000:2.3.3\]" "$out/defect.txt" || { echo "no FAIL on the checksum clause"; exit 1; }
echo "-- garbage (AddressSanitizer, UBSan)"
"$out/garbage"
echo "-- bench (figures for the record, not a gate: a shared machine's speed varies)"
"$out/bench" 1
echo "C examples passed"
