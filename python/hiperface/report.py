"""A certification's ``report.json`` (``hiperface certify slave|master --report DIR``)
as Python objects: the cases (or a master's scenarios) with their verdicts and
findings, each finding with the clause it rests on. A listening run's report
(``hiperface decode|monitor --report DIR``, or ``decode`` here) reads as a
``Listening``: the exchanges heard, each graded with its findings."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Union

from ._hiperface import CASE_VERDICTS

#: Verdicts from worst to best, as the reports spell them (the core's names).
VERDICTS = CASE_VERDICTS


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
    #: The report's files as the command writes them ("report.json", "junit.xml",
    #: "certificate.md", "certificate.html"): a report from ``certify`` has them all.
    files: Dict[str, str] = field(default_factory=dict, repr=False)

    @property
    def outcome(self) -> str:
        """"PASSED", "FAILED" (a case FAILed) or "INCOMPLETE" (nothing failed, but not
        everything was observed), as the command's last line says."""
        stated = self.raw.get("outcome")
        if isinstance(stated, str):
            return stated
        if any(c.verdict == "FAIL" for c in self.cases):
            return "FAILED"
        return "PASSED" if self.passed else "INCOMPLETE"

    @property
    def attention(self) -> List[Dict[str, Any]]:
        """The findings the certificate puts first (FAILs, then ERRORs, NOT-EXERCISED
        and UNKNOWNs), each with its case, clause and the clause's sentence, the request
        and reply it is about and the figure against its limit, as in report.json."""
        return list(self.raw.get("attention", []))

    def write(self, directory: Union[str, Path]) -> Path:
        """Write the report's files into ``directory`` (created if need be), as
        ``hiperface certify slave --report DIR`` does; returns the directory. A report
        read from a file has only its JSON: ValueError."""
        if not self.files:
            raise ValueError("a report read from report.json has only its JSON; certify() gives every file")
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        for name, text in self.files.items():
            (d / name).write_text(text)
        return d

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
    findings = [_finding(f) for f in c.get("findings", [])]
    clauses = c.get("clauses", [])
    if isinstance(clauses, str):
        clauses = [x.strip() for x in clauses.split(",") if x.strip()]
    return Case(c["id"], c.get("title", ""), c["verdict"], list(clauses), findings)


def _slave_report(doc: Dict[str, Any], files: Dict[str, str]) -> Report:
    cases = [_case(c) for c in doc["cases"]]
    return Report("slave", doc.get("tool", ""), doc.get("profile", ""), cases, dict(doc.get("summary", {})), doc, files)


def certify(
    encoder: Any,
    profile: str = "SRS50",
    *,
    cases: Optional[str] = None,
    skip_writes: bool = False,
    skip_counter_change: bool = False,
    world: Optional[Mapping[str, Any]] = None,
) -> Report:
    """Certify an encoder written in Python with the whole slave catalogue, in
    virtual time, in-process: the same cases, verdicts and report as ``hiperface
    certify slave``. ``encoder`` is a callable, or an object with an ``answer``
    method, handed each request as a ``Heard`` (its bytes, UART fault and times in
    µs, once the character timeout after its last character has passed, 000:2.2.2);
    it returns None (silence) or ``(reply, start_us)`` (a bytes-like reply, the time
    its first character starts), or ``(reply, start_us, then_settings)`` with the
    settings byte it listens with afterwards (67h, 000:T33; the default settings kept
    by a request in the default window, 000:T9), taken up once the reply is out, or
    ``(reply, start_us, then_settings, restarts)``: after an Encoder Reset (000:T29)
    ``restarts`` is True and the UART follows the profile's power-up windows
    (000:T9: not listening during the initialization, the default settings in the
    default window, then ``then_settings``, the stored ones) until an answer names
    settings again. It listens from the start in the profile's stored settings, past
    its power-up. Physical values are graded by range, as on a real device, unless
    ``world`` says what world the encoder was put in: then every value is graded
    exactly, the warning bit and the error stack included (a temperature outside the
    profile's limits raises 1Eh before every reply, 000:T59). ``world`` is a dict of
    ``position``, ``speed``, ``temperature_c``, ``led_current_ma`` (the physical
    inputs; defaults 25 °C, 10 mA, the shaft at 0 and at rest), ``init_faults`` and
    ``position_faults`` (lists of names as ``hiperface simulate --init-fault``
    spells them) and ``i2c_fault``. A data field the run creates and reads before writing is expected to hold
    FFh (erased EEPROM, the project's decision DESIGN:fields): other bytes there are
    NON-STRICT, never FAIL. ``profile``: a built-in name or a profile's TOML
    file. ``cases``: only the cases whose id matches this glob. EEPROM writes and
    counter changes run unless skipped. An exception the encoder raises ends the run's
    answers (silence) and is raised when the run is over."""
    from ._hiperface import certify_encoder

    texts = certify_encoder(
        encoder,
        profile,
        cases=cases,
        skip_writes=skip_writes,
        skip_counter_change=skip_counter_change,
        world=world,
    )
    names = ("report.json", "junit.xml", "certificate.md", "certificate.html")
    files = dict(zip(names, texts))
    files["report.json"] += "\n"
    return _slave_report(json.loads(texts[0]), files)


