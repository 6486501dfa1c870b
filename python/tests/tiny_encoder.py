"""TINY-PY: a tiny HIPERFACE encoder (slave) written from the specification (000) alone.

It is an independent peer for ``hiperface.certify``: an object with an
``answer(heard)`` method, handed each request frame once the character timeout after
its last character has passed (000:2.2.2), returning None (silence) or
``(reply, start_us)``.

Device (the TINY-PY profile): address 40h, stored UART settings E4h (9600 Baud, even
parity, timeout 55 bit times, standard slave: 000:T28, 000:T4, 000:2.2.2), type code
22h, 80h blocks of memory, option code 00h, a single-turn rotary encoder with 1024
sine/cosine periods. Supported: 42h Read Position, 50h Read Encoder Status, 52h Read
Type Label, 53h Encoder Reset; every other command draws "Unknown command" (0Bh).

Defect switches, each breaking one rule on purpose:

- ``checksum-without-address``: the reply checksum leaves the address out (000:2.3.3).
- ``wrong-unknown-command-code``: an unknown command draws 0Dh instead of 0Bh (000:T49).
- ``no-timeout-wait``: replies start before the request's timeout has elapsed (000:2.2.2).
"""

from __future__ import annotations

from typing import Iterable, List, Optional, Tuple

DEFECTS = ("checksum-without-address", "wrong-unknown-command-code", "no-timeout-wait")

# 000:T5 / 000:2.3.1: address byte 010x_xxxx; this device's address; FFh is broadcast.
ADDRESS = 0x40
BROADCAST = 0xFF

# 000:T28 byte 0: UART settings. E4h = 9600 Baud (100), even parity (10), timeout
# 5*11/data rate (bit 6), standard slave (bit 7). Stored settings == default settings.
SETTINGS = 0xE4
DEFAULT_SETTINGS = 0xE4
BAUD_BY_CODE = {0: 600, 1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}

# 000:T28 bytes 1..3.
TYPE_CODE = 0x22
MEMORY_BLOCKS = 0x80  # total memory in 16 byte blocks (2048 bytes)
OPTION_CODE = 0x00  # "for new HIPERFACE Slaves this value is always 00h"

# 000:T11 / 000:2.4.2 Read Position: 5 bits (32 steps) per sine/cosine period; 1024
# periods per turn and a single turn: 32768 steps, values 0..7FFFh. The shaft stands
# still; by default at this constant, valid position (any value below 8000h is one).
STEPS_PER_TURN = 1024 * 32
POSITION = 0x00002A5C
# The data sheet's temperature limits (the profile's [limits]) and the code for
# leaving them (000:T59).
TEMPERATURE_MIN_C, TEMPERATURE_MAX_C = -40, 115
TEMPERATURE_CRITICAL = 0x1E

# Command identifiers (000:T10).
READ_POSITION = 0x42
READ_ENCODER_STATUS = 0x50
READ_TYPE_LABEL = 0x52
ENCODER_RESET = 0x53

# Master data length of each supported command (000:T12, T27, T28, T29): all zero.
MASTER_DATA_LENGTH = {READ_POSITION: 0, READ_ENCODER_STATUS: 0, READ_TYPE_LABEL: 0, ENCODER_RESET: 0}

# Max. response time after the request's timeout, in µs (000:T10, 000:T8: "response
# time does not include transmission times and protocol timeout").
MAX_RESPONSE_US = {READ_POSITION: 10_000, READ_ENCODER_STATUS: 5_000, READ_TYPE_LABEL: 5_000}
# When this encoder starts its replies after the request's timeout: well inside every
# command's limit (an error response gets the same; 5 ms is the shortest figure in T10).
REPLY_DELAY_US = 500

# Fault codes (000:2.4.3).
PARITY_ERROR = 0x09  # 000:T47: any UART fault (parity, framing, noise, overrun)
CHECKSUM_ERROR = 0x0A  # 000:T48
UNKNOWN_COMMAND = 0x0B  # 000:T49
WRONG_LENGTH = 0x0C  # 000:T50
WRONG_ARGUMENT = 0x0D  # 000:T51

# 000:2.4.1 / 000:T9 state machine, times after power-on/reset (the profile's [timing]).
INIT_US = 100_000  # Initialization: no UART communication
DEFAULT_WINDOW_US = 900_000  # Default Communication until 900 ms without a message
USER_SETTINGS_US = 1_100_000  # Change of communication settings until 1100 ms

