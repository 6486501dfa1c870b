//! Timing verdicts of one exchange: when the reply started, against the request's
//! timeout (000:2.2.2) and the command's maximum response time (000:T10).
//!
//! Both instants are windows (see `line::Window`): a line without a UART clock cannot
//! tell whether a peer meant a write as the start or the end of a character, and a
//! USB adapter passes bytes on late. A reply is early only if it is early under every
//! reading, late only if it is late under every reading: the harness's uncertainty
//! is never charged to the device.

use super::{Finding, TimingMode};
use crate::exchange::Exchange;
use hiperface_model::clause;
use hiperface_model::command::ResponseLimit;
use hiperface_model::Edition;

/// Grade the start of a reply of a device of `edition`. `tolerance_us`: the line's
/// jitter; the harness's own scheduling delay measured in the exchange is added (it
/// may have noticed the reply that much late, or written the request that much late).
pub fn grade(
    x: &Exchange,
    limits: ResponseLimit,
    tolerance_us: u64,
    mode: TimingMode,
    edition: Edition,
) -> Vec<Finding> {
    let Some((lo, hi)) = x.response_time_us() else { return Vec::new() };
    if mode == TimingMode::Off {
        return Vec::new();
    }
    let tol = (tolerance_us + x.harness_late_us) as i64;
    let mut found = Vec::new();
    if hi + tol < 0 {
        let msg = format!("reply started at least {} µs before the request's timeout elapsed", -hi);
        found.push(Finding::fail(msg, clause::FRAME_TIMING, edition));
    } else if lo - tol > limits.max_ms as i64 * 1000 {
        let msg = format!(
            "reply started at least {:.3} ms after the request's timeout; the limit is {} ms",
            lo as f64 / 1000.0,
            limits.max_ms
        );
        found.push(Finding::fail(msg, clause::COMMANDS, edition));
    } else if let Some(strict) = limits.strict_ms.filter(|s| lo - tol > *s as i64 * 1000) {
        let msg = format!(
            "reply after at least {:.3} ms: within Table 10's limit, beyond Table 36's {strict} ms",
            lo as f64 / 1000.0
        );
        found.push(Finding::non_strict(msg, clause::READ_SYNC_OFFSET));
    }
    if mode == TimingMode::Lenient {
        found = found.into_iter().map(|f| f.softened("timing graded leniently on this line")).collect();
    }
    found
}

/// The response time as one figure for statistics: the most the line's uncertainty
/// allows (exact on a UART and in virtual time), µs.
pub fn at_most_us(x: &Exchange) -> Option<i64> {
    x.response_time_us().map(|(_, hi)| hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::CaseVerdict;
    use crate::line::Window;
    use hiperface_model::datalink::RxChar;
    use hiperface_model::UartSettings;

    const CT: u64 = 1146; // 9600 Bd, 11 bits
    const TIMEOUT: u64 = 5730;

    /// A Read Position exchange: the request ends in `end`, the reply's first start bit
    /// began in `start`.
    fn exchange(end: Window, start: Window) -> Exchange {
        Exchange {
            request: vec![0x40, 0x42, 0x02],
            stray: Vec::new(),
            sent_start_us: end.earliest_us - 3 * CT,
            request_end: end,
            reply: vec![RxChar::ok(0x40, start.latest_us + CT)],
            reply_start: Some(start),
            trailing: Vec::new(),
            settings: UartSettings::DEFAULT,
            timeout_us: TIMEOUT,
            harness_late_us: 0,
        }
    }

    const LIMITS: ResponseLimit = ResponseLimit { max_ms: 10, strict_ms: None };

    fn verdicts(x: &Exchange, mode: TimingMode) -> Vec<CaseVerdict> {
        grade(x, LIMITS, 2_000, mode, Edition::Current).into_iter().map(|f| f.verdict()).collect()
    }

    #[test]
    fn a_peer_writing_its_reply_when_its_timeout_elapsed_is_on_time() {
        // A pseudo-terminal peer that writes the whole reply the moment its timeout
        // elapsed: its write is read as the start of the first character.
        let end = Window::exact(100_000);
        let arrival = 100_000 + TIMEOUT + 50;
        let x = exchange(end, Window { earliest_us: arrival - CT, latest_us: arrival });
        assert_eq!(verdicts(&x, TimingMode::Strict), vec![]);
    }

    #[test]
    fn a_peer_that_does_not_wait_for_the_timeout_is_early() {
        let end = Window::exact(100_000);
        let arrival = 100_000 + 500;
        let x = exchange(end, Window { earliest_us: arrival - CT, latest_us: arrival });
        let f = grade(&x, LIMITS, 2_000, TimingMode::Strict, Edition::Current);
        assert_eq!(f.len(), 1);
        assert_eq!((f[0].verdict(), f[0].clause_id()), (CaseVerdict::Fail, "000:2.2.2"));
        assert!(f[0].message().contains("at least 5230 µs before"), "{}", f[0].message());
    }

    #[test]
    fn late_only_when_late_under_every_reading() {
        let end = Window { earliest_us: 100_000, latest_us: 100_000 + CT };
        // The earliest reading of the start is 10.5 ms after the latest reading of the timeout:
        // within the 2 ms tolerance of the 10 ms limit.
        let s = 100_000 + CT + TIMEOUT + 10_500;
        let x = exchange(end, Window { earliest_us: s, latest_us: s + CT });
        assert_eq!(verdicts(&x, TimingMode::Strict), vec![]);
        let s = s + 2_000;
        let x = exchange(end, Window { earliest_us: s, latest_us: s + CT });
        assert_eq!(verdicts(&x, TimingMode::Strict), vec![CaseVerdict::Fail]);
        assert_eq!(verdicts(&x, TimingMode::Lenient), vec![CaseVerdict::NonStrict]);
        assert_eq!(verdicts(&x, TimingMode::Off), vec![]);
        // The harness itself woke 3 ms late in that exchange: it may have noticed the
        // reply that late, so the reply is not shown to be late.
        let x = Exchange { harness_late_us: 3_000, ..x };
        assert_eq!(verdicts(&x, TimingMode::Strict), vec![]);
    }

    #[test]
    fn table_36_is_non_strict() {
        let end = Window::exact(100_000);
        let s = 100_000 + TIMEOUT + 20_000;
        let x = exchange(end, Window::exact(s));
        let f = grade(&x, ResponseLimit { max_ms: 30, strict_ms: Some(10) }, 0, TimingMode::Strict, Edition::Current);
        assert_eq!(f.iter().map(|f| f.verdict()).collect::<Vec<_>>(), vec![CaseVerdict::NonStrict]);
        assert_eq!(at_most_us(&x), Some(20_000));
    }
}
