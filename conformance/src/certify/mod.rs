//! Certify a slave: run the case catalogue against a device under test, with the
//! model's oracle in lockstep grading every answer and its timing.

pub mod cases;

use crate::line::{Line, LineError};
use crate::master::{Exchange, Master};
use hiperface_model::oracle::Verdict;
use hiperface_model::{checksum, CommandId, Hex, Knowledge, Oracle, Profile, Reply, Slave};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// A case's verdict. PASS and NON-STRICT pass certification; FAIL does not; ERROR
/// means the harness could not run the case; NOT-APPLICABLE, that the profile or
/// the options exclude it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "SCREAMING-KEBAB-CASE")]
pub enum CaseVerdict {
    Pass,
    NonStrict,
    Fail,
    NotApplicable,
    Error,
}

impl CaseVerdict {
    /// Severity for "worst of": FAIL > ERROR > NON-STRICT > PASS.
    fn rank(self) -> u8 {
        match self {
            CaseVerdict::Pass | CaseVerdict::NotApplicable => 0,
            CaseVerdict::NonStrict => 1,
            CaseVerdict::Error => 2,
            CaseVerdict::Fail => 3,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            CaseVerdict::Pass => "PASS",
            CaseVerdict::NonStrict => "NON-STRICT",
            CaseVerdict::Fail => "FAIL",
            CaseVerdict::NotApplicable => "NOT-APPLICABLE",
            CaseVerdict::Error => "ERROR",
        }
    }
}

impl From<Verdict> for CaseVerdict {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Pass => CaseVerdict::Pass,
            Verdict::NonStrict => CaseVerdict::NonStrict,
            Verdict::Fail => CaseVerdict::Fail,
        }
    }
}

/// What a case may do to the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Needs {
    /// Reads only.
    Nothing,
    /// EEPROM writes, all restored by the case.
    Writes,
    /// Changes the counter, which cannot be restored (000:T17, T18).
    CounterChange,
}

/// Options of a run.
#[derive(Debug, Clone)]
pub struct Options {
    pub allow_writes: bool,
    pub allow_counter_change: bool,
    /// At most this many EEPROM writes (counted by the model in lockstep).
    pub write_budget: u32,
    /// Only cases whose id matches this glob (`*` and `?`).
    pub cases: Option<String>,
    pub knowledge: Knowledge,
    /// Set (e.g. by Ctrl-C) to stop the run: pending restores still run.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// What the lockstep model knows of the device's world (a simulator's inputs and
    /// start-up faults); empty for real devices.
    pub world: World,
}

/// The device's physical inputs and the faults it found at start-up.
#[derive(Debug, Clone, Default)]
pub struct World {
    pub inputs: Option<hiperface_model::slave::inputs::PhysicalInputs>,
    pub init_faults: Vec<hiperface_model::slave::inputs::InitFault>,
}

impl World {
    /// Bring a model into this world: inputs set, start-up faults found.
    pub fn apply(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        if !self.init_faults.is_empty() {
            for f in &self.init_faults {
                model.inject_init_fault(*f, true);
            }
            model.power_cycle(0);
            model.settle();
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            allow_writes: false,
            allow_counter_change: false,
            write_budget: 200,
            cases: None,
            knowledge: Knowledge::Exact,
            interrupt: None,
            world: World::default(),
        }
    }
}

/// One statement of a case's result.
#[derive(Debug, Clone, Serialize)]
pub struct Finding {
    pub verdict: CaseVerdict,
    pub message: String,
    pub clause: String,
}

/// One line of the wire log.
#[derive(Debug, Clone, Serialize)]
pub struct WireEntry {
    /// µs since the run started (receive time of the last character for requests,
    /// start of the first character for replies).
    pub t_us: u64,
    pub direction: &'static str,
    pub bytes: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    pub id: &'static str,
    pub title: &'static str,
    pub clauses: Vec<&'static str>,
    pub verdict: CaseVerdict,
    pub findings: Vec<Finding>,
    pub exchanges: usize,
    pub wire: Vec<WireEntry>,
    pub duration_ms: f64,
}

