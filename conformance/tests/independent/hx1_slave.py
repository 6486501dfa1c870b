#!/usr/bin/env python3
"""HX-1: an independent HIPERFACE slave, written from the SICK HIPERFACE specification's
tables (Table 4 UART, 2.2.2 frame timing, Tables 5-7 frame, 2.3.4 fault indication,
Table 9 state machine, Tables 10-36 commands, Tables 37-68 fault messages) and from
nothing in this repository's Rust code. It behaves like typical third-party firmware
and simulators do on a pseudo-terminal:

- every byte is time-stamped when it arrives; a request ends when no further byte
  came within the timeout (22 or 55 bit times of the active data rate);
- the whole reply is written in one write() as soon as the timeout has elapsed;
- it keeps its own data-field memory, access codes, error stack and state machine.

Its data sheet, for the harness, is hx1.toml next to this file.

Usage:
  hx1_slave.py --pty [--defect NAME ...] [--temperature C] [--erased-byte B] [--log]
      creates a pseudo-terminal, prints the path to open on stdout, serves until
      stdin closes or SIGTERM.
  hx1_slave.py --list-defects

Defect switches make it deliberately non-conformant, one rule at a time, for testing
the harness's FAIL verdicts.
"""

import argparse
import os
import select
import signal
import stat
import sys
import termios
import time
import tty

# ---------------------------------------------------------------------------------
# Data sheet of the HX-1 (must agree with hx1.toml)

FACTORY_ADDRESS = 0x40
FACTORY_SETTINGS = 0xE4          # 9600 Bd, even parity, 5*11 bit timeout, standard slave
TYPE_CODE = 0xFF                 # identifies by the Extended Type Label only (Table 19)
OPTION_CODE = 0x00
TOTAL_BLOCKS = 0x40              # 1024 bytes of memory (Read Type Label)
USER_BLOCKS = 0x38               # 896 bytes for data fields (Memory Status when empty)
PERIODS_PER_TURN = 256
TURNS = 4096
RANGE = 32 * PERIODS_PER_TURN * TURNS    # 32 position steps per period (Table 11)
BAUD_RATES = {4: 9600, 5: 19200, 6: 38400}   # settings bits 0-2 -> Bd (Table 28)
SERIAL = b"HX1000042"
FIRMWARE = b"hx1 fw 2.7"
FIRMWARE_DATE = b"03.10.26"
TEMPERATURE_MIN = -20
TEMPERATURE_MAX = 100
COMMANDS = {0x42, 0x43, 0x44, 0x46, 0x47, 0x49, 0x4A, 0x4B, 0x4C, 0x4D, 0x4E, 0x4F,
            0x50, 0x52, 0x53, 0x55, 0x56, 0x57, 0x67, 0x6A, 0x6C}
INIT_S = 0.100                   # Table 9
DEFAULT_WINDOW_S = 0.900
USER_SETTINGS_S = 1.100


def extended_type_label():
    """Table 20: 64 bytes, XOR checksum over all of them at offset 0."""
    label = bytearray(64)
    label[1] = 0x00                                   # rotary, unipolar
    label[2:6] = PERIODS_PER_TURN.to_bytes(4, "big")
    label[6:10] = TURNS.to_bytes(4, "big")
    name = b"HX-1 multiturn"
    label[10:10 + len(name)] = name
    label[0x1C:0x1E] = (0x0007).to_bytes(2, "big")     # temperature channel, min, max
    label[0x1E:0x20] = (0x0048).to_bytes(2, "big")
    label[0x20:0x22] = (TEMPERATURE_MIN & 0xFFFF).to_bytes(2, "big")
    label[0x22:0x24] = (TEMPERATURE_MAX & 0xFFFF).to_bytes(2, "big")
    x = 0
    for b in label[1:]:
        x ^= b
    label[0] = x
    return bytes(label)


ETL = extended_type_label()

# Fault codes (2.4.3)
E_COUNTER = 0x08
E_CHECKSUM = 0x0A
E_UNKNOWN_COMMAND = 0x0B
E_LENGTH = 0x0C
E_ARGUMENT = 0x0D
E_READ_ONLY = 0x0E
E_ACCESS_CODE = 0x0F
E_MEMORY = 0x10
E_OFFSET = 0x11
E_FIELD_NUMBER = 0x12
W_TEMPERATURE = 0x1E

