"""The HIPERFACE reference model and its conformance oracle, for Python test benches.

- Frame helpers: ``checksum``, ``seal``, ``is_valid`` (000:2.3.3), ``decode_request``
  (raises ``MalformedRequest(message, code)`` with the fault code a slave answers).
- ``Slave(profile)``: the reference model of an encoder (a built-in profile name or a
  profile's TOML file); ``receive`` each character the master sends, ``poll`` for what
  to send and in which window (000:2.2.2, 000:T8).
- ``Oracle(exact=False).grade(slave, request, at_us, reply)``: a device's reply graded
  PASS, NON-STRICT or FAIL with the clause id and the reason, in lockstep with the model.
- ``verify_vectors(dir)``: the golden vectors checked as ``hiperface vectors verify`` does
  (a directory without a vector is an error); ``load_vectors(file)`` gives a file's
  vectors one by one, each with ``verify()``.
- Frames may be ``bytes``, ``bytearray`` or ``memoryview``; a missing file raises
  ``FileNotFoundError`` everywhere.
- ``decode(path)``: a capture file (wire log, logic analyser CSV, sigrok-cli) graded
  as ``hiperface decode`` grades it: every exchange with its verdict and findings.
- ``read_report(path)``: a ``report.json`` as Python objects (a certification's
  ``Report``, a listening run's ``Listening``).
- ``certify(encoder, profile)``: an encoder written in Python (a callable, or an
  object with an ``answer`` method, handed each request as a ``Heard``) certified
  in-process with the whole slave catalogue in virtual time: a ``Report`` with its
  verdicts, clauses and findings, which ``write(dir)`` writes as the command does.
- ``certify_master(master, profile)``: a master written in Python (an object with
  ``step(now_us, heard)``, handed the encoder's reply characters as they end) certified
  in-process with the scenario catalogue in virtual time, as ``certify master`` does.
"""

from ._hiperface import (
    Grade,
    Heard,
    HiperfaceError,
    MalformedRequest,
    Oracle,
    ProfileError,
    Request,
    Slave,
    Transmission,
    Vector,
    catalogue,
    checksum,
    decode_request,
    is_valid,
    load_vectors,
    seal,
    verify_vectors,
)
from .report import Case, Exchange, Finding, Listening, Report, certify, certify_master, decode, read_report

__all__ = [
    "Case",
    "Exchange",
    "Finding",
    "Grade",
    "Heard",
    "HiperfaceError",
    "Listening",
    "MalformedRequest",
    "Oracle",
    "ProfileError",
    "Report",
    "Request",
    "Slave",
    "Transmission",
    "Vector",
    "catalogue",
    "certify",
    "certify_master",
    "checksum",
    "decode",
    "decode_request",
    "is_valid",
    "read_report",
    "load_vectors",
    "seal",
    "verify_vectors",
]
