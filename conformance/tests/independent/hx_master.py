#!/usr/bin/env python3
"""HX-M: an independent HIPERFACE master, written from 000's text alone (2.2.2 frame
timing, 2.3 frames, 2.3.4 warning bit, 2.4.1 state machine, 3.3.1 start-up, 3.3.4 and
Table 74 fault reaction). Standard library only; it shares no code with the Rust model.

    hx_master.py PORT [--defect NAME] [--poll-ms N] [--user-baud N]

Without --defect it is a conformant master: it waits out initialization, reads the
status until the stack is empty, reads the type label, then polls Read Position; it
reads the stack whenever a reply carries the warning bit, retries a request answered
with a protocol error, resets (53h) after critical start-up faults and unknown codes,
and stops reading the position after 22h. It sets its port to the default settings
(9600 Bd, even parity, Table 4); with --user-baud it is a drive configured for an
encoder whose stored data rate is N: it waits out the default window (1100 ms, 3.3.1)
and talks at N. Each defect switch breaks one rule, the way masters in the field do.
"""
import time

# Power-on is this process's start: the clock starts before anything else.
T0 = time.monotonic()

import os  # noqa: E402
import sys  # noqa: E402
import termios  # noqa: E402
import tty  # noqa: E402


def running_for():
    """How long this process has run (Linux: its start time in /proc/self/stat against
    /proc/uptime, 10 ms resolution): the interpreter's own start-up, which a busy machine
    stretches, is part of the time since power-on."""
    try:
        with open("/proc/self/stat") as f:
            after_name = f.read().rsplit(")", 1)[1].split()
        start_ticks = int(after_name[19])       # field 22, starttime
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])
        return max(0.0, uptime - start_ticks / os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError, IndexError):
        return 0.0


T0 -= running_for()

DEFECTS = {
    "talks-during-init": "sends its first request 20 ms after power-on",
    "settings-window": "sends its first request at 950 ms, while the encoder changes settings",
    "no-pause": "sends two requests back to back",
    "gap-in-request": "pauses 10 ms inside a request",
    "wrong-checksum": "sends a Read Position with a wrong checksum",
    "ignores-warning": "never reads the stack when the warning bit is set",
    "ignores-sync-fault": "keeps reading the position after 22h",
    "retries-forever": "retries a failing Read Position without bound and never resets",
    "no-reset-wait": "talks 20 ms after Encoder Reset",
    "no-retry": "answers a protocol error by moving on to another command",
    "naive-poll": "waits out initialization, then polls 42h in a loop, nothing else (no status read)",
    "ignores-extended-type-label": "never reads the Extended Type Label of a type FFh encoder",
    "no-baud": "never sets its port's data rate (a pseudo-terminal stays at 38400 Bd)",
    "user-baud-early": "with --user-baud, talks at the user data rate from the start",
    "sparse-poll": "polls once every 1.5 s: faults go unseen for that long",
    "late-default": "waits out the default window, then talks at 9600 Bd whatever the encoder stores",
    "receive-idle": "ends a reply after two character times of silence (a UART receive-idle interrupt) "
                    "and sends its next request 7.5 ms after the last character it read",
}

BAUD = {600: termios.B600, 1200: termios.B1200, 2400: termios.B2400, 4800: termios.B4800,
        9600: termios.B9600, 19200: termios.B19200, 38400: termios.B38400}

CHAR_S = 11 / 9600          # one character at 9600 Bd, 8E1
TIMEOUT_S = 55 / 9600       # 000:2.2.2 default timeout
ADDRESS = 0x40


def xor(data):
    x = 0
    for b in data:
        x ^= b
    return x


