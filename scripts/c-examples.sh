#!/usr/bin/env bash
# The C API as C code uses it: build the static library, compile the examples with
# the system's C compiler (warnings are errors) and run them.
#   tiny_encoder            a tiny C encoder (written from the specification alone)
#                           certified in-process with the whole catalogue (hf_certify),
#                           under AddressSanitizer and UBSan: PASSED, in under 50 ms
#   tiny_encoder --defect   its checksum slip: FAILED, on the checksum clause 000:2.3.3
#   tiny_encoder --temperature 120
#                           its world (the sensor reads 120 °C, above its 115) told to
#                           the run, which grades exactly: warning 1Eh on every reply,
#                           PASSED; with --ignore-temperature FAILED on 000:T27 and
#                           000:2.3.4, and PASSED at 25 °C (the defect needs the heat)
#   tiny_master             a tiny C master (written from the specification alone)
#                           certified in-process with the whole scenario catalogue
#                           (hf_certify_master), under AddressSanitizer and UBSan: PASSED
#   tiny_master --defect    its checksum slip: FAILED, on 000:2.3/master
#   garbage                 every function fed nulls, short buffers and random bytes,
#                           under AddressSanitizer and UBSan: status codes, no crash
#   vectors vectors/*.json  every golden vector replayed through the C API: each
#                           gets the verdict it expects; and a copy with one reply
#                           byte changed is caught
#   bench                   exchanges graded per second (printed)
set -euo pipefail
cd "$(dirname "$0")/.."
CC=${CC:-cc}
# The library as it ships: the c-release profile (size-optimised, LTO; Cargo.toml).
cargo build -q -p hiperface-ffi --profile c-release
out=target/c-examples
mkdir -p "$out"
lib=target/c-release/libhiperface.a
flags=(-std=c11 -Wall -Wextra -Werror -Iffi/include)
libs=("$lib" -lpthread -ldl -lm)
sanitized=(-g -fsanitize=address,undefined -fno-sanitize-recover=all)
"$CC" "${flags[@]}" "${sanitized[@]}" -o "$out/tiny_encoder" examples/c/tiny_encoder.c "${libs[@]}"
"$CC" "${flags[@]}" "${sanitized[@]}" -o "$out/tiny_master" examples/c/tiny_master.c "${libs[@]}"
"$CC" "${flags[@]}" -o "$out/vectors" examples/c/vectors.c "${libs[@]}"
"$CC" "${flags[@]}" -O2 -o "$out/bench" examples/c/bench.c "${libs[@]}"
"$CC" "${flags[@]}" "${sanitized[@]}" -o "$out/garbage" examples/c/garbage.c "${libs[@]}"
# Each certification in well under 50 ms (virtual time; the figure is the program's own).
under_50ms() {
    local ms
    ms=$(grep -oE "certified in [0-9.]+ ms" "$1" | grep -oE "[0-9.]+")
    awk -v ms="$ms" 'BEGIN { exit !(ms != "" && ms < 50) }' || { echo "the certification took ${ms:-?} ms"; exit 1; }
}
echo "-- tiny_encoder: certified in-process (expected PASSED), JUnit written"
"$out/tiny_encoder" --junit "$out/tiny_encoder.junit.xml" | tee "$out/tiny.txt"
grep -q "^PASSED$" "$out/tiny.txt" || { echo "the conformant encoder was not PASSED"; exit 1; }
under_50ms "$out/tiny.txt"
grep -q "<testcase" "$out/tiny_encoder.junit.xml" || { echo "no JUnit test cases written"; exit 1; }
echo "-- tiny_encoder linked with the shared library alone (-lhiperface -lpthread -ldl)"
"$CC" "${flags[@]}" -o "$out/tiny_encoder_shared" examples/c/tiny_encoder.c -Ltarget/c-release -lhiperface -lpthread -ldl
LD_LIBRARY_PATH=target/c-release "$out/tiny_encoder_shared" > /dev/null
strip -o "$out/libhiperface.stripped.so" target/c-release/libhiperface.so
size=$(stat -c %s "$out/libhiperface.stripped.so")
echo "libhiperface.so stripped: $size bytes; libhiperface.a: $(stat -c %s "$lib") bytes"
# The C library links the model and the suite's core, none of the harness (issue 39).
[ "$size" -lt 2097152 ] || { echo "the stripped shared library is 2 MB or more"; exit 1; }
echo "-- tiny_encoder --defect (expected FAILED on the checksum, 000:2.3.3)"
if "$out/tiny_encoder" --defect > "$out/defect.txt"; then
    cat "$out/defect.txt"; echo "the defective encoder was not failed"; exit 1
