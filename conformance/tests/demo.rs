//! The demonstration session runs in virtual time and shows what the model does.

use hiperface_conformance::demo;
use hiperface_model::profiles;

#[test]
fn demo_transcript_shows_the_model_at_work() {
    let t = demo::run(profiles::srs50());
    // Set Position 0 then Read Position answers 0 (raw position 12345 in the demo).
    assert!(t.contains("M> 40 42 02\n") && t.contains("S< 40 42 00 00 30 39 0B"), "{t}");
    assert!(t.contains("S< 40 42 00 00 00 00 02"), "{t}");
    assert!(t.contains("S< 40 50 0A 1A"), "bad checksum answered with 0Ah:\n{t}");
    assert!(t.contains("Encoder Reset (no reply)  [000:T29]"), "{t}");
    assert!(t.contains("(no reply; slave state: Initialization)"), "{t}");
    assert!(t.contains("EEPROM writes: 3"), "{t}");
    // The legacy edition runs too.
    let l = demo::run(profiles::legacy_srs());
    assert!(l.contains("Legacy edition"), "{l}");
}
