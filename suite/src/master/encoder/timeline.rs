//! What happened on the line in one scenario ([`Timeline`]), and what of it the
//! harness's own timing or a busy machine could explain: a reply the harness
//! disturbed, a rule broken by less than the master's process waited or the line went
//! unwatched, a talk-over a late read could hide.

use crate::verdict::WireEntry;
use hiperface_model::master::obligations::{Observation, Rule};
use hiperface_model::{Profile, RequestFrame, UartSettings};
use std::collections::BTreeMap;

/// A reply the harness's own timing disturbed (a busy machine, a hypervisor's pause).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Disturbance {
    /// When the reply started, µs since power-on.
    pub at_us: u64,
    /// The longest pause inside it the harness did not plan, µs (0: none a receiver
    /// could see).
    pub pause_us: u64,
    /// That pause was of the timeout or more: two transmissions to the master
    /// (000:2.2.2), which the scenario did not plan.
    pub split: bool,
    /// How late the reply started after the command's maximum response time because
    /// the harness read the request late, µs (0: within it).
    pub answered_late_us: u64,
    /// How long the kernel's workers, which deliver it to a master on a
    /// pseudo-terminal, waited for a processor while it was written, µs (0: not a
    /// character time): it may have reached the master with a pause the harness did
    /// not write, or in two parts.
    pub delivered_late_us: u64,
}

impl Disturbance {
    /// Whether it changed what any master saw, whatever the master did: a reply in two
    /// parts (two transmissions, 000:2.2.2: the scenario's reply was not the one it
    /// planned). A reply past its command's limit, or a shorter unplanned pause,
    /// changed only what a master that then broke a rule, or missed its reaction, may
    /// have made of it: a master that did neither was graded on what it did, in
    /// harder conditions, and its PASS stands.
    pub fn decides(&self) -> bool {
        self.split
    }
}

/// What happened on the line in one scenario, on one time axis (µs since power-on).
#[derive(Debug, Default)]
pub struct Timeline {
    pub entries: Vec<WireEntry>,
    pub observations: Vec<Observation>,
    /// The master's process's wait for a processor since it started, sampled: (µs
    /// since power-on, µs waited); empty where the master is not a process here.
    pub master_waited: Vec<(u64, u64)>,
    /// The kernel's workers' wait for a processor since the run began (at each
    /// sample, the longest any one of them added), sampled like `master_waited`: they
    /// deliver what is written to a pseudo-terminal, and one that waits holds the
    /// characters back either way. Empty where the master is not on a pseudo-terminal
    /// here.
    pub kernel_waited: Vec<(u64, u64)>,
    /// How long the machine's processors stopped since the run began (at each sample,
    /// the longest pause of any one of them that ended since the sample before: the
    /// hypervisor pausing it), sampled like `master_waited`: a master process running on a
    /// stopped processor is not waiting for one, and its run delay does not count it.
    /// Empty where the master is not a process here, or the pauses are not timed.
    pub host_paused: Vec<(u64, u64)>,
    /// Requests seen per command.
    pub requests: BTreeMap<u8, u32>,
    /// The master's well-formed requests as the encoder framed them.
    pub requests_log: Vec<LoggedRequest>,
    /// When the scenario's situation arose (µs), if it did.
    pub situation_us: Option<u64>,
    /// When the scenario ended, µs.
    pub end_us: u64,
    /// Replies the harness's own timing disturbed: a pause it did not plan, or an
    /// answer late because the request was read late.
    pub disturbed: Vec<Disturbance>,
    /// The encoder's thread ran at a real-time priority.
    pub real_time: bool,
    pub characters: usize,
    /// Characters read after the line had gone unwatched for a while (the harness was
    /// busy writing a reply, or not scheduled on a busy machine): their stamp (µs), and
    /// how long the line had been unwatched before (µs). They may have come that much
    /// earlier than stamped.
    pub late_chars: Vec<(u64, u64)>,
    /// The master's characters read with a parity or framing error (a drive on a port,
    /// whose kernel marks them).
    pub uart_faults: usize,
    /// Faults of the line itself (an echo unlike the reply, `--echo off` on a line that
    /// echoes): when (µs), and what. Never the master's.
    pub line_faults: Vec<(u64, String)>,
    /// The replies as the observer was told of them: when each began and ended, µs
    /// (a reply in two transmissions: its first).
    pub replies: Vec<(u64, u64)>,
    /// The longest character time the encoder listened at, µs (0: none yet; the
    /// default data rate is taken then): how far a request's characters may stretch.
    pub slowest_char_us: u64,
}

