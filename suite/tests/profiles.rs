//! Profiles as TOML: the shipped files equal the built-in profiles, and malformed
//! files are rejected with the file, the line and the field.

use hiperface_model::profiles;
use hiperface_suite::profile_file::{self, ProfileLoadError};
use rstest::rstest;
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../conformance/profiles").join(format!("{}.toml", name.to_lowercase()))
}

#[test]
fn every_builtin_profile_is_shipped_as_toml_and_reads_back_identical() {
    for (name, make) in profiles::BUILTIN {
        let path = shipped(name);
        let loaded = profile_file::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded, make(), "{name}");
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, profile_file::to_toml(&make()), "{name}: regenerate with `hiperface export-profile {name}`");
    }
}

#[test]
fn a_file_can_override_a_builtin() {
    let p = profile_file::parse(
        "name = \"My SRM50\"\nbase = \"SRM50\"\n[interface]\naddress = 0x45\n[limits]\ntemperature_max_c = 90\n",
        Path::new("mine.toml"),
    )
    .unwrap();
    assert_eq!((p.name.as_str(), p.address.byte(), p.temperature_max_c, p.type_code), ("My SRM50", 0x45, 90, 0x27));
}

#[rstest]
#[case::unknown_field("name = \"x\"\n[timing]\ninit_ms = 100\nint_ms = 5\n", 4, "int_ms", "unknown field")]
#[case::wrong_type("name = \"x\"\n\n[memory]\nuser_blocks = \"many\"\n", 4, "memory.user_blocks", "invalid type")]
#[case::out_of_range(
    "name = \"x\"\n[identity]\ntype_code = 0x1FF\n",
    3,
    "identity.type_code",
    "a whole number from 0 to 255"
)]
#[case::bad_address(
    "name = \"x\"\n[interface]\nsettings = 0xE4\naddress = 0x60\n",
    4,
    "interface.address",
    "60h is not in 40h...5Fh"
)]
#[case::bad_settings("name = \"x\"\n[interface]\nsettings = 0xE7\n", 3, "interface.settings", "data rate bits 111")]
#[case::init_too_long("name = \"x\"\n[timing]\n\ninit_ms = 300\n", 4, "timing.init_ms", "allows 1 to 200 ms")]
#[case::init_zero("name = \"x\"\n[timing]\ninit_ms = 0\n", 3, "timing.init_ms", "allows 1 to 200 ms")]
#[case::bad_command(
    "name = \"x\"\n[commands]\nsupported = [0x42, 0x45]\n",
    3,
    "commands.supported",
    "45h is not a HIPERFACE command"
)]
#[case::legacy_command(
    "name = \"x\"\nedition = \"legacy\"\n[commands]\nsupported = [0x42, 0x6C]\n",
    3,
    "commands",
    "not defined in this edition"
)]
#[case::unknown_base("name = \"x\"\nbase = \"SRS51\"\n", 2, "base", "unknown built-in profile")]
#[case::missing_name("[timing]\ninit_ms = 100\n", 1, "name", "missing field")]
#[case::short_label(
    "name = \"x\"\n[extended_type_label]\nbytes = [0, 1]\n",
    3,
    "extended_type_label.bytes",
    "2 bytes, need 64"
)]
fn malformed_profiles_name_file_line_and_field(
    #[case] text: &str,
    #[case] line: usize,
    #[case] field: &str,
    #[case] message: &str,
) {
    let err = profile_file::parse(text, Path::new("bad.toml")).expect_err("must be rejected");
    let shown = err.to_string();
    assert!(shown.starts_with(&format!("bad.toml:{line}:")), "{shown}");
    assert!(shown.contains(message), "{shown}");
    match err {
        ProfileLoadError::Invalid { field: f, .. } => assert_eq!(f, field, "{shown}"),
        other => panic!("{other}"),
    }
}

#[test]
fn missing_file_and_unknown_builtin() {
    let e = profile_file::load(Path::new("/nonexistent/p.toml")).unwrap_err().to_string();
    assert!(e.starts_with("/nonexistent/p.toml: "), "{e}");
    let e = profile_file::resolve("SRS51").unwrap_err().to_string();
    assert!(e.contains("unknown built-in profile `SRS51`") && e.contains("SRS50"), "{e}");
}
