//! The reports of every front end, written one way: `report.json` for programs,
//! `junit.xml` for CI, and a certificate for people as Markdown and HTML. The forms
//! and each front end's report are the suite's core (`hiperface_suite::report`,
//! re-exported here, and `slave::report`, `master::report`, `listen::report`); the
//! files, their names and the checks before a run are here, and `recorded.rs`: `decode`
//! of a report that holds the record of its wire.

use crate::command::CommandError;
use std::path::Path;

pub use hiperface_suite::report::{escape, junit_suite, page_head, wire_text, Reports};

pub mod recorded;

/// Write report.json, junit.xml and the certificate as .md and .html into `dir`.
pub fn write_all<R: Reports>(r: &R, dir: &Path) -> Result<(), CommandError> {
    write_files(r, dir).map_err(|source| CommandError::WriteReport { dir: dir.to_path_buf(), source })
}

fn write_files<R: Reports>(r: &R, dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let json = r.json().map_err(std::io::Error::other)?;
    std::fs::write(dir.join("report.json"), json + "\n")?;
    std::fs::write(dir.join("junit.xml"), r.junit())?;
    std::fs::write(dir.join(format!("{}.md", R::CERTIFICATE)), r.markdown())?;
    std::fs::write(dir.join(format!("{}.html", R::CERTIFICATE)), r.html())
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
    Ok(())
}
