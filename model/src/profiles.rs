//! Built-in profiles of the device families the documents describe.
//!
//! Sources: resolutions from 000:T11 and 003 §11.2; type codes 22h (SRS), 27h (SRM),
//! 42h (SEK) as drive masters in the field accept them (see docs/src/design.md,
//! "Built-in profiles"); families whose type code the
//! documents do not give use FFh with an Extended Type Label (000:T19 "new and
//! future"). The S36 follows 001 §5.1.4; the legacy encoder follows 002.

use crate::address::SlaveAddress;
use crate::command::{CommandId, CommandSet};
use crate::profile::{
    AdjustmentOption, AnalogChannel, AnalogEncoding, AnalogSource, ExtendedTypeLabel, Profile, Resolution, StackOrder,
    Text, VersionPins,
};
use crate::settings::{Edition, UartSettings};

const TEMPERATURE: AnalogChannel =
    AnalogChannel { selector: 0x48, source: AnalogSource::Temperature, encoding: AnalogEncoding::Celsius };
const LEGACY_TEMPERATURE: AnalogChannel =
    AnalogChannel { selector: 0xF0, source: AnalogSource::Temperature, encoding: AnalogEncoding::Celsius2048 };

/// `s` in `N` bytes, padded with 00h or cut. One copy, no loop: a bounded model
/// checker builds every profile in its harnesses.
fn padded<const N: usize>(s: &str) -> [u8; N] {
    let mut a = [0u8; N];
    let n = s.len().min(N);
    if let (Some(to), Some(from)) = (a.get_mut(..n), s.as_bytes().get(..n)) {
        to.copy_from_slice(from);
    }
    a
}

fn text(s: &str) -> Text<32> {
    Text::truncating(s)
}

/// A current-edition SICK device with all mandatory commands and no optional ones.
fn current(name: &str, resolution: Resolution, type_code: u8) -> Profile {
    let mut commands = CommandSet::all_for(false);
    for optional in [
        CommandId::TemporarilySetSerialInterface,
        CommandId::SetPositionWithSync,
        CommandId::SensorAdjustment,
        CommandId::ReadSyncOffset,
    ] {
        commands.remove(optional);
    }
    Profile {
        name: text(name),
        edition: Edition::Current,
        commands,
        address: SlaveAddress::DEFAULT,
        settings: UartSettings::DEFAULT,
        baud_rates: [false, true, true, true, true, true, true],
        type_code,
        option_code: 0,
        // 000:2.4.2 "typical user memory size is 1792 bytes"; 2048 bytes total (000:T28 example).
        memory_blocks: 0x80,
        user_memory_blocks: 0x70,
        extended_type_label: None,
        resolution,
        analog: [Some(TEMPERATURE), None, None, None],
        temperature_min_c: -40,
        temperature_max_c: 115,
        led_current_max_ma: 50,
        max_read_speed: 6000, // 000:T12 note: typically 6000 rpm
        serial: padded("000000001"),
        firmware: padded("hiperface-model"),
        firmware_date: *b"22.11.26",
        version_pins: VersionPins::default(),
        adjustment: [None; 4],
        adjustment_response_ms: 40,
        init_ms: 100,
        default_window_ms: Edition::Current.power_up_windows_ms().0,
        user_settings_ms: Edition::Current.power_up_windows_ms().1,
        stack_order: StackOrder::OldestFirst,
    }
}

fn with_etl(mut p: Profile, designation: &str) -> Profile {
    p.extended_type_label = Some(
        ExtendedTypeLabel {
            resolution: p.resolution,
            bipolar: false,
            designation,
            temperature: Some((0x48, p.temperature_min_c, p.temperature_max_c)),
            max_speed: None,
        }
        .build(),
    );
    p
}

/// SKS36: 128 periods, 4096 steps per turn, singleturn.
pub fn sks36() -> Profile {
    with_etl(current("SKS36", Resolution::Rotary { periods_per_turn: 128, turns: 1 }, 0xFF), "SKS36")
}

/// SKM36: 128 periods, 4096 steps per turn, 4096 turns.
pub fn skm36() -> Profile {
    with_etl(current("SKM36", Resolution::Rotary { periods_per_turn: 128, turns: 4096 }, 0xFF), "SKM36")
}

/// SRS50: 1024 periods, 32768 steps per turn, singleturn, type 22h.
pub fn srs50() -> Profile {
    current("SRS50", Resolution::Rotary { periods_per_turn: 1024, turns: 1 }, 0x22)
}

/// SRM50: 1024 periods, 32768 steps per turn, 4096 turns, type 27h.
pub fn srm50() -> Profile {
    current("SRM50", Resolution::Rotary { periods_per_turn: 1024, turns: 4096 }, 0x27)
}

/// SEK37: 16 periods, 512 steps per turn, type 42h; also answers the legacy F0h channel.
pub fn sek37() -> Profile {
    let mut p = current("SEK37", Resolution::Rotary { periods_per_turn: 16, turns: 1 }, 0x42);
    p.analog[1] = Some(LEGACY_TEMPERATURE);
    p
}

