//! Profiles as TOML files: a device data sheet as data, validated on load. Every
//! error names the file, the line and the field.
//!
//! A file may start from a built-in profile (`base = "SRS50"`) and override fields.

use hiperface_model::command::{CommandId, CommandSet};
use hiperface_model::profile::{
    AdjustmentOption, AnalogChannel, AnalogEncoding, AnalogSource, ExtendedTypeLabel, Resolution, StackOrder, Text,
    VersionPins,
};
use hiperface_model::settings::{Baud, Edition, UartSettings};
use hiperface_model::{profiles, Profile, SlaveAddress};
use std::path::{Path, PathBuf};

mod export;
mod format;

pub use export::to_toml;
use format::*;

/// A profile that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ProfileLoadError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}:{line}: not a profile: the file is not TOML ({message})")]
    NotToml { path: PathBuf, line: usize, message: String },
    #[error("{path}:{line}: field `{field}`: {message}")]
    Invalid { path: PathBuf, line: usize, field: String, message: String },
    #[error("unknown built-in profile `{name}` (known: {known})")]
    UnknownBuiltin { name: String, known: String },
}

/// The built-in profile names.
pub fn builtin_names() -> String {
    profiles::BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// A built-in profile by name, with a clear error listing the known ones.
pub fn builtin(name: &str) -> Result<Profile, ProfileLoadError> {
    profiles::builtin(name)
        .ok_or_else(|| ProfileLoadError::UnknownBuiltin { name: name.to_string(), known: builtin_names() })
}

/// `NAME` of a built-in profile or a path to a TOML file.
pub fn resolve(spec: &str) -> Result<Profile, ProfileLoadError> {
    let path = Path::new(spec);
    if spec.ends_with(".toml") || path.exists() {
        load(path)
    } else {
        builtin(spec)
    }
}

/// Load and validate a profile file.
pub fn load(path: &Path) -> Result<Profile, ProfileLoadError> {
    let text = std::fs::read_to_string(path).map_err(|source| ProfileLoadError::Io { path: path.into(), source })?;
    parse(&text, path)
}

/// Parse and validate profile text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<Profile, ProfileLoadError> {
    parse_checked(text, path, true)
}

/// Parse the profile a record of a run holds, as the run had it: not checked against
/// 000:T9's bound on the initialization again (a test may certify against a data sheet
/// outside it), but against everything else a profile file is.
pub fn parse_recorded(text: &str, path: &Path) -> Result<Profile, ProfileLoadError> {
    parse_checked(text, path, false)
}

