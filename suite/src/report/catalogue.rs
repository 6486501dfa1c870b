//! The catalogues as a reader meets them before a run: every slave case and every
//! master scenario with its id (what `--cases` and `--scenarios` select), its title and
//! the clauses it grades. One text, printed by `certify slave --list` and `certify
//! master --list` and held equal to the book's catalogue page (docs/src/catalogue.md)
//! by a test.

use hiperface_model::clause::Clause;

/// A catalogue as a Markdown table: id, title, clauses.
fn table(units: impl Iterator<Item = (&'static str, &'static str, &'static [Clause])>) -> String {
    let mut s = String::from("| id | what it checks | clauses |\n|---|---|---|\n");
    for (id, title, clauses) in units {
        let clauses: Vec<&str> = clauses.iter().map(|c| c.id()).collect();
        s.push_str(&format!("| `{id}` | {} | {} |\n", title.replace('|', "\\|"), clauses.join(", ")));
    }
    s
}

/// `certify slave --list`: the slave cases, in run order.
pub fn slave_cases() -> String {
    table(crate::slave::cases::catalogue().into_iter().map(|c| (c.id, c.title, c.clauses)))
}

/// `certify master --list`: the master scenarios, in run order.
pub fn master_scenarios() -> String {
    table(crate::master::scenarios::catalogue().into_iter().map(|s| (s.id, s.title, s.clauses)))
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_unit_is_a_row_with_its_clauses() {
        let slave = super::slave_cases();
        assert_eq!(slave.lines().count(), 2 + crate::slave::cases::catalogue().len());
        assert!(slave.contains("| `identity.type-label` |"), "{slave}");
        let master = super::master_scenarios();
        assert_eq!(master.lines().count(), 2 + crate::master::scenarios::catalogue().len());
        assert!(master.lines().skip(2).all(|l| l.starts_with("| `") && l.matches(" | ").count() == 2), "{master}");
    }
}
