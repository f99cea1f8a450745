//! Tag names: source names made acceptable to tags.csv, and fresh names for
//! the helper bits an importer adds, never clashing (case-insensitively).

use std::collections::HashMap;

#[derive(Debug, Default)]
pub struct Names {
    /// Lower-case Alba name → taken.
    taken: HashMap<String, ()>,
    /// Source name (exact) → Alba name.
    map: HashMap<String, String>,
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
        let mut base: String = source
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' })
            .collect();
        if base.is_empty() {
            base = "tag".into();
        }
        if base.as_bytes().first().is_some_and(|b| b.is_ascii_digit()) {
            base = format!("t_{base}");
        }
        if base.len() > 60 {
            base.truncate(60);
        }
        if let Err(e) = alba_model::tags::check_tag_name(&base) {
            why = Some(e);
            base = format!("x_{base}");
            if base.len() > 60 {
                base.truncate(60);
            }
        } else if base != source {
            why = Some(format!("`{source}` is not a valid Alba tag name"));
        }
        let mut name = base.clone();
        let mut n = 2;
        while self.is_taken(&name) || alba_model::tags::check_tag_name(&name).is_err() {
            if why.is_none() {
                why = Some(format!(
                    "`{source}` clashes with another name (Alba names are case-insensitive)"
                ));
            }
            name = format!("{base}_{n}");
            n += 1;
        }
        self.take(&name);
        self.map.insert(key.to_string(), name.clone());
        (name, why)
    }

    /// A new name starting with `base` that no source name uses.
    pub fn fresh(&mut self, base: &str) -> String {
        let mut n = 1;
        loop {
            let name = format!("{base}{n}");
            if !self.is_taken(&name) && alba_model::tags::check_tag_name(&name).is_ok() {
                self.take(&name);
                return name;
            }
            n += 1;
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