fn parse_checked(text: &str, path: &Path, validate: bool) -> Result<Profile, ProfileLoadError> {
    let invalid = |field: &str, message: String| ProfileLoadError::Invalid {
        path: path.into(),
        line: locate(text, field),
        field: field.to_string(),
        message,
    };
    let line_of = |e: &toml::de::Error| {
        e.span().map_or(1, |s| 1 + text.as_bytes()[..s.start.min(text.len())].iter().filter(|b| **b == b'\n').count())
    };
    // Syntax first: a file that is not TOML at all (a wrong path) is not reported as a
    // field error.
    if let Err(e) = text.parse::<toml::Table>() {
        return Err(ProfileLoadError::NotToml {
            path: path.into(),
            line: line_of(&e),
            message: e.message().to_string(),
        });
    }
    let file: ProfileFile = toml::from_str(text).map_err(|e| {
        let line = line_of(&e);
        ProfileLoadError::Invalid {
            path: path.into(),
            line,
            // An unknown or missing field is named by the message; a bad value by
            // the key on its line.
            field: field_of(e.message()).unwrap_or_else(|| key_at(text, line)),
            message: with_range(e.message()),
        }
    })?;
    let mut p = match &file.base {
        Some(base) => profiles::builtin(base)
            .ok_or_else(|| invalid("base", format!("unknown built-in profile (known: {})", builtin_names())))?,
        None => profiles::srs50(),
    };
    p.name = Text::new(&file.name).ok_or_else(|| invalid("name", "longer than 32 bytes".into()))?;
    if let Some(e) = file.edition {
        p.set_edition(match e {
            EditionName::Current => Edition::Current,
            EditionName::Legacy => Edition::Legacy,
        });
    }
    if let Some(id) = &file.identity {
        p.type_code = id.type_code.unwrap_or(p.type_code);
        p.option_code = id.option_code.unwrap_or(p.option_code);
        if let Some(s) = &id.serial {
            p.serial = fixed(s).ok_or_else(|| invalid("identity.serial", "must be at most 9 ASCII bytes".into()))?;
        }
        if let Some(s) = &id.firmware {
            p.firmware =
                fixed(s).ok_or_else(|| invalid("identity.firmware", "must be at most 20 ASCII bytes".into()))?;
        }
        if let Some(s) = &id.firmware_date {
            p.firmware_date =
                fixed(s).ok_or_else(|| invalid("identity.firmware_date", "must be at most 8 ASCII bytes".into()))?;
        }
        if let Some(pinned) = &id.pinned {
            let mut pins = VersionPins::default();
            for key in pinned {
                match key.as_str() {
                    "serial" => pins.serial = true,
                    "firmware" => pins.firmware = true,
                    "firmware_date" => pins.date = true,
                    other => {
                        return Err(invalid(
                            "identity.pinned",
                            format!("`{other}` is none of serial, firmware, firmware_date"),
                        ))
                    }
                }
            }
            p.version_pins = pins;
        }
    }
    if let Some(i) = &file.interface {
        if let Some(a) = i.address {
            p.address = SlaveAddress::new(a)
                .ok_or_else(|| invalid("interface.address", format!("{a:02X}h is not in 40h...5Fh")))?;
        }
        if let Some(s) = i.settings {
            p.settings = UartSettings::decode(s).map_err(|e| invalid("interface.settings", e.to_string()))?;
        }
        if let Some(rates) = &i.baud_rates {
            let mut set = [false; 7];
            for r in rates {
                let b = Baud::from_bits_per_second(*r)
                    .ok_or_else(|| invalid("interface.baud_rates", format!("{r} is not a HIPERFACE data rate")))?;
                set[Baud::ALL.iter().position(|x| *x == b).unwrap_or(0)] = true;
            }
            p.baud_rates = set;
        }
    }
    if let Some(c) = file.commands.as_ref().and_then(|c| c.supported.as_ref()) {
        let mut set = CommandSet::EMPTY;
        for b in c {
            let id = CommandId::decode(*b);
            if id.spec().is_none() {
                return Err(invalid("commands.supported", format!("{b:02X}h is not a HIPERFACE command")));
            }
            set.insert(id);
        }
        p.commands = set;
    }
    if let Some(m) = &file.memory {
        p.memory_blocks = m.total_blocks.unwrap_or(p.memory_blocks);
        p.user_memory_blocks = m.user_blocks.unwrap_or(p.user_memory_blocks);
    }
    if let Some(r) = &file.resolution {
        p.resolution = match *r {
            ResolutionTable::Rotary { periods_per_turn, turns } => Resolution::Rotary { periods_per_turn, turns },
            ResolutionTable::Linear { period_nm, periods } => Resolution::Linear { period_nm, periods },
        };
    }
    if let Some(list) = &file.analog {
        if list.len() > p.analog.len() {
            return Err(invalid("analog", format!("at most {} channels", p.analog.len())));
        }
        p.analog = [None; 4];
        for (slot, a) in p.analog.iter_mut().zip(list) {
            *slot = Some(AnalogChannel {
                selector: a.selector,
                source: match a.source {
                    SourceName::Temperature => AnalogSource::Temperature,
                    SourceName::LedCurrent => AnalogSource::LedCurrent,
                },
                encoding: match a.encoding {
                    EncodingName::Celsius => AnalogEncoding::Celsius,
                    EncodingName::Celsius2048 => AnalogEncoding::Celsius2048,
                    EncodingName::Milliamps => AnalogEncoding::Milliamps,
                },
            });
        }
    }
    if let Some(l) = &file.limits {
        p.temperature_min_c = l.temperature_min_c.unwrap_or(p.temperature_min_c);
        p.temperature_max_c = l.temperature_max_c.unwrap_or(p.temperature_max_c);
        p.led_current_max_ma = l.led_current_max_ma.unwrap_or(p.led_current_max_ma);
        p.max_read_speed = l.max_read_speed.unwrap_or(p.max_read_speed);
    }
    if let Some(t) = &file.timing {
        p.init_ms = t.init_ms.unwrap_or(p.init_ms);
        p.default_window_ms = t.default_window_ms.unwrap_or(p.default_window_ms);
        p.user_settings_ms = t.user_settings_ms.unwrap_or(p.user_settings_ms);
        p.adjustment_response_ms = t.adjustment_response_ms.unwrap_or(p.adjustment_response_ms);
    }
    if let Some(e) = &file.extended_type_label {
        p.extended_type_label = Some(match (&e.bytes, &e.designation) {
            (Some(bytes), None) => <[u8; 64]>::try_from(bytes.as_slice())
                .map_err(|_| invalid("extended_type_label.bytes", format!("{} bytes, need 64", bytes.len())))?,
            (None, designation) => ExtendedTypeLabel {
                resolution: p.resolution,
                bipolar: e.bipolar.unwrap_or(false),
                designation: designation.as_deref().unwrap_or(""),
                temperature: p
                    .analog
                    .iter()
                    .flatten()
                    .find(|c| c.source == AnalogSource::Temperature)
                    .map(|c| (c.selector, p.temperature_min_c, p.temperature_max_c)),
                max_speed: None,
            }
            .build(),
            (Some(_), Some(_)) => {
                return Err(invalid("extended_type_label", "give either `bytes` or `designation`".into()));
            }
        });
    }
    if let Some(list) = &file.adjustment {
        if list.len() > p.adjustment.len() {
            return Err(invalid("adjustment", format!("at most {} options", p.adjustment.len())));
        }
        p.adjustment = [None; 4];
        for (slot, a) in p.adjustment.iter_mut().zip(list) {
            *slot = Some(AdjustmentOption { option: a.option, status: a.status });
        }
    }
    if let Some(o) = file.stack_order {
        p.stack_order = match o {
            StackOrderName::OldestFirst => StackOrder::OldestFirst,
            StackOrderName::NewestFirst => StackOrder::NewestFirst,
        };
    }
    if validate {
        p.validate().map_err(|e| invalid(e.field(), e.to_string()))?;
    } else {
        // A recorded profile may lie outside 000:T9's initialization bound (a data
        // sheet's longer one), but never outside what the model rests on: a measuring
        // range (a record whose range is 0 made the model divide by it: found by the
        // `report` fuzz target), windows in order, a stored rate it supports.
        let mut bounded = p;
        bounded.init_ms = bounded.init_ms.min(200);
        bounded.validate().map_err(|e| invalid(e.field(), e.to_string()))?;
    }
    Ok(p)
}