class Line:
    # The silence that ends a reply: the timeout (2.2.2), or less for receive-idle.
    reply_end_s = TIMEOUT_S + 0.002

    def __init__(self, path, baud):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[6][termios.VMIN] = 0
        attrs[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
        if baud is not None:
            self.set_baud(baud)
        os.set_blocking(self.fd, False)
        self.t0 = T0
        self.idle_since = 0.0
        self.last_char = 0.0

    def set_baud(self, baud):
        """8 data bits, even parity, one stop bit at `baud` (Table 4)."""
        attrs = termios.tcgetattr(self.fd)
        attrs[2] = (attrs[2] & ~(termios.CSIZE | termios.PARODD | termios.CSTOPB)) | termios.CS8 | termios.PARENB
        attrs[4] = attrs[5] = BAUD[baud]
        termios.tcsetattr(self.fd, termios.TCSADRAIN, attrs)

    def now(self):
        return time.monotonic() - self.t0

    def sleep_until(self, t):
        while True:
            left = t - self.now()
            if left <= 0:
                return
            time.sleep(min(left, 0.01))

    def write(self, data, gap_before=None, gap_s=0.0):
        if gap_before is None:
            os.write(self.fd, bytes(data))
        else:
            os.write(self.fd, bytes(data[:gap_before]))
            time.sleep(len(data[:gap_before]) * CHAR_S + gap_s)
            os.write(self.fd, bytes(data[gap_before:]))
        # The line is busy while the characters go out.
        time.sleep(len(data) * CHAR_S)

    def discard_input(self):
        """Read and drop what has come since the last reply; True if anything had."""
        got = False
        while True:
            try:
                chunk = os.read(self.fd, 256)
            except BlockingIOError:
                chunk = b""
            if not chunk:
                return got
            got = True

    def read_reply(self, max_response_s):
        """Bytes of one reply: the first within the timeout plus the maximum response
        time, the rest until a pause of the timeout (2.2.2)."""
        deadline = self.now() + TIMEOUT_S + max_response_s + 0.005
        got = bytearray()
        last = None
        while True:
            try:
                chunk = os.read(self.fd, 256)
            except BlockingIOError:
                chunk = b""
            now = self.now()
            if chunk:
                got += chunk
                last = now
            elif last is None and now > deadline:
                break
            elif last is not None and now - last > self.reply_end_s:
                break
            time.sleep(0.0005)
        self.idle_since = self.now()
        # When the last character was read (the reply's end as the master knew it).
        self.last_char = last if last is not None else self.idle_since
        return bytes(got)


class Master:
    def __init__(self, line, defect, poll_s, user_baud):
        self.line = line
        self.defect = defect
        self.poll_s = poll_s
        self.user_baud = user_baud
        self.position_stopped = False
        self.resets = 0

    def request(self, body, max_response_s=0.010, gap=None):
        frame = bytes(body) + bytes([xor(body)])
        if self.defect == "wrong-checksum" and body[1] == 0x42:
            frame = frame[:-1] + bytes([frame[-1] ^ 0x01])
        # 2.2.2: a pause of at least the timeout after the last transmission. A reply
        # that came after it was given up is no answer to this request: discard it, and
        # pause after it too.
        # receive-idle: the pause counted from the last character read, the timeout
        # and a character (a pseudo-terminal delivers a character when it is written,
        # a character time before a UART would). Not from when it ended the reply: its
        # request then meets the rest of a reply with a pause inside by 4 ms, not by
        # 1.4 ms, which its own scheduling on a busy machine could take away.
        while True:
            if self.defect == "receive-idle":
                self.line.sleep_until(self.line.last_char + TIMEOUT_S + CHAR_S + 0.0006)
                break
            self.line.sleep_until(self.line.idle_since + TIMEOUT_S + 0.001)
            if not self.line.discard_input():
                break
            self.line.idle_since = self.line.now()
        if self.defect == "gap-in-request" and body[1] == 0x42:
            self.line.write(frame, gap_before=2, gap_s=0.010)
        else:
            self.line.write(frame)
        if body[1] == 0x53:
            self.line.idle_since = self.line.last_char = self.line.now()
            return None
        reply = self.line.read_reply(max_response_s)
        if len(reply) < 3 or xor(reply) != 0 or reply[0] != ADDRESS:
            return None
        return reply

    def ask(self, command, data=b"", max_response_s=0.010):
        """A request; (command byte, data, warning) of a valid reply, or None."""
        reply = self.request([ADDRESS, command] + list(data), max_response_s)
        if reply is None:
            return None
        warning = bool(reply[1] & 0x80)
        if warning and command != 0x50 and self.defect != "ignores-warning":
            self.read_stack()
        return reply[1] & 0x7F, reply[2:-1], warning

    def read_stack(self):
        """50h until the stack is empty (four codes at most, 2.3.4), then react to the
        codes together: Table 74's "06h + 08h" row is Minor with no action, where 06h
        alone or with any other code asks for a reset."""
        codes = []
        for _ in range(5):
            r = self.ask(0x50, max_response_s=0.005)
            if r is None:
                break
            _, data, warning = r
            code = data[0] if data else 0
            if code == 0 and not warning:
                break
            if code != 0:
                codes.append(code)
        if 0x06 in codes and 0x08 in codes:
            codes = [c for c in codes if c not in (0x06, 0x08)]
        for code in codes:
            if self.react(code, start_up=True):
                return

    def react(self, code, start_up=False):
        """Table 74; True when the reaction ended the attempt."""
        if 0x09 <= code <= 0x0D:
            return False
        if code == 0x22:
            if self.defect != "ignores-sync-fault":
                self.position_stopped = True
            return True
        known = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x0E, 0x0F, 0x10, 0x11, 0x12,
                 0x1C, 0x1D, 0x1E, 0x1F, 0x20, 0x21, 0x22, 0x23, 0x24}
        critical_at_start = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x1D, 0x20, 0x21}
        if code not in known or (start_up and code in critical_at_start):
            self.reset()
            return True
        return False

    def reset(self):
        if self.resets >= 3 or self.defect == "retries-forever":
            self.position_stopped = self.defect != "retries-forever"
            return
        self.resets += 1
        self.request([ADDRESS, 0x53])
        wait = 0.020 if self.defect == "no-reset-wait" else TIMEOUT_S + 0.100 + 0.020
        self.line.sleep_until(self.line.now() + wait)
        if self.user_baud is not None and self.defect != "no-baud":
            self.line.set_baud(9600)        # after a reset the encoder starts in default settings
        self.read_stack()

    def start_up(self):
        if self.defect == "talks-during-init":
            pass                            # at once, well inside the 100 ms
        elif self.defect == "settings-window":
            self.line.sleep_until(0.940)
        elif self.defect == "late-default":
            self.line.sleep_until(1.120)
        elif self.user_baud is not None and self.defect == "user-baud-early":
            self.line.set_baud(self.user_baud)
            self.line.sleep_until(0.120)
        elif self.user_baud is not None:
            self.line.sleep_until(1.120)    # 3.3.1: the user settings hold from 1100 ms
            self.line.set_baud(self.user_baud)
        else:
            self.line.sleep_until(0.120)   # 2.4.1: initialization is over after 100 ms
        self.read_stack()
        label = None
        for _ in range(3):                  # no valid reply: ask again (Table 74 "Retry command.")
            label = self.ask(0x52, max_response_s=0.005)
            if label is not None:
                break
        # Type FFh: the parameters are in the Extended Type Label, field FFh (Table 19).
        if label and len(label[1]) >= 2 and label[1][1] == 0xFF and self.defect != "ignores-extended-type-label":
            self.ask(0x4A, bytes([0xFF, 0x00, 0x40, 0x00]), max_response_s=0.030)
        if self.defect == "no-pause":
            frame = bytes([ADDRESS, 0x42, xor([ADDRESS, 0x42])])
            self.line.write(frame + frame)
            self.line.read_reply(0.010)

    def poll(self):
        if self.position_stopped:
            self.line.sleep_until(self.line.now() + 0.1)
            self.read_stack()
            return
        for attempt in range(100 if self.defect == "retries-forever" else 4):
            r = self.ask(0x42)
            if r is None:
                continue
            command, data, _ = r
            if command == 0x42:
                return
            code = data[0] if data else 0
            if self.defect == "no-retry" and 0x09 <= code <= 0x0D:
                self.ask(0x46)
                return
            if self.react(code):
                return
        self.reset()

    def run(self):
        if self.defect == "naive-poll":
            # Wait out initialization (2.4.1), then poll: no status, no reaction to anything.
            frame = bytes([ADDRESS, 0x42, xor([ADDRESS, 0x42])])
            self.line.sleep_until(0.120)
            while True:
                self.line.sleep_until(self.line.idle_since + TIMEOUT_S + 0.001)
                self.line.write(frame)
                self.line.read_reply(0.010)
        self.start_up()
        while True:
            self.poll()
            self.line.sleep_until(self.line.now() + self.poll_s)


def main():
    args = sys.argv[1:]
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if args else 2
    port = args[0]
    defect = None
    poll_s = 0.020
    if "--defect" in args:
        defect = args[args.index("--defect") + 1]
        if defect not in DEFECTS:
            print(f"unknown defect {defect}; known: {', '.join(DEFECTS)}", file=sys.stderr)
            return 2
    if "--poll-ms" in args:
        poll_s = int(args[args.index("--poll-ms") + 1]) / 1000
    if defect == "sparse-poll":
        poll_s = 1.5
    user_baud = None
    if "--user-baud" in args:
        user_baud = int(args[args.index("--user-baud") + 1])
        if user_baud not in BAUD:
            print(f"not a HIPERFACE data rate: {user_baud}", file=sys.stderr)
            return 2
    baud = None if defect == "no-baud" else 9600
    line = Line(port, baud)
    if defect == "receive-idle":
        line.reply_end_s = 2 * CHAR_S
    Master(line, defect, poll_s, user_baud).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
