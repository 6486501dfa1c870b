//! The master obligations' observer (`hiperface_model::master::obligations::Observer`)
//! never panics, whatever it is told in whatever order: characters from the master at
//! any time, with or without a UART fault; the encoder's replies (readable or not) from
//! any start to any end, with any warning bit and any code; power-on, settings,
//! address, data rate, polls and the end of the observation, at any time (times need
//! not increase: a capture's clock may jump). A live bus or a capture feeds it what it
//! reads, so the oracle that grades a drive must not be the one that fails. // 000:2.2.2

use hiperface_model::datalink::{RxChar, UartFault};
use hiperface_model::master::obligations::{Observation, Observer};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::settings::UartSettings;
use hiperface_model::{FaultCode, Profile, SlaveAddress};

/// One thing the observer is told, as plain values that a Kani harness makes symbolic
/// and a property test samples: `kind` picks the observer's input ([`tell`]), the
/// other fields are its arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(kani, derive(kani::Arbitrary))]
pub struct LineEvent {
    pub kind: u8,
    /// A character's byte, a settings or address byte, or the reply's form.
    pub byte: u8,
    /// The code or type code a reply carries.
    pub code: u8,
    pub at_us: u64,
    /// A reply's end, a data rate, or which UART fault.
    pub until_us: u64,
}

/// How many inputs [`tell`] tells apart.
pub const KINDS: u8 = 9;

/// Tell `observer` what `event` says; `seen` counts the observations it reports.
pub fn tell(observer: &mut Observer, event: &LineEvent, seen: &mut u32) {
    let mut out = |_: Observation| *seen = seen.saturating_add(1);
    let e = *event;
    match e.kind % KINDS {
        0 => observer.master_char(RxChar::ok(e.byte, e.at_us), &mut out),
        1 => {
            let fault = [UartFault::Parity, UartFault::Framing, UartFault::Noise, UartFault::Overrun];
            let fault = fault.get((e.until_us % 4) as usize).copied();
            observer.master_char(RxChar { byte: e.byte, at_us: e.at_us, fault }, &mut out)
        }
        2 => observer.poll(e.at_us, &mut out),
        3 => observer.encoder_reply(e.at_us, e.until_us, Some(&reply(e.byte, e.code))),
        // A reply the master cannot read (a corrupted one).
        4 => observer.encoder_reply(e.at_us, e.until_us, None),
        5 => observer.power_on(e.at_us),
        6 => match (UartSettings::decode(e.byte), SlaveAddress::new(e.code)) {
            (Ok(settings), _) => observer.encoder_listens(settings),
            (Err(_), Some(address)) => observer.encoder_at(address),
            (Err(_), None) => {}
        },
        7 => observer.master_data_rate(e.at_us, e.until_us as u32, &mut out),
        _ => observer.end(e.at_us, &mut out),
    }
}

/// A reply whose response the observer branches on: an error code, a code read from
/// the stack, a type label (FFh: the Extended Type Label to read), a position; with
/// the warning bit when `form` has bit 7.
pub fn reply(form: u8, code: u8) -> ResponseFrame {
    let response = match form % 4 {
        0 => Response::Error(FaultCode::decode(code)),
        1 => Response::EncoderStatus(FaultCode::decode(code)),
        2 => Response::TypeLabel { settings: 0xE4, type_code: code, memory_blocks: 0x70, option: 0 },
        _ => Response::Position(code as u32),
    };
    ResponseFrame { address: 0x40, warning: form & 0x80 != 0, response }
}

/// The observer of a master talking to an encoder of `profile` is told `events`: it
/// returns (no panic) with the count of observations reported.
pub fn observe(profile: Profile, events: &[LineEvent]) -> u32 {
    let mut observer = Observer::new(profile);
    let mut seen = 0;
    for e in events {
        tell(&mut observer, e, &mut seen);
    }
    seen
}
