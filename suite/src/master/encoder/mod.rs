//! The encoder a master is certified against: the model served (in real time by the
//! harness's serving loop, or taken in again from a record), with a scenario's fault injections, and the observer of
//! the master's obligations watching every character the master sends.
//!
//! Here the encoder ([`DriveEncoder`]) and what a run sets and reads of it; hooks.rs
//! its hooks of the serving loop (each character, frame and reply: observed,
//! injected, recorded); timeline.rs what happened on the line ([`Timeline`]) and what
//! of it the harness's or the machine's timing could explain; tests.rs the tests of
//! both.

use super::scenario::{Injection, Scenario, Situation};
use crate::line::reply_echo::ReplyEcho;
use crate::serve::Serving;
use crate::verdict::WireEntry;
use hiperface_model::datalink::RxChar;
use hiperface_model::master::obligations::Observer;
use hiperface_model::{CommandId, Hex, Profile, UartSettings};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

mod hooks;
mod timeline;

pub use timeline::{changes_only, Disturbance, LoggedRequest, Timeline};

/// The hooks: observe, inject, record.
pub struct DriveEncoder {
    observer: Observer,
    /// The application's polling period the observer was given, µs (000:3.2.2).
    polling_period_us: u64,
    plan: &'static [Injection],
    /// Which of the plan's injections have taken place (each takes place once).
    fired: Vec<bool>,
    /// The plan's injections due on the request now being answered.
    due: Vec<usize>,
    pub timeline: Timeline,
    profile: Profile,
    /// The command of the last frame, if it was a request: what a reply answers.
    answered: Option<CommandId>,
    /// The master's characters since the last pause of the timeout, for the timeline
    /// (the encoder may ignore them, e.g. while it initializes).
    heard: Vec<RxChar>,
    /// The master's end of a pseudo-terminal, whose settings are the master's own.
    peer: Option<Box<dyn MasterSettings>>,
    /// The master's data rate as last read while the line was quiet.
    peer_bps: Option<u32>,
    /// The frame being heard went out at another data rate than the encoder listens
    /// at, as far as the master's settings tell (`frame_begins`): noise to the encoder.
    noise: bool,
    /// What the encoder listened at when the last character came.
    listening: Option<UartSettings>,
    /// How long the line had gone unwatched before the read whose characters come.
    read_late_us: u64,
    /// What the scenario is about, and where the serving loop learns when it arose
    /// (µs, `u64::MAX` until then) to watch long enough after it.
    situation: Situation,
    arisen: Arc<AtomicU64>,
    /// A drive on a port: the port marks UART faults, and the echo of the replies is
    /// watched.
    port: Option<OnPort>,
    /// Everything taken in, in order, for the record of the wire (`master::record`).
    log: Vec<super::inputs::Input>,
    /// Taken in again from a record: the master's data rates as they were read.
    replayed_rates: Option<std::collections::VecDeque<Option<u32>>>,
    /// The commands the master declared it never sends (`--not-used`).
    not_used: Vec<CommandId>,
}

/// Where the master's own settings can be read while it runs: the master's end of a
/// pseudo-terminal, whose settings are the master's (the harness gives one).
pub trait MasterSettings: Send {
    /// The master's data rate now, bit/s, where it can be read.
    fn data_rate(&self) -> Option<u32>;
}

/// What the encoder knows of a drive's port.
#[derive(Debug, Clone)]
pub struct OnPort {
    pub echo: ReplyEcho,
}

/// More characters than any master needs in a scenario: a flood is cut here.
pub const MAX_CHARACTERS: usize = 20_000;

impl DriveEncoder {
    /// `scenario`: its plan of faults, and the situation it is about.
    /// `power_on_seen`: the scenario starts at the master's power-on of the encoder
    /// (t = 0); otherwise the rules about power-on are not graded.
    /// `peer`: the pseudo-terminal's end the master uses, whose settings (its data
    /// rate) the harness reads; `None` on a real port, where they cannot be read.
    pub fn new(
        profile: Profile,
        scenario: &Scenario,
        power_on_seen: bool,
        peer: Option<Box<dyn MasterSettings>>,
    ) -> DriveEncoder {
        let mut observer = Observer::new(profile);
        if power_on_seen {
            observer.power_on(0);
        }
        DriveEncoder {
            observer,
            polling_period_us: hiperface_model::master::obligations::POLLING_PERIOD_MS as u64 * 1000,
            plan: scenario.plan,
            fired: vec![false; scenario.plan.len()],
            due: Vec::new(),
            timeline: Timeline::default(),
            profile,
            answered: None,
            heard: Vec::new(),
            peer,
            peer_bps: None,
            noise: false,
            listening: None,
            read_late_us: 0,
            situation: scenario.situation,
            arisen: Arc::new(AtomicU64::new(u64::MAX)),
            port: None,
            log: Vec::new(),
            replayed_rates: None,
            not_used: Vec::new(),
        }
    }

