//! An encoder under test in-process, given frame by frame: a firmware's protocol code
//! linked into its own unit tests (from Rust, C or Python) answers each request the
//! character timeout delimits, with the reply and when its first character starts, or
//! silence. The framing is the model's data link (000:2.2.2): a request is whole once
//! the timeout after its last character has passed, as a slave's UART driver finds it.
//!
//! [`FramedEncoder`] puts such an encoder on the virtual line (it is a
//! [`SlaveDevice`]), so that the whole catalogue runs against it in virtual time
//! (`slave::in_process`).

use super::virtual_line::SlaveDevice;
use hiperface_model::datalink::{DataLink, ReceivedFrame, RxChar};
use hiperface_model::slave::powerup::{CommState, PowerUp};
use hiperface_model::{Edition, Frame, Profile, Transmission, UartSettings};

/// What an encoder under test does with a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Answer {
    /// The reply's characters, or `None`: silence.
    pub reply: Option<Frame>,
    /// When the reply's first character starts (the beginning of its start bit), µs.
    /// The line cannot start it before the request has ended: earlier is taken as the
    /// request's end (an encoder that does not wait for the timeout, 000:2.2.2).
    pub start_us: u64,
    /// The UART settings the encoder listens with from now on (after its reply, or
    /// at once when silent): 67h (000:T33), the default settings kept by a request in
    /// the default window (000:T9), or the stored settings again after an Encoder
    /// Reset (000:T29). `None`: unchanged.
    pub then_settings: Option<UartSettings>,
    /// The encoder restarts (Encoder Reset, 000:T29): from the answer's end its UART
    /// follows the power-up windows of its profile (000:T9): not listening during the
    /// initialization, the default settings in the default window, none while it
    /// changes them, and `then_settings` after (the stored ones; `None`: the
    /// profile's). An answer that names settings of its own ends the windows (the
    /// default settings kept by a request in the default window).
    pub restarts: bool,
}

impl Answer {
    /// Silence, settings unchanged.
    pub const SILENT: Answer = Answer { reply: None, start_us: 0, then_settings: None, restarts: false };

    /// `reply`, its first character starting at `start_us`.
    pub const fn reply(reply: Frame, start_us: u64) -> Answer {
        Answer { reply: Some(reply), start_us, then_settings: None, restarts: false }
    }

    /// Silence, and a restart: the power-up windows of 000:T9 from the request's end,
    /// then the settings `stored`.
    pub const fn restart(stored: UartSettings) -> Answer {
        Answer { then_settings: Some(stored), restarts: true, ..Answer::SILENT }
    }
}

/// An encoder under test, frame by frame.
pub trait FrameEncoder {
    /// The request `frame` as the character timeout delimited it: its characters (the
    /// first `MAX_FRAME`, with the count of all), the first UART fault among them
    /// (a character sent in other settings than the encoder listens with arrives with
    /// one, 000:T47), when its first and last characters were received (the end of
    /// their stop bits) and when it was known whole (`complete_us`, now), µs.
    fn answer(&mut self, frame: &ReceivedFrame) -> Answer;
}

impl<F: FnMut(&ReceivedFrame) -> Answer> FrameEncoder for F {
    fn answer(&mut self, frame: &ReceivedFrame) -> Answer {
        self(frame)
    }
}

/// A [`FrameEncoder`] as a [`SlaveDevice`] on the virtual line: it listens from the
/// start in the profile's stored UART settings (as the reference model does, already
/// past its power-up), frames by the timeout of the settings it listens with, and
/// changes them as its answers say.
pub struct FramedEncoder<E: FrameEncoder> {
    pub encoder: E,
    profile: Profile,
    link: DataLink,
    listening: UartSettings,
    /// Settings the encoder takes up at a time (after a reply still on the wire).
    next: Option<(UartSettings, u64)>,
    /// Since a restart: its power-up, whose windows (000:T9) say what the UART
    /// listens with, and the settings after them.
    powering: Option<(PowerUp, UartSettings)>,
}

impl<E: FrameEncoder> FramedEncoder<E> {
    pub fn new(encoder: E, profile: &Profile) -> FramedEncoder<E> {
        let listening = profile.settings;
        let link = DataLink::new(listening.timeout_us(profile.edition));
        FramedEncoder { encoder, profile: *profile, link, listening, next: None, powering: None }
    }

    /// The settings the encoder takes up by `now_us`, if a change is due.
    fn due(&self, now_us: u64) -> Option<UartSettings> {
        self.next.filter(|(_, at)| *at <= now_us).map(|(settings, _)| settings)
    }

    /// What the UART listens with at `now_us` (`None`: in a power-up window where it
    /// does not listen), and the settings that frame what it receives then: those of
    /// the window to come while it does not listen.
    fn settings_at(&self, now_us: u64) -> (Option<UartSettings>, UartSettings) {
        let Some((up, stored)) = self.powering else {
            let s = self.due(now_us).unwrap_or(self.listening);
            return (Some(s), s);
        };
        let framing = match up.state(&self.profile, now_us) {
            CommState::Initialization => UartSettings::DEFAULT,
            _ => stored,
        };
        let listening = up.settings(&self.profile, now_us, stored);
        (listening, listening.unwrap_or(framing))
    }

    /// Take up the settings due by `now_us`.
    fn settle(&mut self, now_us: u64) {
        if let Some(settings) = self.due(now_us) {
            self.listening = settings;
            self.next = None;
        }
        let (_, framing) = self.settings_at(now_us);
        self.link.set_timeout(framing.timeout_us(self.profile.edition));
    }

    fn answer(&mut self, frame: ReceivedFrame) -> Option<Transmission> {
        let answer = self.encoder.answer(&frame);
        let (_, settings) = self.settings_at(frame.last_us);
        let start = answer.start_us.max(frame.last_us);
        let reply_ends = |f: &Frame| start + f.len() as u64 * settings.char_time_us();
        let free_at = answer.reply.as_ref().map_or(frame.complete_us, reply_ends);
        if answer.restarts {
            let stored = answer.then_settings.unwrap_or(self.profile.settings);
            self.powering = Some((PowerUp::at(free_at), stored));
            self.next = None;
        } else if let Some(then) = answer.then_settings {
            // Settings of its own: the power-up windows no longer decide.
            if self.powering.take().is_some() {
                self.listening = settings;
            }
            self.next = Some((then, free_at));
        }
        let frame = answer.reply?;
        Some(Transmission {
            frame,
            earliest_start_us: start,
            latest_start_us: start,
            settings,
            then_settings: answer.then_settings,
        })
    }
}

impl<E: FrameEncoder> SlaveDevice for FramedEncoder<E> {
    fn receive(&mut self, ch: RxChar) -> Option<Transmission> {
        self.settle(ch.at_us);
        let frame = self.link.receive(ch)?;
        self.answer(frame)
    }

    fn poll(&mut self, now_us: u64) -> Option<Transmission> {
        self.settle(now_us);
        let frame = self.link.poll(now_us)?;
        self.answer(frame)
    }

    fn next_deadline(&self, _now_us: u64) -> Option<u64> {
        self.link.deadline()
    }

    fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        self.settings_at(now_us).0
    }

    /// The encoder says when its reply starts: nothing is added.
    fn reply_delay_us(&self) -> u64 {
        0
    }

    fn edition(&self) -> Edition {
        self.profile.edition
    }

    fn describe(&self) -> String {
        format!(
            "an encoder under test in-process, frame by frame, in virtual time ({:?} edition)",
            self.profile.edition
        )
    }
}