def certify_master(
    master: Any,
    profile: str = "SRS50",
    *,
    scenarios: Optional[str] = None,
    polling_period_ms: int = 1000,
    name: Optional[str] = None,
    not_used: Optional[List[Union[int, str]]] = None,
) -> Report:
    """Certify a master (a drive's HIPERFACE side) written in Python with the scenario
    catalogue, in virtual time, in-process: the same scenarios, encoder, verdicts and
    report as ``hiperface certify master --exec``, without a pseudo-terminal or a
    process. Each scenario powers the encoder and the master on at time 0: the master's
    ``power_on()`` is called (if it has one), then ``step(now_us, heard)`` (or the
    master itself, if callable): once at power-on (``now_us`` 0, nothing heard), once
    for each character of the encoder's replies as its stop bit ends (``heard``: one
    ``(byte, end_us)`` pair, ``now_us`` its end), and at the time it asked for when no
    character came first (a time not after now: 1 µs from now). ``step`` returns None
    (nothing new: a time asked for earlier still stands), a time in µs (be called again
    then, replacing the one asked before), or ``(data, start_us[, wake_us[, bps]])``:
    bytes-like data whose first character starts at ``start_us`` (no earlier than now,
    nor than the end of what it sent before), sent at
    ``bps`` (9600 unless given: the encoder's delivery rate, 000:T7). ``profile``: the
    encoder's, a built-in name or a profile's TOML file; ``scenarios``: only those whose
    id matches this glob; ``polling_period_ms``: the application's polling period
    (000:3.2.2; 1000 ms unless given, as the command); ``not_used``: the commands the
    master declares it never sends (``[0x4A]`` or ``["4Ah"]``), whose scenarios are then
    NOT-APPLICABLE, "declared not used", as ``--not-used`` does. An exception the master raises ends its actions and is raised when the
    run is over. The report's ``kind`` is "master"; ``write(dir)`` writes its files."""
    from ._hiperface import certify_master_in_process

    texts = certify_master_in_process(
        master, profile, scenarios=scenarios, polling_period_ms=polling_period_ms, name=name, not_used=not_used
    )
    names = ("report.json", "junit.xml", "certificate.md", "certificate.html")
    files = dict(zip(names, texts))
    files["report.json"] += "\n"
    doc = json.loads(texts[0])
    cases = [_case(c) for c in doc["scenarios"]]
    return Report("master", doc.get("tool", ""), doc.get("profile", ""), cases, dict(doc.get("summary", {})), doc, files)


def read_report(path: Union[str, Path]) -> Union[Report, "Listening"]:
    """Read ``report.json`` (or the directory that holds it): a ``Report`` of a
    certification, a ``Listening`` of ``decode`` or ``monitor``. Raises ValueError
    naming the file and what is missing for a file that is neither."""
    p = Path(path)
    if p.is_dir():
        p = p / "report.json"
    doc = json.loads(p.read_text())
    if not isinstance(doc, dict):
        raise ValueError(f"{p}: not a certification report (a JSON object is expected)")
    if "capture" in doc and "summary" in doc and "cases" not in doc:
        try:
            kept = [_exchange(e) for e in doc["summary"].get("exchanges_kept", [])]
            return _listening(doc, kept)
        except (KeyError, TypeError) as e:
            raise ValueError(f"{p}: a listening report without {e}") from None
    if "cases" in doc:
        kind, items = "slave", doc["cases"]
    elif "scenarios" in doc:
        kind, items = "master", doc["scenarios"]
    else:
        raise ValueError(f"{p}: not a certification report (no `cases`, `scenarios` nor `capture`)")
    try:
        cases = [_case(c) for c in items]
    except KeyError as e:
        raise ValueError(f"{p}: a case without {e}") from None
    return Report(kind, doc.get("tool", ""), doc.get("profile", ""), cases, dict(doc.get("summary", {})), doc)


