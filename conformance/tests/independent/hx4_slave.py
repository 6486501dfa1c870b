#!/usr/bin/env python3
"""HX-4: an independent HIPERFACE slave (encoder) simulator, legacy edition.

Data sheet (hx4.toml; hx4-defects.md has it in a table): a legacy SICK|STEGMANN-style multiturn kit motor
feedback ("SCL-like"): 1024 sine/cosine periods per turn, 32 steps per period
(32768 steps/turn), 4096 turns, absolute range 2^27 steps. Command set of the
legacy description (002): 42h 43h 44h 46h 47h 49h 4Ah 4Bh 4Ch 4Dh 4Eh 4Fh 50h
52h 53h 55h 56h 57h 63h. 512 bytes EEPROM (20h blocks), 448 bytes (1Ch blocks)
for user data fields. One analog channel: F0h (legacy temperature).
No Extended Type Label (type code 27h), no 67h/6Ah/6Bh/6Ch.

Written from the specification texts only (000 current edition, 002 legacy
description); standard library only.

Usage:
    hx4_slave.py --pty [--defect dNN ...] [--temperature C] [--position STEPS]
    hx4_slave.py --list-defects
"""

import argparse
import os
import select
import signal
import stat
import sys
import time
import tty

# ---------------------------------------------------------------------------
# Data sheet
# ---------------------------------------------------------------------------
FACTORY_ADDRESS = 0x40
DEFAULT_SETTINGS = 0xE4          # 9600 Bd, 8E1, long timeout, standard slave
TYPE_CODE = 0x27
TOTAL_BLOCKS = 0x20              # 512 bytes EEPROM
USER_BLOCKS = 0x1C               # 448 bytes for data fields
OPTION_CODE = 0x01
SERIAL = b"174002031"            # 9 ASCII digits
FIRMWARE = b"SCL-L 2.13"         # up to 20 chars, padded with 00h
FIRMWARE_DATE = b"14.03.03"      # DD.MM.YY
PERIODS_PER_TURN = 1024
STEPS_PER_TURN = PERIODS_PER_TURN * 32
TURNS = 4096
RANGE = STEPS_PER_TURN * TURNS   # 2^27
ANALOG_TEMPERATURE = 0xF0
TEMP_MIN_C = -40.0
TEMP_MAX_C = 115.0

RATES = {0: 600, 1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}
SUPPORTED_RATES = {1200, 2400, 4800, 9600, 19200, 38400}

INIT_S = 0.100                   # initialization after power-on/reset (000:T9)
DEFAULT_WINDOW_S = 1.000         # legacy: default settings for "1 second approx" (002, 57h)

# Master data length per command: fixed number, or None for Store Data (variable)
REQ_LEN = {
    0x42: 0, 0x43: 5, 0x44: 1, 0x46: 0, 0x47: 0, 0x49: 1, 0x4A: 4, 0x4B: None,
    0x4C: 1, 0x4D: 3, 0x4E: 0, 0x4F: 3, 0x50: 0, 0x52: 0, 0x53: 0, 0x55: 2,
    0x56: 0, 0x57: 2, 0x63: 5,
}
SUPPORTED = set(REQ_LEN)

# Processing time before the reply starts, after the request's timeout (ms).
# All well inside the maximum response times of 000 Table 10 / 002.
PROC_MS = {
    0x42: 1.2, 0x43: 12.0, 0x44: 1.0, 0x46: 1.0, 0x47: 8.0, 0x49: 8.0,
    0x4A: 2.5, 0x4B: 3.0, 0x4C: 1.0, 0x4D: 15.0, 0x4E: 1.0, 0x4F: 10.0,
    0x50: 1.0, 0x52: 1.0, 0x55: 10.0, 0x56: 1.2, 0x57: 10.0, 0x63: 20.0,
}
ERR_PROC_MS = 1.0

NUM_DEFECTS = 16
DEFECT_IDS = ["d%02d" % i for i in range(1, NUM_DEFECTS + 1)]


def xor(bs):
    c = 0
    for b in bs:
        c ^= b
    return c


def settings_timeout_s(settings, defects=frozenset()):
    baud = RATES.get(settings & 0x07, 9600)
    chars = 44 if settings & 0x40 else 11      # 002: 11/baud or 44/baud (default)
    if 8 in defects and baud < 9600:
        baud = 9600
    return chars / baud


class Field:
    """A data field: its status byte and its start in the user EEPROM area."""
    __slots__ = ("status", "start")

    def __init__(self, status, start):
        self.status = status
        self.start = start

    @property
    def size(self):
        return ((self.status & 0x07) + 1) * 16

    @property
    def blocks(self):
        return (self.status & 0x07) + 1


