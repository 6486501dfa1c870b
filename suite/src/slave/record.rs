//! The record of the wire: what the harness saw of a slave certification, kept in
//! report.json so that `decode` grades the run again and gets what the run got.
//!
//! Long because: the record's types, the Recorder that writes them and the Replay that
//! plays them back must agree field for field; in one file they are kept in step.
//!
//! A verdict must rest on what the device did on the wire and on nothing else. The
//! record holds exactly that: every exchange as the line delivered it (the request and
//! the window in which its last character ended, each reply character with its stamp,
//! what came outside a reply, the settings in force, how late the harness and the line
//! itself may have been), every wait on the idle line, every change of settings, and
//! the run's options, profile and line facts (its kind, its tolerance). It is recorded
//! at the boundary every verdict passes through ([`Bus`]): [`Recorder`] writes it
//! while a run talks to a live line, [`Replay`] plays it back to the same catalogue,
//! which then makes the same requests and gets the same answers. So the verdicts of a
//! decoded record are the run's, case by case and exchange by exchange, and a record
//! that does not fit the catalogue (another version's) is refused where it departs,
//! never graded against the wrong request.

use crate::exchange::{Bus, Char, Exchange, HeardLate, LineFacts, LineFindings, Listen};
use crate::line::{LineError, Window};
use hiperface_model::datalink::RxChar;
use hiperface_model::{Hex, UartSettings};
use serde::{Deserialize, Serialize};

/// The record's format, as written into it.
pub const FORMAT: &str = "hiperface-wire-record/1";

fn chars(c: &[RxChar]) -> Vec<Char> {
    c.iter().copied().map(Char::from).collect()
}

fn rx(c: &[Char]) -> Vec<RxChar> {
    c.iter().copied().map(RxChar::from).collect()
}

/// One exchange as the line delivered it (see [`Exchange`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedExchange {
    /// The request, hex.
    pub request: String,
    /// Why the harness sent a frame no conformant master sends, where it did: a
    /// request it makes malformed on purpose, or one sent with the wrong parity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub injected: Option<String>,
    /// The settings in force (the settings byte, hex).
    pub settings: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stray: Vec<Char>,
    pub sent_start_us: u64,
    /// When the slave received the request's last character: a window on a line
    /// without a UART clock, exact in virtual time and on a UART.
    pub request_end: Window,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reply: Vec<Char>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reply_start: Option<Window>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trailing: Vec<Char>,
    pub timeout_us: u64,
    pub pause_us: u64,
    /// What the harness could not see: its own lateness and the line's measured delay.
    pub harness_late_us: u64,
    /// How long the harness's write of the request took (`Exchange::request_write_us`);
    /// absent in records written before it was kept, which are graded as they were.
    #[serde(default, skip_serializing_if = "crate::line::delivery::is_zero")]
    pub request_write_us: u64,
    #[serde(default)]
    pub line_late: crate::line::delivery::LineLate,
    /// How long the device's processor was held (`Exchange::device_held`); absent
    /// where nothing was measured (a device with a processor of its own) and in
    /// records written before it was kept.
    #[serde(default, skip_serializing_if = "crate::line::delivery::DeviceHeld::is_zero")]
    pub device_held: crate::line::delivery::DeviceHeld,
}

impl RecordedExchange {
    fn of(x: &Exchange, listen: Listen) -> RecordedExchange {
        RecordedExchange {
            request: Hex(&x.request).to_string(),
            injected: injected(&x.request, listen.wrong_parity),
            settings: format!("{:02X}", x.settings.byte()),
            stray: chars(&x.stray),
            sent_start_us: x.sent_start_us,
            request_end: x.request_end,
            reply: chars(&x.reply),
            reply_start: x.reply_start,
            trailing: chars(&x.trailing),
            timeout_us: x.timeout_us,
            pause_us: x.pause_us,
            harness_late_us: x.harness_late_us,
            request_write_us: x.request_write_us,
            line_late: x.line_late,
            device_held: x.device_held,
        }
    }

