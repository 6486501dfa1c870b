//! A device data sheet as a plain value. Loading profiles from files lives in the
//! harness crate; the model takes this struct.
//!
//! Long because: the data sheet is one value, and its fields, what each
//! means and the limits derived from them are read together (under 420 without its
//! tests).

use crate::address::SlaveAddress;
use crate::command::{CommandId, CommandSet, ResponseLimit};
use crate::settings::{Baud, Edition, UartSettings};
use core::fmt;

/// Short text held inline (no allocation).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Text<const N: usize> {
    buf: [u8; N],
    len: u8,
}

impl<const N: usize> Text<N> {
    /// `None` when longer than `N` bytes.
    pub fn new(s: &str) -> Option<Text<N>> {
        let mut buf = [0; N];
        buf.get_mut(..s.len())?.copy_from_slice(s.as_bytes());
        Some(Text { buf, len: s.len() as u8 })
    }

    /// The longest prefix of `s` that fits, cut at a character boundary.
    pub fn truncating(s: &str) -> Text<N> {
        let mut end = s.len().min(N);
        while !s.is_char_boundary(end) {
            end -= 1;
        }
        let mut buf = [0; N];
        buf[..end].copy_from_slice(&s.as_bytes()[..end]);
        Text { buf, len: end as u8 }
    }

    pub fn as_str(&self) -> &str {
        core::str::from_utf8(&self.buf[..self.len as usize]).unwrap_or("?")
    }
}

impl<const N: usize> fmt::Debug for Text<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl<const N: usize> fmt::Display for Text<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Resolution and measuring range. The absolute position has 32 steps per period. // 000:T11
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Resolution {
    Rotary {
        periods_per_turn: u32,
        turns: u32,
    },
    /// Period length in nm and number of periods over the measuring length.
    Linear {
        period_nm: u32,
        periods: u32,
    },
}

impl Resolution {
    pub const STEPS_PER_PERIOD: u64 = 32;

    /// Position steps over the whole measuring range (position values are `0..range`).
    pub const fn range_steps(self) -> u64 {
        match self {
            Resolution::Rotary { periods_per_turn, turns } => {
                Self::STEPS_PER_PERIOD * periods_per_turn as u64 * turns as u64
            }
            Resolution::Linear { periods, .. } => Self::STEPS_PER_PERIOD * periods as u64,
        }
    }

    pub const fn is_linear(self) -> bool {
        matches!(self, Resolution::Linear { .. })
    }
}

/// What an analog channel measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AnalogSource {
    Temperature,
    LedCurrent,
}

/// How an analog value is encoded. // 000:T14
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AnalogEncoding {
    /// Signed 16 bit, 1 °C steps (channel 48h).
    Celsius,
    /// Signed 16 bit, 2.048 °C steps from -40 °C: value = (T + 40) / 2.048 (channel F0h).
    Celsius2048,
    /// Unsigned 16 bit, mA.
    Milliamps,
}

impl AnalogEncoding {
    /// Encode a reading (°C or mA). Celsius2048 rounds to the nearest step.
    pub const fn encode(self, reading: i32) -> u16 {
        match self {
            AnalogEncoding::Celsius => reading as i16 as u16,
            AnalogEncoding::Celsius2048 => {
                // (T + 40) / 2.048 = (T + 40) * 1000 / 2048, rounded half away from zero.
                let num = (reading + 40) * 1000;
                let q = if num >= 0 { (num + 1024) / 2048 } else { (num - 1024) / 2048 };
                q as i16 as u16
            }
            AnalogEncoding::Milliamps => reading as u16,
        }
    }

    /// The reading (°C or mA) a value stands for; Celsius2048 to the nearest degree.
    pub const fn decode(self, value: u16) -> i32 {
        match self {
            AnalogEncoding::Celsius => value as i16 as i32,
            AnalogEncoding::Celsius2048 => {
                // T = value * 2.048 - 40 = value * 2048 / 1000 - 40, rounded.
                let num = value as i16 as i32 * 2048;
                let q = if num >= 0 { (num + 500) / 1000 } else { (num - 500) / 1000 };
                q - 40
            }
            AnalogEncoding::Milliamps => value as i32,
        }
    }
}

/// One channel of Read Analog Value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AnalogChannel {
    pub selector: u8,
    pub source: AnalogSource,
    pub encoding: AnalogEncoding,
}

