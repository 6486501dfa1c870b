"""A certification's ``report.json`` (``hiperface certify slave|master --report DIR``)
as Python objects: the cases (or a master's scenarios) with their verdicts and
findings, each finding with the clause it rests on."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Union

#: Verdicts from worst to best, as the reports spell them.
VERDICTS = ("FAIL", "ERROR", "NOT-EXERCISED", "UNKNOWN", "NON-STRICT", "PASS", "NOT-APPLICABLE")


@dataclass(frozen=True)
class Finding:
    verdict: str
    message: str
    #: The clause id ("000:T26"), empty where the finding rests on none.
    clause: str


@dataclass(frozen=True)
class Case:
    id: str
    title: str
    verdict: str
    clauses: List[str]
    findings: List[Finding]


@dataclass(frozen=True)
class Report:
    #: "slave" (certify slave) or "master" (certify master).
    kind: str
    tool: str
    profile: str
    cases: List[Case]
    summary: Dict[str, int]
    #: The whole JSON document, for what these fields leave out.
    raw: Dict[str, Any] = field(repr=False)

    @property
    def passed(self) -> bool:
        """PASSED as the command's exit code says: cases run, none FAILed or left
        ungraded (NON-STRICT and NOT-APPLICABLE do not stop a pass)."""
        bad = {"FAIL", "ERROR", "NOT-EXERCISED", "UNKNOWN"}
        cut_short = self.raw.get("aborted") or self.raw.get("cut_short")
        return bool(self.cases) and not cut_short and not any(c.verdict in bad for c in self.cases)

    def case(self, id: str) -> Case:
        """The case (or scenario) with this id; KeyError if there is none."""
        for c in self.cases:
            if c.id == id:
                return c
        raise KeyError(id)


def _case(c: Dict[str, Any]) -> Case:
    findings = [Finding(f.get("verdict", ""), f.get("message", ""), f.get("clause") or "") for f in c.get("findings", [])]
    clauses = c.get("clauses", [])
    if isinstance(clauses, str):
        clauses = [x.strip() for x in clauses.split(",") if x.strip()]
    return Case(c["id"], c.get("title", ""), c["verdict"], list(clauses), findings)


def read_report(path: Union[str, Path]) -> Report:
    """Read ``report.json`` (or the directory that holds it). Raises ValueError naming
    the file and what is missing for a file that is not a certification report."""
    p = Path(path)
    if p.is_dir():
        p = p / "report.json"
    doc = json.loads(p.read_text())
    if not isinstance(doc, dict):
        raise ValueError(f"{p}: not a certification report (a JSON object is expected)")
    if "cases" in doc:
        kind, items = "slave", doc["cases"]
    elif "scenarios" in doc:
        kind, items = "master", doc["scenarios"]
    else:
        raise ValueError(f"{p}: not a certification report (no `cases` nor `scenarios`)")
    try:
        cases = [_case(c) for c in items]
    except KeyError as e:
        raise ValueError(f"{p}: a case without {e}") from None
    return Report(kind, doc.get("tool", ""), doc.get("profile", ""), cases, dict(doc.get("summary", {})), doc)
