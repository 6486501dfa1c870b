//! The breadth-first search, to a depth or to a fixpoint, and what it checks in every
//! state it runs from and reaches: the invariant, the frame rules, and that a power
//! cycle and the power-up windows lead to a reply.

use super::{abstraction, apply, frame_of, frame_rules, representatives, Event, Fingerprint, StepFn, World};
use crate::invariant::slave_invariant;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{Outcome, Reply};
use std::collections::{HashSet, VecDeque};

/// How far a search goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// Concrete states, to this many events from the start.
    Depth(usize),
    /// Abstract states, until no new one appears; give up (an error) beyond this many.
    Fixpoint { max_states: usize },
}

#[derive(Debug, Clone)]
pub struct Report {
    pub profile: String,
    /// Distinct (abstract, for a fixpoint) states reached.
    pub states: usize,
    /// Concrete states the invariant was checked in: representatives and successors.
    pub checked: u64,
    pub transitions: u64,
    /// The longest shortest path to a state, in events.
    pub depth: usize,
    /// No new state appeared: every reachable (abstract) state was explored.
    pub fixpoint: bool,
}

impl core::fmt::Display for Report {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{}: {} states, {} transitions, {} concrete states checked, depth {}, {}",
            self.profile,
            self.states,
            self.transitions,
            self.checked,
            self.depth,
            if self.fixpoint { "fixpoint reached" } else { "bounded" }
        )
    }
}

/// A violated rule and the events that lead to it from the start.
#[derive(Debug, Clone)]
pub struct Counterexample {
    pub what: String,
    pub trace: Vec<Event>,
}

impl core::fmt::Display for Counterexample {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(f, "{} after {} events:", self.what, self.trace.len())?;
        for e in &self.trace {
            writeln!(f, "  {e:?}")?;
        }
        Ok(())
    }
}

/// Breadth-first search from `start` over `alphabet`, the slave stepping with `step`:
/// the invariant in every concrete state run from and reached, the frame rules on
/// every frame, and that a power cycle and the power-up windows lead to a reply.
pub fn search(start: World, alphabet: &[Event], step: StepFn, bound: Bound) -> Result<Report, Counterexample> {
    let abstracted = matches!(bound, Bound::Fixpoint { .. });
    // A depth-bounded search compares concrete states, but for the count of EEPROM
    // writes (the model's bookkeeping, which no command reads).
    let key = |mut w: World| {
        if abstracted {
            abstraction(&w)
        } else {
            w.slave.reset_eeprom_writes();
            w
        }
    };
    let profile = start.slave.profile().name.as_str().to_string();
    let first = key(start);
    // Every state's fingerprint, and how each was first reached: (parent, event).
    let mut seen: HashSet<u128> = HashSet::new();
    let mut parents: Vec<(u32, u16)> = vec![(u32::MAX, 0)];
    seen.insert(Fingerprint::of(&first));
    // A state left unexpanded at the depth bound: no fixpoint.
    let mut cut = false;
    let mut queue = VecDeque::from([(first, 0u32, 0usize)]);
    let (mut checked, mut transitions, mut depth) = (0u64, 0u64, 0usize);
    let trace = |parents: &[(u32, u16)], mut i: u32, last: Option<u16>| {
        let mut t: Vec<Event> = last.map(|e| alphabet[e as usize].clone()).into_iter().collect();
        while let Some((p, e)) = parents.get(i as usize).copied().filter(|(p, _)| *p != u32::MAX) {
            t.push(alphabet[e as usize].clone());
            i = p;
        }
        t.reverse();
        t
    };
    while let Some((state, id, d)) = queue.pop_front() {
        depth = depth.max(d);
        let fail = |parents: &[(u32, u16)], what: String, last: Option<u16>| Counterexample {
            what,
            trace: trace(parents, id, last),
        };
        if let Err(what) = recovers(&state, step) {
            return Err(fail(&parents, what, None));
        }
        if matches!(bound, Bound::Depth(max) if d >= max) {
            // Checked, not expanded.
            cut = true;
            if let Err(v) = slave_invariant(&state.slave) {
                return Err(fail(&parents, format!("invariant: {v}"), None));
            }
            checked += 1;
            continue;
        }
        let froms = if abstracted { representatives(&state) } else { vec![state.clone()] };
        for from in &froms {
            let counter = from.slave.nonvolatile().counter;
            if let Err(v) = slave_invariant(&from.slave) {
                return Err(fail(&parents, format!("invariant: {v} (counter {counter:X}h)"), None));
            }
            checked += 1;
            for (i, e) in alphabet.iter().enumerate() {
                let mut next = from.clone();
                let outcome = apply(step, &mut next, e);
                transitions += 1;
                if let Err(what) = successor_rules(from, e, outcome.as_ref(), &next) {
                    return Err(fail(&parents, format!("{what} (from counter {counter:X}h)"), Some(i as u16)));
                }
                checked += 1;
                let k = key(next);
                let print = Fingerprint::of(&k);
                if seen.insert(print) {
                    if let Bound::Fixpoint { max_states } = bound {
                        if parents.len() >= max_states {
                            return Err(fail(&parents, format!("no fixpoint within {max_states} states"), None));
                        }
                    }
                    let n = parents.len() as u32;
                    parents.push((id, i as u16));
                    queue.push_back((k, n, d + 1));
                }
            }
        }
    }
    Ok(Report { profile, states: seen.len(), checked, transitions, depth, fixpoint: !cut })
}

/// The rules for one event from `from` to `next`: the frame rules on a frame's
/// outcome, and the invariant in the state reached.
fn successor_rules(from: &World, e: &Event, outcome: Option<&Outcome>, next: &World) -> Result<(), String> {
    if let (Some(o), Some(f)) = (outcome, frame_of(e)) {
        // After a reset the world is the power cycle's (see `apply_frame`): a silent
        // outcome, which reads nothing of it.
        frame_rules(from, &f, o, &next.slave).map_err(|w| format!("frame rule: {w}"))?;
    }
    slave_invariant(&next.slave).map_err(|v| format!("invariant: {v}"))
}

/// A power cycle and the power-up windows lead to Operational with the stored
/// settings, and the slave answers there. // 000:T9
fn recovers(w: &World, step: StepFn) -> Result<(), String> {
    let mut r = w.clone();
    apply(step, &mut r, &Event::PowerCycle);
    for _ in 0..4 {
        apply(step, &mut r, &Event::Advance);
    }
    if r.slave.state(r.now_us) != CommState::OperationalUser {
        return Err(format!("not Operational after the power-up windows: {:?}", r.slave.state(r.now_us)));
    }
    match apply(step, &mut r, &Event::Request(vec![0xFF, 0x42])).map(|o| o.reply) {
        Some(Reply::Frame(_)) => Ok(()),
        other => Err(format!("no reply after the power-up windows: {other:?}")),
    }
}
