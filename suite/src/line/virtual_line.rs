//! An in-process line in virtual time: the master's characters go straight into a
//! sans-IO slave with their receive times, and the slave's transmissions come back
//! character by character. No sleeping: a whole catalogue runs in milliseconds. The
//! slave is the reference model, a defective variant of it built for tests, or an
//! encoder under test given frame by frame (see [`super::frame_encoder`]).

use super::{Line, LineError, LineKind, Sent, Window};
use hiperface_model::datalink::RxChar;
use hiperface_model::{Edition, Slave, Transmission, UartSettings};
use std::collections::VecDeque;

/// A slave as a sans-IO state machine: characters in with their receive times, and
/// what it puts on the wire.
pub trait SlaveDevice {
    /// A character received; what the device transmits because of it, if anything.
    fn receive(&mut self, ch: RxChar) -> Option<Transmission>;
    /// Time has come to `now_us` (a deadline the device named); what it transmits.
    fn poll(&mut self, now_us: u64) -> Option<Transmission>;
    fn next_deadline(&self, now_us: u64) -> Option<u64>;
    /// The UART settings the device listens with at `now_us` (`None`: it is not
    /// listening). A character sent in other settings arrives with a UART fault.
    fn listening_settings(&self, now_us: u64) -> Option<UartSettings>;
    /// Delay between the earliest allowed start and the actual start of a reply.
    fn reply_delay_us(&self) -> u64 {
        300
    }
    /// Extra idle time before character `index` of a reply (0 for a conforming slave).
    fn extra_gap_before_us(&self, _index: usize) -> u64 {
        0
    }
    fn edition(&self) -> Edition;
    /// What the line is, for reports.
    fn describe(&self) -> String {
        format!("in-process virtual line ({:?} edition)", self.edition())
    }
}

impl SlaveDevice for Slave {
    fn receive(&mut self, ch: RxChar) -> Option<Transmission> {
        Slave::receive(self, ch)?.transmission
    }
    fn poll(&mut self, now_us: u64) -> Option<Transmission> {
        Slave::poll(self, now_us)?.transmission
    }
    fn next_deadline(&self, now_us: u64) -> Option<u64> {
        Slave::next_deadline(self, now_us)
    }
    fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        Slave::listening_settings(self, now_us)
    }
    fn edition(&self) -> Edition {
        self.profile().edition
    }
}

/// The line.
pub struct VirtualLine<D: SlaveDevice> {
    pub device: D,
    now: u64,
    settings: UartSettings,
    /// Characters on their way to the master: (receive time, byte).
    inbound: VecDeque<RxChar>,
}

impl<D: SlaveDevice> VirtualLine<D> {
    pub fn new(device: D) -> VirtualLine<D> {
        VirtualLine { device, now: 0, settings: UartSettings::DEFAULT, inbound: VecDeque::new() }
    }

    /// Start at `t_us` (e.g. after the power-up windows).
    pub fn starting_at(mut self, t_us: u64) -> Self {
        self.now = t_us;
        self
    }

    /// Let the device act on everything due up to `t_us`.
    fn advance(&mut self, t_us: u64) {
        // A deadline already past is due now; one the device names again after it was
        // polled at that time has nothing more to do then (a device under test that
        // keeps naming a past time must not hold the line for ever).
        let mut polled_at = None;
        while let Some(deadline) = self.device.next_deadline(self.now).filter(|d| *d <= t_us) {
            let at = deadline.max(self.now);
            if polled_at == Some(at) {
                break;
            }
            if let Some(t) = self.device.poll(at) {
                self.transmit(t);
            }
            polled_at = Some(at);
            self.now = at;
        }
        self.now = self.now.max(t_us);
    }

    fn transmit(&mut self, t: Transmission) {
        // A reply in other settings than the master listens with is garbage to it.
        let garbled = t.settings != self.settings;
        let ct = t.settings.char_time_us();
        let mut at_us = t.earliest_start_us + self.device.reply_delay_us();
        for (i, b) in t.frame.as_bytes().iter().enumerate() {
            at_us += self.device.extra_gap_before_us(i) + ct;
            let fault = garbled.then_some(hiperface_model::UartFault::Framing);
            self.inbound.push_back(RxChar { byte: *b, at_us, fault });
        }
    }
}

/// The UART fault a character sent in `sent` settings arrives with at a receiver
/// listening in `heard` settings: none when they agree; a parity error where only the
/// parity differs and both have a parity bit (the bit is wrong for one of the two
/// rules); a framing error otherwise (the receiver finds no stop bit where it expects
/// one). // 000:T47
pub fn arrives_with(sent: UartSettings, heard: UartSettings) -> Option<hiperface_model::UartFault> {
    use hiperface_model::settings::Parity;
    use hiperface_model::UartFault;
    if sent == heard {
        return None;
    }
    let both_have_parity = sent.parity != Parity::None && heard.parity != Parity::None;
    let only_parity = UartSettings { parity: heard.parity, ..sent } == heard;
    Some(if only_parity && both_have_parity { UartFault::Parity } else { UartFault::Framing })
}

impl<D: SlaveDevice> Line for VirtualLine<D> {
    fn now_us(&mut self) -> u64 {
        self.now
    }

    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        // Half duplex: the master starts after anything still on the wire.
        let start = self.now.max(self.inbound.back().map_or(0, |c| c.at_us));
        let ct = self.settings.char_time_us();
        let mut last = start;
        for (i, b) in bytes.iter().enumerate() {
            last = start + (i as u64 + 1) * ct;
            self.advance(last.saturating_sub(1));
            let fault = self.device.listening_settings(last).and_then(|heard| arrives_with(self.settings, heard));
            if let Some(t) = self.device.receive(RxChar { byte: *b, at_us: last, fault }) {
                self.transmit(t);
            }
        }
        self.now = last;
        Ok(Sent::within(Window::exact(last)))
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        loop {
            if let Some(c) = self.inbound.front().copied() {
                if c.at_us <= until_us {
                    self.advance(c.at_us);
                    self.inbound.pop_front();
                    return Ok(Some(c));
                }
            }
            // Nothing due: let the device work until the next event or the limit.
            match self.device.next_deadline(self.now).filter(|d| *d <= until_us && *d > self.now) {
                Some(d) => self.advance(d),
                None => {
                    if self.inbound.front().is_some_and(|c| c.at_us <= until_us) {
                        continue;
                    }
                    self.advance(until_us);
                    return Ok(None);
                }
            }
        }
    }

    fn start_of(&self, ch: &RxChar) -> Window {
        Window::exact(ch.at_us.saturating_sub(self.settings.char_time_us()))
    }

    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        self.advance(t_us);
        Ok(())
    }

    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        self.settings = settings;
        Ok(())
    }

    fn settings(&self) -> UartSettings {
        self.settings
    }

    fn kind(&self) -> LineKind {
        LineKind::Virtual
    }

    fn carries_parity(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn describe(&self) -> String {
        self.device.describe()
    }
}
