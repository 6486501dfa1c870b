//! What a listening run adds up to: counts, the master's broken rules, response times
//! per command as a histogram, and the exchanges worth reading. Bounded in memory
//! whatever the capture's length (a cap on what is kept, counts for the rest).

use super::HeardExchange;
use crate::verdict::{CaseVerdict, Finding, Outcome};
use hiperface_model::command::CommandId;
use hiperface_model::master::obligations::Rule;
use serde::Serialize;
use std::collections::BTreeMap;

/// Exchanges kept for the report (the worst first ones); notes kept.
const KEPT: usize = 1000;

/// Response-time histogram bounds, ms (the last bucket is "more").
pub const BUCKETS_MS: [f64; 8] = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0];

#[derive(Debug, Clone, Default, Serialize)]
pub struct Times {
    pub count: u64,
    pub min_ms: f64,
    pub max_ms: f64,
    pub mean_ms: f64,
    /// Counts per bucket of [`BUCKETS_MS`], and one for beyond.
    pub histogram: Vec<u64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct MasterRule {
    pub rule: String,
    pub count: u64,
    pub first: Finding,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct Summary {
    pub characters: u64,
    /// Characters captured with a parity or framing error.
    pub flagged: u64,
    pub breaks: u64,
    pub exchanges: u64,
    /// Exchanges per verdict.
    pub verdicts: BTreeMap<&'static str, u64>,
    /// Exchanges per command and verdict.
    #[serde(serialize_with = "by_command_name")]
    pub per_command: BTreeMap<CommandId, BTreeMap<&'static str, u64>>,
    /// Frames neither a request nor a reply in its window (not graded).
    pub unattributed: u64,
    /// The characters of those frames.
    pub unattributed_characters: u64,
    pub master: Vec<MasterRule>,
    #[serde(serialize_with = "by_command_name")]
    pub response_times: BTreeMap<CommandId, Times>,
    /// The first exchanges that were not PASS.
    pub exchanges_kept: Vec<HeardExchange>,
    pub notes: Vec<String>,
    pub notes_dropped: u64,
}

impl Summary {
    pub(super) fn exchange(&mut self, h: &HeardExchange) {
        self.exchanges += 1;
        let label = h.verdict.label();
        // The counts exist after the first exchanges: looked up, not entered, on the
        // path every exchange takes.
        match self.verdicts.get_mut(label) {
            Some(n) => *n += 1,
            None => _ = self.verdicts.insert(label, 1),
        }
        let per_verdict = match self.per_command.get_mut(&h.command) {
            Some(v) => v,
            None => self.per_command.entry(h.command).or_default(),
        };
        match per_verdict.get_mut(label) {
            Some(n) => *n += 1,
            None => _ = per_verdict.insert(label, 1),
        }
        if h.verdict != CaseVerdict::Pass && self.exchanges_kept.len() < KEPT {
            self.exchanges_kept.push(h.clone());
        }
    }

    pub(super) fn note(&mut self, n: String) {
        if self.notes.len() < KEPT {
            self.notes.push(n);
        } else {
            self.notes_dropped += 1;
        }
    }

    pub(super) fn response_time(&mut self, command: CommandId, t_us: i64) {
        let ms = t_us as f64 / 1000.0;
        let t = match self.response_times.get_mut(&command) {
            Some(t) => t,
            None => self.response_times.entry(command).or_default(),
        };
        if t.count == 0 {
            (t.min_ms, t.max_ms) = (ms, ms);
            t.histogram = vec![0; BUCKETS_MS.len() + 1];
        }
        t.count += 1;
        t.min_ms = t.min_ms.min(ms);
        t.max_ms = t.max_ms.max(ms);
        t.mean_ms += (ms - t.mean_ms) / t.count as f64;
        let i = BUCKETS_MS.iter().position(|b| ms <= *b).unwrap_or(BUCKETS_MS.len());
        if let Some(c) = t.histogram.get_mut(i) {
            *c += 1;
        }
    }

    pub(super) fn master(&mut self, rule: Rule, f: Finding) {
        match self.master.iter_mut().find(|m| m.rule == rule.text()) {
            Some(m) => m.count += 1,
            None => self.master.push(MasterRule { rule: rule.text().to_string(), count: 1, first: f }),
        }
    }

    /// The worst verdict of the slave's exchanges and the master's rules.
    pub fn worst(&self) -> CaseVerdict {
        let slave = CaseVerdict::ALL
            .into_iter()
            .filter(|h| self.count(*h) > 0)
            .fold(CaseVerdict::NotApplicable, CaseVerdict::worst);
        self.master.iter().fold(slave, |w, m| w.worst(m.first.verdict()))
    }

    /// What the listening run adds up to, and why where it is not PASSED: a FAIL
    /// fails; a capture in which no exchange could be graded, or most of whose
    /// characters could not be read (a line error, a break, a frame neither request
    /// nor reply), is INCOMPLETE. UNKNOWN exchanges among graded ones are reported,
    /// not held against the run: a listener never knows everything.
    pub fn outcome(&self) -> (Outcome, Option<String>) {
        if self.worst() == CaseVerdict::Fail {
            return (Outcome::Failed, None);
        }
        let graded = self.count(CaseVerdict::Pass) + self.count(CaseVerdict::NonStrict);
        let unread = self.flagged + self.unattributed_characters + self.breaks;
        if graded == 0 {
            let why = format!(
                "nothing could be graded: {} characters, {} exchanges ({} UNKNOWN), {} frames not attributed, \
                 {} characters with a line error, {} breaks",
                self.characters,
                self.exchanges,
                self.count(CaseVerdict::Unknown),
                self.unattributed,
                self.flagged,
                self.breaks
            );
            return (Outcome::Incomplete, Some(why));
        }
        if unread * 2 > self.characters + self.breaks {
            let why = format!(
                "most of the capture could not be read: {} of {} characters had a line error or were in frames \
                 neither request nor reply, {} breaks",
                self.flagged + self.unattributed_characters,
                self.characters,
                self.breaks
            );
            return (Outcome::Incomplete, Some(why));
        }
        (Outcome::Passed, None)
    }

    pub fn count(&self, h: CaseVerdict) -> u64 {
        self.verdicts.get(h.label()).copied().unwrap_or(0)
    }
}

// The report names commands and shows bytes as hex; the listener keeps them as they
// are (formatting every exchange would cost more than grading it).

pub(super) fn command_name<S: serde::Serializer>(c: &CommandId, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(c)
}

pub(super) fn hex<S: serde::Serializer>(b: &[u8], s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&hiperface_model::frame::Hex(b))
}

pub(super) fn hex_or_silence<S: serde::Serializer>(b: &Option<Vec<u8>>, s: S) -> Result<S::Ok, S::Error> {
    match b {
        Some(b) => hex(b, s),
        None => s.serialize_none(),
    }
}

fn by_command_name<S: serde::Serializer, V: Serialize>(m: &BTreeMap<CommandId, V>, s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(m.iter().map(|(c, v)| (c.to_string(), v)))
}
