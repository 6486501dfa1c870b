#!/usr/bin/env python3
"""HXM3: a HIPERFACE master (the drive side of the SICK HIPERFACE parameter channel).

Written from the HIPERFACE specification ("000") alone.  Clause references in the
comments are to 000 (e.g. "000:2.2.2" = Frame Timing, "T9" = Table 9).

Usage:  python3 hxm3_master.py PORT [--defect dNN] [--polling-period-ms N]

PORT is the encoder's serial line (a pseudo-terminal or a UART device).  The moment
this process starts is taken as the encoder's power-on (the drive switches the
encoder supply on and starts its encoder interface at the same time).

What it does (how it was written and its sealed defects: hxm3-defects.md):
  1. opens PORT, 9600 Bd 8E1 raw (000:2.2.1 Table 4 default settings);
  2. waits out the encoder's initialization (T9: 100 ms, at most 200 ms) and talks
     inside the default-communication window, so the encoder stays at its default
     settings (T9 "Operational (default communication)");
  3. start-up (000:3.3.1): Read Encoder Status until the stack is empty, Read Type
     Label, the Extended Type Label (Read Data, field FFh) for a type FFh encoder,
     fault reaction per 000:3.3.4 Table 74 (one SW reset for a critical start-up
     fault, as 000 Table 37 "Initialization" recommends);
  4. cyclic Read Position (42h) every polling period (000:3.2.2), warning bit read
     out with 50h (000:2.3.4), Table 74 reactions, bounded retries.
Runs until SIGTERM/SIGINT.
"""

import argparse
import os
import select
import signal
import sys
import termios
import time
import tty

# ---------------------------------------------------------------------------
# Protocol constants (000)
# ---------------------------------------------------------------------------

DEFAULT_BAUD = 9600                     # 000:2.2.1 Table 4 "Data rate 9600 Baud" (default)
BIT_TIMES_PER_CHAR = 11                 # 1 start + 8 data + parity + 1 stop (Table 4)
# 000:2.2.2 "The timeout condition can be programmed to be either 22 s/Data rate or
# 55 s/Data rate (default, i.e. 5.73 ms for 9600 Baud)".  In default communication the
# encoder always uses the 5x timeout (T9 "default settings (9600 Baud, even parity,
# 5x timeout)"); this master never leaves default communication.
TIMEOUT_S = 55.0 / DEFAULT_BAUD         # 5.729 ms
CHAR_S = BIT_TIMES_PER_CHAR / DEFAULT_BAUD   # 1.146 ms per character on the wire

# Margins on top of the normative minima (a real drive adds a little for its timer
# resolution and ISR latency; here for scheduler latency).
PAUSE_S = TIMEOUT_S + 0.0012            # pause after any line activity before a request
REPLY_END_SILENCE_S = TIMEOUT_S + 0.0015  # a reply has ended after this silence (000:2.2.2)
REPLY_WINDOW_MARGIN_S = 0.015           # on top of timeout + max. response time (Table 10)

# T9 Initialization: "Automatically 100 ms after power-on/reset ... Even in these cases
# the duration shall not exceed 200 ms after power-on/reset."  This master waits for
# the worst case (200 ms) plus a margin, and talks well before 900 ms (T9 "No message
# until 900 ms" would switch the encoder to its stored settings).
INIT_WAIT_S = 0.250
DEFAULT_WINDOW_END_S = 0.900            # T9 "No message until 900 ms after power-on/reset"
USER_SETTINGS_FROM_S = 1.100            # T9 "Automatically 1100 ms after power-on/reset"

ADDRESS = 0x40                          # 000:2.3.1 Table 5, "default address ... 0 (40h)"
ACCESS_CODE_DEFAULT = 0x55              # 000 Table 8 "Default value for code 0 is 55h"

# 000 Table 10: max. response time [ms] per command.
RESPONSE_TIME_MS = {
    0x42: 10, 0x43: 40, 0x44: 5, 0x46: 5, 0x47: 30, 0x49: 30, 0x4A: 30, 0x4B: 250,
    0x4C: 5, 0x4D: 70, 0x4E: 5, 0x4F: 40, 0x50: 5, 0x52: 5, 0x53: None, 0x55: 40,
    0x56: 5, 0x57: 40, 0x67: 5, 0x6A: 40, 0x6B: 40, 0x6C: 30,
}

BAUD_CODES = {0: 600, 1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}  # Table 28
TERMIOS_BAUD = {600: termios.B600, 1200: termios.B1200, 2400: termios.B2400,
                4800: termios.B4800, 9600: termios.B9600, 19200: termios.B19200,
                38400: termios.B38400}