    /// The master declared it never sends these commands: graded where it does.
    pub fn declared_not_used(mut self, not_used: &[CommandId]) -> DriveEncoder {
        self.not_used = not_used.to_vec();
        self
    }

    /// The commands the master declared it never sends.
    pub fn not_used(&self) -> &[CommandId] {
        &self.not_used
    }

    /// Taking a record in again: the master's data rate is read from `rates`, in
    /// order, as the run read it from the pseudo-terminal.
    pub fn replaying(mut self, rates: std::collections::VecDeque<Option<u32>>) -> DriveEncoder {
        self.replayed_rates = Some(rates);
        self
    }

    /// What the encoder took in, in order (the record of the wire).
    pub fn take_log(&mut self) -> Vec<super::inputs::Input> {
        std::mem::take(&mut self.log)
    }

    /// Served on a drive's port (`certify master --port`), opened marking UART faults.
    pub fn on_port(mut self, port: OnPort) -> DriveEncoder {
        self.port = Some(port);
        self
    }

    /// What the encoder learnt of the port (its echo), for the next scenario.
    pub fn port(&self) -> Option<&OnPort> {
        self.port.as_ref()
    }

    /// Where the time (µs) the scenario's situation arose is published for the
    /// serving loop (`u64::MAX` until then).
    pub fn arisen(&self) -> Arc<AtomicU64> {
        self.arisen.clone()
    }

    /// An injection of the plan took place at `at_us`: on the timeline, and the
    /// scenario's situation where that is an injection.
    fn injected(&mut self, at_us: u64, what: String) {
        self.arises(Situation::Injected, at_us);
        self.note(at_us, WireEntry::INJECTED, what);
    }

    /// `situation` arose at `at_us`: the first time counts.
    fn arises(&mut self, situation: Situation, at_us: u64) {
        if situation == self.situation && self.timeline.situation_us.is_none() {
            self.timeline.situation_us = Some(at_us);
            self.arisen.store(at_us, Ordering::Relaxed);
        }
    }

    /// The application's polling period (000:3.2.2).
    pub fn set_polling_period_ms(&mut self, ms: u32) {
        self.observer.set_polling_period_ms(ms);
        self.polling_period_us = ms as u64 * 1000;
    }

    /// The application's polling period, µs (000:3.2.2).
    pub fn polling_period_us(&self) -> u64 {
        self.polling_period_us
    }

    /// The master's data rate now, where the harness can read it (kept in the record).
    fn peer_bps(&mut self) -> Option<u32> {
        let bps = match self.replayed_rates.as_mut() {
            Some(rates) => rates.pop_front().flatten(),
            None => self.peer.as_ref().and_then(|p| p.data_rate()),
        };
        self.log.push(super::inputs::Input::PeerRate { bps });
        bps
    }

    /// Whether the master's data rate can be read (the master's end of a
    /// pseudo-terminal, or a record of it).
    fn reads_peer(&self) -> bool {
        self.peer.is_some() || self.replayed_rates.is_some()
    }

