//! RFC 2217 (Telnet Com Port Control): a serial device server that sets its UART's
//! data rate and parity when the client asks (ser2net's `telnet(rfc2217)`, Moxa NPort,
//! Lantronix). Sans-IO: [`Telnet`] takes the bytes that come from the server and gives
//! the serial data in them and the answers the server's negotiation needs;
//! [`set_settings`] is the request for new UART settings. [`super::tcp::TcpLine`]
//! speaks it for `rfc2217://host:port`.

use hiperface_model::settings::Parity;
use hiperface_model::UartSettings;

/// Telnet's "interpret as command" byte; a data byte FFh is sent twice (RFC 854).
pub const IAC: u8 = 0xFF;
const SE: u8 = 240;
const SB: u8 = 250;
const WILL: u8 = 251;
const WONT: u8 = 252;
const DO: u8 = 253;
const DONT: u8 = 254;
/// RFC 856: 8-bit data as it is (no CR NUL).
const BINARY: u8 = 0;
/// RFC 858.
const SUPPRESS_GO_AHEAD: u8 = 3;
/// RFC 2217's option.
pub const COM_PORT_OPTION: u8 = 44;
/// RFC 2217 client-to-server commands; the server answers each with the command +
/// 100 and the value it applied.
const SET_BAUDRATE: u8 = 1;
const SET_DATASIZE: u8 = 2;
const SET_PARITY: u8 = 3;
const SET_STOPSIZE: u8 = 4;

/// What the client says first: it will use the com port option, and binary data both
/// ways (a HIPERFACE frame is any bytes).
pub fn greeting() -> Vec<u8> {
    vec![IAC, WILL, COM_PORT_OPTION, IAC, WILL, BINARY, IAC, DO, BINARY, IAC, DO, SUPPRESS_GO_AHEAD]
}

/// The request for `settings`: data rate, 8 data bits, parity, 1 stop bit (000:T7).
pub fn set_settings(settings: UartSettings) -> Vec<u8> {
    let parity = parity_code(settings);
    let mut out = Vec::new();
    let mut sub = |command: u8, value: &[u8]| {
        out.extend([IAC, SB, COM_PORT_OPTION, command]);
        for b in value {
            out.push(*b);
            if *b == IAC {
                out.push(IAC);
            }
        }
        out.extend([IAC, SE]);
    };
    sub(SET_BAUDRATE, &settings.baud.bits_per_second().to_be_bytes());
    sub(SET_DATASIZE, &[8]);
    sub(SET_PARITY, &[parity]);
    sub(SET_STOPSIZE, &[1]);
    out
}

/// RFC 2217's value for a parity rule.
fn parity_code(settings: UartSettings) -> u8 {
    match settings.parity {
        Parity::None => 1,
        Parity::Odd => 2,
        Parity::Even => 3,
    }
}

/// Serial data bytes to send: FFh doubled.
pub fn escape(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len());
    for b in data {
        out.push(*b);
        if *b == IAC {
            out.push(IAC);
        }
    }
    out
}

/// What one byte from the server was.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// A byte of serial data.
    Data(u8),
    /// Part of a command; nothing to do.
    Nothing,
    /// A negotiation to answer with these bytes.
    Answer(Vec<u8>),
    /// The server applied a com port setting (its command + 100 and the value).
    Applied { command: u8, value: Vec<u8> },
}

/// The receiving side's state.
#[derive(Debug, Default)]
pub struct Telnet {
    state: State,
    sub: Vec<u8>,
    /// The server agreed to the com port option (DO 44).
    pub com_port: bool,
    /// The value the server last said it applied, by command.
    pub applied: std::collections::BTreeMap<u8, Vec<u8>>,
}

#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
enum State {
    #[default]
    Data,
    Iac,
    Option(u8),
    Sub,
    SubIac,
}

