"""The certification report reader on a report the command wrote."""

import subprocess

import pytest

from hiperface import read_report


def test_a_certification_report_reads_as_objects(tmp_path, hiperface_bin):
    run = subprocess.run(
        [str(hiperface_bin), "certify", "slave", "--port", "sim", "--tolerance-ms", "20", "--report", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    r = read_report(tmp_path)
    assert r.kind == "slave" and r.passed and r.profile == "SRS50"
    assert r.summary.get("PASS", 0) == sum(c.verdict == "PASS" for c in r.cases)
    parity = r.case("protocol.parity")
    assert parity.verdict == "NOT-APPLICABLE" and "parity" in parity.findings[0].message
    with pytest.raises(KeyError):
        r.case("no.such.case")


def test_a_file_that_is_no_report_is_a_clear_error(tmp_path):
    f = tmp_path / "report.json"
    f.write_text("[]")
    with pytest.raises(ValueError, match="not a certification report"):
        read_report(f)
