//! The UART settings byte and the timing it implies. // 000:T4, 000:T28, 000:T32, 000:2.2.2

use core::fmt;

/// Which edition of the protocol a device follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Edition {
    /// 000, the current SICK specification.
    Current,
    /// 002, the older SICK-STEGMANN description: 11/44 bit-time pauses, 63h, ~1 s default window.
    Legacy,
}

impl Edition {
    /// The power-up windows after power-on or reset, ms: until when the default
    /// settings hold, and from when the stored ones do (000:T9: 900 and 1100 ms, with
    /// silence between; 002: about 1 s, no silent window).
    pub const fn power_up_windows_ms(self) -> (u16, u16) {
        match self {
            Edition::Current => (900, 1100),
            Edition::Legacy => (1000, 1000),
        }
    }
}

/// Data rate, settings bits 0-2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Baud {
    B600,
    B1200,
    B2400,
    B4800,
    B9600,
    B19200,
    B38400,
}

impl Baud {
    pub const ALL: [Baud; 7] =
        [Baud::B600, Baud::B1200, Baud::B2400, Baud::B4800, Baud::B9600, Baud::B19200, Baud::B38400];

    pub const fn bits_per_second(self) -> u32 {
        match self {
            Baud::B600 => 600,
            Baud::B1200 => 1200,
            Baud::B2400 => 2400,
            Baud::B4800 => 4800,
            Baud::B9600 => 9600,
            Baud::B19200 => 19200,
            Baud::B38400 => 38400,
        }
    }

    const fn code(self) -> u8 {
        match self {
            Baud::B600 => 0,
            Baud::B1200 => 1,
            Baud::B2400 => 2,
            Baud::B4800 => 3,
            Baud::B9600 => 4,
            Baud::B19200 => 5,
            Baud::B38400 => 6,
        }
    }

    pub fn from_bits_per_second(bps: u32) -> Option<Baud> {
        Baud::ALL.iter().copied().find(|b| b.bits_per_second() == bps)
    }
}

/// Data bits and parity, settings bits 4-5 (always 8 data bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parity {
    None,
    Even,
    Odd,
}

/// Timeout selection, settings bit 6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TimeoutSelect {
    /// 0: 2*11 bit times (legacy: 1*11).
    Short,
    /// 1: 5*11 bit times (legacy: 4*11), the default.
    Long,
}

/// Bus mode, settings bit 7.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BusMode {
    /// 0: bus slave (obsolete bus system).
    BusSlave,
    /// 1: standard slave (default).
    Standard,
}

/// Why a settings byte is rejected (the slave answers 0Dh).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SettingsError {
    /// Data rate bits 111 are not defined.
    UndefinedBaud,
    /// Parity bits 01 are not defined.
    UndefinedParity,
    /// Bit 3 is "not implemented"; a strict decoder rejects it set.
    ReservedBitSet,
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SettingsError::UndefinedBaud => "data rate bits 111 are undefined (000:T28)",
            SettingsError::UndefinedParity => "parity bits 01 are undefined (000:T28)",
            SettingsError::ReservedBitSet => "bit 3 is not implemented and must be 0 (000:T28)",
        })
    }
}

/// The UART settings byte as a type. // 000:T28 settings byte
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct UartSettings {
    pub baud: Baud,
    pub parity: Parity,
    pub timeout: TimeoutSelect,
    pub bus: BusMode,
}

impl UartSettings {
    /// The same settings with the other parity rule (even for odd, odd for even):
    /// every character sent in them arrives with a parity error at a receiver in
    /// these. `None` without parity, where no parity error can be made. // 000:T47
    pub const fn with_wrong_parity(self) -> Option<UartSettings> {
        let parity = match self.parity {
            Parity::Even => Parity::Odd,
            Parity::Odd => Parity::Even,
            Parity::None => return None,
        };
        Some(UartSettings { parity, ..self })
    }

    /// E4h: 9600 Bd, 8 data bits, even parity, 5*11 timeout, standard slave. // 000:T28
    pub const DEFAULT: UartSettings =
        UartSettings { baud: Baud::B9600, parity: Parity::Even, timeout: TimeoutSelect::Long, bus: BusMode::Standard };

