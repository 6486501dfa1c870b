//! Source mutants of the master: the mutated copy's reference master (one switch on)
//! certified in-process with the whole scenario catalogue, as `certify master` grades a
//! drive, against the unmutated encoder, observer and obligations.
//!
//! The reference master is sans-IO (`master::reference`: actions and what they gave);
//! [`MutatedMaster`] does what its actions say on the in-process line, as the harness's
//! `hiperface master` does on a port: a request once the line has been quiet for the
//! slave's timeout (000:2.2.2), its reply framed by the same timeout and listened for
//! until the command's limit and the master's margin have passed.

use crate::certify::{self, Verdicts};
use crate::device::guarded;
use hiperface_model::datalink::RxChar;
use hiperface_model::{Profile, UartSettings};
use hiperface_model_mutated as dut;
use hiperface_model_mutated::master::reference::{Action, Done, ReferenceMaster};
use hiperface_model_mutated::mutant;
use hiperface_suite::master::in_process::{self, MasterAction, MasterUnderTest, Transmit};
use hiperface_suite::master::DriveReport;
use hiperface_suite::verdict::CaseVerdict;

/// The files of the encoder's family whose code the master runs too (it encodes its
/// requests and decodes the replies with them, and reads the profile): their mutants
/// make defective masters as well.
pub const SHARED: [&str; 7] = [
    "model/src/address.rs",
    "model/src/checksum.rs",
    "model/src/command.rs",
    "model/src/frame.rs",
    "model/src/profile.rs",
    "model/src/request.rs",
    "model/src/response.rs",
];

/// The polling period the harness's `hiperface master` uses by default, ms.
pub const POLLING_PERIOD_MS: u64 = 20;

/// Where the driver is between two of the master's actions.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Line {
    /// Waiting for `until` (an action's wait).
    Waiting { until: u64 },
    /// A request waiting for the line to be quiet.
    Ready { bytes: Vec<u8>, listen_ms: u16 },
    /// The request sent, its reply listened for.
    Listening { request_end: u64, window_end: u64, reply: Vec<RxChar> },
    /// The master's run is over, or it crashed.
    Stopped,
}

/// The mutated copy's reference master, driven on the in-process line.
pub struct MutatedMaster {
    profile: Profile,
    /// Its period of Read Position, ms.
    polling_period_ms: u64,
    machine: Option<ReferenceMaster>,
    line: Line,
    /// When the line was last busy (a character ended), µs.
    busy_until: u64,
    /// Why the master crashed (a panic of the mutated copy), if it did.
    pub crashed: Option<String>,
}

/// The slave's frame timeout at the default settings the reference master keeps, µs:
/// from the unmutated model (the line's, not the master's).
fn timeout_us(profile: &Profile) -> u64 {
    UartSettings::DEFAULT.timeout_us(profile.edition)
}

impl MutatedMaster {
    pub fn new(profile: Profile) -> MutatedMaster {
        MutatedMaster {
            profile,
            polling_period_ms: POLLING_PERIOD_MS,
            machine: None,
            line: Line::Stopped,
            busy_until: 0,
            crashed: None,
        }
    }

    /// Read Position every `ms` instead.
    pub fn polling_every(mut self, ms: u64) -> MutatedMaster {
        self.polling_period_ms = ms;
        self
    }

    /// Tell the machine what its action gave; the next action.
    fn next(&mut self, done: Done<'_>) -> Option<Action> {
        let machine = self.machine.as_mut()?;
        match guarded(|| machine.next(done, &mut |_| {})) {
            Ok(a) => Some(a),
            Err(why) => {
                self.crashed = Some(why);
                self.machine = None;
                None
            }
        }
    }

    /// Take up an action at `now`.
    fn take(&mut self, action: Option<Action>) {
        self.line = match action {
            Some(Action::WaitUntil(t)) => Line::Waiting { until: t },
            Some(Action::Exchange { request, listen_ms }) => match guarded(|| request.encode().as_bytes().to_vec()) {
                Ok(bytes) => Line::Ready { bytes, listen_ms },
                Err(why) => {
                    self.crashed = Some(why);
                    Line::Stopped
                }
            },
            Some(Action::Stop) | None => Line::Stopped,
        };
    }
}

impl MasterUnderTest for MutatedMaster {
    fn power_on(&mut self) {
        self.crashed = None;
        self.busy_until = 0;
        let Some(dp) = crate::device::dut_profile(&self.profile) else {
            self.machine = None;
            self.line = Line::Stopped;
            return;
        };
        let options = dut::master::reference::Options { polling_period_ms: self.polling_period_ms, duration_ms: None };
        match guarded(|| {
            let mut m = ReferenceMaster::new(dp, options);
            let first = m.power_on();
            (m, first)
        }) {
            Ok((m, first)) => {
                self.machine = Some(m);
                self.take(Some(first));
            }
            Err(why) => {
                self.crashed = Some(why);
                self.machine = None;
                self.line = Line::Stopped;
            }
        }
    }

    fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction {
        let timeout = timeout_us(&self.profile);
        if let Some(last) = heard.last() {
            self.busy_until = self.busy_until.max(last.at_us);
        }
        if let Line::Listening { reply, .. } = &mut self.line {
            reply.extend_from_slice(heard);
        }
        // Act until the master waits for something later than now.
        for _ in 0..64 {
            match self.line.clone() {
                Line::Stopped => return MasterAction::default(),
                Line::Waiting { until } if now_us < until => {
                    return MasterAction { send: None, wake_us: Some(until) };
                }
                Line::Waiting { .. } => {
                    let a = self.next(Done::Waited { now_us });
                    self.take(a);
                }
                Line::Ready { bytes, listen_ms } => {
                    let ready = self.busy_until + timeout;
                    if now_us < ready {
                        return MasterAction { send: None, wake_us: Some(ready) };
                    }
                    let ct = UartSettings::DEFAULT.char_time_us();
                    let request_end = now_us + bytes.len() as u64 * ct;
                    self.busy_until = request_end;
                    let window_end = request_end + timeout + u64::from(listen_ms) * 1000;
                    self.line = Line::Listening { request_end, window_end, reply: Vec::new() };
                    return MasterAction {
                        send: Some(Transmit {
                            bytes,
                            start_us: now_us,
                            bps: UartSettings::DEFAULT.baud.bits_per_second(),
                        }),
                        wake_us: Some(window_end),
                    };
                }
                Line::Listening { request_end, window_end, reply } => {
                    // The reply ends a timeout after its last character (000:2.2.2).
                    let ends = reply.last().map(|c| c.at_us + timeout);
                    let over = match ends {
                        Some(t) => now_us >= t,
                        None => now_us >= window_end,
                    };
                    if !over {
                        return MasterAction { send: None, wake_us: Some(ends.unwrap_or(window_end)) };
                    }
                    let bytes: Vec<u8> = reply.iter().map(|c| c.byte).collect();
                    let a = self.next(Done::Exchanged {
                        now_us,
                        request_end_us: request_end,
                        timeout_us: timeout,
                        reply: &bytes,
                    });
                    self.take(a);
                }
            }
        }
        MasterAction::default()
    }
}

/// Certify the master with switch `id` on against an encoder of `profile`.
pub fn certify_master(id: u32, profile: Profile) -> (DriveReport, Option<String>) {
    mutant::activate(id);
    let mut m = MutatedMaster::new(profile);
    let report = in_process::run(&mut m, "a mutant of the reference master", profile, &in_process::Options::default());
    mutant::activate(0);
    (report, m.crashed)
}

/// The profiles a master is certified against.
fn profiles() -> Vec<Profile> {
    vec![
        hiperface_model::profiles::srs50(),
        hiperface_model::profiles::sek37(),
        hiperface_model::profiles::legacy_srs(),
    ]
}

/// The conformant master's reports.
pub struct Baselines {
    reports: Vec<(Profile, DriveReport)>,
}

impl Baselines {
    pub fn new() -> Baselines {
        Baselines { reports: profiles().into_iter().map(|p| (p, certify_master(0, p).0)).collect() }
    }

    /// The profiles where the conformant master did not PASS, with its findings.
    pub fn not_passed(&self) -> Vec<String> {
        self.reports
            .iter()
            .filter(|(_, r)| !r.outcome().passed())
            .map(|(p, r)| {
                let bad: Vec<String> = r
                    .scenarios
                    .iter()
                    .filter(|s| !matches!(s.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable))
                    .flat_map(|s| {
                        s.findings.iter().map(move |f| format!("{} {}: {}", s.id, f.verdict().label(), f.message()))
                    })
                    .collect();
                format!("{}: {}", p.name.as_str(), bad.join("; "))
            })
            .collect()
    }

    pub fn certify(&mut self, id: u32) -> Verdicts {
        let best = certify::until_fail(&self.reports, None, |(p, baseline)| {
            let (report, crashed) = certify_master(id, *p);
            let aborted = report.cut_short.clone();
            certify::compare_results(
                p.name.as_str(),
                &report.scenarios,
                &baseline.scenarios,
                aborted.as_deref(),
                crashed,
            )
        });
        best.unwrap_or_else(|| Verdicts::unbuildable("-", "no profile".into()))
    }
}

impl Default for Baselines {
    fn default() -> Self {
        Baselines::new()
    }
}

/// The ids of master mutants whose place the conformant master ran.
pub fn reached() -> Vec<u32> {
    mutant::activate(0);
    mutant::forget_reached();
    let _ = Baselines::new();
    mutant::ALL.iter().map(|m| m.id).filter(|id| mutant::reached(*id)).collect()
}
