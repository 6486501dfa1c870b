"""Benchmark: the golden vectors graded through the package, as a bench would grade a
device's replies. Prints vectors/s and exchanges/s (each vector: a fresh slave, its
setup, every step graded). Target (issue 31): 200 000 vectors/s.

    python python/benches/bench.py [VECTORS_DIR] [SECONDS]
"""

import json
import sys
import time
from pathlib import Path

from hiperface import Oracle, Slave


def load(directory):
    vectors = []
    for path in sorted(Path(directory).glob("*.json")):
        doc = json.loads(path.read_text())
        for group in doc.get("testGroups", []):
            setup = group.get("setup", {})
            if set(setup) - {"inputs", "requests"}:
                continue  # start-up faults, timed power-up: not driven here
            for test in group["tests"]:
                steps = test.get("steps") or []
                if not steps or any("at_us" in s for s in steps):
                    continue
                compiled = [
                    (bytes.fromhex(s["request"]), None if s.get("response") is None else bytes.fromhex(s["response"]),
                     s.get("uart_fault", False), s.get("inputs"))
                    for s in steps
                ]
                requests = [bytes.fromhex(r) for r in setup.get("requests", [])]
                vectors.append((group["profile"], setup.get("inputs"), requests, compiled))
    return vectors


def main():
    directory = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "vectors"
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 2.0
    vectors = load(directory)
    oracle = Oracle(exact=True)
    # A slave per profile and setup, copied per vector as a bench resets its device.
    done = exchanges = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        for profile, inputs, requests, steps in vectors:
            s = Slave(profile)
            if inputs:
                s.set_inputs(**inputs)
            for r in requests:
                s.handle_frame(r, 0)
            for request, reply, uart_fault, step_inputs in steps:
                if step_inputs:
                    s.set_inputs(**step_inputs)
                oracle.grade(s, request, 0, reply, uart_fault)
                exchanges += 1
            done += 1
    elapsed = time.perf_counter() - start
    print(f"{len(vectors)} vectors; {done / elapsed:,.0f} vectors/s, {exchanges / elapsed:,.0f} exchanges/s graded")


if __name__ == "__main__":
    main()
