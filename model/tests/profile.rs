//! Profiles: the Extended Type Label they build (000:T20), what makes one unusable
//! (each error at its limit, naming its field), the response limits they give, and
//! their small value types.

use hiperface_model::command::CommandSet;
use hiperface_model::profile::{
    AdjustmentOption, AnalogChannel, AnalogEncoding, AnalogSource, ExtendedTypeLabel, ProfileError, Resolution, Text,
};
use hiperface_model::settings::Baud;
use hiperface_model::{profiles, CommandId, Profile};

fn label(
    resolution: Resolution,
    bipolar: bool,
    temperature: Option<(u8, i16, i16)>,
    max_speed: Option<u16>,
) -> [u8; 64] {
    ExtendedTypeLabel { resolution, bipolar, designation: "SKM36-HFA0-K02", temperature, max_speed }.build()
}

/// 000:T20: byte 01h bit 0 linear, bit 1 bipolar; resolution and range big-endian;
/// the designation left-justified with trailing 00h; the parameter selector at 1Ch
/// (bits 0-2: temperature channel, min, max; bit 9: speed max) and the values at 1Eh;
/// byte 00h the XOR of the rest.
#[test]
fn the_extended_type_label_is_laid_out_as_table_20_says() {
    let rotary = Resolution::Rotary { periods_per_turn: 1024, turns: 4096 };
    let linear = Resolution::Linear { period_nm: 40_000, periods: 10_000 };
    for (resolution, bipolar, byte1) in
        [(rotary, false, 0x00), (rotary, true, 0x02), (linear, false, 0x01), (linear, true, 0x03)]
    {
        let l = label(resolution, bipolar, None, None);
        assert_eq!(l[1], byte1, "{resolution:?} bipolar {bipolar}");
        assert_eq!(l.iter().fold(0, |x, b| x ^ b), 0, "checksum");
    }
    let l = label(linear, false, None, None);
    assert_eq!(&l[2..10], &[0x00, 0x00, 0x9C, 0x40, 0x00, 0x00, 0x27, 0x10]);
    assert_eq!(&l[0x0A..0x1C], b"SKM36-HFA0-K02\0\0\0\0");
    assert_eq!(&l[0x1C..0x1E], &[0x00, 0x00], "no parameters");
    let t = label(rotary, false, Some((0x48, -20, 110)), None);
    assert_eq!(&t[0x1C..0x24], &[0x00, 0x07, 0x00, 0x48, 0xFF, 0xEC, 0x00, 0x6E]);
    let s = label(rotary, false, None, Some(12_000));
    assert_eq!(&s[0x1C..0x1E], &[0x02, 0x00]);
    assert_eq!(&s[0x30..0x32], &[0x2E, 0xE0]);
    let both = label(rotary, false, Some((0x48, -20, 110)), Some(12_000));
    assert_eq!(&both[0x1C..0x1E], &[0x02, 0x07]);
    assert!(both[0x3C..].iter().all(|b| *b == 0), "3Ch...: read 0");
}

fn valid() -> Profile {
    let p = profiles::srs50();
    assert_eq!(p.validate(), Ok(()));
    p
}

fn check(edit: impl FnOnce(&mut Profile)) -> Result<(), ProfileError> {
    let mut p = valid();
    edit(&mut p);
    p.validate()
}

/// Each consistency rule at its limit: the limit itself is allowed.
#[test]
fn a_profile_is_refused_past_each_limit_and_not_at_it() {
    // Initialization from 1 to 200 ms (000:T9).
    assert_eq!(check(|p| p.init_ms = 200), Ok(()));
    assert_eq!(check(|p| p.init_ms = 1), Ok(()));
    assert_eq!(check(|p| p.init_ms = 0), Err(ProfileError::InitOutOfRange { init_ms: 0 }));
    assert_eq!(check(|p| p.init_ms = 201), Err(ProfileError::InitOutOfRange { init_ms: 201 }));
    // init < default window <= user settings.
    assert_eq!(check(|p| p.user_settings_ms = p.default_window_ms), Ok(()));
    assert_eq!(check(|p| p.user_settings_ms = p.default_window_ms - 1), Err(ProfileError::WindowsOutOfOrder));
    assert_eq!(check(|p| p.default_window_ms = p.init_ms), Err(ProfileError::WindowsOutOfOrder));
    assert_eq!(check(|p| p.default_window_ms = p.init_ms + 1), Ok(()));
    // User memory within the total.
    assert_eq!(check(|p| p.user_memory_blocks = p.memory_blocks), Ok(()));
    assert_eq!(check(|p| p.user_memory_blocks = p.memory_blocks + 1), Err(ProfileError::UserMemoryExceedsTotal));
    // Range: at least one step, at most 2^32 (32-bit positions, 000:T12).
    let rotary =
        |periods_per_turn, turns| move |p: &mut Profile| p.resolution = Resolution::Rotary { periods_per_turn, turns };
    assert_eq!(check(rotary(0, 1)), Err(ProfileError::EmptyRange));
    assert_eq!(check(rotary(1 << 27, 1)), Ok(()));
    assert_eq!(check(rotary((1 << 27) + 1, 1)), Err(ProfileError::RangeTooLarge));
    assert_eq!(check(rotary(1 << 26, 2)), Ok(()));
    // Analog channels once each.
    let channel =
        AnalogChannel { selector: 0x48, source: AnalogSource::Temperature, encoding: AnalogEncoding::Celsius };
    assert_eq!(
        check(|p| p.analog = [Some(channel), None, Some(channel), None]),
        Err(ProfileError::DuplicateAnalogChannel { selector: 0x48 })
    );
    let other = AnalogChannel { selector: 0x49, ..channel };
    assert_eq!(check(|p| p.analog = [Some(channel), Some(other), None, None]), Ok(()));
    // The stored data rate must be one the device has.
    assert_eq!(
        check(|p| {
            p.baud_rates = [false; 7];
            p.baud_rates[4] = true;
            p.settings.baud = Baud::B19200;
        }),
        Err(ProfileError::StoredBaudUnsupported)
    );
    // Commands of the edition only: 63h is legacy (002).
    assert_eq!(
        check(|p| p.commands = CommandSet::all_for(true)),
        Err(ProfileError::CommandNotInEdition { command: CommandId::decode(0x63) })
    );
    // Temperature limits in order; equal is allowed.
    assert_eq!(check(|p| p.temperature_min_c = p.temperature_max_c), Ok(()));
    assert_eq!(check(|p| p.temperature_min_c = p.temperature_max_c + 1), Err(ProfileError::TemperatureLimits));
    // The Extended Type Label: its checksum, and required for type FFh (000:T19).
    let mut etl = label(Resolution::Rotary { periods_per_turn: 1024, turns: 1 }, false, None, None);
    assert_eq!(check(|p| p.extended_type_label = Some(etl)), Ok(()));
    etl[5] ^= 1;
    assert_eq!(check(|p| p.extended_type_label = Some(etl)), Err(ProfileError::ExtendedTypeLabelChecksum));
    assert_eq!(check(|p| p.type_code = 0xFF), Err(ProfileError::ExtendedTypeLabelWithoutCode));
    assert_eq!(profiles::reference().validate(), Ok(()), "type FFh with a label");
}

