//! USB-serial adapters on Linux: which driver stands behind a port, and the FTDI
//! latency timer. An FTDI chip holds received bytes until its latency timer expires
//! (16 ms by default), so a reply reaches the harness in chunks up to 16 ms late:
//! timing verdicts are only worth the latency they are measured through. The harness
//! lowers the timer to 1 ms where it may (restoring it afterwards) and otherwise
//! widens the timing windows by it and says so on the certificate.
//!
//! Detection reads sysfs (`/sys/class/tty/<name>/device/{driver,latency_timer}`), so a
//! fake tree under another root tests it.

use std::path::{Path, PathBuf};

/// The latency a USB full-speed adapter adds beyond its latency timer: one 1 ms frame.
pub const USB_FRAME_US: u64 = 1_000;
/// What an adapter of an unknown kind may hold bytes back for (the FTDI default).
pub const UNKNOWN_LATENCY_US: u64 = 16_000;
/// Timing verdicts through more latency than this are graded leniently by default.
pub const STRICT_LIMIT_US: u64 = 3_000;

/// A USB-serial adapter behind a port.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Adapter {
    /// The kernel driver (`ftdi_sio`, `ch341`, `cp210x`, `pl2303`, `cdc_acm`, ...).
    pub driver: String,
    /// The FTDI latency timer in ms, where the driver has one.
    pub latency_timer_ms: Option<u32>,
    latency_file: Option<PathBuf>,
    /// The timer's value before the harness lowered it, to restore on drop.
    restore_ms: Option<u32>,
}

impl Adapter {
    /// The adapter behind `port` (a device path, symlinks such as
    /// `/dev/serial/by-id/...` followed), looked up under the sysfs root `sysfs`.
    /// `None` for native UARTs, pseudo-terminals and anything sysfs does not know.
    pub fn detect(port: &str, sysfs: &Path) -> Option<Adapter> {
        let resolved = std::fs::canonicalize(port).unwrap_or_else(|_| PathBuf::from(port));
        let name = resolved.file_name()?.to_str()?.to_string();
        let device = sysfs.join("class/tty").join(&name).join("device");
        let driver = std::fs::read_link(device.join("driver")).ok()?.file_name()?.to_str()?.to_string();
        if !is_usb_driver(&driver) {
            return None;
        }
        let latency_file = device.join("latency_timer");
        let latency_timer_ms = read_ms(&latency_file);
        Some(Adapter {
            driver,
            latency_file: latency_timer_ms.is_some().then_some(latency_file),
            latency_timer_ms,
            restore_ms: None,
        })
    }

    /// Lower an FTDI latency timer to 1 ms. `Ok(true)` if it changed, `Ok(false)` if
    /// there is none or it was low already, `Err` with the reason if not permitted.
    pub fn lower_latency(&mut self) -> Result<bool, String> {
        let (Some(file), Some(ms)) = (&self.latency_file, self.latency_timer_ms) else { return Ok(false) };
        if ms <= 1 {
            return Ok(false);
        }
        std::fs::write(file, "1").map_err(|e| format!("cannot write {}: {e}", file.display()))?;
        match read_ms(file) {
            Some(1) => {
                self.restore_ms = Some(ms);
                self.latency_timer_ms = Some(1);
                Ok(true)
            }
            other => Err(format!("{} reads {other:?} after writing 1", file.display())),
        }
    }

    /// How long the adapter may hold received bytes before the harness sees them.
    pub fn input_latency_us(&self) -> u64 {
        match (self.driver.as_str(), self.latency_timer_ms) {
            (_, Some(ms)) => ms as u64 * 1000 + USB_FRAME_US,
            // Known drivers that pass bytes on at the next USB frame or two.
            ("ch341" | "cp210x" | "pl2303" | "cdc_acm", None) => 2 * USB_FRAME_US,
            // An FTDI whose timer cannot be read: assume its default.
            _ => UNKNOWN_LATENCY_US,
        }
    }

    /// How long a request may wait in the adapter before its UART starts it.
    pub fn output_latency_us(&self) -> u64 {
        USB_FRAME_US
    }

    /// One line for the certificate.
    pub fn describe(&self) -> String {
        let timer = match (self.latency_timer_ms, self.restore_ms) {
            (Some(now), Some(was)) => format!(", latency timer lowered from {was} ms to {now} ms for the run"),
            (Some(now), None) => format!(", latency timer {now} ms"),
            _ => String::new(),
        };
        format!(
            "USB adapter ({}{timer}): replies may reach the harness up to {:.1} ms after they were on the wire",
            self.driver,
            self.input_latency_us() as f64 / 1000.0
        )
    }
}