    /// Strict decoder: undefined data rate or parity codes and bit 3 set are errors.
    pub const fn decode(byte: u8) -> Result<UartSettings, SettingsError> {
        let baud = match byte & 0x07 {
            0 => Baud::B600,
            1 => Baud::B1200,
            2 => Baud::B2400,
            3 => Baud::B4800,
            4 => Baud::B9600,
            5 => Baud::B19200,
            6 => Baud::B38400,
            _ => return Err(SettingsError::UndefinedBaud),
        };
        if byte & 0x08 != 0 {
            return Err(SettingsError::ReservedBitSet);
        }
        let parity = match (byte >> 4) & 0x03 {
            0 => Parity::None,
            2 => Parity::Even,
            3 => Parity::Odd,
            _ => return Err(SettingsError::UndefinedParity),
        };
        let timeout = if byte & 0x40 != 0 { TimeoutSelect::Long } else { TimeoutSelect::Short };
        let bus = if byte & 0x80 != 0 { BusMode::Standard } else { BusMode::BusSlave };
        Ok(UartSettings { baud, parity, timeout, bus })
    }

    pub const fn byte(self) -> u8 {
        let parity = match self.parity {
            Parity::None => 0x00,
            Parity::Even => 0x20,
            Parity::Odd => 0x30,
        };
        let timeout = match self.timeout {
            TimeoutSelect::Short => 0,
            TimeoutSelect::Long => 0x40,
        };
        let bus = match self.bus {
            BusMode::BusSlave => 0,
            BusMode::Standard => 0x80,
        };
        self.baud.code() | parity | timeout | bus
    }

    /// Bits per character: start + 8 data + parity + stop.
    pub const fn bits_per_char(self) -> u32 {
        match self.parity {
            Parity::None => 10,
            _ => 11,
        }
    }

    /// The frame timeout in bit times, as a receiver counts it: from the end of one
    /// received character to the end of the next (its UART interrupt). 22 or 55 in
    /// both editions. // 000:2.2.2, DESIGN:legacy-timeout
    ///
    /// 002 prints 11 and 44, and 000 (2.2.2, note) says that figure "did not consider
    /// the fact that typical UART interrupts of microcontrollers are generated at the
    /// end of the first received character": 002 counts the pause from a stop bit to
    /// the next start bit, one character (11 bit times) less. Counted from character
    /// ends, 002's 11 would split a request sent back to back. See [`Self::pause_bits`].
    pub const fn timeout_bits(self, _edition: Edition) -> u32 {
        match self.timeout {
            TimeoutSelect::Short => 22,
            TimeoutSelect::Long => 55,
        }
    }

    /// The shortest pause, in bit times from a stop bit to the next start bit, that
    /// ends a transmission: the master's before the reply (or its next request), the
    /// slave's after its reply. 000:2.2.2 "a pause of at least the length of the
    /// timeout condition": 22 or 55; 002: 11 or 44 ("TIMEOUT programmable, 11/baud
    /// rate or 44/baud rate"). // 000:2.2.2, 002:timing, DESIGN:legacy-timeout
    pub const fn pause_bits(self, edition: Edition) -> u32 {
        match (edition, self.timeout) {
            (Edition::Current, TimeoutSelect::Short) => 22,
            (Edition::Current, TimeoutSelect::Long) => 55,
            (Edition::Legacy, TimeoutSelect::Short) => 11,
            (Edition::Legacy, TimeoutSelect::Long) => 44,
        }
    }

    /// Time for `bits` bit times in µs, rounded up.
    pub const fn bits_us(self, bits: u32) -> u64 {
        let bps = self.baud.bits_per_second() as u64;
        (bits as u64 * 1_000_000).div_ceil(bps)
    }

    /// One bit time in µs, rounded up.
    pub const fn bit_time_us(self) -> u64 {
        self.bits_us(1)
    }

    /// One character on the wire in µs, rounded up.
    pub const fn char_time_us(self) -> u64 {
        self.bits_us(self.bits_per_char())
    }

