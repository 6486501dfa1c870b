//! The catalogue against the reference model in virtual time: every case passes.

use hiperface_conformance::certify::{self, CaseVerdict, Options};
use hiperface_conformance::line::virtual_line::VirtualLine;
use hiperface_model::{profiles, Slave};

#[test]
fn the_reference_model_passes_every_case_in_virtual_time() {
    for (name, make) in profiles::BUILTIN {
        let line = VirtualLine::new(Slave::operational(make()));
        let report = certify::run(Box::new(line), make(), &Options::all_allowed(), |_, _, _| {});
        for c in &report.cases {
            assert!(
                matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable),
                "{name}: {} {}: {:#?}\n{:#?}",
                c.id,
                c.verdict.label(),
                c.findings,
                c.wire
            );
        }
        assert!(report.outcome().passed());
        assert!(report.cases.iter().filter(|c| c.verdict == CaseVerdict::Pass).count() >= 20, "{name}");
    }
}

/// A current-edition profile with every optional command (67h, 6Ah, 6Bh, 6Ch).
pub fn every_command() -> hiperface_model::Profile {
    let mut p = profiles::ttk70();
    p.commands = hiperface_model::command::CommandSet::all_for(false);
    p
}

#[test]
fn every_case_runs_and_passes_on_a_profile_with_every_command() {
    let p = every_command();
    let report =
        certify::run(Box::new(VirtualLine::new(Slave::operational(p))), p, &Options::all_allowed(), |_, _, _| {});
    for c in &report.cases {
        let legacy_only = c.id.starts_with("legacy.");
        let expected = if legacy_only { CaseVerdict::NotApplicable } else { CaseVerdict::Pass };
        assert_eq!(c.verdict, expected, "{}: {:#?}", c.id, c.findings);
    }
}