class Slave:
    def __init__(self, defects, temperature, position):
        self.defects = set(defects)
        self.temperature = temperature
        self.raw = position % RANGE
        # ---- non-volatile memory (EEPROM) -------------------------------
        self.address = FACTORY_ADDRESS
        self.settings = DEFAULT_SETTINGS          # stored settings
        self.codes = [0x55, 0x55, 0x55, 0x55]
        self.offset = 0
        self.counter_ee = 0
        self.fields = []
        self.ee = bytearray([0xFF]) * (USER_BLOCKS * 16)   # user area, erased
        # ---- volatile state ---------------------------------------------
        self.counter = 0
        self.stack = []
        self.rx = bytearray()
        self.last_rx = 0.0
        self.pending = []        # list of (send_at, bytes, after) sorted
        self.active = DEFAULT_SETTINGS
        self.rx_address = self.address
        self.init_until = 0.0
        self.uart_on_at = 0.0
        self.window_until = 0.0
        self.window_kept = False
        self.position_valid_at = 0.0
        self.reset_pending_at = None
        self.power_on(time.monotonic(), software=False)

    def d(self, n):
        return n in self.defects

    # ------------------------------------------------------------------
    # Start-up
    # ------------------------------------------------------------------
    def power_on(self, t, software):
        self.rx = bytearray()
        self.stack = []
        self.active = DEFAULT_SETTINGS
        self.window_kept = False
        self.init_until = t + INIT_S
        self.uart_on_at = self.init_until
        self.position_valid_at = self.init_until
        if self.d(13):
            self.uart_on_at = t + 0.030
        self.window_until = t + DEFAULT_WINDOW_S
        self.rx_address = self.address
        if self.d(2) and software:
            pass
        else:
            self.counter_ee = self.counter
        self.counter = self.counter_ee
        if self.d(6) and software:
            self.push(0x07)

    def timeout_s(self):
        return settings_timeout_s(self.active, self.defects)

    def tick_state(self, now):
        if (not self.window_kept and self.window_until and now >= self.window_until):
            self.active = self.settings
            self.window_until = 0.0
        if self.reset_pending_at is not None and now >= self.reset_pending_at:
            t = self.reset_pending_at
            self.reset_pending_at = None
            self.power_on(t, software=True)

    # ------------------------------------------------------------------
    # Error stack (000:2.3.4, Table 27)
    # ------------------------------------------------------------------
    def push(self, code):
        if code in self.stack:
            return
        if len(self.stack) >= 4:
            self.stack.pop(0)
        self.stack.append(code)

    def check_world(self):
        if not (TEMP_MIN_C <= self.temperature <= TEMP_MAX_C):
            self.push(0x1E)

    # ------------------------------------------------------------------
    # Receiving
    # ------------------------------------------------------------------
    def on_bytes(self, data, now):
        self.tick_state(now)
        if now < self.uart_on_at or self.reset_pending_at is not None:
            return                                  # UART off: initialization
        # a frame whose timeout already elapsed is processed first
        self.poll(now, process_only=True)
        for b in data:
            self.rx.append(b)
            self.last_rx = now
            if self.d(4) and len(self.rx) == 3 and self.rx[1] == 0x42 \
                    and self.rx[0] in (self.rx_address, 0xFF) and xor(self.rx) == 0:
                frame = bytes(self.rx)
                self.rx = bytearray()
                self.process(frame, now, fast=True)

    def next_deadline(self):
        ds = []
        if self.rx:
            ds.append(self.last_rx + self.timeout_s())
        for p in self.pending:
            ds.append(p[0])
        if self.reset_pending_at is not None:
            ds.append(self.reset_pending_at)
        if not self.window_kept and self.window_until:
            ds.append(self.window_until)
        return min(ds) if ds else None

    def poll(self, now, process_only=False):
        self.tick_state(now)
        if self.rx and now >= self.last_rx + self.timeout_s():
            frame = bytes(self.rx)
            t_end = self.last_rx + self.timeout_s()
            self.rx = bytearray()
            self.process(frame, t_end)
        if process_only:
            return []
        out = []
        while self.pending and self.pending[0][0] <= now:
            _, bs, after = self.pending.pop(0)
            out.append(bs)
            if after:
                after()
        return out

    def schedule(self, t, frame, after=None):
        self.pending.append((t, frame, after))
        self.pending.sort(key=lambda p: p[0])

    # ------------------------------------------------------------------
    # Frame processing
    # ------------------------------------------------------------------
    def reply(self, cmd, data=b""):
        self.check_world()
        c = cmd | (0x80 if self.stack else 0)
        body = bytes([self.address, c]) + bytes(data)
        return body

    def finish(self, body):
        if self.d(12) and len(body) > 128:
            return body + bytes([xor(body[:128])])
        return body + bytes([xor(body)])

    def process(self, frame, t_end, fast=False):
        if not frame:
            return
        a = frame[0]
        if a != 0xFF and a != self.rx_address:
            return                                   # not addressed to us
        broadcast = a == 0xFF
        res = self.execute(frame, t_end, broadcast)
        if res is None:
            return
        body, delay_ms, after = res
        if fast:
            delay_ms = 0.8
        self.schedule(t_end + delay_ms / 1000.0, self.finish(body), after)

    def error(self, code, frame=None, broadcast=False):
        self.check_world()
        c = 0x50 | (0x80 if self.stack else 0)
        addr = self.address
        if self.d(3) and broadcast:
            addr = 0xFF
        if self.d(11) and code == 0x0F:
            self.push(code)
        return (bytes([addr, c, code]), ERR_PROC_MS, None)

    def execute(self, frame, t_end, broadcast):
        err = lambda code: self.error(code, frame, broadcast)
        if len(frame) < 2:
            return err(0x0C)
        if xor(frame) != 0:
            return err(0x0A)
        # a plausible request keeps the default settings (000:T9, 002 57h)
        if self.window_until and t_end < self.window_until:
            self.window_kept = True
        if len(frame) < 3:
            return err(0x0C)
        cmd = frame[1]
        data = frame[2:-1]
        if cmd not in SUPPORTED:
            return err(0x0B)
        n = REQ_LEN[cmd]
        if n is None:                                # Store Data
            if len(data) < 5 or len(data) > 132 or len(data) != 4 + data[2]:
                return err(0x0C)
        elif len(data) != n:
            return err(0x0C)
        handler = getattr(self, "cmd_%02X" % cmd)
        res = handler(data, t_end, broadcast)
        if res is None:
            return None
        if res[0] == "err":
            return err(res[1])
        body, delay = res[0], res[1]
        after = res[2] if len(res) > 2 else None
        return (body, delay, after)

    # ------------------------------------------------------------------
    # Commands
    # ------------------------------------------------------------------
    def position(self, t):
        if self.d(13) and t < self.position_valid_at:
            return 0
        return (self.raw + self.offset) % RANGE

    def cmd_42(self, data, t, bc):
        p = self.position(t)
        return (self.reply(0x42, p.to_bytes(4, "big")), PROC_MS[0x42])

    def _set_offset(self, preset):
        off = (preset - self.raw) % RANGE
        if self.d(7):
            off &= 0xFFFFFF
        self.offset = off

    def cmd_43(self, data, t, bc):
        if data[4] != self.codes[0]:
            return ("err", 0x0F)
        preset = int.from_bytes(data[0:4], "big")
        if preset >= RANGE:
            return ("err", 0x0D)
        self._set_offset(preset)
        return (self.reply(0x43), PROC_MS[0x43])

    def cmd_63(self, data, t, bc):
        if data[4] != self.codes[0] and not self.d(14):
            return ("err", 0x0F)
        preset = int.from_bytes(data[0:4], "big")
        if preset >= RANGE:
            return ("err", 0x0D)
        # internal track synchronisation: virtual zero at the current shaft
        # position, then the given position stored as offset
        self.offset = (preset - self.raw) % RANGE
        return (self.reply(0x63), PROC_MS[0x63])

    def analog_temperature(self):
        # legacy encoding (000 Table 14, F0h): temperature = (value + 40) / 2.048
        v = int(round(self.temperature * 2.048 - 40))
        return v & 0xFFFF

    def cmd_44(self, data, t, bc):
        ch = data[0]
        if ch != ANALOG_TEMPERATURE:
            return ("err", 0x0D)
        v = self.analog_temperature()
        return (self.reply(0x44, bytes([ch]) + v.to_bytes(2, "big")), PROC_MS[0x44])

    def cmd_46(self, data, t, bc):
        return (self.reply(0x46, self.counter.to_bytes(3, "big")), PROC_MS[0x46])

    def cmd_47(self, data, t, bc):
        if self.counter >= 0xFFFFFF:
            # 002: "Any overflow is shown by the ERROR bit"; counter stays at max
            self.push(0x08)
            return (self.reply(0x47), PROC_MS[0x47])
        self.counter += 1
        if not self.d(2):
            self.counter_ee = self.counter
        return (self.reply(0x47), PROC_MS[0x47])

    def cmd_49(self, data, t, bc):
        if data[0] != self.codes[0]:
            return ("err", 0x0F)
        self.counter = 0
        self.counter_ee = 0
        return (self.reply(0x49), PROC_MS[0x49])

    # ---- data fields -------------------------------------------------
    def used_blocks(self):
        return sum(f.blocks for f in self.fields)

    def free_blocks(self):
        return USER_BLOCKS - self.used_blocks()

    def field(self, num):
        if num < len(self.fields):
            return self.fields[num]
        return None

    def cmd_4A(self, data, t, bc):
        num, off, cnt, code = data
        f = self.field(num)
        if f is None:
            return ("err", 0x12)
        if f.status & 0x08 and code != self.codes[(f.status >> 4) & 3]:
            return ("err", 0x0F)
        limit = f.size + (1 if self.d(1) else 0)
        if cnt == 0 or cnt > 128 or off >= limit or off + cnt > limit:
            return ("err", 0x11)
        a = f.start + off
        payload = bytes(self.ee[a:a + cnt])
        payload += bytes([0xFF]) * (cnt - len(payload))
        return (self.reply(0x4A, bytes([num, off, cnt]) + payload), PROC_MS[0x4A])

    def cmd_4B(self, data, t, bc):
        num, off, cnt, code = data[0], data[1], data[2], data[3]
        payload = data[4:]
        f = self.field(num)
        if f is None:
            return ("err", 0x12)
        if f.status & 0x08:
            if code != self.codes[(f.status >> 4) & 3]:
                return ("err", 0x0F)
            if not f.status & 0x40:
                return ("err", 0x0E)
        elif not f.status & 0x40 and not self.d(5):
            return ("err", 0x0E)
        if off >= f.size or off + cnt > f.size:
            return ("err", 0x11)
        a = f.start + off
        self.ee[a:a + cnt] = payload
        if self.d(15):
            delay = 3.0 + 4.2 * cnt
        else:
            pages = (off + cnt - 1) // 16 - off // 16 + 1
            delay = 3.0 + 5.0 * pages                # 16-byte page writes
        return (self.reply(0x4B, bytes([num, off, cnt])), delay)

    def cmd_4C(self, data, t, bc):
        num = data[0]
        f = self.field(num)
        if f is None:
            return ("err", 0x12)
        return (self.reply(0x4C, bytes([num, f.status])), PROC_MS[0x4C])

    def cmd_4D(self, data, t, bc):
        num, status, code = data
        last = len(self.fields) - 1
        if num == len(self.fields):                  # create the next field
            if not status & 0x80:
                return ("err", 0x12)                 # delete of a field that does not exist
            if code != self.codes[(status >> 4) & 3]:
                return ("err", 0x0F)
            blocks = (status & 0x07) + 1
            if blocks > self.free_blocks():
                return ("err", 0x10)
            self.fields.append(Field(status, self.used_blocks() * 16))
            return (self.reply(0x4D, bytes([num, status])), PROC_MS[0x4D])
        f = self.field(num)
        if f is None:
            return ("err", 0x12)
        old_code = self.codes[(f.status >> 4) & 3]
        new_code = self.codes[(status >> 4) & 3]
        if status & 0x80:                            # modify
            if code != old_code and code != new_code:
                return ("err", 0x0F)
            new_blocks = (status & 0x07) + 1
            if new_blocks != f.blocks:
                if num != last:
                    return ("err", 0x12)
                if new_blocks - f.blocks > self.free_blocks():
                    return ("err", 0x10)
            f.status = status
            return (self.reply(0x4D, bytes([num, status])), PROC_MS[0x4D])
        # delete
        if num != last:
            return ("err", 0x12)
        if code != old_code:
            return ("err", 0x0F)
        if (status | 0x80) != f.status:
            return ("err", 0x0D)
        self.fields.pop()
        return (self.reply(0x4D, bytes([num, status])), PROC_MS[0x4D])

    def cmd_4E(self, data, t, bc):
        return (self.reply(0x4E, bytes([self.free_blocks(), len(self.fields)])), PROC_MS[0x4E])

    def cmd_4F(self, data, t, bc):
        n, old, new = data
        if self.d(9):
            n &= 0x03
        elif n > 3:
            return ("err", 0x0D)
        if old != self.codes[n]:
            return ("err", 0x0F)
        self.codes[n] = new
        return (self.reply(0x4F, bytes([data[0]])), PROC_MS[0x4F])

    # ---- status, identity, settings ----------------------------------
    def cmd_50(self, data, t, bc):
        self.check_world()
        code = self.stack.pop(0) if self.stack else 0x00
        c = 0x50 | (0x80 if self.stack else 0)
        return (bytes([self.address, c, code]), PROC_MS[0x50])

    def cmd_52(self, data, t, bc):
        return (self.reply(0x52, bytes([self.settings, TYPE_CODE, TOTAL_BLOCKS, OPTION_CODE])),
                PROC_MS[0x52])

    def cmd_53(self, data, t, bc):
        # executed once the request's timeout has elapsed; no reply (000:T29)
        if self.d(10) and bc:
            body = self.reply(0x53)
            self.reset_pending_at = t + 0.002
            return (body, 1.0)
        self.reset_pending_at = t
        return None

    def cmd_55(self, data, t, bc):
        new, code = data
        if code != self.codes[0]:
            return ("err", 0x0F)
        if not 0x40 <= new <= 0x5F:
            return ("err", 0x0D)
        self.address = new
        if not self.d(16):
            self.rx_address = new
        return (self.reply(0x55), PROC_MS[0x55])

    def cmd_56(self, data, t, bc):
        fw = FIRMWARE + bytes(20 - len(FIRMWARE))
        return (self.reply(0x56, SERIAL + fw + FIRMWARE_DATE), PROC_MS[0x56])

    def cmd_57(self, data, t, bc):
        s, code = data
        if code != self.codes[0]:
            return ("err", 0x0F)
        rate = RATES.get(s & 0x07)
        if rate is None or rate not in SUPPORTED_RATES:
            return ("err", 0x0D)
        if (s & 0x30) == 0x10 or s & 0x08 or not s & 0x80:
            return ("err", 0x0D)
        self.settings = s
        return (self.reply(0x57, bytes([s])), PROC_MS[0x57])


