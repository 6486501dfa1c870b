"""An independent HIPERFACE encoder (an SRS50 by its data sheet), written from the
specification (000) and the profile alone, by an author who did not read the model
or the catalogue: a peer that the catalogue must PASS, and, one switch at a time,
86 defects it must FAIL or that are argued (test_independent_encoder.py).

Frame interface, as `hiperface.certify` takes it: answer(heard) -> None |
(reply, start_us[, then_settings[, restarts]]). `defect` names one planted bug: each is one
`self.d(...)` branch with its name, so grepping for the name shows the change.
Where 000 is silent the author chose: the argument is checked before the access
code; 4Ah/4Bh check the field number (12h), read-only (0Eh), the code (0Fh), then
offset or count (11h); modifying a field needs its current code; deleting with
other status bits, or creating with a gap in the numbering, draws 12h; 57h refuses
600 Bd, rate 111, parity 01 and bit 3; the power-up state is judged at a request's
first character.
"""

DEFAULT_SETTINGS = 0xE4

# --- SRS50 data sheet (profile) -------------------------------------------
ADDRESS = 0x40
STORED_SETTINGS = 0xE4
BAUD_CODES = {1: 1200, 2: 2400, 3: 4800, 4: 9600, 5: 19200, 6: 38400}  # no 600
SUPPORTED = [0x42, 0x43, 0x44, 0x46, 0x47, 0x49, 0x4A, 0x4B, 0x4C, 0x4D,
             0x4E, 0x4F, 0x50, 0x52, 0x53, 0x55, 0x56, 0x57]
TYPE_CODE = 0x22
OPTION_CODE = 0x00
TOTAL_BLOCKS = 0x80
USER_BLOCKS = 0x70
STEPS = 1024 * 32 * 1        # 32 steps per period (000 T11), one turn
SERIAL = b"000000001"
FIRMWARE = b"hiperface-model"
FW_DATE = b"22.11.26"
TEMPERATURE_C = 25
INIT_US = 100_000
DEFAULT_WINDOW_US = 900_000
USER_SETTINGS_US = 1_100_000

# Master data lengths (000 T12..T32); 4Bh is variable.
MASTER_LEN = {0x42: 0, 0x43: 5, 0x44: 1, 0x46: 0, 0x47: 0, 0x49: 1, 0x4A: 4,
              0x4C: 1, 0x4D: 3, 0x4E: 0, 0x4F: 3, 0x50: 0, 0x52: 0, 0x53: 0,
              0x55: 2, 0x56: 0, 0x57: 2}

REPLY_DELAY_US = 400


def xor(data):
    c = 0
    for b in data:
        c ^= b
    return c


class Err(Exception):
    def __init__(self, code):
        self.code = code