/// One of the master's well-formed requests as the encoder framed it, on the time axis
/// of its settings when it was received (a user data rate, 000:T28, makes its
/// characters shorter or longer than the default's).
#[derive(Debug, Clone, Copy)]
pub struct LoggedRequest {
    /// When its first character began, µs: the end of its stop bit less a character
    /// time at the settings it was received at (what the observer takes, too).
    pub begin_us: u64,
    /// The end of its last character, µs.
    pub end_us: u64,
    /// A character time at the settings it was received at, µs.
    pub char_us: u64,
    pub request: RequestFrame,
}

impl Timeline {
    /// How long the master's process waited for a processor between `from_us` and
    /// `to_us`, at most (the samples around them), µs; 0 where it was not measured.
    pub fn master_waited_in(&self, from_us: u64, to_us: u64) -> u64 {
        waited_in(&self.master_waited, from_us, to_us)
    }

    /// How long a processor stopped between `from_us` and `to_us`, at most, µs: a
    /// master's process on it stopped with it. 0 where it was not measured.
    pub fn host_paused_in(&self, from_us: u64, to_us: u64) -> u64 {
        waited_in(&self.host_paused, from_us, to_us)
    }

    /// How long the kernel's workers waited for a processor between `from_us` and
    /// `to_us`, at most, µs: what was written to the pseudo-terminal then may have
    /// reached the other end that much later. 0 where it was not measured.
    pub fn kernel_waited_in(&self, from_us: u64, to_us: u64) -> u64 {
        waited_in(&self.kernel_waited, from_us, to_us)
    }

    /// The replies the kernel's workers may have held back, in part, for a character
    /// time or more (their wait while the reply was written: `kernel_waited_in`), each
    /// as a disturbance of the harness's own line, in order with the others. A master
    /// on a pseudo-terminal then heard a pause inside the reply, or two transmissions,
    /// that the harness never wrote; what it did after is not proven its own.
    /// Returns them as `(reply start, wait)`, µs.
    pub fn disturbed_by_kernel(&mut self) -> Vec<(u64, u64)> {
        let ct = self.longest_char_us();
        let held: Vec<Disturbance> = self
            .replies
            .iter()
            .filter_map(|&(start, end)| {
                let waited = self.kernel_waited_in(start, end);
                (waited >= crate::serve::disturbed_from_us(ct)).then_some(Disturbance {
                    at_us: start,
                    pause_us: 0,
                    split: false,
                    answered_late_us: 0,
                    delivered_late_us: waited,
                })
            })
            .collect();
        let found = held.iter().map(|d| (d.at_us, d.delivered_late_us)).collect();
        for d in held {
            match self.disturbed.iter_mut().find(|e| e.at_us == d.at_us) {
                Some(e) => e.delivered_late_us = d.delivered_late_us,
                None => self.disturbed.push(d),
            }
        }
        self.disturbed.sort_by_key(|d| d.at_us);
        found
    }

    /// Whether `o` may be the machine's doing rather than the master's, where the
    /// master is a process on it: a rule a slow master breaks (a request too late, a
    /// pause too long) broken by less than the master's process waited for a processor,
    /// and the processors stopped, before it. The two together, µs, or `None` when the
    /// observation stands.
    pub fn master_slowed(&self, o: &Observation, timeout_us: u64, profile: &Profile, period_us: u64) -> Option<u64> {
        let measured = o.measured_us?;
        let (window, margin) = match o.rule {
            // The first request came in the settings-change window: since power-on.
            Rule::DuringSettingsChange => {
                ((0, o.at_us), measured.saturating_sub(profile.default_window_ms as u64 * 1000))
            }
            // A request written in two parts: the pause between them.
            Rule::GapInRequest => ((o.at_us, o.at_us + measured), measured.saturating_sub(timeout_us)),
            // No request within the polling period: the gap.
            Rule::NoCyclicRequest => ((o.at_us, o.at_us + measured), measured.saturating_sub(period_us)),
            _ => return None,
        };
        let waited = self.master_waited_in(window.0, window.1) + self.host_paused_in(window.0, window.1);
        (waited > 0 && waited >= margin).then_some(waited)
    }

    /// A request the master may have begun before a reply's end although the harness
    /// read it after: its first character came `after` µs after the end of the reply
    /// before it, and the harness had not read the line for longer than that when it
    /// read the request's characters (a busy machine; the kernel's delivery), so they
    /// may have come that much earlier. `(when the request began, how long unwatched)`
    /// of the first such request; `None` when every request was read soon enough to
    /// tell (000:2.2/cycle: the observer sees a talk-over only where the stamps show it).
    pub fn hidden_talk_over(&self) -> Option<(u64, u64)> {
        self.requests_log.iter().find_map(|r| {
            let (_, reply_end) = self.replies.iter().rev().find(|(start, _)| *start < r.begin_us)?;
            let after = r.begin_us.checked_sub(*reply_end)?;
            // The harness's own lateness only (the probe's delivery included): the
            // kernel's workers' wait, sampled every 5 ms by a thread that is itself
            // late on a busy machine, spans too much to guard a PASS with (measured:
            // scenarios of a conformant master left UNKNOWN on "up to 59.5 ms"); a
            // master that talks over replies does so at more than one, and is caught
            // where nothing hides it.
            let late = self.late_in(r.begin_us + r.char_us, r.end_us);
            (late > after).then_some((r.begin_us, late))
        })
    }

