#!/usr/bin/env python3
"""HX-L: an independent HIPERFACE slave of the LEGACY edition, written from the
SICK-STEGMANN "Description of the HIPERFACE Interface" alone (seed 002, its English
half: "The Transmission Protocol" L397-466, "Command Set" L468-513, the command
sections L515-820 and the data field example L665-727), and from nothing in this
repository's Rust code. Line numbers below are 002's.

The figures of 002 (frame layouts, Fig. 20-42) did not survive in the text. Where the
text is silent, HX-L does what typical HIPERFACE firmware does; each such choice is
marked "latitude" in a comment.

Timeout (002 L426-432, L503)
  "TIMEOUT - programmable, 11/baud rate or 44/baud rate = default" (L426). HX-L's UART
  raises its receive interrupt at the END of each character (after the stop bit), as
  typical microcontroller UARTs do (000 2.2.2's note on this figure). The firmware
  restarts its timeout timer in that interrupt and counts the programmed 11 or 44 bit
  times (settings bit 6 = 0 or 1; bit time = 1/baud) from there. So a request is
  processed only when the line has been idle for the full 11/44 bit times after the end
  of its last character (L428); measured from the START of the last character that is
  22/55 bit times, which is what the later specification (000 2.2.2) wrote down.
  At 9600 Bd the default is 44/9600 = 4.58 ms (002 L503: "4.7 ms approx.").
  On the pseudo-terminal the time a byte is read stands for that interrupt; the whole
  reply is written in one write() once the timeout has elapsed, never earlier.

Power-up (002 L800-802, L767)
  After power-on (process start) and after Encoder Reset 53h (L767: "the same
  initialisation process"), HX-L initialises for INIT_S (60 ms; latitude: 002 gives no
  figure; its UART is not yet running, characters are lost). Until 1 s after power-on
  it listens with the default settings (9600 Bd, even parity, 44 bit times: E4h). A
  plausible message in that second (latitude: a frame to its own address or FFh with a
  correct checksum) keeps the defaults until the next power-up/reset; otherwise at 1 s
  it adopts the stored settings (--settings, 57h). 57h only changes the stored byte;
  it becomes active through 53h or power-up (L802).

Response times (002 L476-503): the "maximum response time" column, measured after the
timeout (L501). HX-L answers at the end of the timeout, Read Position 42h 2 ms later
(L528: the RS-485 driver is switched active 2 ms approx. before the reply).

Usage:
  hxl_slave.py --pty [--settings 0xNN] [--defect NAME ...] [--temperature C] [--log]
      creates a pseudo-terminal (raw), prints its path on the first stdout line, serves
      until stdin closes or SIGTERM.
  hxl_slave.py --list-defects

Its data sheet, for the harness, is hxl.toml next to this file. Defect switches make
it deliberately non-conformant, one rule at a time, for testing the harness's FAILs.
"""

import argparse
import os
import select
import signal
import stat
import sys
import time
import tty

# ---------------------------------------------------------------------------------
# Data sheet of the HX-L (must agree with hxl.toml)

