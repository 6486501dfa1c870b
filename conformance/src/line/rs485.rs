//! The kernel's RS-485 mode (`TIOCSRS485`) for a native UART that drives its
//! transceiver's DE pin with RTS: set for a run with `--rs485 on`, read back as the
//! driver reports it (for the certificate), and put back as it was when the run ends.
//! The ioctl is `serial2`'s (the crate wraps the unsafe call); a port whose driver
//! has no RS-485 mode (a pseudo-terminal, most USB adapters) is refused with a clear
//! message rather than run in a mode it is not in.

use hiperface_suite::line::LineError;
use serial2::rs4xx::{Rs485Config, TransceiverMode};
use std::time::Duration;

/// `--rs485`: what to do with the port's RS-485 mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Rs485Mode {
    /// Leave the port's mode as it is (an adapter with automatic direction control,
    /// or a port set up beforehand).
    #[default]
    Leave,
    /// RS-485: the kernel keys RTS for each transmission.
    On,
    /// The default (RS-232) mode.
    Off,
}

/// The RS-485 settings asked for on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rs485Settings {
    pub mode: Rs485Mode,
    /// RTS low (not high) while sending: for transceivers whose DE is active low.
    pub rts_low_while_sending: bool,
    /// Delay between RTS and the first character, ms.
    pub delay_before_ms: f64,
    /// Delay between the last character and RTS released, ms.
    pub delay_after_ms: f64,
}

/// The port's mode while a run holds it; the mode it had is put back on drop.
pub struct Rs485Guard {
    port: serial2::SerialPort,
    before: TransceiverMode,
    /// The mode in force, as the driver reports it.
    pub in_force: String,
}

impl Rs485Settings {
    /// The transceiver mode these settings ask for; `None` to leave the port as it is.
    pub fn transceiver_mode(&self) -> Option<TransceiverMode> {
        match self.mode {
            Rs485Mode::Leave => None,
            Rs485Mode::Off => Some(TransceiverMode::Default),
            Rs485Mode::On => {
                let mut c = Rs485Config::new();
                c.set_invert_rts(self.rts_low_while_sending);
                c.set_delay_before_send(Duration::from_secs_f64(self.delay_before_ms.max(0.0) / 1000.0));
                c.set_delay_after_send(Duration::from_secs_f64(self.delay_after_ms.max(0.0) / 1000.0));
                Some(TransceiverMode::Rs485(c))
            }
        }
    }

    /// Set the mode on `path` before the run opens it; `None` where it is left alone.
    /// The guard must live as long as the run: its drop puts the old mode back.
    pub fn apply(&self, path: &str) -> Result<Option<Rs485Guard>, LineError> {
        let Some(mode) = self.transceiver_mode() else { return Ok(None) };
        let refused = |what: &str, e: std::io::Error| LineError::Open {
            port: path.to_string(),
            reason: format!(
                "{what}: {e}; its driver has no RS-485 mode (a pseudo-terminal or a USB adapter): use one \
                 with automatic direction control and --rs485 leave"
            ),
        };
        let port = serial2::SerialPort::open(path, serial2::KeepSettings)
            .map_err(|e| LineError::Open { port: path.to_string(), reason: e.to_string() })?;
        let before = port.get_rs4xx_mode().map_err(|e| refused("cannot read the RS-485 mode (TIOCGRS485)", e))?;
        port.set_rs4xx_mode(mode).map_err(|e| refused("cannot set the RS-485 mode (TIOCSRS485)", e))?;
        let in_force = port.get_rs4xx_mode().map(|m| describe(&m)).unwrap_or_else(|e| format!("unknown ({e})"));
        Ok(Some(Rs485Guard { port, before, in_force }))
    }
}

impl Drop for Rs485Guard {
    fn drop(&mut self) {
        let _ = self.port.set_rs4xx_mode(self.before.clone());
    }
}

/// A transceiver mode for people: "RS-485, RTS high while sending, 0.000 ms before,
/// 0.000 ms after".
pub fn describe(mode: &TransceiverMode) -> String {
    match mode {
        TransceiverMode::Default => "default (RS-232) mode".into(),
        TransceiverMode::Rs422 => "RS-422 mode".into(),
        TransceiverMode::Rs485(c) => format!(
            "RS-485 mode: RTS {} while sending, {:.3} ms before the first character, {:.3} ms after the last{}",
            if c.get_invert_rts() { "low" } else { "high" },
            c.get_delay_before_send().as_secs_f64() * 1000.0,
            c.get_delay_after_send().as_secs_f64() * 1000.0,
            if c.get_full_duplex() { ", full duplex" } else { "" }
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leave_touches_nothing() {
        let s = Rs485Settings::default();
        assert!(s.transceiver_mode().is_none());
        assert!(s.apply("/dev/does-not-exist-hf").unwrap().is_none(), "not even opened");
    }

    #[test]
    fn the_settings_asked_for_are_the_mode_set() {
        let s = Rs485Settings {
            mode: Rs485Mode::On,
            rts_low_while_sending: true,
            delay_before_ms: 0.5,
            delay_after_ms: 2.0,
        };
        let m = s.transceiver_mode().unwrap();
        assert_eq!(
            describe(&m),
            "RS-485 mode: RTS low while sending, 0.500 ms before the first character, 2.000 ms after the last"
        );
        let off = Rs485Settings { mode: Rs485Mode::Off, ..s };
        assert_eq!(describe(&off.transceiver_mode().unwrap()), "default (RS-232) mode");
    }

    /// A pseudo-terminal has no RS-485 mode: refused, with the port and what to do.
    #[test]
    fn a_port_without_rs485_mode_is_refused_clearly() {
        let (_a, b) = serialport::TTYPort::pair().unwrap();
        let path = serialport::SerialPort::name(&b).unwrap();
        let s = Rs485Settings { mode: Rs485Mode::On, ..Rs485Settings::default() };
        let e = s.apply(&path).err().expect("a pseudo-terminal has no RS-485 mode");
        let text = e.to_string();
        assert!(text.contains(&path) && text.contains("RS-485") && text.contains("--rs485 leave"), "{text}");
    }
}
