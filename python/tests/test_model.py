"""The model and the oracle through the package: frame helpers, the slave's
transmissions, grades with clause ids, errors as exceptions."""

import pytest

import hiperface
from hiperface import MalformedRequest, Oracle, ProfileError, Slave

CHAR_US = 1146  # one character at 9600 Bd, 11 bits (000:T28)


def test_checksum_seal_and_validity_follow_000_table_7():
    assert hiperface.checksum(bytes([0x40, 0x42])) == 0x02
    assert hiperface.seal(bytes([0x40, 0x42])) == bytes([0x40, 0x42, 0x02])
    assert hiperface.is_valid(bytes([0x40, 0x42, 0x02]))
    assert not hiperface.is_valid(bytes([0x40, 0x42, 0x03]))
    assert not hiperface.is_valid(b"")


def test_every_bytes_like_object_is_a_frame_and_nothing_else():
    frame = bytes([0x40, 0x42, 0x02])
    for like in (frame, bytearray(frame), memoryview(frame), memoryview(bytearray(b"\x00" + frame))[1:]):
        assert hiperface.checksum(like) == 0x00 and hiperface.is_valid(like)
        assert hiperface.seal(like[:2]) == frame
        assert hiperface.decode_request(like).command == 0x42
        s = Slave("SRS50")
        reply = s.handle_frame(like, 0)
        assert reply is not None
        assert Oracle().grade(Slave("SRS50"), like, 0, bytearray(reply)).verdict == "PASS"
    for wrong in ("40 42 02", [0x40, 0x42, 0x02], 3, None):
        with pytest.raises(TypeError, match="bytes-like object"):
            hiperface.checksum(wrong)


def test_decode_request_and_its_errors_carry_the_slaves_code():
    r = hiperface.decode_request(bytes([0x40, 0x42, 0x02]))
    assert (r.address, r.command, r.data) == (0x40, 0x42, b"")
    for frame, code in [(b"\x40\x42", 0x0C), (b"\x40\x42\x03", 0x0A), (hiperface.seal(b"\x40\x7e"), 0x0B)]:
        with pytest.raises(MalformedRequest) as e:
            hiperface.decode_request(frame)
        assert e.value.args[1] == code, e.value.args


def test_the_slave_answers_read_position_in_its_window():
    s = Slave("SRS50")
    for i, b in enumerate([0x40, 0x42, 0x02]):
        s.receive(b, 1000 + i * CHAR_US)
        assert s.poll(1000 + i * CHAR_US) is None
    tx = s.poll(100_000)
    assert tx is not None and tx.frame[:2] == b"\x40\x42" and hiperface.is_valid(tx.frame)
    assert tx.earliest_start_us < tx.latest_start_us


def test_the_oracle_passes_the_models_reply_and_fails_a_wrong_checksum():
    model, graded = Slave("SRS50"), Slave("SRS50")
    reply = model.handle_frame(b"\x40\x50\x10", 10_000)
    g = Oracle().grade(graded, b"\x40\x50\x10", 10_000, reply)
    assert (g.verdict, g.clause) == ("PASS", "000:T27"), g
    wrong = reply[:-1] + bytes([reply[-1] ^ 1])
    g = Oracle().grade(graded, b"\x40\x50\x10", 30_000, wrong)
    assert (g.verdict, g.clause) == ("FAIL", "000:2.3.3"), g
    assert "checksum" in g.reason


def test_silence_where_a_reply_is_due_fails():
    g = Oracle().grade(Slave("SRS50"), b"\x40\x42\x02", 10_000, None)
    assert g.verdict == "FAIL", g


def test_inputs_reach_the_position():
    s = Slave("SRS50")
    s.set_inputs(position=32 * 1000, temperature_c=40)
    assert s.inputs[0] == 32 * 1000 and s.inputs[2] == 40
    reply = s.handle_frame(b"\x40\x42\x02", 10_000)
    assert int.from_bytes(reply[2:6], "big") == 1000 * 32


def test_profiles_by_name_and_from_toml_with_the_line_and_field(tmp_path, root):
    assert "SEK37" in repr(Slave("SEK37"))
    with pytest.raises(ProfileError):
        Slave("no such profile")
    bad = tmp_path / "bad.toml"
    text = (root / "conformance/tests/independent/hx1.toml").read_text()
    bad.write_text(text.replace("address = 0x40", "address = 0x60", 1))
    with pytest.raises(ProfileError) as e:
        Slave(str(bad))
    assert "bad.toml" in str(e.value) and "address" in str(e.value), e.value


def test_an_unknown_uart_fault_is_a_value_error():
    with pytest.raises(ValueError):
        Slave("SRS50").receive(0x40, 0, fault="static")
    Slave("SRS50").receive(0x40, 0, fault="parity")


def test_every_name_is_the_cores_spelling():
    # One spelling for every front end (reports, C, Python): the names come from the
    # core, in the reports' order, worst verdict first.
    from hiperface._hiperface import CASE_VERDICTS, UART_FAULTS
    from hiperface.report import VERDICTS

    assert VERDICTS == CASE_VERDICTS == (
        "FAIL", "ERROR", "NOT-EXERCISED", "UNKNOWN", "NON-STRICT", "PASS", "NOT-APPLICABLE")
    assert UART_FAULTS == ("parity", "framing", "noise", "overrun")
    for fault in UART_FAULTS:
        # A character with a UART fault ends in 09h for the slave (000:T47).
        slave = Slave("SRS50")
        frame = bytes([0x40, 0x42, 0x02])
        for i, b in enumerate(frame):
            slave.receive(b, (i + 1) * CHAR_US, fault=fault if i == 0 else None)
        t = slave.poll(3 * CHAR_US + 10_000)
        assert t is not None and t.frame[1:3] == b"\x50\x09", (fault, t)
    with pytest.raises(ValueError, match='expected None, "parity", "framing", "noise", "overrun"'):
        Slave("SRS50").receive(0x40, 0, fault="static")
    good = Slave("SRS50").handle_frame(b"\x40\x50\x10", 10_000)
    grades = {Oracle().grade(Slave("SRS50"), b"\x40\x50\x10", 10_000, r).verdict for r in (good, None)}
    assert grades == {"PASS", "FAIL"} and grades <= set(VERDICTS)
