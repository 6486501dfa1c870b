//! A planned reply on its way out, without the line: which run of characters to write
//! when, and what the writing made of the reply. The one who has the line asks
//! [`Sending::poll`], waits until the time it names, writes, and says when it wrote
//! ([`Sending::written`]); a run written late shifts the rest of the reply, and a pause
//! it leaves inside the reply is noted in the reply as sent ([`Planned::disturbed_us`],
//! [`Planned::split_by_harness`]). In virtual time every run is written when due. The
//! real-time serving loop and the in-process line send replies through it alike.

use super::{disturbed_from_us, Planned};
use std::collections::VecDeque;
use std::ops::Range;

/// What to do next for a reply on its way out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Next {
    /// Write the characters `run` of the frame when the first of them would be
    /// complete (`due_us`: a UART hands a character on at the end of its stop bit),
    /// then call [`Sending::written`].
    Write { due_us: u64, run: Range<usize> },
    /// Keep the line until `until_us` (the characters written are on the wire until
    /// then; a planned pause follows).
    Wait { until_us: u64 },
    /// The reply is out: its last character ended at `end_us`; [`Sending::sent`] is
    /// the reply as it went.
    Done { end_us: u64 },
}

#[derive(Debug, Clone)]
enum Op {
    /// Write these characters.
    Write(Range<usize>),
    /// A part of the reply ends: the line is busy until its last character is out,
    /// then this planned pause follows.
    PartEnd(u64),
    /// An empty part: only its pause.
    Pause(u64),
}

/// A planned reply being sent.
#[derive(Debug, Clone)]
pub struct Sending {
    planned: Planned,
    ops: VecDeque<Op>,
    /// A character time at the reply's settings, µs.
    char_time_us: u64,
    /// The timeout at the reply's settings (000:2.2.2): a pause this long ends a reply.
    timeout_us: u64,
    /// When the next run's first character begins, µs.
    start_us: u64,
    /// Nothing written yet.
    first: bool,
    /// The index of the next character to write.
    index: usize,
}

impl Sending {
    /// `planned` to be sent; `timeout_us`: the timeout at its settings for the slave's
    /// edition.
    pub fn new(planned: Planned, timeout_us: u64) -> Sending {
        let len = planned.frame.len();
        let split = planned.gap.map_or(len, |(i, _)| i.min(len));
        let pause = planned.gap.map_or(0, |(_, g)| g);
        let mut ops = VecDeque::new();
        for (part, pause) in [(0..split, pause), (split..len, 0)] {
            if part.is_empty() {
                ops.push_back(Op::Pause(pause));
                continue;
            }
            if planned.paced {
                ops.extend(part.map(|i| Op::Write(i..i + 1)));
            } else {
                ops.push_back(Op::Write(part));
            }
            ops.push_back(Op::PartEnd(pause));
        }
        Sending {
            char_time_us: planned.settings.char_time_us(),
            timeout_us,
            start_us: planned.start_us,
            first: true,
            index: 0,
            ops,
            planned,
        }
    }

    /// The frame's bytes.
    pub fn frame(&self) -> &[u8] {
        &self.planned.frame
    }

    /// What to do next.
    pub fn poll(&mut self) -> Next {
        loop {
            match self.ops.front().cloned() {
                Some(Op::Write(run)) => return Next::Write { due_us: self.start_us + self.char_time_us, run },
                Some(Op::PartEnd(pause)) => {
                    self.ops.pop_front();
                    let until_us = self.start_us;
                    self.start_us += pause;
                    return Next::Wait { until_us };
                }
                Some(Op::Pause(pause)) => {
                    self.ops.pop_front();
                    self.start_us += pause;
                }
                None => return Next::Done { end_us: self.start_us },
            }
        }
    }

    /// The run [`Next::Write`] named was written (whole) in a write that began at
    /// `began_us` and returned at `now_us`: its characters began a character time each
    /// before they reached the line, and not before they were due to.
    ///
    /// They reached it somewhere in the write. Stamped from its beginning, the
    /// earliest: a master is graded against a reply that may have come that early
    /// (its next request after the reply's end, never over it), and the harness held in
    /// its write (a busy machine) is not charged to the master. Judged late from its
    /// return, the latest: a pause the writing may have left in the reply is noted.
    pub fn written(&mut self, began_us: u64, now_us: u64) {
        let Some(Op::Write(run)) = self.ops.pop_front() else { return };
        let ct = self.char_time_us;
        let written = began_us.min(now_us).saturating_sub(ct).max(self.start_us);
        let held = now_us.saturating_sub(began_us);
        if held >= disturbed_from_us(ct) {
            self.planned.disturbed_us = self.planned.disturbed_us.max(held);
        }
        if self.first {
            self.planned.start_us = written;
            self.first = false;
        } else {
            let late = now_us.saturating_sub(ct).max(self.start_us) - self.start_us;
            if late >= disturbed_from_us(ct) {
                self.planned.disturbed_us = self.planned.disturbed_us.max(late);
            }
            if late >= self.timeout_us && self.planned.gap.is_none() {
                // Written so late that the reply has a pause of the timeout inside:
                // to the master it ended there (000:2.2.2).
                self.planned.gap = Some((self.index, late));
                self.planned.split_by_harness = true;
            }
        }
        self.start_us = written + run.len() as u64 * ct;
        self.index += run.len();
    }