/// A case of the catalogue.
pub struct Case {
    pub id: &'static str,
    pub title: &'static str,
    pub clauses: &'static [&'static str],
    pub needs: Needs,
    /// `Some(reason)` when the profile excludes the case.
    pub applies: fn(&Profile) -> Option<&'static str>,
    pub run: fn(&mut Ctx<'_>) -> Result<(), CaseError>,
}

/// Why a case stopped early.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("{0}")]
    Line(#[from] LineError),
    /// The case cannot go on (e.g. a precondition failed); already recorded.
    #[error("{0}")]
    Abort(String),
    #[error("EEPROM write budget of {0} exhausted")]
    Budget(u32),
    #[error("the device has not answered any request: check the port, power, address and data rate")]
    Silent,
    #[error("interrupted")]
    Interrupted,
}

/// Response-time statistics of one command.
#[derive(Debug, Clone, Serialize)]
pub struct TimingStats {
    pub command: String,
    pub count: usize,
    pub min_us: i64,
    pub median_us: i64,
    pub max_us: i64,
}

/// What a case sees: the master on the line and the model in lockstep.
pub struct Ctx<'a> {
    master: &'a mut Master<Box<dyn Line>>,
    pub model: &'a mut Slave,
    oracle: Oracle,
    result: &'a mut CaseResult,
    response_times: &'a mut BTreeMap<u8, Vec<i64>>,
    pub(crate) physical_min_us: &'a mut u64,
    options: &'a Options,
    /// The device has answered at least once in this run.
    answered_any: &'a mut bool,
    /// Requests that undo this case's changes, last first, run by the runner if the
    /// case does not release them itself.
    guards: Vec<(u64, Vec<u8>)>,
    next_guard: u64,
    restoring: bool,
}

/// A pending restore, released by the case once it has restored by itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use = "release the guard once the case has restored"]
pub struct Guard(u64);

/// A graded exchange.
pub struct Graded {
    pub exchange: Exchange,
    pub verdict: CaseVerdict,
    pub reply: Option<Vec<u8>>,
}

