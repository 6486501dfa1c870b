//! Behavioural mutants at the wire: the conformant encoder (the model) with one
//! defect in what it puts on the line or does with a request, per command and per
//! reply byte: a wrong value, a byte dropped or repeated, the checksum without the
//! address, another error code, an error for a valid request, the state effect
//! skipped, doubled or applied elsewhere, a reply early, late, split or missing; and
//! for every reply: the warning bit stuck or never set, the frame timeout or a
//! power-up window off by about a character, settings taken up a request early or
//! late.
//!
//! Long because: the defects (Op) and the device that applies them are read together,
//! each defect's effect a branch of the device's reply.
//!
//! The device frames requests with its own data link (the model's, so that its
//! timeout can be changed) and hands each frame to the model ([`Slave::process`]).

use crate::certify::{self, Caught, Verdicts};
use crate::configs::{self, Config};
use crate::run::{Family, MutantName};
use hiperface_model::checksum;
use hiperface_model::datalink::{DataLink, ReceivedFrame, RxChar};
use hiperface_model::{CommandId, Edition, Frame, Slave, Transmission, UartSettings, COMMAND_TABLE};
use hiperface_suite::line::virtual_line::SlaveDevice;
use hiperface_suite::slave::Report;

/// What the defect does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// Reply byte `byte` XOR `mask`; the checksum recomputed unless it is the byte.
    Flip { byte: u8, mask: u8 },
    /// Reply byte `byte` left out; the checksum over what is sent.
    Drop { byte: u8 },
    /// Reply byte `byte` sent twice; the checksum over what is sent.
    Repeat { byte: u8 },
    /// The checksum over the bytes after the address only.
    ChecksumWithoutAddress,
    /// Another error code than the model's, where the reply is an error.
    OtherError,
    /// Error 0Dh where the reply is not an error.
    ErrorInsteadOfReply,
    /// The reply as due, the request's effect not done.
    Skip,
    /// The reply as due, the request's effect done twice.
    Double,
    /// The reply as due, the effect done on another field, code, offset or value.
    Elsewhere,
    /// The reply started before the request's timeout has elapsed.
    Early,
    /// The reply started after the command's maximum response time.
    Late,
    /// A pause of more than the timeout inside the reply.
    Split,
    /// No reply.
    Silent,
    /// Every reply with the warning bit.
    WarningStuck,
    /// No reply with the warning bit.
    WarningNeverSet,
    /// The frame timeout a character longer or shorter.
    Timeout { longer: bool },
    /// A power-up window (0 initialization, 1 default settings, 2 user settings) two
    /// milliseconds (about a character at 9600 Bd) longer or shorter.
    Window { which: u8, longer: bool },
    /// New UART settings taken up a request early (67h: the reply already in them;
    /// 57h: at once, not from the next reset).
    SettingsEarly,
    /// 67h's settings taken up a request late (the next request still heard in the old).
    SettingsLate,
}

/// A defect, on one command's replies or on all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WireMutant {
    pub op: Op,
    pub command: Option<CommandId>,
}

fn command_name(c: Option<CommandId>) -> String {
    match c.and_then(|c| c.spec()) {
        Some(s) => format!("{:02X}h {}", s.id.byte(), s.name),
        None => "every reply".into(),
    }
}

