//! What a test encoder does to one request instead of answering as the model does:
//! the deviations the certification of a master injects to see how it reacts (an
//! error code, silence, a late, corrupt or interrupted reply, a position fault, a
//! restart). One definition for the harness's encoder, the search of the reference
//! master to a fixpoint and the tests that replay both.

use crate::frame::Frame;
use crate::response::{Response, ResponseFrame};
use crate::slave::inputs::PositionFault;
use crate::FaultCode;
use core::fmt;

/// What the encoder does to one request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Act {
    /// Answer with this error code instead (000:2.3.4).
    Error(FaultCode),
    /// No reply at all.
    Silence,
    /// Start the reply this much after its earliest start (past the limit of 000:T10).
    LateMs(u16),
    /// A reply whose checksum is wrong (000:2.3.3).
    CorruptChecksum,
    /// A pause of `us` inside the reply before character `before` (000:2.2.2: from
    /// the timeout on, two transmissions).
    Gap { before: usize, us: u64 },
    /// From this request on the encoder has this position fault (000:T39).
    PositionFault(PositionFault),
    /// The encoder restarts (a brown-out): no reply, initialization, default settings.
    Restart,
}

/// A reply as the encoder sends it: its characters, when the first start bit begins
/// (µs since power-on) and a pause inside it (before which character, how long).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ActedReply {
    pub frame: Frame,
    pub start_us: u64,
    pub gap: Option<(usize, u64)>,
}

/// What becomes of the reply once the act is done.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Acted {
    /// It is sent, as the act left it.
    Sent,
    /// None is sent.
    Silent,
    /// None is sent and the encoder restarts: the caller power-cycles its slave.
    Restart,
}

impl Act {
    /// The position fault this act switches on (the caller decides from which
    /// request on; the reply itself is left as it is).
    pub fn position_fault(self) -> Option<PositionFault> {
        match self {
            Act::PositionFault(f) => Some(f),
            _ => None,
        }
    }

    /// Do the act to `reply`, the model's reply to a request whose address byte was
    /// `address`.
    pub fn apply(self, address: u8, reply: &mut ActedReply) -> Acted {
        match self {
            Act::PositionFault(_) => {}
            Act::Error(code) => {
                // 000:2.3.4: an error reply carries command value 50h and the code.
                let error = ResponseFrame { address, warning: false, response: Response::Error(code) };
                reply.frame = error.encode();
            }
            Act::Silence => return Acted::Silent,
            Act::Restart => return Acted::Restart,
            Act::LateMs(ms) => reply.start_us = reply.start_us.saturating_add(u64::from(ms) * 1000),
            Act::CorruptChecksum => {
                if let Some((last, body)) = reply.frame.as_bytes().split_last() {
                    // The same length as the frame it is made from: it fits.
                    let corrupt = Frame::from_bytes(body).and_then(|mut f| f.push(last ^ 0x5A).map(|()| f));
                    if let Ok(frame) = corrupt {
                        reply.frame = frame;
                    }
                }
            }
            Act::Gap { before, us } => reply.gap = Some((before, us)),
        }
        Acted::Sent
    }
}

/// What the act did, as a report says it ("injected: ...").
impl fmt::Display for Act {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Act::Error(code) => write!(f, "error reply {code}"),
            Act::Silence => f.write_str("no reply"),
            Act::LateMs(ms) => write!(f, "reply {ms} ms late"),
            Act::CorruptChecksum => f.write_str("reply with a wrong checksum"),
            Act::Gap { us, .. } => write!(f, "a gap of {us} µs inside the reply"),
            Act::PositionFault(fault) => write!(f, "{fault:?} from now on"),
            Act::Restart => f.write_str("the encoder restarts"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checksum;

    fn reply() -> ActedReply {
        // Read Position's reply, address 40h (000:T11 form), sealed.
        let mut frame = Frame::from_bytes(&[0x40, 0x42, 0x00, 0x01, 0x02, 0x03]).unwrap();
        frame.seal().unwrap();
        ActedReply { frame, start_us: 1_000, gap: None }
    }

    #[test]
    fn an_error_reply_carries_50h_the_code_and_a_right_checksum() {
        let mut r = reply();
        assert_eq!(Act::Error(FaultCode::decode(0x0A)).apply(0x47, &mut r), Acted::Sent);
        assert_eq!(r.frame.as_bytes(), &[0x47, 0x50, 0x0A, 0x47 ^ 0x50 ^ 0x0A]);
        assert_eq!((r.start_us, r.gap), (1_000, None));
    }

    #[test]
    fn a_corrupt_checksum_changes_the_last_byte_only() {
        let mut r = reply();
        let before = r.frame;
        assert_eq!(Act::CorruptChecksum.apply(0x40, &mut r), Acted::Sent);
        let (b, a) = (before.as_bytes(), r.frame.as_bytes());
        assert_eq!(a.len(), b.len());
        assert_eq!(a[..a.len() - 1], b[..b.len() - 1]);
        assert_eq!(a[a.len() - 1], b[b.len() - 1] ^ 0x5A);
        assert!(!checksum::is_valid(a));
    }

    #[test]
    fn late_gap_silence_restart_and_position_faults() {
        let mut r = reply();
        assert_eq!(Act::LateMs(30).apply(0x40, &mut r), Acted::Sent);
        assert_eq!(r.start_us, 31_000);
        assert_eq!(Act::Gap { before: 3, us: 20_000 }.apply(0x40, &mut r), Acted::Sent);
        assert_eq!(r.gap, Some((3, 20_000)));
        let unchanged = r;
        assert_eq!(Act::Silence.apply(0x40, &mut r), Acted::Silent);
        assert_eq!(Act::Restart.apply(0x40, &mut r), Acted::Restart);
        let fault = Act::PositionFault(PositionFault::Singleturn);
        assert_eq!(fault.apply(0x40, &mut r), Acted::Sent);
        assert_eq!(r, unchanged);
        assert_eq!(fault.position_fault(), Some(PositionFault::Singleturn));
        assert_eq!(Act::Silence.position_fault(), None);
        let mut far = ActedReply { start_us: u64::MAX - 1, ..reply() };
        Act::LateMs(u16::MAX).apply(0x40, &mut far);
        assert_eq!(far.start_us, u64::MAX);
    }
}
