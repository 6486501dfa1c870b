//! The reports of every front end, written one way: `report.json` for programs,
//! `junit.xml` for CI, and a certificate for people as Markdown and HTML. The forms
//! and each front end's report are the suite's core (`hiperface_suite::report`, and
//! `slave::report`, `master::report`, `listen::report` there); the
//! files, their names and the checks before a run are here, and `recorded.rs`: `decode`
//! of a report that holds the record of its wire.

use crate::command::CommandError;
use std::path::Path;

use hiperface_suite::report::{profile_digest, Attention, Reports, RunInfo};

pub mod compare;
pub mod recorded;
pub mod signature;

/// The console's end: the findings the certificate puts first, the same list.
pub fn say_attention(items: &[Attention]) {
    if items.is_empty() {
        return;
    }
    say!("findings to read first ({}):", items.len());
    for (i, a) in items.iter().enumerate() {
        for (j, line) in a.lines().into_iter().enumerate() {
            match j {
                0 => say!("{:>3}. {line}", i + 1),
                _ => say!("  {line}"),
            }
        }
    }
}

/// Write report.json, junit.xml and the certificate as .md and .html into `dir`, and
/// with a signer, report.sig over them all (`signature`).
pub fn write_all<R: Reports>(r: &R, dir: &Path, signer: Option<&signature::Signer>) -> Result<(), CommandError> {
    write_files(r, dir, signer).map_err(|source| CommandError::WriteReport { dir: dir.to_path_buf(), source })
}

fn write_files<R: Reports>(r: &R, dir: &Path, signer: Option<&signature::Signer>) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let json = r.json().map_err(std::io::Error::other)?;
    let (markdown, html) = (format!("{}.md", R::CERTIFICATE), format!("{}.html", R::CERTIFICATE));
    std::fs::write(dir.join("report.json"), json + "\n")?;
    std::fs::write(dir.join("junit.xml"), r.junit())?;
    std::fs::write(dir.join(&markdown), r.markdown())?;
    std::fs::write(dir.join(&html), r.html())?;
    match signer {
        Some(s) => s.sign(dir, &["report.json", "junit.xml", &markdown, &html]),
        None => Ok(()),
    }
}

/// Said where a certify run was given no `--report`: nothing of it is kept (a newcomer
/// looked for the certificate the README's main command had not written).
pub const NO_REPORT: &str =
    "no certificate written: --report DIR writes certificate.md, certificate.html, report.json and junit.xml";

/// The files a report directory receives (a certify run's certificate, or a listening
/// report's).
const WRITTEN: [&str; 11] = [
    "report.json",
    "junit.xml",
    "certificate.md",
    "certificate.html",
    "listening.md",
    "listening.html",
    signature::FILE,
    compare::MARKDOWN,
    compare::HTML,
    compare::JSON,
    compare::JUNIT,
];

/// An input is never the output: refused where writing the reports into `dir` would
/// replace the file `input` (`decode DIR/report.json --report DIR` would put a report
/// without its record in the place of the one with it).
pub fn refuse_overwriting(input: &Path, dir: &Path) -> Result<(), CommandError> {
    let (Ok(input), Ok(dir_real)) = (input.canonicalize(), dir.canonicalize()) else { return Ok(()) };
    match WRITTEN.iter().find(|name| dir_real.join(name) == input) {
        Some(name) => Err(CommandError::ReportDir {
            dir: dir.to_path_buf(),
            why: format!("the input {} would be replaced by the new {name}: choose another directory", input.display()),
        }),
        None => Ok(()),
    }
}

/// Create the report directory `dir` and check that files can be written in it, before
/// a run: a run's results are never found unwritable only after it.
pub fn prepare_dir(dir: &Path) -> Result<(), CommandError> {
    let refused = |why: String| CommandError::ReportDir { dir: dir.to_path_buf(), why };
    if dir.exists() && !dir.is_dir() {
        return Err(refused("it exists and is not a directory".into()));
    }
    std::fs::create_dir_all(dir).map_err(|e| refused(format!("cannot create the directory: {e}")))?;
    let probe = dir.join(".hiperface-write-check");
    std::fs::write(&probe, b"").map_err(|e| refused(format!("cannot write in the directory: {e}")))?;
    let _ = std::fs::remove_file(probe);
    if let Some(aside) =
        move_earlier_run_aside(dir).map_err(|e| refused(format!("cannot move an earlier run aside: {e}")))?
    {
        eprintln!("an earlier run's reports in {} were moved to {}", dir.display(), aside.display());
    }
    Ok(())
}

/// Never mixed, nothing lost: the report files of an earlier run in `dir` (any of
/// [`WRITTEN`]; a link is moved as the link) go together into the first free
/// `dir/earlier-run-N`, so that a new run's report.json never stands beside an old
/// run's certificate. Returns where they went, `None` when there were none.
fn move_earlier_run_aside(dir: &Path) -> std::io::Result<Option<std::path::PathBuf>> {
    let earlier: Vec<&str> = WRITTEN.iter().copied().filter(|name| dir.join(name).symlink_metadata().is_ok()).collect();
    if earlier.is_empty() {
        return Ok(None);
    }
    let Some(aside) =
        (1..=10_000).map(|n| dir.join(format!("earlier-run-{n}"))).find(|d| d.symlink_metadata().is_err())
    else {
        return Err(std::io::Error::other("10 000 earlier runs are there already"));
    };
    std::fs::create_dir(&aside)?;
    for name in earlier {
        std::fs::rename(dir.join(name), aside.join(name))?;
    }
    Ok(Some(aside))
}

