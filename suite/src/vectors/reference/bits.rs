//! The bytes that pack bit fields, drawn bit by bit and spelled out: the UART settings
//! byte (000:T28, T32, T33), the data field status byte (000:T23, T24) and the command
//! byte's warning bit (000:2.3.4). The meaning of every value a layout lists is the
//! model's decoder applied to a byte with that value, never typed here, so a layout
//! cannot say what the model does not do.

use crate::report::escape;
use hiperface_model::settings::{BusMode, Parity, SettingsError, TimeoutSelect};
use hiperface_model::slave::fields::{FieldStatus, BLOCK};
use hiperface_model::{Edition, UartSettings};
use std::fmt::Write as _;

/// One field of a packed byte: its bits (high to low) and what each value means.
pub struct BitField {
    pub high: u8,
    pub low: u8,
    pub name: &'static str,
    /// Each value of the field with its meaning, the default marked.
    pub values: Vec<(u8, String)>,
}

/// Which packed byte, and in which frame: the data field status byte means "exists" in
/// 4Ch's reply, "create or modify / delete" in 4Dh's request, "created or modified /
/// deleted" in 4Dh's reply (000:T23, T24).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Packed {
    Settings,
    FieldStatus,
    CreateRequest,
    CreateReply,
}

impl Packed {
    pub const fn title(self) -> &'static str {
        match self {
            Packed::Settings => "The UART settings byte",
            Packed::FieldStatus => "The data field status byte",
            Packed::CreateRequest => "The status byte of a Create Data Field request",
            Packed::CreateReply => "The status byte of a Create Data Field reply",
        }
    }

    pub const fn clause(self) -> &'static str {
        match self {
            Packed::Settings => "000:T28",
            Packed::FieldStatus => "000:T23",
            Packed::CreateRequest | Packed::CreateReply => "000:T24",
        }
    }
}

/// The fields of a packed byte, high bits first, each value's meaning from the model.
pub fn layout(packed: Packed) -> Vec<BitField> {
    match packed {
        Packed::Settings => settings_layout(),
        other => status_layout(other),
    }
}

/// Each value of bits `high..=low` put into `base`: the byte to decode.
fn with(base: u8, high: u8, low: u8, value: u8) -> u8 {
    let mask = (((1u16 << (high - low + 1)) - 1) as u8) << low;
    (base & !mask) | ((value << low) & mask)
}

fn values(high: u8, low: u8, mut meaning: impl FnMut(u8) -> String) -> Vec<(u8, String)> {
    (0..1u8 << (high - low + 1)).map(|v| (v, meaning(v))).collect()
}

fn settings_layout() -> Vec<BitField> {
    let default = UartSettings::DEFAULT.byte();
    let field = |high: u8, low: u8, name: &'static str, word: fn(Result<UartSettings, SettingsError>) -> String| {
        let values = values(high, low, |v| {
            let byte = with(default, high, low, v);
            let mark = if byte == default { " (default)" } else { "" };
            word(UartSettings::decode(byte)) + mark
        });
        BitField { high, low, name, values }
    };
    vec![
        field(7, 7, "HIPERFACE bus", |s| s.map_or_else(|e| e.to_string(), |s| bus(s.bus).into())),
        field(6, 6, "timeout", |s| s.map_or_else(|e| e.to_string(), timeout)),
        field(5, 4, "data bits, parity", |s| match s {
            Ok(s) => parity(s.parity).into(),
            Err(SettingsError::UndefinedParity) => "undefined: answered with 0Dh".into(),
            Err(e) => e.to_string(),
        }),
        field(3, 3, "not implemented", |s| match s {
            Ok(_) => "0".into(),
            Err(SettingsError::ReservedBitSet) => "must be 0: answered with 0Dh".into(),
            Err(e) => e.to_string(),
        }),
        field(2, 0, "data rate", |s| match s {
            Ok(s) => format!("{} Bd", s.baud.bits_per_second()),
            Err(SettingsError::UndefinedBaud) => "undefined: answered with 0Dh".into(),
            Err(e) => e.to_string(),
        }),
    ]
}

fn bus(b: BusMode) -> &'static str {
    match b {
        BusMode::BusSlave => "bus slave",
        BusMode::Standard => "standard slave",
    }
}

fn parity(p: Parity) -> &'static str {
    match p {
        Parity::None => "8 data bits, no parity",
        Parity::Even => "8 data bits, even parity",
        Parity::Odd => "8 data bits, odd parity",
    }
}

/// The timeout as the model counts it (both editions alike: DESIGN:legacy-timeout).
fn timeout(s: UartSettings) -> String {
    let select = match s.timeout {
        TimeoutSelect::Short => "short",
        TimeoutSelect::Long => "long",
    };
    format!("{select}: {} bit times", s.timeout_bits(Edition::Current))
}

fn status_layout(packed: Packed) -> Vec<BitField> {
    // A write-enabled 16-byte field with Code0, the bits under test put in.
    let base = 0xC0;
    let field = |high: u8, low: u8, name: &'static str, word: fn(FieldStatus) -> String| BitField {
        high,
        low,
        name,
        values: values(high, low, |v| word(FieldStatus(with(base, high, low, v)))),
    };
    let bit7: fn(FieldStatus) -> String = match packed {
        Packed::CreateRequest => |s| if s.exists() { "create or modify the field" } else { "delete the field" }.into(),
        Packed::CreateReply => |s| if s.exists() { "field created or modified" } else { "field deleted" }.into(),
        _ => |s| if s.exists() { "the field exists" } else { "no such field" }.into(),
    };
    vec![
        field(7, 7, if matches!(packed, Packed::FieldStatus) { "exists" } else { "create / delete" }, bit7),
        field(6, 6, "write access", |s| if s.writable() { "write-enabled" } else { "read-only" }.into()),
        field(5, 4, "access code", |s| format!("Code{}", s.code_number())),
        field(3, 3, "code", |s| if s.code_enabled() { "enabled" } else { "disabled" }.into()),
        field(2, 0, "size", |s| format!("{} bytes", s.size_bytes())),
    ]
}