FACTORY_ADDRESS = 0x40           # subscriber 0 + 40h (L447)
# RS485 settings byte (Fig. 42 lost; latitude, the usual SICK layout):
#   bits 0-2 data rate: 0=600 1=1200 2=2400 3=4800 4=9600 5=19200 6=38400 (L407 order)
#   bits 4-5 parity: 00 none, 10 even, 11 odd (01 reserved)
#   bit 6    timeout: 0 = 11/baud, 1 = 44/baud (L426)
#   bits 3,7 reserved, stored as given (factory: bit 7 = 1)
DEFAULT_SETTINGS = 0xE4          # 9600 Bd, even parity (L414-418), 44/baud (L426)
FACTORY_SETTINGS = 0xE4
BAUD = {0: 600, 1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}
FACTORY_CODE = 0x55              # Code 0 and access codes 0-3 when shipped (L499, L663)
TYPE_CODE = 0x61                 # "Encoder type", HX-L's own data sheet (L751-752)
OPTION_CODE = 0x00               # "Options" (L755-757)
EEPROM_BLOCKS = 0x10             # EEPR_Size: 16 * 16 = 256 bytes EEPROM (L753-754)
USER_BLOCKS = 0x08               # 128 bytes for data fields, as in 002's example (L671)
PERIODS_PER_TURN = 512
TURNS = 4096
STEPS_PER_PERIOD = 32            # "a resolution of 5 bits/period" (L535)
RANGE = STEPS_PER_PERIOD * PERIODS_PER_TURN * TURNS
SERIAL = b"061204711"            # 9-digit serial number (L780)
FIRMWARE = b"HXL-FW V01.30 legacy"   # exactly 20 characters ("up to 20", L784)
FIRMWARE_DATE = b"14.03.05"      # DD.MM.YY (L786)
TEMPERATURE_CHANNEL = 0x48       # Read Analogue Value channel: temperature, signed, 1 degC
TEMPERATURE_MIN = -20            # monitoring limits (L461): warning 1Eh outside
TEMPERATURE_MAX = 110
INIT_S = 0.060                   # latitude: 002 gives no initialisation time
DEFAULT_WINDOW_S = 1.000         # "for a time of 1 second approx." (L800)
DRIVER_ON_S = 0.002              # 42h: driver active 2 ms before the data (L528)

# Error codes. 002's text names no codes (its Fig. 35 is lost, L740 defers to the data
# sheet); latitude: HX-L's data sheet uses SICK's usual codes.
E_COUNTER_OVERFLOW = 0x08
E_CHECKSUM = 0x0A
E_UNKNOWN_COMMAND = 0x0B
E_LENGTH = 0x0C
E_ARGUMENT = 0x0D
E_WRITE_PROTECTED = 0x0E
E_ACCESS_CODE = 0x0F
E_FIELD_SIZE = 0x10
E_ADDRESS_RANGE = 0x11
E_NO_FIELD = 0x12
W_TEMPERATURE = 0x1E

# Master data bytes after the command byte (without checksum); latitude for the lost
# figures, the usual layouts. Store Data 4Bh: 4 + count.
REQUEST_DATA = {
    0x42: 0,   # -
    0x43: 5,   # Pos_HH Pos_H Pos_L Pos_LL Code0
    0x44: 1,   # CHANNEL
    0x46: 0,
    0x47: 0,
    0x49: 1,   # Code0
    0x4A: 4,   # Datafield, byte address, count, Access Code
    0x4C: 1,   # Datafield
    0x4D: 3,   # Datafield, status, Code          (002 example L689)
    0x4E: 0,   #                                   (002 example L677)
    0x4F: 3,   # Code_Nr, Old_Code, New_Code       (002 example L713)
    0x50: 0,
    0x52: 0,
    0x53: 0,
    0x55: 2,   # New_Address, Code0
    0x56: 0,
    0x57: 2,   # RS485 settings, Code0
    0x63: 5,   # Pos_HH Pos_H Pos_L Pos_LL Code0 (L814-816)
}
COMMANDS = set(REQUEST_DATA) | {0x4B}

DEFECTS = {
    "reply-checksum": "Read Type Label (52h) replies carry a wrong checksum",
    "early-reply": "Read Position (42h) is answered 0.3 ms after the request arrived, "
                   "without waiting for its timeout (L428)",
    "late-reply": "Read Counter (46h) is answered 40 ms after the timeout "
                  "(L480: max. 5 ms, L501: after the timeout)",
    "gap-in-reply": "Read Type Label (52h) reply: 2 bytes, a pause of three timeouts, the rest",
    "wrong-error-code": "unknown commands draw 0Dh (argument) instead of 0Bh (unknown command); "
                        "002 leaves the codes to the data sheet (L740), so a harness may call it latitude",
    "reset-answers": "Encoder Reset (53h) is acknowledged (L765: no acknowledgement)",
    "no-code-check": "Set Position (43h) accepts any Code 0 (L541)",
    "settings-at-once": "57h settings take effect at once, not at the next reset (L802)",
    "ignores-broadcast": "stays silent on the broadcast address FFh (L451)",
}


def xor(data):
    x = 0
    for b in data:
        x ^= b
    return x


