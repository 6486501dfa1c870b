"""``hiperface.certify`` on TINY-PY, a tiny encoder written from the specification alone
(tests/tiny_encoder.py): the conformant encoder passes, each defect FAILs on the
clause it breaks, and the encoder's calling convention is held to."""

import xml.etree.ElementTree as ET

import pytest

import hiperface
from tiny_encoder import DEFECTS, POSITION, TinyEncoder

PROFILE = """\
name = "TINY-PY"
edition = "current"
adjustment = []
stack_order = "oldest-first"

[identity]
type_code = 0x22
option_code = 0x00
serial = "000000001"
firmware = "tiny-python"
firmware_date = "26.11.26"
pinned = []

[interface]
address = 0x40
settings = 0xE4
baud_rates = [1200, 2400, 4800, 9600, 19200, 38400]

[commands]
supported = [0x42, 0x50, 0x52, 0x53]

[memory]
total_blocks = 0x80
user_blocks = 0x70

[resolution]
kind = "rotary"
periods_per_turn = 1024
turns = 1

[limits]
temperature_min_c = -40
temperature_max_c = 115
led_current_max_ma = 50
max_read_speed = 6000

[timing]
init_ms = 100
default_window_ms = 900
user_settings_ms = 1100
adjustment_response_ms = 40
"""

# The clause each defect breaks.
DEFECT_CLAUSES = {
    # 000:2.3.3: "XOR operation on all frame bytes including address".
    "checksum-without-address": "000:2.3.3",
    # 000:T49: an unknown command value draws 0Bh.
    "wrong-unknown-command-code": "000:T49",
    # 000:2.2.2: a request is terminated (and processed) only once no further character
    # came within the timeout; the end of a master transmission is such a pause.
    "no-timeout-wait": "000:2.2.2",
}
assert set(DEFECT_CLAUSES) == set(DEFECTS)


@pytest.fixture
def profile(tmp_path):
    path = tmp_path / "tiny-py.toml"
    path.write_text(PROFILE)
    return str(path)


def fails(report):
    return [(c.id, f) for c in report.cases for f in c.findings if f.verdict == "FAIL"]


def test_the_conformant_encoder_passes(profile):
    # Its shaft stands where the run does not know: physical values are graded by
    # range in-process, as on a real device (any position below 8000h, 000:T11-T12).
    report = hiperface.certify(TinyEncoder(), profile)
    assert report.outcome == "PASSED", fails(report)
    assert report.raw["grading"] == "Range"


def test_the_default_position_is_a_valid_read_position_reply(profile):
    # The grading by range behind the test above: the oracle accepts the encoder's
    # default position, and refuses one past the single turn (000:T11).
    request = bytes([0x40, 0x42, 0x02])
    ok = hiperface.seal(bytes([0x40, 0x42]) + POSITION.to_bytes(4, "big"))
    grade = hiperface.Oracle(exact=False).grade(hiperface.Slave(profile), request, 0, ok)
    assert (grade.verdict, grade.clause) == ("PASS", "000:T12")
    beyond = hiperface.seal(bytes([0x40, 0x42]) + (1024 * 32).to_bytes(4, "big"))
    grade = hiperface.Oracle(exact=False).grade(hiperface.Slave(profile), request, 0, beyond)
    assert (grade.verdict, grade.clause) == ("FAIL", "000:T12")


