//! The echo's paths on a virtual line that echoes: found, taken off, late, unlike the
//! request, and under `--echo off`.

use super::*;
use crate::line::virtual_line::VirtualLine;
use hiperface_model::{profiles, Slave};

/// The reference model on a virtual line that echoes: every character the
/// master sends comes back a character time later, or, with `corrupt`, with its
/// lowest bit flipped; one sent with the wrong parity comes back as 00h.
struct Echoing {
    line: VirtualLine<Slave>,
    corrupt: bool,
    back: VecDeque<RxChar>,
    /// The machine's delivery delay: everything the harness reads (echo and
    /// reply alike, in the order they were on the wire) reaches it this late, µs.
    delay_us: u64,
}

impl Echoing {
    /// The device's next character due by `until_us` as delivered.
    fn device_char(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let d = self.delay_us;
        Ok(self.line.recv(until_us.saturating_sub(d))?.map(|c| RxChar { at_us: c.at_us + d, ..c }))
    }
}

impl Line for Echoing {
    fn now_us(&mut self) -> u64 {
        self.line.now_us()
    }
    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let start = self.line.now_us();
        let ct = self.line.settings().char_time_us();
        // Sent in other settings than the line's (the wrong parity): the harness's
        // UART, back in the right ones when the echo is read, reads each as 00h
        // (Linux without PARMRK).
        let garbled = self.line.settings() != UartSettings::DEFAULT;
        let sent = self.line.send(bytes)?;
        for (i, b) in bytes.iter().enumerate() {
            let byte = if garbled {
                0
            } else if self.corrupt {
                b ^ 1
            } else {
                *b
            };
            self.back.push_back(RxChar::ok(byte, start + (i as u64 + 1) * ct + self.delay_us));
        }
        Ok(sent)
    }
    /// In the order of arrival: the device's characters due before the next echo
    /// come first.
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        match self.back.front().map(|c| c.at_us) {
            Some(at) if at <= until_us => match self.device_char(at.saturating_sub(1))? {
                Some(c) => Ok(Some(c)),
                None => Ok(self.back.pop_front()),
            },
            _ => self.device_char(until_us),
        }
    }
    fn start_of(&self, ch: &RxChar) -> Window {
        self.line.start_of(ch)
    }
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        self.line.wait_until(t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        self.line.configure(settings)
    }
    fn settings(&self) -> UartSettings {
        self.line.settings()
    }
    fn kind(&self) -> LineKind {
        LineKind::Virtual
    }
    fn describe(&self) -> String {
        "echoing".into()
    }
    fn carries_parity(&self) -> Result<(), &'static str> {
        Ok(())
    }
}

fn echoing(corrupt: bool) -> Echoing {
    Echoing {
        line: VirtualLine::new(Slave::operational(profiles::srs50())),
        corrupt,
        back: VecDeque::new(),
        delay_us: 0,
    }
}

fn read_all(line: &mut impl Line, until_us: u64) -> Vec<u8> {
    std::iter::from_fn(|| line.recv(until_us).ok().flatten()).map(|c| c.byte).collect()
}

/// Read Type Label to 40h: the request and the reply the model gives.
const REQUEST: [u8; 3] = [0x40, 0x52, 0x12];

#[test]
fn auto_finds_the_echo_and_takes_it_off() {
    let mut line = EchoLine::new(echoing(false), EchoMode::Auto);
    let sent = line.send(&REQUEST).unwrap();
    assert_eq!(line.echo(), Echo::Echoes);
    let reply = read_all(&mut line, sent.end.latest_us + 100_000);
    assert_eq!(&reply[..2], &[0x40, 0x52], "the device's reply, without the echo: {reply:02X?}");
    assert!(hiperface_model::checksum::is_valid(&reply));
    // The second request's echo is taken off too.
    let sent = line.send(&REQUEST).unwrap();
    assert_eq!(&read_all(&mut line, sent.end.latest_us + 100_000)[..2], &[0x40, 0x52]);
}