# Fault codes (000:2.4.3, reactions 000:3.3.4 Table 74)
PROTOCOL_CODES = {0x09, 0x0A, 0x0B, 0x0C, 0x0D}           # "Retry command."
# Position group, "Retry command. If error persists, SW reset of Slave."
RETRY_THEN_RESET_CODES = {0x01, 0x02, 0x05, 0x1C, 0x1D, 0x20, 0x21, 0x23, 0x24}
# Initialization group, critical, "SW reset of Slave."
CRITICAL_INIT_CODES = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x1D, 0x20, 0x21}
DATA_CODES = {0x03, 0x0E, 0x0F, 0x10, 0x11, 0x12}
# Codes that narrow down an "Internal checksum error" 06h (Table 44 note; the
# "06h + xx" rows of Table 74).
CRC_PARTNER_CODES = {0x01, 0x02, 0x03, 0x04, 0x05, 0x08, 0x12, 0x21}
KNOWN_CODES = (PROTOCOL_CODES | RETRY_THEN_RESET_CODES | CRITICAL_INIT_CODES | DATA_CODES
               | {0x07, 0x08, 0x1E, 0x1F, 0x22})
CODE_NAMES = {
    0x01: "alignment data / analog signals", 0x02: "internal angular offset",
    0x03: "data field partitioning table", 0x04: "analog limit values",
    0x05: "internal I2C bus", 0x06: "internal checksum", 0x07: "program watchdog",
    0x08: "counter overflow", 0x09: "parity error", 0x0A: "checksum error",
    0x0B: "unknown command", 0x0C: "wrong command length", 0x0D: "wrong argument",
    0x0E: "read-only data field", 0x0F: "incorrect access code", 0x10: "out of memory",
    0x11: "wrong data field offset", 0x12: "wrong data field number",
    0x1C: "value monitoring analog signals", 0x1D: "transmitter current critical",
    0x1E: "encoder temperature critical", 0x1F: "speed too high",
    0x20: "singleturn position unreliable", 0x21: "multiturn amplitude fault",
    0x22: "multiturn sync fault", 0x23: "multiturn vectorlength fault",
    0x24: "multiturn counter fault",
}

MAX_PROTOCOL_RETRIES = 3    # no reply / bad frame / protocol error code: bounded (Table 74)
MAX_POSITION_RETRIES = 2    # "Retry command. If error persists, SW reset of Slave."
MAX_RESETS_PER_EPISODE = 1  # 000 Table 37: "SW reset first. If this didn't succeed a power cycle"
MAX_STATUS_READS = 5        # stack of up to four codes (000:2.3.4) plus the final 00h

DEFECT = None


def xor_checksum(data):
    """000:2.3.3 "XOR operation on all frame bytes including address"."""
    c = 0
    for b in data:
        c ^= b
    return c


def hexs(data):
    return " ".join("%02X" % b for b in data)


def code_name(code):
    return "%02Xh %s" % (code, CODE_NAMES.get(code, "(unknown code)"))


class Reply:
    """Outcome of one exchange."""
    OK, ERROR, NONE, BAD = "ok", "error", "none", "bad"

    def __init__(self, kind, raw=b"", data=b"", code=None, warning=False, reason=""):
        self.kind = kind
        self.raw = raw
        self.data = data
        self.code = code
        self.warning = warning
        self.reason = reason


class CommsLost(Exception):
    pass


def boottime_to_monotonic_offset():
    return time.clock_gettime(time.CLOCK_BOOTTIME) - time.monotonic()


def process_start_monotonic():
    """The power-on instant: this process's start (the harness/drive switches the
    encoder on as it starts us).  /proc gives it in clock ticks of the boot clock; the
    estimate is at most one tick early, which only makes the waits below longer."""
    try:
        with open("/proc/self/stat") as f:
            s = f.read()
        fields = s[s.rindex(")") + 2:].split()
        start_ticks = int(fields[19])
        hz = os.sysconf("SC_CLK_TCK")
        start_boot = start_ticks / float(hz)
        est = start_boot - boottime_to_monotonic_offset()
        now = time.monotonic()
        if now - 5.0 < est <= now:
            return est
    except Exception:
        pass
    return time.monotonic()


