//! An encoder served on a line: what the serving loop does besides the model, as
//! hooks (see each character the master sends, change or withhold a reply, learn what
//! was sent), the reply it plans, and the session ([`Session`]) that calls the hooks in
//! their order for whoever has the line (in real time on a port or pseudo-terminal:
//! `hiperface-conformance`'s `simulate::serve_with`). The master certification's
//! encoder ([`crate::master::encoder::DriveEncoder`]) is these hooks, and its record
//! ([`crate::master::record`]) is the calls into them, taken in again without any line.

mod receiving;
mod sending;
mod session;

pub use receiving::Receiving;
pub use sending::{Next, Sending};
pub use session::{NoReply, Session};

use hiperface_model::datalink::RxChar;
use hiperface_model::{Slave, Step, UartSettings};

/// How long after the earliest allowed start the simulator begins a reply.
pub const REPLY_DELAY_US: u64 = 300;

/// While anything is due, reads return at least every 500 µs.
pub const READ_US: u64 = 500;

/// How an encoder is served on a line, beside what it does: what the one who has the
/// line does with its port for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Serving {
    /// Whether the port follows the slave's listening settings. Not where the port's
    /// settings are the peer's: on a pseudo-terminal, setting one end sets the other
    /// (Linux), and the master under test owns them.
    pub sets_port: bool,
    /// Whether the port's own data rate is the line's, set by whoever serves the other
    /// end (a serial device server that takes settings through RFC 2217, writing them
    /// to the pseudo-terminal): a character heard at another rate than the slave
    /// listens at arrives with a framing error, and a reply sent at another rate than
    /// the line's is not heard (a UART at the wrong rate finds no characters).
    pub follows_line_settings: bool,
    /// Whether the characters of a read that came `unwatched_us` late are stamped as
    /// early as that allows (never before the one before them ended), not when read. A
    /// device's UART stamps a character when it arrives: a simulator that was not
    /// scheduled must not see a pause that was its own and split a request the master
    /// sent whole (seen: `certify slave` through a line emulator to the simulator on a
    /// busy machine, 0Ch to a valid request). Not for the encoder that grades a master
    /// (it says so): it grades pauses, and marks what a late read could hide as
    /// unproven instead.
    pub stamps_as_early_as_unwatched: bool,
    /// Whether the port marks UART faults in what it delivers (`PARMRK`: see the
    /// harness's marking port): a master's character with a parity or framing error
    /// reaches the model as one.
    pub marks_errors: bool,
    /// How long one read may wait while the model has nothing due (no frame in
    /// progress, no state change), µs: 50 ms for the model as it is, so that an idle
    /// simulator sleeps. The first character after such a stretch is stamped when the
    /// thread wakes; a harness that grades when requests begin watches closer.
    pub idle_read_us: u64,
}

impl Serving {
    /// The model as a simulator serves it on its own port.
    pub const MODEL: Serving = Serving {
        sets_port: true,
        follows_line_settings: false,
        stamps_as_early_as_unwatched: true,
        marks_errors: false,
        idle_read_us: 50_000,
    };
}

/// What an encoder served on a line does besides the model: see each character the
/// master sends, change or withhold a reply (fault injection), learn what was sent.
/// The session ([`Session`]) calls them in their order; the default hooks serve the
/// model as it is.
pub trait Hooks {
    /// A character from the master, stamped at the end of its stop bit, and the
    /// settings the slave listens at then (`None` while it does not listen); whether
    /// the slave hears it (`false`: it went out at a data rate the slave does not
    /// listen at, which a real line garbles into noise that no slave answers).
    fn received(&mut self, _ch: RxChar, _listening: Option<UartSettings>) -> bool {
        true
    }
    /// The characters of one read follow (`received` for each): the line had not been
    /// read for `unwatched_us` before it (0 when it was watched; the harness was busy
    /// writing a reply, or not scheduled). They may have come any time in that
    /// stretch; they are stamped when read.
    fn read(&mut self, _unwatched_us: u64) {}
    /// Time passes with nothing received; the model was polled at `now_us` just before.
    fn idle(&mut self, _now_us: u64) {}
    /// The model processed a frame (whether it replies or not).
    fn frame(&mut self, _slave: &mut Slave, _step: &Step) {}
    /// The model's reply to a frame: what to send instead, if anything.
    fn reply(&mut self, _slave: &mut Slave, _step: &Step, planned: Planned) -> Option<Planned> {
        Some(planned)
    }
    /// A run of a reply's characters is about to be written, `late_us` after it was
    /// due (a busy machine woke the serving thread late; 0 when on time).
    fn writing(&mut self, _late_us: u64) {}
    /// A reply went out as planned, its last character ending at `end_us`.
    fn sent(&mut self, _planned: &Planned, _end_us: u64) {}
    /// The echo of the replies, where the line may echo (a drive on a port): what it
    /// takes off the line never reaches the model or [`Hooks::received`].
    fn reply_echo(&mut self) -> Option<&mut crate::line::reply_echo::ReplyEcho> {
        None
    }
    /// Whether the hooks have taken in all they will (a master that floods the line):
    /// the serving loop then ends, so that nothing grows without bound.
    fn wants_stop(&self) -> bool {
        false
    }
    /// Whether the serving thread got the real-time priority it asked for.
    fn real_time(&mut self, _granted: bool) {}
}

/// A reply as it will go on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Planned {
    pub frame: Vec<u8>,
    /// When its first start bit begins, µs since power-on.
    pub start_us: u64,
    pub settings: hiperface_model::UartSettings,
    /// A pause inserted before the character of this index, µs.
    pub gap: Option<(usize, u64)>,
    /// Write each character when it is complete, as a UART delivers them, instead of
    /// a run at once: a peer that reads a pseudo-terminal then sees the reply end
    /// when it really ends.
    pub paced: bool,
    /// Set when sent: the longest pause inside the reply that was not planned (the
    /// harness wrote a character late), or the longest the harness was held in a write
    /// of it (its characters may have reached the line that much later than stamped),
    /// µs; 0 when none reached [`disturbed_from_us`].
    pub disturbed_us: u64,
    /// Set when sent: the harness wrote a character so late that the reply has a pause
    /// of the timeout inside, which it did not plan (`gap` then holds that pause).
    pub split_by_harness: bool,
    /// Set by the hooks: the request was read so late that the reply, answered late by
    /// as much, started after the command's maximum response time (000:T10), µs late.
    pub answered_late_us: u64,
}

/// An unplanned pause inside a paced reply this long or longer is one a receiver can
/// see: one character time at the reply's data rate (a UART's receive-idle interrupt
/// fires after a character time of idle line or more; a shorter pause is invisible to
/// any receiver). Below the timeout (000:2.2.2) it does not end the reply: a master
/// that talks after it talks over the reply, which 000 forbids, so such a pause decides
/// a run only where the master broke a rule after it (`master::grade`).
pub const fn disturbed_from_us(char_time_us: u64) -> u64 {
    char_time_us
}

/// The model's reply as the serving loop plans it before the hooks see it: at the
/// earliest start plus [`REPLY_DELAY_US`].
pub fn planned_reply(tx: &hiperface_model::slave::Transmission) -> Planned {
    Planned {
        frame: tx.frame.as_bytes().to_vec(),
        start_us: tx.earliest_start_us + REPLY_DELAY_US,
        settings: tx.settings,
        gap: None,
        paced: false,
        disturbed_us: 0,
        split_by_harness: false,
        answered_late_us: 0,
    }
}

/// The model as it is.
pub struct Plain;
impl Hooks for Plain {}
