//! Grading one scenario run: whether its situation arose and its reaction followed,
//! and each rule the master broke, with what the harness's own timing could explain
//! kept from a FAIL.

use super::encoder::{self, DriveEncoder, Timeline};
use super::scenario::Scenario;
use crate::verdict::{CaseResult, Finding};
use hiperface_model::master::obligations::{Observation, Rule};
use hiperface_model::UartSettings;

/// The verdict, and the timeline with the broken rules on it; `duration_ms`: how long
/// the run took, for the report. `by_operator`: the
/// drive's power-on was the operator's, at the encoder's or later. Returns why the
/// harness's own timing may have decided something, where it may have.
pub fn finish(
    result: &mut CaseResult,
    hooks: &mut DriveEncoder,
    scenario: &Scenario,
    duration_ms: f64,
    by_operator: bool,
    cut_short: bool,
) -> Option<String> {
    if cut_short {
        let at = hooks.timeline.end_us as f64 / 1000.0;
        result.push(Finding::not_exercised(format!(
            "cut short by an interrupt at {at:.0} ms: what the master did until then is graded, its reaction was not awaited"
        )));
    }
    let disturbed = grade(result, hooks, scenario, by_operator, cut_short);
    result.wire.append(&mut hooks.timeline.entries);
    for o in &hooks.timeline.observations {
        result.wire.push(crate::verdict::WireEntry {
            t_us: o.at_us,
            direction: crate::verdict::WireEntry::BROKEN,
            bytes: format!("{} ({})", o.rule.text(), o.rule.clause()),
        });
    }
    result.wire.sort_by_key(|w| w.t_us);
    result.duration_ms = duration_ms;
    disturbed
}

/// Whether the scenario's situation arose (else NOT-EXERCISED: nothing about it was
/// seen), and whether the reaction it expects followed (else graded by the force of
/// the reaction's clause, unless a rule of the observer already judged it).
fn exercised(result: &mut CaseResult, timeline: &Timeline, scenario: &Scenario, edition: hiperface_model::Edition) {
    let Some(at_us) = timeline.situation_us else {
        result.push(Finding::not_exercised(format!("not exercised: {}", scenario.situation.missing(scenario))));
        return;
    };
    let reaction = scenario.reaction;
    let on = scenario.plan.first().map(|p| p.on);
    let seen = timeline.requests_log.iter().any(|r| r.end_us > at_us && reaction.seen_in(&r.request, on));
    let judged = timeline.observations.iter().any(|o| reaction.judged_by().contains(&o.rule));
    if !seen && !judged {
        let message = format!(
            "the expected reaction, {}, was not seen in the {} ms after the situation arose at {:.3} ms",
            reaction.text(),
            timeline.end_us.saturating_sub(at_us) / 1000,
            at_us as f64 / 1000.0
        );
        result.push(Finding::broken(reaction.clause(), message, edition).at(at_us));
    }
}