    fn exchange(&self) -> Result<Exchange, RecordError> {
        let bad = |what: &str| RecordError::Malformed(format!("{what} of the exchange of request [{}]", self.request));
        let request = crate::vectors::parse_hex(&self.request).map_err(|_| bad("the request"))?;
        let byte = u8::from_str_radix(&self.settings, 16).map_err(|_| bad("the settings byte"))?;
        let settings = UartSettings::decode(byte).map_err(|_| bad("the settings byte"))?;
        Ok(Exchange {
            request,
            stray: rx(&self.stray),
            sent_start_us: self.sent_start_us,
            request_end: self.request_end,
            reply: rx(&self.reply),
            reply_start: self.reply_start,
            trailing: rx(&self.trailing),
            settings,
            timeout_us: self.timeout_us,
            pause_us: self.pause_us,
            harness_late_us: self.harness_late_us,
            request_write_us: self.request_write_us,
            line_late: self.line_late,
            device_held: self.device_held,
            heard_late: HeardLate::default(),
        })
    }
}

/// Why a frame the harness sent is one no conformant master sends.
fn injected(frame: &[u8], wrong_parity: bool) -> Option<String> {
    if wrong_parity {
        return Some("sent with the wrong parity on purpose (000:T47)".into());
    }
    hiperface_model::request::RequestFrame::decode(frame)
        .err()
        .map(|e| format!("a frame that is no request, sent on purpose: {e}"))
}

/// A line fault as recorded (the run ended on it, or a case did).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Failure {
    pub kind: String,
    pub message: String,
}

impl Failure {
    fn of(e: &LineError) -> Failure {
        let kind = match e {
            LineError::Open { .. } => "open",
            LineError::Io(_) => "io",
            LineError::Gone(_) => "gone",
            LineError::Echo(_) => "echo",
            LineError::Settings { .. } => "settings",
            LineError::Record(_) => "record",
        };
        let message = match e {
            LineError::Gone(m) | LineError::Echo(m) | LineError::Record(m) => m.clone(),
            other => other.to_string(),
        };
        Failure { kind: kind.into(), message }
    }

    fn error(&self) -> LineError {
        match self.kind.as_str() {
            "gone" => LineError::Gone(self.message.clone()),
            "echo" => LineError::Echo(self.message.clone()),
            "record" => LineError::Record(self.message.clone()),
            _ => LineError::Io(std::io::Error::other(self.message.clone())),
        }
    }
}

/// One thing the run asked of the line, and what the line gave.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "kebab-case")]
pub enum Event {
    /// The clock read.
    Now { t_us: u64 },
    Exchange {
        listen: Listen,
        #[serde(flatten)]
        exchange: Box<RecordedExchange>,
    },
    /// A request the line could not carry: what was asked, and the line's fault.
    ExchangeFailed { request: String, listen: Listen, failure: Failure },
    /// A wait on the idle line, and what came in it.
    Listen {
        until_us: u64,
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        heard: Vec<Char>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        failure: Option<Failure>,
    },
    /// The line switched to other settings (the settings byte, hex).
    Configure {
        settings: String,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        failure: Option<Failure>,
    },
}

/// The run's options that bear on verdicts, as given.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedOptions {
    pub allow_writes: bool,
    pub allow_counter_change: bool,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub allow_adjustment: bool,
    pub write_budget: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cases: Option<String>,
    pub grading: String,
    pub timing: crate::verdict::timing::TimingMode,
    /// The simulator's world the lockstep model was put in (empty for a device).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world_inputs: Option<RecordedInputs>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub world_init_faults: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub world_position_faults: Vec<String>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub world_i2c_fault: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedInputs {
    pub position: u64,
    pub speed: i32,
    pub temperature_c: i16,
    pub led_current_ma: u16,
}

impl RecordedOptions {
    pub fn of(o: &super::Options) -> RecordedOptions {
        RecordedOptions {
            allow_writes: o.allow_writes,
            allow_counter_change: o.allow_counter_change,
            allow_adjustment: o.allow_adjustment,
            write_budget: o.write_budget,
            cases: o.cases.clone(),
            grading: format!("{:?}", o.grading).to_lowercase(),
            timing: o.timing,
            world_inputs: o.world.inputs.map(|i| RecordedInputs {
                position: i.position,
                speed: i.speed,
                temperature_c: i.temperature_c,
                led_current_ma: i.led_current_ma,
            }),
            world_init_faults: o.world.init_faults.iter().map(|f| f.name().to_string()).collect(),
            world_position_faults: o.world.position_faults.iter().map(|f| f.name().to_string()).collect(),
            world_i2c_fault: o.world.i2c_fault,
        }
    }

