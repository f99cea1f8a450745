//! `[reports]`: the shift reports `alba run` writes to a folder when a shift
//! ends (docs/alarms.md, "Scheduled reports"): the same workbook and PDF as
//! `GET /api/reports/shift.xlsx` and `.pdf`, for the shift just finished.
//!
//! ```toml
//! [reports]
//! folder = "reports"          # beside alba.toml unless absolute
//! shift_hours = [6, 14, 22]   # the hours the shifts change (or: period_hours = 8)
//! utc_offset_minutes = 60     # the hours are local time: UTC + this (fixed)
//! formats = ["xlsx", "pdf"]
//! ```

use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

pub const DEFAULT_REPORTS_FOLDER: &str = "reports";

/// A scheduled report's file type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReportFormat {
    Xlsx,
    Pdf,
}

impl ReportFormat {
    /// The file extension (and the API's: `shift.xlsx`, `shift.pdf`).
    pub fn ext(self) -> &'static str {
        match self {
            ReportFormat::Xlsx => "xlsx",
            ReportFormat::Pdf => "pdf",
        }
    }
}

/// `[reports]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reports {
    /// Where the files go (relative to the project folder unless absolute).
    pub folder: String,
    /// The hours of the day (local time, 0–23) a shift ends and the next
    /// begins, ascending and distinct; never empty.
    pub shift_hours: Vec<u8>,
    /// Local time is UTC plus this many minutes (a fixed offset: daylight
    /// saving time is not followed).
    pub utc_offset_minutes: i32,
    /// Written for each shift, in this order; never empty.
    pub formats: Vec<ReportFormat>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawReports {
    folder: Option<Spanned<String>>,
    shift_hours: Option<Spanned<Vec<Spanned<i64>>>>,
    period_hours: Option<Spanned<i64>>,
    utc_offset_minutes: Option<Spanned<i64>>,
    formats: Option<Spanned<Vec<ReportFormat>>>,
}

