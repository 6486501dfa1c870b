//! The breadth-first search over the canonical joint states from every world's
//! power-on, and what it checks at every step: no must broken, no panic, no hang
//! (every step moves the clock on); what it found (a report, or a counterexample
//! replayed in concrete time).

use super::joint::{Joint, Seen};
use super::{acts, applies, worlds, MasterStep, World, BASE_US};
use crate::fixpoint::Fingerprint;
use hiperface_model::master::obligations::{Observation, Rule};
use hiperface_model::master::reference::{Action, Event, ResetCause, Stage};
use hiperface_model::slave::act::Act;
use hiperface_model::Profile;
use std::collections::{HashSet, VecDeque};

/// Whether `o` breaks a must: a rule on a normative clause that binds the edition (what
/// `certify master` FAILs; a recommendation or a decision is NON-STRICT).
pub fn is_must(o: &Observation, edition: hiperface_model::Edition) -> bool {
    o.rule.clause().binding(edition).is_some()
}

/// The master's events by kind, for counting which reactions were reached.
pub const EVENT_KINDS: [&str; 13] = [
    "type label",
    "extended type label",
    "version",
    "status code",
    "position",
    "position error",
    "no valid reply",
    "multiturn sync fault",
    "unknown code",
    "resets exhausted",
    "reset: persisting",
    "reset: critical code",
    "reset: unknown code",
];

fn event_kind(e: &Event) -> usize {
    match e {
        Event::TypeLabel { .. } => 0,
        Event::ExtendedTypeLabel { .. } => 1,
        Event::Version(_) => 2,
        Event::Status(_) => 3,
        Event::Position(_) => 4,
        Event::PositionError(_) => 5,
        Event::PositionNoValidReply => 6,
        Event::SyncFault => 7,
        Event::UnknownCode(_) => 8,
        Event::ResetsExhausted => 9,
        Event::Reset(ResetCause::Persisting) => 10,
        Event::Reset(ResetCause::Critical(_)) => 11,
        Event::Reset(ResetCause::Unknown(_)) => 12,
    }
}

/// What a search found.
#[derive(Debug, Clone)]
pub struct Report {
    pub profile: String,
    /// Distinct canonical joint states reached.
    pub states: usize,
    pub transitions: u64,
    /// The longest shortest path to a state, in steps (actions of the master).
    pub depth: usize,
    pub fixpoint: bool,
    /// Transitions in which each act of [`acts`] changed what the encoder did.
    pub acts_applied: Vec<(Option<Act>, u64)>,
    /// Each kind of the master's events ([`EVENT_KINDS`]), how often.
    pub events: [u64; EVENT_KINDS.len()],
    /// Stages the master was in where it decided.
    pub stages: Vec<Stage>,
    /// Transitions with a request before the previous one's reply window closed
    /// (`Rule::ReplyWindow`, a decision of this project: NON-STRICT). The one rule
    /// that is no must whose memory the canonical state keeps whole; the
    /// recommendations' memory is forgotten (`Observer::forget_recommendations`), so
    /// what they would say is not counted.
    pub reply_window: u64,
    pub seconds: f64,
}

impl core::fmt::Display for Report {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{}: {} states, {} transitions, depth {}, {}, {:.1} s",
            self.profile,
            self.states,
            self.transitions,
            self.depth,
            if self.fixpoint { "fixpoint reached" } else { "bounded" },
            self.seconds
        )
    }
}

/// A step of a counterexample: what the master did, what the encoder did to it, and
/// what was seen.
#[derive(Debug, Clone)]
pub struct TraceStep {
    pub at_us: u64,
    pub action: Action,
    pub act: Option<Act>,
    pub events: Vec<Event>,
    pub observations: Vec<Observation>,
}

impl core::fmt::Display for TraceStep {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let ms = self.at_us as f64 / 1000.0;
        match self.action {
            Action::Exchange { request, .. } => {
                let act = self.act.map_or("Answer".into(), |a| format!("{a:?}"));
                write!(f, "{ms:>9.3} ms  {:?} {act}", request.request.command())?
            }
            Action::WaitUntil(t) => write!(f, "{ms:>9.3} ms  wait until {:.3} ms", t as f64 / 1000.0)?,
            Action::Stop => write!(f, "{ms:>9.3} ms  stop")?,
        }
        for e in &self.events {
            write!(f, "; {e:?}")?;
        }
        for o in &self.observations {
            write!(f, "; broke {:?} ({})", o.rule, o.rule.clause().id())?;
        }
        Ok(())
    }
}

/// A must broken (or a panic, a hang), with the steps from power-on that lead to it.
#[derive(Debug, Clone)]
pub struct Counterexample {
    pub what: String,
    pub world: &'static str,
    pub trace: Vec<TraceStep>,
}

impl core::fmt::Display for Counterexample {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(f, "{} (world: {}) after {} steps:", self.what, self.world, self.trace.len())?;
        for s in &self.trace {
            writeln!(f, "  {s}")?;
        }
        Ok(())
    }
}

/// How a state was first reached: its parent and the act (an index into the acts),
/// or for a power-on the world's index.
const ROOT: u32 = u32::MAX;