impl Ctx<'_> {
    pub fn profile(&self) -> Profile {
        *self.model.profile()
    }

    pub fn address(&self) -> u8 {
        self.model.nonvolatile().address.byte()
    }

    /// Record a finding; the case verdict is the worst of its findings.
    pub fn finding(&mut self, verdict: CaseVerdict, message: impl Into<String>, clause: &str) {
        if verdict.rank() > self.result.verdict.rank() {
            self.result.verdict = verdict;
        }
        self.result.findings.push(Finding { verdict, message: message.into(), clause: clause.to_string() });
    }

    /// A harness-level check (e.g. data read back equals data stored).
    pub fn check(&mut self, ok: bool, message: impl Into<String>, clause: &str) {
        if !ok {
            self.finding(CaseVerdict::Fail, message, clause);
        }
    }

    /// Register a request (body without checksum) that undoes a change just made.
    pub fn guard(&mut self, undo: Vec<u8>) -> Guard {
        self.next_guard += 1;
        self.guards.push((self.next_guard, undo));
        Guard(self.next_guard)
    }

    /// The case restored by itself: drop the guard.
    pub fn release(&mut self, guard: Guard) {
        self.guards.retain(|(id, _)| *id != guard.0);
    }

    /// Run the pending guards, last first.
    fn restore(&mut self) -> Result<usize, CaseError> {
        self.restoring = true;
        let mut n = 0;
        while let Some((_, undo)) = self.guards.pop() {
            self.ask(&undo)?;
            n += 1;
        }
        Ok(n)
    }

    /// Send a body with its checksum appended; grade the answer.
    pub fn ask(&mut self, body: &[u8]) -> Result<Graded, CaseError> {
        let mut frame = body.to_vec();
        frame.push(checksum::xor(body));
        self.send_frame(&frame)
    }

    /// Send a frame as it is (for malformed frames); grade the answer.
    pub fn send_frame(&mut self, frame: &[u8]) -> Result<Graded, CaseError> {
        if !self.restoring && self.options.interrupt.as_ref().is_some_and(|f| f.load(Ordering::Relaxed)) {
            return Err(CaseError::Interrupted);
        }
        // Talk in the settings the slave listens with now (67h, reset, power-up windows).
        let now = self.master.now_us();
        if let Some(s) = self.model.listening_settings(now).filter(|s| *s != self.master.line.settings()) {
            self.master.line.configure(s)?;
        }
        let command = frame.get(1).map(|b| CommandId::decode(b & 0x7F));
        let spec = command.and_then(|c| c.spec());
        let max_ms = match spec {
            Some(s) if s.id == CommandId::SensorAdjustment => self.model.profile().adjustment_response_ms,
            Some(s) => s.max_response_ms.unwrap_or(5),
            None => 5,
        };
        let before = self.model.clone();
        // Where the model expects a reply, listen well past the limit so that a late
        // reply is measured and graded; where it expects silence, only to the limit.
        let estimate = self.master.now_us()
            + frame.len() as u64 * self.master.line.settings().char_time_us()
            + self.master.timeout_us();
        let expects_reply = matches!(before.clone().handle_frame(frame, estimate).reply, Reply::Frame(_));
        let listen_ms = if expects_reply { (3 * max_ms).max(max_ms + 100) } else { max_ms };
        let x = self.master.exchange(frame, listen_ms)?;
        let expected = self.model.handle_frame(frame, x.complete_us);
        if self.model.eeprom_writes() > self.options.write_budget {
            return Err(CaseError::Budget(self.options.write_budget));
        }
        let observed = x.reply_bytes();
        *self.answered_any |= observed.is_some();
        if !*self.answered_any && matches!(expected.reply, Reply::Frame(_)) {
            // Never a word from the device: it is not there, not powered, or at another
            // address or data rate. The harness cannot run the case.
            return Err(CaseError::Silent);
        }
        let grade = self.oracle.grade(&before, frame, x.complete_us, &expected, observed.as_deref());
        let mut verdict: CaseVerdict = grade.verdict.into();
        self.result.exchanges += 1;
        self.result.wire.push(WireEntry { t_us: x.sent_end_us, direction: "M>", bytes: Hex(frame).to_string() });
        if let (Some(bytes), Some(start)) = (&observed, x.reply_start_us()) {
            self.result.wire.push(WireEntry { t_us: start, direction: "S<", bytes: Hex(bytes).to_string() });
        }
        if verdict != CaseVerdict::Pass {
            let reason = grade.deviation.map_or(String::new(), |d| d.to_string());
            self.finding(verdict, format!("request [{}]: {reason}", Hex(frame)), grade.clause);
        }
        if !x.stray.is_empty() {
            let bytes: Vec<u8> = x.stray.iter().map(|c| c.byte).collect();
            let msg = format!("{} characters [{}] arrived outside any reply", bytes.len(), Hex(&bytes));
            self.finding(CaseVerdict::Fail, msg, "000:2.2.1");
            verdict = CaseVerdict::Fail;
        }
        let ct = x.settings.char_time_us();
        // The request on the wire and the slave's timeout after it, from the wire log.
        let request_and_timeout = x.complete_us.saturating_sub(x.sent_start_us);
        match (x.response_time_us(), matches!(expected.reply, Reply::Frame(_))) {
            (Some(rt), true) => {
                let tol = self.master.line.tolerance_us() as i64;
                if rt + tol < 0 {
                    let msg = format!("reply started {} µs before the request's timeout elapsed", -rt);
                    self.finding(CaseVerdict::Fail, msg, "000:2.2.2");
                    verdict = CaseVerdict::Fail;
                } else if rt > max_ms as i64 * 1000 + tol {
                    let msg = format!(
                        "reply started {:.3} ms after the request's timeout; the limit is {max_ms} ms",
                        rt as f64 / 1000.0
                    );
                    self.finding(CaseVerdict::Fail, msg, "000:T10");
                    verdict = CaseVerdict::Fail;
                } else if let Some(strict) = spec.and_then(|s| s.strict_response_ms) {
                    if rt > strict as i64 * 1000 + tol {
                        let msg = format!(
                            "reply after {:.3} ms: within Table 10's limit, beyond Table 36's {strict} ms",
                            rt as f64 / 1000.0
                        );
                        self.finding(CaseVerdict::NonStrict, msg, "000:T36");
                    }
                }
                if let Some(cmd) = command {
                    self.response_times.entry(cmd.byte()).or_default().push(rt);
                }
                let reply_wire = x.reply.len() as u64 * ct;
                *self.physical_min_us += request_and_timeout + rt.max(0) as u64 + reply_wire + x.timeout_us;
            }
            _ => {
                // Silence is only known once a reply can no longer start: the request,
                // its timeout, the whole response time and one character.
                *self.physical_min_us += request_and_timeout + max_ms as u64 * 1000 + ct;
            }
        }
        if let Some(s) = expected.then_settings {
            self.master.line.configure(s)?;
        }
        Ok(Graded { exchange: x, verdict, reply: observed })
    }

    /// Wait, with nothing on the line; anything that arrives is a FAIL.
    pub fn wait_ms(&mut self, ms: u64) -> Result<(), CaseError> {
        let until = self.master.now_us() + ms * 1000;
        let got = self.master.listen_until(until)?;
        *self.physical_min_us += ms * 1000;
        if !got.is_empty() {
            let bytes: Vec<u8> = got.iter().map(|c| c.byte).collect();
            self.finding(CaseVerdict::Fail, format!("unsolicited characters [{}]", Hex(&bytes)), "000:2.2.1");
        }
        Ok(())
    }

    /// Now on the line's clock, µs.
    pub fn now_us(&mut self) -> u64 {
        self.master.now_us()
    }

    pub fn allow_counter_change(&self) -> bool {
        self.options.allow_counter_change
    }
}