/// A run against a line in real time, from its start to its end: the processors kept
/// out of their idle sleep where permitted (`sched::KeepAwake`), and what the
/// hypervisor took of them meanwhile. One for every front end that runs in real time:
/// `certify slave` on a real line, `certify master` and `monitor`.
pub struct RealTimeRun {
    processors: Option<crate::procfs::CpuTimes>,
    awake: Result<crate::sched::KeepAwake, String>,
}

impl RealTimeRun {
    /// The run starts: the processors' times read, the processors held awake.
    pub fn start() -> RealTimeRun {
        RealTimeRun { processors: crate::procfs::CpuTimes::now(), awake: crate::sched::KeepAwake::hold() }
    }

    /// The run ends: the processors released. Returns what the report says of the hold
    /// (a note, held or not), and what the hypervisor took since the start: `None` where
    /// the machine does not count steal time, or never had any since it booted (no
    /// hypervisor that says so).
    pub fn finish(self) -> (String, Option<hiperface_suite::report::Steal>) {
        let note = crate::sched::KeepAwake::note(&self.awake);
        drop(self.awake);
        let steal = match (self.processors, crate::procfs::CpuTimes::now()) {
            (Some(start), Some(now)) if now.steal > 0 => Some(now.steal_since(start)),
            _ => None,
        };
        (note, steal)
    }
}

/// On the console, where the hypervisor took enough to matter: why a run may have had
/// scenarios or cases run again, or left undecided.
pub fn say_steal(steal: Option<hiperface_suite::report::Steal>) {
    if let Some(s) = steal.filter(|s| s.worth_saying()) {
        say!(
            "note: during this run {}: the harness and the device's process were paused by the host in that time, \
             which the harness measures only in part: what that could explain is run again or UNKNOWN, never \
             charged to the device, and a quieter host needs fewer runs again",
            s.text()
        );
    }
}

/// The revision the command was built from (`build.rs`: `git rev-parse`), or "unknown".
pub const REVISION: &str = env!("HIPERFACE_REVISION");

/// What a certificate says of its run, collected as it starts: now (UTC), this host,
/// the command line as given, the tool's revision, the profile's digest, and what the
/// operator said was certified (`--device`, none where the command has no such option).
pub fn run_info(profile: &hiperface_model::Profile, device: &[String]) -> RunInfo {
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_else(|_| "unknown".into());
    let quote = |a: String| {
        if a.is_empty() || a.contains(|c: char| c.is_whitespace() || "'\"$`\\{}*?!".contains(c)) {
            format!("'{}'", a.replace('\'', "'\\''"))
        } else {
            a
        }
    };
    RunInfo {
        started_utc: utc(now),
        host,
        command_line: std::env::args().map(quote).collect::<Vec<_>>().join(" "),
        revision: REVISION.to_string(),
        profile_digest: profile_digest(profile),
        device: device.to_vec(),
        steal: None,
    }
}

/// Seconds since 1970 as ISO 8601 UTC (days to a civil date: H. Hinnant's algorithm).
pub fn utc(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rest = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z", rest / 3600, rest % 3600 / 60, rest % 60)
}

#[cfg(test)]
mod tests {
    #[test]
    fn seconds_since_1970_read_as_the_calendar_does() {
        assert_eq!(super::utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(super::utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(super::utc(1_795_678_212), "2026-11-26T07:30:12Z");
        assert_eq!(super::utc(4_107_542_399), "2100-02-28T23:59:59Z");
    }

    /// A report directory that holds an earlier run: its files go aside together, a
    /// link as the link (its target untouched), other files stay; a new run's files
    /// never stand beside the old ones (issue 55: a FAILED report.json beside a PASSED
    /// certificate.md).
    #[test]
    fn an_earlier_run_is_moved_aside_never_mixed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().join("run");
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("certificate.md"), "PASSED").unwrap();
        let elsewhere = dir.path().join("elsewhere.json");
        std::fs::write(&elsewhere, "kept").unwrap();
        std::os::unix::fs::symlink(&elsewhere, d.join("report.json")).unwrap();
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        super::prepare_dir(&d).unwrap();
        let aside = d.join("earlier-run-1");
        assert_eq!(std::fs::read_to_string(aside.join("certificate.md")).unwrap(), "PASSED");
        assert!(aside.join("report.json").symlink_metadata().unwrap().file_type().is_symlink());
        assert!(!d.join("certificate.md").exists() && d.join("report.json").symlink_metadata().is_err());
        assert_eq!(std::fs::read_to_string(d.join("notes.txt")).unwrap(), "mine");
        assert_eq!(std::fs::read_to_string(&elsewhere).unwrap(), "kept");
        // Again: the next free place.
        std::fs::write(d.join("junit.xml"), "x").unwrap();
        super::prepare_dir(&d).unwrap();
        assert!(d.join("earlier-run-2").join("junit.xml").exists());
        // Nothing to move: nothing moved.
        super::prepare_dir(&d).unwrap();
        assert!(!d.join("earlier-run-3").exists());
    }
}