# 000:2.3.4 / 000:2.4.2 Read Encoder Status: up to four stored codes.
STACK_DEPTH = 4


def timeout_us(settings: int) -> float:
    """The character timeout of a settings byte: 22 or 55 bit times (000:2.2.2, 000:T28
    bit 6: 2*11 or 5*11 / data rate)."""
    baud = BAUD_BY_CODE[settings & 0x07]
    bits = 55 if settings & 0x40 else 22
    return bits * 1_000_000 / baud


def xor(data: Iterable[int]) -> int:
    """000:2.3.3: the checksum is the XOR of all frame bytes including the address."""
    c = 0
    for b in data:
        c ^= b
    return c


class TinyEncoder:
    """The TINY-PY encoder. ``defects``: names from ``DEFECTS``, each breaking one rule.
    ``position``: where the (standing) shaft is, in absolute position steps."""

    def __init__(self, defects: Iterable[str] = (), *, position: int = POSITION, temperature_c: int = 25,
                 watches_temperature: bool = True) -> None:
        self.defects = frozenset(defects)
        unknown = self.defects - set(DEFECTS)
        if unknown:
            raise ValueError(f"unknown defects: {sorted(unknown)}")
        if not 0 <= position < STEPS_PER_TURN:
            raise ValueError(f"a single-turn position is 0..{STEPS_PER_TURN - 1} (000:T11)")
        self.position = position
        # What its sensor reads, and whether the firmware looks at it at all (False: the
        # defect of an encoder that never raises 1Eh).
        self.temperature_c = temperature_c
        self.watches_temperature = watches_temperature
        # 000:T9: at time 0 the encoder is already past power-up, operational in its
        # stored settings. `reset_us` is the last (software) reset, None: none yet.
        self.reset_us: Optional[int] = None
        # Whether a request was heard in the default window after the last reset
        # (000:T9: "Any single Master request" keeps the default settings).
        self.spoken_in_default_window = False
        # 000:2.3.4 / 000:2.4.2: the error stack, oldest entry first.
        self.stack: List[int] = []
        self.log: List[Tuple[object, Optional[bytes], Optional[int]]] = []

    # -- faults not tied to a request (Warning Bit, 000:2.3.4) ------------------------

    def raise_fault(self, code: int) -> None:
        """Store an operational fault for Read Encoder Status: stored once until read
        out (no duplicates), at most four, the oldest dropped first (000:2.4.2 Read
        Encoder Status)."""
        if code in self.stack:
            return
        self.stack.append(code)
        del self.stack[:-STACK_DEPTH]

    # -- the request handler -----------------------------------------------------------

    def answer(self, heard) -> Optional[Tuple[bytes, int]]:
        reply = self._answer(heard)
        self.log.append((heard, reply[0] if reply else None, reply[1] if reply else None))
        return reply

    def __call__(self, heard):
        return self.answer(heard)

    def _state(self, t_us: int) -> str:
        """The 000:T9 state at ``t_us`` (a request's first character)."""
        if self.reset_us is None:
            return "operational"
        dt = t_us - self.reset_us
        if dt < INIT_US:
            return "initialization"  # no UART communication
        if self.spoken_in_default_window:
            return "operational"  # Operational (default communication)
        if dt < DEFAULT_WINDOW_US:
            return "default"  # Default Communication
        if dt < USER_SETTINGS_US:
            return "changing"  # Change of communication settings: no UART communication
        return "operational"  # Operational (user-defined communication)

    def _answer(self, heard) -> Optional[Tuple[bytes, int]]:
        frame = bytes(heard.bytes)
        state = self._state(heard.first_us)
        if state in ("initialization", "changing"):
            return None  # 000:T9: no UART communication in these states
        if state == "default":
            # 000:T9: any single request moves on to Operational (default communication).
            self.spoken_in_default_window = True
        if not frame:
            return None

        # 000:2.3.1: only the own address and the broadcast FFh are answered; each slave
        # acknowledges a broadcast with its own address. Frames to others: silence.
        if frame[0] not in (ADDRESS, BROADCAST):
            return None

        # 000:T47: a UART fault (parity, framing, noise, overrun) in the request: error
        # 09h, the message is not parsed further and nothing is performed.
        if heard.uart_fault is not None:
            return self._error(heard, PARITY_ERROR)

        # 000:T50: an invalid number of message bytes. Address, command and checksum
        # are the least a frame holds (000:2.3, 000:T8).
        if len(frame) < 3:
            return self._error(heard, WRONG_LENGTH)

        # 000:2.3.3 / 000:T48: the XOR of all bytes including address and checksum is 0.
        if xor(frame) != 0:
            return self._error(heard, CHECKSUM_ERROR)

        command = frame[1]
        data = frame[2:-1]
        # 000:T6 (bit 7 clear, bit 6 set) and 000:T49: commands this device does not
        # implement are unknown commands.
        if command not in MASTER_DATA_LENGTH:
            code = WRONG_ARGUMENT if "wrong-unknown-command-code" in self.defects else UNKNOWN_COMMAND
            return self._error(heard, code)
        # 000:T50: the master data length of the command (000:T12, T27, T28, T29).
        if len(data) != MASTER_DATA_LENGTH[command]:
            return self._error(heard, WRONG_LENGTH)
        # (000:T51 "Wrong command argument" cannot arise: none of these commands takes
        # an argument.)

        if command == ENCODER_RESET:
            # 000:T29: no response; executed after the timeout of the request, then the
            # same initialization as after power-on (000:T9). Address and settings are
            # kept; a reset clears the warning bit and the error stack (000:2.3.4).
            self.reset_us = heard.complete_us
            self.spoken_in_default_window = False
            self.stack.clear()
            return None

        if command == READ_POSITION:
            # 000:T12: absolute position, unsigned 32 bit, MSB first.
            return self._reply(heard, command, self.position.to_bytes(4, "big"))

        if command == READ_ENCODER_STATUS:
            # 000:2.4.2 Read Encoder Status / 000:T27: one stored code per request, the
            # oldest first; 00h when none. The read-out code leaves the stack; the
            # warning bit stays until every code is read out (000:2.3.4).
            code = self.stack.pop(0) if self.stack else 0x00
            return self._reply(heard, command, bytes([code]))

        if command == READ_TYPE_LABEL:
            # 000:T28: UART settings, encoder type code, memory size, option code.
            return self._reply(heard, command, bytes([SETTINGS, TYPE_CODE, MEMORY_BLOCKS, OPTION_CODE]))

        raise AssertionError(f"unhandled command {command:02X}h")  # pragma: no cover

    # -- replies ------------------------------------------------------------------------

    def _error(self, heard, code: int) -> Tuple[bytes, int]:
        """000:2.3.4 Error Response: command value 50h and the error code (D0h with the
        warning bit when an operational fault is stored)."""
        return self._reply(heard, READ_ENCODER_STATUS, bytes([code]))

    def _reply(self, heard, command: int, data: bytes) -> Tuple[bytes, int]:
        # 000:T59 Encoder temperature critical, "checked prior to every Slave response
        # message": outside the data sheet's limits it is stored as 1Eh.
        if self.watches_temperature and not TEMPERATURE_MIN_C <= self.temperature_c <= TEMPERATURE_MAX_C:
            self.raise_fault(TEMPERATURE_CRITICAL)
        # 000:2.3.4 Warning Bit: bit 7 of the command byte while a fault is stored.
        if self.stack:
            command |= 0x80
        # 000:2.3.1: always the own address, also to a broadcast.
        body = bytes([ADDRESS, command]) + data
        if "checksum-without-address" in self.defects:
            cs = xor(body[1:])  # defect: the address left out of the XOR
        else:
            cs = xor(body)  # 000:2.3.3
        reply = body + bytes([cs])
        return reply, self._start_us(heard)

    def _start_us(self, heard) -> int:
        """When the reply's first start bit falls: after the request's character timeout
        (000:2.2.2: a request ends with a pause of at least the timeout) and within the
        command's maximum response time counted from there (000:T8, 000:T10)."""
        if "no-timeout-wait" in self.defects:
            # defect: the reply starts a third of the timeout after the last character,
            # i.e. before the request is over by 000:2.2.2.
            return int(heard.last_us + timeout_us(SETTINGS) / 3)
        return int(heard.complete_us) + REPLY_DELAY_US
