"""HX-M, the independent master (conformance/tests/independent/hx_master.py, written
from 000 alone), run in-process on the run's virtual clock instead of a
pseudo-terminal: its logic is untouched (its ``Master`` class, its defect switches);
only its line is replaced. HX-M is written as a blocking program (sleep, write, read
until a pause), so it runs in a thread of its own, and each blocking call hands control
back to the run: the run calls ``step`` with the time and the characters that reached
the master, the master runs until it blocks again, and what it sent and when it wants
to be woken are the step's answer. One of the two runs at a time."""

from __future__ import annotations

import importlib.util
import math
import threading
from pathlib import Path
from typing import List, Optional, Tuple

HX_M = Path(__file__).resolve().parents[2] / "conformance" / "tests" / "independent" / "hx_master.py"


def load_hx_m():
    spec = importlib.util.spec_from_file_location("hx_master", HX_M)
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    return module


class _Stopped(BaseException):
    """The scenario is over: the master's thread ends."""


class VirtualLine:
    """HX-M's ``Line`` (the methods its ``Master`` calls) on the virtual clock."""

    def __init__(self, hx, runner: "HxMaster", baud: Optional[int]):
        self.hx = hx
        self.runner = runner
        # A pseudo-terminal nobody set stays at 38400 Bd (HX-M's no-baud defect).
        self.bps = baud if baud is not None else 38400
        self.idle_since = 0.0
        self.last_char = 0.0
        self.reply_end_s = hx.TIMEOUT_S + 0.002

    def set_baud(self, baud: int) -> None:
        self.bps = baud

    def now(self) -> float:
        return self.runner.now_us / 1e6

    def sleep_until(self, t: float) -> None:
        while self.now() < t:
            self.runner.block(math.ceil(t * 1e6))

    def write(self, data, gap_before=None, gap_s=0.0) -> None:
        data = bytes(data)
        if gap_before is None:
            self.runner.send(data, self.bps)
        else:
            self.runner.send(data[:gap_before], self.bps)
            self.sleep_until(self.now() + gap_before * self.hx.CHAR_S + gap_s)
            self.runner.send(data[gap_before:], self.bps)
        # The line is busy while the characters go out.
        self.sleep_until(self.now() + len(data) * self.hx.CHAR_S)

    def discard_input(self) -> bool:
        got = bool(self.runner.inbox)
        self.runner.inbox.clear()
        return got

    def read_reply(self, max_response_s: float) -> bytes:
        deadline = self.now() + self.hx.TIMEOUT_S + max_response_s + 0.005
        got = bytearray()
        last = None
        while True:
            if self.runner.inbox:
                got += bytes(b for b, _ in self.runner.inbox)
                self.runner.inbox.clear()
                last = self.now()
            elif last is None and self.now() > deadline:
                break
            elif last is not None and self.now() - last > self.reply_end_s:
                break
            # Until a character comes, or just past the time that ends the wait.
            until = deadline if last is None else last + self.reply_end_s
            self.runner.block(math.floor(until * 1e6) + 1)
        self.idle_since = self.now()
        # When the last character was read (the reply's end as the master knew it).
        self.last_char = last if last is not None else self.idle_since
        return bytes(got)


class HxMaster:
    """HX-M as ``hiperface.certify_master`` calls a master: ``power_on`` and ``step``."""

    def __init__(self, defect: Optional[str] = None, poll_ms: int = 20, user_baud: Optional[int] = None):
        self.hx = load_hx_m()
        if defect is not None and defect not in self.hx.DEFECTS:
            raise ValueError(f"unknown defect {defect}")
        self.defect = defect
        self.poll_s = 1.5 if defect == "sparse-poll" else poll_ms / 1000
        self.user_baud = user_baud
        self.now_us = 0
        self.inbox: List[Tuple[int, int]] = []
        self._thread: Optional[threading.Thread] = None
        # A pair per scenario: a thread that ended leaves nothing behind for the next.
        self._to_master = threading.Semaphore(0)
        self._to_run = threading.Semaphore(0)
        self._stop = False
        self._sending: Optional[Tuple[bytes, int, int]] = None
        self._action = None
        self._error: Optional[BaseException] = None

    # --- the master's side (its thread) ---

    def send(self, data: bytes, bps: int) -> None:
        # Each write is followed by a wait before the next one, so one per step.
        assert self._sending is None, "two writes without a wait between them"
        self._sending = (data, self.now_us, bps)

    def block(self, wake_us: int) -> None:
        sending, self._sending = self._sending, None
        if sending is None:
            self._action = wake_us
        else:
            data, start_us, bps = sending
            self._action = (data, start_us, wake_us, bps)
        self._to_run.release()
        self._to_master.acquire()
        if self._stop:
            raise _Stopped()

    def _run(self) -> None:
        self._to_master.acquire()
        try:
            if not self._stop:
                baud = None if self.defect == "no-baud" else 9600
                line = VirtualLine(self.hx, self, baud)
                if self.defect == "receive-idle":
                    line.reply_end_s = 2 * self.hx.CHAR_S
                self.hx.Master(line, self.defect, self.poll_s, self.user_baud).run()
        except _Stopped:
            pass
        except BaseException as e:  # handed to the run, which raises it
            self._error = e
        self._action = None
        self._to_run.release()

    def _end_scenario(self) -> None:
        if self._thread is not None:
            self._stop = True
            self._to_master.release()
            self._thread.join(timeout=10)
            assert not self._thread.is_alive(), "HX-M's thread did not end"
        self._thread = None
        self._to_master = threading.Semaphore(0)
        self._to_run = threading.Semaphore(0)

    # --- the run's side ---

    def power_on(self) -> None:
        self._end_scenario()
        self._stop = False
        self.now_us = 0
        self.inbox.clear()
        self._sending = None
        self._action = None
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def step(self, now_us: int, heard):
        self.now_us = now_us
        self.inbox.extend(heard)
        self._to_master.release()
        if not self._to_run.acquire(timeout=30):
            raise RuntimeError("HX-M did not yield within 30 s")
        if self._error is not None:
            raise self._error
        return self._action

    def close(self) -> None:
        self._end_scenario()
