//! `[session]`: how long a login to the HTTP API lasts (docs/security.md,
//! "Sessions and roles").

use super::setting::int_setting;
use alba_diag::{Diagnostic, FileId};
use serde::Deserialize;
use toml::Spanned;

pub const DEFAULT_IDLE_MINUTES: u32 = 30;
pub const DEFAULT_MAX_HOURS: u32 = 12;

/// `[session]`: a session ends after `idle_minutes` without a request, and
/// `max_hours` after its login whatever happens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Session {
    pub idle_minutes: u32,
    pub max_hours: u32,
}

impl Default for Session {
    fn default() -> Session {
        Session {
            idle_minutes: DEFAULT_IDLE_MINUTES,
            max_hours: DEFAULT_MAX_HOURS,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSession {
    idle_minutes: Option<Spanned<i64>>,
    max_hours: Option<Spanned<i64>>,
}

/// Validates `[session]`: the defaults, with what the table sets.
pub(super) fn session(s: RawSession, file: FileId, diags: &mut Vec<Diagnostic>) -> Session {
    Session {
        idle_minutes: int_setting(
            "idle_minutes",
            s.idle_minutes,
            1..=24 * 60,
            DEFAULT_IDLE_MINUTES,
            "minutes",
            file,
            diags,
        ),
        max_hours: int_setting(
            "max_hours",
            s.max_hours,
            1..=24 * 31,
            DEFAULT_MAX_HOURS,
            "hours",
            file,
            diags,
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Settings as Config;
    use alba_diag::Files;

    fn parse(text: &str) -> Result<Config, Vec<String>> {
        let mut files = Files::new();
        let f = files.add("alba.toml", text);
        match Config::parse(text, f) {
            (Some(c), d) if d.is_empty() => Ok(c),
            (_, d) => Err(d.iter().map(|d| d.short(&files)).collect()),
        }
    }

    #[test]
    fn session_lengths_default_set_and_checked() {
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").expect("minimal");
        assert_eq!(
            c.session,
            Session {
                idle_minutes: 30,
                max_hours: 12
            }
        );
        let c =
            parse("name = \"x\"\nprograms = [\"a.lad\"]\n[session]\nidle_minutes = 5\nmax_hours = 1\n").expect("set");
        assert_eq!(
            c.session,
            Session {
                idle_minutes: 5,
                max_hours: 1
            }
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[session]\nidle_minutes = 0\nmax_hours = 10000\n")
            .expect_err("out of range");
        assert_eq!(
            e,
            [
                "alba.toml:4:16: error[E102]: idle_minutes = 0 is out of range",
                "alba.toml:5:13: error[E102]: max_hours = 10000 is out of range",
            ]
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[session]\nidle = 3\n").expect_err("unknown");
        assert!(e[0].contains("unknown field `idle`"), "{e:?}");
    }
}
