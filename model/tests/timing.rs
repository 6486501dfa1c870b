//! Frame timing and the power-up state machine, in virtual time through the data link.

mod common;
use common::*;
use hiperface_model::datalink::RxChar;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{profiles, Edition, Slave, Step, UartSettings};

const MS: u64 = 1000;

/// Send `frame` with characters back to back from `start_us` at `settings`; then poll
/// until the slave has processed it. Returns the step.
fn send(s: &mut Slave, frame: &[u8], start_us: u64, settings: UartSettings) -> Option<Step> {
    let ct = settings.char_time_us();
    let mut step = None;
    for (i, b) in frame.iter().enumerate() {
        step = step.or(s.receive(RxChar::ok(*b, start_us + (i as u64 + 1) * ct)));
    }
    let last = start_us + frame.len() as u64 * ct;
    step.or_else(|| s.poll(last + 10 * s.timeout_us(last)))
}

fn reply_of(step: &Option<Step>) -> Option<Vec<u8>> {
    step.as_ref().and_then(|s| s.transmission).map(|t| t.frame.as_bytes().to_vec())
}

#[test]
fn reply_window_follows_the_request_timeout() {
    let mut s = Slave::operational(profiles::srs50());
    let d = UartSettings::DEFAULT;
    let step = send(&mut s, &[0x40, 0x42, 0x02], 0, d).unwrap();
    let t = step.transmission.unwrap();
    let last_rx = 3 * d.char_time_us();
    // 000:2.2.2: processed when no character arrives within the timeout (55 bit times).
    assert_eq!(step.received.complete_us, last_rx + 5730);
    assert_eq!(t.earliest_start_us, last_rx + 5730);
    // 000:T10: Read Position within 10 ms.
    assert_eq!(t.latest_start_us, t.earliest_start_us + 10 * MS);
    assert_eq!(t.settings, d);
    // 4Bh allows 250 ms.
    let step = send(&mut s, &sealed(&[0x40, 0x4D, 0, 0xC0, 0x55]), 100 * MS, d).unwrap();
    assert_eq!(step.transmission.map(|t| t.latest_start_us - t.earliest_start_us), Some(70 * MS));
}

#[test]
fn a_gap_of_one_timeout_splits_a_frame() {
    let mut s = Slave::operational(profiles::srs50());
    let d = UartSettings::DEFAULT;
    assert!(s.receive(RxChar::ok(0x40, 1000)).is_none());
    // The second character arrives exactly one timeout later: the first frame (just
    // the address) is complete and draws 0Ch.
    let step = s.receive(RxChar::ok(0x42, 1000 + d.timeout_us(Edition::Current))).unwrap();
    assert_eq!(reply_of(&Some(step)), Some(error(0x40, 0x0C)));
    // One µs less keeps characters together.
    let mut s = Slave::operational(profiles::srs50());
    s.receive(RxChar::ok(0x40, 1000));
    assert!(s.receive(RxChar::ok(0x42, 1000 + 5729)).is_none());
    assert!(s.receive(RxChar::ok(0x02, 1000 + 2 * 5729)).is_none());
    assert!(s.poll(1000 + 2 * 5729 + 5729).is_none());
    assert_eq!(reply_of(&s.poll(1000 + 2 * 5729 + 5730)), Some(hex("40 42 00 00 00 00 02")));
}

#[test]
fn power_up_windows_current_edition() {
    let d = UartSettings::DEFAULT;
    // Stored settings differ from the defaults: 19200 Bd, odd, short timeout.
    let mut p = profiles::srs50();
    p.settings = UartSettings::decode(0xB5).unwrap();
    let stored = p.settings;

    // No request: default 100..900 ms, silent 900..1100 ms, stored settings after.
    let mut s = Slave::new(p);
    assert_eq!(s.state(50 * MS), CommState::Initialization);
    assert!(send(&mut s, &[0x40, 0x42, 0x02], 10 * MS, d).is_none(), "000:T9: no UART during initialization");
    assert_eq!(s.listening_settings(500 * MS), Some(d));
    assert_eq!(s.listening_settings(950 * MS), None);
    assert!(send(&mut s, &[0x40, 0x42, 0x02], 950 * MS, d).is_none(), "change of settings: no UART");
    assert_eq!(s.state(1100 * MS), CommState::OperationalUser);
    let step = send(&mut s, &[0x40, 0x42, 0x02], 1200 * MS, stored).unwrap();
    assert_eq!(step.transmission.unwrap().settings, stored);
    assert_eq!(step.received.complete_us - 1200 * MS - 3 * stored.char_time_us(), stored.timeout_us(Edition::Current));

    // A request in the default window keeps the defaults until reset.
    let mut s = Slave::new(p);
    assert!(send(&mut s, &[0x40, 0x42, 0x02], 200 * MS, d).is_some());
    assert_eq!(s.state(5000 * MS), CommState::OperationalDefault);
    assert_eq!(s.listening_settings(5000 * MS), Some(d));
    // A request for another address does not.
    let mut s = Slave::new(p);
    assert!(send(&mut s, &sealed(&[0x41, 0x42]), 200 * MS, d).unwrap().transmission.is_none());
    assert_eq!(s.state(5000 * MS), CommState::OperationalUser);
}

