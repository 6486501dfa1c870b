//! Differential runs: a mutant of the encoder and the conformant device side by side
//! on the same random streams of requests (valid and malformed, to every address, at
//! every kind of pause, in random worlds and profiles), compared at the wire: the
//! reply's bytes, when it starts, its UART settings and the settings the device listens
//! with afterwards. A difference is a witness that the mutant is not equivalent (and
//! the stream that shows it, for the case that will tell it); none in many streams is
//! the evidence behind an "equivalent" in the list of survivors (with its argument).
//!
//! What is not the wire is not compared: the model's bookkeeping for the harness (the
//! latest start of a reply it allows, the clauses, the acceptable alternatives, the
//! bytes it knows, its count of EEPROM writes).

use crate::configs;
use crate::device::{build_slave, dut_profile, guarded};
use hiperface_model::address::AddressByte;
use hiperface_model::request::{Request, RequestFrame};
use hiperface_model::{profiles, Profile};
use hiperface_model_mutated as dut;
use hiperface_model_mutated::mutant;
use hiperface_suite::world::World;

/// What a device put on the wire at one step, or its state of listening.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Seen {
    Reply { bytes: Vec<u8>, start_us: u64, settings: u8, then: Option<u8> },
    Listening { at_us: u64, settings: Option<u8> },
    Crashed(String),
}

fn settings_byte(s: dut::UartSettings) -> u8 {
    crate::device::from_dut_settings(s).byte()
}

fn seen(t: dut::Transmission) -> Seen {
    Seen::Reply {
        bytes: t.frame.as_bytes().to_vec(),
        start_us: t.earliest_start_us,
        settings: settings_byte(t.settings),
        then: t.then_settings.map(settings_byte),
    }
}

/// One device of the pair, with what it showed.
struct Side {
    slave: Option<dut::Slave>,
    id: u32,
    log: Vec<Seen>,
}

impl Side {
    fn call<T>(&mut self, f: impl FnOnce(&mut dut::Slave) -> T) -> Option<T> {
        mutant::activate(self.id);
        let slave = self.slave.as_mut()?;
        let r = guarded(|| f(slave));
        mutant::activate(0);
        match r {
            Ok(v) => Some(v),
            Err(why) => {
                self.log.push(Seen::Crashed(why));
                self.slave = None;
                None
            }
        }
    }

    fn receive(&mut self, c: dut::RxChar) {
        if let Some(Some(t)) = self.call(|s| s.receive(c).and_then(|st| st.transmission)) {
            self.log.push(seen(t));
        }
    }

    /// Let the device act on every deadline up to `t_us`. A deadline not after the
    /// time looked from is polled once, then looked past (a device may name the moment
    /// it is in).
    fn advance(&mut self, from_us: u64, t_us: u64) {
        let mut now = from_us;
        for _ in 0..16 {
            let Some(Some(d)) = self.call(|s| s.next_deadline(now)) else { break };
            if d > t_us {
                break;
            }
            let at = d.max(now);
            if let Some(Some(t)) = self.call(|s| s.poll(at).and_then(|st| st.transmission)) {
                self.log.push(seen(t));
            }
            now = if d <= now { now + 1 } else { at };
        }
    }

    fn listening(&mut self, at_us: u64) {
        if let Some(l) = self.call(|s| s.listening_settings(at_us).map(settings_byte)) {
            self.log.push(Seen::Listening { at_us, settings: l });
        }
    }
}

/// A small deterministic generator (SplitMix64): a stream is reproduced from its seed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// 0..n.
    pub fn below(&mut self, n: u64) -> u64 {
        if n == 0 {
            0
        } else {
            self.next_u64() % n
        }
    }
    pub fn byte(&mut self) -> u8 {
        self.next_u64() as u8
    }
    /// `true` with probability `p` in per cent.
    pub fn chance(&mut self, p: u64) -> bool {
        self.below(100) < p
    }
    pub fn pick<T: Copy>(&mut self, from: &[T]) -> Option<T> {
        from.get(self.below(from.len() as u64) as usize).copied()
    }
}

