//! The tests of the master's record: runs again at the end, quiet turns, the machine's
//! waits kept.

use super::*;
use crate::exchange::Char;

/// A scenario run again at the end of the run (still undecided after its runs in a
/// row) has runs on both sides of the others': they are one scenario's runs, its
/// result the last run's, in the place it first ran.
#[test]
fn runs_again_at_the_end_are_the_scenario_s_own() {
    let catalogue = super::super::scenarios::catalogue();
    let (a, b) = (&catalogue[0], &catalogue[1]);
    let early = |s: &super::super::scenario::Scenario, attempt, why: &str| {
        let mut result = CaseResult::named(s.id, s.title, s.clauses);
        result.push(crate::verdict::Finding::error(why.to_string()));
        ScenarioRecord { attempt, ..ScenarioRecord::early_of(&result) }
    };
    let record = MasterRecord {
        format: FORMAT.into(),
        tool: "test".into(),
        profile: crate::profile_file::to_toml(&hiperface_model::profiles::srs50()),
        polling_period_ms: 100,
        not_used: Vec::new(),
        runs: vec![early(a, 1, "first"), early(b, 1, "other"), early(a, 2, "again at the end")],
        interrupted: false,
    };
    let (_, results, _) = replay(&record).unwrap();
    let seen: Vec<_> = results.iter().map(|r| (r.id, r.attempts, r.findings[0].message().to_string())).collect();
    assert_eq!(seen, vec![(a.id, 2, "again at the end".to_string()), (b.id, 1, "other".to_string())]);
}

/// The machine's samples are kept where there are any, and a record from before
/// the processors' pauses were timed still reads (none).
#[test]
fn the_machines_waits_are_kept_and_older_records_read() {
    let run = ScenarioRecord {
        id: "reply.gap".into(),
        master_waited: vec![(5_000, 10)],
        host_paused: vec![(5_000, 0), (10_000, 7_100)],
        ..ScenarioRecord::default()
    };
    let json = serde_json::to_string(&run).unwrap();
    assert!(json.contains(r#""host_paused":[[5000,0],[10000,7100]]"#), "{json}");
    assert_eq!(serde_json::from_str::<ScenarioRecord>(&json).unwrap(), run);
    let older = json.replace(r#","host_paused":[[5000,0],[10000,7100]]"#, "");
    assert!(serde_json::from_str::<ScenarioRecord>(&older).unwrap().host_paused.is_empty());
    let none = ScenarioRecord { host_paused: Vec::new(), ..run };
    assert!(!serde_json::to_string(&none).unwrap().contains("host_paused"), "left out where empty");
}

#[test]
fn quiet_turns_are_kept_short_and_written_out_alike() {
    let ch = Char(0x40, 1_000, None);
    let log = vec![
        Input::RealTime { granted: true },
        Input::Read { unwatched_us: 0 },
        Input::Idle { now_us: 500 },
        Input::PeerRate { bps: Some(9600) },
        Input::Read { unwatched_us: 0 },
        Input::Idle { now_us: 1_001 },
        Input::PeerRate { bps: Some(9600) },
        Input::Read { unwatched_us: 700 },
        Input::Received { ch, listening: Some("E4".into()) },
        Input::Idle { now_us: 1_600 },
        Input::Read { unwatched_us: 0 },
        Input::Idle { now_us: 2_100 },
        Input::Read { unwatched_us: 0 },
        Input::Idle { now_us: 2_600 },
        Input::PeerRate { bps: None },
    ];
    let short = compact(log.clone());
    assert_eq!(
        short,
        vec![
            Input::RealTime { granted: true },
            Input::Quiet { at: "500 501".into(), rate_read: true, bps: Some(9600) },
            Input::Read { unwatched_us: 700 },
            Input::Received { ch, listening: Some("E4".into()) },
            Input::Idle { now_us: 1_600 },
            Input::Quiet { at: "2100".into(), rate_read: false, bps: None },
            Input::Quiet { at: "2600".into(), rate_read: true, bps: None },
        ]
    );
    assert_eq!(expand(&short).unwrap(), log);
    assert!(expand(&[Input::Quiet { at: "1 x".into(), rate_read: false, bps: None }]).is_err());
    // Short forms are not written out without bound.
    let flood = Input::Quiet { at: "1 ".repeat(MAX_INPUTS), rate_read: true, bps: None };
    let e = expand(&[flood]).unwrap_err();
    assert!(e.to_string().contains("more than 1000000 inputs"), "{e}");
}