impl WireMutant {
    pub fn description(&self) -> String {
        let what = match self.op {
            Op::Flip { byte, mask } => format!("reply byte {byte} XOR {mask:02X}h"),
            Op::Drop { byte } => format!("reply byte {byte} left out"),
            Op::Repeat { byte } => format!("reply byte {byte} sent twice"),
            Op::ChecksumWithoutAddress => "checksum without the address".into(),
            Op::OtherError => "another error code".into(),
            Op::ErrorInsteadOfReply => "error 0Dh instead of the reply".into(),
            Op::Skip => "effect skipped".into(),
            Op::Double => "effect done twice".into(),
            Op::Elsewhere => "effect done elsewhere".into(),
            Op::Early => "reply before the timeout".into(),
            Op::Late => "reply after the maximum response time".into(),
            Op::Split => "reply split by a pause of the timeout".into(),
            Op::Silent => "no reply".into(),
            Op::WarningStuck => "warning bit always set".into(),
            Op::WarningNeverSet => "warning bit never set".into(),
            Op::Timeout { longer } => {
                format!("frame timeout a character {}", if longer { "longer" } else { "shorter" })
            }
            Op::Window { which, longer } => format!(
                "{} window 2 ms {}",
                ["initialization", "default settings", "user settings"].get(which as usize).copied().unwrap_or("?"),
                if longer { "longer" } else { "shorter" }
            ),
            Op::SettingsEarly => "new settings a request early".into(),
            Op::SettingsLate => "new settings a request late".into(),
        };
        format!("{}: {what}", command_name(self.command))
    }

    pub fn name(&self, id: u32) -> MutantName {
        let function = command_name(self.command);
        MutantName { family: Family::Wire, id, key: format!("wire: {}", self.description()), function }
    }
}

/// Commands whose request changes the device's state.
fn changes_state(c: CommandId) -> bool {
    use CommandId as C;
    c.spec().is_some_and(|s| s.writes_eeprom())
        || matches!(c, C::ReadEncoderStatus | C::EncoderReset | C::TemporarilySetSerialInterface | C::IncrementCounter)
}

/// The request with its effect moved elsewhere, for the commands that have an
/// elsewhere: the preset one higher, the data one byte further on, another code, the
/// address one higher, another data rate, another field size.
fn elsewhere(bytes: &[u8]) -> Option<Vec<u8>> {
    let mut b = bytes.to_vec();
    let cmd = CommandId::of_frame(bytes);
    use CommandId as C;
    match cmd {
        C::SetPosition | C::SetPositionWithSync | C::SetPositionInternalSync => {
            let p = u32::from_be_bytes(b.get(2..6)?.try_into().ok()?).wrapping_add(1);
            b.get_mut(2..6)?.copy_from_slice(&p.to_be_bytes());
        }
        C::StoreData => *b.get_mut(3)? = b.get(3)?.wrapping_add(1),
        C::SetAccessCode => *b.get_mut(2)? ^= 0x01,
        C::SetEncoderAddress => *b.get_mut(2)? ^= 0x01,
        C::SetSerialInterface | C::TemporarilySetSerialInterface => *b.get_mut(2)? ^= 0x01,
        C::CreateDataField => *b.get_mut(3)? ^= 0x01,
        _ => return None,
    }
    let n = b.len().checked_sub(1)?;
    let sum = checksum::xor(b.get(..n)?);
    *b.get_mut(n)? = sum;
    Some(b)
}