class Field:
    """A data field. Status byte (Fig. 31/32 lost; read from 002's example, L688 C9h
    = 32 bytes, code 0, writable, code required; L700 E0h = 16 bytes, code 2, writable):
      bit 7 E   field defined (E = 0 deletes, L649)
      bit 6 WE  write enable (L631)
      bits 5-4  number of the access code (0...3, L603)
      bit 3 CE  code enable: the code is checked (L624)
      bits 2-0  size in 16-byte blocks - 1 (16...128 bytes, L603)
    (002's E0h has CE = 0 although its prose says "code must be given"; the bits win.
    Its request 40 4D 01 E0 55 69 carries a wrong checksum, B9h is right: HX-L answers
    that literal frame with 0Ah.)"""

    def __init__(self, status):
        self.status = status
        self.data = bytearray(b"\xff" * self.size())   # latitude: erased EEPROM reads FFh

    def size(self):
        return ((self.status & 0x07) + 1) * 16

    def blocks(self):
        return (self.status & 0x07) + 1

    def code_number(self):
        return (self.status >> 4) & 0x03

    def code_enabled(self):
        return bool(self.status & 0x08)

    def writable(self):
        return bool(self.status & 0x40)


class HXL:
    def __init__(self, defects, settings, temperature):
        self.defects = set(defects)
        # EEPROM (kept over 53h, L767)
        self.address = FACTORY_ADDRESS
        self.stored_settings = settings
        self.codes = [FACTORY_CODE] * 4
        self.offset = 0
        self.counter = 0x000017          # latitude: some power-ups already counted
        self.fields = []
        # the physical world: standstill
        self.raw_position = 0x0123_4567 % RANGE
        self.temperature = temperature
        self.active_now = None           # settings-at-once defect
        self.power_on(time.monotonic())

    # -- power-up (L800-802) ------------------------------------------------------
    def power_on(self, now):
        self.boot = now
        self.stack = []                  # error codes are volatile (L462: reset clears)
        self.kept_default = False
        self.boot_settings = self.stored_settings
        self.active_now = None

    def listening(self, now):
        """The settings byte the UART works with now, or None while initialising."""
        t = now - self.boot
        if t < INIT_S:
            return None
        if self.active_now is not None:
            return self.active_now
        if t < DEFAULT_WINDOW_S or self.kept_default:
            return DEFAULT_SETTINGS
        return self.boot_settings

    def timeout_s(self, now):
        s = self.listening(now)
        if s is None:
            s = DEFAULT_SETTINGS
        bits = 44 if s & 0x40 else 11
        return bits / BAUD.get(s & 0x07, 9600)

    # -- error bit and error stack (L460-464) ---------------------------------------
    def store_error(self, code):
        # latitude: a code already stored is not stored twice; a fifth is dropped
        if code not in self.stack and len(self.stack) < 4:
            self.stack.append(code)

    def monitor(self):
        """The operational state, checked while executing a command (L461)."""
        if not TEMPERATURE_MIN <= self.temperature <= TEMPERATURE_MAX:
            self.store_error(W_TEMPERATURE)

    def frame(self, command, data=b""):
        # The error bit (bit 7 of the command byte) stays set while error codes wait
        # (L463-464). Always the specific address, also for a broadcast (L451).
        body = bytes([self.address, command | (0x80 if self.stack else 0)]) + bytes(data)
        return body + bytes([xor(body)])

    def reply(self, command, data=b""):
        self.monitor()
        return self.frame(command, data)

    def error(self, code):
        """The error protocol (L460: "see command 50h"): the 50h reply layout with the
        code of the failure. Latitude: the code is not also stored; the error bit shows
        stored codes as in every reply."""
        self.monitor()
        return self.frame(0x50, [code])

    # -- one request ------------------------------------------------------------------
    def handle(self, req, now):
        if not req:
            return None
        own = req[0] == self.address
        broadcast = req[0] == 0xFF and "ignores-broadcast" not in self.defects
        if not (own or broadcast):
            return None          # another subscriber's frame (L432, L434)
        if len(req) < 3:
            # latitude: address alone or address + one byte
            return self.error(E_LENGTH)
        if xor(req) != 0:
            return self.error(E_CHECKSUM)
        # a plausible message in the first second keeps the defaults (L800)
        if now - self.boot < DEFAULT_WINDOW_S:
            self.kept_default = True
        cmd = req[1] & 0x7F      # latitude: the master's bit 7 is ignored
        if cmd not in COMMANDS:
            return self.error(E_ARGUMENT if "wrong-error-code" in self.defects
                              else E_UNKNOWN_COMMAND)
        data = req[2:-1]
        if cmd == 0x4B:
            if len(data) < 4 or len(data) != 4 + data[2]:
                return self.error(E_LENGTH)
        elif len(data) != REQUEST_DATA[cmd]:
            return self.error(E_LENGTH)
        return getattr(self, "cmd_%02x" % cmd)(bytes(data), now)

    # -- position ------------------------------------------------------------------------
    def position(self):
        return (self.raw_position + self.offset) % RANGE

    def cmd_42(self, d, now):
        # unsigned long, LSB right-justified (L524)
        return self.reply(0x42, self.position().to_bytes(4, "big"))

    def set_position(self, cmd, d):
        value = int.from_bytes(d[0:4], "big")
        code = d[4]
        if code != self.codes[0] and not (cmd == 0x43 and "no-code-check" in self.defects):
            return self.error(E_ACCESS_CODE)
        if value >= RANGE:       # "any value within the measuring range" (L546)
            return self.error(E_ARGUMENT)
        self.offset = (value - self.raw_position) % RANGE
        return self.reply(cmd)

    def cmd_43(self, d, now):
        return self.set_position(0x43, d)

    def cmd_63(self, d, now):
        # HX-L is a kit (L808): the track synchronisation finds the virtual 0 at the
        # present shaft position; the offset given is stored with it (L812-814).
        return self.set_position(0x63, d)

    # -- analogue value (L565-571) -----------------------------------------------------
    def cmd_44(self, d, now):
        channel = d[0]
        if channel != TEMPERATURE_CHANNEL:
            return self.error(E_ARGUMENT)
        return self.reply(0x44, bytes([channel]) + (self.temperature & 0xFFFF).to_bytes(2, "big"))

    # -- counter (L573-595) ----------------------------------------------------------------
    def cmd_46(self, d, now):
        return self.reply(0x46, self.counter.to_bytes(3, "big"))

    def cmd_47(self, d, now):
        # "Any overflow is shown by the ERROR bit" (L589): the expected reply, with the
        # error bit set and 08h stored. Latitude: the 24-bit counter wraps to 0.
        self.counter += 1
        if self.counter > 0xFFFFFF:
            self.counter = 0
            self.store_error(E_COUNTER_OVERFLOW)
        return self.reply(0x47)

    def cmd_49(self, d, now):
        if d[0] != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        self.counter = 0
        return self.reply(0x49)

    # -- data fields (L599-727) --------------------------------------------------------------
    def field(self, number):
        return self.fields[number] if number < len(self.fields) else None

    def cmd_4a(self, d, now):
        number, start, count, code = d
        f = self.field(number)
        if f is None:
            return self.error(E_NO_FIELD)
        if f.code_enabled() and code != self.codes[f.code_number()]:
            return self.error(E_ACCESS_CODE)
        if not 1 <= count <= 128:                     # L609
            return self.error(E_ARGUMENT)
        if start + count > f.size():
            return self.error(E_ADDRESS_RANGE)
        # latitude: the reply repeats field, address and count as 4Bh's does (L718)
        return self.reply(0x4A, bytes([number, start, count]) + bytes(f.data[start:start + count]))

    def cmd_4b(self, d, now):
        number, start, count, code = d[0:4]
        payload = d[4:]
        f = self.field(number)
        if f is None:
            return self.error(E_NO_FIELD)
        if f.code_enabled() and code != self.codes[f.code_number()]:
            return self.error(E_ACCESS_CODE)
        if not f.writable():
            return self.error(E_WRITE_PROTECTED)
        if not 1 <= count <= 128:
            return self.error(E_ARGUMENT)
        if start + count > f.size():
            return self.error(E_ADDRESS_RANGE)
        f.data[start:start + count] = payload
        return self.reply(0x4B, bytes([number, start, count]))     # L718

    def cmd_4c(self, d, now):
        f = self.field(d[0])
        if f is None:
            return self.error(E_NO_FIELD)
        return self.reply(0x4C, bytes([d[0], f.status]))

    def free_blocks(self):
        return USER_BLOCKS - sum(f.blocks() for f in self.fields)

    def cmd_4d(self, d, now):
        number, status, code = d
        blocks = (status & 0x07) + 1
        if number == len(self.fields):
            # a new field, in ascending order (L644); its code is the one it names
            if not status & 0x80:
                return self.error(E_NO_FIELD)
            if code != self.codes[(status >> 4) & 0x03]:
                return self.error(E_ACCESS_CODE)
            if blocks > self.free_blocks():
                return self.error(E_FIELD_SIZE)
            self.fields.append(Field(status))
            return self.reply(0x4D, bytes([number, status]))        # L690
        f = self.field(number)
        if f is None:
            return self.error(E_NO_FIELD)       # not in ascending order
        # redefinition: "only possible by giving the access Code", irrespective of CE
        # (L649); latitude: the code the field is assigned to now
        if code != self.codes[f.code_number()]:
            return self.error(E_ACCESS_CODE)
        last = number == len(self.fields) - 1
        if not status & 0x80:
            if not last:                          # deleting: the last field only (L649)
                return self.error(E_FIELD_SIZE)
            self.fields.pop()
            return self.reply(0x4D, bytes([number, status]))
        if blocks != f.blocks():
            if not last:                          # size: the last field only (L649)
                return self.error(E_FIELD_SIZE)
            if blocks - f.blocks() > self.free_blocks():
                return self.error(E_FIELD_SIZE)
            size = blocks * 16
            f.data = (f.data + bytearray(b"\xff" * size))[:size]
        f.status = status
        return self.reply(0x4D, bytes([number, status]))

    def cmd_4e(self, d, now):
        return self.reply(0x4E, bytes([self.free_blocks(), len(self.fields)]))   # L678

    def cmd_4f(self, d, now):
        number, old, new = d
        if number > 3:
            return self.error(E_ARGUMENT)
        if old != self.codes[number]:                # L663
            return self.error(E_ACCESS_CODE)
        self.codes[number] = new
        return self.reply(0x4F, bytes([number]))    # L714

    # -- status, identity ---------------------------------------------------------------------
    def cmd_50(self, d, now):
        # read out successively, oldest first (latitude, L463); 00h when none waits.
        # The error bit of this reply: set while more codes wait (L464).
        self.monitor()
        code = self.stack.pop(0) if self.stack else 0x00
        return self.frame(0x50, [code])

    def cmd_52(self, d, now):
        # RS485 settings, encoder type, EEPR_Size, options (L749-757). Latitude: the
        # settings byte as stored (what 57h wrote), which is the one the next power-up
        # will use.
        frame = self.reply(0x52, bytes([self.stored_settings, TYPE_CODE, EEPROM_BLOCKS, OPTION_CODE]))
        if "reply-checksum" in self.defects:
            frame = frame[:-1] + bytes([frame[-1] ^ 0x21])
        return frame

    def cmd_53(self, d, now):
        self.power_on(now)            # L767; no acknowledgement (L765)
        if "reset-answers" in self.defects:
            return self.frame(0x53)
        return None

    def cmd_55(self, d, now):
        new, code = d
        if code != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        # latitude: subscriber numbers 0...31 (40h...5Fh); FFh is the broadcast
        if not 0x40 <= new <= 0x5F:
            return self.error(E_ARGUMENT)
        self.address = new
        return self.reply(0x55)       # latitude: already from the new address (L776)

    def cmd_56(self, d, now):
        return self.reply(0x56, SERIAL + FIRMWARE + FIRMWARE_DATE)

    def cmd_57(self, d, now):
        settings, code = d
        if code != self.codes[0]:
            return self.error(E_ACCESS_CODE)
        if (settings & 0x07) not in BAUD or (settings & 0x30) == 0x10:
            return self.error(E_ARGUMENT)
        self.stored_settings = settings
        frame = self.reply(0x57, bytes([settings]))
        if "settings-at-once" in self.defects:
            self.active_now = settings
        return frame