/// The breadth-first search from every world's power-on, the master stepping with
/// `master_step`, until no new canonical state appears (or `max_states`, an error).
pub fn search(profile: Profile, master_step: MasterStep, max_states: usize) -> Result<Report, Counterexample> {
    let started = std::time::Instant::now();
    let worlds = worlds(profile);
    let acts = acts();
    let edition = profile.edition;
    let mut seen_states: HashSet<u128> = HashSet::new();
    let mut parents: Vec<(u32, u16)> = Vec::new();
    let mut queue: VecDeque<(Joint, u32, usize)> = VecDeque::new();
    let mut report = Report {
        profile: profile.name.as_str().to_string(),
        states: 0,
        transitions: 0,
        depth: 0,
        fixpoint: false,
        acts_applied: acts.iter().map(|a| (*a, 0)).collect(),
        events: [0; EVENT_KINDS.len()],
        stages: Vec::new(),
        reply_window: 0,
        seconds: 0.0,
    };
    for (i, w) in worlds.iter().enumerate() {
        let first = Joint::power_on(w);
        let look_back = first.observer.look_back_us();
        let fail = |what: String| Counterexample { what, world: w.name, trace: Vec::new() };
        if look_back > BASE_US {
            return Err(fail(format!("the observer looks back {look_back} µs, past the base {BASE_US} µs")));
        }
        let first = first.canonical();
        if seen_states.insert(Fingerprint::of(&first)) {
            queue.push_back((first, parents.len() as u32, 0));
            parents.push((ROOT, i as u16));
        }
    }
    let counterexample = |parents: &[(u32, u16)], id: u32, last: Option<u16>, what: String| {
        let (world, trace) = replay(&worlds, &acts, master_step, parents, id, last);
        Counterexample { what, world, trace }
    };
    while let Some((state, id, d)) = queue.pop_front() {
        report.depth = report.depth.max(d);
        let stage = state.master.flow().stage;
        if !report.stages.contains(&stage) {
            report.stages.push(stage);
        }
        let choices: &[Option<Act>] = match state.action {
            Action::Exchange { .. } => &acts,
            Action::WaitUntil(_) => &acts[..1],
            // With no duration the master never stops: a stop is a hang.
            Action::Stop => return Err(counterexample(&parents, id, None, "the master stopped".into())),
        };
        for (a, &act) in choices.iter().enumerate() {
            if !applies(act, &state.action) {
                continue;
            }
            let mut next = state.clone();
            let mut seen = Seen::default();
            if let Err(what) = next.step(master_step, act, &mut seen) {
                return Err(counterexample(&parents, id, Some(a as u16), what));
            }
            // An act that changed nothing is the answer's transition again.
            if a > 0 && !seen.applied {
                continue;
            }
            report.transitions += 1;
            if let Some(what) = seen.unmodelled {
                return Err(counterexample(&parents, id, Some(a as u16), format!("not modelled: {what}")));
            }
            let exchange = matches!(state.action, Action::Exchange { .. });
            if let Some(slot) = report.acts_applied.get_mut(a).filter(|_| seen.applied || (a == 0 && exchange)) {
                slot.1 += 1;
            }
            for e in &seen.events {
                if let Some(n) = report.events.get_mut(event_kind(e)) {
                    *n += 1;
                }
            }
            for o in &seen.observations {
                if is_must(o, edition) {
                    let what = format!("must broken: {:?} ({}, {})", o.rule, o.rule.clause().id(), o.rule.text());
                    return Err(counterexample(&parents, id, Some(a as u16), what));
                }
                if o.rule == Rule::ReplyWindow {
                    report.reply_window += 1;
                }
            }
            // Never hangs: every step moves the clock on.
            if next.line.now_us <= state.line.now_us {
                let what = format!("the master's step took no time ({:?})", state.action);
                return Err(counterexample(&parents, id, Some(a as u16), what));
            }
            let canonical = next.canonical();
            if seen_states.insert(Fingerprint::of(&canonical)) {
                if parents.len() >= max_states {
                    let what = format!("no fixpoint within {max_states} states");
                    return Err(counterexample(&parents, id, None, what));
                }
                queue.push_back((canonical, parents.len() as u32, d + 1));
                parents.push((id, a as u16));
            }
        }
    }
    report.states = seen_states.len();
    report.fixpoint = true;
    report.seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// The steps from power-on to state `id` (and the act `last` from it), replayed in
/// concrete time (nothing canonical): the world's name and the steps.
fn replay(
    worlds: &[World],
    acts: &[Option<Act>],
    master_step: MasterStep,
    parents: &[(u32, u16)],
    id: u32,
    last: Option<u16>,
) -> (&'static str, Vec<TraceStep>) {
    let mut path: Vec<u16> = last.into_iter().collect();
    let mut i = id;
    let mut world = 0;
    while let Some(&(p, e)) = parents.get(i as usize) {
        if p == ROOT {
            world = e;
            break;
        }
        path.push(e);
        i = p;
    }
    path.reverse();
    let Some(w) = worlds.get(world as usize) else { return ("?", Vec::new()) };
    let path = path.into_iter().map(|a| acts.get(a as usize).copied().flatten());
    (w.name, play(w, master_step, path))
}

/// The master's steps from power-on in `world`, the encoder doing the `acts` in turn
/// (one per step; a wait takes one too), in concrete time.
pub fn play(w: &World, master_step: MasterStep, acts: impl IntoIterator<Item = Option<Act>>) -> Vec<TraceStep> {
    let mut state = Joint::power_on(w);
    let mut trace = Vec::new();
    for act in acts {
        let mut seen = Seen::default();
        let (at_us, action) = (state.line.now_us, state.action);
        let _ = state.step(master_step, act, &mut seen);
        let exchange = matches!(action, Action::Exchange { .. });
        let observations = seen.observations.iter().filter(|o| is_must(o, w.encoder.edition)).copied().collect();
        trace.push(TraceStep { at_us, action, act: act.filter(|_| exchange), events: seen.events, observations });
    }
    trace
}
