//! Tag names: source names made acceptable to tags.csv, and fresh names for
//! the helper bits an importer adds, never clashing (case-insensitively).

use alba_model::tags::MAX_NAME_LEN;
use std::collections::HashMap;

#[derive(Debug, Default)]
pub struct Names {
    /// Lower-case Alba name → taken.
    taken: HashMap<String, ()>,
    /// Source name (exact) → Alba name.
    map: HashMap<String, String>,
    /// Lower-case base → the next number to try after it, so that the n-th
    /// name on one base costs one look-up, not n.
    next: HashMap<String, usize>,
}

/// `base` with the suffix `{sep}{n}`, `base` shortened so that the name
/// fits [`MAX_NAME_LEN`] (`base` is ASCII).
fn numbered(base: &str, sep: &str, n: usize) -> String {
    let suffix = format!("{sep}{n}");
    let keep = MAX_NAME_LEN.saturating_sub(suffix.len()).min(base.len());
    format!("{}{suffix}", &base[..keep])
}

/// Letters, digits and `_` of `s` (anything else `_`), not starting with a
/// digit, never empty: a name that stays valid with digits after it.
fn identifier(s: &str, empty: &str) -> String {
    let mut base: String = s
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' })
        .collect();
    if base.is_empty() {
        base = empty.into();
    }
    if base.as_bytes().first().is_some_and(|b| b.is_ascii_digit()) {
        base = format!("t_{base}");
    }
    base
}

impl Names {
    pub fn new() -> Names {
        Names::default()
    }

    /// Reserves `name` as is (it must be valid).
    fn take(&mut self, name: &str) {
        self.taken.insert(name.to_ascii_lowercase(), ());
    }

    pub fn is_taken(&self, name: &str) -> bool {
        self.taken.contains_key(&name.to_ascii_lowercase())
    }

    /// The Alba name of a source name, choosing one on first use. The second
    /// value is why it had to change, if it did.
    pub fn alba(&mut self, source: &str) -> (String, Option<String>) {
        self.alba_as(source, source)
    }

    /// [`Names::alba`] for the name `source` remembered under `key` (a
    /// scoped name: the same source name in two scopes gets two tags).
    pub fn alba_as(&mut self, key: &str, source: &str) -> (String, Option<String>) {
        if let Some(n) = self.map.get(key) {
            return (n.clone(), None);
        }
        let mut why = None;
        let mut base = identifier(source, "tag");
        if base.len() > 60 {
            base.truncate(60);
        }
        if let Err(e) = alba_model::tags::check_tag_name(&base) {
            why = Some(e.to_string());
            base = format!("x_{base}");
            if base.len() > 60 {
                base.truncate(60);
            }
        } else if base != source {
            why = Some(format!("`{source}` is not a valid Alba tag name"));
        }
        let mut name = base.clone();
        if self.is_taken(&name) || alba_model::tags::check_tag_name(&name).is_err() {
            if why.is_none() {
                why = Some(format!(
                    "`{source}` clashes with another name (Alba names are case-insensitive)"
                ));
            }
            name = self.numbered_free(&base, "_", 2);
        }
        self.take(&name);
        self.map.insert(key.to_string(), name.clone());
        (name, why)
    }

    /// A new name starting with `base` (made a valid name first) that no
    /// source name uses: `base1`, `base2`, …
    pub fn fresh(&mut self, base: &str) -> String {
        let base = identifier(base, "x");
        let name = self.numbered_free(&base, "", 1);
        self.take(&name);
        name
    }

    /// The first free `{base}{sep}{n}` from `first` on (every one is a valid
    /// name: `base` is an identifier, the digits end it, the length fits).
    fn numbered_free(&mut self, base: &str, sep: &str, first: usize) -> String {
        let key = format!("{}{sep}", base.to_ascii_lowercase());
        let mut n = self.next.get(&key).copied().unwrap_or(first).max(first);
        loop {
            let name = numbered(base, sep, n);
            n += 1;
            if !self.is_taken(&name) {
                self.next.insert(key, n);
                return name;
            }
        }
    }
}

/// A program's name as a file name: letters, digits, `_` and `-` kept,
/// anything else `_` (`program` for an empty name).
pub(crate) fn file_stem(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "program".into() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `import_ldmicro` hung on a CTC whose name had 70 letters: its helper
    /// `<name>_wrap<n>` was never a valid name (longer than 64), and
    /// `fresh` counted up for ever.
    #[test]
    fn fresh_names_are_valid_whatever_the_base() {
        let mut names = Names::new();
        for base in ["x".repeat(70), "%IX0.0_edge".into(), String::new(), "9lives".into()] {
            for _ in 0..3 {
                let n = names.fresh(&base);
                assert!(alba_model::tags::check_tag_name(&n).is_ok(), "{base:?} gave {n:?}");
            }
        }
        assert_eq!(names.fresh("pwr"), "pwr1");
        assert_eq!(names.fresh("pwr"), "pwr2");
    }

    /// Clashing source names numbered past `_999` stay within 64 characters.
    #[test]
    fn many_clashes_on_a_long_name_end() {
        let mut names = Names::new();
        let long = "a".repeat(60);
        let mut seen = std::collections::HashSet::new();
        for i in 0..2000 {
            let (n, _) = names.alba_as(&format!("k{i}"), &long);
            assert!(alba_model::tags::check_tag_name(&n).is_ok(), "{n}");
            assert!(seen.insert(n.to_ascii_lowercase()), "{n} twice");
        }
    }
}