/// A packed byte's layout as an HTML table: a column per bit, each field a cell over
/// its bits with its values listed beneath.
pub fn layout_html(packed: Packed) -> String {
    let fields = layout(packed);
    let mut s = String::from("<table class=\"hf-bits\">\n<tr><th>bit</th>");
    for bit in (0..8).rev() {
        let _ = write!(s, "<th>{bit}</th>");
    }
    s.push_str("</tr>\n<tr><th>field</th>");
    for f in &fields {
        let _ = write!(s, "<td colspan=\"{}\"><b>{}</b></td>", f.high - f.low + 1, escape(f.name));
    }
    s.push_str("</tr>\n<tr><th>values</th>");
    for f in &fields {
        let width = (f.high - f.low + 1) as usize;
        let lines: Vec<String> =
            f.values.iter().map(|(v, meaning)| format!("<code>{v:0width$b}</code> {}", escape(meaning))).collect();
        let _ = write!(s, "<td colspan=\"{width}\">{}</td>", lines.join("<br>"));
    }
    s.push_str("</tr>\n</table>\n");
    s
}

/// A packed byte of a frame spelled out by the model: "E4h = 1110 0100: standard slave,
/// long: 55 bit times, 8 data bits, even parity, 9600 Bd".
pub fn spelled(packed: Packed, byte: u8) -> String {
    let bits = format!("{:04b} {:04b}", byte >> 4, byte & 0x0F);
    let words = match packed {
        Packed::Settings => match UartSettings::decode(byte) {
            Ok(s) => {
                format!("{}, timeout {}, {}, {} Bd", bus(s.bus), timeout(s), parity(s.parity), s.baud.bits_per_second())
            }
            Err(e) => format!("not a valid settings byte: {e}"),
        },
        _ => {
            let s = FieldStatus(byte);
            let first = layout(packed)
                .first()
                .and_then(|f| f.values.get(usize::from(byte >> 7)).map(|(_, m)| m.clone()))
                .unwrap_or_default();
            format!(
                "{first}, {}, {} bytes ({} of {BLOCK} bytes), {}",
                if s.writable() { "write-enabled" } else { "read-only" },
                s.size_bytes(),
                if s.blocks() == 1 { "1 block".to_string() } else { format!("{} blocks", s.blocks()) },
                if s.code_enabled() {
                    format!("protected by Code{}", s.code_number())
                } else {
                    format!("Code{} (access code disabled)", s.code_number())
                }
            )
        }
    };
    format!("{byte:02X}h = {bits}: {words}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_settings_layout_is_the_models_decoder() {
        let l = layout(Packed::Settings);
        let rate = &l[4];
        assert_eq!((rate.high, rate.low), (2, 0));
        assert_eq!(rate.values[4].1, "9600 Bd (default)");
        assert_eq!(rate.values[6].1, "38400 Bd");
        assert_eq!(rate.values[7].1, "undefined: answered with 0Dh");
        assert_eq!(l[2].values[1].1, "undefined: answered with 0Dh");
        assert_eq!(l[2].values[2].1, "8 data bits, even parity (default)");
        assert_eq!(l[1].values[0].1, "short: 22 bit times");
        assert_eq!(l[3].values[1].1, "must be 0: answered with 0Dh");
        // Every bit in exactly one field.
        let bits: u32 = l.iter().map(|f| u32::from(f.high - f.low + 1)).sum();
        assert_eq!(bits, 8);
    }

    #[test]
    fn the_status_layouts_say_what_bit_7_means_where() {
        assert_eq!(layout(Packed::FieldStatus)[0].values[1].1, "the field exists");
        assert_eq!(layout(Packed::CreateRequest)[0].values[0].1, "delete the field");
        assert_eq!(layout(Packed::CreateReply)[0].values[1].1, "field created or modified");
        assert_eq!(layout(Packed::FieldStatus)[4].values[7].1, "128 bytes");
        assert_eq!(layout(Packed::FieldStatus)[2].values[3].1, "Code3");
    }

    #[test]
    fn a_byte_is_spelled_out() {
        assert_eq!(
            spelled(Packed::Settings, 0xE4),
            "E4h = 1110 0100: standard slave, timeout long: 55 bit times, 8 data bits, even parity, 9600 Bd"
        );
        assert!(spelled(Packed::Settings, 0xE7)
            .ends_with("not a valid settings byte: data rate bits 111 are undefined (000:T28)"));
        assert_eq!(
            spelled(Packed::FieldStatus, 0xC8),
            "C8h = 1100 1000: the field exists, write-enabled, 16 bytes (1 block of 16 bytes), protected by Code0"
        );
        assert_eq!(
            spelled(Packed::CreateRequest, 0x78),
            "78h = 0111 1000: delete the field, write-enabled, 16 bytes (1 block of 16 bytes), protected by Code3"
        );
        let table = layout_html(Packed::Settings);
        assert!(table.contains("<td colspan=\"3\"><b>data rate</b></td>"), "{table}");
    }
}