fn fixed<const N: usize>(s: &str) -> Option<[u8; N]> {
    if s.len() > N || !s.is_ascii() {
        return None;
    }
    let mut a = [0u8; N];
    a[..s.len()].copy_from_slice(s.as_bytes());
    Some(a)
}

/// The field a serde message names (`unknown field `x``, `missing field `x``).
fn field_of(message: &str) -> Option<String> {
    let named = message.starts_with("unknown field") || message.starts_with("missing field");
    named.then(|| message.split('`').nth(1).unwrap_or("").to_string())
}

/// The dotted key written on 1-based `line` (`timing.init_ms`), with the table it is in.
fn key_at(text: &str, line: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let key = lines.get(line.saturating_sub(1)).and_then(|l| l.split_once('=')).map(|(k, _)| k.trim());
    let table = lines[..line.saturating_sub(1).min(lines.len())]
        .iter()
        .rev()
        .map(|l| l.trim())
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim());
    match (table, key) {
        (Some(t), Some(k)) => format!("{t}.{k}"),
        (None, Some(k)) => k.to_string(),
        (Some(t), None) => t.to_string(),
        (None, None) => String::new(),
    }
}

/// serde's message, with the range an integer type allows spelled out.
fn with_range(message: &str) -> String {
    let ranges = [("u8", "0 to 255 (0xFF)"), ("u16", "0 to 65535"), ("u32", "0 to 4294967295"), ("i8", "-128 to 127")];
    match ranges.iter().find(|(t, _)| message.ends_with(&format!("expected {t}"))) {
        Some((_, range)) => format!("{message}: a whole number from {range}"),
        None => message.to_string(),
    }
}

/// The 1-based line where a dotted field (`timing.init_ms`, `analog`) is written,
/// or where its table starts; 1 if absent.
pub fn locate(text: &str, field: &str) -> usize {
    let (table, key) = match field.rsplit_once('.') {
        Some((t, k)) => (Some(t), k),
        None => (None, field),
    };
    let mut in_table = table.is_none();
    let mut table_line = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            let name = t.trim_matches(|c| c == '[' || c == ']').trim();
            in_table = Some(name) == table;
            if Some(name) == table || (table.is_none() && name == key) {
                table_line.get_or_insert(i + 1);
                if table.is_none() {
                    return i + 1;
                }
            }
            continue;
        }
        let k = t.split('=').next().unwrap_or("").trim();
        if in_table && k == key {
            return i + 1;
        }
    }
    table_line.unwrap_or(1)
}