    pub fn options(&self) -> Result<super::Options, RecordError> {
        use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
        let grading =
            self.grading.parse().map_err(|_| RecordError::Malformed(format!("grading `{}`", self.grading)))?;
        let init_faults = self
            .world_init_faults
            .iter()
            .map(|n| InitFault::from_name(n).ok_or_else(|| RecordError::Malformed(format!("start-up fault `{n}`"))))
            .collect::<Result<Vec<_>, _>>()?;
        let position_faults = self
            .world_position_faults
            .iter()
            .map(|n| PositionFault::from_name(n).ok_or_else(|| RecordError::Malformed(format!("position fault `{n}`"))))
            .collect::<Result<Vec<_>, _>>()?;
        let inputs = self.world_inputs.map(|i| PhysicalInputs {
            position: i.position,
            speed: i.speed,
            temperature_c: i.temperature_c,
            led_current_ma: i.led_current_ma,
        });
        Ok(super::Options {
            allow_writes: self.allow_writes,
            allow_counter_change: self.allow_counter_change,
            allow_adjustment: self.allow_adjustment,
            write_budget: self.write_budget,
            cases: self.cases.clone(),
            grading,
            interrupt: None,
            world: crate::world::World { inputs, init_faults, position_faults, i2c_fault: self.world_i2c_fault },
            timing: self.timing,
        })
    }
}

/// The record of one slave certification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    pub format: String,
    /// The tool that wrote it: a record is played back to that catalogue.
    pub tool: String,
    /// The profile the device was certified against, as TOML (a built-in's too).
    pub profile: String,
    pub options: RecordedOptions,
    pub line: LineFacts,
    pub events: Vec<Event>,
    /// What the run found out about the line by its end (its echo, the probe's figures).
    pub found: LineFindings,
}

/// Why a record cannot be played back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RecordError {
    #[error("not a record of this tool's format: {0}")]
    Format(String),
    #[error("the record's {0} cannot be read")]
    Malformed(String),
    #[error("the record's profile does not load: {0}")]
    Profile(String),
}

/// Records what a run asks of a [`Bus`] and what it gives.
pub struct Recorder<'a> {
    bus: &'a mut dyn Bus,
    events: Vec<Event>,
}

impl<'a> Recorder<'a> {
    pub fn new(bus: &'a mut dyn Bus) -> Recorder<'a> {
        Recorder { bus, events: Vec::new() }
    }

    /// The record of the run, with its profile and options.
    pub fn finish(self, profile: &hiperface_model::Profile, options: &super::Options) -> Record {
        Record {
            format: FORMAT.into(),
            tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
            profile: crate::profile_file::to_toml(profile),
            options: RecordedOptions::of(options),
            line: self.bus.facts(),
            found: self.bus.findings(),
            events: self.events,
        }
    }
}

impl Bus for Recorder<'_> {
    fn now_us(&mut self) -> u64 {
        let t_us = self.bus.now_us();
        self.events.push(Event::Now { t_us });
        t_us
    }
    fn exchange_listening(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError> {
        let got = self.bus.exchange_listening(request, listen);
        self.events.push(match &got {
            Ok(x) => Event::Exchange { listen, exchange: Box::new(RecordedExchange::of(x, listen)) },
            Err(e) => Event::ExchangeFailed { request: Hex(request).to_string(), listen, failure: Failure::of(e) },
        });
        got
    }
    fn listen_until(&mut self, until_us: u64) -> Result<Vec<RxChar>, LineError> {
        let got = self.bus.listen_until(until_us);
        self.events.push(match &got {
            Ok(c) => Event::Listen { until_us, heard: chars(c), failure: None },
            Err(e) => Event::Listen { until_us, heard: Vec::new(), failure: Some(Failure::of(e)) },
        });
        got
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        let got = self.bus.configure(settings);
        let failure = got.as_ref().err().map(Failure::of);
        self.events.push(Event::Configure { settings: format!("{:02X}", settings.byte()), failure });
        got
    }
    fn settings(&self) -> UartSettings {
        self.bus.settings()
    }
    fn timeout_us(&self) -> u64 {
        self.bus.timeout_us()
    }
    fn facts(&self) -> LineFacts {
        self.bus.facts()
    }
    fn findings(&self) -> LineFindings {
        self.bus.findings()
    }
}

/// A record played back: each request the run makes must be the one recorded there,
/// and gets the recorded answer. Settings and the timeout follow the recorded changes.
pub struct Replay {
    events: std::iter::Peekable<std::vec::IntoIter<Event>>,
    index: usize,
    /// Where the run departed from the record, once it has.
    departed: Option<String>,
    last_now: u64,
    settings: UartSettings,
    edition: hiperface_model::Edition,
    line: LineFacts,
    found: LineFindings,
}

impl Replay {
    pub fn new(record: &Record, edition: hiperface_model::Edition) -> Replay {
        Replay {
            events: record.events.clone().into_iter().peekable(),
            index: 0,
            departed: None,
            last_now: 0,
            settings: UartSettings::DEFAULT,
            edition,
            line: record.line.clone(),
            found: record.found.clone(),
        }
    }

