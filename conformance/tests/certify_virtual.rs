//! The catalogue against the reference model in virtual time: every case passes.

use hiperface_conformance::certify::{self, CaseVerdict, Options};
use hiperface_conformance::line::virtual_line::VirtualLine;
use hiperface_model::{profiles, Slave};

fn all_allowed() -> Options {
    Options { allow_writes: true, allow_counter_change: true, ..Options::default() }
}

#[test]
fn the_reference_model_passes_every_case_in_virtual_time() {
    for (name, make) in profiles::BUILTIN {
        let line = VirtualLine::new(Slave::operational(make()));
        let report = certify::run(Box::new(line), make(), &all_allowed(), |_, _, _| {});
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
        assert!(report.passed());
        assert!(report.cases.iter().filter(|c| c.verdict == CaseVerdict::Pass).count() >= 20, "{name}");
    }
}
