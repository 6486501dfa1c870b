//! Local echo on the encoder's side (`certify master --port`): a two-wire RS-485
//! adapter whose receiver stays on hears the harness's own replies. [`ReplyEcho`]
//! sorts every character read into the echo of a reply (taken off the line) and the
//! master's (given to the model), so that the master is graded on what it sent.
//!
//! Sans-IO: told what went out and when, it is given the characters as they are read
//! and the time as it passes. Found at the first reply of a run (`--echo auto`), as
//! on the master's side ([`super::echo`]): the reply comes back byte for byte while
//! it goes out, before the master may begin its next request. An echo unlike the
//! reply is a fault of the line (a collision, a broken transceiver), never charged to
//! the master; so is an echoing line with `--echo off`.

use super::echo::{Echo, EchoMode};
use hiperface_model::datalink::RxChar;
use hiperface_model::Hex;

/// The echo of the replies on one line.
#[derive(Debug, Clone)]
pub struct ReplyEcho {
    mode: EchoMode,
    echo: Echo,
    /// How late after a reply's end its echo may still come (the line's latency), µs.
    slack_us: u64,
    /// The reply whose echo is awaited, the part of it come back so far, and by when
    /// the rest must have come (µs).
    awaited: Option<Awaited>,
    /// Faults of the line found so far: when (µs), and what.
    faults: Vec<(u64, String)>,
}

#[derive(Debug, Clone)]
struct Awaited {
    reply: Vec<u8>,
    /// The characters that matched the reply from its start (held, for the master,
    /// until they are known to be the echo).
    matched: Vec<RxChar>,
    deadline_us: u64,
}

impl ReplyEcho {
    /// `known`: what an earlier part of the run found (the echo is the line's, not a
    /// scenario's). `slack_us`: how much later than its reply's end an echo may be read.
    pub fn new(mode: EchoMode, known: Echo, slack_us: u64) -> ReplyEcho {
        let echo = match (mode, known) {
            (EchoMode::On, _) => Echo::Echoes,
            (_, known) => known,
        };
        ReplyEcho { mode, echo, slack_us, awaited: None, faults: Vec::new() }
    }

    pub fn echo(&self) -> Echo {
        self.echo
    }

    pub fn mode(&self) -> EchoMode {
        self.mode
    }

    /// For the next scenario, whose time starts at 0 when this one's ends: an echo
    /// still on its way (the last reply went out just before the end) is awaited there
    /// for as long as an echo may be late, and taken off the line when it comes.
    pub fn carried_over(mut self) -> ReplyEcho {
        let wait_us = self.wait_us();
        if let Some(a) = self.awaited.as_mut() {
            a.deadline_us = wait_us;
            for c in &mut a.matched {
                c.at_us = 0;
            }
        }
        self.faults.clear();
        self
    }

    /// How long after a reply's end its echo is awaited, µs: the line's latency, and on
    /// a line known to echo as long as a late reply is waited for. The echo is on the
    /// wire before anything the master sends after the reply, and a busy machine's
    /// pseudo-terminal delivered one past the latency (real_lines with three busy
    /// loops: "did not come back (0 of 7 characters did)"); only a line that lost an
    /// echo pays the wait. The first reply of a line not yet known to echo keeps the
    /// short wait: a master's request that begins like the reply is held while it is
    /// awaited.
    fn wait_us(&self) -> u64 {
        match (self.echo, self.mode) {
            (Echo::Echoes, _) => self.slack_us + super::echo::LATE_ECHO_GRACE_US,
            _ => self.slack_us,
        }
    }

    /// The faults of the line found so far: when (µs) and what; taken.
    pub fn take_faults(&mut self) -> Vec<(u64, String)> {
        std::mem::take(&mut self.faults)
    }

    /// A reply went out, its last character ending at `end_us`: its echo is awaited
    /// unless the line is known to be quiet. With `--echo off` every reply is watched,
    /// to say so rather than grade the master on its own echo.
    pub fn sent(&mut self, reply: &[u8], end_us: u64, out: &mut Vec<RxChar>) {
        self.settle(u64::MAX, out);
        let watch = match (self.mode, self.echo) {
            (EchoMode::Off, _) => true,
            (_, Echo::Quiet) => false,
            _ => true,
        };
        if watch && !reply.is_empty() {
            let deadline_us = end_us + self.wait_us();
            self.awaited = Some(Awaited { reply: reply.to_vec(), matched: Vec::new(), deadline_us });
        }
    }