# Master data lengths (Tables 12-36); Store Data is 5...132.
MASTER_LENGTH = {0x42: 0, 0x43: 5, 0x44: 1, 0x46: 0, 0x47: 0, 0x49: 1, 0x4A: 4, 0x4C: 1,
                 0x4D: 3, 0x4E: 0, 0x4F: 3, 0x50: 0, 0x52: 0, 0x53: 0, 0x55: 2, 0x56: 0,
                 0x57: 2, 0x67: 1, 0x6A: 5, 0x6C: 0}

DEFECTS = {
    "reply-checksum": "Read Version replies carry a wrong checksum",
    "no-timeout-wait": "Read Encoder Status is answered 0.5 ms after the request, not after its timeout",
    "late-reply": "Read Counter is answered 12 ms after the timeout (Table 10: 5 ms)",
    "very-late-reply": "Read Version is answered 250 ms after the timeout (Table 10: 5 ms), "
                       "after a harness's usual reply window",
    "gap-in-reply": "Read Type Label replies pause for twice the timeout after two bytes",
    "answers-other-address": "also answers requests for the neighbouring address",
    "ignores-broadcast": "stays silent on the broadcast address FFh",
    "no-field-bounds": "Read Data does not check offset + count against the field size",
    "wrong-error-code": "unknown commands draw 0Dh instead of 0Bh",
    "warning-stuck": "the warning bit is set in every reply although nothing is stored",
    "store-read-only": "Store Data writes into read-only data fields",
    "reset-answers": "Encoder Reset is answered",
    "no-init-silence": "answers during the initialization after an Encoder Reset",
    "no-code-check": "Set Position accepts any Code0",
    "old-address-reply": "Set Encoder Address replies from the old address",
    "ignores-temporary-settings": "replies to Temporarily Set Serial Interface but keeps its old settings",
}


def xor(data):
    x = 0
    for b in data:
        x ^= b
    return x


# What a new data field's bytes read before they are written. 000 does not say; an
# erased EEPROM reads FFh, but some firmware clears new fields to 00h (--erased-byte).
ERASED = 0xFF


class Field:
    def __init__(self, status):
        self.status = status | 0x80
        self.data = bytearray(bytes([ERASED]) * self.size())

    def size(self):
        return ((self.status & 0x07) + 1) * 16

    def code_number(self):
        return (self.status >> 4) & 0x03

    def code_enabled(self):
        return bool(self.status & 0x08)

    def writable(self):
        return bool(self.status & 0x40)