    /// The frame timeout in µs, rounded up (5729 µs for E4h: "5.73 ms for 9600 Baud").
    pub const fn timeout_us(self, edition: Edition) -> u64 {
        self.bits_us(self.timeout_bits(edition))
    }

    /// [`Self::pause_bits`] in µs, rounded up.
    pub const fn pause_us(self, edition: Edition) -> u64 {
        self.bits_us(self.pause_bits(edition))
    }
}

impl Default for UartSettings {
    fn default() -> Self {
        UartSettings::DEFAULT
    }
}

impl fmt::Display for UartSettings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parity = match self.parity {
            Parity::None => "N",
            Parity::Even => "E",
            Parity::Odd => "O",
        };
        let timeout = match self.timeout {
            TimeoutSelect::Short => "short",
            TimeoutSelect::Long => "long",
        };
        write!(f, "{:02X}h ({} Bd 8{}1, {} timeout)", self.byte(), self.baud.bits_per_second(), parity, timeout)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn baud_all_is_in_the_order_of_the_enum() {
        for (i, b) in Baud::ALL.iter().enumerate() {
            assert_eq!(*b as usize, i, "{b:?}");
        }
    }

    #[test]
    fn the_wrong_parity_is_the_other_rule() {
        let even = UartSettings::DEFAULT;
        let odd = UartSettings { parity: Parity::Odd, ..even };
        assert_eq!(even.with_wrong_parity(), Some(odd));
        assert_eq!(odd.with_wrong_parity(), Some(even));
        assert_eq!(UartSettings { parity: Parity::None, ..even }.with_wrong_parity(), None);
    }

    #[test]
    fn strict_decoder_accepts_exactly_the_defined_bytes() {
        let mut valid = 0;
        for b in 0..=255u8 {
            match UartSettings::decode(b) {
                Ok(s) => {
                    valid += 1;
                    assert_eq!(s.byte(), b);
                }
                Err(e) => {
                    let why = match e {
                        SettingsError::UndefinedBaud => b & 7 == 7,
                        SettingsError::ReservedBitSet => b & 8 != 0,
                        SettingsError::UndefinedParity => (b >> 4) & 3 == 1,
                    };
                    assert!(why, "{b:02X}: {e}");
                }
            }
        }
        // 7 rates x 3 parities x 2 timeouts x 2 bus modes
        assert_eq!(valid, 84);
        assert_eq!(UartSettings::decode(0xE4), Ok(UartSettings::DEFAULT));
    }

    #[test]
    fn timing() {
        let d = UartSettings::DEFAULT;
        assert_eq!(d.timeout_us(Edition::Current), 5730, "000:2.2.2: 5.73 ms at 9600 Bd");
        // 002's 44 bit times are a pause; counted between character ends, 000's 55.
        assert_eq!((d.pause_bits(Edition::Legacy), d.timeout_bits(Edition::Legacy)), (44, 55));
        assert_eq!((d.pause_bits(Edition::Current), d.timeout_bits(Edition::Current)), (55, 55));
        assert_eq!(d.char_time_us(), 1146);
        let none = UartSettings { parity: Parity::None, ..d };
        assert_eq!(none.bits_per_char(), 10);
        let short = UartSettings { timeout: TimeoutSelect::Short, baud: Baud::B38400, ..d };
        assert_eq!(short.timeout_bits(Edition::Current), 22);
        assert_eq!(short.timeout_us(Edition::Current), 573);
        assert_eq!((short.pause_bits(Edition::Legacy), short.timeout_bits(Edition::Legacy)), (11, 22));
        assert_eq!((short.pause_bits(Edition::Current), short.timeout_bits(Edition::Current)), (22, 22));
        assert_eq!(short.pause_us(Edition::Legacy), 287, "11 bit times at 38400 Bd, rounded up");
        // Back to back, two characters' ends are one character apart: never a pause
        // of the timeout, in either edition and with or without parity.
        for e in [Edition::Current, Edition::Legacy] {
            assert!(short.timeout_us(e) > short.char_time_us());
        }
    }
}