class Encoder:
    def __init__(self, defect=None):
        self.defect = defect
        # non-volatile
        self.address = ADDRESS
        self.stored_settings = STORED_SETTINGS
        self.codes = [0x55] * 4
        self.offset = 0
        self.counter = 0
        self.fields = []          # list of [status, bytearray]
        self.memory = bytearray(b"\xff" * (USER_BLOCKS * 16))   # erased EEPROM
        self.field_start = []     # start block of each field
        # volatile
        self.raw_position = 0x1234 % STEPS
        self.stack = []
        self.active_settings = STORED_SETTINGS
        self.reset_at = None      # None: past power-up, operational
        self.phase = "operational"

    # ----------------------------------------------------------------- utils
    def d(self, name):
        return self.defect == name

    def frame(self, addr, cmd, data=b""):
        if self.d("stack_all_errors") and cmd == 0x50 and data and data[0] not in (0,) \
                and getattr(self, "_in_status", False) is False:
            self.stack_push(data[0])
        if self.stack and not self.d("warning_bit_never"):
            cmd |= 0x80
        body = bytes([addr, cmd]) + bytes(data)
        if self.d("checksum_without_address"):
            return body + bytes([xor(body[1:])])
        return body + bytes([xor(body)])

    def stack_push(self, code):
        if code in self.stack:
            return
        self.stack.append(code)
        if len(self.stack) > 4:
            self.stack.pop(0)

    def blocks_used(self):
        return sum((s & 7) + 1 for s, _ in self.fields)

    def free_blocks(self):
        return USER_BLOCKS - self.blocks_used() - getattr(self, "leak", 0)

    def field_size(self, n):
        return ((self.fields[n][0] & 7) + 1) * 16

    def field_base(self, n):
        if self.d("fields_overlap") and n > 0:
            return sum((s & 7) + 1 for s, _ in self.fields[:n]) * 16 - 16
        return sum((s & 7) + 1 for s, _ in self.fields[:n]) * 16

    def field_code_ok(self, n, code):
        status = self.fields[n][0]
        if not status & 0x08 and not self.d("code_required_when_disabled"):
            return True
        if self.d("code_ignored"):
            return True
        num = (status >> 4) & 3
        if self.d("field_code_always_code0"):
            num = 0
        return code == self.codes[num]

    # ------------------------------------------------------------ power-up
    def listening(self, now):
        """'silent', 'default' or 'active' at time now (µs)."""
        if self.reset_at is None:
            return "active"
        t = now - self.reset_at
        if self.phase == "operational-default":
            return "default"
        init = INIT_US
        if self.d("init_140ms"):
            init = 140_000
        if self.d("init_155ms"):
            init = 155_000
        window = 500_000 if self.d("window_500ms") else DEFAULT_WINDOW_US
        switch = USER_SETTINGS_US
        if self.d("switch_1000ms"):
            switch = 1_000_000
        if self.d("switch_1050ms"):
            switch = 1_050_000
        if t < init:
            if self.d("answer_during_init"):
                return "default"
            return "silent"
        if t <= window:
            return "default"
        if t < switch and not self.d("no_switch_gap"):
            return "silent"
        return "active"

    # ----------------------------------------------------------- interface
    def answer(self, heard):
        now = heard.complete_us
        # the UART must be on when the first character arrives
        state = self.listening(heard.first_us)
        if state == "silent":
            return None
        then = None
        if self.reset_at is not None:
            if state == "default" and not self.d("default_window_stored"):
                # any single request in the default window: stay at default
                self.phase = "operational-default"
                self.active_settings = DEFAULT_SETTINGS
                then = DEFAULT_SETTINGS
            else:
                self.phase = "operational"
                self.reset_at = None
                self.active_settings = self.stored_settings
                then = self.stored_settings
                if self.d("settings_not_taken_after_reset"):
                    self.active_settings = then = DEFAULT_SETTINGS
        out = self.handle(heard, now)
        if out is None:
            return None
        start = now + REPLY_DELAY_US
        if self.d("reply_before_timeout"):
            start = heard.last_us + 1000
        if self.d("slow_read_position") and len(heard.bytes) > 1 and heard.bytes[1] == 0x42:
            start = now + 10_600
        if self.d("slow_memstatus") and len(heard.bytes) > 1 and heard.bytes[1] == 0x4E:
            start = now + 5_600
        if self.d("slow_store_data") and len(heard.bytes) > 1 and heard.bytes[1] == 0x4B:
            start = now + 251_000
        if isinstance(out, tuple):          # (reply, then_settings[, restarts])
            return (out[0], start, *out[1:])
        if then is not None:
            return (out, start, then)
        return (out, start)

    def handle(self, heard, now):
        f = bytes(heard.bytes)
        if not f:
            return None
        addr = f[0]
        if self.d("answer_other_address"):
            if not (0x40 <= addr <= 0x5F or addr == 0xFF):
                return None
        elif addr != self.address and addr != 0xFF:
            if self.d("checksum_before_address") and len(f) >= 3 and xor(f) != 0:
                return self.frame(self.address, 0x50, [0x0A])
            return None
        reply_addr = self.address
        if addr == 0xFF and self.d("broadcast_reply_ff"):
            reply_addr = 0xFF
        if heard.uart_fault:
            if self.d("parity_ignored"):
                return None
            return self.frame(reply_addr, 0x50, [0x09])
        if len(f) < 3:
            return self.frame(reply_addr, 0x50, [0x0C])
        if self.d("unknown_before_checksum") and f[1] not in SUPPORTED:
            return self.frame(reply_addr, 0x50, [0x0B])
        if xor(f) != 0:
            if self.d("checksum_ignored"):
                pass
            else:
                return self.frame(reply_addr, 0x50, [0x0A])
        cmd = f[1]
        data = f[2:-1]
        if cmd not in SUPPORTED and not (self.d("answers_67h") and cmd == 0x67):
            return self.frame(reply_addr, 0x50, [0x0B])
        if cmd == 0x4B:
            if len(data) < 5:
                return self.frame(reply_addr, 0x50, [0x0C])
            if not self.d("store_no_count_check") and len(data) != 4 + data[2]:
                return self.frame(reply_addr, 0x50, [0x0C])
        elif len(data) != MASTER_LEN[cmd] and not (cmd == 0x53 and self.d("reset_ignores_length")):
            return self.frame(reply_addr, 0x50, [0x0C])
        try:
            res = getattr(self, "c%02X" % cmd)(data, now)
        except Err as e:
            code = e.code
            if self.d("swap_0D_0F"):
                code = {0x0D: 0x0F, 0x0F: 0x0D}.get(code, code)
            if self.d("swap_11_12"):
                code = {0x11: 0x12, 0x12: 0x11}.get(code, code)
            if self.d("no_warning_on_stacking_reply") and code in self.stack:
                return bytes([reply_addr, 0x50, code, reply_addr ^ 0x50 ^ code])
            return self.frame(reply_addr, 0x50, [code])
        if res is None:
            return None
        if isinstance(res, tuple) and res[0] == "reset":
            return (b"", res[1], True)      # restarts: the power-up windows, 000:T9
        if isinstance(res, tuple) and res[0] == "raw53":
            return (self.frame(reply_addr, cmd, b""), res[1])
        if isinstance(res, tuple) and res[0] == "raw":
            return (self.frame(reply_addr, cmd, bytes([res[1]])), res[1])
        if isinstance(res, tuple) and res[0] == "newaddr":
            a = res[1] if not self.d("setaddr_old_address") else res[2]
            return self.frame(a, cmd, res[3])
        out = self.frame(reply_addr, cmd, res)
        self._in_status = False
        return out

    # ------------------------------------------------------------ commands
    def position(self):
        return (self.raw_position + self.offset) % STEPS

    def c42(self, data, now):
        if self.d("position_17bit"):
            return ((self.raw_position + 0x10000 + self.offset) % (2 * STEPS * 2)).to_bytes(4, "big")
        return self.position().to_bytes(4, "big")

    def c43(self, data, now):
        preset = int.from_bytes(data[0:4], "big")
        code = data[4]
        if self.d("setpos_no_range"):
            preset %= STEPS
        if self.d("code_before_range") or self.d("code_before_range_all"):
            if code != self.codes[0]:
                raise Err(0x0F)
            if preset >= STEPS:
                raise Err(0x0D)
        else:
            if preset >= STEPS:
                raise Err(0x0D)
            if code != self.codes[0]:
                raise Err(0x0F)
        if self.d("setpos_not_applied"):
            return b""
        if self.d("setpos_off_by_one"):
            preset = (preset + 1) % STEPS
        self.offset = (preset - self.raw_position) % STEPS
        return b""

    def c44(self, data, now):
        ch = data[0]
        if ch != 0x48 and not self.d("analog_any_channel"):
            raise Err(0x0D)
        t = TEMPERATURE_C
        if self.d("analog_fahrenheit"):
            t = TEMPERATURE_C * 9 // 5 + 32
        if self.d("analog_little_endian"):
            return bytes([ch]) + (t & 0xFFFF).to_bytes(2, "little")
        if self.d("analog_no_channel_echo"):
            ch = 0
        return bytes([ch]) + (t & 0xFFFF).to_bytes(2, "big")

    def c46(self, data, now):
        return self.counter.to_bytes(3, "big")

    def c47(self, data, now):
        if self.counter >= 0xFFFFFF and not self.d("counter_wraps"):
            self.stack_push(0x08)
            raise Err(0x08)
        self.counter += 2 if self.d("counter_plus_two") else 1
        self.counter = self.counter & 0xFFFFFF if self.d("counter_wraps") else min(self.counter, 0xFFFFFF)
        return b""

    def c49(self, data, now):
        if not self.d("reset_counter_no_code") and data[0] != self.codes[0]:
            raise Err(0x0F)
        self.counter = 0
        return b""

    def _field_access(self, data, write):
        n, off, cnt, code = data[0], data[1], data[2], data[3]
        if n >= len(self.fields):
            raise Err(0x12)
        if write and not self.fields[n][0] & 0x40 and not self.d("readonly_writable"):
            raise Err(0x0E)
        if not self.field_code_ok(n, code):
            raise Err(0x0F)
        size = self.field_size(n)
        if self.d("field_size_from_blocks_plus1"):
            size += 16
        if (cnt == 0 and not self.d("count_zero_ok")) or off >= size:
            raise Err(0x11)
        limit = size + 1 if self.d("read_allows_plus1") and not write else size
        if off + cnt > limit:
            raise Err(0x11)
        return n, off, cnt

    def c4A(self, data, now):
        n, off, cnt = self._field_access(data, False)
        base = self.field_base(n)
        mem = self.memory + b"\xff" * 16
        return bytes(data[0:3]) + bytes(mem[base + off: base + off + cnt])

    def c4B(self, data, now):
        n, off, cnt = self._field_access(data, True)
        payload = data[4:4 + cnt]
        base = self.field_base(n)
        if self.d("store_drops_last_byte"):
            payload = payload[:-1]
        if self.d("store_wrong_offset"):
            off = max(0, off - 1) if off else off
        self.memory[base + off: base + off + len(payload)] = payload
        return bytes(data[0:3])

    def c4C(self, data, now):
        n = data[0]
        if n >= len(self.fields):
            if self.d("status_missing_zero"):
                return bytes([n, 0x00])
            raise Err(0x12)
        return bytes([n, self.fields[n][0]])

    def c4D(self, data, now):
        n, status, code = data
        count = len(self.fields)
        if n > count and not self.d("create_gap_number"):
            raise Err(0x12)
        if n > count:
            n = count
        if n == count:
            # create
            if not status & 0x80:
                raise Err(0x12)
            want = self.codes[0] if self.d("create_checks_code0") else self.codes[(status >> 4) & 3]
            if code != want:
                raise Err(0x0F)
            blocks = (status & 7) + 1
            if blocks > self.free_blocks() + (1 if self.d("create_oom_off_by_one") else 0):
                raise Err(0x10)
            base = self.blocks_used() * 16
            if not self.d("create_no_erase"):
                self.memory[base: base + blocks * 16] = b"\xff" * (blocks * 16)
            self.fields.append([status, None])
            return bytes([n, status])
        # modify or delete an existing field
        old = self.fields[n][0]
        if self.d("modify_code_new"):
            want = self.codes[(status >> 4) & 3]
        else:
            want = self.codes[(old >> 4) & 3]
        if code != want:
            raise Err(0x0F)
        last = n == count - 1
        if not status & 0x80:
            if not last and not self.d("delete_any"):
                raise Err(0x12)
            if (status | 0x80) != old and not self.d("delete_ignores_status_bits"):
                raise Err(0x12)
            if self.d("delete_not_freeing"):
                self.leak = getattr(self, "leak", 0) + (old & 7) + 1
            del self.fields[n]
            return bytes([n, status])
        if (status & 7) != (old & 7):
            if not last and not self.d("resize_not_last"):
                raise Err(0x12)
            grow = (status & 7) - (old & 7)
            if grow > self.free_blocks() and not self.d("resize_no_oom_check"):
                raise Err(0x10)
            if grow > 0:
                end = self.field_base(n) + self.field_size(n)
                self.memory[end: end + grow * 16] = b"\xff" * (grow * 16)
        self.fields[n][0] = status
        return bytes([n, status])

    def c4E(self, data, now):
        free = self.free_blocks()
        if self.d("memstatus_miscount"):
            free = USER_BLOCKS - sum((s & 7) for s, _ in self.fields)
        return bytes([max(0, free) & 0xFF, len(self.fields)])

    def c4F(self, data, now):
        num, old, new = data
        if num > 3 and not self.d("setcode_num_masked"):
            raise Err(0x0D)
        num &= 3
        if old != self.codes[num]:
            raise Err(0x0F)
        if self.d("setcode_wrong_code"):
            num2 = (num + 1) % 4 if num else 0
            self.codes[num2] = new
        else:
            self.codes[num] = new
        if self.d("setcode_reply_new"):
            return bytes([new])
        return bytes([num])

    def c50(self, data, now):
        self._in_status = True
        if not self.stack:
            return b"\x00"
        if self.d("stack_not_removed"):
            code = self.stack[0]
        elif self.d("stack_newest_first"):
            code = self.stack.pop()
        else:
            code = self.stack.pop(0)
        return bytes([code])

    def c52(self, data, now):
        s = self.active_settings if self.d("typelabel_active") else self.stored_settings
        return bytes([s, TYPE_CODE, USER_BLOCKS if self.d("typelabel_user_blocks") else TOTAL_BLOCKS, OPTION_CODE])

    def c53(self, data, now):
        # executed after the request's timeout (now); no reply
        if not self.d("reset_keeps_stack"):
            self.stack = []
        self.reset_at = now
        self.phase = "init"
        if self.d("address_volatile"):
            self.address = ADDRESS
        if self.d("offset_volatile"):
            self.offset = 0
        if self.d("codes_volatile"):
            self.codes = [0x55] * 4
        if self.d("counter_volatile"):
            self.counter = 0
        if self.d("fields_volatile"):
            self.fields = []
        self.active_settings = DEFAULT_SETTINGS
        if self.d("reset_acknowledged"):
            return ("raw53", self.stored_settings)
        if self.d("reset_keeps_stack"):
            pass
        if self.d("settings_not_taken_after_reset"):
            return ("reset", DEFAULT_SETTINGS)
        return ("reset", self.stored_settings)

    def c55(self, data, now):
        new, code = data
        if self.d("code_before_range_all") and code != self.codes[0]:
            raise Err(0x0F)
        if not 0x40 <= new <= (0x7F if self.d("setaddr_range_7F") else 0x5F):
            raise Err(0x0D)
        if code != self.codes[0]:
            raise Err(0x0F)
        old = self.address
        self.address = new
        return ("newaddr", new, old, b"")

    def valid_settings(self, s):
        rates = BAUD_CODES
        if self.d("setserial_any_rate"):
            rates = {**BAUD_CODES, 0: 600}   # 000 Table 28's full list
        if s & 0x07 not in rates:
            return False
        if s & 0x08 and not self.d("setserial_bit3_ok"):
            return False
        if (s >> 4) & 3 == 1 and not self.d("setserial_parity01_ok"):
            return False
        return True

    def c57(self, data, now):
        s, code = data
        if self.d("code_before_range_all") and code != self.codes[0]:
            raise Err(0x0F)
        if not self.valid_settings(s):
            raise Err(0x0D)
        if code != self.codes[0]:
            raise Err(0x0F)
        old_stored = self.stored_settings
        self.stored_settings = s
        if self.d("setserial_immediate"):
            self.active_settings = s
            return ("raw", s)
        if self.d("setserial_reply_old"):
            return bytes([old_stored])
        return bytes([s])

    def c56(self, data, now):
        fw = FIRMWARE.ljust(20, b"\x00")
        if self.d("version_short_fw"):
            fw = FIRMWARE.ljust(19, b"\x00")
        if self.d("version_date_nodots"):
            return SERIAL + fw + b"26112022"
        return SERIAL + fw + FW_DATE


def make(defect=None):
    enc = Encoder(defect)
    return enc.answer, enc


if __name__ == "__main__":
    # `--list-defects`: the defect switches, one a line (the book's counts are checked
    # against it).
    import re
    import sys

    if sys.argv[1:] != ["--list-defects"]:
        sys.exit("usage: independent_encoder.py --list-defects")
    for name in sorted(set(re.findall(r'self\.d\("([A-Za-z0-9_]+)"\)', open(__file__).read()))):
        print(name)