# ---------------------------------------------------------------------------
# Main loop
# ---------------------------------------------------------------------------
def watch_stdin():
    try:
        st = os.fstat(0)
    except OSError:
        return False
    if os.isatty(0):
        return True
    return stat.S_ISFIFO(st.st_mode) or stat.S_ISSOCK(st.st_mode)


def serve(slave):
    master, slave_fd = os.openpty()
    tty.setraw(slave_fd)
    path = os.ttyname(slave_fd)
    sys.stdout.write(path + "\n")
    sys.stdout.flush()

    stop = [False]

    class Stop(Exception):
        pass

    def on_term(signum, frame):
        stop[0] = True
        raise Stop()

    signal.signal(signal.SIGTERM, on_term)
    signal.signal(signal.SIGHUP, on_term)
    signal.signal(signal.SIGINT, on_term)

    fds = [master]
    if watch_stdin():
        fds.append(0)
    try:
        _loop(slave, master, fds, stop)
    except Stop:
        pass
    os.close(master)
    os.close(slave_fd)


def _loop(slave, master, fds, stop):
    while not stop[0]:
        now = time.monotonic()
        dl = slave.next_deadline()
        timeout = None if dl is None else max(0.0, dl - now)
        if timeout is not None:
            timeout = min(timeout, 5.0)
        try:
            r, _, _ = select.select(fds, [], [], timeout)
        except InterruptedError:
            continue
        now = time.monotonic()
        if master in r:
            try:
                data = os.read(master, 4096)
            except OSError:
                data = b""
                time.sleep(0.01)     # peer closed; keep serving, avoid spinning
            if data:
                slave.on_bytes(data, now)
        if 0 in r:
            try:
                if not os.read(0, 4096):
                    break
            except OSError:
                break
        for bs in slave.poll(time.monotonic()):
            try:
                os.write(master, bs)
            except OSError:
                pass


def main():
    ap = argparse.ArgumentParser(description="HX-4 legacy-edition HIPERFACE slave simulator")
    ap.add_argument("--pty", action="store_true", help="serve on a new pseudo-terminal")
    ap.add_argument("--defect", action="append", default=[], help="switch on a planted defect (dNN)")
    ap.add_argument("--list-defects", action="store_true")
    ap.add_argument("--temperature", type=float, default=35.2, help="encoder temperature, deg C")
    ap.add_argument("--position", type=int, default=5 * STEPS_PER_TURN + 0x2A57,
                    help="raw shaft position in steps")
    args = ap.parse_args()
    if args.list_defects:
        for d in DEFECT_IDS:
            print(d)
        return 0
    defects = set()
    for d in args.defect:
        for part in d.split(","):
            part = part.strip().lower()
            if part not in DEFECT_IDS:
                ap.error("unknown defect %r (see --list-defects)" % part)
            defects.add(int(part[1:]))
    if not args.pty:
        ap.error("--pty is required")
    serve(Slave(defects, args.temperature, args.position))
    return 0


if __name__ == "__main__":
    sys.exit(main())