class HX1:
    """The encoder: EEPROM contents, volatile state and the Table 9 state machine."""

    def __init__(self, defects, temperature):
        self.defects = set(defects)
        # EEPROM
        self.address = FACTORY_ADDRESS
        self.stored_settings = FACTORY_SETTINGS
        self.codes = [0x55, 0x55, 0x55, 0x55]
        self.offset = 0
        self.counter = 0
        self.fields = []
        # physical world
        self.raw_position = 0x0123_4567 % RANGE
        self.temperature = temperature
        self.power_on(time.monotonic())

    # -- Table 9 ------------------------------------------------------------------
    def power_on(self, now):
        self.boot = now
        self.stack = []
        self.temporary_settings = None
        self.spoke_in_default_window = False
        self.boot_settings = self.stored_settings

    def listening(self, now):
        """The settings byte the UART listens with now, or None while it does not."""
        t = now - self.boot
        if t < INIT_S and "no-init-silence" not in self.defects:
            return None
        if self.temporary_settings is not None:
            return self.temporary_settings
        if t < DEFAULT_WINDOW_S or self.spoke_in_default_window:
            return FACTORY_SETTINGS
        if t < USER_SETTINGS_S:
            return None
        return self.boot_settings

    def timeout_s(self, now):
        s = self.listening(now)
        if s is None:
            s = FACTORY_SETTINGS
        bits = 55 if s & 0x40 else 22
        return bits / BAUD_RATES.get(s & 0x07, 9600)

    # -- error stack (2.3.4, Table 27) --------------------------------------------
    def stack_push(self, code):
        if code in self.stack:
            return
        self.stack.append(code)
        if len(self.stack) > 4:
            self.stack.pop(0)

    def monitor(self):
        """Checked prior to every response (Table 59)."""
        if not TEMPERATURE_MIN <= self.temperature <= TEMPERATURE_MAX:
            self.stack_push(W_TEMPERATURE)

    # -- frames ---------------------------------------------------------------------
    def frame(self, address, command, data=b""):
        warning = bool(self.stack) or "warning-stuck" in self.defects
        body = bytes([address, command | (0x80 if warning else 0)]) + bytes(data)
        return body + bytes([xor(body)])

    def error(self, code):
        self.monitor()
        return self.frame(self.address, 0x50, [code])

    def reply(self, command, data=b"", address=None):
        self.monitor()
        return self.frame(self.address if address is None else address, command, data)

    def handle(self, req, now):
        """One request frame, ended at `now`. Returns the reply bytes or None."""
        if not req:
            return None
        own = req[0] == self.address
        if "answers-other-address" in self.defects and req[0] == self.address ^ 0x01:
            own = True
        broadcast = req[0] == 0xFF and "ignores-broadcast" not in self.defects
        if not (own or broadcast):
            return None
        # Any single request keeps the default settings (Table 9).
        if now - self.boot < DEFAULT_WINDOW_S:
            self.spoke_in_default_window = True
        if len(req) < 3:
            return self.error(E_LENGTH)
        if xor(req) != 0:
            return self.error(E_CHECKSUM)
        cmd = req[1] & 0x7F
        if cmd not in COMMANDS:
            return self.error(E_ARGUMENT if "wrong-error-code" in self.defects else E_UNKNOWN_COMMAND)
        data = req[2:-1]
        if cmd == 0x4B:
            if len(data) < 5 or len(data) != 4 + data[2]:
                return self.error(E_LENGTH)
        elif len(data) != MASTER_LENGTH[cmd]:
            return self.error(E_LENGTH)
        return getattr(self, "cmd_%02x" % cmd)(data, now)

    # -- commands (Tables 12-36) -------------------------------------------------------
    def position(self):
        return (self.raw_position + self.offset) % RANGE

    def cmd_42(self, d, now):
        return self.reply(0x42, self.position().to_bytes(4, "big"))

    def cmd_43(self, d, now):
        preset = int.from_bytes(d[0:4], "big")
        if preset >= RANGE:
            return self.error(E_ARGUMENT)
        if d[4] != self.codes[0] and "no-code-check" not in self.defects:
            return self.error(E_ACCESS_CODE)
        self.offset = (preset - self.raw_position) % RANGE
        return self.reply(0x43)

    def cmd_44(self, d, now):
        if d[0] != 0x48:
            return self.error(E_ARGUMENT)
        return self.reply(0x44, bytes([0x48]) + (self.temperature & 0xFFFF).to_bytes(2, "big"))

    def cmd_46(self, d, now):
        return self.reply(0x46, self.counter.to_bytes(3, "big"))

    def cmd_47(self, d, now):
        if self.counter == 0xFFFFFF:
            return self.error(E_COUNTER)
        self.counter += 1
        return self.reply(0x47)

    def cmd_49(self, d, now):
        if d[0] != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        self.counter = 0
        return self.reply(0x49)

    def field_for(self, number):
        if 0 <= number < len(self.fields):
            return self.fields[number]
        return None

    def cmd_4a(self, d, now):
        number, offset, count, code = d
        if number == 0xFF:
            content, size = ETL, len(ETL)
        else:
            field = self.field_for(number)
            if field is None:
                return self.error(E_FIELD_NUMBER)
            if field.code_enabled() and code != self.codes[field.code_number()]:
                return self.error(E_ACCESS_CODE)
            content, size = field.data, field.size()
        if count == 0 or count > 128:
            return self.error(E_ARGUMENT)
        if offset + count > size:
            if "no-field-bounds" not in self.defects:
                return self.error(E_OFFSET)
            content = bytes(content) + b"\x00" * 256
        return self.reply(0x4A, bytes([number, offset, count]) + bytes(content[offset:offset + count]))

    def cmd_4b(self, d, now):
        number, offset, count, code = d[0:4]
        payload = d[4:]
        if number == 0xFF:
            return self.error(E_READ_ONLY)
        field = self.field_for(number)
        if field is None:
            return self.error(E_FIELD_NUMBER)
        if field.code_enabled() and code != self.codes[field.code_number()]:
            return self.error(E_ACCESS_CODE)
        if not field.writable() and "store-read-only" not in self.defects:
            return self.error(E_READ_ONLY)
        if count == 0 or count > 128 or offset + count > field.size():
            return self.error(E_OFFSET)
        field.data[offset:offset + count] = payload
        return self.reply(0x4B, bytes([number, offset, count]))

    def cmd_4c(self, d, now):
        number = d[0]
        if number == 0xFF:
            return self.reply(0x4C, bytes([0xFF, 0x83]))   # exists, read-only, no code, 64 bytes
        field = self.field_for(number)
        if field is None:
            return self.error(E_FIELD_NUMBER)
        return self.reply(0x4C, bytes([number, field.status]))

    def free_blocks(self):
        return USER_BLOCKS - sum(f.size() // 16 for f in self.fields)

    def cmd_4d(self, d, now):
        number, status, code = d
        if number == 0xFF:
            return self.error(E_MEMORY)
        blocks = (status & 0x07) + 1
        if number == len(self.fields):
            # a new field: the code byte must be the code the new status names
            if not status & 0x80:
                return self.error(E_FIELD_NUMBER)
            if code != self.codes[(status >> 4) & 0x03]:
                return self.error(E_ACCESS_CODE)
            if blocks > self.free_blocks():
                return self.error(E_MEMORY)
            self.fields.append(Field(status))
            return self.reply(0x4D, bytes([number, status]))
        field = self.field_for(number)
        if field is None:
            return self.error(E_FIELD_NUMBER)
        if code != self.codes[field.code_number()]:
            return self.error(E_ACCESS_CODE)
        last = number == len(self.fields) - 1
        if not status & 0x80:
            # delete: only the last one, all other status bits as stored
            if not last:
                return self.error(E_FIELD_NUMBER)
            if (status & 0x7F) != (field.status & 0x7F):
                return self.error(E_ARGUMENT)
            self.fields.pop()
            return self.reply(0x4D, bytes([number, status]))
        old_blocks = field.size() // 16
        if blocks != old_blocks:
            if not last:
                return self.error(E_FIELD_NUMBER)
            if blocks - old_blocks > self.free_blocks():
                return self.error(E_MEMORY)
            new = bytearray(bytes([ERASED]) * (blocks * 16))
            keep = min(blocks, old_blocks) * 16
            new[:keep] = field.data[:keep]
            field.data = new
        field.status = status | 0x80
        return self.reply(0x4D, bytes([number, status]))

    def cmd_4e(self, d, now):
        return self.reply(0x4E, bytes([self.free_blocks(), len(self.fields)]))

    def cmd_4f(self, d, now):
        number, old, new = d
        if number > 3:
            return self.error(E_ARGUMENT)
        if old != self.codes[number]:
            return self.error(E_ACCESS_CODE)
        self.codes[number] = new
        return self.reply(0x4F, bytes([number]))

    def cmd_50(self, d, now):
        code = self.stack.pop(0) if self.stack else 0x00
        # The warning bit of this reply tells whether more entries wait.
        return self.frame(self.address, 0x50, [code])

    def cmd_52(self, d, now):
        return self.reply(0x52, bytes([self.stored_settings, TYPE_CODE, TOTAL_BLOCKS, OPTION_CODE]))

    def cmd_53(self, d, now):
        self.power_on(now)    # executed after the request's timeout: now
        if "reset-answers" in self.defects:
            return self.frame(self.address, 0x53)
        return None

    def cmd_55(self, d, now):
        new, code = d
        # This firmware checks the access code before the argument.
        if code != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        if not 0x40 <= new <= 0x5F:
            return self.error(E_ARGUMENT)
        old = self.address
        self.address = new
        return self.reply(0x55, address=old if "old-address-reply" in self.defects else new)

    def cmd_56(self, d, now):
        version = SERIAL.ljust(9, b" ")[:9] + FIRMWARE.ljust(20, b"\x00")[:20] + FIRMWARE_DATE[:8]
        frame = self.reply(0x56, version)
        if "reply-checksum" in self.defects:
            frame = frame[:-1] + bytes([frame[-1] ^ 0x5A])
        return frame

    @staticmethod
    def settings_valid(s):
        return (s & 0x07) in BAUD_RATES and (s & 0x30) != 0x10

    def cmd_57(self, d, now):
        settings, code = d
        if not self.settings_valid(settings):
            return self.error(E_ARGUMENT)
        if code != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        self.stored_settings = settings
        return self.reply(0x57, bytes([settings]))

    def cmd_67(self, d, now):
        settings = d[0]
        if not self.settings_valid(settings):
            return self.error(E_ARGUMENT)
        frame = self.reply(0x67, bytes([settings]))
        self.pending_settings = settings        # after this reply
        return frame

    def cmd_6a(self, d, now):
        preset = int.from_bytes(d[0:4], "big")
        if preset >= RANGE:
            return self.error(E_ARGUMENT)
        if d[4] != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        # Round to the nearest value in phase with the sine/cosine signals (ties upward).
        phase = self.raw_position % 32
        below = preset - ((preset - phase) % 32)
        above = below + 32
        used = below if preset - below < above - preset else above
        used %= RANGE
        self.offset = (used - self.raw_position) % RANGE
        return self.reply(0x6A, used.to_bytes(4, "big"))

    def cmd_6c(self, d, now):
        # added to the position, gives the sine/cosine phase
        return self.reply(0x6C, bytes([(self.raw_position - self.position()) % 32]))


# ---------------------------------------------------------------------------------
# The UART side: frames by the timeout, replies in one write


def answered_at_once(slave, pending):
    """The `no-timeout-wait` defect: a whole Read Encoder Status request is answered
    0.5 ms after its checksum byte, without waiting for the timeout."""
    return ("no-timeout-wait" in slave.defects and len(pending) == 3
            and pending[1] & 0x7F == 0x50 and xor(pending) == 0)


def watch_stdin():
    """Stop when the process that started us closes our standard input (a pipe)."""
    try:
        return stat.S_ISFIFO(os.fstat(sys.stdin.fileno()).st_mode)
    except OSError:
        return False


# How late a wake-up after the timeout may be for this process still to know that
# bytes found pending came after the timeout.
LATE_WAKE_S = 0.0005


# How late this process may be in answering before the run is no longer a faithful
# sample of HX-1's behaviour (--late-log): well under Table 10's 5 ms, so that a run
# in which the test machine, not HX-1's design, made a reply late is recognised.
SELF_LATE_S = 0.003


def run_delay_s():
    """The time this process has spent runnable but waiting for a processor
    (/proc/self/schedstat, second field, ns); 0 where the kernel does not keep it."""
    try:
        with open("/proc/self/schedstat") as f:
            return int(f.read().split()[1]) / 1e9
    except (OSError, ValueError, IndexError):
        return 0.0


class SelfLateness:
    """Whether the machine made HX-1 late: woken after a reply's time, or held off a
    processor while a request was arriving or being answered. Each such reply is a
    line in the --late-log file, which a test reads to know its sample was not HX-1's
    own behaviour."""

    def __init__(self, path):
        self.path = path
        self.queued_at_start = 0.0

    def request_started(self):
        if self.path:
            self.queued_at_start = run_delay_s()

    def replying(self, request, woke_late_s):
        if not self.path:
            return
        queued = run_delay_s() - self.queued_at_start
        late = max(woke_late_s, queued)
        if late > SELF_LATE_S:
            with open(self.path, "a") as f:
                f.write("late %.1f ms answering %s\n" % (late * 1000, request.hex(" ")))


LATENESS = SelfLateness(None)


# termios speed constants -> Bd, for --follow-line.
SPEEDS = {getattr(termios, "B%d" % bd): bd for bd in (600, 1200, 2400, 4800, 9600, 19200, 38400)}


def line_bd(fd):
    """The data rate the other end of the pseudo-terminal set (a device server that
    takes settings through RFC 2217 writes them there)."""
    return SPEEDS.get(termios.tcgetattr(fd)[4])


def at_line_rate(fd, slave, now, follow):
    """With --follow-line: whether the line runs at the rate this device listens
    and replies at. A UART at another rate finds no characters."""
    settings = slave.listening(now)
    return not follow or settings is None or line_bd(fd) == BAUD_RATES.get(settings & 0x07)


def serve(fd, slave, log, follow=False):
    pending = bytearray()
    last_rx = None
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    inputs = [fd] + ([sys.stdin.fileno()] if watch_stdin() else [])
    while not stop:
        now = time.monotonic()
        end = None
        if last_rx is not None:
            end = last_rx + (0.0005 if answered_at_once(slave, pending) else slave.timeout_s(last_rx))
        try:
            ready, _, _ = select.select(inputs, [], [], 0.5 if end is None else max(0.0, end - now))
        except InterruptedError:
            continue
        now = time.monotonic()
        if sys.stdin.fileno() in ready and fd != sys.stdin.fileno():
            if not os.read(sys.stdin.fileno(), 64):
                return
        if end is not None and now >= end and fd not in ready:
            request = bytes(pending)
            pending.clear()
            last_rx = None
            respond(fd, slave, request, end, log, follow)
            continue
        if fd in ready:
            if not pending:
                LATENESS.request_started()
            try:
                chunk = os.read(fd, 512)
            except OSError:
                chunk = b""
            if slave.listening(now) is None or not at_line_rate(fd, slave, now, follow):
                continue   # no UART communication, or another rate: characters are lost
            if end is not None and now >= end and now - end < LATE_WAKE_S:
                # woken on time and these bytes were not there yet: the previous
                # request ended before they came
                respond(fd, slave, bytes(pending), end, log, follow)
                pending.clear()
            # woken late (a busy machine), the bytes may have come before the timeout
            # ended: a UART would have stamped them; this process cannot tell, and
            # takes them as the rest of the request (the likelier reading).
            pending.extend(chunk)
            last_rx = now


def respond(fd, slave, request, end, log, follow=False):
    LATENESS.replying(request, time.monotonic() - end)
    slave.pending_settings = None
    reply = slave.handle(request, end)
    if reply is not None and not at_line_rate(fd, slave, end, follow):
        reply = None   # sent at another rate than the line's: nobody hears it
    if log:
        print("%10.3f M> %s" % (end - slave.boot, request.hex(" ")), file=sys.stderr, flush=True)
    if reply is None:
        return
    cmd = request[1] & 0x7F if len(request) > 1 else None
    if cmd == 0x46 and "late-reply" in slave.defects:
        time.sleep(0.012)
    if cmd == 0x56 and "very-late-reply" in slave.defects:
        time.sleep(0.250)
    if cmd == 0x52 and "gap-in-reply" in slave.defects:
        os.write(fd, reply[:2])
        time.sleep(2 * slave.timeout_s(time.monotonic()))
        os.write(fd, reply[2:])
    else:
        os.write(fd, reply)
    if log:
        print("%10.3f S< %s" % (time.monotonic() - slave.boot, reply.hex(" ")), file=sys.stderr, flush=True)
    if slave.pending_settings is not None and "ignores-temporary-settings" not in slave.defects:
        slave.temporary_settings = slave.pending_settings


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--pty", action="store_true", help="create a pseudo-terminal and print its path")
    p.add_argument("--defect", action="append", default=[], choices=sorted(DEFECTS))
    p.add_argument("--temperature", type=int, default=25)
    p.add_argument("--erased-byte", type=lambda v: int(v, 0), default=0xFF,
                   help="what unwritten bytes of a new data field read (default 0xFF)")
    p.add_argument("--log", action="store_true")
    p.add_argument("--follow-line", action="store_true",
                   help="take the line's data rate from the pseudo-terminal (set by a device server "
                        "through RFC 2217): characters at another rate are lost")
    p.add_argument("--list-defects", action="store_true")
    p.add_argument("--late-log", metavar="FILE",
                   help="append a line to FILE for each reply this process was late with "
                        "(more than %.0f ms: the machine's doing, not HX-1's)" % (SELF_LATE_S * 1000))
    args = p.parse_args()
    global LATENESS
    LATENESS = SelfLateness(args.late_log)
    if args.list_defects:
        for name, what in DEFECTS.items():
            print("%-22s %s" % (name, what))
        return
    if not args.pty:
        p.error("--pty is required")
    master, slave_fd = os.openpty()
    tty.setraw(slave_fd)
    print(os.ttyname(slave_fd), flush=True)
    global ERASED
    ERASED = args.erased_byte & 0xFF
    device = HX1(args.defect, args.temperature)
    serve(master, device, args.log, args.follow_line)
    os.close(slave_fd)


if __name__ == "__main__":
    main()
