//! Which units `--cases` and `--scenarios` select: one grammar for the command line,
//! the C API (`HfCertifyOptions.cases`, `HfMasterOptions.scenarios`) and Python
//! (`cases=`, `scenarios=`), written down once here and in the book's command-line
//! chapter.
//!
//! - `*` matches any run of characters, `?` any one character; everything else is
//!   itself (`protocol.*`, `fields.?ode*`).
//! - A comma separates alternatives: `identity.version,counter.read` selects both.
//!   Spaces around an alternative are ignored.
//! - Braces give alternatives inside one: `{powerup.reset,timing.read-position}` and
//!   `timing.{read-position,gap}` (nested braces too); a comma inside braces belongs
//!   to them.
//! - An alternative that starts with `!` excludes what it matches, braces included
//!   (`!{fault,reply}.*`). Exclusions win; without any other alternative they start
//!   from everything: `!fault.*` is every unit but the fault scenarios.
//! - A pattern whose braces do not pair, or that expands to more than
//!   [`MAX_ALTERNATIVES`] alternatives, selects nothing (the front ends then say that no
//!   unit matches it).

/// The most alternatives a pattern may expand to (braces multiply them): a pattern
/// from outside (a C or Python caller's string) never takes the machine's memory.
pub const MAX_ALTERNATIVES: usize = 256;

/// Whether `pattern` selects the unit id `text`.
pub fn glob_match(pattern: &str, text: &str) -> bool {
    let Some(alternatives) = alternatives(pattern) else { return false };
    let (mut any_positive, mut selected) = (false, false);
    for (excluded, p) in &alternatives {
        if *excluded {
            if wildcard(p.as_bytes(), text.as_bytes()) {
                return false;
            }
        } else {
            any_positive = true;
            selected |= wildcard(p.as_bytes(), text.as_bytes());
        }
    }
    selected || !any_positive
}

/// `*` and `?` over one alternative without braces.
fn wildcard(p: &[u8], t: &[u8]) -> bool {
    match (p.first(), t.first()) {
        (None, None) => true,
        (Some(b'*'), _) => wildcard(&p[1..], t) || (!t.is_empty() && wildcard(p, &t[1..])),
        (Some(b'?'), Some(_)) => wildcard(&p[1..], &t[1..]),
        (Some(a), Some(b)) if a == b => wildcard(&p[1..], &t[1..]),
        _ => false,
    }
}

/// The pattern's alternatives, each with whether it excludes: split at the commas
/// outside braces, braces expanded. `None` where braces do not pair or there would be
/// more than [`MAX_ALTERNATIVES`].
fn alternatives(pattern: &str) -> Option<Vec<(bool, String)>> {
    let mut out = Vec::new();
    for top in split_outside_braces(pattern)? {
        let top = top.trim();
        let (excluded, body) = match top.strip_prefix('!') {
            Some(body) => (true, body.trim()),
            None => (false, top),
        };
        for one in expand(body)? {
            out.push((excluded, one));
            if out.len() > MAX_ALTERNATIVES {
                return None;
            }
        }
    }
    Some(out)
}

/// `s` split at its commas outside braces; `None` where its braces do not pair.
fn split_outside_braces(s: &str) -> Option<Vec<&str>> {
    let (mut depth, mut start, mut parts) = (0usize, 0, Vec::new());
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth = depth.checked_sub(1)?,
            ',' if depth == 0 => {
                parts.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    (depth == 0).then(|| {
        parts.push(&s[start..]);
        parts
    })
}

/// One alternative with its first brace group replaced by each of its members, and so
/// on until none is left; `None` past [`MAX_ALTERNATIVES`] or for unpaired braces.
fn expand(s: &str) -> Option<Vec<String>> {
    let Some(open) = s.find('{') else {
        return (!s.contains('}')).then(|| vec![s.to_string()]);
    };
    let mut depth = 0usize;
    let close = s[open..].char_indices().find_map(|(i, c)| {
        match c {
            '{' => depth += 1,
            '}' => depth = depth.saturating_sub(1),
            _ => return None,
        }
        (depth == 0).then_some(open + i)
    })?;
    let (head, inner, tail) = (&s[..open], &s[open + 1..close], &s[close + 1..]);
    let mut out = Vec::new();
    for member in split_outside_braces(inner)? {
        for one in expand(&format!("{head}{}{tail}", member.trim()))? {
            out.push(one);
            if out.len() > MAX_ALTERNATIVES {
                return None;
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::glob_match;

    #[test]
    fn wildcards_and_comma_alternatives() {
        assert!(glob_match("position.*", "position.read"));
        assert!(glob_match("reply.?ap", "reply.gap"));
        assert!(glob_match("fault.*, reply.gap", "reply.gap"));
        assert!(glob_match("identity.version,counter.read", "counter.read"));
        assert!(!glob_match("position.*", "powerup.window"));
        assert!(!glob_match("reply.gap", "reply.gap-under-timeout"));
        assert!(glob_match("*", ""));
    }

    #[test]
    fn exclusions_take_away_and_alone_start_from_everything() {
        assert!(glob_match("!fault.*", "reply.gap"));
        assert!(!glob_match("!fault.*", "fault.data-field"));
        assert!(glob_match("startup.*, !startup.user-settings", "startup.default"));
        assert!(!glob_match("startup.*, !startup.user-settings", "startup.user-settings"));
        assert!(!glob_match("startup.*, !startup.user-settings", "reply.gap"));
        assert!(!glob_match("!*", "reply.gap"));
    }

    /// The two patterns: a brace list of whole ids selected "no case", and a
    /// brace list of globs selected only its last member.
    #[test]
    fn braces_are_alternatives_inside_one() {
        let ids = ["powerup.reset", "timing.read-position", "settings.stored", "identity.version"];
        let chosen = |p: &str| ids.iter().filter(|id| glob_match(p, id)).copied().collect::<Vec<_>>();
        assert_eq!(chosen("{powerup.reset,timing.read-position}"), ["powerup.reset", "timing.read-position"]);
        assert_eq!(
            chosen("{powerup.*,settings.*,timing.*}"),
            ["powerup.reset", "timing.read-position", "settings.stored"]
        );
        assert_eq!(chosen("timing.{read-position,gap}"), ["timing.read-position"]);
        assert_eq!(chosen("{power{up,down}.reset,identity.*}"), ["powerup.reset", "identity.version"]);
        assert_eq!(chosen("*, !{powerup,timing}.*"), ["settings.stored", "identity.version"]);
        assert_eq!(chosen("{ powerup.reset , settings.stored }"), ["powerup.reset", "settings.stored"]);
    }

    #[test]
    fn unpaired_braces_and_runaway_patterns_select_nothing() {
        for bad in ["{powerup.reset", "powerup.reset}", "}{", "a,{b,c"] {
            assert!(!glob_match(bad, "powerup.reset"), "{bad}");
            assert!(!glob_match(bad, "b"), "{bad}");
        }
        // 2^10 alternatives: over the bound, so nothing rather than a thousand strings.
        let runaway = "{a,b}".repeat(10);
        assert!(!glob_match(&runaway, "aaaaaaaaaa"));
        assert!(glob_match(&"{a,b}".repeat(8), "abababab"), "2^8 = 256 is within the bound");
    }
}