    /// A character read: into `out` when it is the master's (or may be: a character
    /// that matched a reply so far is held until the whole reply has come back).
    pub fn take(&mut self, ch: RxChar, out: &mut Vec<RxChar>) {
        self.settle(ch.at_us, out);
        let Some(a) = self.awaited.as_mut() else {
            out.push(ch);
            return;
        };
        if a.reply.get(a.matched.len()) == Some(&ch.byte) && ch.fault.is_none() {
            a.matched.push(ch);
            if a.matched.len() == a.reply.len() {
                self.came_back(ch.at_us);
            }
            return;
        }
        // Not the echo's next character.
        let Some(a) = self.awaited.take() else { return };
        if self.echo == Echo::Echoes {
            let heard: Vec<u8> = a.matched.iter().map(|c| c.byte).chain([ch.byte]).collect();
            self.faults.push((
                ch.at_us,
                format!(
                    "the echo of the reply [{}] came back as [{}]: a collision or a fault of the line, not the master's",
                    Hex(&a.reply),
                    Hex(&heard)
                ),
            ));
        } else {
            // The master's characters after all: the line does not echo.
            self.quiet();
            out.extend(a.matched);
        }
        out.push(ch);
    }

    /// Time passes: an echo not come back by its deadline is not coming.
    pub fn idle(&mut self, now_us: u64, out: &mut Vec<RxChar>) {
        self.settle(now_us, out);
    }

    /// The reply came back whole.
    fn came_back(&mut self, at_us: u64) {
        self.awaited = None;
        if self.mode == EchoMode::Off {
            self.echo = Echo::Echoes;
            self.faults.push((
                at_us,
                "the line echoes: the reply came back byte for byte while it went out; use --echo auto".into(),
            ));
        } else {
            self.echo = Echo::Echoes;
        }
    }

    /// The line does not echo (found now, in auto mode).
    fn quiet(&mut self) {
        if self.echo == Echo::Unknown {
            self.echo = Echo::Quiet;
        }
    }

