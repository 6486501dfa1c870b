//! The figures the book prints for the searches to a fixpoint, read back from it, so
//! that a test fails when the program and the page disagree (the page is what a reader
//! quotes; a search that changes must change it too).

/// The verification page of the book.
const PAGE: &str = include_str!("../../docs/src/verification.md");

/// The numbers of the table row that begins `| {row} |` first after the heading
/// `## {section}`: each cell's digits, thousands separated by spaces ("43 200"), in
/// order; a cell with a unit ("13 s", a time) is not a figure and is left out.
pub fn figures(section: &str, row: &str) -> Result<Vec<u64>, String> {
    let heading = format!("\n## {section}\n");
    let from = PAGE.find(&heading).ok_or_else(|| format!("no section \"{section}\" in verification.md"))?;
    let prefix = format!("| {row} |");
    let line = PAGE
        .get(from..)
        .and_then(|rest| rest.lines().find(|l| l.starts_with(&prefix)))
        .ok_or_else(|| format!("no row \"{row}\" after \"{section}\" in verification.md"))?;
    let cells = line.trim_matches('|').split('|').skip(1).map(str::trim);
    Ok(cells.filter_map(|c| c.replace(' ', "").parse().ok()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_is_read_as_its_figures() {
        let slave = figures("Model checking to a fixpoint", "current (SEK37)").unwrap();
        assert_eq!(slave.len(), 4, "states, transitions, concrete states, levels: {slave:?}");
        let master = figures("The reference master to a fixpoint", "current (SEK37)").unwrap();
        assert_eq!(master.len(), 3, "states, transitions, levels: {master:?}");
        assert!(figures("No such section", "current (SEK37)").is_err());
        assert!(figures("Model checking to a fixpoint", "no such row").is_err());
    }
}