impl Drop for Adapter {
    fn drop(&mut self) {
        if let (Some(file), Some(ms)) = (&self.latency_file, self.restore_ms) {
            let _ = std::fs::write(file, ms.to_string());
        }
    }
}

fn is_usb_driver(driver: &str) -> bool {
    matches!(
        driver,
        "ftdi_sio" | "ch341" | "cp210x" | "pl2303" | "cdc_acm" | "usbserial_generic" | "ark3116" | "mos7840" | "option"
    ) || driver.starts_with("usb")
}

fn read_ms(file: &Path) -> Option<u32> {
    std::fs::read_to_string(file).ok()?.trim().parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sysfs tree with one tty: `driver` names its kernel driver, `latency` its timer.
    fn fake_sysfs(name: &str, driver: &str, latency: Option<&str>) -> tempfile::TempDir {
        let root = tempfile::tempdir().unwrap();
        let device = root.path().join("devices/pci0000:00/usb1/1-1/1-1:1.0").join(name);
        std::fs::create_dir_all(&device).unwrap();
        let drivers = root.path().join("bus/usb-serial/drivers").join(driver);
        std::fs::create_dir_all(&drivers).unwrap();
        std::os::unix::fs::symlink(&drivers, device.join("driver")).unwrap();
        if let Some(l) = latency {
            std::fs::write(device.join("latency_timer"), l).unwrap();
        }
        let tty = root.path().join("class/tty").join(name);
        std::fs::create_dir_all(&tty).unwrap();
        std::os::unix::fs::symlink(&device, tty.join("device")).unwrap();
        root
    }

    #[test]
    fn an_ftdi_adapter_is_found_and_its_timer_lowered_then_restored() {
        let root = fake_sysfs("ttyUSB0", "ftdi_sio", Some("16\n"));
        let timer = root.path().join("class/tty/ttyUSB0/device/latency_timer");
        {
            let mut a = Adapter::detect("/dev/ttyUSB0", root.path()).expect("an FTDI adapter");
            assert_eq!((a.driver.as_str(), a.latency_timer_ms), ("ftdi_sio", Some(16)));
            assert_eq!(a.input_latency_us(), 17_000);
            assert_eq!(a.lower_latency(), Ok(true));
            assert_eq!(std::fs::read_to_string(&timer).unwrap().trim(), "1");
            assert_eq!(a.input_latency_us(), 2_000);
            assert!(a.describe().contains("lowered from 16 ms to 1 ms"), "{}", a.describe());
            assert_eq!(a.lower_latency(), Ok(false), "already low");
        }
        assert_eq!(std::fs::read_to_string(&timer).unwrap().trim(), "16", "restored when the line closes");
    }

    #[test]
    fn a_timer_that_cannot_be_written_is_reported() {
        let root = fake_sysfs("ttyUSB1", "ftdi_sio", Some("16"));
        let timer = root.path().join("class/tty/ttyUSB1/device/latency_timer");
        // A directory where the file should be: writing fails whoever we are.
        std::fs::remove_file(&timer).unwrap();
        std::fs::create_dir(&timer).unwrap();
        let a = Adapter::detect("/dev/ttyUSB1", root.path()).expect("still an FTDI adapter");
        assert_eq!(a.latency_timer_ms, None);
        assert_eq!(a.input_latency_us(), UNKNOWN_LATENCY_US, "an unreadable timer is taken at its default");
        let root = fake_sysfs("ttyUSB2", "ftdi_sio", Some("16"));
        let timer = root.path().join("class/tty/ttyUSB2/device/latency_timer");
        let mut a = Adapter::detect("/dev/ttyUSB2", root.path()).unwrap();
        std::fs::remove_file(&timer).unwrap();
        std::fs::create_dir(&timer).unwrap();
        assert!(a.lower_latency().is_err());
        assert_eq!(a.input_latency_us(), 17_000, "the timer stays as it was");
    }

    #[test]
    fn other_adapters_and_native_uarts() {
        let root = fake_sysfs("ttyUSB3", "ch341", None);
        let a = Adapter::detect("/dev/ttyUSB3", root.path()).unwrap();
        assert_eq!((a.driver.as_str(), a.latency_timer_ms, a.input_latency_us()), ("ch341", None, 2_000));
        let root = fake_sysfs("ttyS0", "serial8250", None);
        assert_eq!(Adapter::detect("/dev/ttyS0", root.path()), None, "a native UART");
        assert_eq!(Adapter::detect("/dev/pts/3", root.path()), None, "not in sysfs");
        let root = fake_sysfs("ttyUSB4", "usb-mystery", None);
        assert_eq!(Adapter::detect("/dev/ttyUSB4", root.path()).unwrap().input_latency_us(), UNKNOWN_LATENCY_US);
    }
}
