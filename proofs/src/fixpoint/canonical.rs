//! The abstraction of the search to a fixpoint: a world's class and its canonical
//! world (the counter's classes, the offset's, the power-up phases; the module
//! documentation says why each is sound), and the worlds each event is run from.

use super::World;
use crate::invariant::COUNTER_MAX;
use hiperface_model::Slave;

/// The counter's classes: the values Increment Counter tells apart (000:T16, 000:T46,
/// 002:47h), and `Beyond` for a value no state may hold, kept concrete so that the
/// invariant sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CounterClass {
    Zero,
    One,
    Between,
    BelowTop,
    Top,
    Beyond,
}

impl CounterClass {
    pub fn of(counter: u32) -> CounterClass {
        match counter {
            0 => CounterClass::Zero,
            1 => CounterClass::One,
            c if c < COUNTER_MAX - 1 => CounterClass::Between,
            c if c == COUNTER_MAX - 1 => CounterClass::BelowTop,
            COUNTER_MAX => CounterClass::Top,
            _ => CounterClass::Beyond,
        }
    }

    /// The values the search runs each command from: the class's ends (the first is
    /// the class's canonical value). `Beyond` has none: it is never abstracted.
    pub fn representatives(self) -> &'static [u32] {
        match self {
            CounterClass::Zero => &[0],
            CounterClass::One => &[1],
            CounterClass::Between => &[2, COUNTER_MAX - 2],
            CounterClass::BelowTop => &[COUNTER_MAX - 1],
            CounterClass::Top => &[COUNTER_MAX],
            CounterClass::Beyond => &[],
        }
    }
}

/// The offset's canonical value in its class: 0, the last step, or the middle of the
/// range for every step between.
fn canonical_offset(offset: u64, range: u64) -> u64 {
    if offset == 0 || offset + 1 == range || offset >= range {
        offset
    } else {
        range / 2
    }
}

/// The start of the power-up phase `now` is in: the earliest of power-on and the
/// windows' ends (000:T9) at or before `now` from which the state is the same.
fn phase_start(s: &Slave, now: u64) -> u64 {
    let p = s.profile();
    let state = s.state(now);
    let Some(since) = s.power_up().since_us else { return 0 };
    let at = |ms: u16| since.saturating_add(ms as u64 * 1000);
    [since, at(p.init_ms), at(p.default_window_ms), at(p.user_settings_ms)]
        .into_iter()
        .filter(|t| *t <= now && s.state(*t) == state)
        .min()
        .unwrap_or(now)
}

/// The abstraction: the canonical world of `w`'s class.
pub fn abstraction(w: &World) -> World {
    let mut a = w.clone();
    let nv = a.slave.nonvolatile();
    let (counter, offset, range) = (nv.counter, nv.offset, a.slave.profile().range());
    if let Some(c) = CounterClass::of(counter).representatives().first() {
        a.slave.set_counter(*c);
    }
    let offset = canonical_offset(offset, range);
    if offset < range {
        // The raw position is 0 in the search: the preset is the offset.
        let raw = a.slave.inputs().position % range;
        a.slave.adopt_preset((offset + raw) % range);
    }
    a.slave.reset_eeprom_writes();
    a.now_us = phase_start(&a.slave, a.now_us);
    a
}

/// The worlds the search runs each event from for abstract world `a`: one per
/// representative of its counter's class.
pub fn representatives(a: &World) -> Vec<World> {
    let class = CounterClass::of(a.slave.nonvolatile().counter);
    if class == CounterClass::Beyond {
        return vec![a.clone()];
    }
    class
        .representatives()
        .iter()
        .map(|c| {
            let mut w = a.clone();
            w.slave.set_counter(*c);
            w
        })
        .collect()
}