/// The order in which Read Encoder Status pops the stack (DESIGN: a profile knob).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StackOrder {
    OldestFirst,
    NewestFirst,
}

/// One option of Sensor Adjustment and the status it answers. // 000:T35
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AdjustmentOption {
    pub option: u8,
    pub status: u8,
}

/// Which Read Version values the data sheet pins. Units of one family differ in serial
/// number and may differ in firmware, so on a real device only pinned values are
/// compared exactly; the others are graded by their form. // 000:T31
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct VersionPins {
    pub serial: bool,
    pub firmware: bool,
    pub date: bool,
}

pub const MAX_ANALOG_CHANNELS: usize = 4;
pub const MAX_ADJUSTMENT_OPTIONS: usize = 4;

/// A device data sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Profile {
    pub name: Text<32>,
    pub edition: Edition,
    /// Commands the device implements; others draw 0Bh.
    pub commands: CommandSet,
    /// Factory address.
    pub address: SlaveAddress,
    /// Factory stored UART settings.
    pub settings: UartSettings,
    /// Data rates the device accepts in 57h/67h; others draw 0Dh.
    pub baud_rates: [bool; 7],
    pub type_code: u8,
    pub option_code: u8,
    /// Total memory in 16 byte blocks, as Read Type Label reports it.
    pub memory_blocks: u8,
    /// User memory for data fields in 16 byte blocks, as Memory Status reports it when empty.
    pub user_memory_blocks: u8,
    /// The 64 bytes of the Extended Type Label (field FFh), if the device has one.
    pub extended_type_label: Option<[u8; 64]>,
    pub resolution: Resolution,
    pub analog: [Option<AnalogChannel>; MAX_ANALOG_CHANNELS],
    /// Temperatures outside `min..=max` °C raise 1Eh.
    pub temperature_min_c: i16,
    pub temperature_max_c: i16,
    /// LED current above this raises 1Dh.
    pub led_current_max_ma: u16,
    /// Largest speed (rpm, or mm/s for linear devices) at which Read Position answers.
    pub max_read_speed: u32,
    /// What the model answers to Read Version (a sample unit of the family)...
    pub serial: [u8; 9],
    pub firmware: [u8; 20],
    pub firmware_date: [u8; 8],
    /// ...and which of them a real device must report exactly.
    pub version_pins: VersionPins,
    pub adjustment: [Option<AdjustmentOption>; MAX_ADJUSTMENT_OPTIONS],
    /// Sensor Adjustment response time (000:T35: "to be specified in data sheet").
    pub adjustment_response_ms: u16,
    /// Initialization time after power-on or reset (000:T9: 100 ms, at most 200 ms).
    pub init_ms: u16,
    /// End of the default-settings window (000:T9: 900 ms; 002: about 1 s).
    pub default_window_ms: u16,
    /// Start of user-defined settings (000:T9: 1100 ms; legacy: same as the window end).
    pub user_settings_ms: u16,
    pub stack_order: StackOrder,
}

/// Why a profile is not usable. Each names the field at fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProfileError {
    InitOutOfRange { init_ms: u16 },
    WindowsOutOfOrder,
    UserMemoryExceedsTotal,
    EmptyRange,
    RangeTooLarge,
    DuplicateAnalogChannel { selector: u8 },
    StoredBaudUnsupported,
    CommandNotInEdition { command: CommandId },
    TemperatureLimits,
    ExtendedTypeLabelChecksum,
    ExtendedTypeLabelWithoutCode,
}

