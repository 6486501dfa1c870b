//! The encoder's hooks of the serving loop: every character the master sends to the
//! observer and the record, each frame counted and the plan's injections due on it
//! found, each reply acted on and its time told to the observer.

use super::{Disturbance, DriveEncoder, LoggedRequest, MAX_CHARACTERS};
use crate::line::reply_echo::ReplyEcho;
use crate::master::inputs;
use crate::master::scenario::{Injection, Situation};
use crate::serve::{Hooks, Planned};
use crate::verdict::WireEntry;
use hiperface_model::datalink::{RxChar, UartFault};
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::act::{Acted, ActedReply};
use hiperface_model::{CommandId, Frame, Hex, RequestFrame, Slave, Step, UartSettings};

impl Hooks for DriveEncoder {
    fn received(&mut self, ch: RxChar, listening: Option<UartSettings>) -> bool {
        // A flood is cut here: nothing more is kept (the run, its record and its
        // observations stay bounded) and the serving loop ends (`wants_stop`).
        if self.timeline.characters >= MAX_CHARACTERS {
            self.timeline.characters += 1;
            return true;
        }
        let listening_hex = inputs::settings_hex(listening);
        self.log.push(inputs::Input::Received { ch: ch.into(), listening: listening_hex });
        if listening != self.listening {
            if let Some(s) = listening {
                self.observer.encoder_listens(s);
            }
            self.listening = listening;
        }
        let char_us = listening.unwrap_or_default().char_time_us();
        self.timeline.slowest_char_us = self.timeline.slowest_char_us.max(char_us);
        let start_us = ch.at_us.saturating_sub(char_us);
        self.flush_heard(start_us);
        if self.heard.is_empty() {
            self.frame_begins(start_us);
        }
        self.heard.push(ch);
        if self.read_late_us > 0 {
            self.timeline.late_chars.push((ch.at_us, self.read_late_us));
        }
        self.timeline.characters += 1;
        if let Some(fault @ (UartFault::Parity | UartFault::Framing)) = ch.fault {
            self.timeline.uart_faults += 1;
            // The kernel marks both alike (listen::tap::Marks): "parity" may be either.
            let what = format!("{:02X} read with a {fault:?} error (a UART fault, 000:T47)", ch.byte);
            self.note(ch.at_us, WireEntry::INJECTED, what);
        }
        let seen = &mut self.timeline.observations;
        self.observer.master_char(ch, &mut |o| seen.push(o));
        !self.noise
    }

    fn wants_stop(&self) -> bool {
        self.timeline.characters >= MAX_CHARACTERS
    }

    fn reply_echo(&mut self) -> Option<&mut ReplyEcho> {
        self.port.as_mut().map(|p| &mut p.echo)
    }

    fn read(&mut self, unwatched_us: u64) {
        self.log.push(inputs::Input::Read { unwatched_us });
        self.read_late_us = unwatched_us;
    }

    fn idle(&mut self, now_us: u64) {
        self.log.push(inputs::Input::Idle { now_us });
        if self.heard.is_empty() {
            self.peer_bps = self.peer_bps();
        }
        let seen = &mut self.timeline.observations;
        self.observer.poll(now_us, &mut |o| seen.push(o));
        self.flush_heard(now_us);
    }

    fn frame(&mut self, slave: &mut Slave, step: &Step) {
        self.log.push(inputs::Input::Frame);
        self.due.clear();
        let bytes = step.received.bytes.as_bytes();
        let decoded = RequestFrame::decode(bytes).ok();
        self.answered = decoded.map(|r| r.request.command());
        let Some(request) = decoded else { return };
        let command = request.request.command();
        let at = step.received.last_us;
        // The settings its characters were received at (`received` keeps them).
        let char_us = self.listening.unwrap_or_default().char_time_us();
        let begin_us = step.received.first_us.saturating_sub(char_us);
        self.timeline.requests_log.push(LoggedRequest { begin_us, end_us: at, char_us, request });
        self.arises(Situation::Talked, at);
        if at >= self.profile.user_settings_ms as u64 * 1000 {
            self.arises(Situation::TalkedAfterWindows, at);
        }
        let n = {
            let count = self.timeline.requests.entry(command.byte()).or_default();
            *count += 1;
            *count
        };
        // The plan's injections due on this request (by its count, or by time); position
        // faults switch on at their request, before the reply.
        for (i, inj) in self.plan.iter().enumerate() {
            let done = self.fired.get(i).copied().unwrap_or(true);
            if !inj.due(command, n, at, done) {
                continue;
            }
            if let Some(f) = self.fired.get_mut(i) {
                *f = true;
            }
            self.due.push(i);
            if let Some(f) = inj.act.position_fault() {
                slave.inject_position_fault(f, true);
                self.injected(step.received.last_us, format!("injected: {}", inj.act));
            }
        }
    }

