//! Fuzz target bodies, shared by the cargo-fuzz targets (`fuzz/`) and the corpus
//! replay under a stable `cargo test`. Each panics on a violated invariant.

use arbitrary::Arbitrary;
use hiperface_model::datalink::{DataLink, RxChar, UartFault};
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::{checksum, profiles, CommandId, Reply, RequestFrame, ResponseFrame, Slave};

/// Request decoding: no panic; whatever decodes re-encodes to the same bytes.
pub fn request(data: &[u8]) {
    if let Ok(r) = RequestFrame::decode(data) {
        assert_eq!(r.encode().as_bytes(), data);
    }
}

/// Response decoding (the first byte names the request's command): no panic;
/// whatever decodes re-encodes to the same bytes.
pub fn response(data: &[u8]) {
    if let Some((to, bytes)) = data.split_first() {
        if let Ok(r) = ResponseFrame::decode(bytes, CommandId::decode(*to & 0x7F)) {
            assert_eq!(r.encode().as_bytes(), bytes);
        }
    }
}

/// Both decoders.
pub fn decode(data: &[u8]) {
    request(data);
    response(data);
}

#[derive(Debug, Arbitrary)]
pub struct TimedChar {
    pub byte: u8,
    /// Gap to the previous character, µs.
    pub gap_us: u16,
    pub fault: Option<u8>,
}

fn fault(f: Option<u8>) -> Option<UartFault> {
    f.map(|f| [UartFault::Parity, UartFault::Framing, UartFault::Noise, UartFault::Overrun][(f % 4) as usize])
}

/// The data link frames any character sequence without panicking, never merges
/// characters at least a timeout apart, and loses none.
pub fn datalink(timeout_us: u16, chars: &[TimedChar]) {
    datalink_of(timeout_us, chars.iter().map(|c| (c.byte, c.gap_us, c.fault)));
}

/// [`datalink`] on (byte, gap in µs, fault) triples, from whatever holds them: the
/// fuzz input, or the property's pairs, without collecting them (no allocation, so
/// that Kani checks the same function).
pub fn datalink_of(timeout_us: u16, chars: impl ExactSizeIterator<Item = (u8, u16, Option<u8>)>) {
    let timeout = timeout_us.max(1) as u64;
    let mut link = DataLink::new(timeout);
    // Checked as the frames come, with nothing kept but counts: every character in
    // exactly one frame, frames apart by at least the timeout, and as many frames as
    // gaps of the timeout + 1.
    let mut seen = Frames { timeout, chars: 0, count: 0, last_us: None };
    let (mut t, mut prev, mut splits) = (0u64, None::<u64>, 0usize);
    let len = chars.len();
    for (byte, gap_us, f) in chars {
        t += gap_us as u64;
        if prev.is_some_and(|p| t - p >= timeout) {
            splits += 1;
        }
        prev = Some(t);
        if let Some(frame) = link.receive(RxChar { byte, at_us: t, fault: fault(f) }) {
            seen.add(&frame);
        }
    }
    if let Some(frame) = link.poll(u64::MAX) {
        seen.add(&frame);
    }
    assert_eq!(seen.chars, len, "characters lost or duplicated");
    assert_eq!(seen.count, if len == 0 { 0 } else { splits + 1 });
}

/// What [`datalink`] has seen of the frames so far.
struct Frames {
    timeout: u64,
    chars: usize,
    count: usize,
    last_us: Option<u64>,
}

impl Frames {
    fn add(&mut self, f: &hiperface_model::datalink::ReceivedFrame) {
        if let Some(last) = self.last_us {
            assert!(f.first_us - last >= self.timeout, "frames split by less than the timeout");
        }
        self.chars += f.char_count;
        self.count += 1;
        self.last_us = Some(f.last_us);
    }
}

#[derive(Debug, Arbitrary)]
pub enum Event {
    Char(TimedChar),
    /// A whole frame (checksum appended), to reach deep states quickly.
    Frame {
        body: Vec<u8>,
        gap_ms: u8,
    },
    Inputs {
        position: u32,
        speed: i16,
        temperature_c: i8,
        led_current_ma: u8,
    },
    PositionFault(u8, bool),
    InitFault(u8, bool),
    PowerCycle,
    Wait {
        ms: u16,
    },
}

#[derive(Debug, Arbitrary)]
pub struct SlaveInput {
    pub profile: u8,
    pub events: Vec<Event>,
}

