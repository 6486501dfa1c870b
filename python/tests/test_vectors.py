"""The documents' worked examples graded through the package exactly as
`hiperface vectors verify` grades them: 001 §5.1.4's 19 examples and its two errata
(both ways), 002's data-field sequence."""

import json
import subprocess

import pytest

from hiperface import Oracle, Slave, verify_vectors


def replay(group_setup, profile, test):
    """Whether every step gets its verdict: the last the vector's result, the others PASS."""
    s = Slave(profile)
    inputs = group_setup.get("inputs", {})
    if inputs:
        s.set_inputs(**inputs)
    for r in group_setup.get("requests", []):
        s.handle_frame(bytes.fromhex(r), 0)
    want_last = {"valid": "PASS", "acceptable": "NON-STRICT", "invalid": "FAIL"}[test["result"]]
    oracle = Oracle(exact=True)
    for i, step in enumerate(test["steps"]):
        if "inputs" in step:
            s.set_inputs(**step["inputs"])
        reply = bytes.fromhex(step["response"]) if step.get("response") is not None else None
        g = oracle.grade(s, bytes.fromhex(step["request"]), step.get("at_us", 0), reply, step.get("uart_fault", False))
        want = want_last if i + 1 == len(test["steps"]) else "PASS"
        if g.verdict != want:
            return f"step {i}: {g}, expected {want}"
    return None


def test_the_worked_examples_grade_as_vectors_verify_grades_them(root, hiperface_bin):
    doc = json.loads((root / "vectors/documents.json").read_text())
    graded = []
    for group in doc["testGroups"]:
        for test in group["tests"]:
            if not test.get("steps"):
                continue
            problem = replay(group.get("setup", {}), group["profile"], test)
            assert problem is None, (test["id"], problem)
            graded.append(test["id"])
    assert len([i for i in graded if i.startswith("001-")]) == 21, graded
    assert any(i.startswith("002-") for i in graded), graded
    # The package's own verify and the command agree: every vector as the model says.
    count, mismatches = verify_vectors(str(root / "vectors"))
    assert count > 400 and mismatches == [], mismatches
    cli = subprocess.run([str(hiperface_bin), "vectors", "verify", str(root / "vectors")], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stdout + cli.stderr


def test_a_corrupted_example_fails():
    s = Slave("Kuebler-S36-ST")
    s.set_inputs(position=0, temperature_c=37)
    reply = s.handle_frame(bytes.fromhex("40 42 02"), 0)
    graded = Slave("Kuebler-S36-ST")
    graded.set_inputs(position=0, temperature_c=37)
    g = Oracle(exact=True).grade(graded, bytes.fromhex("40 42 02"), 0, reply[:-2] + bytes([reply[-2] ^ 4, reply[-1] ^ 4]))
    assert g.verdict == "FAIL", g


def test_one_vector_at_a_time_as_vectors_verify_checks_it(root, tmp_path):
    """The per-vector API: a file's vectors, each verified; a changed reply caught."""
    from hiperface import HiperfaceError, load_vectors

    vectors = load_vectors(str(root / "vectors/documents.json"))
    assert len(vectors) > 20 and all(v.verify() == [] for v in vectors), [v for v in vectors if v.verify()]
    first = vectors[0]
    assert first.id and first.profile and first.result in ("valid", "acceptable", "invalid")
    assert repr(first).startswith("Vector(id=")
    # The same file with one reply byte and its checksum changed: that vector disagrees.
    doc = json.loads((root / "vectors/documents.json").read_text())
    changed = None
    for group in doc["testGroups"]:
        for t in group["tests"]:
            if changed is None and t.get("result") == "valid" and t.get("steps") and t["steps"][-1].get("response"):
                reply = t["steps"][-1]["response"].split()
                reply[-2] = "%02X" % (int(reply[-2], 16) ^ 1)
                reply[-1] = "%02X" % (int(reply[-1], 16) ^ 1)
                t["steps"][-1]["response"] = " ".join(reply)
                changed = t["id"]
    tampered = tmp_path / "tampered.json"
    tampered.write_text(json.dumps(doc))
    wrong = [v.id for v in load_vectors(str(tampered)) if v.verify()]
    assert wrong == [changed]
    # Not a vector file, and no file at all.
    (tmp_path / "not.json").write_text("{}")
    with pytest.raises(HiperfaceError):
        load_vectors(str(tmp_path / "not.json"))
    with pytest.raises(FileNotFoundError):
        load_vectors(str(tmp_path / "missing.json"))


def test_nothing_to_verify_is_an_error_and_a_missing_directory_is_not_found(tmp_path):
    """As the command: an empty directory verifies nothing, which is no pass."""
    from hiperface import HiperfaceError

    with pytest.raises(HiperfaceError, match="no vectors to verify"):
        verify_vectors(str(tmp_path))
    with pytest.raises(FileNotFoundError):
        verify_vectors(str(tmp_path / "missing"))
