//! The TOML layout of a profile file: one section per part of a data sheet.

use serde::{Deserialize, Serialize};

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
#[serde(rename_all = "snake_case")]
pub(super) struct ProfileFile {
    pub(super) name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) base: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) edition: Option<EditionName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) identity: Option<IdentitySection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) interface: Option<Interface>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) commands: Option<Commands>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) memory: Option<MemorySection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) resolution: Option<ResolutionTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) analog: Option<Vec<Analog>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) limits: Option<Limits>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) timing: Option<Timing>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) extended_type_label: Option<Etl>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) adjustment: Option<Vec<Adjustment>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) stack_order: Option<StackOrderName>,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub(super) enum EditionName {
    Current,
    Legacy,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub(super) enum StackOrderName {
    OldestFirst,
    NewestFirst,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct IdentitySection {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) type_code: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) option_code: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) serial: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) firmware: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) firmware_date: Option<String>,
    /// Which of serial, firmware, firmware_date a device must report exactly; the
    /// others are a sample unit's values, graded by their form. Default: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) pinned: Option<Vec<String>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Interface {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) address: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) settings: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) baud_rates: Option<Vec<u32>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Commands {
    /// Command bytes, or absent for all commands of the edition.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) supported: Option<Vec<u8>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MemorySection {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) total_blocks: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) user_blocks: Option<u8>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "kebab-case")]
pub(super) enum ResolutionTable {
    Rotary { periods_per_turn: u32, turns: u32 },
    Linear { period_nm: u32, periods: u32 },
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Analog {
    pub(super) selector: u8,
    pub(super) source: SourceName,
    pub(super) encoding: EncodingName,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub(super) enum SourceName {
    Temperature,
    LedCurrent,
}

#[derive(Debug, Deserialize, Serialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub(super) enum EncodingName {
    Celsius,
    Celsius2048,
    Milliamps,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Limits {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) temperature_min_c: Option<i16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) temperature_max_c: Option<i16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) led_current_max_ma: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) max_read_speed: Option<u32>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Timing {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) init_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) default_window_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) user_settings_ms: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) adjustment_response_ms: Option<u16>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Etl {
    /// Build the label from the resolution with this designation...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) designation: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) bipolar: Option<bool>,
    /// ...or give all 64 bytes (byte 0 must be the XOR of bytes 1..63).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) bytes: Option<Vec<u8>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Adjustment {
    pub(super) option: u8,
    pub(super) status: u8,
}
