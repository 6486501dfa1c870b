"""A master written in Python certified in-process, in virtual time
(``hiperface.certify_master``): HX-M, the independent master written from 000 alone
(conformance/tests/independent/hx_master.py), on a virtual line instead of a
pseudo-terminal. The same catalogue, verdicts and clauses as ``certify master --exec``
gives it (conformance/tests/certify_master.rs, DEFECTS): it passes every scenario, and
each defect switch is caught in the same scenario, on the same clause, with the same
verdict; a scenario the defect does not touch stays PASS."""

from __future__ import annotations

import json
import subprocess
import xml.etree.ElementTree as ET

import pytest

import hiperface
from hx_master_in_process import HxMaster


def certify(master: HxMaster, **kwargs) -> hiperface.Report:
    try:
        return hiperface.certify_master(master, "SRS50", **kwargs)
    finally:
        master.close()


def test_the_independent_master_passes_every_scenario_in_virtual_time(tmp_path):
    report = certify(HxMaster())
    assert report.kind == "master"
    assert len(report.cases) == 22
    assert report.outcome == "PASSED", [(c.id, c.verdict, c.findings) for c in report.cases if c.verdict != "PASS"]
    assert all(c.verdict == "PASS" for c in report.cases)
    written = report.write(tmp_path)
    suites = ET.parse(written / "junit.xml").getroot()
    assert int(suites.get("tests")) == 22 and int(suites.get("failures")) == 0
    assert "HIPERFACE master certificate" in (written / "certificate.md").read_text()


def test_the_independent_master_set_for_user_settings_passes_that_scenario():
    # HX-M as a drive configured for 38400 Bd: it waits out the default window and talks
    # at the encoder's stored data rate (000:3.3.1).
    report = certify(HxMaster(user_baud=38400), scenarios="startup.user-settings")
    case = report.case("startup.user-settings")
    assert case.verdict == "PASS", case.findings
    wire = report.raw["scenarios"][0]["wire"]
    assert any(w["direction"] == "M>" and w["t_us"] > 1_100_000 for w in wire)


# (defect, HX-M's options, scenario, clause, verdict there, a scenario it leaves PASS)
DEFECTS = [
    ("talks-during-init", {}, "startup.default", "000:3.3.1", "FAIL", None),
    ("settings-window", {}, "startup.default", "000:3.3.1", "FAIL", None),
    ("no-pause", {}, "startup.default", "000:2.2.2/master-pause", "FAIL", None),
    ("gap-in-request", {}, "startup.default", "000:2.2.2/master-gap", "FAIL", None),
    ("wrong-checksum", {}, "startup.default", "000:2.3/master", "FAIL", None),
    ("ignores-warning", {}, "warning.one-code", "000:2.3.4/warning", "NON-STRICT", "startup.default"),
    ("ignores-sync-fault", {}, "fault.multiturn-sync", "000:3.3.4", "NON-STRICT", "startup.default"),
    ("retries-forever", {}, "fault.singleturn-persistent", "000:3.3.4", "NON-STRICT", "startup.default"),
    ("no-reset-wait", {}, "fault.critical-at-start", "000:T29/master", "FAIL", "startup.default"),
    ("no-retry", {}, "protocol.checksum-error", "000:3.3.4", "NON-STRICT", "startup.default"),
    ("ignores-extended-type-label", {}, "startup.extended-type-label", "000:T19/master", "NON-STRICT", "startup.default"),
    ("no-baud", {}, "startup.default", "000:3.3.1", "FAIL", None),
    ("user-baud-early", {"user_baud": 38400}, "startup.user-settings", "000:3.3.1", "FAIL", None),
    ("late-default", {}, "startup.user-settings", "000:3.3.1", "FAIL", "startup.default"),
    ("sparse-poll", {}, "polling.long", "000:3.2.2/cyclic", "NON-STRICT", None),
    ("receive-idle", {}, "reply.gap-under-timeout", "000:2.2/cycle", "FAIL", "startup.default"),
    ("naive-poll", {}, "startup.default", "000:3.3.1/status", "NON-STRICT", None),
]


@pytest.mark.parametrize("defect,options,scenario,clause,verdict,untouched", DEFECTS, ids=[d[0] for d in DEFECTS])
def test_each_defect_of_the_independent_master_is_caught_where_the_command_catches_it(
    defect, options, scenario, clause, verdict, untouched
):
    globs = scenario if untouched is None else f"{scenario},{untouched}"
    report = certify(HxMaster(defect, **options), scenarios=globs)
    case = report.case(scenario)
    assert case.verdict == verdict, (defect, case.findings)
    assert any(f.verdict == verdict and f.clause == clause for f in case.findings), (defect, case.findings)
    if untouched is not None:
        assert report.case(untouched).verdict == "PASS", (defect, report.case(untouched).findings)
    assert report.outcome == ("FAILED" if verdict == "FAIL" else "PASSED")


