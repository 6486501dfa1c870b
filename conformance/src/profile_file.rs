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
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

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

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
#[serde(rename_all = "snake_case")]
struct ProfileFile {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    base: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    edition: Option<EditionName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    identity: Option<IdentitySection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    interface: Option<Interface>,
    #[serde(skip_serializing_if = "Option::is_none")]
    commands: Option<Commands>,
    #[serde(skip_serializing_if = "Option::is_none")]
    memory: Option<MemorySection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    resolution: Option<ResolutionTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    analog: Option<Vec<Analog>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    limits: Option<Limits>,
    #[serde(skip_serializing_if = "Option::is_none")]
    timing: Option<Timing>,
    #[serde(skip_serializing_if = "Option::is_none")]
    extended_type_label: Option<Etl>,
    #[serde(skip_serializing_if = "Option::is_none")]
    adjustment: Option<Vec<Adjustment>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stack_order: Option<StackOrderName>,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum EditionName {
    Current,
    Legacy,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum StackOrderName {
    OldestFirst,
    NewestFirst,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct IdentitySection {
    #[serde(skip_serializing_if = "Option::is_none")]
    type_code: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    option_code: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    serial: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    firmware: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    firmware_date: Option<String>,
    /// Which of serial, firmware, firmware_date a device must report exactly; the
    /// others are a sample unit's values, graded by their form. Default: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pinned: Option<Vec<String>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Interface {
    #[serde(skip_serializing_if = "Option::is_none")]
    address: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    settings: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    baud_rates: Option<Vec<u32>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Commands {
    /// Command bytes, or absent for all commands of the edition.
    #[serde(skip_serializing_if = "Option::is_none")]
    supported: Option<Vec<u8>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct MemorySection {
    #[serde(skip_serializing_if = "Option::is_none")]
    total_blocks: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    user_blocks: Option<u8>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "kebab-case")]
enum ResolutionTable {
    Rotary { periods_per_turn: u32, turns: u32 },
    Linear { period_nm: u32, periods: u32 },
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Analog {
    selector: u8,
    source: SourceName,
    encoding: EncodingName,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum SourceName {
    Temperature,
    LedCurrent,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum EncodingName {
    Celsius,
    Celsius2048,
    Milliamps,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Limits {
    #[serde(skip_serializing_if = "Option::is_none")]
    temperature_min_c: Option<i16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    temperature_max_c: Option<i16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    led_current_max_ma: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_read_speed: Option<u32>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Timing {
    #[serde(skip_serializing_if = "Option::is_none")]
    init_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    default_window_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    user_settings_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    adjustment_response_ms: Option<u16>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Etl {
    /// Build the label from the resolution with this designation...
    #[serde(skip_serializing_if = "Option::is_none")]
    designation: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    bipolar: Option<bool>,
    /// ...or give all 64 bytes (byte 0 must be the XOR of bytes 1..63).
    #[serde(skip_serializing_if = "Option::is_none")]
    bytes: Option<Vec<u8>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct Adjustment {
    option: u8,
    status: u8,
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
    let file: ProfileFile = toml::from_str(text).map_err(|e| ProfileLoadError::Invalid {
        path: path.into(),
        line: line_of(&e),
        field: field_of(e.message()),
        message: e.message().to_string(),
    })?;
    let mut p = match &file.base {
        Some(base) => profiles::builtin(base)
            .ok_or_else(|| invalid("base", format!("unknown built-in profile (known: {})", builtin_names())))?,
        None => profiles::srs50(),
    };
    p.name = Text::new(&file.name).ok_or_else(|| invalid("name", "longer than 32 bytes".into()))?;
    if let Some(e) = file.edition {
        p.edition = match e {
            EditionName::Current => Edition::Current,
            EditionName::Legacy => Edition::Legacy,
        };
        p.commands = CommandSet::all_for(p.edition == Edition::Legacy);
        if p.edition == Edition::Legacy {
            p.default_window_ms = 1000;
            p.user_settings_ms = 1000;
        }
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
    p.validate().map_err(|e| invalid(e.field(), e.to_string()))?;
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
fn field_of(message: &str) -> String {
    message.split('`').nth(1).unwrap_or("").to_string()
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

/// A profile as TOML text that [`parse`] reads back to the same profile.
pub fn to_toml(p: &Profile) -> String {
    let bauds = Baud::ALL.iter().zip(p.baud_rates).filter(|(_, on)| *on).map(|(b, _)| b.bits_per_second()).collect();
    let text = |bytes: &[u8]| String::from_utf8_lossy(bytes).trim_end_matches('\0').to_string();
    let file = ProfileFile {
        name: p.name.to_string(),
        base: None,
        edition: Some(match p.edition {
            Edition::Current => EditionName::Current,
            Edition::Legacy => EditionName::Legacy,
        }),
        identity: Some(IdentitySection {
            type_code: Some(p.type_code),
            option_code: Some(p.option_code),
            serial: Some(text(&p.serial)),
            firmware: Some(text(&p.firmware)),
            firmware_date: Some(text(&p.firmware_date)),
            pinned: Some(
                [
                    (p.version_pins.serial, "serial"),
                    (p.version_pins.firmware, "firmware"),
                    (p.version_pins.date, "firmware_date"),
                ]
                .into_iter()
                .filter(|(on, _)| *on)
                .map(|(_, k)| k.to_string())
                .collect(),
            ),
        }),
        interface: Some(Interface {
            address: Some(p.address.byte()),
            settings: Some(p.settings.byte()),
            baud_rates: Some(bauds),
        }),
        commands: Some(Commands { supported: Some(p.commands.iter().map(|c| c.byte()).collect()) }),
        memory: Some(MemorySection { total_blocks: Some(p.memory_blocks), user_blocks: Some(p.user_memory_blocks) }),
        resolution: Some(match p.resolution {
            Resolution::Rotary { periods_per_turn, turns } => ResolutionTable::Rotary { periods_per_turn, turns },
            Resolution::Linear { period_nm, periods } => ResolutionTable::Linear { period_nm, periods },
        }),
        analog: Some(
            p.analog
                .iter()
                .flatten()
                .map(|a| Analog {
                    selector: a.selector,
                    source: match a.source {
                        AnalogSource::Temperature => SourceName::Temperature,
                        AnalogSource::LedCurrent => SourceName::LedCurrent,
                    },
                    encoding: match a.encoding {
                        AnalogEncoding::Celsius => EncodingName::Celsius,
                        AnalogEncoding::Celsius2048 => EncodingName::Celsius2048,
                        AnalogEncoding::Milliamps => EncodingName::Milliamps,
                    },
                })
                .collect(),
        ),
        limits: Some(Limits {
            temperature_min_c: Some(p.temperature_min_c),
            temperature_max_c: Some(p.temperature_max_c),
            led_current_max_ma: Some(p.led_current_max_ma),
            max_read_speed: Some(p.max_read_speed),
        }),
        timing: Some(Timing {
            init_ms: Some(p.init_ms),
            default_window_ms: Some(p.default_window_ms),
            user_settings_ms: Some(p.user_settings_ms),
            adjustment_response_ms: Some(p.adjustment_response_ms),
        }),
        extended_type_label: p.extended_type_label.map(|l| Etl {
            designation: None,
            bipolar: None,
            bytes: Some(l.to_vec()),
        }),
        adjustment: Some(
            p.adjustment.iter().flatten().map(|a| Adjustment { option: a.option, status: a.status }).collect(),
        ),
        stack_order: Some(match p.stack_order {
            StackOrder::OldestFirst => StackOrderName::OldestFirst,
            StackOrder::NewestFirst => StackOrderName::NewestFirst,
        }),
    };
    let body = toml::to_string(&file).unwrap_or_else(|e| format!("# cannot serialise: {e}\n"));
    let body: String = body.lines().map(|l| hex_literals(l) + "\n").collect();
    format!("# HIPERFACE device profile (generated by `hiperface export-profile {}`)\n{body}", p.name)
}

/// Keys whose values read best in hex, as the documents write them.
const HEX_KEYS: &[&str] = &[
    "type_code",
    "option_code",
    "address",
    "settings",
    "supported",
    "selector",
    "total_blocks",
    "user_blocks",
    "option",
    "status",
];

/// `type_code = 34` -> `type_code = 0x22` (and each number of an array).
fn hex_literals(line: &str) -> String {
    let Some((key, value)) = line.split_once(" = ") else { return line.to_string() };
    if !HEX_KEYS.contains(&key.trim()) {
        return line.to_string();
    }
    let value: String = value
        .split_inclusive(|c: char| !c.is_ascii_digit())
        .map(|part| {
            let digits: String = part.chars().take_while(|c| c.is_ascii_digit()).collect();
            match digits.parse::<u8>() {
                Ok(n) if !digits.is_empty() => format!("0x{n:02X}{}", &part[digits.len()..]),
                _ => part.to_string(),
            }
        })
        .collect();
    format!("{key} = {value}")
}