/// Every wire mutant, in a fixed order.
pub fn all() -> Vec<WireMutant> {
    let mut v = Vec::new();
    for spec in COMMAND_TABLE {
        let c = Some(spec.id);
        let reply_len = match spec.slave_data {
            hiperface_model::command::DataLength::Fixed(n) => Some(3 + n),
            hiperface_model::command::DataLength::Range { .. } => Some(7),
            _ => None,
        };
        if let Some(len) = reply_len {
            for byte in 0..len {
                for mask in [0x01, 0x80] {
                    v.push(WireMutant { op: Op::Flip { byte, mask }, command: c });
                }
                v.push(WireMutant { op: Op::Drop { byte }, command: c });
                v.push(WireMutant { op: Op::Repeat { byte }, command: c });
            }
            for op in [Op::ChecksumWithoutAddress, Op::ErrorInsteadOfReply, Op::Early, Op::Late, Op::Split, Op::Silent]
            {
                v.push(WireMutant { op, command: c });
            }
        }
        // A status reply of 50h has the form of an error reply: no error of its own to change.
        if spec.id != CommandId::ReadEncoderStatus {
            v.push(WireMutant { op: Op::OtherError, command: c });
        }
        if changes_state(spec.id) {
            v.push(WireMutant { op: Op::Skip, command: c });
            v.push(WireMutant { op: Op::Double, command: c });
        }
        let sample = [0x40, spec.id.byte(), 0, 0, 0, 0, 0];
        if elsewhere(&sample).is_some() {
            v.push(WireMutant { op: Op::Elsewhere, command: c });
        }
    }
    v.push(WireMutant { op: Op::SettingsEarly, command: Some(CommandId::TemporarilySetSerialInterface) });
    v.push(WireMutant { op: Op::SettingsLate, command: Some(CommandId::TemporarilySetSerialInterface) });
    v.push(WireMutant { op: Op::SettingsEarly, command: Some(CommandId::SetSerialInterface) });
    for op in [Op::WarningStuck, Op::WarningNeverSet, Op::Timeout { longer: true }, Op::Timeout { longer: false }] {
        v.push(WireMutant { op, command: None });
    }
    for which in 0..3 {
        for longer in [true, false] {
            v.push(WireMutant { op: Op::Window { which, longer }, command: None });
        }
    }
    v
}

/// The mutant with id `id` (its place in [`all`] from 1).
pub fn by_id(id: u32) -> Option<WireMutant> {
    all().get((id as usize).checked_sub(1)?).copied()
}

/// The names of every wire mutant.
pub fn names() -> Vec<MutantName> {
    all().iter().enumerate().map(|(i, m)| m.name(i as u32 + 1)).collect()
}

/// The conformant encoder with one wire defect.
pub struct WireDevice {
    slave: Slave,
    link: DataLink,
    /// The defect; `None`: the conformant device, framing by itself.
    m: Option<WireMutant>,
    edition: Edition,
    /// The reply now being sent has a pause inside.
    split: bool,
    /// 67h late: the settings still heard, until the next frame.
    late_settings: Option<UartSettings>,
}

impl WireDevice {
    pub fn new(config: &Config, m: Option<WireMutant>) -> WireDevice {
        let (profile, world) = (config.profile, &config.world);
        let mut p = profile;
        if let Some(Op::Window { which, longer }) = m.map(|m| m.op) {
            let w = match which {
                0 => &mut p.init_ms,
                1 => &mut p.default_window_ms,
                _ => &mut p.user_settings_ms,
            };
            *w = if longer { w.saturating_add(2) } else { w.saturating_sub(2) };
        }
        let mut slave = Slave::operational(p);
        world.apply(&mut slave);
        if let Some(n) = config.counter {
            slave.set_counter(n);
        }
        let link = DataLink::new(UartSettings::DEFAULT.timeout_us(p.edition));
        WireDevice { slave, link, m, edition: p.edition, split: false, late_settings: None }
    }

    fn op(&self) -> Option<Op> {
        self.m.map(|m| m.op)
    }

    fn targeted(&self, cmd: CommandId) -> bool {
        self.m.is_some_and(|m| m.command.is_none_or(|c| c == cmd))
    }

    fn timeout_us(&self, at_us: u64) -> u64 {
        let t = self.slave.timeout_us(at_us);
        let ct = self.slave.listening_settings(at_us).unwrap_or(UartSettings::DEFAULT).char_time_us();
        match self.op() {
            Some(Op::Timeout { longer: true }) => t + ct,
            Some(Op::Timeout { longer: false }) => t.saturating_sub(ct),
            _ => t,
        }
    }