    /// Whatever was awaited and not come back by `now_us`: on a line found to echo
    /// (whatever `--echo` said) a fault of the line, what came of it the echo's; else
    /// the line is quiet and what was held the master's.
    fn settle(&mut self, now_us: u64, out: &mut Vec<RxChar>) {
        let Some(a) = self.awaited.as_ref() else { return };
        if now_us <= a.deadline_us {
            return;
        }
        let Some(a) = self.awaited.take() else { return };
        if self.echo == Echo::Echoes {
            self.faults.push((
                a.deadline_us,
                format!(
                    "the echo of the reply [{}] did not come back ({} of {} characters did): a fault of the line",
                    Hex(&a.reply),
                    a.matched.len(),
                    a.reply.len()
                ),
            ));
        } else {
            // Not an echo: the master's characters.
            self.quiet();
            out.extend(a.matched);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CT: u64 = 1146;

    fn ch(byte: u8, at_us: u64) -> RxChar {
        RxChar { byte, at_us, fault: None }
    }

    /// Feed `chars` after a reply [40 42 ..] that ended at 10 ms; what reached the
    /// master's side, the echo found, and the faults.
    fn run(mode: EchoMode, known: Echo, chars: &[(u8, u64)]) -> (Vec<u8>, Echo, Vec<String>) {
        let mut e = ReplyEcho::new(mode, known, 2_000);
        let mut out = Vec::new();
        e.sent(&[0x40, 0x42, 0x01, 0x02], 10_000, &mut out);
        for &(b, t) in chars {
            e.take(ch(b, t), &mut out);
        }
        e.idle(2_000_000, &mut out);
        let faults = e.take_faults().into_iter().map(|(_, f)| f).collect();
        (out.iter().map(|c| c.byte).collect(), e.echo(), faults)
    }

    fn echo_then(request: &[u8]) -> Vec<(u8, u64)> {
        let reply = [0x40u8, 0x42, 0x01, 0x02];
        let mut chars: Vec<(u8, u64)> =
            reply.iter().enumerate().map(|(i, b)| (*b, 10_000 - (3 - i as u64) * CT)).collect();
        chars.extend(request.iter().enumerate().map(|(i, b)| (*b, 20_000 + i as u64 * CT)));
        chars
    }

    #[test]
    fn an_echo_is_found_at_the_first_reply_and_taken_off() {
        let (master, echo, faults) = run(EchoMode::Auto, Echo::Unknown, &echo_then(&[0x40, 0x42, 0x02]));
        assert_eq!((master, echo, faults), (vec![0x40, 0x42, 0x02], Echo::Echoes, vec![]));
    }

    #[test]
    fn a_quiet_line_gives_everything_to_the_master_even_a_request_like_the_reply() {
        // The master's request begins as the reply did (same address and command):
        // held while it matches, given back at the first difference.
        let (master, echo, faults) =
            run(EchoMode::Auto, Echo::Unknown, &[(0x40, 12_000), (0x42, 13_000), (0x02, 14_000)]);
        assert_eq!((master, echo, faults), (vec![0x40, 0x42, 0x02], Echo::Quiet, vec![]));
        // Nothing at all comes back: quiet, found when the echo's time is over.
        let (master, echo, _) = run(EchoMode::Auto, Echo::Unknown, &[]);
        assert_eq!((master, echo), (vec![], Echo::Quiet));
        // A part of the reply's start, then silence past the deadline: the master's.
        let (master, echo, faults) = run(EchoMode::Auto, Echo::Unknown, &[(0x40, 11_000)]);
        assert_eq!((master, echo, faults), (vec![0x40], Echo::Quiet, vec![]));
    }

    #[test]
    fn once_quiet_nothing_is_held() {
        let mut e = ReplyEcho::new(EchoMode::Auto, Echo::Quiet, 2_000);
        let mut out = Vec::new();
        e.sent(&[0x40, 0x42], 10_000, &mut out);
        e.take(ch(0x40, 10_500), &mut out);
        assert_eq!(out.len(), 1, "given on at once, not held");
    }

    #[test]
    fn a_garbled_echo_is_a_fault_of_the_line_not_the_masters() {
        let mut chars = echo_then(&[]);
        chars[2].0 = 0x81;
        let (_, echo, faults) = run(EchoMode::Auto, Echo::Echoes, &chars);
        assert_eq!(echo, Echo::Echoes);
        assert!(faults.len() == 1 && faults[0].contains("came back as [40 42 81]"), "{faults:?}");
        // A missing echo on a line known to echo.
        let (_, _, faults) = run(EchoMode::On, Echo::Unknown, &[]);
        assert!(faults.len() == 1 && faults[0].contains("0 of 4 characters"), "{faults:?}");
    }

    /// On a line known to echo, an echo delivered 30 ms after its reply's end (past the
    /// line's 2 ms) is still the echo, taken off; the master's request after it is the
    /// master's. Before, "did not come back (0 of 4 characters did)".
    #[test]
    fn a_late_echo_on_a_line_known_to_echo_is_taken_off() {
        let late: Vec<(u8, u64)> = echo_then(&[0x40, 0x42, 0x02]).into_iter().map(|(b, t)| (b, t + 30_000)).collect();
        let (master, echo, faults) = run(EchoMode::Auto, Echo::Echoes, &late);
        assert_eq!((master, echo, faults), (vec![0x40, 0x42, 0x02], Echo::Echoes, vec![]));
        // Still a fault where it never comes, once the wait is over.
        let mut e = ReplyEcho::new(EchoMode::Auto, Echo::Echoes, 2_000);
        let mut out = Vec::new();
        e.sent(&[0x40, 0x42], 10_000, &mut out);
        e.idle(500_000, &mut out);
        assert!(e.take_faults().is_empty(), "awaited within the wait");
        e.idle(1_013_000, &mut out);
        assert_eq!(e.take_faults().len(), 1);
    }

    #[test]
    fn echo_off_on_an_echoing_line_is_a_diagnosis_at_every_reply() {
        let (master, echo, faults) = run(EchoMode::Off, Echo::Echoes, &echo_then(&[0x40, 0x42, 0x02]));
        assert_eq!((master, echo), (vec![0x40, 0x42, 0x02], Echo::Echoes));
        assert!(faults.len() == 1 && faults[0].contains("use --echo auto"), "{faults:?}");
        // Off on a quiet line: nothing to say.
        let (master, _, faults) = run(EchoMode::Off, Echo::Unknown, &[(0x40, 20_000)]);
        assert_eq!((master, faults), (vec![0x40], Vec::<String>::new()));
    }

    /// With `--echo off` on a line found to echo, the echo is still the echo: a late
    /// one is waited for and taken off, a part of one is a fault of the line, never
    /// the master's characters (real_lines with three busy loops and a test run beside
    /// them: a split echo read as "a request while the encoder was replying", a FAIL of
    /// the master for the harness's own reply).
    #[test]
    fn echo_off_on_a_line_found_to_echo_never_gives_the_master_its_echo() {
        let late: Vec<(u8, u64)> = echo_then(&[0x40, 0x42, 0x02]).into_iter().map(|(b, t)| (b, t + 30_000)).collect();
        let (master, echo, faults) = run(EchoMode::Off, Echo::Echoes, &late);
        assert_eq!((master, echo), (vec![0x40, 0x42, 0x02], Echo::Echoes));
        assert!(faults.len() == 1 && faults[0].contains("use --echo auto"), "{faults:?}");
        let part = [(0x40, 10_500), (0x42, 11_600)];
        let (master, _, faults) = run(EchoMode::Off, Echo::Echoes, &part);
        assert_eq!(master, Vec::<u8>::new(), "a part of the echo is not the master's");
        assert!(faults.len() == 1 && faults[0].contains("did not come back (2 of 4"), "{faults:?}");
    }

    #[test]
    fn characters_after_an_echo_keep_their_times() {
        let mut e = ReplyEcho::new(EchoMode::Auto, Echo::Unknown, 2_000);
        let mut out = Vec::new();
        e.sent(&[0x40, 0x42], 10_000, &mut out);
        e.take(ch(0x40, 11_000), &mut out);
        e.take(ch(0x43, 11_500), &mut out);
        let times: Vec<u64> = out.iter().map(|c| c.at_us).collect();
        assert_eq!(times, vec![11_000, 11_500]);
    }
}
