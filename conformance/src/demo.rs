//! A demonstration of the model: a master session against the reference slave in
//! virtual time, through the sans-IO data link, with every frame timestamped.

use hiperface_model::datalink::RxChar;
use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{Hex, Profile, Reply, Slave, UartSettings};
use hiperface_suite::exchange::sealed;
use std::fmt::Write as _;

/// The master's side of one exchange as the demo prints it.
pub struct DemoExchange {
    pub title: &'static str,
    pub request: Vec<u8>,
    pub sent_at_us: u64,
    pub reply: Option<(u64, Vec<u8>)>,
    pub window_us: Option<(u64, u64)>,
    pub clause: &'static str,
}

/// Drive one request through the slave's data link: characters back to back, the
/// reply starting `reply_delay_us` into its window. Returns the exchange and the time
/// the line is idle again.
fn exchange(slave: &mut Slave, title: &'static str, request: Vec<u8>, at_us: u64) -> (DemoExchange, u64) {
    let settings = slave.listening_settings(at_us).unwrap_or(UartSettings::DEFAULT);
    let ct = settings.char_time_us();
    let mut step = None;
    for (i, b) in request.iter().enumerate() {
        step = step.or(slave.receive(RxChar::ok(*b, at_us + (i as u64 + 1) * ct)));
    }
    let last = at_us + request.len() as u64 * ct;
    let step = step.or_else(|| slave.poll(last + slave.timeout_us(last)));
    let reply_delay_us = 200;
    let mut idle = last + slave.timeout_us(last);
    let (reply, window, clause) = match step {
        Some(s) => {
            let window = s.transmission.map(|t| (t.earliest_start_us, t.latest_start_us));
            let reply = s.transmission.map(|t| {
                let start = t.earliest_start_us + reply_delay_us;
                idle = start
                    + t.frame.len() as u64 * t.settings.char_time_us()
                    + t.settings.timeout_us(slave.profile().edition);
                (start, t.frame.as_bytes().to_vec())
            });
            if let Reply::Silent(_) = s.outcome.reply {
                idle = s.received.complete_us;
            }
            (reply, window, s.outcome.clause.id())
        }
        None => (None, None, "000:T9"),
    };
    (DemoExchange { title, request, sent_at_us: at_us, reply, window_us: window, clause }, idle)
}

/// Run the demonstration session and return its transcript.
pub fn run(profile: Profile) -> String {
    let mut out = String::new();
    let mut slave = Slave::new(profile);
    slave.set_inputs(PhysicalInputs { position: 12_345, speed: 0, temperature_c: 37, led_current_ma: 10 });
    let p = *slave.profile();
    let _ = writeln!(
        out,
        "Reference slave: {} ({:?} edition), address {}, stored settings {}",
        p.name, p.edition, p.address, p.settings
    );
    let _ = writeln!(
        out,
        "Measuring range {} steps; {} user memory blocks; type code {:02X}h",
        p.range(),
        p.user_memory_blocks,
        p.type_code
    );
    let _ = writeln!(out, "Power-on at t = 0. State machine (000:T9):");
    for t in [0u64, p.init_ms as u64, p.default_window_ms as u64, p.user_settings_ms as u64] {
        let _ = writeln!(out, "  t = {:>5} ms  {}", t, slave.state(t * 1000).name());
    }
    let _ = writeln!(out);

    let a = p.address.byte();
    let script: Vec<(&'static str, Vec<u8>)> = vec![
        ("Read Type Label", sealed(&[a, 0x52])),
        ("Read Version", sealed(&[a, 0x56])),
        ("Read Encoder Status", sealed(&[a, 0x50])),
        ("Read Position", sealed(&[a, 0x42])),
        ("Memory Status", sealed(&[a, 0x4E])),
        ("Create Data Field 0 (32 bytes, Code0)", sealed(&[a, 0x4D, 0, 0xC9, 0x55])),
        ("Store Data", sealed(&[a, 0x4B, 0, 0, 4, 0x55, 0xCA, 0xFE, 0xBA, 0xBE])),
        ("Read Data", sealed(&[a, 0x4A, 0, 0, 6, 0x55])),
        ("Set Position 0", sealed(&[a, 0x43, 0, 0, 0, 0, 0x55])),
        ("Read Position", sealed(&[a, 0x42])),
        ("Bad checksum", vec![a, 0x42, 0x00]),
        ("Wrong access code", sealed(&[a, 0x49, 0x00])),
        ("Broadcast Read Position", sealed(&[0xFF, 0x42])),
        ("Another address (silence)", sealed(&[a ^ 0x01, 0x42])),
        ("Encoder Reset (no reply)", sealed(&[a, 0x53])),
        ("Read Position during initialization", sealed(&[a, 0x42])),
    ];
    let mut t = p.user_settings_ms as u64 * 1000 + 10_000;
    for (title, request) in script {
        let (x, idle) = exchange(&mut slave, title, request, t);
        let _ = writeln!(out, "{}  [{}]", x.title, x.clause);
        let _ = writeln!(out, "  {:>10.3} ms  M> {}", x.sent_at_us as f64 / 1000.0, Hex(&x.request));
        match (&x.reply, x.window_us) {
            (Some((start, bytes)), Some((from, to))) => {
                let _ = writeln!(
                    out,
                    "  {:>10.3} ms  S< {}   (window {:.3}..{:.3} ms)",
                    *start as f64 / 1000.0,
                    Hex(bytes),
                    from as f64 / 1000.0,
                    to as f64 / 1000.0
                );
            }
            _ => {
                let _ = writeln!(out, "                 (no reply; slave state: {})", slave.state(idle).name());
            }
        }
        t = idle + 1_000;
    }
    let _ = writeln!(out, "\nEEPROM writes: {}", slave.eeprom_writes());
    out
}
