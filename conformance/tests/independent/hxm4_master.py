#!/usr/bin/env python3
"""HX-M4: the encoder interface of a drive (a HIPERFACE master) for a
legacy-edition HIPERFACE encoder (SICK|STEGMANN HIPERFACE description), with
the master rules of the current HIPERFACE specification.

    python3 hxm4_master.py PORT [--defect dNN ...] [--list-defects]

The process start is taken as the encoder's power-on. The master waits out the
encoder's initialization, reads the encoder status and the type label (the
Extended Type Label too for an encoder of type FFh), then reads the position
cyclically, reacting to error replies, missing replies, broken replies and the
warning bit. It runs until it is killed (SIGTERM, SIGINT).
"""
import argparse
import os
import select
import signal
import sys
import termios
import time
import tty

T_START = time.monotonic()

DEFECT_IDS = ["d%02d" % i for i in range(1, 17)]
_DEFECTS = set()


def defect(name):
    return name in _DEFECTS


# ---------------------------------------------------------------- constants
DEFAULT_BAUD = 9600
BAUD_CONST = {
    600: termios.B600, 1200: termios.B1200, 2400: termios.B2400,
    4800: termios.B4800, 9600: termios.B9600, 19200: termios.B19200,
    38400: termios.B38400,
}
SETTINGS_RATE = {0: 600, 1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}

# Master data length and slave data length (bytes) per command, 000 Table 10ff.
REQ_LEN = {0x42: 0, 0x44: 1, 0x46: 0, 0x4A: 4, 0x4C: 1, 0x4E: 0, 0x50: 0,
           0x52: 0, 0x53: 0, 0x56: 0}
RSP_LEN = {0x42: 4, 0x44: 3, 0x46: 3, 0x4C: 2, 0x4E: 2, 0x50: 1, 0x52: 4,
           0x56: 37}
# Maximum response time (ms) after the request's timeout, 000 Table 10.
RESP_MS = {0x42: 10, 0x43: 40, 0x44: 5, 0x46: 5, 0x47: 30, 0x49: 30,
           0x4A: 30, 0x4B: 250, 0x4C: 5, 0x4D: 70, 0x4E: 5, 0x4F: 40,
           0x50: 5, 0x52: 5, 0x55: 40, 0x56: 5, 0x57: 40}

PROTOCOL_CODES = {0x09, 0x0A, 0x0B, 0x0C, 0x0D}
# Table 74: "Retry command. If error persists, SW reset of Slave." (and the
# initialization faults that ask for a SW reset when reported by Read Position)
RETRY_RESET_CODES = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x1C, 0x1D, 0x20,
                     0x21, 0x23, 0x24}
NO_ACTION_CODES = {0x07, 0x08, 0x0E, 0x0F, 0x10, 0x11, 0x12, 0x1E, 0x1F}
KNOWN_CODES = (PROTOCOL_CODES | RETRY_RESET_CODES | NO_ACTION_CODES | {0x22})
# Critical when found on the stack at start-up (Table 74, Initialization rows)
STARTUP_CRITICAL = {0x01, 0x02, 0x03, 0x04, 0x05, 0x1D, 0x20, 0x21}
PAIRS_06 = {0x01, 0x02, 0x03, 0x04, 0x05, 0x08, 0x12, 0x21}

MAX_RETRIES = 3          # per request, for protocol errors / lost / broken replies
POSITION_FAULT_RETRIES = 2
MAX_RESETS = 2           # SW resets before giving up on a persisting fault
PERIOD_S = 0.100         # cyclic request period
ETL_SIZE = 64
ETL_CHUNK = 16


def xor(data):
    c = 0
    for b in data:
        c ^= b
    return c


def log(msg):
    sys.stderr.write("hxm4 %8.3f %s\n" % (time.monotonic() - T_START, msg))
    sys.stderr.flush()


class Reply:
    def __init__(self, status, raw=b"", t_end=0.0, req_cmd=0, deadline=0.0):
        self.status = status          # 'ok', 'none', 'bad'
        self.raw = bytes(raw)
        self.t_end = t_end            # end of the request frame
        self.deadline = deadline      # end of the reply window
        self.addr = raw[0] if len(raw) > 0 else None
        self.cmd = raw[1] if len(raw) > 1 else None
        self.warning = bool(self.cmd & 0x80) if self.cmd is not None else False
        self.error = (status == "ok" and (self.cmd & 0x7F) == 0x50
                      and req_cmd != 0x50)
        self.data = self.raw[2:-1] if status == "ok" else b""
        self.code = self.data[0] if self.error and self.data else None


