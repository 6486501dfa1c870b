//! Properties of the model, written once and checked twice: by Kani harnesses
//! (`cargo kani -p hiperface-proofs`, behind `cfg(kani)`) and under `cargo test`
//! (`properties::PROPERTIES`: each exhausted over a bounded domain or sampled with
//! proptest). Also: explicit-state model checking of the slave (`model_check`) and
//! the fuzz target bodies (`targets`), whose corpus a stable `cargo test` replays.

pub mod contents;
#[cfg(test)]
mod documented;
pub mod fixpoint;
pub mod inductive;
pub mod invariant;
pub mod master_fixpoint;
pub mod model_check;
pub mod observer;
pub mod properties;
pub mod targets;

use hiperface_model::master::interpolation;
use hiperface_model::master::quadrature::{self, Ab, Count};
use hiperface_model::master::sync::{self, Correction};
use hiperface_model::settings::{SettingsError, UartSettings};
use hiperface_model::{checksum, AddressByte};

/// A frame with its checksum appended XORs to 0, and flipping any one bit of it
/// (checksum included) is detected. // 000:2.3.3
pub fn checksum_detects_single_bit_flips<const N: usize>(body: [u8; N], bit: usize) -> bool {
    let mut frame = [0u8; 8];
    let Some(slot) = frame.get_mut(..N) else { return false };
    slot.copy_from_slice(&body);
    frame[N] = checksum::xor(&body);
    let sealed_ok = checksum::is_valid(&frame[..=N]);
    let (byte, mask) = (bit / 8, 1u8 << (bit % 8));
    if byte > N {
        return sealed_ok;
    }
    frame[byte] ^= mask;
    sealed_ok && !checksum::is_valid(&frame[..=N])
}

/// The settings byte decodes exactly when defined, and encodes back to itself. // 000:T28
pub fn settings_codec_round_trips(byte: u8) -> bool {
    match UartSettings::decode(byte) {
        Ok(s) => s.byte() == byte,
        Err(SettingsError::UndefinedBaud) => byte & 0x07 == 0x07,
        Err(SettingsError::ReservedBitSet) => byte & 0x08 != 0,
        Err(SettingsError::UndefinedParity) => byte & 0x30 == 0x10,
    }
}

/// The address byte codec round-trips; slave addresses are exactly 40h..=5Fh. // 000:T5
pub fn address_codec_round_trips(byte: u8) -> bool {
    let a = AddressByte::decode(byte);
    let is_slave = matches!(a, AddressByte::Slave(_));
    a.byte() == byte && is_slave == (0x40..=0x5F).contains(&byte)
}

/// 000 Table 72 as printed, row by row: (A(n-1), B(n-1), A(n), B(n)) -> counter.
/// +1 = 1, -1 = -1, no action = 0, invalid = 2.
const SPEC_TABLE_72: [(u8, i8); 16] = [
    (0b0000, 0),
    (0b0001, 1),
    (0b0010, -1),
    (0b0011, 2),
    (0b0100, -1),
    (0b0101, 0),
    (0b0110, 2),
    (0b0111, 1),
    (0b1000, 1),
    (0b1001, 2),
    (0b1010, 0),
    (0b1011, -1),
    (0b1100, 2),
    (0b1101, -1),
    (0b1110, 1),
    (0b1111, 0),
];

/// The quadrature step equals 000 Table 72 for the row `row` (0..16). // 000:T72
pub fn quadrature_equals_table_72(row: u8) -> bool {
    let Some((bits, want)) = SPEC_TABLE_72.iter().copied().find(|(b, _)| *b == row & 0x0F) else { return false };
    let ab = |hi: u8, lo: u8| Ab { a: bits & hi != 0, b: bits & lo != 0 };
    let got = match quadrature::step(ab(8, 4), ab(2, 1)) {
        Count::NoAction => 0,
        Count::Up => 1,
        Count::Down => -1,
        Count::Invalid => 2,
    };
    got == want
}

/// 000:3.2.5's table as printed: (f(i:i-1), a(4:3)) -> 0 same, 1 a+1, -1 a-1, 2 invalid.
const SPEC_SYNC: [(u8, u8, i8); 16] = [
    (0, 0, 0),
    (0, 1, 0),
    (0, 2, 2),
    (0, 3, 1),
    (1, 0, 0),
    (1, 1, 0),
    (1, 2, 0),
    (1, 3, 2),
    (2, 0, 2),
    (2, 1, 0),
    (2, 2, 0),
    (2, 3, 0),
    (3, 0, -1),
    (3, 1, 2),
    (3, 2, 0),
    (3, 3, 0),
];

/// The synchronisation correction equals the spec table for (fine, absolute) quadrants. // 000:3.2.5
pub fn sync_equals_table(fine: u8, absolute: u8) -> bool {
    let Some((_, _, want)) = SPEC_SYNC.iter().copied().find(|(f, a, _)| *f == fine & 3 && *a == absolute & 3) else {
        return false;
    };
    let got = match sync::correction(fine, absolute) {
        Correction::Same => 0,
        Correction::PlusOne => 1,
        Correction::MinusOne => -1,
        Correction::Invalid => 2,
    };
    got == want
}