impl ProfileError {
    /// The profile field at fault, as the TOML files spell it.
    pub const fn field(&self) -> &'static str {
        match self {
            ProfileError::InitOutOfRange { .. } => "timing.init_ms",
            ProfileError::WindowsOutOfOrder => "timing",
            ProfileError::UserMemoryExceedsTotal => "memory.user_blocks",
            ProfileError::EmptyRange | ProfileError::RangeTooLarge => "resolution",
            ProfileError::DuplicateAnalogChannel { .. } => "analog",
            ProfileError::StoredBaudUnsupported => "settings",
            ProfileError::CommandNotInEdition { .. } => "commands",
            ProfileError::TemperatureLimits => "limits",
            ProfileError::ExtendedTypeLabelChecksum | ProfileError::ExtendedTypeLabelWithoutCode => {
                "extended_type_label"
            }
        }
    }
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProfileError::InitOutOfRange { init_ms } => {
                write!(f, "initialization of {init_ms} ms: 000:T9 allows 1 to 200 ms (100 ms nominal)")
            }
            ProfileError::WindowsOutOfOrder => {
                f.write_str("need init_ms < default_window_ms <= user_settings_ms (000:T9)")
            }
            ProfileError::UserMemoryExceedsTotal => f.write_str("user memory exceeds the total memory"),
            ProfileError::EmptyRange => f.write_str("the measuring range is empty"),
            ProfileError::RangeTooLarge => {
                f.write_str("the measuring range exceeds 2^32 position steps (000:T12: 32 bit)")
            }
            ProfileError::DuplicateAnalogChannel { selector } => {
                write!(f, "analog channel {selector:02X}h is defined twice")
            }
            ProfileError::StoredBaudUnsupported => {
                f.write_str("the stored settings use a data rate the device does not support")
            }
            ProfileError::CommandNotInEdition { command } => {
                write!(f, "{command} is not defined in this edition")
            }
            ProfileError::TemperatureLimits => f.write_str("temperature_min_c exceeds temperature_max_c"),
            ProfileError::ExtendedTypeLabelChecksum => {
                f.write_str("byte 0 of the Extended Type Label is not the XOR of bytes 1..63 (000:T20)")
            }
            ProfileError::ExtendedTypeLabelWithoutCode => {
                f.write_str("type code FFh needs an Extended Type Label (000:T19)")
            }
        }
    }
}

impl Profile {
    /// The limits a reply to `command` must start within, after the request's timeout:
    /// 000:T10's figure, the data sheet's for Sensor Adjustment (000:T35), and for
    /// errors to unknown commands the shortest time of Table 10.
    pub fn response_limit(&self, command: CommandId) -> ResponseLimit {
        match command.spec() {
            Some(s) if s.id == CommandId::SensorAdjustment => {
                ResponseLimit { max_ms: self.adjustment_response_ms, strict_ms: None }
            }
            Some(s) => ResponseLimit { max_ms: s.max_response_ms.unwrap_or(5), strict_ms: s.strict_response_ms },
            None => ResponseLimit { max_ms: 5, strict_ms: None },
        }
    }

    /// Switch to `edition` with its defaults: every command the edition defines and
    /// its power-up windows.
    pub fn set_edition(&mut self, edition: Edition) {
        self.edition = edition;
        self.commands = CommandSet::all_for(edition == Edition::Legacy);
        (self.default_window_ms, self.user_settings_ms) = edition.power_up_windows_ms();
    }

    /// The measuring range in position steps.
    pub fn range(&self) -> u64 {
        self.resolution.range_steps()
    }

    pub fn supports_baud(&self, baud: Baud) -> bool {
        // `baud_rates` is in the order of `Baud::ALL`, which is the enum's order: one
        // index, no search (a bounded model checker need not unwind one).
        self.baud_rates.get(baud as usize).copied().unwrap_or(false)
    }

    pub fn analog_channel(&self, selector: u8) -> Option<AnalogChannel> {
        self.analog.iter().flatten().copied().find(|c| c.selector == selector)
    }

    pub fn adjustment_option(&self, option: u8) -> Option<AdjustmentOption> {
        self.adjustment.iter().flatten().copied().find(|o| o.option == option)
    }

    /// Check the profile's internal consistency.
    pub fn validate(&self) -> Result<(), ProfileError> {
        // 000:T9: "100 ms after power-on/reset ... shall not exceed 200 ms"; the state
        // of no UART communication exists on every slave, so it is never 0.
        if !(1..=200).contains(&self.init_ms) {
            return Err(ProfileError::InitOutOfRange { init_ms: self.init_ms });
        }
        if !(self.init_ms < self.default_window_ms && self.default_window_ms <= self.user_settings_ms) {
            return Err(ProfileError::WindowsOutOfOrder);
        }
        if self.user_memory_blocks > self.memory_blocks {
            return Err(ProfileError::UserMemoryExceedsTotal);
        }
        match self.range() {
            0 => return Err(ProfileError::EmptyRange),
            r if r > 1 << 32 => return Err(ProfileError::RangeTooLarge),
            _ => {}
        }
        for (i, a) in self.analog.iter().flatten().enumerate() {
            if self.analog.iter().flatten().skip(i + 1).any(|b| b.selector == a.selector) {
                return Err(ProfileError::DuplicateAnalogChannel { selector: a.selector });
            }
        }
        if !self.supports_baud(self.settings.baud) {
            return Err(ProfileError::StoredBaudUnsupported);
        }
        let defined = CommandSet::all_for(self.edition == Edition::Legacy);
        if let Some(command) = self.commands.iter().find(|c| !defined.contains(*c)) {
            return Err(ProfileError::CommandNotInEdition { command });
        }
        if self.temperature_min_c > self.temperature_max_c {
            return Err(ProfileError::TemperatureLimits);
        }
        match self.extended_type_label {
            Some(etl) if crate::checksum::xor(&etl) != 0 => return Err(ProfileError::ExtendedTypeLabelChecksum),
            None if self.type_code == 0xFF => return Err(ProfileError::ExtendedTypeLabelWithoutCode),
            _ => {}
        }
        Ok(())
    }
}