# ---------------------------------------------------------------------------------
# The UART side


def watch_stdin():
    try:
        return stat.S_ISFIFO(os.fstat(sys.stdin.fileno()).st_mode)
    except OSError:
        return False


def early(slave, pending):
    """early-reply: a whole Read Position request is answered 0.3 ms after it came."""
    return ("early-reply" in slave.defects and len(pending) == 3
            and pending[1] & 0x7F == 0x42 and xor(pending) == 0)


def serve(fd, slave, log):
    pending = bytearray()
    last_rx = None
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    inputs = [fd] + ([sys.stdin.fileno()] if watch_stdin() else [])
    while not stop:
        end = None
        if last_rx is not None:
            end = last_rx + (0.0003 if early(slave, pending) else slave.timeout_s(last_rx))
        now = time.monotonic()
        try:
            ready, _, _ = select.select(inputs, [], [], 0.5 if end is None else max(0.0, end - now))
        except InterruptedError:
            continue
        now = time.monotonic()
        if len(inputs) > 1 and inputs[1] in ready:
            if not os.read(inputs[1], 64):
                return
        if fd in ready:
            try:
                chunk = os.read(fd, 512)
            except OSError:
                chunk = b""
            if slave.listening(now) is None:
                continue                  # initialising: the UART is not running
            if end is not None and now >= end + 0.0005:
                # the timeout ended before these bytes were read (we woke late):
                # the earlier request is complete
                respond(fd, slave, bytes(pending), end, log)
                pending.clear()
            pending.extend(chunk)
            last_rx = now                 # the receive interrupt of the last character
            continue
        if end is not None and now >= end:
            request = bytes(pending)
            pending.clear()
            last_rx = None
            respond(fd, slave, request, end, log)


