//! `alba.toml`, the project settings (SPEC §10.1).

use crate::codes::Code;
use crate::diag::{Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

pub const DEFAULT_SCAN_MS: u32 = 10;
pub const MAX_SCAN_MS: u32 = 60_000;

/// Boards Alba knows (used by the Arduino issue; validated now so a typo
/// does not wait until then).
pub const BOARDS: &[&str] = &["uno", "nano", "mega"];
/// Pin map presets (SPEC §7.1).
pub const PIN_MAPS: &[&str] = &["aurora", "s7", "openplc"];

#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub name: String,
    pub description: String,
    pub scan_ms: u32,
    /// Program files in execution order, with where each is listed.
    pub programs: Vec<(String, Span)>,
    /// Plant-model programs, run after `programs` in simulation.
    pub plant: Vec<(String, Span)>,
    pub board: Option<Board>,
}

/// Placeholder for the Arduino issue: which board and pin map.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Board {
    pub model: String,
    pub pinmap: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    scan_ms: Option<Spanned<i64>>,
    programs: Spanned<Vec<Spanned<String>>>,
    #[serde(default)]
    plant: Vec<Spanned<String>>,
    board: Option<RawBoard>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBoard {
    model: Spanned<String>,
    pinmap: Option<Spanned<String>>,
}

/// `s` as a TOML string (quoted and escaped), for writing alba.toml.
pub fn toml_string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

impl Config {
    /// Parses and validates `alba.toml`, reporting every problem found. The
    /// config is `None` only when the file could not be read as settings at
    /// all; with bad values it is returned (with defaults in their place) so
    /// the rest of the project is still checked.
    pub fn parse(text: &str, file: FileId) -> (Option<Config>, Vec<Diagnostic>) {
        let raw: RawConfig = match toml::from_str(text) {
            Ok(r) => r,
            Err(e) => {
                let span = Span::new(file, e.span().unwrap_or(0..0));
                let msg = e.message().trim().to_string();
                let code =
                    if msg.contains("missing field") || msg.contains("unknown field") || msg.contains("invalid type") {
                        Code::ConfigField
                    } else {
                        Code::TomlSyntax
                    };
                let mut d = Diagnostic::new(code, format!("alba.toml: {msg}"), span, "here");
                if msg.contains("missing field") {
                    d = d.with_help(
                        "the minimal alba.toml is: name = \"tank\"  scan_ms = 10  programs = [\"main.lad\"]",
                    );
                }
                return (None, vec![d]);
            }
        };
        let mut diags = Vec::new();
        let sp = |r: std::ops::Range<usize>| Span::new(file, r);
        let name = raw.name.get_ref().trim().to_string();
        if name.is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "the project name is empty",
                sp(raw.name.span()),
                "empty name",
            ));
        }
        let scan_ms = match raw.scan_ms {
            None => DEFAULT_SCAN_MS,
            Some(s) => match u32::try_from(*s.get_ref()) {
                Ok(v) if (1..=MAX_SCAN_MS).contains(&v) => v,
                _ => {
                    diags.push(Diagnostic::new(
                        Code::ConfigField,
                        format!("scan_ms = {} is out of range", s.get_ref()),
                        sp(s.span()),
                        format!("expected 1 to {MAX_SCAN_MS} milliseconds"),
                    ));
                    DEFAULT_SCAN_MS
                }
            },
        };
        if raw.programs.get_ref().is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "`programs` is empty",
                sp(raw.programs.span()),
                "expected at least one program file",
            ));
        }
        let listed = |v: Vec<Spanned<String>>| v.into_iter().map(|p| (p.get_ref().clone(), sp(p.span()))).collect();
        let programs = listed(raw.programs.into_inner());
        let plant = listed(raw.plant);
        let board = raw.board.map(|b| {
            let model = b.model.get_ref().to_ascii_lowercase();
            if !BOARDS.contains(&model.as_str()) {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("unknown board `{}`", b.model.get_ref()),
                    sp(b.model.span()),
                    format!("expected one of {}", BOARDS.join(", ")),
                ));
            }
            let pinmap = match &b.pinmap {
                Some(p) => {
                    let v = p.get_ref().to_ascii_lowercase();
                    if !PIN_MAPS.contains(&v.as_str()) {
                        diags.push(Diagnostic::new(
                            Code::ConfigField,
                            format!("unknown pin map `{}`", p.get_ref()),
                            sp(p.span()),
                            format!("expected one of {}", PIN_MAPS.join(", ")),
                        ));
                    }
                    v
                }
                None => "aurora".to_string(),
            };
            Board { model, pinmap }
        });
        let config = Config {
            name,
            description: raw.description,
            scan_ms,
            programs,
            plant,
            board,
        };
        (Some(config), diags)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Files;

    fn parse(text: &str) -> Result<Config, Vec<String>> {
        let mut files = Files::new();
        let f = files.add("alba.toml", text);
        match Config::parse(text, f) {
            (Some(c), d) if d.is_empty() => Ok(c),
            (_, d) => Err(d.iter().map(|d| d.short(&files)).collect()),
        }
    }

    #[test]
    fn names_with_quotes_and_backslashes_round_trip() {
        for name in ["plain", "a\\b", "say \"hi\"", "tab\there", "ñandú"] {
            let text = format!("name = {}\nprograms = [\"a.lad\"]\n", toml_string(name));
            assert_eq!(parse(&text).unwrap().name, name, "{text}");
        }
    }

    #[test]
    fn minimal_config_takes_defaults() {
        let c = parse("name = \"tank\"\nprograms = [\"main.lad\"]\n").unwrap();
        assert_eq!(c.scan_ms, 10);
        assert_eq!(c.programs[0].0, "main.lad");
        assert!(c.board.is_none());
    }

    #[test]
    fn board_placeholder_is_validated() {
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"Nano\"\npinmap = \"s7\"\n").unwrap();
        assert_eq!(
            c.board,
            Some(Board {
                model: "nano".into(),
                pinmap: "s7".into()
            })
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"due\"\n").unwrap_err();
        assert_eq!(e, ["alba.toml:4:9: error[E102]: unknown board `due`"]);
    }

    #[test]
    fn bad_configs_are_located() {
        let e = parse("name = \"x\"\nscan_m = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(
            e[0].starts_with("alba.toml:2:1: error[E102]: alba.toml: unknown field `scan_m`"),
            "{e:?}"
        );
        let e = parse("name = \"x\"\nscan_ms = 0\nprograms = []\n").unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:2:11: error[E102]: scan_ms = 0 is out of range",
                "alba.toml:3:12: error[E102]: `programs` is empty"
            ]
        );
        let e = parse("name = \"x\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].contains("error[E101]"), "{e:?}");
        let e = parse("programs = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].contains("missing field `name`"), "{e:?}");
        let e = parse("name = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].starts_with("alba.toml:1:8: error[E102]"), "{e:?}");
    }
}