/// The scenario's verdict from what the observer saw.
fn grade(
    result: &mut CaseResult,
    hooks: &DriveEncoder,
    scenario: &Scenario,
    by_operator: bool,
    cut_short: bool,
) -> Option<String> {
    let timeline = &hooks.timeline;
    let edition = hooks.profile().edition;
    if timeline.characters == 0 {
        result.push(Finding::error("the master sent nothing: there is nothing to grade"));
        return None;
    }
    // The line's own faults: what the master is graded on may not be what it sent.
    if let Some((at_us, what)) = timeline.line_faults.first() {
        let more = match timeline.line_faults.len() - 1 {
            0 => String::new(),
            n => format!(" ({n} more faults of the line after it)"),
        };
        result.push(Finding::error(format!("at {:.3} ms: {what}{more}", *at_us as f64 / 1000.0)).at(*at_us));
    }
    if timeline.characters >= encoder::MAX_CHARACTERS {
        // Cut off: what the master did before the flood is no scenario run to grade.
        result.push(Finding::error(format!(
            "the master flooded the line: more than {} characters in the scenario, cut off there",
            encoder::MAX_CHARACTERS
        )));
        return None;
    }
    // A declaration the master's own requests contradict: the scenarios it left out were
    // not graded on a truth, which the run cannot call a PASS (nor a FAIL of 000).
    for c in hooks.not_used() {
        if let Some(n) = timeline.requests.get(&c.byte()) {
            result.push(Finding::unknown(format!(
                "the master sent {c} {n} times, though it declared it never sends it (--not-used): the scenarios \
                 left out on that declaration were not graded"
            )));
        }
    }
    let before_reaction = result.findings.len();
    if !cut_short {
        exercised(result, timeline, scenario, edition);
    }
    // The scenario's situation did not arise or its reaction was not seen: a
    // disturbance anywhere in the run may be why.
    let reaction_missed = result.findings.len() > before_reaction;
    // One finding per rule, with the count and the first observation that stands. An
    // observation the harness's own timing may explain is not charged to the master:
    // the rule is then UNKNOWN, with the reason. That is one the harness
    // read late by as much as the rule was broken by, and anything after a reply the
    // harness wrote with a pause it did not plan (the master may have heard the reply
    // end there, and all it did after rests on that).
    let timeout = UartSettings::DEFAULT.timeout_us(edition);
    // From where what the master did may rest on the harness's own timing: the first
    // reply it disturbed in a way any master sees (in two parts, or past its limit),
    // or the first unplanned pause a rule was broken after.
    let disturbed_from = timeline
        .disturbed
        .iter()
        .find(|d| d.decides() || reaction_missed || timeline.observations.iter().any(|o| o.at_us >= d.at_us))
        .map(|d| d.at_us);
    let unproven = |o: &Observation| -> Option<String> {
        if let Some(waited) = timeline.master_slowed(o, timeout, hooks.profile(), hooks.polling_period_us()) {
            return Some(format!(
                "the master's own process waited for a processor, or the processors were stopped, for up to {:.1} ms \
                 before it (a busy machine): its timing was the machine's, not proven the master's",
                waited as f64 / 1000.0
            ));
        }
        if let Some(late) = timeline.unproven(o, timeout, hooks.profile()) {
            return Some(format!(
                "the harness did not read the line, or the kernel held its characters back, for up to {:.1} ms around \
                 it (a busy machine): the timing is not proven",
                late as f64 / 1000.0
            ));
        }
        disturbed_from.filter(|&from| o.at_us >= from).map(|from| {
            format!(
                "the harness's own timing disturbed its reply at {:.3} ms (a busy machine): what the master did \
                 after it is not proven",
                from as f64 / 1000.0
            )
        })
    };
    let mut rules: Vec<Rule> = Vec::new();
    for o in &timeline.observations {
        if !rules.contains(&o.rule) {
            rules.push(o.rule);
        }
    }
    let mut any_unproven = None;
    for rule in rules {
        let all: Vec<&Observation> = timeline.observations.iter().filter(|o| o.rule == rule).collect();
        let count = all.len();
        let standing = all.iter().find(|o| unproven(o).is_none());
        let shown = standing.or(all.first()).copied();
        let Some(&Observation { at_us, measured_us: measured, data_rates: rates, .. }) = shown else { continue };
        let figure = match (measured, rates) {
            (Some(m), _) => format!(", {:.3} ms", m as f64 / 1000.0),
            (None, Some(r)) => match r.changed_from_bps {
                Some(from) => format!(
                    ", {from} or {} Bd (its settings changed as it sent), the encoder at {} Bd",
                    r.master_bps, r.encoder_bps
                ),
                None => format!(", {} Bd, the encoder at {} Bd", r.master_bps, r.encoder_bps),
            },
            (None, None) => String::new(),
        };
        let times = if count > 1 { format!(" ({count} times)") } else { String::new() };
        let message = format!("{} at {:.3} ms{figure}{times}", rule.text(), at_us as f64 / 1000.0);
        let mut finding = Finding::broken(rule.clause(), message, edition).at(at_us);
        if let (None, Some(why)) = (standing, shown.and_then(unproven)) {
            finding = finding.untold(&why);
            any_unproven.get_or_insert(why);
        }
        // A request in the settings-change window by the encoder's clock may be in the
        // default window by the drive's, which powered on later.
        result.push(match (rule, by_operator) {
            (Rule::DuringSettingsChange, true) => {
                finding.softened("the drive powered on when the operator switched it, perhaps after the encoder")
            }
            _ => finding,
        });
    }
    // A request the harness read after a reply's end but may have come before it (read
    // late): the talk-over the observer did not see may have been there. Not a PASS on
    // 000:2.2/cycle: UNKNOWN, and a reason to run the scenario again.
    let seen_talk_over = timeline.observations.iter().any(|o| o.rule == Rule::TalksOverReply);
    if let (false, Some((at_us, late))) = (seen_talk_over, timeline.hidden_talk_over()) {
        let why = format!(
            "the harness did not read the line for up to {:.1} ms before it (a busy machine): whether it began after \
             the reply's end is not proven",
            late as f64 / 1000.0
        );
        let message = format!("a request read after a reply's end at {:.3} ms", at_us as f64 / 1000.0);
        result.push(Finding::broken(Rule::TalksOverReply.clause(), message, edition).untold(&why).at(at_us));
        any_unproven.get_or_insert(why);
    }
    // Why this run may not be the master's own: a reply disturbed in a way that could
    // have changed what the master did, or a rule that only a late read broke. An
    // unplanned pause under the timeout after which the master broke no rule changed
    // nothing a conformant master could see: no reason to run the scenario again.
    let deciding: Vec<_> = timeline.disturbed.iter().filter(|d| disturbed_from.is_some_and(|f| d.at_us >= f)).collect();
    let pause = deciding.iter().map(|d| d.pause_us).max().unwrap_or(0);
    let late = deciding.iter().map(|d| d.answered_late_us).max().unwrap_or(0);
    let held = deciding.iter().map(|d| d.delivered_late_us).max().unwrap_or(0);
    match disturbed_from {
        Some(from) if held > 0 && late == 0 && pause == 0 => Some(format!(
            "{} written while the kernel's workers that deliver them waited up to {:.3} ms for a processor, from \
             {:.3} ms on (the master may have heard them with pauses or in parts), and what the master did after them",
            replies(deciding.len()),
            held as f64 / 1000.0,
            from as f64 / 1000.0
        )),
        Some(from) if late > 0 => Some(format!(
            "{} disturbed by the harness's own timing from {:.3} ms on (a request read up to {:.3} ms late, \
             answered after its limit)",
            replies(deciding.len()),
            from as f64 / 1000.0,
            late as f64 / 1000.0
        )),
        Some(from) => Some(format!(
            "{} written with an unplanned pause (up to {:.3} ms) from {:.3} ms on, and what the master did \
             after them",
            replies(deciding.len()),
            pause as f64 / 1000.0,
            from as f64 / 1000.0
        )),
        None => any_unproven,
    }
}

/// "1 reply", "3 replies".
fn replies(n: usize) -> String {
    if n == 1 {
        "1 reply".to_string()
    } else {
        format!("{n} replies")
    }
}
