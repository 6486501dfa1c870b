"""A pytest bench as a lab PC runs one: HX-1 (the independent slave, in Python) on a
pseudo-terminal, talked to with pyserial, every reply graded by the package's oracle
in lockstep. HX-1 conforms: nothing FAILs; with its `reply-checksum` defect, Read
Version FAILs on 000:2.3.3."""

import subprocess
import sys
import time

import pytest
import serial

from hiperface import Oracle, Slave

REQUESTS = [
    "40 52 12",  # Read Type Label
    "40 50 10",  # Read Encoder Status
    "40 42 02",  # Read Position
    "40 56 16",  # Read Version
    "40 4C 0C",  # Memory Status
    "40 7E",     # an unknown command (checksum added below)
]


def with_checksum(hex_bytes):
    b = bytes.fromhex(hex_bytes)
    if len(b) == 2:
        x = 0
        for c in b:
            x ^= c
        b += bytes([x])
    return b


@pytest.fixture
def hx1(root, request):
    defects = getattr(request, "param", [])
    args = [sys.executable, str(root / "conformance/tests/independent/hx1_slave.py"), "--pty"]
    for d in defects:
        args += ["--defect", d]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stdin=subprocess.PIPE, text=True)
    path = proc.stdout.readline().strip()
    assert path.startswith("/dev/"), path
    # Just powered on: past its initialization (000:T9, at most 200 ms) it answers.
    time.sleep(0.25)
    yield path
    proc.kill()
    proc.wait()


def bench(path, profile):
    """Send each request, read the reply (the line falls quiet for 30 ms), grade it."""
    port = serial.Serial(path, 9600, parity=serial.PARITY_EVEN, timeout=0.03)
    model, oracle = Slave(profile), Oracle(exact=False)
    grades = []
    t0 = time.monotonic()
    for hex_request in REQUESTS:
        request = with_checksum(hex_request)
        port.reset_input_buffer()
        port.write(request)
        port.flush()
        reply = b""
        deadline = time.monotonic() + 0.5
        while time.monotonic() < deadline:
            chunk = port.read(64)
            if not chunk and reply:
                break
            reply += chunk
        at_us = int((time.monotonic() - t0) * 1e6) + 10_000_000
        grades.append((request.hex(" "), oracle.grade(model, request, at_us, reply or None)))
        time.sleep(0.02)
    port.close()
    return grades


def test_hx1_passes_the_bench(hx1, root):
    grades = bench(hx1, str(root / "conformance/tests/independent/hx1.toml"))
    assert [g.verdict for _, g in grades if g.verdict == "FAIL"] == [], grades
    assert sum(g.verdict == "PASS" for _, g in grades) >= 5, grades


@pytest.mark.parametrize("hx1", [["reply-checksum"]], indirect=True)
def test_a_defective_hx1_fails_where_it_breaks_the_rule(hx1, root):
    grades = dict(bench(hx1, str(root / "conformance/tests/independent/hx1.toml")))
    version = grades["40 56 16"]
    assert (version.verdict, version.clause) == ("FAIL", "000:2.3.3"), grades
    assert all(g.verdict != "FAIL" for r, g in grades.items() if r != "40 56 16"), grades
