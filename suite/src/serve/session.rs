//! An encoder served on a line, without the line: the model and what the encoder does
//! besides it (its hooks), driven by whoever has the line. Hand it what was read and
//! when ([`Session::handle_read`], [`Session::receive`]), tell it the time
//! ([`Session::handle_timeout`]), ask it what to transmit ([`Session::poll_transmit`])
//! and when it next needs the time ([`Session::poll_timeout`]), tell it what was sent
//! ([`Session::on_sent`]). The order the hooks are called in is kept here once: a
//! serving loop in real time, one in virtual time and the replay of a record of the
//! hooks' inputs ([`crate::master::record`]) drive the same session.

use super::{planned_reply, Hooks, Planned};
use hiperface_model::datalink::RxChar;
use hiperface_model::{Slave, Step, UartSettings};
use std::collections::VecDeque;

/// The model served, with its hooks, between calls of the one who has the line.
pub struct Session<H> {
    slave: Slave,
    hooks: H,
    /// The model's steps (frames it took) not yet shown to the hooks, in order.
    steps: VecDeque<Step>,
    /// The step shown to the hooks last: what a reply answers.
    current: Option<Step>,
    /// The end of the last character of the last frame shown to the hooks, µs.
    framed_through_us: u64,
}

/// Why no reply can be planned now (a record that departs from what the model does).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum NoReply {
    #[error("a reply to no frame")]
    NoFrame,
    #[error("the model has no reply")]
    NoTransmission,
}

impl<H: Hooks> Session<H> {
    /// `slave` served with `hooks`; nothing read yet.
    pub fn new(slave: Slave, hooks: H) -> Session<H> {
        Session { slave, hooks, steps: VecDeque::new(), current: None, framed_through_us: 0 }
    }

    pub fn slave(&self) -> &Slave {
        &self.slave
    }

    pub fn hooks(&self) -> &H {
        &self.hooks
    }

    pub fn hooks_mut(&mut self) -> &mut H {
        &mut self.hooks
    }

    /// The hooks, the session over.
    pub fn into_hooks(self) -> H {
        self.hooks
    }

    /// The settings the model listens at, at `now_us` (`None` while it does not).
    pub fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        self.slave.listening_settings(now_us)
    }

    /// The end of the last character of the last frame the hooks were shown, µs: a
    /// character after it, read late, may belong to a frame still in progress.
    pub fn framed_through_us(&self) -> u64 {
        self.framed_through_us
    }

    /// When the model next needs the time, if it does (a frame in progress, a state
    /// to change), µs.
    pub fn poll_timeout(&self, now_us: u64) -> Option<u64> {
        self.slave.next_deadline(now_us)
    }

    /// Whether the serving thread got the real-time priority it asked for.
    pub fn real_time(&mut self, granted: bool) {
        self.hooks.real_time(granted);
    }

    /// The characters of one read follow; the line had not been watched for
    /// `unwatched_us` before it (0 when it was).
    pub fn handle_read(&mut self, unwatched_us: u64) {
        self.hooks.read(unwatched_us);
    }

    /// A character of the master, stamped at the end of its stop bit, received at
    /// `listening` (the settings the model listened at when it came).
    pub fn receive(&mut self, ch: RxChar, listening: Option<UartSettings>) {
        if self.hooks.received(ch, listening) {
            self.steps.extend(self.slave.receive(ch));
        }
    }

    /// The master's characters in the order they came: each received at the settings
    /// the model listens at when they were read (`read_us`), or where they were held
    /// (an echo's), when they were stamped.
    pub fn receive_all(&mut self, chars: impl IntoIterator<Item = RxChar>, read_us: Option<u64>) {
        for ch in chars {
            let listening = self.slave.listening_settings(read_us.unwrap_or(ch.at_us));
            self.receive(ch, listening);
        }
    }

    /// The time is `now_us`: the model polled, then the hooks told the time (one
    /// instant for both, so that a record of the hooks' inputs holds when the model
    /// was polled too).
    pub fn handle_timeout(&mut self, now_us: u64) {
        self.steps.extend(self.slave.poll(now_us));
        self.hooks.idle(now_us);
    }

    /// Show the hooks the model's next step; `false` when there is none.
    pub fn next_frame(&mut self) -> bool {
        let Some(step) = self.steps.pop_front() else { return false };
        self.framed_through_us = self.framed_through_us.max(step.received.last_us);
        self.hooks.frame(&mut self.slave, &step);
        self.current = Some(step);
        true
    }

    /// The reply to the step shown last, as the hooks plan it (`None`: withheld).
    pub fn plan_reply(&mut self) -> Result<Option<Planned>, NoReply> {
        let step = self.current.as_ref().ok_or(NoReply::NoFrame)?;
        let tx = step.transmission.as_ref().ok_or(NoReply::NoTransmission)?;
        Ok(self.hooks.reply(&mut self.slave, step, planned_reply(tx)))
    }

    /// The next reply to transmit, each step before it shown to the hooks; `None`
    /// when no step is left that is answered.
    pub fn poll_transmit(&mut self) -> Option<Planned> {
        while self.next_frame() {
            if let Ok(Some(planned)) = self.plan_reply() {
                return Some(planned);
            }
        }
        None
    }

    /// A reply went out as `sent` says (when it started, the pauses in it), its last
    /// character ending at `end_us`.
    pub fn on_sent(&mut self, sent: &Planned, end_us: u64) {
        self.hooks.sent(sent, end_us);
    }

    /// Whether the hooks have taken in all they will: serving then ends.
    pub fn wants_stop(&self) -> bool {
        self.hooks.wants_stop()
    }
}
