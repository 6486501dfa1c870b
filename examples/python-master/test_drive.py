"""A drive team's CI test (docs/src/ci-recipes.md, the Python master): the drive's
HIPERFACE master certified in-process with the whole scenario catalogue, in virtual
time, by pytest (``hiperface.certify_master``). The report is written for the CI to
keep (report.json, junit.xml, certificate.md, certificate.html).

The master here is HX-M, the repository's independent master, on the virtual line
(python/tests/hx_master_in_process.py); in your repository it is your drive's master:
an object with ``power_on()`` and ``step(now_us, heard)`` (docs/src/from-python.md).
``DRIVE_DEFECT`` switches one of HX-M's defects on (``wrong-checksum``, ...): the test
then fails, which shows that the gate can."""

import os
import sys
from pathlib import Path

import hiperface

REPO = Path(os.environ.get("HIPERFACE_SRC", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(REPO / "python" / "tests"))
from hx_master_in_process import HxMaster  # noqa: E402


def test_the_drive_passes_every_scenario():
    drive = HxMaster(os.environ.get("DRIVE_DEFECT") or None)
    try:
        report = hiperface.certify_master(drive, "SRS50")
    finally:
        drive.close()
    report.write(os.environ.get("HIPERFACE_REPORT", "master-report"))
    failed = [(c.id, c.verdict, [(f.clause, f.message) for f in c.findings]) for c in report.cases if c.verdict != "PASS"]
    assert report.outcome == "PASSED", failed
