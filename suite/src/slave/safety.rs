//! Did the run leave the device as it found it? Two sources, kept apart:
//!
//! - **read back**: what the device reports of its stored state (Read Type Label's
//!   settings byte, Memory Status, every Data Field Status, the counter) before the
//!   catalogue and after it; a difference is a fact about the device;
//! - **bookkeeping**: the model in lockstep, for what cannot be read (access codes,
//!   the Set Position offset). Where the device chose within the documents' latitude
//!   the model adopted its choice, so a difference here is the harness's uncertainty.
//!
//! Neither is a verdict on the device: a conformant device follows the restoring
//! requests, and each of those is graded like any other request. This is the
//! operator's safety information, printed apart from the verdicts.

use super::ctx::{physical_time_us, Tally};
use crate::exchange::{sealed, Bus, Listen, LATE_REPLY_GRACE_MS};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::slave::powerup::CommState;
use hiperface_model::slave::NonVolatile;
use hiperface_model::{CommandId, Slave};
use serde::Serialize;

/// How long past a power-up state change the model predicts the harness waits before
/// it counts on the device being in the new state (reading it back here, probing a
/// window's edge in the cases): the device's clock started when it saw the reset, a
/// little off the harness's. A decision (docs/src/design.md, "Power-up margins"):
/// 20 ms tells a 100 ms initialization from a 140 ms one and the 1100 ms switch from
/// a 1050 ms one.
pub(crate) const SETTLE_MARGIN_US: u64 = 20_000;

/// What the device reports of its stored state; `None` where it did not answer.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Snapshot {
    pub settings: Option<u8>,
    pub memory: Option<(u8, u8)>,
    pub statuses: Option<Vec<u8>>,
    pub counter: Option<u32>,
}

impl Snapshot {
    /// Read it, ungraded, from the slave at `address`, in the settings the model says
    /// it listens with.
    pub(crate) fn read(master: &mut dyn Bus, model: &Slave, tally: &mut Tally) -> Snapshot {
        let address = model.nonvolatile().address.byte();
        // A run cut short in a power-up window (an interrupt during Encoder Reset's
        // wait) leaves the device initializing or switching its settings: wait, as the
        // model says, until it talks in its own settings again, so that it is read
        // back rather than missed (000:3.3.1, Figure 16: at most two changes ahead).
        for _ in 0..3 {
            let now = master.now_us();
            let settling = matches!(
                model.state(now),
                CommState::Initialization | CommState::DefaultCommunication | CommState::ChangeOfSettings
            );
            match model.next_deadline(now).filter(|_| settling) {
                // Past the change by a margin: the device's clock is not the model's.
                Some(t) if master.listen_until(t.max(now) + SETTLE_MARGIN_US).is_ok() => {}
                Some(_) => return Snapshot::default(),
                None => break,
            }
        }
        let now = master.now_us();
        if let Some(s) = model.listening_settings(now).filter(|s| *s != master.settings()) {
            if master.configure(s).is_err() {
                return Snapshot::default();
            }
        }
        // A probe waits for its reply as a case does (the limit three times over, and a
        // late reply's grace), so that a late reply is this probe's and not the next
        // request's. Once a probe has had no reply at all, the device may not be there:
        // the rest listen to their window only, so that a run without a device ends soon.
        let mut first = true;
        let mut ask = |body: &[u8]| -> Option<Response> {
            let frame = sealed(body);
            let command = CommandId::of_frame(body);
            let limits = model.profile().response_limit(command);
            let grace = first || tally.answered_any;
            first = false;
            let listen = Listen {
                reply_ms: crate::verdict::timing::reply_awaited_ms(limits),
                late_grace_ms: if grace { LATE_REPLY_GRACE_MS } else { 0 },
                ..Listen::default()
            };
            let x = master.exchange_listening(&frame, listen).ok()?;
            tally.line_time_us += physical_time_us(&x, limits.max_ms);
            let reply = x.reply_bytes()?;
            // A device that answered here is there, whatever the first case then hears.
            tally.answered_any = true;
            ResponseFrame::decode(&reply, command).ok().map(|r| r.response)
        };
        let settings = match ask(&[address, 0x52]) {
            Some(Response::TypeLabel { settings, .. }) => Some(settings),
            _ => None,
        };
        let memory = match ask(&[address, 0x4E]) {
            Some(Response::MemoryStatus { free_blocks, fields }) => Some((free_blocks, fields)),
            _ => None,
        };
        let statuses = memory.and_then(|(_, count)| {
            (0..count)
                .map(|n| match ask(&[address, 0x4C, n]) {
                    Some(Response::FieldStatus { status, .. }) => Some(status),
                    _ => None,
                })
                .collect::<Option<Vec<u8>>>()
        });
        let counter = match ask(&[address, 0x46]) {
            Some(Response::Counter(c)) => Some(c),
            _ => None,
        };
        Snapshot { settings, memory, statuses, counter }
    }