    /// The next event, or why the run asked for something the record does not hold.
    fn next(&mut self, asked: &str) -> Result<Event, LineError> {
        if let Some(why) = &self.departed {
            return Err(LineError::Record(why.clone()));
        }
        self.index += 1;
        self.events.next().ok_or_else(|| {
            LineError::Record(format!("the run asked for {asked} at event {}, after the record's end", self.index))
        })
    }

    /// The run asked for something else than the record holds next: from here on
    /// every request is refused with the reason.
    fn departs(&mut self, recorded: &Event, asked: &str) -> LineError {
        let what = match recorded {
            Event::Now { .. } => "a reading of the clock".to_string(),
            Event::Exchange { exchange, .. } => format!("the request [{}]", exchange.request),
            Event::ExchangeFailed { request, .. } => format!("the request [{request}]"),
            Event::Listen { until_us, .. } => format!("a wait until {until_us} µs"),
            Event::Configure { settings, .. } => format!("a change to settings {settings}h"),
        };
        let why = format!(
            "the record departs from this catalogue at event {}: it holds {what}, the run asked for {asked}",
            self.index
        );
        self.departed = Some(why.clone());
        LineError::Record(why)
    }

    /// Where the run departed from the record, if it did; or the events it left unread.
    pub fn departure(&mut self) -> Option<String> {
        self.departed.clone().or_else(|| {
            let left = self.events.by_ref().count();
            (left > 0).then(|| format!("the run ended with {left} events of the record unread"))
        })
    }
}

impl Bus for Replay {
    fn now_us(&mut self) -> u64 {
        // The clock is read where the run reads it. Where the record holds something
        // else, the run has departed from it: the time stays where it was, and the
        // next request is refused with the reason.
        match self.events.peek() {
            Some(Event::Now { t_us }) if self.departed.is_none() => {
                let t = *t_us;
                self.index += 1;
                self.events.next();
                self.last_now = t;
                t
            }
            Some(other) if self.departed.is_none() => {
                let other = other.clone();
                self.index += 1;
                let _ = self.departs(&other, "a reading of the clock");
                self.last_now
            }
            _ => self.last_now,
        }
    }
    fn exchange_listening(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError> {
        let asked = format!("the request [{}]", Hex(request));
        match self.next(&asked)? {
            Event::Exchange { listen: l, exchange } if l == listen && exchange.request == Hex(request).to_string() => {
                exchange.exchange().map_err(|e| LineError::Record(e.to_string()))
            }
            Event::ExchangeFailed { request: r, listen: l, failure }
                if l == listen && r == Hex(request).to_string() =>
            {
                Err(failure.error())
            }
            other => Err(self.departs(&other, &asked)),
        }
    }
    fn listen_until(&mut self, t_us: u64) -> Result<Vec<RxChar>, LineError> {
        let asked = format!("a wait until {t_us} µs");
        match self.next(&asked)? {
            Event::Listen { until_us, heard, failure } if until_us == t_us => match failure {
                Some(f) => Err(f.error()),
                None => Ok(rx(&heard)),
            },
            other => Err(self.departs(&other, &asked)),
        }
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        let byte = format!("{:02X}", settings.byte());
        let asked = format!("a change to settings {byte}h");
        match self.next(&asked)? {
            Event::Configure { settings: s, failure } if s == byte => match failure {
                Some(f) => Err(f.error()),
                None => {
                    self.settings = settings;
                    Ok(())
                }
            },
            other => Err(self.departs(&other, &asked)),
        }
    }
    fn settings(&self) -> UartSettings {
        self.settings
    }
    fn timeout_us(&self) -> u64 {
        self.settings.timeout_us(self.edition)
    }
    fn facts(&self) -> LineFacts {
        self.line.clone()
    }
    fn findings(&self) -> LineFindings {
        self.found.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_a_master_never_sends_is_marked_injected() {
        assert_eq!(injected(&[0x40, 0x42, 0x02], false), None);
        assert!(injected(&[0x40, 0x42, 0x00], false).is_some_and(|w| w.contains("no request")));
        assert!(injected(&[0x40, 0x42, 0x02], true).is_some_and(|w| w.contains("parity")));
    }
}
