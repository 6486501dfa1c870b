"""A capture file graded through the package as `hiperface decode` grades it."""

import json
import subprocess

import pytest

from hiperface import HiperfaceError, Listening, ProfileError, decode, read_report

# 9600 Bd: each request's timeout has passed 7 ms after its last stop bit (000:2.2.2).
# Read Position answered (any position passes: the listener does not know the shaft);
# Read Encoder Status answered with a wrong checksum (000:2.3.3).
LOG = """\
   10.000 ms  M> 40 42 02
   17.000 ms  S< 40 42 00 00 00 00 02
  100.000 ms  M> 40 50 10
  107.000 ms  S< 40 50 00 11
"""


def test_each_exchange_is_graded_with_its_findings(tmp_path):
    capture = tmp_path / "bus.log"
    capture.write_text(LOG)
    heard = decode(capture)
    assert isinstance(heard, Listening)
    assert (heard.outcome, heard.verdict, heard.passed) == ("FAILED", "FAIL", False)
    first, second = heard.exchanges
    assert first.request == bytes([0x40, 0x42, 0x02]) and first.reply == bytes.fromhex("40420000000002")
    assert "Read Position" in first.command and first.verdict == "PASS" and first.findings == []
    assert second.verdict == "FAIL" and [f.clause for f in second.findings] == ["000:2.3.3"]
    assert "checksum" in second.findings[0].message
    assert heard.summary["exchanges"] == 2 and heard.summary["verdicts"] == {"FAIL": 1, "PASS": 1}


def test_exchanges_can_be_handed_over_as_heard(tmp_path):
    capture = tmp_path / "bus.log"
    capture.write_text(LOG)
    seen = []
    heard = decode(capture, on_exchange=seen.append)
    assert [e.verdict for e in seen] == ["PASS", "FAIL"] and heard.exchanges == []

    def stop(_):
        raise RuntimeError("the bench stops here")

    with pytest.raises(RuntimeError, match="the bench stops here"):
        decode(capture, on_exchange=stop)


def test_nothing_graded_is_not_passed(tmp_path):
    capture = tmp_path / "unanswered.log"
    capture.write_text("   10.000 ms  M> 40 42 02\n")
    heard = decode(capture)
    assert heard.outcome == "INCOMPLETE" and not heard.passed
    assert heard.exchanges[0].verdict == "UNKNOWN" and heard.exchanges[0].reply is None
    assert "nothing could be graded" in heard.incomplete


def test_input_it_cannot_read_is_a_clear_error(tmp_path):
    capture = tmp_path / "garbage.log"
    capture.write_text("garbage\n")
    with pytest.raises(HiperfaceError, match="garbage.log: line 1: cannot tell the format"):
        decode(capture)
    # A missing file is FileNotFoundError, as everywhere in the package.
    with pytest.raises(FileNotFoundError, match="no-such-file"):
        decode(tmp_path / "no-such-file.log")
    with pytest.raises(FileNotFoundError):
        read_report(tmp_path / "no-such-report.json")
    with pytest.raises(ValueError, match="format `pcap`"):
        decode(capture, format="pcap")
    with pytest.raises(FileNotFoundError, match="missing.toml"):
        decode(capture, profile=str(tmp_path / "missing.toml"))
    (tmp_path / "broken.toml").write_text("name = ")
    with pytest.raises(ProfileError, match="broken.toml"):
        decode(capture, profile=str(tmp_path / "broken.toml"))
    with pytest.raises(ValueError, match="polling_period_ms: at least 1 ms"):
        decode(capture, polling_period_ms=0)


def test_the_same_verdicts_as_the_command(tmp_path, hiperface_bin):
    """The main job's wire log (a certify report) decoded by the package and by
    `hiperface decode --report`: the same outcome, counts and first non-PASS exchanges;
    read_report reads the command's listening report as a Listening."""
    run = subprocess.run(
        [str(hiperface_bin), "certify", "slave", "--port", "sim", "--tolerance-ms", "20", "--report", str(tmp_path / "c")],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    wire_log = tmp_path / "c" / "report.json"
    run = subprocess.run(
        [str(hiperface_bin), "decode", str(wire_log), "--listen", "--quiet", "--report", str(tmp_path / "d")],
        capture_output=True,
        text=True,
    )
    assert run.returncode in (0, 1), run.stdout + run.stderr
    command = json.loads((tmp_path / "d" / "report.json").read_text())
    heard = decode(wire_log)
    assert (heard.outcome, heard.verdict) == (command["outcome"], command["verdict"])
    for key in ("characters", "exchanges", "verdicts", "per_command", "master", "unattributed"):
        assert heard.summary[key] == command["summary"][key], key
    assert len(heard.exchanges) == command["summary"]["exchanges"] > 100
    read = read_report(tmp_path / "d")
    assert isinstance(read, Listening) and read.outcome == heard.outcome
    kept = [e for e in heard.exchanges if e.verdict != "PASS"][: len(read.exchanges)]
    assert read.exchanges == kept
