//! What the device said of itself (Read Type Label 52h, Read Version 56h), as read,
//! for the certificate. Grading is the oracle's: against the profile for 52h, by form
//! (and exactly only where the profile pins a value) for 56h.

use hiperface_model::response::Response;
use serde::Serialize;

/// The fields of a Read Type Label reply. // 000:T28
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct TypeLabel {
    pub settings: u8,
    pub type_code: u8,
    pub memory_blocks: u8,
    pub option: u8,
}

/// The identity read from the device; `None` where it never answered the command.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Identity {
    pub type_label: Option<TypeLabel>,
    pub serial: Option<String>,
    pub firmware: Option<String>,
    pub firmware_date: Option<String>,
}

impl Identity {
    /// Take what a well-formed reply says of the device.
    pub fn record(&mut self, response: &Response) {
        match *response {
            Response::TypeLabel { settings, type_code, memory_blocks, option } => {
                self.type_label = Some(TypeLabel { settings, type_code, memory_blocks, option });
            }
            Response::Version(v) => {
                self.serial = Some(text(&v.serial));
                self.firmware = Some(text(&v.firmware));
                self.firmware_date = Some(text(&v.date));
            }
            _ => {}
        }
    }

    /// One line per value, for people.
    pub fn lines(&self) -> Vec<(&'static str, String)> {
        let unread = || "not read".to_string();
        vec![
            (
                "type label (52h)",
                self.type_label.map_or_else(unread, |t| {
                    format!(
                        "settings {:02X}h, type {:02X}h, memory {} blocks of 16 bytes in all (000:T28; Memory Status counts the user memory's free blocks), option {:02X}h",
                        t.settings, t.type_code, t.memory_blocks, t.option
                    )
                }),
            ),
            ("serial number (56h)", self.serial.clone().unwrap_or_else(unread)),
            ("firmware version (56h)", self.firmware.clone().unwrap_or_else(unread)),
            ("firmware date (56h)", self.firmware_date.clone().unwrap_or_else(unread)),
        ]
    }
}

/// ASCII as it is, trailing 00h padding dropped, anything else as `\xNN`.
fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().rposition(|b| *b != 0).map_or(0, |i| i + 1);
    let mut s = String::new();
    for b in &bytes[..end] {
        if b.is_ascii_graphic() || *b == b' ' {
            s.push(*b as char);
        } else {
            s.push_str(&format!("\\x{b:02X}"));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::response::Version;

    #[test]
    fn version_text_shows_what_was_read() {
        let mut id = Identity::default();
        let mut firmware = [0u8; 20];
        firmware[..5].copy_from_slice(b"HX1 2");
        firmware[5] = 0xB5;
        id.record(&Response::Version(Version { serial: *b"000012345", firmware, date: *b"01.02.26" }));
        assert_eq!(id.serial.as_deref(), Some("000012345"));
        assert_eq!(id.firmware.as_deref(), Some("HX1 2\\xB5"));
        assert_eq!(id.firmware_date.as_deref(), Some("01.02.26"));
        assert_eq!(id.lines()[0].1, "not read");
    }
}