#[test]
fn encoder_reset_restarts_initialization_after_the_request_timeout() {
    let d = UartSettings::DEFAULT;
    let mut s = Slave::operational(profiles::srs50());
    let step = send(&mut s, &[0x40, 0x53, 0x13], 0, d).unwrap();
    assert!(step.transmission.is_none(), "000:T29: no response");
    let reset_at = step.received.complete_us;
    assert_eq!(s.state(reset_at), CommState::Initialization);
    // 000:T29: respond again after 100 ms initialization plus the request timeout.
    assert!(send(&mut s, &[0x40, 0x42, 0x02], reset_at + 90 * MS, d).is_none());
    assert!(send(&mut s, &[0x40, 0x42, 0x02], reset_at + 100 * MS, d).is_some());
}

#[test]
fn temporary_settings_apply_after_the_reply_and_vanish_on_reset() {
    let d = UartSettings::DEFAULT;
    let mut p = profiles::srs50();
    p.commands.insert(hiperface_model::CommandId::TemporarilySetSerialInterface);
    let mut s = Slave::operational(p);
    let fast = UartSettings::decode(0xE6).unwrap(); // 38400 Bd
    let step = send(&mut s, &sealed(&[0x40, 0x67, 0xE6]), 0, d).unwrap();
    let t = step.transmission.unwrap();
    // 000:T33: the reply in the previous settings, the new ones right after.
    assert_eq!((t.settings, t.then_settings), (d, Some(fast)));
    assert_eq!(s.listening_settings(1), Some(fast));
    let step = send(&mut s, &[0x40, 0x42, 0x02], 100 * MS, fast).unwrap();
    assert_eq!(step.transmission.unwrap().settings, fast);
    let step = send(&mut s, &[0x40, 0x53, 0x13], 200 * MS, fast).unwrap();
    s.settle();
    assert!(step.transmission.is_none());
    assert_eq!(s.listening_settings(u64::MAX), Some(d), "lost on reset");
}

#[test]
fn legacy_edition_timing() {
    let d = UartSettings::DEFAULT;
    let mut p = profiles::legacy_srs();
    p.settings = UartSettings::decode(0xE5).unwrap();
    let mut s = Slave::new(p);
    // 002: timeout 44 bit times, "≈4.7 ms" at 9600 Bd: a pause on the line, which a
    // receiver counting from character ends sees as 55 (DESIGN:legacy-timeout).
    assert_eq!(d.pause_us(Edition::Legacy), 4584);
    assert_eq!(d.timeout_us(Edition::Legacy), 5730);
    let step = send(&mut s, &[0x40, 0x42, 0x02], 200 * MS, d).unwrap();
    assert_eq!(step.received.complete_us, 200 * MS + 3 * d.char_time_us() + 5730);
    // The short setting (11 bit times): a request sent back to back is one frame.
    let mut short_profile = p;
    short_profile.settings = UartSettings::decode(0xA4).unwrap();
    let mut s = Slave::new(short_profile);
    s.settle();
    let short = UartSettings::decode(0xA4).unwrap();
    let step = send(&mut s, &[0x40, 0x42, 0x02], 2000 * MS, short).unwrap();
    assert_eq!(reply_of(&Some(step)).map(|r| r.len()), Some(7), "Read Position answered whole");
    assert_eq!(step.received.complete_us, 2000 * MS + 3 * short.char_time_us() + short.bits_us(22));
    // 002:57h: default settings for about 1 s, then the stored ones, with no silent gap.
    let s = Slave::new(p);
    assert_eq!(s.listening_settings(999 * MS), Some(d));
    assert_eq!(s.listening_settings(1000 * MS).map(|x| x.byte()), Some(0xE5));
}

/// What a master should talk in: the settings the slave listens with, or while it does
/// not listen the ones it will listen with next (000:T9). And when the power-up state
/// changes by itself.
#[test]
fn the_settings_heard_next_and_the_state_changes() {
    let d = UartSettings::DEFAULT;
    let mut p = profiles::srs50();
    let stored = UartSettings::decode(0x64).unwrap(); // 9600 Bd, even, long, but not E4h's bus bit
    p.settings = stored;
    let s = Slave::new(p);
    // Initialization (0-100 ms): not listening; next the defaults.
    assert_eq!(s.listening_settings(50 * MS), None);
    assert_eq!(s.settings_heard_next(50 * MS), d);
    // Default window: the defaults.
    assert_eq!(s.settings_heard_next(500 * MS), d);
    // Change of settings (900-1100 ms): not listening; next the stored ones.
    assert_eq!(s.listening_settings(1000 * MS), None);
    assert_eq!(s.settings_heard_next(1000 * MS), stored);
    assert_eq!(s.settings_heard_next(2000 * MS), stored);
    // The changes at 100, 900 and 1100 ms: strictly after the start of the span, no
    // later than its end.
    assert!(s.state_changes_within(99 * MS, 100 * MS));
    assert!(!s.state_changes_within(100 * MS, 899 * MS));
    assert!(s.state_changes_within(100 * MS, 900 * MS));
    assert!(!s.state_changes_within(900 * MS, 1099 * MS));
    assert!(s.state_changes_within(1099 * MS, 1100 * MS));
    assert!(!s.state_changes_within(1100 * MS, 9000 * MS));
    // Legacy: no silent window before the stored settings.
    let mut l = profiles::legacy_srs();
    l.settings = UartSettings::decode(0x65).unwrap();
    let s = Slave::new(l);
    assert_eq!(s.settings_heard_next(10 * MS), d);
    assert_eq!(s.settings_heard_next(1000 * MS).byte(), 0x65);
    assert!(s.state_changes_within(999 * MS, 1000 * MS) && !s.state_changes_within(1000 * MS, 5000 * MS));
}
