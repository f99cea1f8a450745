//! `[ladder]`: how Ladder is read where the systems Alba takes programs from
//! disagree (docs/ladder.md "Dialects").

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use serde_spanned::Spanned;

/// Whose semantics Ladder follows where Logix and AuroraLD (`000_…`) differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LadderDialect {
    /// Rockwell Logix (the default).
    #[default]
    Logix,
    /// AuroraLD Studio: `LIM` excludes its upper bound, `sqrt` of a
    /// negative is 0.
    AuroraLd,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLadder {
    dialect: Option<Spanned<String>>,
}

pub(super) fn ladder(raw: RawLadder, file: FileId, diags: &mut Vec<Diagnostic>) -> LadderDialect {
    let Some(d) = raw.dialect else {
        return LadderDialect::Logix;
    };
    match d.get_ref().to_ascii_lowercase().as_str() {
        "logix" => LadderDialect::Logix,
        "aurorald" => LadderDialect::AuroraLd,
        other => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("unknown ladder dialect `{other}`"),
                Span::new(file, d.span()),
                "expected \"logix\" or \"aurorald\"",
            ));
            LadderDialect::Logix
        }
    }
}

#[cfg(test)]
mod tests {
    use super::LadderDialect;
    use alba_diag::FileId;

    fn dialect(table: &str) -> (Option<LadderDialect>, Vec<String>) {
        let text = format!("name = \"t\"\nprograms = [\"main.lad\"]\n{table}");
        let (c, d) = crate::config::parse_for_test(&text, FileId(0));
        (c.map(|c| c.ladder_dialect), d.into_iter().map(|d| d.message).collect())
    }

    #[test]
    fn the_dialect_is_logix_unless_aurorald_is_asked_for() {
        assert_eq!(dialect(""), (Some(LadderDialect::Logix), vec![]));
        assert_eq!(dialect("[ladder]\n"), (Some(LadderDialect::Logix), vec![]));
        assert_eq!(
            dialect("[ladder]\ndialect = \"AuroraLD\"\n"),
            (Some(LadderDialect::AuroraLd), vec![])
        );
        assert_eq!(
            dialect("[ladder]\ndialect = \"logix\"\n"),
            (Some(LadderDialect::Logix), vec![])
        );
        let (d, e) = dialect("[ladder]\ndialect = \"siemens\"\n");
        assert_eq!(d, Some(LadderDialect::Logix));
        assert_eq!(e, ["unknown ladder dialect `siemens`"]);
        let (_, e) = dialect("[ladder]\nflavour = \"aurorald\"\n");
        assert!(e[0].contains("unknown field"), "{e:?}");
    }
}