/// The result of a whole run.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub tool: String,
    pub profile: String,
    pub edition: String,
    pub line: String,
    pub knowledge: String,
    pub identity: Identity,
    pub cases: Vec<CaseResult>,
    pub summary: BTreeMap<&'static str, usize>,
    pub response_times: Vec<TimingStats>,
    pub eeprom_writes: u32,
    pub wall_time_ms: f64,
    pub physical_minimum_ms: f64,
    pub notes: Vec<String>,
    /// Set when the run stopped early (port gone, Ctrl-C): the report is partial.
    pub aborted: Option<String>,
}

/// What the device said of itself.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Identity {
    pub type_label: Option<String>,
    pub serial: Option<String>,
    pub firmware: Option<String>,
    pub firmware_date: Option<String>,
}

impl Report {
    /// The report of a run that could not start (e.g. the port cannot be opened).
    pub fn aborted_before_start(profile: &Profile, line: &str, reason: &str) -> Report {
        Report {
            tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
            profile: profile.name.to_string(),
            edition: format!("{:?}", profile.edition),
            line: line.to_string(),
            knowledge: String::new(),
            identity: Identity::default(),
            cases: Vec::new(),
            summary: BTreeMap::new(),
            response_times: Vec::new(),
            eeprom_writes: 0,
            wall_time_ms: 0.0,
            physical_minimum_ms: 0.0,
            notes: Vec::new(),
            aborted: Some(reason.to_string()),
        }
    }

    /// No case FAILed.
    pub fn passed(&self) -> bool {
        self.cases.iter().all(|c| c.verdict != CaseVerdict::Fail) && self.aborted.is_none()
    }
}

/// `*` and `?` glob matching for `--cases`.
pub fn glob_match(pattern: &str, text: &str) -> bool {
    fn go(p: &[u8], t: &[u8]) -> bool {
        match (p.first(), t.first()) {
            (None, None) => true,
            (Some(b'*'), _) => go(&p[1..], t) || (!t.is_empty() && go(p, &t[1..])),
            (Some(b'?'), Some(_)) => go(&p[1..], &t[1..]),
            (Some(a), Some(b)) if a == b => go(&p[1..], &t[1..]),
            _ => false,
        }
    }
    pattern.split(',').any(|p| go(p.trim().as_bytes(), text.as_bytes()))
}