/// Validates `[reports]`: `shift_hours` or `period_hours` (one of them),
/// the rest defaulted. `None` when no schedule could be made of it.
pub(super) fn reports(r: RawReports, file: FileId, diags: &mut Vec<Diagnostic>) -> Option<Reports> {
    let sp = |range: std::ops::Range<usize>| Span::new(file, range);
    let folder = match r.folder {
        Some(f) if f.get_ref().trim().is_empty() => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "`folder` is empty",
                sp(f.span()),
                "expected a folder, such as \"reports\"",
            ));
            DEFAULT_REPORTS_FOLDER.to_string()
        }
        Some(f) => f.into_inner(),
        None => DEFAULT_REPORTS_FOLDER.to_string(),
    };
    let shift_hours = match (r.shift_hours, r.period_hours) {
        (Some(_), Some(p)) => {
            diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    "`[reports]` sets both `shift_hours` and `period_hours`",
                    sp(p.span()),
                    "one of the two",
                )
                .with_help("`period_hours = 8` is `shift_hours = [0, 8, 16]`"),
            );
            return None;
        }
        (None, None) => {
            diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    "`[reports]` needs `shift_hours` or `period_hours`",
                    Span::new(file, 0..0),
                    "in alba.toml",
                )
                .with_help("for three shifts: shift_hours = [6, 14, 22]"),
            );
            return None;
        }
        (None, Some(p)) => {
            let period = int_setting("period_hours", Some(p.clone()), 1..=24, 0, "hours", file, diags);
            if period == 0 {
                return None;
            }
            if 24 % period != 0 {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("period_hours = {period} does not divide a day"),
                    sp(p.span()),
                    "expected 1, 2, 3, 4, 6, 8, 12 or 24",
                ));
                return None;
            }
            (0..24).step_by(period as usize).map(|h| h as u8).collect()
        }
        (Some(h), None) => {
            let span = h.span();
            let mut hours = Vec::new();
            for v in h.into_inner() {
                match u8::try_from(*v.get_ref()) {
                    Ok(x) if x < 24 => {
                        if hours.contains(&x) {
                            diags.push(Diagnostic::new(
                                Code::ConfigField,
                                format!("hour {x} is listed twice in `shift_hours`"),
                                sp(v.span()),
                                "again here",
                            ));
                            return None;
                        }
                        hours.push(x);
                    }
                    _ => {
                        diags.push(Diagnostic::new(
                            Code::ConfigField,
                            format!("shift hour {} is out of range", v.get_ref()),
                            sp(v.span()),
                            "expected an hour of the day, 0 to 23",
                        ));
                        return None;
                    }
                }
            }
            if hours.is_empty() {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    "`shift_hours` is empty",
                    sp(span),
                    "expected at least one hour, such as [6, 14, 22]",
                ));
                return None;
            }
            hours.sort_unstable();
            hours
        }
    };
    let utc_offset_minutes = match r.utc_offset_minutes {
        Some(o) if (-720..=840).contains(o.get_ref()) => *o.get_ref() as i32,
        Some(o) => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("utc_offset_minutes = {} is out of range", o.get_ref()),
                sp(o.span()),
                "expected -720 to 840 minutes",
            ));
            0
        }
        None => 0,
    };
    let formats = match r.formats {
        Some(f) if f.get_ref().is_empty() => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "`formats` is empty",
                sp(f.span()),
                "expected [\"xlsx\"], [\"pdf\"] or both",
            ));
            return None;
        }
        Some(f) => {
            let mut v = Vec::new();
            for x in f.into_inner() {
                if !v.contains(&x) {
                    v.push(x);
                }
            }
            v
        }
        None => vec![ReportFormat::Xlsx, ReportFormat::Pdf],
    };
    Some(Reports {
        folder,
        shift_hours,
        utc_offset_minutes,
        formats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Settings;
    use alba_diag::Files;

    fn parse(reports: &str) -> Result<Option<Reports>, Vec<String>> {
        let text = format!("name = \"x\"\nprograms = [\"a.lad\"]\n{reports}");
        let mut files = Files::new();
        let f = files.add("alba.toml", &text);
        match Settings::parse(&text, f) {
            (Some(c), d) if d.is_empty() => Ok(c.reports),
            (_, d) => Err(d.iter().map(|d| d.short(&files)).collect()),
        }
    }

    #[test]
    fn a_schedule_by_hours_or_by_period() {
        assert_eq!(parse("").expect("none"), None);
        let r = parse("[reports]\nshift_hours = [22, 6, 14]\n")
            .expect("hours")
            .expect("on");
        assert_eq!(
            r,
            Reports {
                folder: "reports".into(),
                shift_hours: vec![6, 14, 22],
                utc_offset_minutes: 0,
                formats: vec![ReportFormat::Xlsx, ReportFormat::Pdf],
            }
        );
        let r = parse(
            "[reports]\nperiod_hours = 8\nfolder = \"/srv/shift\"\nformats = [\"pdf\"]\nutc_offset_minutes = -300\n",
        )
        .expect("period")
        .expect("on");
        assert_eq!(r.shift_hours, vec![0, 8, 16]);
        assert_eq!(r.folder, "/srv/shift");
        assert_eq!(r.formats, vec![ReportFormat::Pdf]);
        assert_eq!(r.utc_offset_minutes, -300);
    }

    #[test]
    fn bad_schedules_are_refused_at_their_place() {
        for (text, said) in [
            ("[reports]\nfolder = \"r\"\n", "needs `shift_hours` or `period_hours`"),
            ("[reports]\nshift_hours = [6]\nperiod_hours = 8\n", "sets both"),
            ("[reports]\nshift_hours = [6, 24]\n", "shift hour 24 is out of range"),
            ("[reports]\nshift_hours = [6, 6]\n", "hour 6 is listed twice"),
            ("[reports]\nshift_hours = []\n", "`shift_hours` is empty"),
            ("[reports]\nperiod_hours = 5\n", "does not divide a day"),
            ("[reports]\nperiod_hours = 0\n", "period_hours = 0 is out of range"),
            ("[reports]\nshift_hours = [6]\nformats = []\n", "`formats` is empty"),
            ("[reports]\nshift_hours = [6]\nformats = [\"csv\"]\n", "unknown variant"),
            ("[reports]\nshift_hours = [6]\nfolder = \" \"\n", "`folder` is empty"),
            (
                "[reports]\nshift_hours = [6]\nutc_offset_minutes = 900\n",
                "utc_offset_minutes = 900 is out of range",
            ),
            ("[reports]\nshift_hours = [6]\nevery = 1\n", "unknown field"),
        ] {
            let errs = parse(text).expect_err(text);
            assert!(errs.iter().any(|e| e.contains(said)), "{text}: {errs:?}");
        }
    }
}