    /// Nothing was read: the device did not answer at all.
    pub fn is_empty(&self) -> bool {
        *self == Snapshot::default()
    }
}

/// The safety section of a report.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Safety {
    /// What the device reported the same before and after the run.
    pub verified: Vec<String>,
    /// What the device reported differently after the run (facts about the device).
    pub changed: Vec<String>,
    /// Where the harness's record of unreadable state differs (its uncertainty).
    pub bookkeeping: Vec<String>,
    /// What was read before the run and could not be read back after it, with why:
    /// neither changed nor restored as far as the harness knows.
    pub unverified: Vec<String>,
    /// Requests the harness ran to undo a case's changes the case did not undo itself.
    pub restores_run: usize,
    /// EEPROM writes, counted by the model in lockstep.
    pub eeprom_writes: u32,
    /// What the harness could not vouch for, per case.
    pub notes: Vec<String>,
}

impl Safety {
    /// Everything read before the run was read back unchanged, and the bookkeeping
    /// agrees.
    pub fn restored(&self) -> bool {
        self.changed.is_empty() && self.bookkeeping.is_empty() && self.unverified.is_empty()
    }

    /// Something differs after the run (read back, or in the harness's record).
    pub fn differs(&self) -> bool {
        !self.changed.is_empty() || !self.bookkeeping.is_empty()
    }

    /// Compare the state before and after a run (`after`: why it was not read back, if
    /// it was not). `counter_may_change`: the operator allowed cases that move the
    /// counter, which cannot be restored (000:T17, T18).
    pub fn compare(
        before: &Snapshot,
        after: Result<&Snapshot, &str>,
        model_before: &NonVolatile,
        model_after: &NonVolatile,
        counter_may_change: bool,
    ) -> Safety {
        let mut s = Safety::default();
        match after {
            Err(why) => s.read_back(before, &Snapshot::default(), counter_may_change, why),
            Ok(after) if after.is_empty() && !before.is_empty() => s.changed.push(format!(
                "the device no longer answers at address {:02X}h in the settings it started with",
                model_before.address.byte()
            )),
            Ok(after) => s.read_back(before, after, counter_may_change, "no answer after the run"),
        }
        if s.verified.is_empty() && s.changed.is_empty() && s.unverified.is_empty() {
            // A device that never answered: nothing is known, so nothing is "restored".
            s.unverified.push("nothing of the device's stored state could be read, before or after the run".into());
        }
        let (a, b) = (model_before, model_after);
        if a.address != b.address {
            s.bookkeeping.push(format!("address {:02X}h -> {:02X}h", a.address.byte(), b.address.byte()));
        }
        if a.settings != b.settings {
            s.bookkeeping.push(format!("stored settings {} -> {}", a.settings, b.settings));
        }
        for (n, (x, y)) in a.codes.iter().zip(&b.codes).enumerate() {
            if x != y {
                s.bookkeeping.push(format!("access code Code{n} {x:02X}h -> {y:02X}h"));
            }
        }
        if a.offset != b.offset {
            s.bookkeeping.push(format!("Set Position offset {} -> {}", a.offset, b.offset));
        }
        if a.fields.statuses() != b.fields.statuses() || a.fields.free_blocks() != b.fields.free_blocks() {
            s.bookkeeping.push(format!(
                "data fields {:02X?} ({} blocks free) -> {:02X?} ({} blocks free)",
                a.fields.statuses(),
                a.fields.free_blocks(),
                b.fields.statuses(),
                b.fields.free_blocks()
            ));
        }
        if a.counter != b.counter && !counter_may_change {
            s.bookkeeping.push(format!("counter {} -> {}", a.counter, b.counter));
        }
        s
    }

