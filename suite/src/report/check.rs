//! What to check, one line per finding: where in a device's firmware (or, for what the
//! harness could not see, in the set-up) a reader of a certificate starts looking. One
//! row per family of clauses; every clause of the registry is in exactly one row
//! (tested), so that a new clause cannot go without its line.

use crate::verdict::CaseVerdict;

/// The rows: the clauses of a family, and where to look when the device broke one.
const ROWS: &[(&[&str], &str)] = &[
    (
        &["000:T4", "000:2.2.1", "000:T28/settings"],
        "the UART set-up: data rate, parity and stop bit as the settings byte gives them, and when new settings take effect",
    ),
    (
        &["000:2.2.1/slave", "000:2.2.2", "000:2.2.2/reply-end", "000:2.2.2/timeout", "002:timing", "DESIGN:legacy-timeout"],
        "the frame timer: a request ends after the timeout pause (measured from the last stop bit), and nothing is sent \
         but replies, each followed by that pause",
    ),
    (
        &["000:T8", "000:T10"],
        "the reply path's latency: from the request's timeout to the first start bit, within the command's time of \
         Table 10 (EEPROM writes and interrupt latency before the reply count)",
    ),
    (
        &["000:T5", "000:2.3.1", "000:T6", "000:T30"],
        "the address and command bytes of the reply: the device's own address (also to the broadcast FFh, and a new \
         one as soon as Set Encoder Address took it), bit 6 of the command byte set, bit 7 only for a pending warning",
    ),
    (
        &["000:2.3.3", "000:T7", "000:T48"],
        "the checksum: the XOR of the address, the command and every data byte, over the bytes as sent, checked on \
         receipt and computed on transmission",
    ),
    (
        &["000:2.3.4", "000:2.3.4/critical", "000:T27", "000:T37", "DESIGN:stack"],
        "the error stack: a code pushed once while unread, the warning bit on every reply until 50h read it or 53h \
         reset the device, the position locked after a critical fault",
    ),
    (
        &["000:2.3.4/error", "000:2.4.2", "000:T47", "000:T49", "000:T50", "000:T51", "000:T52", "000:T53", "000:T54",
          "000:T55", "000:T56", "002:50h", "DESIGN:order"],
        "the request checks: which fault the firmware detects first when several hold, and the code it answers with \
         (Tables 47 to 56)",
    ),
    (
        &["000:T9", "000:T29", "000:T29/keeps", "002:57h", "DESIGN:power-up"],
        "the start-up sequence: silent while initializing, default settings until the first request or the window's \
         end, and what an Encoder Reset keeps",
    ),
    (
        &["000:T11", "000:T12", "000:T13", "000:T34", "000:T36", "002:63h", "DESIGN:position"],
        "the position path: the value's width and resolution in the reply, and how a preset sets the offset",
    ),
    (
        &["000:T14", "000:T15", "000:T57", "000:T58", "000:T59", "000:T60", "000:T72", "000:3.2.4", "000:3.2.5",
          "000:T61-T68", "000:T74"],
        "the sensor monitoring: the channel asked for, its value's scaling, and which measured condition raises which \
         fault code",
    ),
    (
        &["000:T16", "000:T17", "000:T18", "000:T46", "002:47h"],
        "the counter in EEPROM: its 24 bits, Code0 for Reset Counter, and the overflow's fault code",
    ),
    (
        &["000:2.4.2/data-fields", "000:T20", "000:T21", "000:T22", "000:T23", "000:T24", "000:T25", "000:T26",
          "DESIGN:fields", "002:example"],
        "the data-field bookkeeping: sizes in 16-byte blocks, each field's access code and write protection, offset + \
         count within the field, free memory",
    ),
    (
        &["000:T28", "000:T31", "000:T32", "000:T33", "000:T35", "002:56h", "DESIGN:52h", "001:5.1.4", "000:T38-T46",
          "000:T43", "000:T44"],
        "the command's handler: the reply's length and fields in the command's table, and the faults its EEPROM or \
         sensor access can raise",
    ),
    (
        &["000:2.2/cycle", "000:3.2.2/cyclic", "DESIGN:reply-window"],
        "the master's request cycle: one request at a time, the reply window left open before the next",
    ),
    (
        &["000:2.2.2/master-gap", "000:2.2.2/master-pause"],
        "the master's transmitter: a request's characters back to back (no gap of the timeout inside it), a pause of \
         the timeout before the next",
    ),
    (
        &["000:2.3/master", "000:2.3.4/master"],
        "the master's frames: address, command, data and checksum as the command table gives them, no fault \
         indications of its own",
    ),
    (
        &["000:T29/master", "000:3.3.1", "000:3.3.1/status"],
        "the master's start-up: the wait after power-up or a reset, then the slave's status read before operation",
    ),
    (
        &["000:2.3.4/warning", "000:3.3.4", "000:3.3.4/unknown", "000:T19/master"],
        "the master's fault reaction: the warning bit read out with 50h, each code's reaction, the worst case for a \
         code it does not know",
    ),
];

/// Where to look for a finding with `verdict` on `clause` ("" for the harness's own).
pub fn what_to_check(verdict: CaseVerdict, clause: &str) -> &'static str {
    match verdict {
        CaseVerdict::Error => {
            "the connection and the set-up: the port, the cable and the line's power, the device's address and data \
             rate, then run again"
        }
        CaseVerdict::Unknown => {
            "nothing on the device yet: the harness could not tell (the finding says why); run again on an idle \
             machine or a line that stamps each character"
        }
        CaseVerdict::NotExercised => {
            "the run, not the device: the situation never arose (the profile's options, the run's length or the \
             world given to it)"
        }
        _ => ROWS
            .iter()
            .find(|(ids, _)| ids.contains(&clause))
            .map_or("the device's behaviour against the clause's sentence above", |(_, what)| what),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::clause::CLAUSES;

    #[test]
    fn every_clause_is_in_one_row_and_every_row_names_clauses() {
        for c in CLAUSES {
            let rows = ROWS.iter().filter(|(ids, _)| ids.contains(&c.id())).count();
            assert_eq!(rows, 1, "{} is in {rows} rows of what to check", c.id());
        }
        for (ids, _) in ROWS {
            for id in *ids {
                assert!(CLAUSES.iter().any(|c| c.id() == *id), "{id} is no clause");
            }
        }
    }

    #[test]
    fn the_line_follows_the_clause_and_the_verdict() {
        assert!(what_to_check(CaseVerdict::Fail, "000:2.3.3").starts_with("the checksum"));
        assert!(what_to_check(CaseVerdict::Fail, "000:T10").starts_with("the reply path"));
        assert!(what_to_check(CaseVerdict::Error, "000:T10").starts_with("the connection"));
        assert!(what_to_check(CaseVerdict::Unknown, "").starts_with("nothing on the device"));
        assert!(what_to_check(CaseVerdict::Fail, "").starts_with("the device's behaviour"));
    }
}