#[test]
fn a_profile_error_names_its_field_and_says_why() {
    let all = [
        (ProfileError::InitOutOfRange { init_ms: 300 }, "timing.init_ms", "300 ms"),
        (ProfileError::WindowsOutOfOrder, "timing", "000:T9"),
        (ProfileError::UserMemoryExceedsTotal, "memory.user_blocks", "user memory"),
        (ProfileError::EmptyRange, "resolution", "empty"),
        (ProfileError::RangeTooLarge, "resolution", "2^32"),
        (ProfileError::DuplicateAnalogChannel { selector: 0x48 }, "analog", "48h"),
        (ProfileError::StoredBaudUnsupported, "settings", "data rate"),
        (ProfileError::CommandNotInEdition { command: CommandId::decode(0x63) }, "commands", "edition"),
        (ProfileError::TemperatureLimits, "limits", "temperature"),
        (ProfileError::ExtendedTypeLabelChecksum, "extended_type_label", "000:T20"),
        (ProfileError::ExtendedTypeLabelWithoutCode, "extended_type_label", "000:T19"),
    ];
    for (e, field, says) in all {
        assert_eq!(e.field(), field, "{e:?}");
        assert!(e.to_string().contains(says), "{e:?}: {e}");
    }
}

/// 000:T10's limits per command; Sensor Adjustment's from the data sheet (000:T35);
/// an unknown command's error within the shortest limit.
#[test]
fn response_limits_come_from_the_table_and_the_data_sheet() {
    let mut p = profiles::reference();
    p.adjustment_response_ms = 1234;
    assert_eq!(p.response_limit(CommandId::SensorAdjustment).max_ms, 1234);
    assert_eq!(p.response_limit(CommandId::ReadPosition).max_ms, 10);
    assert_eq!(p.response_limit(CommandId::SetEncoderAddress).max_ms, 40);
    assert_eq!(p.response_limit(CommandId::Unknown(0x45)).max_ms, 5);
    assert_eq!(p.adjustment_option(0x01), Some(AdjustmentOption { option: 0x01, status: 0x00 }));
    assert_eq!(p.adjustment_option(0x02), None);
}

#[test]
fn text_is_cut_at_a_character_boundary() {
    assert_eq!(Text::<4>::truncating("abcdef").as_str(), "abcd");
    // "é" takes bytes 4 and 5: it does not fit in 5, so the cut is before it.
    assert_eq!(Text::<5>::truncating("abcdé").as_str(), "abcd");
    assert_eq!(Text::<6>::truncating("abcdé").as_str(), "abcdé");
    assert_eq!(Text::<4>::truncating("€€").as_str(), "€", "3 bytes of 4");
    assert_eq!(Text::<4>::new("abcde"), None);
    let t = Text::<8>::new("SRS50").unwrap();
    assert_eq!((t.to_string(), format!("{t:?}")), ("SRS50".to_string(), "\"SRS50\"".to_string()));
}

/// 000:T14: F0h counts 2.048 °C from -40 °C, rounded to the nearest step on both
/// sides of -40 °C.
#[test]
fn temperatures_below_minus_forty_round_to_the_nearest_step() {
    assert_eq!(AnalogEncoding::Celsius2048.encode(-41), 0, "-0.49 steps");
    assert_eq!(AnalogEncoding::Celsius2048.encode(-42), 0xFFFF, "-0.98 steps");
    assert_eq!(AnalogEncoding::Celsius2048.encode(-43), 0xFFFF, "-1.46 steps");
    assert_eq!(AnalogEncoding::Celsius2048.encode(-44), 0xFFFE, "-1.95 steps");
    assert_eq!(AnalogEncoding::Milliamps.encode(37), 37);
}