impl Telnet {
    /// Take one byte from the server.
    pub fn take(&mut self, b: u8) -> Event {
        match (self.state, b) {
            (State::Data, IAC) => self.to(State::Iac, Event::Nothing),
            (State::Data, b) => Event::Data(b),
            (State::Iac, IAC) => self.to(State::Data, Event::Data(IAC)),
            (State::Iac, WILL | WONT | DO | DONT) => self.to(State::Option(b), Event::Nothing),
            (State::Iac, SB) => {
                self.sub.clear();
                self.to(State::Sub, Event::Nothing)
            }
            // NOP, GA, and the rest: no data.
            (State::Iac, _) => self.to(State::Data, Event::Nothing),
            (State::Option(verb), option) => {
                self.state = State::Data;
                self.negotiate(verb, option)
            }
            (State::Sub, IAC) => self.to(State::SubIac, Event::Nothing),
            (State::Sub, b) => {
                self.sub.push(b);
                Event::Nothing
            }
            (State::SubIac, SE) => {
                self.state = State::Data;
                match self.sub.as_slice() {
                    [COM_PORT_OPTION, command, value @ ..] if *command > 100 => {
                        let (command, value) = (command - 100, value.to_vec());
                        self.applied.insert(command, value.clone());
                        Event::Applied { command, value }
                    }
                    _ => Event::Nothing,
                }
            }
            (State::SubIac, b) => {
                // IAC IAC inside a subnegotiation is a data FFh of it.
                self.sub.push(b);
                self.to(State::Sub, Event::Nothing)
            }
        }
    }

    fn to(&mut self, state: State, e: Event) -> Event {
        self.state = state;
        e
    }

    /// Answer a negotiation: yes to the com port option, binary and no go-ahead; no to
    /// anything else (echo above all: the line's own echo is the harness's business).
    fn negotiate(&mut self, verb: u8, option: u8) -> Event {
        let wanted = matches!(option, COM_PORT_OPTION | BINARY | SUPPRESS_GO_AHEAD);
        match verb {
            DO if option == COM_PORT_OPTION => {
                self.com_port = true;
                Event::Nothing // our WILL was the offer
            }
            DO if wanted => Event::Nothing,
            DO => Event::Answer(vec![IAC, WONT, option]),
            WILL if wanted => Event::Answer(vec![IAC, DO, option]),
            WILL => Event::Answer(vec![IAC, DONT, option]),
            _ => Event::Nothing,
        }
    }

    /// Whether the server has said it applied `settings` (its answers to the data rate
    /// and parity requests of [`set_settings`]).
    pub fn has_applied(&self, settings: UartSettings) -> bool {
        let latest = |c: u8| self.applied.get(&c).map(Vec::as_slice);
        let rate = settings.baud.bits_per_second().to_be_bytes();
        latest(SET_BAUDRATE) == Some(&rate[..]) && latest(SET_PARITY) == Some(&[parity_code(settings)][..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::settings::Baud;

    #[test]
    fn the_settings_request_is_rfc_2217s() {
        let s = UartSettings { baud: Baud::B19200, parity: Parity::Odd, ..UartSettings::DEFAULT };
        assert_eq!(
            set_settings(s),
            [
                [IAC, SB, 44, 1, 0, 0, 0x4B, 0x00, IAC, SE].as_slice(),
                &[IAC, SB, 44, 2, 8, IAC, SE],
                &[IAC, SB, 44, 3, 2, IAC, SE],
                &[IAC, SB, 44, 4, 1, IAC, SE],
            ]
            .concat()
        );
    }

    #[test]
    fn data_comes_through_and_ffh_is_doubled() {
        assert_eq!(escape(&[0x40, 0xFF, 0x01]), [0x40, 0xFF, 0xFF, 0x01]);
        let mut t = Telnet::default();
        let got: Vec<Event> = [0x40, IAC, IAC, 0x01].into_iter().map(|b| t.take(b)).collect();
        assert_eq!(got, [Event::Data(0x40), Event::Nothing, Event::Data(0xFF), Event::Data(0x01)]);
    }

    #[test]
    fn negotiation_is_answered_and_applied_settings_are_heard() {
        let mut t = Telnet::default();
        let mut answers = Vec::new();
        let mut data = Vec::new();
        let s = UartSettings { baud: Baud::B19200, ..UartSettings::DEFAULT };
        let mut from_server =
            vec![IAC, DO, 44, IAC, WILL, 1 /* echo */, IAC, DO, 24 /* terminal type */, 0x55];
        from_server.extend([IAC, SB, 44, 101, 0, 0, 0x4B, 0x00, IAC, SE, IAC, SB, 44, 103, 3, IAC, SE]);
        for b in from_server {
            match t.take(b) {
                Event::Answer(a) => answers.extend(a),
                Event::Data(d) => data.push(d),
                _ => {}
            }
        }
        assert!(t.com_port);
        assert_eq!(answers, [IAC, DONT, 1, IAC, WONT, 24]);
        assert_eq!(data, [0x55]);
        assert!(t.has_applied(s));
        assert!(!t.has_applied(UartSettings::DEFAULT), "9600 was not applied");
    }
}
