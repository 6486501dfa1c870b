//! The catalogue against the reference model in virtual time: every case passes.

mod common;

use hiperface_model::{profiles, Slave};
use hiperface_suite::line::virtual_line::VirtualLine;
use hiperface_suite::slave::{self, Options};
use hiperface_suite::verdict::CaseVerdict;

#[test]
fn the_reference_model_passes_every_case_in_virtual_time() {
    for (name, make) in profiles::BUILTIN {
        let line = VirtualLine::new(Slave::operational(make()));
        let report = slave::run(Box::new(line), make(), &Options::all_allowed(), |_, _, _| {});
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
        slave::run(Box::new(VirtualLine::new(Slave::operational(p))), p, &Options::all_allowed(), |_, _, _| {});
    for c in &report.cases {
        let legacy_only = c.id.starts_with("legacy.");
        let expected = if legacy_only { CaseVerdict::NotApplicable } else { CaseVerdict::Pass };
        assert_eq!(c.verdict, expected, "{}: {:#?}", c.id, c.findings);
    }
}

/// "The reference passes itself in every configuration": every built-in profile with
/// its stored settings byte set to every value the profile accepts (each data rate it
/// lists, every parity, both timeouts, both bus modes; both editions), certified in
/// virtual time. Every run PASSED, no case run again (virtual time has no lateness),
/// and the wire log's times never go backwards. The count is printed.
#[test]
fn the_reference_passes_itself_with_every_settings_byte_of_every_profile() {
    let mut configurations = 0;
    let mut failures = Vec::new();
    for (name, make) in profiles::BUILTIN {
        for byte in 0..=255u8 {
            let mut p = make();
            let Ok(settings) = hiperface_model::UartSettings::decode(byte) else { continue };
            p.settings = settings;
            if p.validate().is_err() {
                continue;
            }
            configurations += 1;
            let line = VirtualLine::new(Slave::operational(p));
            let report = slave::run(Box::new(line), p, &Options::all_allowed(), |_, _, _| {});
            common::replay::assert_replays(&report);
            let wrong: Vec<String> = report
                .cases
                .iter()
                .filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable) || c.attempts > 1)
                .map(|c| format!("{} {} ({} runs): {:?}", c.id, c.verdict.label(), c.attempts, c.findings))
                .collect();
            let backwards = report
                .cases
                .iter()
                .flat_map(|c| c.wire.windows(2).filter(|w| w[1].t_us < w[0].t_us).map(move |w| (c.id, w[0].t_us)))
                .collect::<Vec<_>>();
            if !report.outcome().passed() || !wrong.is_empty() || !backwards.is_empty() {
                failures.push(format!(
                    "{name} {byte:02X}h: {:?} {wrong:#?} wire backwards: {backwards:?}",
                    report.outcome()
                ));
            }
        }
    }
    println!("{configurations} profile x settings configurations certified in virtual time");
    assert!(failures.is_empty(), "{} of {configurations} did not pass:\n{}", failures.len(), failures.join("\n"));
    // 10 built-in profiles: 84 settings where 600 Bd is listed, 72 where it is not.
    assert!(configurations >= 768, "{configurations}");
}

/// The record of the wire played back gives the run's verdicts: the reference in
/// virtual time with every built-in profile, and a run whose device FAILs (the
/// record holds what a defect did, not what the model would have done).
#[test]
fn a_record_played_back_gives_the_runs_verdicts() {
    for (_, make) in profiles::BUILTIN {
        let live = slave::run(
            Box::new(VirtualLine::new(Slave::operational(make()))),
            make(),
            &Options::all_allowed(),
            |_, _, _| {},
        );
        common::replay::assert_replays(&live);
    }
}

/// The playback grades the record, it does not copy the run's verdicts: a reply
/// changed in the record FAILs where it was changed, and a record that does not fit
/// the catalogue is refused where it departs.
#[test]
fn a_changed_record_is_graded_as_it_is() {
    use hiperface_suite::slave::record::Event;
    let p = profiles::srs50();
    let live = slave::run(Box::new(VirtualLine::new(Slave::operational(p))), p, &Options::all_allowed(), |_, _, _| {});
    let record = live.record.clone().expect("a record");
    // The first Read Position reply of the catalogue, one data byte changed.
    let mut changed = record.clone();
    let x = changed
        .events
        .iter_mut()
        .find_map(|e| match e {
            Event::Exchange { exchange, .. } if exchange.request == "40 42 02" && !exchange.reply.is_empty() => {
                Some(exchange)
            }
            _ => None,
        })
        .expect("a Read Position");
    x.reply[2].0 ^= 0x01;
    let again = slave::replay(&changed, |_, _, _| {}).expect("plays back");
    let read = again.cases.iter().find(|c| c.id == "identity.type-label" || c.id == "position.read");
    assert!(!again.outcome().passed(), "{:?}", again.summary);
    assert!(
        again
            .cases
            .iter()
            .any(|c| c.verdict == CaseVerdict::Fail && c.findings.iter().any(|f| f.clause_id() == "000:2.3.3")),
        "a reply whose checksum no longer fits: {read:#?}"
    );
    // An exchange taken out: the catalogue asks for it, the record holds the next.
    let mut short = record;
    let i = short.events.iter().position(|e| matches!(e, Event::Exchange { .. })).expect("an exchange");
    short.events.remove(i);
    let again = slave::replay(&short, |_, _, _| {}).expect("plays back");
    let why = again.aborted.clone().unwrap_or_default();
    assert!(
        why.contains("departs") || again.cases.iter().any(|c| c.verdict == CaseVerdict::Error),
        "{why} {:?}",
        again.summary
    );
    assert!(!again.outcome().passed());
}