class Master:
    def __init__(self, port, address=0x40, period=PERIOD_S, verbose=False):
        self.addr = address
        self.period = period
        self.verbose = verbose
        self.fd = os.open(port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.fd)
        self.baud = None
        self.set_rate(DEFAULT_BAUD)
        termios.tcflush(self.fd, termios.TCIOFLUSH)
        self.last_activity = time.monotonic()
        self.stored_rate = DEFAULT_BAUD
        self.type_code = None
        self.etl = None
        self.position = None
        self.position_enabled = True
        self.motor_stopped = False
        self.resets = 0
        self.good_reads = 0
        self.warn_latched = False

    # ------------------------------------------------------------ line
    def set_rate(self, baud):
        attrs = termios.tcgetattr(self.fd)
        attrs[2] &= ~(termios.CSIZE | termios.PARODD | termios.CSTOPB)
        attrs[2] |= termios.CS8 | termios.PARENB | termios.CREAD | termios.CLOCAL
        attrs[4] = attrs[5] = BAUD_CONST[baud]
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
        self.baud = baud

    def char_time(self):
        return 11.0 / self.baud                    # start, 8 data, parity, stop

    def timeout(self):
        return 55.0 / self.baud                    # 000:2.2.2, 5x11/data rate

    def pause(self):
        if defect("d02"):
            return 44.0 / self.baud
        return self.timeout() + 0.0015

    def rx_silence(self):
        return self.timeout() + 0.002

    def _read_available(self, wait):
        r, _, _ = select.select([self.fd], [], [], max(0.0, wait))
        if not r:
            return b""
        try:
            data = os.read(self.fd, 1024)
        except BlockingIOError:
            return b""
        except OSError:
            time.sleep(0.001)
            return b""
        if data:
            self.last_activity = time.monotonic()
        return data

    def idle_until(self, t):
        """Wait until monotonic time t, taking in (and discarding) stray input."""
        while True:
            now = time.monotonic()
            if now >= t:
                return
            data = self._read_available(t - now)
            if data and self.verbose:
                log("stray input %s" % data.hex())

    def wait_quiet(self, quiet):
        """Wait until the line has been silent for `quiet` seconds."""
        while True:
            now = time.monotonic()
            due = self.last_activity + quiet
            if now >= due:
                return
            self._read_available(due - now)

    def send(self, frame, slow=False):
        t0 = time.monotonic()
        if slow:
            for b in frame:
                os.write(self.fd, bytes([b]))
                time.sleep(0.010)
        else:
            os.write(self.fd, frame)
        try:
            termios.tcdrain(self.fd)
        except termios.error:
            pass
        t_end = max(time.monotonic(), t0 + len(frame) * self.char_time())
        self.last_activity = t_end
        return t_end

    def frame(self, payload):
        return bytes(payload) + bytes([xor(payload)])

    # ------------------------------------------------------------ transactions
    def expected_len(self, cmd, buf, payload):
        if len(buf) < 2:
            return None
        if (buf[1] & 0x7F) == 0x50 and cmd != 0x50:
            return 4
        if cmd == 0x4A and len(payload) >= 5:
            return 3 + 3 + payload[4]
        return 3 + RSP_LEN.get(cmd & 0x7F, 0)

    def transact(self, payload, retry=False, raw_frame=None):
        cmd = payload[1] & 0x7F
        frame = raw_frame if raw_frame is not None else self.frame(payload)
        self.wait_quiet(self.pause())
        t_end = self.send(frame, slow=retry and defect("d04"))
        deadline = t_end + self.timeout() + RESP_MS.get(cmd, 40) / 1000.0 + 0.040
        buf = bytearray()
        t_last = None
        exp = None
        while True:
            if buf:
                exp = self.expected_len(cmd, buf, payload)
                if exp is not None and len(buf) >= exp:
                    break
                limit = t_last + self.rx_silence()
            else:
                limit = deadline
            now = time.monotonic()
            if now >= limit:
                break
            data = self._read_available(limit - now)
            if data:
                t_last = time.monotonic()
                buf += data
        if not buf:
            return Reply("none", t_end=t_end, req_cmd=cmd, deadline=deadline)
        ok = (exp is not None and len(buf) == exp and buf[0] == self.addr
              and xor(buf[:-1]) == buf[-1]
              and (buf[1] & 0x7F) in (cmd, 0x50))
        if not ok:
            if self.verbose:
                log("broken reply %s" % bytes(buf).hex())
            return Reply("bad", buf, t_end=t_end, req_cmd=cmd)
        return Reply("ok", buf, t_end=t_end, req_cmd=cmd)

    def after_lost_reply(self, r):
        """No reply: the encoder may be (re)initializing. Retry only when its
        initialization time has passed even if it began at the end of the
        reply window."""
        if defect("d01"):
            return
        self.idle_until(r.deadline + 0.100 + 0.010)

    def after_broken_reply(self):
        self.wait_quiet(0.030)

    def request(self, payload, handle_warning=True):
        """A request with the retries of 000:3.3.4 for lost, broken and
        protocol-error replies. Returns the last Reply (or None if lost)."""
        attempt = 0
        while True:
            saved = None
            if attempt > 0 and defect("d06") and last.status == "none":
                saved = self.baud
                self.set_rate(self.stored_rate)
            r = self.transact(payload, retry=attempt > 0)
            if saved is not None:
                self.set_rate(saved)
            last = r
            if r.status == "ok" and not (r.error and r.code in PROTOCOL_CODES):
                if r.warning and handle_warning and (payload[1] & 0x7F) != 0x50:
                    self.on_warning(r)
                elif not r.warning:
                    self.warn_latched = False
                return r
            attempt += 1
            if r.status == "none":
                if attempt > MAX_RETRIES:
                    log("no reply to %02Xh" % payload[1])
                    return r
                self.after_lost_reply(r)
            elif r.status == "bad":
                self.after_broken_reply()
                if attempt > MAX_RETRIES:
                    log("no valid reply to %02Xh" % payload[1])
                    return r
            else:
                if attempt > MAX_RETRIES:
                    log("protocol error %02Xh persists on %02Xh" % (r.code, payload[1]))
                    return r

    # ------------------------------------------------------------ warnings
    def read_stack(self, from_warning=False, limit=6):
        codes = []
        for _ in range(limit):
            payload = [self.addr, 0x50]
            raw = None
            if from_warning and defect("d13"):
                raw = self.frame(payload) + b"\x00"
            r = self.transact(payload, raw_frame=raw)
            tries = 0
            while r.status != "ok" and tries < 2:
                tries += 1
                if r.status == "none":
                    self.after_lost_reply(r)
                else:
                    self.after_broken_reply()
                r = self.transact(payload, retry=True, raw_frame=raw)
            if r.status != "ok":
                break
            code = r.data[0] if r.data else 0
            if code == 0:
                break
            codes.append(code)
            if not r.warning:
                break
        if codes:
            log("encoder status codes: %s" % " ".join("%02Xh" % c for c in codes))
        return codes

    def on_warning(self, reply):
        if defect("d09"):
            if self.warn_latched:
                return
            self.warn_latched = True
            codes = self.read_stack(from_warning=True, limit=1)
        else:
            codes = self.read_stack(from_warning=True)
        action = self.classify_stack(codes, startup=False)
        if defect("d07"):
            self.transact([reply.addr, reply.cmd])
        if action == "reset":
            self.sw_reset()
        elif action == "disable":
            self.disable_position("status codes")

    def classify_stack(self, codes, startup):
        s = set(codes)
        action = None
        if 0x06 in s:
            partners = s & PAIRS_06
            if not partners or (partners - {0x08}):
                action = "reset"
        for c in s - {0x06}:
            if c not in KNOWN_CODES:
                log("unknown status code %02Xh: motor stop" % c)
                self.motor_stopped = True
                if action is None:
                    action = "disable"
            elif c == 0x22:
                action = action or "disable"
            elif startup and c in STARTUP_CRITICAL:
                action = "reset"
            elif not startup and c in {0x02, 0x03, 0x04, 0x05}:
                action = "reset"
        if startup and action == "disable":
            self.disable_position("status at start-up")
            action = None
        return action

    def disable_position(self, why):
        if self.position_enabled:
            log("position reads stopped (%s); sine/cosine only" % why)
        self.position_enabled = False
        self.motor_stopped = True

    # ------------------------------------------------------------ reset
    def sw_reset(self):
        if self.resets >= MAX_RESETS:
            log("fault persists after %d SW resets: motor stop" % self.resets)
            self.disable_position("resets exhausted")
            return
        self.resets += 1
        self.good_reads = 0
        log("encoder reset (53h)")
        payload = [self.addr, 0x53]
        frame = self.frame(payload)
        if defect("d05"):
            frame = bytes([self.addr, 0x53, 0x53])
        if defect("d14"):
            t_write = time.monotonic()
            r = self.transact(payload, raw_frame=frame)
            t_end = r.t_end
            if r.status == "none":
                self.wait_quiet(self.pause())
                t_write = time.monotonic()
                t_end = self.send(frame)
        else:
            self.wait_quiet(self.pause())
            t_write = time.monotonic()
            t_end = self.send(frame)
        if defect("d08"):
            self.idle_until(t_write + 0.100)
        else:
            self.idle_until(t_end + self.timeout() + 0.100 + 0.030)
        if defect("d11"):
            self.set_rate(self.stored_rate)
        self.startup(after_reset=True)

    # ------------------------------------------------------------ start-up
    def startup(self, after_reset=False):
        if not after_reset:
            self.idle_until(T_START + 0.150)
        codes = []
        if not defect("d03"):
            codes = self.read_stack()
        label = self.request([self.addr, 0x52])
        if label.status == "ok" and not label.error and len(label.data) == 4:
            settings, self.type_code = label.data[0], label.data[1]
            self.stored_rate = SETTINGS_RATE.get(settings & 0x07, DEFAULT_BAUD)
            log("type label: settings %02Xh type %02Xh memory %02Xh option %02Xh"
                % tuple(label.data))
            if self.type_code == 0xFF:
                self.read_etl()
        action = self.classify_stack(codes, startup=True)
        if action == "reset":
            self.sw_reset()
            return
        self.poll()

    def read_etl(self):
        data = bytearray()
        end = ETL_SIZE + ETL_CHUNK if defect("d16") else ETL_SIZE
        for off in range(0, end, ETL_CHUNK):
            payload = [self.addr, 0x4A, 0xFF, off, ETL_CHUNK]
            if not defect("d10"):
                payload.append(0x55)
            r = self.request(payload)
            if r.status != "ok":
                break
            if r.error:
                log("extended type label: error %02Xh, going on" % r.code)
                break
            data += r.data[3:]
        if len(data) >= ETL_SIZE:
            self.etl = bytes(data[:ETL_SIZE])
            res = int.from_bytes(self.etl[2:6], "big")
            log("extended type label: %d periods, designation %r"
                % (res, self.etl[0x0A:0x1C].rstrip(b"\0").decode("ascii", "replace")))

    # ------------------------------------------------------------ cyclic
    def poll(self):
        if self.position_enabled:
            self.read_position()
        else:
            self.request([self.addr, 0x50], handle_warning=False)

    def read_position(self):
        fault_tries = 0
        while True:
            r = self.request([self.addr, 0x42])
            if r.status != "ok":
                return
            if not r.error:
                self.position = int.from_bytes(r.data, "big")
                self.good_reads += 1
                if self.good_reads >= 100:
                    self.resets = 0
                return
            code = r.code
            log("read position: error %02Xh" % code)
            if r.warning:
                self.on_warning(r)
            if code in PROTOCOL_CODES:
                return                              # retries exhausted in request()
            if code == 0x22:
                self.disable_position("multiturn sync fault")
                return
            if code in RETRY_RESET_CODES:
                fault_tries += 1
                if fault_tries <= POSITION_FAULT_RETRIES:
                    continue
                self.sw_reset()
                return
            if code in NO_ACTION_CODES:
                return
            if defect("d12"):
                return
            log("unknown fault code %02Xh: worst case, motor stop" % code)
            self.disable_position("unknown fault code")
            return

    def run(self):
        self.startup()
        next_t = time.monotonic() + self.period
        while True:
            self.idle_until(next_t)
            if defect("d15") and not self.position_enabled:
                next_t = time.monotonic() + 3600.0
                continue
            self.poll()
            next_t += self.period
            now = time.monotonic()
            while next_t <= now:
                next_t += self.period


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("port", nargs="?", help="serial port / pseudo-terminal path")
    ap.add_argument("--defect", action="append", default=[], metavar="dNN",
                    help="switch on a defect (repeatable, or comma-separated)")
    ap.add_argument("--list-defects", action="store_true", help="print the defect ids")
    ap.add_argument("--period-ms", type=float, default=PERIOD_S * 1000,
                    help="cyclic request period (default 100)")
    ap.add_argument("--address", type=lambda s: int(s, 0), default=0x40,
                    help="encoder address byte (default 0x40)")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    if args.list_defects:
        print("\n".join(DEFECT_IDS))
        return 0
    if not args.port:
        ap.error("PORT is required")
    for item in args.defect:
        for d in item.split(","):
            d = d.strip().lower()
            if d not in DEFECT_IDS:
                ap.error("unknown defect id %r" % d)
            _DEFECTS.add(d)

    def stop(signum, frame):
        raise SystemExit(0)
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    try:
        m = Master(args.port, address=args.address, period=args.period_ms / 1000.0,
                   verbose=args.verbose)
    except (OSError, termios.error) as e:
        sys.stderr.write("hxm4: cannot open %s as a serial port: %s\n" % (args.port, e))
        return 2
    try:
        m.run()
    except SystemExit:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