/// Run the catalogue. `progress` is called after each case.
pub fn run(
    line: Box<dyn Line>,
    profile: Profile,
    options: &Options,
    mut progress: impl FnMut(usize, usize, &CaseResult),
) -> Report {
    let started = Instant::now();
    let edition = profile.edition;
    let line_name = line.describe();
    let mut master = Master::new(line, edition);
    let mut model = Slave::operational(profile);
    options.world.apply(&mut model);
    let mut response_times = BTreeMap::new();
    let mut physical_min_us = 0u64;
    // A real device is not in its factory state: adopt what it reports.
    let mut adopted = None;
    if options.knowledge == Knowledge::PhysicalUnknown {
        adopted = discover(&mut master, &mut model);
    }
    let catalogue = cases::catalogue();
    let selected: Vec<&Case> =
        catalogue.iter().filter(|c| options.cases.as_deref().is_none_or(|g| glob_match(g, c.id))).collect();
    let mut results = Vec::new();
    let mut aborted = None;
    let mut identity = Identity::default();
    let mut answered_any = false;
    let mut restored = 0usize;
    let initial = model.nonvolatile().clone();
    for (i, case) in selected.iter().enumerate() {
        let mut result = CaseResult {
            id: case.id,
            title: case.title,
            clauses: case.clauses.to_vec(),
            verdict: CaseVerdict::Pass,
            findings: Vec::new(),
            exchanges: 0,
            wire: Vec::new(),
            duration_ms: 0.0,
        };
        let case_start = Instant::now();
        let excluded = (case.applies)(&profile).map(str::to_string).or_else(|| match case.needs {
            Needs::Writes if !options.allow_writes => Some("writes EEPROM; run with --allow-writes".into()),
            Needs::CounterChange if !options.allow_counter_change => {
                Some("changes the counter, which cannot be restored; run with --allow-counter-change".into())
            }
            _ => None,
        });
        if let Some(reason) = excluded {
            result.verdict = CaseVerdict::NotApplicable;
            result.findings.push(Finding {
                verdict: CaseVerdict::NotApplicable,
                message: reason,
                clause: String::new(),
            });
        } else if aborted.is_some() {
            result.verdict = CaseVerdict::Error;
            result.findings.push(Finding {
                verdict: CaseVerdict::Error,
                message: format!("not run: {}", aborted.as_deref().unwrap_or("")),
                clause: String::new(),
            });
        } else {
            let mut ctx = Ctx {
                master: &mut master,
                model: &mut model,
                oracle: Oracle::new(options.knowledge),
                result: &mut result,
                response_times: &mut response_times,
                physical_min_us: &mut physical_min_us,
                options,
                answered_any: &mut answered_any,
                guards: Vec::new(),
                next_guard: 0,
                restoring: false,
            };
            let outcome = (case.run)(&mut ctx);
            let line_gone = matches!(outcome, Err(CaseError::Line(LineError::Gone(_))) | Err(CaseError::Silent));
            if let Err(e) = &outcome {
                ctx.finding(CaseVerdict::Error, e.to_string(), "");
                if !matches!(e, CaseError::Abort(_)) {
                    aborted = Some(e.to_string());
                }
            }
            // DESIGN (safety): restore what the case changed, also after a failure or Ctrl-C.
            if !line_gone && !ctx.guards.is_empty() {
                match ctx.restore() {
                    Ok(n) => restored += n,
                    Err(e) => ctx.finding(CaseVerdict::Error, format!("restore failed: {e}"), "DESIGN:safety"),
                }
            }
            if case.id == "identity.type-label" || case.id == "identity.version" {
                identity_from(&result, &mut identity);
            }
        }
        result.duration_ms = case_start.elapsed().as_secs_f64() * 1000.0;
        progress(i + 1, selected.len(), &result);
        results.push(result);
    }
    // The model follows the device in lockstep: its EEPROM state at the end must be
    // the state at the start (the counter may have moved where allowed).
    let mut end = model.nonvolatile().clone();
    if options.allow_counter_change {
        end.counter = initial.counter;
    }
    let mut safety = CaseResult {
        id: "safety.restored",
        title: "The run leaves the device as it found it",
        clauses: vec!["DESIGN:safety"],
        verdict: CaseVerdict::Pass,
        findings: Vec::new(),
        exchanges: 0,
        wire: Vec::new(),
        duration_ms: 0.0,
    };
    if end != initial {
        safety.verdict = CaseVerdict::Fail;
        safety.findings.push(Finding {
            verdict: CaseVerdict::Fail,
            message: format!("EEPROM state changed: before {initial:?}, after {end:?}"),
            clause: "DESIGN:safety".into(),
        });
    }
    results.push(safety);
    let mut summary = BTreeMap::new();
    for r in &results {
        *summary.entry(r.verdict.label()).or_insert(0) += 1;
    }
    let response_times = response_times
        .into_iter()
        .map(|(cmd, mut v)| {
            v.sort_unstable();
            TimingStats {
                command: CommandId::decode(cmd).to_string(),
                count: v.len(),
                min_us: v[0],
                median_us: v[v.len() / 2],
                max_us: v[v.len() - 1],
            }
        })
        .collect();
    Report {
        tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
        profile: profile.name.to_string(),
        edition: format!("{:?}", profile.edition),
        line: line_name,
        knowledge: format!("{:?}", options.knowledge),
        identity,
        cases: results,
        summary,
        response_times,
        eeprom_writes: model.eeprom_writes(),
        wall_time_ms: started.elapsed().as_secs_f64() * 1000.0,
        physical_minimum_ms: physical_min_us as f64 / 1000.0,
        notes: adopted
            .into_iter()
            .chain([format!("Restores run by the harness after a case did not restore by itself: {restored}.")])
            .chain([
            "Power cycling is out of reach on a serial line: the power-up cases start from an Encoder Reset (53h), which 000:T29 says leads to the same initialization as power-on.".into(),
            ])
            .collect(),
        aborted,
    }
}