fi
tail -3 "$out/defect.txt"
grep -q "^FAILED$" "$out/defect.txt" || { echo "the defective encoder's run is not FAILED"; exit 1; }
grep -q "FAIL \[000:2.3.3\]" "$out/defect.txt" || { echo "no FAIL on the checksum clause"; exit 1; }
under_50ms "$out/defect.txt"
echo "-- tiny_encoder --temperature 120: its world told to the run, graded exactly (expected PASSED)"
"$out/tiny_encoder" --temperature 120 > "$out/hot.txt" || { cat "$out/hot.txt"; echo "the hot encoder was not PASSED"; exit 1; }
tail -2 "$out/hot.txt"
echo "-- tiny_encoder --temperature 120 --ignore-temperature (expected FAILED on 000:T27 and 000:2.3.4)"
if "$out/tiny_encoder" --temperature 120 --ignore-temperature > "$out/hot_defect.txt"; then
    cat "$out/hot_defect.txt"; echo "the encoder that ignores its temperature was not failed"; exit 1
fi
grep -q "^FAILED$" "$out/hot_defect.txt" || { echo "its run is not FAILED"; exit 1; }
grep -q "FAIL \[000:T27\] .*expected \[40 D0 1E 8E\]" "$out/hot_defect.txt" \
    || { echo "no FAIL of Read Encoder Status without 1Eh"; exit 1; }
grep -q "FAIL \[000:2.3.4\] .*warning bit clear" "$out/hot_defect.txt" || { echo "no FAIL of the warning bit"; exit 1; }
"$out/tiny_encoder" --temperature 25 --ignore-temperature | tail -1 | grep -q "^PASSED$" \
    || { echo "at 25 °C the defect cannot show, yet the run was not PASSED"; exit 1; }
echo "-- tiny_master: certified in-process with the scenario catalogue (expected PASSED), JUnit written"
"$out/tiny_master" --junit "$out/tiny_master.junit.xml" | tee "$out/tiny_master.txt"
grep -q "^PASSED$" "$out/tiny_master.txt" || { echo "the conformant master was not PASSED"; exit 1; }
[ "$(grep -c "<testcase" "$out/tiny_master.junit.xml")" -eq 22 ] || { echo "not 22 scenarios in the JUnit file"; exit 1; }
echo "-- tiny_master --defect (expected FAILED on 000:2.3/master: frames that are no requests)"
if "$out/tiny_master" --defect > "$out/master_defect.txt"; then
    cat "$out/master_defect.txt"; echo "the defective master was not failed"; exit 1
fi
tail -3 "$out/master_defect.txt"
grep -q "^FAILED$" "$out/master_defect.txt" || { echo "the defective master's run is not FAILED"; exit 1; }
grep -q "FAIL \[000:2.3/master\]" "$out/master_defect.txt" || { echo "no FAIL on 000:2.3/master"; exit 1; }
echo "-- vectors: every golden vector file"
files=()
for f in vectors/*.json; do [ "$(basename "$f")" = schema.json ] || files+=("$f"); done
"$out/vectors" "${files[@]}" | tee "$out/vectors.txt"
# As many as `hiperface vectors verify` checks.
verified=$(cargo run -q --release -p hiperface-conformance -- vectors verify vectors | grep -oE "^[0-9]+ vectors" | grep -oE "[0-9]+")
grep -q "^$verified vectors replayed through the C API" "$out/vectors.txt" \
    || { echo "the C replay did not replay the $verified vectors vectors verify checks"; exit 1; }
echo "-- vectors on a copy of documents.json with one reply byte changed (expected to disagree)"
python3 - vectors/documents.json "$out/tampered.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
for group in doc["testGroups"]:
    for t in group["tests"]:
        if t.get("result") == "valid" and t.get("steps") and t["steps"][-1].get("response"):
            reply = t["steps"][-1]["response"].split()
            # a data byte and the checksum both changed: a well-formed reply with a wrong value
            reply[-2] = "%02X" % (int(reply[-2], 16) ^ 0x01)
            reply[-1] = "%02X" % (int(reply[-1], 16) ^ 0x01)
            t["steps"][-1]["response"] = " ".join(reply)
            print("changed", t["id"])
            json.dump(doc, open(sys.argv[2], "w"))
            sys.exit(0)
sys.exit("no vector to change")
PY
if "$out/vectors" "$out/tampered.json" > "$out/tampered.txt"; then
    cat "$out/tampered.txt"; echo "the changed reply was not caught"; exit 1
fi
cat "$out/tampered.txt"
grep -q "the vector expects PASS" "$out/tampered.txt" || { echo "not caught as a wrong reply"; exit 1; }
echo "-- garbage (AddressSanitizer, UBSan)"
"$out/garbage"
echo "-- bench (figures for the record, not a gate: a shared machine's speed varies)"
"$out/bench" 1
echo "C examples passed"