#[test]
fn auto_on_a_quiet_line_gives_the_reply_back_whole() {
    let mut line = EchoLine::new(VirtualLine::new(Slave::operational(profiles::srs50())), EchoMode::Auto);
    let sent = line.send(&REQUEST).unwrap();
    assert_eq!(line.echo(), Echo::Quiet);
    let reply = read_all(&mut line, sent.end.latest_us + 100_000);
    assert_eq!(reply.len(), 7, "{reply:02X?}");
    assert!(hiperface_model::checksum::is_valid(&reply));
}

/// A request sent with the wrong parity on an echoing line (behind a `Box<dyn
/// Line>`, as a run holds it): its echo is taken off, and what is read is the
/// device's 09h reply (000:T47).
#[test]
fn the_echo_of_a_request_with_a_parity_error_is_taken_off() {
    let mut line: Box<dyn Line> = Box::new(EchoLine::new(echoing(false), EchoMode::On));
    let sent = line.send_with_wrong_parity(&[0x40, 0x42, 0x02]).unwrap();
    let reply = read_all(&mut line, sent.end.latest_us + 100_000);
    // An unparsed request is answered in the form of Read Encoder Status, 09h.
    assert_eq!(reply.get(..3), Some(&[0x40, 0x50, 0x09][..]), "{reply:02X?}");
    assert!(hiperface_model::checksum::is_valid(&reply));
}

/// A line known to echo, delivering 30 ms late (a busy machine's pseudo-terminal):
/// the echo is waited for past its deadline and taken off, the reply read after it
/// (was "the echo of [..] came back as []", a line fault, with three busy loops).
#[test]
fn a_late_echo_of_a_line_known_to_echo_is_waited_for() {
    let mut line = EchoLine::new(Echoing { delay_us: 30_000, ..echoing(false) }, EchoMode::On);
    let sent = line.send(&REQUEST).unwrap();
    let reply = read_all(&mut line, sent.end.latest_us + 100_000);
    assert_eq!(&reply[..2], &[0x40, 0x52], "the device's reply, without the echo: {reply:02X?}");
    assert!(hiperface_model::checksum::is_valid(&reply));
}

/// `--echo on` over a line that does not echo: the reply read for the echo is a
/// line fault, after the wait, never the device's.
#[test]
fn echo_on_over_a_quiet_line_is_a_line_fault() {
    let mut line = EchoLine::new(VirtualLine::new(Slave::operational(profiles::srs50())), EchoMode::On);
    let e = line.send(&REQUEST).unwrap_err();
    assert!(e.to_string().contains("not the device's"), "{e}");
}

#[test]
fn an_echo_unlike_the_request_is_a_line_fault() {
    let mut line = EchoLine::new(echoing(true), EchoMode::On);
    let e = line.send(&REQUEST).unwrap_err();
    assert!(matches!(e, LineError::Echo(_)), "{e}");
    assert!(e.to_string().contains("not the device's"), "{e}");
}

#[test]
fn echo_off_on_an_echoing_line_says_so_at_every_request() {
    let mut line = EchoLine::new(echoing(false), EchoMode::Off);
    let e = line.send(&REQUEST).unwrap_err();
    assert!(e.to_string().contains("use --echo auto"), "{e}");
    // A caller that goes on (the run's first reads do) is told again, and is never
    // given an echo for a reply.
    for _ in 0..3 {
        let e = line.send(&[0x40, 0x56, 0x16]).unwrap_err();
        assert!(e.to_string().contains("use --echo auto"), "{e}");
    }
}

/// Under --echo off the reply to a request whose echo was found is left on the
/// line; on a slow machine it is still there when the next request goes out, ahead
/// of that request's echo. The diagnosis stays the same, never "a collision"
/// (seen in CI: "the echo of [40 52 12] came back as [40 52 40]").
#[test]
fn echo_off_says_the_same_when_an_earlier_reply_is_read_first() {
    let mut line = EchoLine::new(echoing(false), EchoMode::Off);
    let e = line.send(&REQUEST).unwrap_err();
    assert!(e.to_string().contains("use --echo auto"), "{e}");
    // The device replies while the harness is held up.
    let now = line.now_us();
    line.wait_until(now + 20_000).unwrap();
    let e = line.send(&REQUEST).unwrap_err();
    assert!(e.to_string().contains("use --echo auto"), "{e}");
}
