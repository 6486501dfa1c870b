//! The harness against a slave it did not write: HX-1 (`tests/independent/hx1_slave.py`),
//! a stdlib-only Python process written from 000's tables, that behaves like typical
//! third-party firmware and simulators on a pseudo-terminal (whole reply in one
//! write, timeout measured from the last byte that arrived, its own memory, error
//! stack and state machine). Real time, real pseudo-terminals, a real ser2net.
//!
//! Long because: every test certifies the one HX-1 (or HX-L) process, conformant or
//! with a defect switch, over the same pseudo-terminal and ser2net helpers here, and
//! each defect is held against the cases it must fail.
//!
//! - the conformant HX-1 gets no FAIL on the whole catalogue, over a pseudo-terminal
//!   and through ser2net, also with a warning pending and with new fields cleared to 00h;
//! - each defect switch FAILs the case that exercises it, citing the clause it breaks;
//!   the FAILs it causes elsewhere (collateral) are printed and bounded by the list
//!   of cases that exchange the same defective answer.

mod common;

use common::hx1::{a_sample, certify_faithfully, certify_pty_as, legacy_profile, options, profile, Hx1};
use hiperface_conformance::port::PortSpec;
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::CaseVerdict;

/// HX-1 started with `args` and certified over its pseudo-terminal, a run that is no
/// sample of HX-1's behaviour taken again (`hx1::certify_faithfully`).
fn certify_hx1(args: &[&str], expected: impl Fn(&Report) -> bool) -> Report {
    certify_faithfully(&format!("HX-1 {args:?}"), || Hx1::start(args), profile(), expected)
}

/// The run PASSED: no case FAILed or ERRORed, nothing was left UNKNOWN or unexercised
/// (`Outcome::of`).
fn passes(r: &Report) -> bool {
    r.outcome().passed()
}

fn with_verdict(r: &Report, v: CaseVerdict) -> Vec<&'static str> {
    r.cases.iter().filter(|c| c.verdict == v).map(|c| c.id).collect()
}