    /// `missing`: why an item read before is absent after.
    fn read_back(&mut self, before: &Snapshot, after: &Snapshot, counter_may_change: bool, missing: &str) {
        let mut item = |name: &str, a: Option<String>, b: Option<String>, may_change: bool| match (a, b) {
            (Some(a), Some(b)) if a == b => self.verified.push(format!("{name}: {a}")),
            (Some(a), Some(b)) if may_change => {
                self.notes.push(format!("{name}: {a} -> {b} (allowed by --allow-counter-change)"))
            }
            (Some(a), Some(b)) => self.changed.push(format!("{name}: {a} -> {b}")),
            (Some(a), None) => self.unverified.push(format!("{name}: {a} before the run, not read back ({missing})")),
            (None, _) => self.notes.push(format!("{name}: not readable")),
        };
        item(
            "stored settings (52h)",
            before.settings.map(|s| format!("{s:02X}h")),
            after.settings.map(|s| format!("{s:02X}h")),
            false,
        );
        let memory = |m: Option<(u8, u8)>| m.map(|(free, n)| format!("{free} blocks free, {n} fields"));
        item("memory status (4Eh)", memory(before.memory), memory(after.memory), false);
        let statuses = |s: &Option<Vec<u8>>| {
            s.as_ref().map(|v| match v.as_slice() {
                [] => "no data fields".to_string(),
                v => v.iter().map(|b| format!("{b:02X}h")).collect::<Vec<_>>().join(" "),
            })
        };
        item("data field statuses (4Ch)", statuses(&before.statuses), statuses(&after.statuses), false);
        item(
            "counter (46h)",
            before.counter.map(|c| c.to_string()),
            after.counter.map(|c| c.to_string()),
            counter_may_change,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::profiles;

    fn snapshot(counter: u32) -> Snapshot {
        Snapshot { settings: Some(0xE4), memory: Some((0x38, 0)), statuses: Some(vec![]), counter: Some(counter) }
    }

    #[test]
    fn read_back_facts_and_bookkeeping_stay_apart() {
        let model = Slave::operational(profiles::srs50());
        let nv = model.nonvolatile().clone();
        let s = Safety::compare(&snapshot(5), Ok(&snapshot(5)), &nv, &nv, false);
        assert!(s.restored() && s.changed.is_empty() && s.verified.len() == 4, "{s:?}");
        let s = Safety::compare(&snapshot(5), Ok(&snapshot(6)), &nv, &nv, false);
        assert_eq!(s.changed, vec!["counter (46h): 5 -> 6".to_string()]);
        let s = Safety::compare(&snapshot(5), Ok(&snapshot(6)), &nv, &nv, true);
        assert!(s.restored(), "an allowed counter change is a note: {s:?}");
        let mut moved = nv.clone();
        moved.offset = 4660;
        let s = Safety::compare(&snapshot(5), Ok(&snapshot(5)), &nv, &moved, false);
        assert_eq!(s.bookkeeping, vec!["Set Position offset 0 -> 4660".to_string()]);
        let s = Safety::compare(&snapshot(5), Ok(&Snapshot::default()), &nv, &nv, false);
        assert!(s.changed[0].contains("no longer answers at address 40h"), "{s:?}");
        // Not read back: neither "restored" nor "changed", and why.
        let s = Safety::compare(&snapshot(5), Err("the device stopped answering"), &nv, &nv, false);
        assert!(!s.restored() && !s.differs(), "{s:?}");
        assert_eq!(s.unverified.len(), 4, "{s:?}");
        assert!(
            s.unverified[3].contains("counter (46h): 5 before the run, not read back (the device stopped answering)")
        );
        let partly = Snapshot { counter: None, ..snapshot(5) };
        let s = Safety::compare(&snapshot(5), Ok(&partly), &nv, &nv, false);
        assert!(!s.restored() && s.verified.len() == 3 && s.unverified.len() == 1, "{s:?}");
        // A device that never answered is not "restored".
        let s = Safety::compare(&Snapshot::default(), Err("the device has not answered"), &nv, &nv, false);
        assert!(!s.restored() && !s.differs() && s.unverified[0].contains("nothing"), "{s:?}");
    }
}