@dataclass(frozen=True)
class Exchange:
    """One exchange heard on the bus: the master's request, the encoder's reply (None:
    silence), graded as a listener grades it."""

    #: End of the request, ms from the capture's start.
    t_ms: float
    #: The command's name ("Read Position").
    command: str
    request: bytes
    reply: Optional[bytes]
    #: From the end of the request's timeout to the reply's first start bit, ms.
    response_ms: Optional[float]
    verdict: str
    findings: List[Finding]


@dataclass(frozen=True)
class Listening:
    """A listening run (``hiperface decode`` of a capture, ``monitor`` of a live bus)."""

    tool: str
    capture: str
    profile: str
    #: The worst verdict heard.
    verdict: str
    #: "PASSED", "FAILED" or "INCOMPLETE" (nothing graded, or what could not be).
    outcome: str
    #: Why the run is not PASSED, where that is not a FAIL.
    incomplete: Optional[str]
    #: Every exchange heard (``decode``), or the first ones that were not PASS (a
    #: report read from a file keeps only those).
    exchanges: List[Exchange]
    #: Counts: characters, exchanges, verdicts, per command, the master's rules, ...
    summary: Dict[str, Any]
    raw: Dict[str, Any] = field(repr=False)

    @property
    def passed(self) -> bool:
        """PASSED as the command's exit code says."""
        return self.outcome == "PASSED"


def _bytes(text: Any) -> Optional[bytes]:
    try:
        return bytes.fromhex(text) if isinstance(text, str) else None
    except ValueError:
        return None


def _finding(f: Dict[str, Any]) -> Finding:
    return Finding(f.get("verdict", ""), f.get("message", ""), f.get("clause") or "")


def _exchange(e: Dict[str, Any]) -> Exchange:
    return Exchange(
        e["t_ms"],
        e["command"],
        _bytes(e["request"]) or b"",
        _bytes(e.get("reply")),
        e.get("response_ms"),
        e["verdict"],
        [_finding(f) for f in e.get("findings", [])],
    )


def _listening(doc: Dict[str, Any], exchanges: List[Exchange]) -> Listening:
    return Listening(
        doc.get("tool", ""),
        doc["capture"],
        doc.get("profile", ""),
        doc["verdict"],
        doc["outcome"],
        doc.get("incomplete"),
        exchanges,
        dict(doc.get("summary", {})),
        doc,
    )


def decode(
    path: Union[str, Path],
    *,
    profile: str = "SRS50",
    baud: int = 9600,
    format: Optional[str] = None,
    samplerate: Optional[int] = None,
    tolerance_ms: Optional[float] = None,
    master_channel: Optional[str] = None,
    polling_period_ms: Optional[int] = None,
    on_exchange: Optional[Callable[[Exchange], None]] = None,
) -> Listening:
    """Grade a capture file as ``hiperface decode`` does: a wire log (a certify
    report's ``report.json``, ``hiperface monitor --capture``), a logic analyser's CSV
    export or sigrok-cli's UART decoder output. ``format``: None detects it
    ("wirelog", "csv", "sigrok"). Every exchange is graded (000:2.2.2 timing, the
    oracle's reply grades, the master's rules); with ``on_exchange`` each is handed
    over as it is heard instead of kept in ``exchanges`` (a long capture).
    Raises ``FileNotFoundError`` for a missing capture or profile file,
    ``HiperfaceError`` naming the file and line for input that cannot be read,
    ``ProfileError`` for a profile file that does not load."""
    from ._hiperface import decode_capture

    kept: List[Exchange] = []
    take = on_exchange if on_exchange is not None else kept.append
    text = decode_capture(
        str(path),
        lambda e: take(_exchange(json.loads(e))),
        profile=profile,
        baud=baud,
        format=format,
        samplerate=samplerate,
        tolerance_ms=tolerance_ms,
        master_channel=master_channel,
        polling_period_ms=polling_period_ms,
    )
    return _listening(json.loads(text), kept)