/// Builds the 64-byte Extended Type Label. // 000:T20
#[derive(Debug, Clone, Copy)]
pub struct ExtendedTypeLabel<'a> {
    pub resolution: Resolution,
    pub bipolar: bool,
    pub designation: &'a str,
    /// Temperature channel with its min/max, if the label names them.
    pub temperature: Option<(u8, i16, i16)>,
    pub max_speed: Option<u16>,
}

impl ExtendedTypeLabel<'_> {
    pub fn build(&self) -> [u8; 64] {
        let mut l = [0u8; 64];
        let linear = self.resolution.is_linear();
        l[1] = linear as u8 | ((self.bipolar as u8) << 1);
        let (res, range) = match self.resolution {
            Resolution::Rotary { periods_per_turn, turns } => (periods_per_turn, turns),
            Resolution::Linear { period_nm, periods } => (period_nm, periods),
        };
        l[2..6].copy_from_slice(&res.to_be_bytes());
        l[6..10].copy_from_slice(&range.to_be_bytes());
        for (dst, src) in l[0x0A..0x1C].iter_mut().zip(self.designation.bytes()) {
            *dst = src;
        }
        let mut selector = 0u16;
        if let Some((channel, min, max)) = self.temperature {
            selector |= 0b111;
            l[0x1E..0x20].copy_from_slice(&(channel as u16).to_be_bytes());
            l[0x20..0x22].copy_from_slice(&min.to_be_bytes());
            l[0x22..0x24].copy_from_slice(&max.to_be_bytes());
        }
        if let Some(speed) = self.max_speed {
            selector |= 1 << 9;
            l[0x30..0x32].copy_from_slice(&speed.to_be_bytes());
        }
        l[0x1C..0x1E].copy_from_slice(&selector.to_be_bytes());
        l[0] = crate::checksum::xor(&l[1..]);
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analog_values_decode_to_what_they_encode() {
        for t in -40..=150 {
            assert_eq!(AnalogEncoding::Celsius.decode(AnalogEncoding::Celsius.encode(t)), t);
            // 2.048 °C steps: back within half a step.
            let back = AnalogEncoding::Celsius2048.decode(AnalogEncoding::Celsius2048.encode(t));
            assert!((back - t).abs() <= 1, "{t} -> {back}");
        }
        assert_eq!(AnalogEncoding::Celsius.decode(0xFFD8), -40);
        assert_eq!(AnalogEncoding::Celsius.decode(25u16.swap_bytes()), 6400);
        assert_eq!(AnalogEncoding::Milliamps.decode(0xFFFF), 65535);
    }

    #[test]
    fn legacy_temperature_encoding() {
        // 000:T14: value = (T + 40) / 2.048
        assert_eq!(AnalogEncoding::Celsius2048.encode(-40), 0);
        assert_eq!(AnalogEncoding::Celsius2048.encode(0), 20); // 19.53 -> 20
        assert_eq!(AnalogEncoding::Celsius2048.encode(100), 68); // 68.36 -> 68
        assert_eq!(AnalogEncoding::Celsius.encode(-5), 0xFFFB);
    }

    #[test]
    fn extended_type_label_checksum() {
        let l = ExtendedTypeLabel {
            resolution: Resolution::Rotary { periods_per_turn: 128, turns: 4096 },
            bipolar: false,
            designation: "SKM36",
            temperature: Some((0x48, -20, 110)),
            max_speed: Some(9000),
        }
        .build();
        assert_eq!(crate::checksum::xor(&l), 0);
        assert_eq!(&l[2..10], &[0, 0, 0, 128, 0, 0, 16, 0]);
        assert_eq!(&l[0x0A..0x0F], b"SKM36");
    }
}