    /// A frame of the master begins at `start_us`: grade its data rate if the
    /// master's settings held still since the line was last quiet (otherwise the
    /// harness cannot tell which settings the characters were sent with), and hear it
    /// as noise where the master's settings as it sent are not the encoder's.
    fn frame_begins(&mut self, start_us: u64) {
        self.noise = false;
        let Some(listening) = self.listening.filter(|_| self.reads_peer()) else { return };
        let now = self.peer_bps();
        // On a real line a frame at another data rate reaches the encoder as framing
        // errors and bytes that are not the master's: no request, no reply. A
        // pseudo-terminal passes the bytes whatever the settings, so the encoder does
        // not hear them here. The settings as the frame's first character came are
        // taken for the frame's: a master sets its port before it writes (where they
        // changed since the line was quiet, the one before is the other candidate,
        // graded below only where both are wrong). // 000:3.3.1
        let encoder_bps = listening.baud.bits_per_second();
        if let Some(bps) = now.filter(|bps| *bps != encoder_bps) {
            self.noise = true;
            self.note(
                start_us,
                WireEntry::HARNESS,
                format!(
                    "heard as noise: the master's settings were {bps} Bd as this frame began, the encoder listens at \
                     {encoder_bps} Bd (a real line garbles such a frame; no reply)"
                ),
            );
        }
        match (self.peer_bps, now) {
            (Some(before), Some(now)) => {
                let seen = &mut self.timeline.observations;
                let count = seen.len();
                self.observer.master_data_rate_changing(start_us, before, now, &mut |o| seen.push(o));
                // Changed, and one of the two the encoder's: which one the frame went
                // out at is not known.
                if before != now && seen.len() == count {
                    self.note(
                        start_us,
                        WireEntry::HARNESS,
                        format!(
                            "data rate not graded: the master's settings changed from {before} to {now} Bd as it \
                             sent"
                        ),
                    );
                }
            }
            _ => self.note(
                start_us,
                WireEntry::HARNESS,
                "data rate not graded: the master's settings were not read both before and as it sent".into(),
            ),
        }
    }

    fn note(&mut self, t_us: u64, direction: &'static str, text: String) {
        self.timeline.entries.push(WireEntry { t_us, direction, bytes: text });
    }

    /// What the machine did to the run's timing, sampled (µs since power-on, µs
    /// waited in all): the master's process's wait for a processor, the kernel's
    /// workers', which deliver the line's characters on a pseudo-terminal, and the
    /// processors' pauses (`Timeline::host_paused`). A reply
    /// written while the workers waited a character time or more is a disturbance of
    /// the harness's own line (`Timeline::disturbed_by_kernel`), noted on the wire.
    pub fn waited(&mut self, master: Vec<(u64, u64)>, kernel: Vec<(u64, u64)>, paused: Vec<(u64, u64)>) {
        self.timeline.master_waited = master;
        self.timeline.kernel_waited = kernel;
        self.timeline.host_paused = paused;
        for (at_us, us) in self.timeline.disturbed_by_kernel() {
            let what = format!(
                "the harness's own line: the kernel's workers, which deliver this reply to the master, waited up to \
                 {:.3} ms for a processor while it was written (a busy machine)",
                us as f64 / 1000.0
            );
            self.note(at_us, WireEntry::HARNESS, what);
        }
    }

    /// Flush the observer and the timeline at the end of the scenario.
    pub fn finish(&mut self, now_us: u64) {
        self.timeline.end_us = now_us;
        if let Some(p) = self.port.as_mut() {
            // An echo still on its way is the next scenario's to take off the line.
            self.timeline.line_faults.extend(p.echo.take_faults());
        }
        let seen = &mut self.timeline.observations;
        self.observer.end(now_us, &mut |o| seen.push(o));
        self.flush_heard(u64::MAX);
    }

    /// The master's characters heard so far make one frame once the timeout has
    /// passed after the last of them (or `now_us` is `u64::MAX`).
    fn flush_heard(&mut self, now_us: u64) {
        let timeout = self.listening.unwrap_or_default().timeout_us(self.profile.edition);
        let Some(last) = self.heard.last() else { return };
        if now_us != u64::MAX && now_us < last.at_us + timeout {
            return;
        }
        let bytes: Vec<u8> = self.heard.iter().map(|c| c.byte).collect();
        let t = last.at_us;
        self.heard.clear();
        self.note(t, WireEntry::REQUEST, Hex(&bytes).to_string());
    }

    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// How the encoder is served: the port set only where its settings are not the
    /// master's; characters as read (a pause in a request is graded, and what a late
    /// read could hide is marked unproven, `Timeline::unproven`, not closed up); UART
    /// faults marked on a drive's port; the line watched every 500 µs, also when
    /// nothing is due, since when a request begins is graded (pauses, windows,
    /// initialization).
    pub fn serving(&self) -> Serving {
        Serving {
            sets_port: !self.reads_peer(),
            follows_line_settings: false,
            stamps_as_early_as_unwatched: false,
            marks_errors: self.port.is_some(),
            idle_read_us: crate::serve::READ_US,
        }
    }
}

#[cfg(test)]
mod tests;