/// What the conformant device knows of itself, for requests that mostly pass its checks.
struct Known {
    address: u8,
    codes: [u8; 4],
    fields: Vec<u8>,
    range: u64,
}

fn known(s: &dut::Slave) -> Known {
    let nv = s.nonvolatile();
    Known {
        address: nv.address.byte(),
        codes: nv.codes,
        fields: nv.fields.statuses().to_vec(),
        range: s.profile().range(),
    }
}

/// A random request frame, mostly one the device accepts, sometimes not.
fn request(rng: &mut Rng, k: &Known, p: &Profile) -> Vec<u8> {
    let code = |rng: &mut Rng, n: usize| if rng.chance(80) { k.codes.get(n).copied().unwrap_or(0) } else { rng.byte() };
    let field = |rng: &mut Rng| {
        let n = k.fields.len() as u64;
        match rng.below(10) {
            0 => 0xFF,
            1 => rng.byte(),
            _ => rng.below(n + 2) as u8,
        }
    };
    let field_code = |rng: &mut Rng, f: u8| {
        let n = k.fields.get(f as usize).map_or(0, |s| ((s >> 4) & 0x03) as usize);
        code(rng, n)
    };
    let size = |f: u8| k.fields.get(f as usize).map_or(16u64, |s| 16u64 << (s & 0x07).min(3));
    let commands =
        hiperface_model::COMMAND_TABLE.iter().map(|c| c.id).filter(|id| p.commands.contains(*id)).collect::<Vec<_>>();
    let id = rng.pick(&commands).unwrap_or(hiperface_model::CommandId::ReadPosition);
    use hiperface_model::CommandId as C;
    let preset =
        |rng: &mut Rng| if rng.chance(90) { rng.below(k.range) as u32 } else { k.range.min(u32::MAX as u64) as u32 };
    let settings = |rng: &mut Rng| if rng.chance(70) { p.settings.byte() ^ (rng.byte() & 0x07) } else { rng.byte() };
    let r = match id {
        C::ReadPosition => Request::ReadPosition,
        C::SetPosition => Request::SetPosition { preset: preset(rng), code0: code(rng, 0) },
        C::ReadAnalogValue => {
            let chans: Vec<u8> = p.analog.iter().flatten().map(|c| c.selector).collect();
            Request::ReadAnalogValue {
                channel: if rng.chance(80) { rng.pick(&chans).unwrap_or(0) } else { rng.byte() },
            }
        }
        C::ReadCounter => Request::ReadCounter,
        C::IncrementCounter => Request::IncrementCounter,
        C::ResetCounter => Request::ResetCounter { code0: code(rng, 0) },
        C::ReadData => {
            let f = field(rng);
            let sz = size(f);
            let offset = rng.below(sz + 2) as u8;
            let count = if rng.chance(80) { (1 + rng.below(16)) as u8 } else { rng.byte() };
            Request::ReadData { field: f, offset, count, code: field_code(rng, f) }
        }
        C::StoreData => {
            let f = field(rng);
            let sz = size(f);
            let most = if rng.chance(80) { 8 } else { 128 };
            let n = 1 + rng.below(most) as usize;
            let data: Vec<u8> = (0..n).map(|_| rng.byte()).collect();
            let data = hiperface_model::frame::FieldBytes::from_bytes(&data).unwrap_or_default();
            Request::StoreData { field: f, offset: rng.below(sz + 1) as u8, code: field_code(rng, f), data }
        }
        C::DataFieldStatus => Request::DataFieldStatus { field: field(rng) },
        C::CreateDataField => {
            let f = field(rng);
            let status = if rng.chance(60) { 0xC0 | (rng.byte() & 0x3F) } else { rng.byte() };
            let n = ((status >> 4) & 0x03) as usize;
            let code = if rng.chance(50) { code(rng, n) } else { field_code(rng, f) };
            Request::CreateDataField { field: f, status, code }
        }
        C::MemoryStatus => Request::MemoryStatus,
        C::SetAccessCode => {
            let number = if rng.chance(90) { rng.below(4) as u8 } else { rng.byte() };
            let old = code(rng, number as usize);
            let new = if rng.chance(50) { old } else { rng.byte() };
            Request::SetAccessCode { number, old, new }
        }
        C::ReadEncoderStatus => Request::ReadEncoderStatus,
        C::ReadTypeLabel => Request::ReadTypeLabel,
        C::EncoderReset => Request::EncoderReset,
        C::SetEncoderAddress => {
            let address = if rng.chance(80) { 0x40 + rng.below(0x21) as u8 } else { rng.byte() };
            Request::SetEncoderAddress { address, code0: code(rng, 0) }
        }
        C::ReadVersion => Request::ReadVersion,
        C::SetSerialInterface => Request::SetSerialInterface { settings: settings(rng), code0: code(rng, 0) },
        C::SetPositionInternalSync => Request::SetPositionInternalSync { preset: preset(rng), code0: code(rng, 0) },
        C::TemporarilySetSerialInterface => Request::TemporarilySetSerialInterface { settings: settings(rng) },
        C::SetPositionWithSync => Request::SetPositionWithSync { preset: preset(rng), code0: code(rng, 0) },
        C::SensorAdjustment => {
            let opts: Vec<u8> = p.adjustment.iter().flatten().map(|o| o.option).collect();
            let known = rng.chance(70);
            let option = match rng.pick(&opts) {
                Some(o) if known => o,
                _ => rng.byte(),
            };
            Request::SensorAdjustment { option, code0: code(rng, 0) }
        }
        C::ReadSyncOffset => Request::ReadSyncOffset,
        _ => Request::ReadPosition,
    };
    let address = match rng.below(20) {
        0 => 0xFF,
        1 => k.address ^ (1 << rng.below(6)),
        _ => k.address,
    };
    let mut bytes = RequestFrame::new(AddressByte::decode(address), r).encode().as_bytes().to_vec();
    match rng.below(40) {
        0 => {
            if let Some(last) = bytes.last_mut() {
                *last ^= 1 << rng.below(8);
            }
        }
        1 => {
            bytes.pop();
        }
        2 => bytes.push(rng.byte()),
        3 => {
            if let Some(c) = bytes.get_mut(1) {
                *c = rng.byte();
            }
        }
        4 => bytes.truncate(rng.below(3) as usize),
        _ => {}
    }
    bytes
}