    /// A character time long enough for any settings the encoder listened at, µs.
    fn longest_char_us(&self) -> u64 {
        self.slowest_char_us.max(UartSettings::DEFAULT.char_time_us())
    }

    /// The longest time unwatched before any character stamped in `from_us..=to_us`.
    pub(super) fn late_in(&self, from_us: u64, to_us: u64) -> u64 {
        let inside = |&&(at, _): &&(u64, u64)| at >= from_us && at <= to_us;
        self.late_chars.iter().filter(inside).map(|(_, late)| *late).max().unwrap_or(0)
    }

    /// How much earlier than stamped characters in `from_us..=to_us` may have come:
    /// the harness's own lateness in reading them, or the kernel's workers' wait
    /// meanwhile (on a pseudo-terminal they deliver what the master wrote).
    fn unseen_in(&self, from_us: u64, to_us: u64) -> u64 {
        self.late_in(from_us, to_us).max(self.kernel_waited_in(from_us, to_us))
    }

    /// Whether `o` may be the harness's own lateness rather than the master's: a
    /// character it rests on was read after the line had gone unwatched, or while the
    /// kernel's workers that deliver it waited, for as long as the margin by which the
    /// rule was broken. `None` when the observation stands;
    /// otherwise how long the line had gone unwatched, µs.
    pub fn unproven(&self, o: &Observation, timeout_us: u64, profile: &Profile) -> Option<u64> {
        // Where a user data rate is slower than the default, its characters stretch
        // further: the windows are taken at the slowest.
        let ct = self.longest_char_us();
        // The longest request: where its characters may be stamped after `at_us`.
        let frame = 24 * ct;
        let start = o.at_us;
        // Characters read after the line went unwatched for the timeout may have come
        // as two frames or as one: where a frame ends is not known.
        if let (Rule::Malformed, None) = (o.rule, o.measured_us) {
            let late = self.unseen_in(start, start + frame);
            return (late >= timeout_us).then_some(late);
        }
        let measured = o.measured_us?;
        let (window, margin) = match o.rule {
            // The first request's characters, read late, came earlier than stamped:
            // the pause after them may have been longer.
            Rule::NoPause => ((start.saturating_sub(frame), start), timeout_us.saturating_sub(measured)),
            // The second fragment's characters, read late, came earlier than stamped:
            // the gap may be shorter.
            Rule::GapInRequest => ((start + measured, start + measured + frame), measured.saturating_sub(timeout_us)),
            // A request read late looks later than it was.
            Rule::TalksOverReply => ((start, start + frame), measured),
            Rule::DuringSettingsChange => {
                ((start, start + frame), measured.saturating_sub(profile.default_window_ms as u64 * 1000))
            }
            // Encoder Reset read late moves the end of its wait later.
            Rule::TooSoonAfterReset => {
                let reset_end = start.saturating_sub(measured + timeout_us);
                (
                    (reset_end.saturating_sub(frame), reset_end + ct),
                    (profile.init_ms as u64 * 1000).saturating_sub(measured),
                )
            }
            _ => return None,
        };
        let late = self.unseen_in(window.0, window.1);
        (late > 0 && late >= margin).then_some(late)
    }
}

/// The growth of a sampled wait (µs since power-on, µs waited in all) between
/// `from_us` and `to_us`, at most (the samples around them); 0 where there are none.
fn waited_in(samples: &[(u64, u64)], from_us: u64, to_us: u64) -> u64 {
    let before = samples.iter().rev().find(|(at, _)| *at <= from_us).map_or(0, |(_, w)| *w);
    let after = samples.iter().find(|(at, _)| *at >= to_us).or(samples.last());
    after.map_or(0, |(_, w)| w.saturating_sub(before))
}

/// A sampled wait as a record keeps it: the first and last samples, and each one
/// whose value differs from the sample before or after it. Between two kept samples
/// the wait was the same at every sample left out, so any window's growth reads as
/// it did from all of them.
pub fn changes_only(samples: &[(u64, u64)]) -> Vec<(u64, u64)> {
    let n = samples.len();
    samples
        .iter()
        .enumerate()
        .filter(|&(i, &(_, v))| {
            let differs = |j: Option<usize>| j.and_then(|j| samples.get(j)).is_none_or(|&(_, w)| w != v);
            i == 0 || i + 1 == n || differs(i.checked_sub(1)) || differs(Some(i + 1))
        })
        .map(|(_, s)| *s)
        .collect()
}