    fn process(&mut self, frame: ReceivedFrame) -> Option<Transmission> {
        self.late_settings = None;
        self.split = false;
        let bytes = frame.bytes.as_bytes().to_vec();
        let cmd = CommandId::of_frame(&bytes);
        let targeted = self.targeted(cmd);
        let before = self.slave.clone();
        let mut step = self.slave.process(frame);
        let op = self.op();
        if let (true, Some(op)) = (targeted, op) {
            match op {
                Op::Skip => {
                    let reply = step.transmission;
                    self.slave = before;
                    step.transmission = reply;
                }
                Op::Double => {
                    let _ = self.slave.process(frame);
                }
                Op::Elsewhere => {
                    if let Some(other) = elsewhere(&bytes).and_then(|b| Frame::from_bytes(&b).ok()) {
                        let mut moved = before;
                        let _ = moved.process(ReceivedFrame { bytes: other, ..frame });
                        self.slave = moved;
                    }
                }
                Op::SettingsEarly if cmd == CommandId::SetSerialInterface => {
                    // Taken up at once: as if a 67h with the stored byte followed.
                    let ok = step.transmission.as_ref().is_some_and(|t| {
                        t.frame.as_bytes().len() == 4 && t.frame.as_bytes().get(1).is_some_and(|b| b & 0x7F == 0x57)
                    });
                    if let (true, Some(s)) = (ok, bytes.get(2)) {
                        let a = self.slave.nonvolatile().address.byte();
                        let f = hiperface_suite::frame::sealed(&[a, 0x67, *s]);
                        let _ = self.slave.handle_frame(&f, frame.complete_us);
                    }
                }
                _ => {}
            }
        }
        let mut t = step.transmission?;
        if let (true, Some(op)) = (targeted, op) {
            match op {
                Op::SettingsEarly if cmd == CommandId::TemporarilySetSerialInterface => {
                    if let Some(s) = t.then_settings {
                        t.settings = s;
                    }
                }
                Op::SettingsLate if t.then_settings.is_some() => self.late_settings = Some(t.settings),
                Op::Early => t.earliest_start_us = frame.last_us,
                Op::Late => t.earliest_start_us = t.latest_start_us + t.settings.char_time_us(),
                Op::Split => self.split = true,
                Op::Silent => return None,
                _ => {}
            }
            let mut b = t.frame.as_bytes().to_vec();
            if self.rewrite(op, &mut b) {
                t.frame = Frame::from_bytes(&b).ok()?;
            }
        }
        Some(t)
    }

    /// The reply's bytes as the defect sends them; `true` where they changed.
    fn rewrite(&self, op: Op, b: &mut Vec<u8>) -> bool {
        let reseal = |b: &mut Vec<u8>| {
            if let Some(n) = b.len().checked_sub(1) {
                let sum = checksum::xor(&b[..n]);
                b[n] = sum;
            }
        };
        let command = self.m.and_then(|m| m.command);
        let is_error =
            b.len() == 4 && b.get(1).is_some_and(|c| c & 0x7F == 0x50) && command != Some(CommandId::ReadEncoderStatus);
        match op {
            Op::Flip { byte, mask } => {
                let last = b.len().saturating_sub(1);
                let Some(x) = b.get_mut(byte as usize) else { return false };
                *x ^= mask;
                if byte as usize != last {
                    reseal(b);
                }
            }
            Op::Drop { byte } => {
                if (byte as usize) >= b.len() {
                    return false;
                }
                let last = byte as usize == b.len() - 1;
                b.remove(byte as usize);
                if !last {
                    reseal(b);
                }
            }
            Op::Repeat { byte } => {
                let Some(x) = b.get(byte as usize).copied() else { return false };
                b.insert(byte as usize, x);
                reseal(b);
            }
            Op::ChecksumWithoutAddress => {
                let n = b.len().saturating_sub(1);
                let sum = checksum::xor(b.get(1..n).unwrap_or(&[]));
                let Some(last) = b.last_mut() else { return false };
                *last = sum;
            }
            Op::OtherError if is_error => {
                if let Some(code) = b.get_mut(2) {
                    *code = if *code == 0x0D { 0x0C } else { 0x0D };
                }
                reseal(b);
            }
            Op::ErrorInsteadOfReply if !is_error => {
                let (Some(a), Some(c)) = (b.first().copied(), b.get(1).copied()) else { return false };
                *b = vec![a, 0x50 | (c & 0x80), 0x0D, 0];
                reseal(b);
            }
            Op::WarningStuck | Op::WarningNeverSet => {
                let Some(c) = b.get_mut(1) else { return false };
                *c = if op == Op::WarningStuck { *c | 0x80 } else { *c & 0x7F };
                reseal(b);
            }
            _ => return false,
        }
        true
    }
}