/// Read a real device's data field table and counter (ungraded) and let the lockstep
/// model adopt them; a note for the report, or `None` if the device did not tell.
fn discover(master: &mut Master<Box<dyn Line>>, model: &mut Slave) -> Option<String> {
    let a = model.nonvolatile().address.byte();
    let mut ask = |body: &[u8]| -> Option<Vec<u8>> {
        let mut f = body.to_vec();
        f.push(checksum::xor(body));
        let x = master.exchange(&f, 30).ok()?;
        let r = x.reply_bytes()?;
        (r.len() >= 3 && checksum::is_valid(&r) && r[1] & 0x7F == body[1]).then_some(r)
    };
    let memory = ask(&[a, 0x4E])?;
    let (free, count) = (*memory.get(2)?, *memory.get(3)?);
    let mut statuses = Vec::new();
    for n in 0..count {
        statuses.push(*ask(&[a, 0x4C, n])?.get(3)?);
    }
    let counter = ask(&[a, 0x46]).and_then(|r| Some(u32::from_be_bytes([0, *r.get(2)?, *r.get(3)?, *r.get(4)?])));
    let counter_value = counter.unwrap_or(0);
    model.adopt(&statuses, free, counter_value).then(|| {
        format!(
            "Adopted from the device before the catalogue: {count} data fields, {free} free blocks, counter {}.",
            counter.map_or("unknown".into(), |c| c.to_string())
        )
    })
}

fn identity_from(result: &CaseResult, identity: &mut Identity) {
    for w in result.wire.iter().filter(|w| w.direction == "S<") {
        let bytes: Vec<u8> = w.bytes.split(' ').filter_map(|b| u8::from_str_radix(b, 16).ok()).collect();
        match bytes.get(1) {
            Some(0x52) | Some(0xD2) => identity.type_label = Some(w.bytes.clone()),
            Some(0x56) | Some(0xD6) if bytes.len() == 40 => {
                let text =
                    |r: std::ops::Range<usize>| String::from_utf8_lossy(&bytes[r]).trim_end_matches('\0').to_string();
                identity.serial = Some(text(2..11));
                identity.firmware = Some(text(11..31));
                identity.firmware_date = Some(text(31..39));
            }
            _ => {}
        }
    }
}