    fn reply(&mut self, slave: &mut Slave, step: &Step, mut planned: Planned) -> Option<Planned> {
        self.log.push(inputs::Input::Reply);
        // A master reads the reply as a UART would deliver it.
        planned.paced = true;
        // `frame` saw this frame first, and found which injections are due on it.
        let bytes = step.received.bytes.as_bytes();
        // What the model itself answers, before any injection: it knows its data fields.
        // The request is the one `frame` logged last (it logs each one it decodes).
        let asked =
            self.answered.and(self.timeline.requests_log.last()).map(|r| (r.request.request.command(), r.begin_us));
        let served = asked.and_then(|(c, at)| Some((c, at, ResponseFrame::decode(&planned.frame, c).ok()?)));
        if let Some((command, begin_us, frame)) = served {
            let seen = &mut self.timeline.observations;
            self.observer.served_reply(command, &frame, begin_us, &mut |o| seen.push(o));
        }
        let due: Vec<Injection> = self.due.iter().filter_map(|i| self.plan.get(*i).copied()).collect();
        for inj in due {
            if inj.act.position_fault().is_some() {
                continue;
            }
            let address = bytes.first().copied().unwrap_or(0x40);
            let Ok(frame) = Frame::from_bytes(&planned.frame) else { continue };
            let mut reply = ActedReply { frame, start_us: planned.start_us, gap: planned.gap };
            let acted = inj.act.apply(address, &mut reply);
            let what = format!("injected: {}", inj.act);
            match acted {
                Acted::Sent => {
                    planned.frame = reply.frame.as_bytes().to_vec();
                    planned.start_us = reply.start_us;
                    planned.gap = reply.gap;
                }
                Acted::Silent => {
                    self.injected(planned.start_us, what);
                    return None;
                }
                Acted::Restart => {
                    // The master cannot know: the observer is not told of this power-on.
                    slave.power_cycle(step.received.complete_us);
                    self.injected(step.received.complete_us, what);
                    return None;
                }
            }
            self.injected(planned.start_us, what);
        }
        // A request read late (the harness was not scheduled) is answered late by as
        // much: to the master the reply comes later than the encoder meant, and a
        // master that gave up and talks again meets it. As with an unplanned pause.
        let ct = planned.settings.char_time_us();
        let last = step.received.last_us;
        let first = last.saturating_sub(bytes.len().saturating_sub(1) as u64 * ct);
        let late = self.timeline.late_in(first, last);
        let limit_us = self.profile.response_limit(self.answered.unwrap_or(CommandId::Unknown(0))).max_ms as u64 * 1000;
        if crate::serve::REPLY_DELAY_US + late > limit_us {
            planned.answered_late_us = planned.answered_late_us.max(late);
        }
        Some(planned)
    }

    fn sent(&mut self, planned: &Planned, end_us: u64) {
        self.log.push(inputs::Input::Sent {
            frame: Hex(&planned.frame).to_string(),
            start_us: planned.start_us,
            end_us,
            gap: planned.gap,
            disturbed_us: planned.disturbed_us,
            split_by_harness: planned.split_by_harness,
        });
        let start_us = planned.start_us;
        self.note(start_us, WireEntry::REPLY, Hex(&planned.frame).to_string());
        if planned.disturbed_us > 0 || planned.answered_late_us > 0 {
            let d = Disturbance {
                at_us: start_us,
                pause_us: planned.disturbed_us,
                split: planned.split_by_harness,
                answered_late_us: planned.answered_late_us,
                delivered_late_us: 0,
            };
            self.timeline.disturbed.push(d);
            let what = if d.answered_late_us > 0 {
                format!(
                    "its request read {:.3} ms late, answered after the command's limit",
                    d.answered_late_us as f64 / 1000.0
                )
            } else {
                format!("an unplanned pause in it, or its writing held up, {:.3} ms", d.pause_us as f64 / 1000.0)
            };
            self.note(start_us, WireEntry::HARNESS, format!("the harness's own timing: {what}"));
        }
        // A reply with a pause of the timeout inside is two transmissions to the master
        // (000:2.2.2): the first ends at the pause, and what follows is unsolicited; a
        // master that talks after the pause is not at fault. A shorter pause does not end
        // the reply: a master that talks then talks over it.
        let timeout = planned.settings.timeout_us(self.profile.edition);
        if let Some((before, _)) = planned.gap.filter(|(_, us)| *us >= timeout) {
            let first_end = start_us + before as u64 * planned.settings.char_time_us();
            self.observer.encoder_reply(start_us, first_end, None);
            self.timeline.replies.push((start_us, first_end));
            return;
        }
        self.timeline.replies.push((start_us, end_us));
        // The observer grades the master against the reply it got.
        let reply = ResponseFrame::decode(&planned.frame, self.answered.unwrap_or(CommandId::Unknown(0))).ok();
        if let Some(r) = &reply {
            if r.warning {
                self.arises(Situation::WarningSent, start_us);
            }
            if let hiperface_model::response::Response::TypeLabel { type_code: 0xFF, .. } = r.response {
                self.arises(Situation::TypeFfSent, start_us);
            }
        }
        self.observer.encoder_reply(start_us, end_us, reply.as_ref());
    }

    fn real_time(&mut self, granted: bool) {
        self.log.push(inputs::Input::RealTime { granted });
        self.timeline.real_time = granted;
    }
}