fn assert_no_fail(r: &Report) {
    let bad: Vec<_> = r.cases.iter().filter(|c| matches!(c.verdict, CaseVerdict::Fail | CaseVerdict::Error)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(r.outcome().passed() && r.aborted.is_none());
    assert!(r.safety.restored(), "{:#?}", r.safety);
    // The catalogue ran: NOT-APPLICABLE only where the profile lacks a command (6Bh's
    // two cases, the legacy 63h) or the line cannot carry the case (on a
    // pseudo-terminal the parity error; over raw TCP also 67h and another stored rate).
    assert!(with_verdict(r, CaseVerdict::NotApplicable).len() < 7, "{:?}", with_verdict(r, CaseVerdict::NotApplicable));
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn the_conformant_hx1_passes_over_a_pseudo_terminal() {
    let _one = common::one_at_a_time();
    let r = certify_hx1(&[], passes);
    assert_no_fail(&r);
    assert!(with_verdict(&r, CaseVerdict::Pass).len() > 25, "{:?}", r.summary);
    // The certificate shows what the device said of itself, not the profile's sample.
    assert_eq!(r.identity.serial.as_deref(), Some("HX1000042"));
    assert_eq!(r.identity.firmware_date.as_deref(), Some("03.10.26"));
    assert_eq!(r.identity.type_label.map(|t| t.type_code), Some(0xFF));
    assert_eq!(r.safety.verified.len(), 4, "{:#?}", r.safety);
    // Its one latitude the check order prefers otherwise: 55h checks the code first.
    assert_eq!(with_verdict(&r, CaseVerdict::NonStrict), vec!["address.change-restore"]);
    eprintln!(
        "HX-1 over a pseudo-terminal: {:?}; wall {:.0} ms, on a real line {:.0} ms",
        r.summary, r.wall_time_ms, r.line_time_ms
    );
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn a_pending_warning_is_the_devices_world() {
    let _one = common::one_at_a_time();
    // 120 °C: 1Eh, a warning (000:T59) the model cannot see on a black box.
    let r = certify_hx1(&["--temperature", "120"], passes);
    assert_no_fail(&r);
    // NON-STRICT, with the code, where the device reports it.
    let status = r.cases.iter().find(|c| c.id == "identity.status").unwrap();
    assert_eq!(status.verdict, CaseVerdict::NonStrict);
    assert!(status.findings.iter().any(|f| f.message().contains("1Eh")), "{:#?}", status.findings);
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn new_fields_cleared_to_00h_are_non_strict() {
    let _one = common::one_at_a_time();
    // 000 does not say what a new field's unwritten bytes read; FFh is the project's
    // decision (erased EEPROM), so another value is NON-STRICT at most.
    let r = certify_hx1(&["--erased-byte", "0x00"], passes);
    assert_no_fail(&r);
    let erased: Vec<_> = r
        .cases
        .iter()
        .flat_map(|c| c.findings.iter().map(move |f| (c.id, f)))
        .filter(|(_, f)| f.clause_id() == "DESIGN:fields")
        .collect();
    assert!(!erased.is_empty(), "the 00h bytes of a new field are noted: {:?}", r.summary);
    assert!(erased.iter().all(|(_, f)| f.verdict() == CaseVerdict::NonStrict));
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn the_conformant_hx1_passes_through_ser2net() {
    let _one = common::one_at_a_time();
    let r = common::faithfully(|| {
        let hx1 = Hx1::start(&[]);
        let server = common::Ser2net::bridge(&hx1.path, "hx1");
        // The default tolerance, as `certify slave --port tcp://...` uses it.
        let line = server.connect();
        let r = slave::run(Box::new(line), profile(), &options(), |_, _, _| {});
        (a_sample(passes(&r), &hx1, &r), r)
    });
    assert_no_fail(&r);
    assert_eq!(r.identity.serial.as_deref(), Some("HX1000042"));
    eprintln!(
        "HX-1 through ser2net: {:?}; wall {:.0} ms, on a real line {:.0} ms",
        r.summary, r.wall_time_ms, r.line_time_ms
    );
}

/// A defect switch, the case that must catch it with the clause it breaks, and the
/// other cases that exchange the same defective answer (the collateral it may cause).
struct Defect {
    name: &'static str,
    case: &'static str,
    clause: &'static str,
    collateral: &'static [&'static str],
}

/// The cases that read Read Encoder Status besides identity.status: the power-up case,
/// and those that answer errors (nothing of them is stacked, 000:T37).
const READS_STATUS: &[&str] = &[
    "address.broadcast",
    "powerup.reset",
    "protocol.checksum",
    "protocol.unknown-command",
    "protocol.length",
    "protocol.argument",
    "fields.lifecycle",
];

const DEFECTS: &[Defect] = &[
    Defect { name: "reply-checksum", case: "identity.version", clause: "000:2.3.3", collateral: &[] },
    Defect {
        name: "no-timeout-wait",
        case: "identity.status",
        clause: "000:2.2.2",
        // the power-up case reads the status too, and so do the cases that answer
        // errors (nothing of them is stacked, 000:T37)
        collateral: READS_STATUS,
    },
    Defect {
        name: "late-reply",
        case: "counter.read",
        clause: "000:T10",
        // reads the counter too; the length case sends every command, 46h among them;
        // what a reset keeps is read back, the counter among it
        collateral: &["counter.increment", "protocol.length", "powerup.retains"],
    },
    // Beyond the window the harness awaits a reply in (three times the limit, at least
    // 100 ms past it): still this request's reply, late (000:T10), and not the next
    // request's ("no reply" here and a wrong answer in the next case, before).
    // The length case sends every command, 56h among them.
    Defect { name: "very-late-reply", case: "identity.version", clause: "000:T10", collateral: &["protocol.length"] },
    Defect {
        name: "gap-in-reply",
        case: "identity.type-label",
        clause: "000:2.2.2/reply-end",
        // the other cases that read the type label (the length case sends every command;
        // the stored settings are read after 57h; the first request after a reset)
        collateral: &["address.broadcast", "protocol.length", "settings.stored", "powerup.retains"],
    },
    Defect {
        name: "answers-other-address",
        case: "address.other",
        clause: "000:T5",
        // after Set Encoder Address the old address is a neighbour, and answers
        collateral: &["address.change-restore"],
    },
    Defect {
        name: "ignores-broadcast",
        case: "address.broadcast",
        clause: "000:2.3.1",
        // a broadcast from the new address
        collateral: &["address.change-restore"],
    },
    Defect {
        name: "no-field-bounds",
        case: "fields.lifecycle",
        clause: "000:T55",
        // reads at the end of the Extended Type Label
        collateral: &["fields.extended-type-label"],
    },
    Defect {
        name: "wrong-error-code",
        case: "protocol.unknown-command",
        clause: "000:T49",
        // a broadcast unknown command too
        collateral: &["address.broadcast"],
    },
    Defect {
        name: "warning-stuck",
        case: "identity.status",
        clause: "000:2.3.4",
        // a warning bit the model did not expect may be a real fault (NON-STRICT on a
        // black box) until Read Encoder Status says nothing is stored; the power-up
        // case reads the status again, and so do the cases that answer errors
        collateral: READS_STATUS,
    },
    Defect {
        name: "store-read-only",
        case: "fields.access-code",
        clause: "000:T52",
        // a store to the field made read-only before the reset
        collateral: &["powerup.retains"],
    },
    // every power-up case starts with an Encoder Reset, and the stored and the
    // temporary settings are each held to one
    Defect {
        name: "reset-answers",
        case: "powerup.reset",
        clause: "000:T29",
        collateral: &[
            "powerup.window",
            "powerup.default-window",
            "powerup.retains",
            "settings.stored",
            "settings.temporary",
        ],
    },
    Defect { name: "no-init-silence", case: "powerup.reset", clause: "000:T9", collateral: &[] },
    Defect { name: "no-code-check", case: "position.set", clause: "000:T53", collateral: &[] },
    // what a reset keeps: the address among it, changed with 55h
    Defect {
        name: "old-address-reply",
        case: "address.change-restore",
        clause: "000:T30",
        collateral: &["powerup.retains"],
    },
];

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn every_defect_switch_fails_its_own_case() {
    let _one = common::one_at_a_time();
    let mut table = vec!["| defect | its case | clause | collateral FAILs |".to_string(), "|---|---|---|---|".into()];
    let mut problems = Vec::new();
    let runs =
        common::two_at_a_time(DEFECTS, |d| certify_hx1(&["--defect", d.name], |r| defect_problems(d, r).is_empty()));
    for (d, r) in DEFECTS.iter().zip(&runs) {
        problems.extend(defect_problems(d, r));
        let collateral: Vec<&str> = with_verdict(r, CaseVerdict::Fail).into_iter().filter(|id| *id != d.case).collect();
        table.push(format!("| {} | {} | {} | {} {:?} |", d.name, d.case, d.clause, collateral.len(), collateral));
        for id in &collateral {
            let c = r.cases.iter().find(|c| c.id == *id).expect("a case");
            if let Some(f) = c.findings.iter().find(|f| f.verdict() == CaseVerdict::Fail) {
                eprintln!("  {}: {id}: {} ({})", d.name, f.message(), f.clause_id());
            }
        }
    }
    eprintln!("{}", table.join("\n"));
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// What is wrong with `r` as the run of HX-1 with the defect `d`: its case not FAILed
/// on its clause, a late reply also called missing, FAILs beyond the known collateral,
/// harness ERRORs.
fn defect_problems(d: &Defect, r: &Report) -> Vec<String> {
    let mut problems = Vec::new();
    let own = r.cases.iter().find(|c| c.id == d.case).expect("a case of the catalogue");
    let cited = own.findings.iter().any(|f| f.verdict() == CaseVerdict::Fail && f.clause_id() == d.clause);
    if own.verdict != CaseVerdict::Fail || !cited {
        problems.push(format!("{}: {} is {:?}, findings {:#?}", d.name, d.case, own.verdict, own.findings));
    }
    // A late reply is late, not missing: no "no reply" finding besides it.
    if d.clause == "000:T10" && own.findings.iter().any(|f| f.clause_id() == "000:T12") {
        problems.push(format!("{}: a late reply is also called missing: {:#?}", d.name, own.findings));
    }
    let collateral = with_verdict(r, CaseVerdict::Fail).into_iter().filter(|id| *id != d.case);
    let unexplained: Vec<&str> = collateral.filter(|id| !d.collateral.contains(id)).collect();
    if !unexplained.is_empty() {
        let why: Vec<String> = unexplained
            .iter()
            .filter_map(|id| r.cases.iter().find(|c| c.id == *id))
            .flat_map(|c| c.findings.iter().filter(|f| f.verdict() == CaseVerdict::Fail).map(move |f| (c.id, f)))
            .map(|(id, f)| format!("{id}: {} ({})", f.message(), f.clause_id()))
            .collect();
        problems.push(format!("{}: unexplained collateral FAILs {unexplained:?}: {why:#?}", d.name));
    }
    let errors = with_verdict(r, CaseVerdict::Error);
    if !errors.is_empty() {
        problems.push(format!("{}: harness ERRORs {errors:?}", d.name));
    }
    problems
}

/// RFC 2217 through a real ser2net: HX-1 takes the line's data rate from its
/// pseudo-terminal (`--follow-line`), so 67h is followed end to end. The conformant
/// HX-1 passes `settings.temporary`; with `ignores-temporary-settings` (it answers 67h
/// and keeps its old rate) the case FAILs, and only that case.
#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn temporary_settings_through_rfc2217_pass_and_their_defect_fails() {
    use hiperface_conformance::port::open_for_slave;
    let _one = common::one_at_a_time();
    let run = |args: &[&str], expected: &[&str]| {
        common::faithfully(|| {
            let hx1 = Hx1::start(args);
            let server = common::Ser2net::bridge_rfc2217(&hx1.path, "hx1rfc2217");
            let spec: PortSpec = format!("rfc2217://{}", server.address()).parse().unwrap();
            let started = std::time::Instant::now();
            let opened = loop {
                match open_for_slave(&spec, profile(), &Default::default(), Default::default()) {
                    Ok(o) => break o,
                    Err(_) if started.elapsed() < std::time::Duration::from_secs(10) => {
                        std::thread::sleep(std::time::Duration::from_millis(100))
                    }
                    Err(e) => panic!("{e}"),
                }
            };
            let options = Options { timing: opened.default_timing.0, ..options() };
            let r = slave::run(opened.line, profile(), &options, |_, _, _| {});
            (a_sample(with_verdict(&r, CaseVerdict::Fail) == expected, &hx1, &r), r)
        })
    };
    let good = run(&["--follow-line"], &[]);
    let fails: Vec<_> = good.cases.iter().filter(|c| c.verdict == CaseVerdict::Fail).collect();
    assert_eq!(with_verdict(&good, CaseVerdict::Fail), Vec::<&str>::new(), "{:?} {fails:#?}", good.summary);
    assert!(with_verdict(&good, CaseVerdict::Pass).contains(&"settings.temporary"), "{:?}", good.summary);
    let bad = run(&["--follow-line", "--defect", "ignores-temporary-settings"], &["settings.temporary"]);
    let fails: Vec<_> = bad.cases.iter().filter(|c| c.verdict == CaseVerdict::Fail).collect();
    assert_eq!(with_verdict(&bad, CaseVerdict::Fail), vec!["settings.temporary"], "{:?} {fails:#?}", bad.summary);
}

/// HX-L, a legacy-edition slave written from 002 alone (`hxl_slave.py`), with its
/// factory settings (44 bit times) and with 002's short timeout (11 bit times, A4h),
/// which a receiver counting from character ends sees as 22 (DESIGN:legacy-timeout):
/// no FAIL either way. Its latitude: other error codes than 000's (002 leaves them to
/// the data sheet, NON-STRICT) and the access code checked before the address in 55h.
#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn the_conformant_legacy_slave_passes_with_either_timeout() {
    let _one = common::one_at_a_time();
    for settings in [0xE4, 0xA4] {
        // Taken again where HX-L was made late or the harness left a verdict UNKNOWN
        // (its own lateness, said so in the report): neither is a sample of HX-L.
        let r = common::faithfully(|| {
            let hxl = Hx1::start_legacy(&["--settings", &format!("0x{settings:02X}")]);
            let r = certify_pty_as(&hxl, legacy_profile(settings));
            (a_sample(passes(&r), &hxl, &r), r)
        });
        let bad: Vec<_> =
            r.cases.iter().filter(|c| matches!(c.verdict, CaseVerdict::Fail | CaseVerdict::Error)).collect();
        assert!(bad.is_empty(), "{settings:02X}h: {bad:#?}");
        assert!(r.outcome().passed(), "{settings:02X}h: {:?}", r.summary);
        assert!(with_verdict(&r, CaseVerdict::Pass).len() > 20, "{settings:02X}h: {:?}", r.summary);
        let latitude = with_verdict(&r, CaseVerdict::NonStrict);
        assert!(latitude.iter().all(|id| ["fields.resize", "address.change-restore"].contains(id)), "{latitude:?}");
    }
}

/// Each of HX-L's defect switches FAILs the case that exercises it, on 002's clause
/// where 002 has one.
#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn every_legacy_defect_switch_fails_its_own_case() {
    let _one = common::one_at_a_time();
    let defects: &[(&str, &str, &str)] = &[
        ("reply-checksum", "identity.type-label", "000:2.3.3"),
        ("early-reply", "position.read", "002:timing"),
        ("late-reply", "counter.read", "000:T10"),
        ("gap-in-reply", "identity.type-label", "000:2.3.4/error"),
        ("reset-answers", "powerup.reset", "000:T29"),
        ("no-code-check", "position.set", "000:T53"),
        ("ignores-broadcast", "address.broadcast", "000:2.3.1"),
    ];
    let mut problems = Vec::new();
    let failed_on = |r: &Report, case: &str, clause: &str| {
        let own = r.cases.iter().find(|c| c.id == case).expect("a case of the catalogue");
        own.verdict == CaseVerdict::Fail
            && own.findings.iter().any(|f| f.verdict() == CaseVerdict::Fail && f.clause_id() == clause)
    };
    let runs = common::two_at_a_time(defects, |(name, case, clause)| {
        let start = || Hx1::start_legacy(&["--defect", name]);
        certify_faithfully(&format!("HX-L {name}"), start, legacy_profile(0xE4), |r| failed_on(r, case, clause))
    });
    for ((name, case, clause), r) in defects.iter().zip(&runs) {
        let own = r.cases.iter().find(|c| c.id == *case).expect("a case of the catalogue");
        if !failed_on(r, case, clause) {
            problems.push(format!("{name}: {case} is {:?}, findings {:#?}", own.verdict, own.findings));
        }
    }
    // 002 leaves the error codes to the data sheet: 0Dh for an unknown command is
    // latitude for a legacy device (002:50h), not a FAIL.
    let hxl = Hx1::start_legacy(&["--defect", "wrong-error-code"]);
    let r = certify_pty_as(&hxl, legacy_profile(0xE4));
    drop(hxl);
    let own = r.cases.iter().find(|c| c.id == "protocol.unknown-command").expect("a case");
    if own.verdict != CaseVerdict::NonStrict || !own.findings.iter().all(|f| f.clause_id() == "002:50h") {
        problems.push(format!("wrong-error-code: {:?}, findings {:#?}", own.verdict, own.findings));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// A FAILED certificate as its customer reads it: HX-1 with two defects (a wrong
/// checksum on 56h, Read Counter answered 12 ms late, its limit 5 ms), certified by the command. In
/// every form (console, Markdown, HTML, JSON) the failures come first, each with its
/// case, its clause and the clause's sentence, the request and the reply it is about,
/// and for the late reply the figure against its limit; the run names itself (UTC
/// start, host, command line); the wire log marks the exchange that failed.
#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn a_failed_certificate_puts_its_failures_first_in_every_form() {
    let _one = common::one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let profile = common::hx1::dir().join("hx1.toml");
    let mut attempt = 0;
    // Taken again where the late reply was left UNKNOWN (the harness's own lateness on
    // a busy machine could explain it: seen with three busy loops and a build, 2026-11-29)
    // or HX-1 was made late; a run that decided it stands, whatever it decided.
    let (out, stdout, dir) = common::faithfully(|| {
        attempt += 1;
        let hx1 = Hx1::start(&["--defect", "reply-checksum", "--defect", "late-reply"]);
        let dir = tmp.path().join(format!("report-{attempt}"));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_hiperface"))
            .args(["certify", "slave", "--port", &hx1.path, "--allow-writes", "--allow-counter-change"])
            .args(["--cases", "identity.version,counter.read,position.read"])
            .arg("--profile")
            .arg(&profile)
            .arg("--report")
            .arg(&dir)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        // From the report's cases, not the console's lines, which list no case by case.
        // (The one failure of this test under three busy loops, 2026-11-29, was no
        // UNKNOWN: the late reply PASSED on a request window the harness's held write
        // had widened, mended in `verdict::timing`.)
        let undecided = std::fs::read_to_string(dir.join("report.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|j| j["cases"].as_array().cloned())
            .is_some_and(|cases| cases.iter().any(|c| c["id"] == "counter.read" && c["verdict"] == "UNKNOWN"));
        let faithful = !undecided && hx1.kept_time();
        // Shown with the test's output if it fails: what each run printed.
        eprintln!(
            "attempt {attempt}{}:\n{stdout}",
            if faithful { "" } else { ": counter.read undecided or HX-1 late; taken again" }
        );
        (faithful, (out, stdout, dir))
    });
    assert_eq!(out.status.code(), Some(1), "FAILED: {stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    // What each form must say of the two failures.
    let checksum = ["identity.version", "000:2.3.3", "XOR operation on all frame bytes", "56h Read Version"];
    let late = ["counter.read", "000:T10", "maximum response times", "46h Read Counter", "at most 5.000 ms allowed"];
    let first_section = |text: &str, start: &str, end: &str| -> String {
        let from = text.find(start).unwrap_or_else(|| panic!("no {start:?} in {text}"));
        let body = from + start.len();
        let to = text[body..].find(end).map_or(text.len(), |i| body + i);
        text[from..to].to_string()
    };
    let check = |form: &str, section: &str| {
        // The JSON holds the figure as numbers (checked below), the others in words.
        let words = |w: &&&str| form != "report.json" || !w.starts_with("at most");
        for what in checksum.iter().chain(&late).filter(words) {
            assert!(section.contains(what), "{form}: {what:?} missing from the failures first:\n{section}");
        }
        assert!(section.find("identity.version").is_some() && section.find("counter.read").is_some(), "{section}");
    };
    // The console ends with the same list.
    check("console", &first_section(&stdout, "findings to read first", "FAILED"));
    let md = std::fs::read_to_string(dir.join("certificate.md")).unwrap();
    let md_first = first_section(&md, "## Findings to read first", "\n## ");
    check("certificate.md", &md_first);
    assert!(md_first.contains("request: `40 56"), "the request as sent: {md_first}");
    assert!(md.find("## Findings to read first") < md.find("## Cases"), "first: {md}");
    for row in ["run started (UTC)", "host", "command line", "tool revision", "profile digest"] {
        assert!(md.contains(&format!("| {row} |")), "{row}: {md}");
    }
    assert!(md.contains("--defect") || md.contains("certify slave --port"), "the command line: {md}");
    // The wire log marks the frame the FAIL is about: the late reply, and the reply
    // whose checksum is wrong, with that byte pointed at.
    assert!(md.lines().any(|l| l.contains("S<  40 46") && l.contains("<-- FAIL 000:T10")), "{md}");
    assert!(!md.lines().any(|l| l.contains("M>  ") && l.contains("<--")), "no request is at fault: {md}");
    assert!(md.lines().any(|l| l.contains("S<  40 56") && l.contains("<-- FAIL 000:2.3.3")), "{md}");
    assert!(md.contains("^^ checksum 76h, the XOR of the bytes before it"), "{md}");
    // Each finding says where to look.
    assert!(md_first.contains("check: the checksum: the XOR of the address"), "{md_first}");
    assert!(md_first.contains("check: the reply path's latency"), "{md_first}");
    let html = std::fs::read_to_string(dir.join("certificate.html")).unwrap();
    let html_first = first_section(&html, "<h2>Findings to read first</h2>", "<h2>");
    check("certificate.html", &html_first);
    assert!(html.contains("<mark class=\"bad\">76</mark>"), "the faulty byte highlighted: {html}");
    assert!(html.find("Findings to read first") < html.find("<h2>Cases</h2>"), "first: {html}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["outcome"], "FAILED");
    let attention = json["attention"].as_array().expect("attention in the JSON");
    check("report.json", &serde_json::to_string(attention).unwrap());
    let late_one = attention.iter().find(|a| a["unit"] == "counter.read").expect("counter.read first");
    assert_eq!(late_one["verdict"], "FAIL");
    assert_eq!(late_one["figure"]["limit_us"], 5_000, "Table 10: Read Counter 5 ms");
    assert!(late_one["figure"]["measured_us"].as_i64().unwrap() > 5_000, "{late_one}");
    assert!(late_one["request"].as_str().unwrap().starts_with("40 46"), "{late_one}");
    assert!(late_one["reply"].as_str().is_some(), "the late reply as heard: {late_one}");
    assert!(json["run_info"]["started_utc"].as_str().unwrap().ends_with('Z'));
}
