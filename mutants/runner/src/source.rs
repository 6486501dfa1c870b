//! Source mutants of the encoder: the mutated model with one switch on, certified in
//! the configurations of [`configs`] sweep after sweep until one FAILs.

use crate::certify::{self, Caught, Verdicts};
use crate::configs::{self, Config};
use crate::device::MutatedEncoder;
use hiperface_model_mutated::mutant;
use hiperface_suite::slave::Report;

/// A sweep: configurations with the conformant device's report in each.
type Sweep = Vec<(Config, Report)>;

/// The conformant device's reports, sweep by sweep (the baseline a mutant is compared
/// with); the later sweeps are run when a mutant first needs them.
pub struct Baselines {
    sweeps: [Option<Sweep>; 3],
}

/// The configurations of sweep `i`: shipped, in worlds, every setting.
fn sweep_configs(i: usize) -> Vec<Config> {
    match i {
        0 => configs::shipped(),
        1 => configs::in_worlds(),
        _ => configs::every_setting(),
    }
}

impl Baselines {
    pub fn new() -> Baselines {
        Baselines { sweeps: [None, None, None] }
    }

    /// The ids of the places the conformant device ran, in every sweep.
    pub fn reached() -> Vec<u32> {
        mutant::activate(0);
        mutant::forget_reached();
        let mut b = Baselines::new();
        for i in 0..3 {
            b.sweep(i);
        }
        mutant::ALL.iter().map(|m| m.id).filter(|id| mutant::reached(*id)).collect()
    }

    /// The configurations where the conformant device did not PASS (there must be none).
    pub fn not_passed(&mut self) -> Vec<String> {
        (0..3)
            .flat_map(|i| {
                self.sweep(i)
                    .iter()
                    .filter(|(_, r)| !r.outcome().passed())
                    .map(|(c, r)| {
                        let bad: Vec<String> = r
                            .cases
                            .iter()
                            .filter(|x| {
                                !matches!(
                                    x.verdict,
                                    hiperface_suite::verdict::CaseVerdict::Pass
                                        | hiperface_suite::verdict::CaseVerdict::NotApplicable
                                )
                            })
                            .flat_map(|x| {
                                x.findings
                                    .iter()
                                    .map(move |f| format!("{} {}: {}", x.id, f.verdict().label(), f.message()))
                            })
                            .collect();
                        format!("{}: {}", c.name, bad.join("; "))
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    fn sweep(&mut self, i: usize) -> &Sweep {
        self.sweeps[i].get_or_insert_with(|| {
            let previous = mutant::active();
            mutant::activate(0);
            let all = sweep_configs(i)
                .into_iter()
                .filter_map(|c| {
                    let device = MutatedEncoder::in_config(&c.profile, &c.world, c.counter).ok()?;
                    let report = certify::run(device, c.profile, &certify::options(&c.world));
                    Some((c, report))
                })
                .collect();
            mutant::activate(previous);
            all
        })
    }

    /// Certify mutant `id`: sweep after sweep until a FAIL.
    pub fn certify(&mut self, id: u32) -> Verdicts {
        let mut best: Option<Verdicts> = None;
        for i in 0..3 {
            let sweep = self.sweep(i);
            mutant::activate(id);
            let found = run_sweep(sweep, best.take());
            mutant::activate(0);
            let fail = found.caught == Caught::Fail;
            best = Some(found);
            if fail {
                break;
            }
        }
        best.unwrap_or_else(|| Verdicts::unbuildable("none", "no configuration".into()))
    }
}

impl Default for Baselines {
    fn default() -> Self {
        Baselines::new()
    }
}

/// The configurations one after another, until one FAILs.
fn run_sweep(configs: &Sweep, start: Option<Verdicts>) -> Verdicts {
    let best = certify::until_fail(configs, start, |(c, baseline)| {
        match MutatedEncoder::in_config(&c.profile, &c.world, c.counter) {
            Ok(device) => {
                let crashed = device.crash_note();
                let report = certify::run(device, c.profile, &certify::options(&c.world));
                let note = crashed.borrow().clone();
                certify::compare(&c.name, &report, baseline, note)
            }
            Err(why) => Verdicts::unbuildable(&c.name, why),
        }
    });
    best.unwrap_or_else(|| Verdicts::unbuildable("none", "no configuration".into()))
}

/// The ids a family's conformant device runs (source families), measured now.
pub fn reached_of(family: crate::run::Family) -> Option<std::collections::BTreeSet<u32>> {
    match family {
        crate::run::Family::Encoder => Some(Baselines::reached().into_iter().collect()),
        crate::run::Family::Master => Some(crate::master::reached().into_iter().collect()),
        crate::run::Family::Wire => None,
    }
}