impl SlaveDevice for WireDevice {
    fn receive(&mut self, ch: RxChar) -> Option<Transmission> {
        let done = self.poll(ch.at_us);
        if self.slave.listening_settings(ch.at_us).is_none() {
            return done;
        }
        let timeout = self.timeout_us(ch.at_us);
        self.link.set_timeout(timeout);
        let closed = self.link.receive(ch).and_then(|f| self.process(f));
        done.or(closed)
    }

    fn poll(&mut self, now_us: u64) -> Option<Transmission> {
        let deadline = self.link.deadline()?;
        if now_us < deadline {
            return None;
        }
        let frame = self.link.poll(deadline)?;
        self.process(frame)
    }

    fn next_deadline(&self, now_us: u64) -> Option<u64> {
        match (self.link.deadline(), self.slave.next_deadline(now_us)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        self.late_settings.or_else(|| self.slave.listening_settings(now_us))
    }

    fn extra_gap_before_us(&self, index: usize) -> u64 {
        if self.split && index == 2 {
            let s = self.slave.listening_settings(0).unwrap_or(UartSettings::DEFAULT);
            s.timeout_us(self.edition) + s.char_time_us()
        } else {
            0
        }
    }

    fn edition(&self) -> Edition {
        self.edition
    }

    fn describe(&self) -> String {
        match self.m {
            Some(m) => format!("the model with a defect at the wire ({})", m.description()),
            None => "the model, framing by itself".into(),
        }
    }
}

/// The conformant device (the model, framing by itself) in every configuration.
pub struct Baselines {
    sweeps: [Option<Vec<(Config, Report)>>; 2],
}

impl Baselines {
    pub fn new() -> Baselines {
        Baselines { sweeps: [None, None] }
    }

    fn sweep(&mut self, i: usize) -> &Vec<(Config, Report)> {
        self.sweeps[i].get_or_insert_with(|| {
            let configs = if i == 0 { configs::shipped() } else { configs::in_worlds() };
            configs
                .into_iter()
                .map(|c| {
                    let d = WireDevice::new(&c, None);
                    let r = certify::run(d, c.profile, &certify::options(&c.world));
                    (c, r)
                })
                .collect()
        })
    }

    /// The configurations where the conformant wire device did not PASS (none).
    pub fn not_passed(&mut self) -> Vec<String> {
        (0..2)
            .flat_map(|i| {
                self.sweep(i)
                    .iter()
                    .filter(|(_, r)| !r.outcome().passed())
                    .map(|(c, _)| c.name.clone())
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    pub fn certify(&mut self, id: u32) -> Verdicts {
        let Some(m) = by_id(id) else { return Verdicts::unbuildable("-", format!("no wire mutant {id}")) };
        let mut best: Option<Verdicts> = None;
        for i in 0..2 {
            best = certify::until_fail(self.sweep(i).iter(), best, |(c, baseline)| {
                let report = certify::run(WireDevice::new(c, Some(m)), c.profile, &certify::options(&c.world));
                certify::compare(&c.name, &report, baseline, None)
            });
            if best.as_ref().is_some_and(|b| b.caught == Caught::Fail) {
                break;
            }
        }
        best.unwrap_or_else(|| Verdicts::unbuildable("-", "no configuration".into()))
    }
}

impl Default for Baselines {
    fn default() -> Self {
        Baselines::new()
    }
}
