//! The reference master on a line: the model's state machine
//! (`hiperface_model::master::reference`: the start-up flow of 000:3.3.1, cyclic Read
//! Position, the warning's codes read out, the fault reaction of Table 74) run over a
//! [`BusMaster`], its events printed for the operator. It is what `certify master` is
//! checked against (every scenario PASS, no NON-STRICT), and a bench tool: on a real
//! encoder it prints the identity and the position. The decisions are the model's;
//! this driver only does what they say on the line.

use hiperface_model::master::reference::{Action, Done, Event, ReferenceMaster};
use hiperface_model::Profile;
use hiperface_suite::exchange::BusMaster;
use hiperface_suite::line::{Line, LineError};

use hiperface_model::master::reference::Options;

/// What the master did, for the operator.
pub trait Console {
    fn line(&mut self, text: &str);
}

impl<F: FnMut(&str)> Console for F {
    fn line(&mut self, text: &str) {
        self(text)
    }
}

/// Run the reference master on `master`'s line (opened at power-on of the encoder).
pub fn run<L: Line>(
    master: &mut BusMaster<L>,
    profile: Profile,
    options: Options,
    console: &mut dyn Console,
) -> Result<(), LineError> {
    let mut machine = ReferenceMaster::new(profile, options);
    let mut say = |e: Event| console.line(&text(&e));
    let mut action = machine.power_on();
    loop {
        action = match action {
            Action::Stop => return Ok(()),
            Action::WaitUntil(t_us) => {
                master.line.wait_until(t_us)?;
                machine.next(Done::Waited { now_us: master.now_us() }, &mut say)
            }
            Action::Exchange { request, listen_ms } => {
                let x = master.exchange(request.encode().as_bytes(), listen_ms)?;
                let reply = x.reply_bytes().unwrap_or_default();
                let done = Done::Exchanged {
                    now_us: master.now_us(),
                    request_end_us: x.request_end.latest_us,
                    timeout_us: x.timeout_us,
                    reply: &reply,
                };
                machine.next(done, &mut say)
            }
        };
    }
}

/// What the operator reads of an event.
pub fn text(event: &Event) -> String {
    match event {
        Event::TypeLabel { type_code } => format!("type label: type {type_code:02X}h"),
        Event::ExtendedTypeLabel { bytes, checksum_ok } => {
            format!("extended type label: {bytes} bytes, checksum {}", if *checksum_ok { "ok" } else { "wrong" })
        }
        Event::Version(v) => {
            let text = |b: &[u8]| String::from_utf8_lossy(b).trim_end_matches(['\0', ' ']).to_string();
            let (serial, firmware, date) = (text(&v.serial), text(&v.firmware), text(&v.date));
            format!("serial {serial}, firmware {firmware}, date {date}")
        }
        Event::Status(code) => format!("status: {code}"),
        Event::Position(p) => format!("position {p}"),
        Event::PositionError(code) => format!("Read Position: {code}"),
        Event::PositionNoValidReply => "Read Position: no valid reply".into(),
        Event::SyncFault => "multiturn sync fault: position reads stopped (sin/cos only)".into(),
        Event::UnknownCode(code) => format!("unknown fault code {code}: worst-case reaction"),
        Event::ResetsExhausted => "the fault persists after SW resets: position reads stopped".into(),
        Event::Reset(_) => "SW reset (53h)".into(),
    }
}