def test_decode_takes_an_in_process_run_in_again_with_every_verdict(tmp_path, hiperface_bin):
    report = certify(HxMaster("no-reset-wait"))
    assert report.outcome == "FAILED"
    written = report.write(tmp_path)
    assert json.loads((written / "report.json").read_text())["record"]["format"] == "hiperface-master-record/1"
    run = subprocess.run([str(hiperface_bin), "decode", str(written / "report.json"), "--quiet"], capture_output=True, text=True)
    assert run.returncode == 1, run.stderr
    assert "every verdict as the report states it" in run.stdout, run.stdout


def test_a_master_that_raises_has_its_exception_raised_after_the_run():
    class Broken:
        def step(self, now_us, heard):
            raise ZeroDivisionError("the master's own bug")

    with pytest.raises(ZeroDivisionError, match="own bug"):
        hiperface.certify_master(Broken(), scenarios="startup.default")


def test_what_a_master_returns_is_checked():
    class Wrong:
        def step(self, now_us, heard):
            return "send something"

    with pytest.raises(TypeError, match="step returns None"):
        hiperface.certify_master(Wrong(), scenarios="startup.default")
    with pytest.raises(ValueError, match="no scenario matches"):
        hiperface.certify_master(lambda now_us, heard: None, scenarios="nothing.*")
    with pytest.raises(TypeError, match="a master is a callable"):
        hiperface.certify_master(object())


def test_a_master_given_as_a_callable_with_bytes_like_data_is_graded():
    # The smallest master: after initialization and the settings window, Read Position
    # once every 100 ms with a memoryview; it never reads the status (NON-STRICT) nor
    # reacts to anything, and it is graded on what it did.
    frame = memoryview(bytes([0x40, 0x42, 0x40 ^ 0x42]))
    due = {"us": 150_000}

    def master(now_us, heard):
        if now_us < due["us"]:
            return due["us"]
        due["us"] = now_us + 100_000
        return (frame, now_us, due["us"])

    report = hiperface.certify_master(master, scenarios="startup.default", name="smallest")
    assert report.raw["master"] == "smallest"
    case = report.case("startup.default")
    assert case.verdict == "NON-STRICT", case.findings
    assert any(f.clause == "000:3.3.1/status" for f in case.findings)


def test_a_master_that_declares_it_never_reads_data_fields_is_passed_on_that_declaration(tmp_path, hiperface_bin):
    # HX-M with ignores-extended-type-label never sends 4Ah Read Data: declared, the
    # scenarios about data fields are NOT-APPLICABLE, and the run is PASSED.
    report = certify(HxMaster("ignores-extended-type-label"), not_used=["4Ah"])
    assert report.outcome == "PASSED", [(c.id, c.verdict) for c in report.cases if c.verdict != "PASS"]
    for id in ("startup.extended-type-label", "fault.data-field"):
        case = report.case(id)
        assert case.verdict == "NOT-APPLICABLE", case.findings
        assert "declared not used" in case.findings[0].message
    assert report.raw["not_used"] == ["4Ah Read Data"]
    assert "| declared not used | 4Ah Read Data" in report.files["certificate.md"]
    # decode takes the declaration in with the record.
    written = report.write(tmp_path)
    run = subprocess.run([str(hiperface_bin), "decode", str(written / "report.json"), "--quiet"], capture_output=True, text=True)
    assert run.returncode == 0 and "every verdict as the report states it" in run.stdout, run.stdout + run.stderr
    # Undeclared, the same master is INCOMPLETE: what the run never saw is no pass.
    assert certify(HxMaster("ignores-extended-type-label")).outcome == "INCOMPLETE"


def test_a_declaration_the_master_contradicts_is_unknown_where_it_does():
    # HX-M reads the position all the time; declared never to send 42h, it is caught.
    report = certify(HxMaster(), scenarios="startup.default,reply.silent", not_used=[0x42])
    assert report.case("reply.silent").verdict == "NOT-APPLICABLE"
    case = report.case("startup.default")
    assert case.verdict == "UNKNOWN", case.findings
    assert any("declared it never sends it" in f.message for f in case.findings)
    assert report.outcome == "INCOMPLETE"
    with pytest.raises(ValueError, match="not a HIPERFACE command"):
        hiperface.certify_master(HxMaster(), not_used=[0x99])