def respond(fd, slave, request, end, log):
    reply = slave.handle(request, end)
    if reply is None:
        if log:
            print("%10.4f M> %s" % (end - slave.boot, request.hex(" ")), file=sys.stderr, flush=True)
        return
    cmd = request[1] & 0x7F if len(request) > 1 else None
    if cmd == 0x42 and not early(slave, request):
        time.sleep(DRIVER_ON_S)
    if cmd == 0x46 and "late-reply" in slave.defects:
        time.sleep(0.040)
    if cmd == 0x52 and "gap-in-reply" in slave.defects:
        os.write(fd, reply[:2])
        time.sleep(3 * slave.timeout_s(time.monotonic()))
        os.write(fd, reply[2:])
    else:
        os.write(fd, reply)
    if log:
        sent = time.monotonic()
        print("%10.4f M> %s" % (end - slave.boot, request.hex(" ")), file=sys.stderr)
        print("%10.4f S< %s" % (sent - slave.boot, reply.hex(" ")), file=sys.stderr, flush=True)


def byte_value(text):
    v = int(text, 0)
    if not 0 <= v <= 0xFF:
        raise argparse.ArgumentTypeError("a byte: 0...0xFF")
    return v


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--pty", action="store_true", help="create a pseudo-terminal and print its path")
    p.add_argument("--settings", type=byte_value, default=FACTORY_SETTINGS,
                   help="the stored RS485 settings byte (default 0xE4; bit 6 = 0: 11/baud timeout)")
    p.add_argument("--defect", action="append", default=[], choices=sorted(DEFECTS))
    p.add_argument("--temperature", type=int, default=25,
                   help="encoder temperature, degC (outside %d...%d: warning 1Eh)"
                        % (TEMPERATURE_MIN, TEMPERATURE_MAX))
    p.add_argument("--log", action="store_true", help="log frames on stderr")
    p.add_argument("--list-defects", action="store_true")
    args = p.parse_args()
    if args.list_defects:
        for name, what in DEFECTS.items():
            print("%-18s %s" % (name, what))
        return
    if not args.pty:
        p.error("--pty is required")
    if (args.settings & 0x07) not in BAUD or (args.settings & 0x30) == 0x10:
        p.error("--settings: not a valid RS485 settings byte")
    master, slave_fd = os.openpty()
    tty.setraw(slave_fd)
    device = HXL(args.defect, args.settings, args.temperature)
    print(os.ttyname(slave_fd), flush=True)
    serve(master, device, args.log)
    os.close(slave_fd)


if __name__ == "__main__":
    main()