    /// The reply as it went (when it started, the pauses in it).
    pub fn sent(&self) -> &Planned {
        &self.planned
    }

    /// The reply as it went, taken.
    pub fn into_sent(self) -> Planned {
        self.planned
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::UartSettings;

    fn planned(paced: bool, gap: Option<(usize, u64)>) -> Planned {
        Planned {
            frame: vec![0x40, 0x42, 0x00, 0x00, 0x00, 0x00, 0x02],
            start_us: 10_000,
            settings: UartSettings::DEFAULT,
            gap,
            paced,
            disturbed_us: 0,
            split_by_harness: false,
            answered_late_us: 0,
        }
    }

    /// Every run written the instant it is due: the reply's own schedule.
    fn on_time(mut s: Sending) -> (Vec<Next>, Planned) {
        let mut steps = Vec::new();
        loop {
            let next = s.poll();
            steps.push(next.clone());
            match next {
                Next::Write { due_us, .. } => s.written(due_us, due_us),
                Next::Wait { .. } => {}
                Next::Done { .. } => return (steps, s.into_sent()),
            }
        }
    }

    #[test]
    fn a_reply_written_on_time_ends_its_characters_and_pause_later() {
        let ct = UartSettings::DEFAULT.char_time_us();
        let (steps, sent) = on_time(Sending::new(planned(false, None), 5_730));
        assert_eq!(
            steps,
            vec![
                Next::Write { due_us: 10_000 + ct, run: 0..7 },
                Next::Wait { until_us: 10_000 + 7 * ct },
                Next::Done { end_us: 10_000 + 7 * ct }
            ]
        );
        assert_eq!(sent, planned(false, None), "as planned");
        // A planned pause before the third character: two runs, the pause between.
        let (steps, sent) = on_time(Sending::new(planned(false, Some((2, 3_000))), 5_730));
        assert_eq!(steps.last(), Some(&Next::Done { end_us: 10_000 + 7 * ct + 3_000 }));
        assert_eq!(steps[2], Next::Write { due_us: 10_000 + 2 * ct + 3_000 + ct, run: 2..7 });
        assert_eq!(sent, planned(false, Some((2, 3_000))));
        // Paced: one character at a time, the same end.
        let (steps, _) = on_time(Sending::new(planned(true, None), 5_730));
        assert_eq!(steps.iter().filter(|s| matches!(s, Next::Write { .. })).count(), 7);
        assert_eq!(steps.last(), Some(&Next::Done { end_us: 10_000 + 7 * ct }));
    }

    /// A run written late: the first moves the reply's start; a later one leaves a
    /// pause inside the reply, noted from a character time on, and a split at the
    /// timeout.
    #[test]
    fn a_run_written_late_is_noted_in_the_reply_as_sent() {
        let ct = UartSettings::DEFAULT.char_time_us();
        let mut s = Sending::new(planned(true, None), 5_730);
        let Next::Write { due_us, .. } = s.poll() else { panic!("a write first") };
        s.written(due_us + 2_000, due_us + 2_000);
        assert_eq!(s.sent().start_us, 12_000);
        let Next::Write { due_us, .. } = s.poll() else { panic!("a write") };
        s.written(due_us + ct / 2, due_us + ct / 2);
        assert_eq!(s.sent().disturbed_us, 0, "under a character time: no receiver sees it");
        let Next::Write { due_us, .. } = s.poll() else { panic!("a write") };
        s.written(due_us + 6_000, due_us + 6_000);
        assert_eq!((s.sent().disturbed_us, s.sent().gap, s.sent().split_by_harness), (6_000, Some((2, 6_000)), true));
    }

    /// The harness held 8 ms in the write of a reply's first run (a busy machine):
    /// the reply is stamped from the write's beginning, the earliest it can have
    /// reached the master, so that a master's next request after the reply's true end
    /// is never taken to talk over it; a later run held as long is a pause the
    /// writing may have left, noted as before.
    #[test]
    fn a_write_the_harness_was_held_in_is_stamped_from_its_beginning() {
        let ct = UartSettings::DEFAULT.char_time_us();
        let mut s = Sending::new(planned(true, None), 5_730);
        let Next::Write { due_us, .. } = s.poll() else { panic!("a write first") };
        s.written(due_us, due_us + 8_000);
        assert_eq!(s.sent().start_us, 10_000, "as planned: it may have gone when due");
        assert_eq!(s.sent().disturbed_us, 8_000, "or 8 ms later: noted");
        assert!(!s.sent().split_by_harness);
        let Next::Write { due_us, .. } = s.poll() else { panic!("a write") };
        assert_eq!(due_us, 10_000 + 2 * ct, "the next run due after the first's character");
        s.written(due_us, due_us + 8_000);
        assert_eq!((s.sent().disturbed_us, s.sent().gap, s.sent().split_by_harness), (8_000, Some((1, 8_000)), true));
    }
}
