//! The language diagnostics are shown in (issue 34 point 11).
//!
//! Messages are formatted in English where they are found (the sites know
//! their values); the Spanish catalogue ([`crate::es`]) is keyed by code and
//! applied when a diagnostic is shown: a Spanish title for every code, and
//! Spanish templates of the commonest messages with the English message's
//! placeholders. A message with no template keeps its English text behind the
//! code's Spanish title, so a Spanish reader always sees Spanish first and
//! never loses a detail. docs/i18n.md has the decision.
//!
//! The CLI sets the process's language once ([`set_language`], from `--lang`
//! or `LC_ALL`/`LC_MESSAGES`/`LANG`); a server translates per request with
//! [`crate::Diagnostic::localized`] and [`Lang::from_accept_language`].

use std::sync::atomic::{AtomicU8, Ordering};

/// A language diagnostics can be shown in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lang {
    #[default]
    En,
    Es,
}

static CURRENT: AtomicU8 = AtomicU8::new(0);

/// Sets the language [`crate::Diagnostic::render`], `short`, `Display` and
/// [`crate::render_all`] use in this process (English until set).
pub fn set_language(lang: Lang) {
    CURRENT.store(lang as u8, Ordering::Relaxed);
}

/// The language set by [`set_language`].
pub fn language() -> Lang {
    match CURRENT.load(Ordering::Relaxed) {
        1 => Lang::Es,
        _ => Lang::En,
    }
}

impl Lang {
    /// `es`, `es-ES`, `es_AR.UTF-8`, `spanish`, `español` → Spanish; `en…`,
    /// `C` and `POSIX` → English; anything else is not a language of ours.
    pub fn parse(s: &str) -> Option<Lang> {
        let s = s.trim().to_ascii_lowercase();
        let base = s.split(['_', '-', '.', '@']).next().unwrap_or("");
        match base {
            "es" | "spa" | "spanish" | "español" | "espanol" => Some(Lang::Es),
            "en" | "eng" | "english" | "c" | "posix" => Some(Lang::En),
            _ => None,
        }
    }

    /// The language of the environment, as POSIX orders the variables: the
    /// first of `LC_ALL`, `LC_MESSAGES`, `LANG` that is set and not empty.
    /// English when none says Spanish.
    pub fn from_env() -> Lang {
        Lang::from_vars(|k| std::env::var(k).ok())
    }

    /// [`Lang::from_env`] over any source of variables (for tests).
    pub fn from_vars(get: impl Fn(&str) -> Option<String>) -> Lang {
        for k in ["LC_ALL", "LC_MESSAGES", "LANG"] {
            if let Some(v) = get(k).filter(|v| !v.trim().is_empty()) {
                return Lang::parse(&v).unwrap_or(Lang::En);
            }
        }
        Lang::En
    }

    /// The language of an HTTP `Accept-Language` header: the first of ours
    /// by quality (`es-ES,es;q=0.9,en;q=0.8` → Spanish); English otherwise.
    pub fn from_accept_language(header: &str) -> Lang {
        let mut best: Option<(f32, Lang)> = None;
        for item in header.split(',') {
            let mut parts = item.split(';');
            let tag = parts.next().unwrap_or("").trim();
            let q = parts
                .find_map(|p| p.trim().strip_prefix("q=").and_then(|v| v.trim().parse::<f32>().ok()))
                .unwrap_or(1.0);
            if let Some(l) = Lang::parse(tag)
                && q > 0.0
                && best.is_none_or(|(bq, _)| q > bq)
            {
                best = Some((q, l));
            }
        }
        best.map_or(Lang::En, |(_, l)| l)
    }
}

/// Matches `text` against an English template whose placeholders are `{}`;
/// the texts the placeholders stand for, in order.
pub(crate) fn match_template<'a>(template: &str, text: &'a str) -> Option<Vec<&'a str>> {
    let pieces: Vec<&str> = template.split("{}").collect();
    let first = pieces[0];
    let mut rest = text.strip_prefix(first)?;
    let mut values = Vec::new();
    for (i, piece) in pieces.iter().enumerate().skip(1) {
        let last = i == pieces.len() - 1;
        if last {
            let v = rest.strip_suffix(piece)?;
            values.push(v);
            rest = "";
        } else {
            let at = if piece.is_empty() { 0 } else { rest.find(piece)? };
            values.push(&rest[..at]);
            rest = &rest[at + piece.len()..];
        }
    }
    rest.is_empty().then_some(values)
}

/// Fills a Spanish template: `{0}`, `{1}`… take the values in order.
pub(crate) fn fill(template: &str, values: &[&str]) -> String {
    let mut out = template.to_string();
    for (i, v) in values.iter().enumerate() {
        out = out.replace(&format!("{{{i}}}"), v);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locale_variables_pick_the_language() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |k: &str| pairs.iter().find(|(n, _)| *n == k).map(|(_, v)| v.to_string())
        };
        assert_eq!(Lang::from_vars(env(&[("LANG", "es_ES.UTF-8")])), Lang::Es);
        assert_eq!(Lang::from_vars(env(&[("LANG", "en_US.UTF-8")])), Lang::En);
        assert_eq!(Lang::from_vars(env(&[])), Lang::En);
        // LC_ALL wins over LANG, an empty one does not count.
        assert_eq!(
            Lang::from_vars(env(&[("LC_ALL", "C"), ("LANG", "es_MX.UTF-8")])),
            Lang::En
        );
        assert_eq!(
            Lang::from_vars(env(&[("LC_ALL", ""), ("LANG", "es_MX.UTF-8")])),
            Lang::Es
        );
        assert_eq!(Lang::from_vars(env(&[("LANG", "de_DE.UTF-8")])), Lang::En);
    }

    #[test]
    fn accept_language_takes_the_best_of_ours() {
        assert_eq!(Lang::from_accept_language("es-ES,es;q=0.9,en;q=0.8"), Lang::Es);
        assert_eq!(Lang::from_accept_language("en;q=0.5, es;q=0.7"), Lang::Es);
        assert_eq!(Lang::from_accept_language("fr, en;q=0.9, es;q=0.1"), Lang::En);
        assert_eq!(Lang::from_accept_language("de"), Lang::En);
        assert_eq!(Lang::from_accept_language(""), Lang::En);
        assert_eq!(Lang::from_accept_language("es;q=0"), Lang::En);
    }

    #[test]
    fn templates_match_and_fill() {
        assert_eq!(
            match_template("unknown tag `{}`", "unknown tag `Strat`"),
            Some(vec!["Strat"])
        );
        assert_eq!(match_template("unknown tag `{}`", "unknown tags `Strat`"), None);
        assert_eq!(
            match_template("{} takes {} operands, found {}", "TON takes 3 operands, found 2"),
            Some(vec!["TON", "3", "2"])
        );
        assert_eq!(match_template("here", "here"), Some(vec![]));
        assert_eq!(match_template("here", "here!"), None);
        assert_eq!(fill("{1} y {0}", &["a", "b"]), "b y a");
    }
}
