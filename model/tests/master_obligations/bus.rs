//! A master talking to an encoder in virtual time, for the observer to watch: requests
//! sent character by character, the encoder's replies, the rules it observed.

use crate::common::sealed;
use hiperface_model::datalink::RxChar;
use hiperface_model::master::obligations::{Observation, Observer, Rule};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::{FaultCode, Profile};

pub(crate) const CT: u64 = 1146; // 9600 Bd, 11 bits
pub(crate) const TIMEOUT: u64 = 5730;
pub(crate) const MS: u64 = 1000;

/// A master talking to an encoder, in virtual time.
pub(crate) struct Bus {
    pub(crate) observer: Observer,
    pub(crate) now: u64,
    pub(crate) seen: Vec<Observation>,
}

impl Bus {
    pub(crate) fn new(profile: Profile) -> Bus {
        let mut observer = Observer::new(profile);
        observer.power_on(0);
        Bus { observer, now: 0, seen: Vec::new() }
    }

    pub(crate) fn at(&mut self, t_us: u64) -> &mut Bus {
        self.observer.poll(t_us, &mut |o| self.seen.push(o));
        self.now = self.now.max(t_us);
        self
    }

    /// The master sends `body` (checksum appended unless `raw`) from `now`, characters
    /// back to back with `gaps` (index, extra µs) inserted.
    pub(crate) fn send_raw(&mut self, bytes: &[u8], gaps: &[(usize, u64)]) -> &mut Bus {
        let mut t = self.now;
        for (i, b) in bytes.iter().enumerate() {
            t += CT + gaps.iter().filter(|(at, _)| *at == i).map(|(_, g)| g).sum::<u64>();
            self.observer.master_char(RxChar::ok(*b, t), &mut |o| self.seen.push(o));
        }
        self.now = t;
        self
    }

    pub(crate) fn send(&mut self, body: &[u8]) -> &mut Bus {
        self.send_raw(&sealed(body), &[])
    }

    /// The encoder answers after the timeout (+300 µs), and the master waits for the
    /// reply's end and the timeout.
    pub(crate) fn reply(&mut self, warning: bool, response: Response) -> &mut Bus {
        let start = self.now + TIMEOUT + 300;
        self.at(start);
        let rf = ResponseFrame { address: 0x40, warning, response };
        let end = start + rf.encode().len() as u64 * CT;
        self.observer.encoder_reply(start, end, Some(&rf));
        self.at(end + TIMEOUT)
    }

    /// Request and reply: what a conformant master does each cycle.
    pub(crate) fn ask(&mut self, body: &[u8], response: Response) -> &mut Bus {
        self.send(body).reply(false, response)
    }

    pub(crate) fn wait_ms(&mut self, ms: u64) -> &mut Bus {
        let t = self.now + ms * MS;
        self.at(t)
    }

    pub(crate) fn rules(&mut self) -> Vec<Rule> {
        let t = self.now + 100 * MS;
        self.at(t);
        self.seen.iter().map(|o| o.rule).collect()
    }
}

pub(crate) const POSITION: Response = Response::Position(1234);

/// The start-up flow of 000:3.3.1 and cyclic Read Position.
pub(crate) fn conformant_start(bus: &mut Bus) {
    bus.at(120 * MS)
        .ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault))
        .ask(&[0x40, 0x52], Response::TypeLabel { settings: 0xE4, type_code: 0x22, memory_blocks: 0x70, option: 0 });
    for _ in 0..5 {
        bus.ask(&[0x40, 0x42], POSITION).wait_ms(2);
    }
}