def test_the_conformant_encoder_with_its_shaft_at_zero_passes_and_writes_its_report(profile, tmp_path):
    encoder = TinyEncoder(position=0)
    report = hiperface.certify(encoder, profile)
    assert report.outcome == "PASSED", fails(report)
    assert report.passed and report.profile == "TINY-PY"
    # Every catalogue case ran; what the profile lacks is not applicable, never unexercised.
    assert {c.verdict for c in report.cases} <= {"PASS", "NOT-APPLICABLE"}
    for id in ("protocol.checksum", "protocol.unknown-command", "protocol.length", "protocol.parity",
               "address.broadcast", "address.other", "powerup.reset", "powerup.window"):
        assert report.case(id).verdict == "PASS"
    assert report.case("settings.temporary").verdict == "NOT-APPLICABLE"  # 67h is not supported
    # The encoder was talked to, and kept to its state machine (000:T9): the catalogue
    # asked during the initialization after an Encoder Reset, and every request that
    # began within the profile's init_ms (100 ms) of a reset's request went unanswered.
    assert len(encoder.log) > 50
    log = encoder.log
    resets = [i for i, (heard, _, _) in enumerate(log) if heard.bytes == b"\x40\x53\x13"]
    in_init = [log[j] for i in resets for j in range(i + 1, len(log))
               if log[j][0].first_us - log[i][0].first_us < 100_000]
    assert resets and in_init and all(reply is None for _, reply, _ in in_init), in_init

    out = report.write(tmp_path / "report")
    names = {"report.json", "junit.xml", "certificate.md", "certificate.html"}
    assert names <= {p.name for p in out.iterdir()}
    assert all((out / n).stat().st_size > 0 for n in names)
    junit = ET.parse(out / "junit.xml").getroot()
    assert len(list(junit.iter("testcase"))) == len(report.cases)
    assert hiperface.read_report(out).outcome == "PASSED"


@pytest.mark.parametrize("defect", sorted(DEFECTS))
def test_each_defect_fails_on_the_clause_it_breaks(profile, defect):
    report = hiperface.certify(TinyEncoder([defect]), profile)
    assert report.outcome == "FAILED"
    clause = DEFECT_CLAUSES[defect]
    found = fails(report)
    assert any(f.clause == clause for _, f in found), found
    assert {f.clause for _, f in found} == {clause}, found
    # The certificate's first section, as report.json has it: the FAIL with its
    # clause's sentence and the request it is about.
    first = [a for a in report.attention if a["verdict"] == "FAIL"]
    assert first and all(a["clause"] == clause and a["clause_text"] for a in first), first
    assert all(a.get("request") for a in first), first
    assert "Findings to read first" in report.files["certificate.md"]


def test_an_encoder_may_be_a_plain_function(profile):
    encoder = TinyEncoder(position=0)
    heard = []

    def answer(h):
        heard.append((h.bytes, h.char_count, h.uart_fault, h.first_us, h.last_us, h.complete_us))
        return encoder.answer(h)

    report = hiperface.certify(answer, profile, cases="protocol.*")
    assert report.outcome == "PASSED", fails(report)
    assert heard
    # Each request is handed over once the timeout after its last character has passed.
    for data, count, _, first, last, complete in heard:
        assert count == len(data) and first <= last < complete


def test_an_exception_in_the_encoder_is_raised_from_certify(profile):
    class Broken(Exception):
        pass

    def broken(heard):
        raise Broken("the encoder fell over")

    with pytest.raises(Broken, match="fell over"):
        hiperface.certify(broken, profile)


@pytest.mark.parametrize(
    "returned",
    ["40 42 02", 42, (b"\x40\x50\x0b\x1b",), [b"\x40\x50\x0b\x1b", 20_000], ("reply", 20_000),
     (b"\x40\x50\x0b\x1b", "soon"), (b"\x40\x50\x0b\x1b", 20_000, 0xE4, "extra")],
)
def test_an_invalid_return_value_is_a_type_error(profile, returned):
    with pytest.raises(TypeError):
        hiperface.certify(lambda heard: returned, profile)


def test_an_object_without_answer_is_a_type_error(profile):
    with pytest.raises(TypeError, match="answer"):
        hiperface.certify(object(), profile)


def test_a_world_given_to_certify_is_graded_exactly(profile):
    # The encoder's sensor reads 120 °C, above its 115: told so, the run grades every
    # value exactly, 1Eh on Read Encoder Status and the warning bit on every reply
    # (000:T59, 000:2.3.4).
    world = {"position": POSITION, "temperature_c": 120}
    hot = TinyEncoder(temperature_c=120)
    report = hiperface.certify(hot, profile, world=world)
    assert report.outcome == "PASSED", fails(report)
    assert report.raw["grading"] == "Exact"
    assert report.case("identity.status").verdict == "PASS"
    assert any(reply and reply[1:3] == b"\xd0\x1e" for _, reply, _ in hot.log), "1Eh was never read"
    # The encoder that never looks at its temperature: FAILED on exactly those rules.
    deaf = TinyEncoder(temperature_c=120, watches_temperature=False)
    report = hiperface.certify(deaf, profile, world=world)
    assert report.outcome == "FAILED"
    assert {f.clause for _, f in fails(report)} == {"000:T27", "000:2.3.4"}, fails(report)
    # Without the world the run cannot know the heat: graded by range, it passes.
    assert hiperface.certify(TinyEncoder(temperature_c=120, watches_temperature=False), profile).outcome == "PASSED"