/// TTK70 linear: 1 period per mm, 32 steps per mm, 4000 mm; Sensor Adjustment for
/// read-head and tape assembly (000:T35), options invented for the simulator.
pub fn ttk70() -> Profile {
    let mut p = current("TTK70", Resolution::Linear { period_nm: 1_000_000, periods: 4000 }, 0xFF);
    p.commands.insert(CommandId::SensorAdjustment);
    p.adjustment = [
        Some(AdjustmentOption { option: 0x00, status: 0x00 }),
        Some(AdjustmentOption { option: 0x01, status: 0x01 }),
        None,
        None,
    ];
    p.max_read_speed = 10_000; // mm/s
    with_etl(p, "TTK70")
}

/// Kübler Sendix S36 singleturn, "Hiperface compatible" (001): type 22h, 16h blocks,
/// serial "123456789", firmware "v1.0.8", date "12072019"; 20 bit position (001 §5.1.2:
/// "20 (32) bit"); implements 6Ah but not 67h, 6Bh, 6Ch (001 §5.1.2 command list).
pub fn kuebler_s36() -> Profile {
    let mut p = current("Kuebler-S36-ST", Resolution::Rotary { periods_per_turn: 1 << 15, turns: 1 }, 0x22);
    p.commands.insert(CommandId::SetPositionWithSync);
    p.memory_blocks = 0x16;
    p.user_memory_blocks = 0x16;
    p.serial = *b"123456789";
    p.firmware = padded("v1.0.8");
    p.firmware_date = *b"12072019";
    p.baud_rates = [true; 7];
    p.temperature_min_c = -40;
    p.temperature_max_c = 120;
    p.max_read_speed = 12_000;
    p
}

/// Kübler Sendix S36 multiturn (001): type 27h, 4096 turns.
pub fn kuebler_s36_mt() -> Profile {
    let mut p = kuebler_s36();
    p.name = text("Kuebler-S36-MT");
    p.type_code = 0x27;
    p.resolution = Resolution::Rotary { periods_per_turn: 1 << 15, turns: 4096 };
    p
}

/// A legacy-edition SICK-STEGMANN encoder (002): 11/44 bit-time timeouts, 63h, the
/// ~1 s default window, 128 bytes of memory (002's data-field example), type 22h.
pub fn legacy_srs() -> Profile {
    let mut p = current("Legacy-SRS", Resolution::Rotary { periods_per_turn: 1024, turns: 1 }, 0x22);
    p.set_edition(Edition::Legacy);
    p.memory_blocks = 0x08;
    p.user_memory_blocks = 0x08;
    p.baud_rates = [true; 7];
    p.analog = [Some(LEGACY_TEMPERATURE), None, None, None];
    p.firmware = padded("legacy 1.0");
    p
}

/// A reference device with every command of the current edition, both temperature
/// channels, an Extended Type Label and Sensor Adjustment: the profile of the
/// generated vectors.
pub fn reference() -> Profile {
    let mut p = current("Reference", Resolution::Rotary { periods_per_turn: 128, turns: 4096 }, 0xFF);
    p.commands = CommandSet::all_for(false);
    p.analog[1] = Some(LEGACY_TEMPERATURE);
    p.adjustment = [Some(AdjustmentOption { option: 0x01, status: 0x00 }), None, None, None];
    p.baud_rates = [true; 7];
    with_etl(p, "Reference")
}

/// A built-in profile's name and constructor.
pub type Builtin = (&'static str, fn() -> Profile);

/// Every built-in profile by its name.
pub const BUILTIN: &[Builtin] = &[
    ("SKS36", sks36),
    ("SKM36", skm36),
    ("SRS50", srs50),
    ("SRM50", srm50),
    ("SEK37", sek37),
    ("TTK70", ttk70),
    ("Kuebler-S36-ST", kuebler_s36),
    ("Kuebler-S36-MT", kuebler_s36_mt),
    ("Legacy-SRS", legacy_srs),
    ("Reference", reference),
];

/// Look a built-in profile up by name (case-insensitive).
pub fn builtin(name: &str) -> Option<Profile> {
    BUILTIN.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)).map(|(_, f)| f())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padded_pads_and_cuts() {
        assert_eq!(padded::<4>("ab"), *b"ab\0\0");
        assert_eq!(padded::<3>("abcd"), *b"abc");
        assert_eq!(padded::<0>("x"), [0u8; 0]);
    }

    #[test]
    fn every_builtin_profile_is_valid_and_named() {
        for (name, make) in BUILTIN {
            let p = make();
            assert_eq!(p.validate(), Ok(()), "{name}");
            assert_eq!(p.name.as_str(), *name);
        }
        assert_eq!(builtin("srm50").map(|p| p.range()), Some(32768 * 4096));
        assert_eq!(builtin("TTK70").map(|p| p.range()), Some(32 * 4000), "000:T11: 32 steps/mm, 4000 mm");
        assert_eq!(builtin("SEK37").map(|p| p.range()), Some(512));
        assert!(builtin("nope").is_none());
    }
}