/// The slave driven by timed characters, frames and physical inputs: no panic, and
/// the invariants hold after every step.
pub fn slave(input: &SlaveInput) {
    let builtin = profiles::BUILTIN;
    let (_, make) = builtin[input.profile as usize % builtin.len()];
    let mut s = Slave::new(make());
    let mut t = 0u64;
    for e in input.events.iter().take(256) {
        let step = match e {
            Event::Char(c) => {
                t += c.gap_us as u64;
                s.receive(RxChar { byte: c.byte, at_us: t, fault: fault(c.fault) })
            }
            Event::Frame { body, gap_ms } => {
                t += *gap_ms as u64 * 1000;
                let mut f = body.iter().copied().take(140).collect::<Vec<_>>();
                f.push(checksum::xor(&f));
                let mut last = None;
                for b in f {
                    t += 1146;
                    last = last.or(s.receive(RxChar::ok(b, t)));
                }
                last
            }
            Event::Inputs { position, speed, temperature_c, led_current_ma } => {
                s.set_inputs(PhysicalInputs {
                    position: *position as u64,
                    speed: *speed as i32,
                    temperature_c: *temperature_c as i16,
                    led_current_ma: *led_current_ma as u16,
                });
                None
            }
            Event::PositionFault(f, on) => {
                s.inject_position_fault(PositionFault::ALL[*f as usize % PositionFault::ALL.len()], *on);
                None
            }
            Event::InitFault(f, on) => {
                s.inject_init_fault(InitFault::ALL[*f as usize % InitFault::ALL.len()], *on);
                None
            }
            Event::PowerCycle => {
                s.power_cycle(t);
                None
            }
            Event::Wait { ms } => {
                t += *ms as u64 * 1000;
                s.poll(t)
            }
        };
        if let Some(step) = step {
            if let Some(tx) = step.transmission {
                assert!(checksum::is_valid(tx.frame.as_bytes()), "reply with a bad checksum");
                assert!(tx.earliest_start_us <= tx.latest_start_us);
            }
            if let Reply::Frame(f) = step.outcome.reply {
                // 000:2.3.4: the warning bit is set exactly when the stack is not empty.
                assert_eq!(f.warning, !s.error_stack().is_empty(), "warning bit and stack disagree");
            }
        }
        invariants(&s);
    }
}

/// No code twice on the stack (000:T27). Every pair of slots visited, no early exit:
/// a loop Kani bounds whatever it knows of the stack.
pub fn holds_each_code_once(stack: &hiperface_model::slave::stack::ErrorStack) -> bool {
    use hiperface_model::slave::stack::STACK_DEPTH;
    let mut repeated = false;
    for i in 0..STACK_DEPTH {
        for j in i + 1..STACK_DEPTH {
            repeated |= stack.slot(i).is_some() && stack.slot(i) == stack.slot(j);
        }
    }
    !repeated
}

/// Invariants of every reachable state: [`crate::invariant::slave_invariant`], whose
/// violation panics here (a fuzz target reports a panic).
pub fn invariants(s: &Slave) {
    if let Err(v) = crate::invariant::slave_invariant(s) {
        panic!("invariant violated: {v}");
    }
}

/// What the observer of a master is told: a master's character, a reply of the
/// encoder (decodable or not), power-on, or time passing.
#[derive(Debug, Arbitrary)]
pub enum MasterEvent {
    Char {
        byte: u8,
        gap_us: u16,
    },
    Reply {
        code: u8,
        warning: bool,
        readable: bool,
        gap_us: u16,
        len: u8,
    },
    PowerOn {
        gap_ms: u8,
    },
    Idle {
        gap_ms: u8,
    },
    /// The encoder listens at the settings of this byte (000:T28), if it is one.
    Listens {
        settings: u8,
    },
    /// A master frame begins at this data rate.
    DataRate {
        bps: u32,
    },
}

/// The master's observer on any events: no panic, time never goes backwards in what it
/// reports, and no more observations than a few per event.
pub fn observer(events: &[MasterEvent]) {
    use hiperface_model::master::obligations::Observer;
    use hiperface_model::response::Response;
    let mut o = Observer::new(profiles::srs50());
    let mut t = 0u64;
    let mut count = 0usize;
    let mut last_at = 0u64;
    let mut sink = |obs: hiperface_model::master::obligations::Observation| {
        count += 1;
        last_at = last_at.max(obs.at_us);
    };
    for e in events.iter().take(512) {
        match *e {
            MasterEvent::Char { byte, gap_us } => {
                t += gap_us as u64;
                o.master_char(RxChar::ok(byte, t), &mut sink);
            }
            MasterEvent::Reply { code, warning, readable, gap_us, len } => {
                t += gap_us as u64;
                let rf = ResponseFrame {
                    address: 0x40,
                    warning,
                    response: Response::Error(hiperface_model::FaultCode::decode(code)),
                };
                let end = t + len as u64 * 1146;
                o.encoder_reply(t, end, readable.then_some(&rf));
                t = end;
            }
            MasterEvent::PowerOn { gap_ms } => {
                t += gap_ms as u64 * 1000;
                o.power_on(t);
            }
            MasterEvent::Idle { gap_ms } => {
                t += gap_ms as u64 * 1000;
                o.poll(t, &mut sink);
            }
            MasterEvent::Listens { settings } => {
                if let Ok(s) = hiperface_model::UartSettings::decode(settings) {
                    o.encoder_listens(s);
                }
            }
            MasterEvent::DataRate { bps } => o.master_data_rate(t, bps, &mut sink),
        }
    }
    assert!(count <= 4 * events.len().min(512) + 4, "{count} observations");
    assert!(last_at <= t + 1, "an observation in the future: {last_at} > {t}");
}