/// For every sign combination: the octant's transformation gives 0 <= X <= Y, Y > 0,
/// and the retransformed node angles stay inside the octant. // 000:3.2.4
pub fn octant_transformation_is_sound(sin: i32, cos: i32) -> bool {
    if sin == 0 && cos == 0 {
        return true;
    }
    let o = interpolation::octant(sin, cos);
    let (x, y) = interpolation::transform(o, sin, cos);
    let ordered = x >= 0 && y > 0 && x <= y;
    // A = 0 and A = 45° map to the octant's two boundaries.
    let lo = interpolation::retransform(o, 0);
    let hi = interpolation::retransform(o, interpolation::OCTANT);
    // The octant's boundaries, modulo a full period (octant 7 ends at 360° = 0).
    let b0 = (o as u32).wrapping_mul(interpolation::OCTANT);
    let b1 = b0.wrapping_add(interpolation::OCTANT);
    let bounds = (lo == b0 && hi == b1) || (lo == b1 && hi == b0);
    ordered && bounds
}

#[cfg(kani)]
mod harnesses;

#[cfg(test)]
mod tests {
    use super::*;

    /// The Kani harnesses in harnesses.rs (`scripts/kani.sh` runs each).
    const HARNESSES: usize = 52;

    /// Every Kani harness has its `cargo test` twin in the registry, and every twin
    /// names a harness that exists: the two lists are one.
    #[test]
    fn every_harness_has_its_twin() {
        let source = include_str!("harnesses.rs");
        // Written in two pieces, so that this line is not itself taken for a harness.
        let marker = concat!("#[kani", "::proof]");
        let mut harnesses: Vec<&str> =
            source.split(marker).skip(1).filter_map(|s| s.split("fn ").nth(1)?.split('(').next()).collect();
        let mut twins: Vec<&str> = properties::PROPERTIES.iter().filter_map(|p| p.harness).collect();
        harnesses.sort_unstable();
        twins.sort_unstable();
        assert_eq!(harnesses.len(), HARNESSES, "{harnesses:?}");
        assert_eq!(harnesses, twins);
    }

    /// Each harness's domain is its twin's, word for word: the `Domain:` line that
    /// opens the harness's doc comment is the twin's `Property::domain`.
    #[test]
    fn every_twin_checks_its_harness_domain() {
        let source = include_str!("harnesses.rs");
        let marker = concat!("#[kani", "::proof]");
        let mut checked = 0;
        for chunk in source.split(marker).skip(1) {
            let Some(name) = chunk.split("fn ").nth(1).and_then(|s| s.split('(').next()) else { continue };
            let twin = properties::PROPERTIES.iter().find(|p| p.harness == Some(name)).expect("a twin");
            // The last `Domain:` line before the harness, with no other function between.
            let before = &source[..source.find(&format!("fn {name}(")).unwrap_or(0)];
            let doc = before.rsplit("/// Domain: ").next().unwrap_or("");
            assert!(!doc.contains("fn "), "{name} has no Domain: line of its own");
            let domain = doc.lines().next().unwrap_or("").trim().trim_end_matches('.');
            assert_eq!(domain, twin.domain, "{name}");
            checked += 1;
        }
        assert_eq!(checked, HARNESSES);
    }

    #[test]
    fn every_property_holds_on_its_domain() {
        let mut failures = Vec::new();
        for p in properties::PROPERTIES {
            let t = std::time::Instant::now();
            match (p.run)() {
                Ok(n) => eprintln!(
                    "{:<30} {:>10} cases  {}  {:.1} s  domain: {}",
                    p.name,
                    n,
                    if p.exhaustive { "exhaustive" } else { "sampled   " },
                    t.elapsed().as_secs_f64(),
                    p.domain
                ),
                Err(e) => failures.push(format!("{}: {e}", p.name)),
            }
        }
        assert!(failures.is_empty(), "{failures:#?}");
    }

    /// The two inputs Kani 0.63 reported against `response_decoder` (a CBMC fault,
    /// docs/src/design.md "Kani"): both decode, as Store Data replies, and re-encode to
    /// the same bytes.
    #[test]
    fn the_replies_kani_reported_round_trip() {
        use hiperface_model::response::Response;
        use hiperface_model::{CommandId, ResponseFrame};
        for data in [[0x4B, 0xDA, 0xCB, 0x89, 0x00, 0xE8, 0x70], [0x4B, 0xC1, 0x4B, 0x0A, 0x80, 0x00, 0x00]] {
            let reply = ResponseFrame::decode(&data[1..], CommandId::StoreData).expect("a Store Data reply");
            assert!(matches!(reply.response, Response::DataStored { .. }), "{reply:?}");
            assert_eq!(reply.encode().as_bytes(), &data[1..]);
            targets::response(&data);
        }
    }

    #[test]
    fn model_checking_of_the_slave() {
        // CI bound: depth 8 (docs/src/verification.md: the deeper release bound, HF_MC_DEPTH=20).
        let depth = std::env::var("HF_MC_DEPTH").ok().and_then(|d| d.parse().ok()).unwrap_or(8);
        let t = std::time::Instant::now();
        let r = model_check::explore(depth).unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "model checking: {} states, {} transitions, depth {} ({}), {:.1} s",
            r.states,
            r.transitions,
            r.depth,
            if r.complete { "complete" } else { "bounded" },
            t.elapsed().as_secs_f64()
        );
        assert!(r.states >= 4000 || depth < 8, "{} states", r.states);
    }
}