class Master:
    def __init__(self, port, polling_period_s, user_baud=DEFAULT_BAUD):
        self.port = port
        self.user_baud = user_baud
        self.poll_s = polling_period_s
        self.power_on = process_start_monotonic()
        self.fd = None
        self.addr = ADDRESS
        self.baud = DEFAULT_BAUD
        self.last_rx = 0.0          # time the last character of the encoder arrived
        self.last_tx_end = 0.0      # end of our last request on the wire
        self.last_tx_write = 0.0
        self.hold_until = 0.0       # no request before this (initialization, reset)
        self.skip_idle_check = False
        self.stored_settings = None
        self.type_code = None
        self.etl = None
        self.position_reads_allowed = True   # cleared after 22h (Table 74)
        self.fault_latched = False           # retries/resets exhausted: poll only
        self.comm_fault = False
        self.resets_in_episode = 0
        self.motor_stopped = False
        self.exchanges = 0
        self.last_position = None
        self.warnings_seen = []
        self.startup_done = False
        self.pending_reset = None

    # ------------------------------------------------------------------ log
    def t(self):
        return time.monotonic() - self.power_on

    def log(self, msg):
        sys.stdout.write("[%8.3f] %s\n" % (self.t(), msg))
        sys.stdout.flush()

    # ------------------------------------------------------------------ line
    def open_port(self):
        fd = os.open(self.port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(fd)
        self.fd = fd
        self.set_baud(DEFAULT_BAUD)

    def set_baud(self, baud):
        """8 data bits, even parity, 1 stop bit (000:2.2.1 Table 4), raw, no echo."""
        attrs = termios.tcgetattr(self.fd)
        iflag, oflag, cflag, lflag, ispeed, ospeed, cc = attrs
        iflag &= ~(termios.IGNBRK | termios.BRKINT | termios.PARMRK | termios.ISTRIP
                   | termios.INLCR | termios.IGNCR | termios.ICRNL | termios.IXON
                   | termios.IXOFF | termios.IXANY)
        iflag |= termios.INPCK            # parity checked by the UART
        oflag &= ~termios.OPOST
        lflag &= ~(termios.ECHO | termios.ECHONL | termios.ICANON | termios.ISIG
                   | termios.IEXTEN)
        cflag &= ~(termios.CSIZE | termios.PARODD | termios.CSTOPB)
        if hasattr(termios, "CRTSCTS"):
            cflag &= ~termios.CRTSCTS
        cflag |= termios.CS8 | termios.PARENB | termios.CREAD | termios.CLOCAL
        speed = TERMIOS_BAUD[baud]
        cc = list(cc)
        cc[termios.VMIN] = 0
        cc[termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSANOW,
                          [iflag, oflag, cflag, lflag, speed, speed, cc])
        self.baud = baud

    def _read_available(self):
        try:
            return os.read(self.fd, 512)
        except BlockingIOError:
            return b""
        except OSError:
            return b""

    def wait_line_free(self):
        """Before any request: the pause of at least the timeout after the end of our
        own last request (000:2.2.2 "the end of a Master transmission must be followed
        by a pause of at least the length of the timeout condition"), after the last
        character of the encoder (000:2.2.2 "The end of the Slave transmission is also
        indicated by a pause of at least the length of the timeout condition": we never
        talk over a reply, 000:2.2 half-duplex), and any initialization hold (T9, T29).
        Stray characters that arrive meanwhile restart the pause."""
        stray = b""
        while True:
            if self.skip_idle_check:
                ready = max(self.last_tx_end + PAUSE_S, self.hold_until)
            else:
                ready = max(self.last_rx + PAUSE_S, self.last_tx_end + PAUSE_S,
                            self.hold_until)
            now = time.monotonic()
            if now >= ready:
                break
            r, _, _ = select.select([self.fd], [], [], ready - now)
            if r:
                got = self._read_available()
                if got and not self.skip_idle_check:
                    stray += got
                    self.last_rx = time.monotonic()
        self.skip_idle_check = False
        if stray:
            self.log("line: %d late/stray character(s) ignored: %s" % (len(stray), hexs(stray[:16])))

    def send(self, frame, split=False, twice=False):
        self.wait_line_free()
        if split:
            os.write(self.fd, frame[:1])
            time.sleep(0.010)
            n = os.write(self.fd, frame[1:])
            n += 1
        elif twice:
            os.write(self.fd, frame)
            time.sleep(0.001)
            n = os.write(self.fd, frame)
        else:
            # One write: the whole request goes out back to back, no gap inside it
            # (000:2.2.2 "Each character of the Master transmission must be followed by
            # a subsequent character within the timeout condition").
            n = os.write(self.fd, frame)
        if n != len(frame):
            raise OSError("short write")
        # On a UART the request ends when its last character has left the shift
        # register; count the transmission time (11 bits per character).
        self.last_tx_write = time.monotonic()
        self.last_tx_end = time.monotonic() + len(frame) * BIT_TIMES_PER_CHAR / float(self.baud)

    def receive(self, cmd, max_len=None):
        """Wait for the reply within the response window, then collect characters until
        a silence of the timeout (000:2.2.2) ends the reply."""
        resp_ms = RESPONSE_TIME_MS.get(cmd, 30) or 30
        if DEFECT == "d13":
            deadline = self.last_tx_write + 0.010
        else:
            # Table 8: "Specification of maximum response time of Slave after Master
            # request timeout ... Response time does not include transmission times and
            # protocol timeout."  So the reply may start as late as request end +
            # timeout + response time; wait that out plus a margin.
            deadline = self.last_tx_end + TIMEOUT_S + resp_ms / 1000.0 + REPLY_WINDOW_MARGIN_S
        buf = bytearray()
        while True:
            now = time.monotonic()
            if not buf:
                if now >= deadline:
                    return bytes(buf)
                wait = deadline - now
            else:
                end_at = self.last_rx + REPLY_END_SILENCE_S
                if now >= end_at:
                    return bytes(buf)
                wait = end_at - now
            r, _, _ = select.select([self.fd], [], [], wait)
            if r:
                got = self._read_available()
                if got:
                    self.last_rx = time.monotonic()
                    buf.extend(got)
                    if max_len is not None and len(buf) >= max_len:
                        self.skip_idle_check = True
                        return bytes(buf[:max_len])
                    if len(buf) > 400:      # longest reply is 135 bytes (Read Data)
                        return bytes(buf)

    def parse(self, cmd, raw, expect_len):
        """000:2.3 frame: address, command, data, checksum.  Command byte bit 7 is the
        error (warning) bit (Table 6, 000:2.3.4).  An error response carries command
        value 50h and the error code (000:2.3.4 "Error Response")."""
        if not raw:
            return Reply(Reply.NONE, reason="no reply")
        if len(raw) < 3:
            return Reply(Reply.BAD, raw, reason="reply too short")
        if xor_checksum(raw) != 0:
            return Reply(Reply.BAD, raw, reason="reply checksum wrong")
        if raw[0] != self.addr:
            return Reply(Reply.BAD, raw, reason="reply from address %02Xh" % raw[0])
        warning = bool(raw[1] & 0x80)
        rcmd = raw[1] & 0x7F
        if rcmd == cmd and (expect_len is None or len(raw) == expect_len):
            return Reply(Reply.OK, raw, data=raw[2:-1], warning=warning)
        if rcmd == 0x50 and cmd != 0x50 and len(raw) == 4:
            return Reply(Reply.ERROR, raw, code=raw[2], warning=warning)
        return Reply(Reply.BAD, raw, reason="unexpected reply")

    def frame(self, cmd, data=b""):
        body = bytes([self.addr, cmd]) + bytes(data)
        return body + bytes([xor_checksum(body)])

    def exchange(self, cmd, data=b"", expect_data_len=None, note="", retry=False,
                 cmd_byte=None, max_len=None, split=False, twice=False):
        """One request and its reply.  Returns a Reply."""
        frame = self.frame(cmd if cmd_byte is None else cmd_byte, data)
        self.send(frame, split=split, twice=twice)
        raw = self.receive(cmd, max_len=max_len)
        expect_len = None if expect_data_len is None else expect_data_len + 3
        rep = self.parse(cmd, raw, expect_len)
        self.exchanges += 1
        if rep.kind == Reply.OK:
            what = note or "ok"
        elif rep.kind == Reply.ERROR:
            what = "error response %s" % code_name(rep.code)
        else:
            what = rep.reason
        if rep.warning:
            what += " [warning bit]"
        self.log("M> %-23s| S< %-26s| %s%s" % (hexs(frame), hexs(raw[:24]) + (" ..." if len(raw) > 24 else ""),
                                              "retry: " if retry else "", what))
        return rep

    # ------------------------------------------------------------------ retries
    def request(self, cmd, data=b"", expect_data_len=None, note="", max_len=None,
                max_retries=MAX_PROTOCOL_RETRIES):
        """A request with bounded retries of transmission/protocol faults (Table 74:
        09h..0Dh "Retry command."; no reply and a corrupted reply likewise).  Other
        error codes are returned to the caller for their Table 74 reaction."""
        rep = None
        baud_probe = [38400, 19200]
        for attempt in range(max_retries + 1):
            if attempt and DEFECT == "d11" and rep is not None and rep.kind == Reply.NONE and baud_probe:
                self.set_baud(baud_probe.pop(0))
            twice = (DEFECT == "d12" and rep is not None and rep.kind == Reply.ERROR)
            rep = self.exchange(cmd, data, expect_data_len, note, retry=attempt > 0,
                                max_len=max_len, twice=twice)
            if DEFECT == "d11" and self.baud != DEFAULT_BAUD:
                self.set_baud(DEFAULT_BAUD)
            if rep.kind == Reply.OK:
                return rep
            if rep.kind == Reply.ERROR:
                if rep.warning:
                    self.read_out_warnings(reason="error response with warning bit")
                if rep.code in PROTOCOL_CODES and not (DEFECT == "d14" and rep.code == 0x0B):
                    continue
                return rep
            # NONE or BAD: retry
        return rep

    # ------------------------------------------------------------------ reset
    def encoder_reset(self, why):
        """Encoder Reset 53h (Table 29).  No reply follows; T29: "A HIPERFACE Master must
        wait for this time [the timeout of the request] plus the initialization time of
        100 ms before communication can resume."  We wait timeout + 200 ms (T9 upper bound
        of initialization) + margin, and then talk before 900 ms so that the encoder
        stays at its default settings (T9)."""
        self.log("SW reset of the encoder (53h): %s" % why)
        if DEFECT == "d01":
            frame = bytes([self.addr, 0x53, 0x53])
        else:
            frame = self.frame(0x53)
        self.send(frame)
        t_write = time.monotonic()
        reset_done = self.last_tx_end + TIMEOUT_S          # executed after the timeout
        if DEFECT == "d06":
            self.hold_until = t_write + 0.100
        elif DEFECT == "d10":
            self.hold_until = reset_done + 0.950
        else:
            self.hold_until = reset_done + INIT_WAIT_S - 0.020
        if DEFECT == "d04":
            self.addr = 0x00
        # A correct Encoder Reset is not answered (Table 29 note).  Anything that does
        # arrive (an error response: the request was not taken) is logged.
        late = bytearray()
        while time.monotonic() < self.hold_until:
            r, _, _ = select.select([self.fd], [], [], max(0.0, self.hold_until - time.monotonic()))
            if r:
                got = self._read_available()
                if got:
                    late.extend(got)
                    self.last_rx = time.monotonic()
        self.exchanges += 1
        self.log("M> %-23s| S< %-26s| %s" % (hexs(frame), hexs(late[:24]),
                                             "encoder reset, initialization waited out" if not late
                                             else "reply to Encoder Reset: the reset was not taken"))
        self.stored_settings = None

    # ------------------------------------------------------------------ status
    def read_status_stack(self, reason):
        """Read Encoder Status (50h) until the stack is empty (status 00h), at most
        four codes plus the final 00h (000:2.3.4 "If multiple operational faults are
        stored, the Master must read out each associated error code separately to reset
        the Error bit"; Table 27)."""
        codes = []
        in_warning = reason.startswith("warning")
        cmd_byte = 0xD0 if (DEFECT == "d03" and in_warning) else None
        if DEFECT == "d07" and reason == "cyclic status poll":
            cmd_byte = 0x10
        for _ in range(MAX_STATUS_READS):
            rep = None
            for attempt in range(MAX_PROTOCOL_RETRIES + 1):
                rep = self.exchange(0x50, b"", 1, note="", retry=attempt > 0, cmd_byte=cmd_byte,
                                    split=(DEFECT == "d05" and in_warning))
                if rep.kind == Reply.OK:
                    break
                if rep.kind == Reply.ERROR and rep.code not in PROTOCOL_CODES:
                    break
            if rep is None or rep.kind != Reply.OK:
                self.log("status read failed (%s)" % (rep.reason if rep and rep.reason else
                                                     code_name(rep.code) if rep else "?"))
                return codes, False
            status = rep.data[0]
            if status == 0x00:
                self.log("status 00h: stack empty (%s)" % reason)
                return codes, True
            if status in codes:
                # The same code again: its condition is still present and the encoder
                # has stored it anew (e.g. 1Eh, "checked prior to every Slave response
                # message", Table 59).  Everything stored before has been read.
                self.log("status code %s again: condition persists (%s)" % (code_name(status), reason))
                return codes, True
            self.log("status code %s (%s)" % (code_name(status), reason))
            codes.append(status)
        self.log("status stack not empty after %d reads" % MAX_STATUS_READS)
        return codes, False

    def read_out_warnings(self, reason="warning bit"):
        """000:3.2.2 "If the command handler receives a warning bit indication ... the
        underlying error code(s) should be read out."  Then react (Table 74)."""
        codes, _ = self.read_status_stack("warning: " + reason)
        self.warnings_seen.extend(codes)
        for c in codes:
            self.react_to_stored_code(c, codes, context="warning")

    # ------------------------------------------------------------------ reactions
    def stop_motor(self, why):
        if not self.motor_stopped:
            self.log("drive: motor stop (%s)" % why)
        self.motor_stopped = True

    def react_to_stored_code(self, code, all_codes, context):
        """Table 74 for codes read from the stack (warnings during operation)."""
        if code == 0x22:
            # Table 74: "Only use sine/cosine based position until shut-down. Replace Slave."
            self.log("reaction 22h: sine/cosine position only until shut-down, replace encoder; no more Read Position")
            self.position_reads_allowed = False
        elif code == 0x1E:
            self.log("reaction 1Eh: change motion profile to fit temperature range (major)")
        elif code == 0x1F:
            self.log("reaction 1Fh: check maximum speed for position read-out (major)")
        elif code == 0x07:
            self.log("reaction 07h: minor, message read and deleted")
        elif code == 0x08 and 0x06 not in all_codes:
            self.log("reaction 08h: reset user counter (major)")
            rep = self.request(0x49, bytes([ACCESS_CODE_DEFAULT]), 0, note="user counter reset")
            if rep.kind != Reply.OK:
                self.log("user counter reset failed")
        elif code in KNOWN_CODES:
            self.log("reaction %02Xh: logged for diagnostics" % code)
        else:
            self.unknown_code(code, context)

    def unknown_code(self, code, context):
        # 000:3.3.4: "It is expected that a HIPERFACE Master can only react with the
        # worst-case fault reaction to unknown fault codes (i.e. motor stop)."
        self.stop_motor("unknown fault code %02Xh (%s): worst-case reaction" % (code, context))
        if DEFECT == "d16":
            return
        self.pending_reset = "unknown fault code %02Xh: worst-case reaction" % code

    # ------------------------------------------------------------------ start-up
    def evaluate_startup_codes(self, codes):
        """000:3.3.1 "It is strongly recommended to read the Slave status after a power-on
        and react according to potential fault indications"; Table 74 (codes read
        together take the row of their pair: 06h + xx)."""
        critical = []
        s = set(codes)
        if 0x06 in s:
            partners = s & CRC_PARTNER_CODES
            if DEFECT == "d15":
                minor_pair = len(s) == 2
            else:
                minor_pair = (partners == {0x08})
            if minor_pair:
                self.log("start-up: 06h + %s: minor (Table 74), no action" %
                         "+".join("%02Xh" % p for p in sorted(partners)))
                s -= {0x06} | partners
            else:
                critical.append("06h + %s" % ("+".join("%02Xh" % p for p in sorted(partners)) or "alone"))
                s -= {0x06} | partners
        for c in sorted(s):
            if c in CRITICAL_INIT_CODES or c in (0x1C, 0x23, 0x24):
                critical.append("%02Xh" % c)
            elif c == 0x22:
                self.react_to_stored_code(c, codes, "start-up")
            elif c in KNOWN_CODES:
                self.react_to_stored_code(c, codes, "start-up")
            else:
                self.stop_motor("unknown start-up fault code %02Xh: worst-case reaction" % c)
                if DEFECT != "d16":
                    critical.append("%02Xh (unknown)" % c)
        return critical

    def startup(self):
        """000:3.3.1 Encoder Start-up (Figure 17), default-communication path."""
        self.pending_reset = None
        while True:
            # Initialization (T9): wait out the encoder's initialization, talk well
            # inside the default-communication window (before 900 ms).
            codes, ok = self.read_status_stack("after power-on/reset")
            rep = self.request(0x52, b"", 4, note="type label")
            if rep.kind == Reply.OK:
                d = rep.data
                self.stored_settings = d[0]
                self.type_code = d[1]
                baud = BAUD_CODES.get(d[0] & 0x07, None)
                par = {0: "none", 2: "even", 3: "odd"}.get((d[0] >> 4) & 3, "?")
                self.log("type label: UART settings %02Xh (stored: %s Bd, parity %s, timeout %dx, %s), "
                         "encoder type %02Xh, memory %d x 16 bytes, option %02Xh"
                         % (d[0], baud, par, 5 if d[0] & 0x40 else 2,
                            "standard slave" if d[0] & 0x80 else "bus slave", d[1], d[2], d[3]))
                if DEFECT == "d08" and baud in TERMIOS_BAUD and baud != self.baud:
                    self.set_baud(baud)
                if rep.warning:
                    self.read_out_warnings("on type label reply")
                if self.type_code == 0xFF:
                    # Table 19: "Slaves that only implement the Extended Type Label have to
                    # use the type code FFh"; read it (Read Data, field FFh, Table 20/21).
                    self.read_extended_type_label()
            elif rep.kind == Reply.ERROR:
                self.react_to_command_error(0x52, rep, startup=True)
            else:
                self.log("type label not read (%s)" % rep.reason)
            critical = self.evaluate_startup_codes(codes)
            if self.pending_reset:
                critical.append(self.pending_reset)
                self.pending_reset = None
            if critical:
                if self.resets_in_episode < MAX_RESETS_PER_EPISODE:
                    self.resets_in_episode += 1
                    # Table 37 "Initialization": "If error messages occur during start-up
                    # it is recommended to carry out a software reset first."
                    self.encoder_reset("critical start-up fault " + ", ".join(critical))
                    continue
                self.log("start-up fault persists after SW reset: power cycle of the encoder required "
                         "(Table 37); drive stays disabled")
                self.stop_motor("persistent start-up fault")
                self.fault_latched = True
            self.startup_done = True
            return

    def read_extended_type_label(self):
        """Read Data (4Ah) of the virtual data field FFh (Table 20, Table 21): offset 0,
        64 bytes, access code byte included (Table 21: "this byte can contain any value
        but must be included in the Master request")."""
        if DEFECT == "d02":
            data = bytes([0xFF, 0x00, 0x40])
        else:
            data = bytes([0xFF, 0x00, 0x40, ACCESS_CODE_DEFAULT])
        rep = self.request(0x4A, data, 3 + 64, note="extended type label",
                           max_len=64 if DEFECT == "d09" else None)
        if rep.kind != Reply.OK:
            if rep.kind == Reply.ERROR:
                self.react_to_command_error(0x4A, rep, startup=True)
            self.log("extended type label not read")
            return
        d = rep.data
        if d[0] != 0xFF or d[1] != 0x00 or d[2] != 0x40:
            self.log("extended type label: reply header %s does not match the request" % hexs(d[:3]))
            return
        etl = bytearray(d[3:])
        self.etl = etl
        chk_ok = xor_checksum(etl[1:64]) == etl[0] or xor_checksum(etl[:64]) == 0
        kind = "linear" if etl[1] & 1 else "rotary"
        res = int.from_bytes(etl[2:6], "big")
        rng = int.from_bytes(etl[6:10], "big")
        name = bytes(etl[0x0A:0x1C]).split(b"\x00")[0].decode("ascii", "replace")
        sel = int.from_bytes(etl[0x1C:0x1E], "big")
        self.log("extended type label: %s, %s, resolution %d, range %d, selector %04Xh, checksum %s"
                 % (name or "?", kind, res, rng, sel, "ok" if chk_ok else "MISMATCH"))
        if sel & 0x8000:
            # Table 20, offset 1Ch bit 15: a second parameter selector follows at 40h.
            rep = self.request(0x4A, bytes([0xFF, 0x40, 0x40, ACCESS_CODE_DEFAULT]), 3 + 64,
                               note="extended type label, 2nd block")
            if rep.kind == Reply.OK:
                self.etl.extend(rep.data[3:])
                self.log("extended type label: 2nd block read (%d bytes in all)" % len(self.etl))
            elif rep.kind == Reply.ERROR:
                self.log("extended type label 2nd block: %s (check/change offset, Table 74)" % code_name(rep.code))

    # ------------------------------------------------------------------ operation
    def react_to_command_error(self, cmd, rep, startup=False):
        code = rep.code
        if code == 0x22:
            self.react_to_stored_code(code, [code], "error response")
        elif code in (0x1E, 0x1F, 0x07):
            self.react_to_stored_code(code, [code], "error response")
        elif code in DATA_CODES:
            self.log("reaction %02Xh: data field error on %02Xh (check request)" % (code, cmd))
        elif code in KNOWN_CODES:
            self.log("reaction %02Xh on %02Xh: logged" % (code, cmd))
        else:
            self.unknown_code(code, "error response to %02Xh" % cmd)

    def read_position_cycle(self):
        """One cyclic Read Position (000:3.2.2: "If no other information is required the
        command Read Position should be used to poll fault indications") with the
        reactions of Table 74."""
        retries = MAX_POSITION_RETRIES
        if self.fault_latched:
            retries = 0
        attempt = 0
        while True:
            # While the line is known to be down, one attempt per polling period.
            rep = self.request(0x42, b"", 4, note="position",
                               max_retries=0 if self.comm_fault else MAX_PROTOCOL_RETRIES)
            if rep.kind == Reply.OK:
                pos = int.from_bytes(rep.data, "big")
                self.last_position = pos
                self.resets_in_episode = 0
                if self.comm_fault:
                    self.log("communication restored")
                self.comm_fault = False
                self.log("position %d (%08Xh)" % (pos, pos))
                if rep.warning:
                    self.read_out_warnings()
                return
            if rep.kind in (Reply.NONE, Reply.BAD):
                if not self.comm_fault:
                    self.log("no valid reply after %d retries: communication fault, drive keeps polling"
                             % MAX_PROTOCOL_RETRIES)
                self.comm_fault = True
                self.stop_motor("encoder communication fault")
                return
            code = rep.code
            if code in PROTOCOL_CODES:
                # retries (if any) done in request(); next attempt in the next cycle
                if DEFECT == "d14" and code == 0x0B:
                    self.position_reads_allowed = False
                self.log("protocol error %s: no position this cycle" % code_name(code))
                return
            if code in RETRY_THEN_RESET_CODES:
                if attempt < retries:
                    attempt += 1
                    continue
                if self.fault_latched:
                    return
                # "If error persists, SW reset of Slave." (critical: at standstill)
                self.stop_motor("position fault %s" % code_name(code))
                if self.resets_in_episode < MAX_RESETS_PER_EPISODE:
                    self.resets_in_episode += 1
                    self.encoder_reset("position fault %s persists" % code_name(code))
                    self.startup()
                else:
                    self.log("position fault persists after SW reset: drive stays disabled, encoder status polled cyclically")
                    self.fault_latched = True
                return
            self.react_to_command_error(0x42, rep)
            if self.pending_reset:
                why = self.pending_reset
                self.pending_reset = None
                if self.resets_in_episode < MAX_RESETS_PER_EPISODE:
                    self.resets_in_episode += 1
                    self.encoder_reset(why)
                    self.startup()
                else:
                    self.fault_latched = True
            return

    def status_poll_cycle(self):
        """After 22h (Table 74: "Only use sine/cosine based position until shut-down"), or
        once the Table 74 reactions are exhausted (retries and the one SW reset done, a
        power cycle required, Table 37), the failing Read Position is not repeated; the
        encoder's fault indications are still polled cyclically (000:3.2.2 "a sufficient
        cyclic request should be implemented") with Read Encoder Status (50h)."""
        codes, _ = self.read_status_stack("cyclic status poll")
        for c in codes:
            if c != 0x22:
                self.react_to_stored_code(c, codes, "status poll")

    def run(self):
        self.open_port()
        self.log("HXM3 master on %s: 9600 Bd 8E1, address %02Xh, polling period %d ms"
                 % (self.port, self.addr, round(self.poll_s * 1000)))
        # T9 Initialization: no UART communication until the encoder has initialized.
        self.hold_until = self.power_on + INIT_WAIT_S
        now = time.monotonic()
        if now - self.power_on > DEFAULT_WINDOW_END_S - 0.05:
            # We came up too late for the default window: the encoder switches to its
            # stored settings at 1100 ms (T9 "Change of communication settings": no UART
            # communication until then); be silent until then and talk at the stored
            # data rate (--user-baud; only on a badly overloaded host).
            self.log("start-up late: waiting for the encoder's user-settings phase (%d Bd)"
                     % self.user_baud)
            self.hold_until = self.power_on + USER_SETTINGS_FROM_S + 0.05
            if self.user_baud != DEFAULT_BAUD:
                self.set_baud(self.user_baud)
        self.startup()
        self.log("start-up done: cyclic %s every %d ms"
                 % ("Read Position" if self.position_reads_allowed and not self.fault_latched
                    else "Read Encoder Status", round(self.poll_s * 1000)))
        next_poll = time.monotonic()
        while True:
            now = time.monotonic()
            if now < next_poll:
                time.sleep(next_poll - now)
            # Period counted from the start of each cycle: a long cycle (retries, a
            # reset) is followed by one cycle at once, never by a burst of catch-ups.
            next_poll = time.monotonic() + self.poll_s
            if self.position_reads_allowed and not self.fault_latched:
                self.read_position_cycle()
            else:
                self.status_poll_cycle()


def main():
    global DEFECT
    ap = argparse.ArgumentParser(description="HXM3 HIPERFACE master")
    ap.add_argument("port", help="the encoder's serial line (pty or UART device)")
    ap.add_argument("--defect", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--polling-period-ms", type=float, default=50.0,
                    help="cyclic Read Position period (default 50 ms)")
    ap.add_argument("--user-baud", type=int, default=DEFAULT_BAUD, choices=sorted(TERMIOS_BAUD),
                    help="the data rate the encoder has stored (Table 28); used only if this "
                         "process comes up too late for the default-communication window")
    args = ap.parse_args()
    if args.defect is not None:
        d = args.defect.lower()
        known = ["d%02d" % i for i in range(1, 17)]
        if d not in known:
            ap.error("unknown defect %s; known: %s" % (args.defect, ", ".join(known)))
        DEFECT = d

    def on_term(signum, frame):
        raise SystemExit(0)

    signal.signal(signal.SIGTERM, on_term)
    signal.signal(signal.SIGINT, on_term)
    m = Master(args.port, args.polling_period_ms / 1000.0, args.user_baud)
    try:
        m.run()
    except SystemExit:
        m.log("stopped after %d exchanges" % m.exchanges)
        raise
    finally:
        if m.fd is not None:
            try:
                os.close(m.fd)
            except OSError:
                pass


if __name__ == "__main__":
    main()