/// A witness: the stream's seed and the first step where the two differ.
#[derive(Debug, Clone)]
pub struct Witness {
    pub seed: u64,
    pub profile: String,
    pub world: String,
    /// The requests sent, in order, up to the difference (hex).
    pub requests: Vec<String>,
    pub conformant: String,
    pub mutant: String,
}

/// Run stream `seed` on mutant `id` and the conformant device; the witness if they differ.
pub fn stream(id: u32, seed: u64, frames: usize) -> Option<Witness> {
    let mut rng = Rng::new(seed);
    let (pname, make) = rng.pick(profiles::BUILTIN)?;
    let p = make();
    let worlds = configs::worlds(&p);
    let (wname, world) =
        if rng.chance(50) { ("default".to_string(), World::default()) } else { rng.pick_owned(&worlds)? };
    let dp = dut_profile(&p)?;
    let build = |sid: u32| {
        mutant::activate(sid);
        let s = guarded(|| build_slave(dp, &world)).ok();
        mutant::activate(0);
        s
    };
    let mut a = Side { slave: build(0), id: 0, log: Vec::new() };
    let mut b = Side { slave: build(id), id, log: Vec::new() };
    if b.slave.is_none() {
        b.log.push(Seen::Crashed("could not be built".into()));
    }
    let mut now = 0u64;
    let mut sent = Vec::new();
    for _ in 0..frames {
        let k = known(a.slave.as_ref()?);
        let bytes = request(&mut rng, &k, &p);
        sent.push(hiperface_model::Hex(&bytes).to_string());
        // The pause before: the timeout, a little more, or long (past a power-up window).
        let heard = a.slave.as_ref().map(|s| s.settings_heard_next(now))?;
        let sent_in = crate::device::from_dut_settings(heard);
        let ct = sent_in.char_time_us();
        let timeout = sent_in.timeout_us(p.edition);
        now += match rng.below(20) {
            0 => 300_000 + rng.below(1_500_000),
            1 => timeout.saturating_sub(rng.below(2 * ct)),
            _ => timeout + rng.below(5_000),
        };
        a.advance(now.saturating_sub(1), now);
        b.advance(now.saturating_sub(1), now);
        let fault_at = rng.chance(3).then(|| rng.below(bytes.len().max(1) as u64) as usize);
        let gap_at = rng.chance(3).then(|| (rng.below(bytes.len().max(1) as u64) as usize, rng.below(3 * timeout)));
        let mut t = now;
        for (i, byte) in bytes.iter().enumerate() {
            if let Some((at, gap)) = gap_at {
                if at == i {
                    t += gap;
                }
            }
            t += ct;
            for side in [&mut a, &mut b] {
                let listening = side.call(|s| s.listening_settings(t)).flatten().map(crate::device::from_dut_settings);
                let mut fault = listening.and_then(|l| hiperface_suite::line::virtual_line::arrives_with(sent_in, l));
                if fault_at == Some(i) && fault.is_none() {
                    fault = Some(hiperface_model::UartFault::Parity);
                }
                let c = dut::RxChar { byte: *byte, at_us: t, fault: fault.map(|_| dut::UartFault::Parity) };
                side.advance(t.saturating_sub(ct), t.saturating_sub(1));
                side.receive(c);
            }
        }
        now = t;
        // Long enough for any reply to be due and sent.
        let end = now + 3 * timeout + 200_000;
        a.advance(now, end);
        b.advance(now, end);
        a.listening(end);
        b.listening(end);
        now = end;
        if std::env::var_os("DIFF_TRACE").is_some() {
            eprintln!("{} -> {:?}", sent.last().map(String::as_str).unwrap_or(""), a.log.last());
        }
        if a.log != b.log {
            let first = a.log.iter().zip(&b.log).position(|(x, y)| x != y).unwrap_or(a.log.len().min(b.log.len()));
            let show = |l: &[Seen]| l.get(first).map_or("nothing".to_string(), |s| format!("{s:?}"));
            return Some(Witness {
                seed,
                profile: pname.to_string(),
                world: wname,
                requests: sent,
                conformant: show(&a.log),
                mutant: show(&b.log),
            });
        }
    }
    None
}

impl std::fmt::Display for Witness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "differs on stream {} ({}, world {}) after {} requests, the last [{}]: the conformant device {}, the mutant {}",
            self.seed,
            self.profile,
            self.world,
            self.requests.len(),
            self.requests.last().map(String::as_str).unwrap_or(""),
            self.conformant,
            self.mutant
        )
    }
}

impl Rng {
    fn pick_owned<T: Clone>(&mut self, from: &[T]) -> Option<T> {
        from.get(self.below(from.len() as u64) as usize).cloned()
    }
}

/// Run `streams` streams of `frames` requests each on mutant `id`; the first witness.
pub fn search(id: u32, streams: u64, frames: usize) -> Option<Witness> {
    (0..streams).find_map(|seed| stream(id, seed, frames))
}

/// The conformant device against itself: no stream may differ (a check of the method).
pub fn self_check(streams: u64, frames: usize) -> Option<Witness> {
    search(0, streams, frames)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_stream_runs_its_frames() {
        let w = super::stream(0, 1, 40);
        assert!(w.is_none());
    }
}