@pytest.mark.parametrize(
    "world, error",
    [
        ({"temperature": 120}, "world: unknown key `temperature`"),
        ({"init_faults": ["dog"]}, "world: unknown start-up fault `dog`"),
        ({"position_faults": ["watchdog"]}, "world: unknown position fault `watchdog`"),
    ],
)
def test_a_world_that_does_not_read_is_refused(profile, world, error):
    with pytest.raises(ValueError, match=error):
        hiperface.certify(TinyEncoder(), profile, world=world)


def test_the_error_stack_and_warning_bit_of_the_encoder_itself():
    # The stack's rules one by one, faults raised directly: 000:2.3.4 warning bit, 000:T27 stack of four, stored once,
    # the oldest dropped and read first; an Encoder Reset clears it.
    from types import SimpleNamespace

    t = [0]

    def heard(frame):
        t[0] += 100_000
        return SimpleNamespace(bytes=frame, char_count=len(frame), uart_fault=None,
                               first_us=t[0], last_us=t[0] + 1146 * (len(frame) - 1),
                               complete_us=t[0] + 1146 * (len(frame) - 1) + 5730)

    enc = TinyEncoder()
    for code in (0x1E, 0x1F, 0x1E, 0x1D, 0x08, 0x1C):
        enc.raise_fault(code)
    reply, _ = enc.answer(heard(b"\x40\x42\x02"))
    assert reply[1] == 0xC2 and hiperface.is_valid(reply)  # warning bit on Read Position
    read = []
    for _ in range(5):
        reply, _ = enc.answer(heard(b"\x40\x50\x10"))
        assert hiperface.is_valid(reply)
        read.append((reply[1], reply[2]))
    assert read == [(0xD0, 0x1F), (0xD0, 0x1D), (0xD0, 0x08), (0x50, 0x1C), (0x50, 0x00)]
    enc.raise_fault(0x1E)
    assert enc.answer(heard(b"\x40\x53\x13")) is None
    reset_us = t[0] + 2 * 1146 + 5730  # executed once the request's timeout is over (000:T29)
    t[0] = reset_us - 100_000 + 50_000
    assert enc.answer(heard(b"\x40\x50\x10")) is None  # initialization (000:T9)
    t[0] = reset_us - 100_000 + 1_000_000
    assert enc.answer(heard(b"\x40\x50\x10")) is None  # no request in the window: changing
    t[0] = reset_us - 100_000 + 1_100_000
    reply, _ = enc.answer(heard(b"\x40\x50\x10"))  # the stored settings, stack cleared
    assert reply == b"\x40\x50\x00\x10"


@pytest.mark.parametrize(
    "glob, chosen",
    [
        ("{protocol.checksum,identity.status}", ["identity.status", "protocol.checksum"]),
        ("protocol.{checksum,length}", ["protocol.checksum", "protocol.length"]),
        ("protocol.*, !protocol.{parity,argument,unknown-command}", ["protocol.checksum", "protocol.length"]),
    ],
)
def test_case_globs_take_braces_commas_and_exclusions(profile, glob, chosen):
    """The command line's grammar (docs: command-line.md, selecting cases)."""
    report = hiperface.certify(TinyEncoder(position=POSITION), profile, cases=glob)
    assert sorted(c.id for c in report.cases) == chosen


def test_a_glob_whose_braces_do_not_pair_selects_nothing_and_is_refused(profile):
    with pytest.raises(ValueError, match="no case matches"):
        hiperface.certify(TinyEncoder(position=POSITION), profile, cases="{protocol.checksum")


def test_the_catalogues_are_what_list_prints():
    slave, master = hiperface.catalogue("slave"), hiperface.catalogue("master")
    assert slave.startswith("| id | what it checks | clauses |") and "| `identity.type-label` |" in slave
    assert "| `startup.default` |" in master
    with pytest.raises(ValueError, match="expected `slave` or `master`"):
        hiperface.catalogue("drive")
