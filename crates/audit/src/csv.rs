//! The CSV form of audit rows (RFC 4180: comma-separated, CRLF line ends, fields
//! with a comma, quote or line break in double quotes, quotes doubled).
//!
//! Spreadsheets run a cell that starts with `=`, `+`, `-`, `@`, a tab or a carriage
//! return as a formula ("CSV injection"), and a user name, tag or detail comes from
//! whoever made the request. Such a field, and one that starts with `'`, is written with
//! a `'` in front, which a spreadsheet shows as text; to read the exact value back,
//! remove one leading `'`. Numbers (`-3.5` in the old/new columns) are left as they are.

use crate::Row;

/// The header line of an export: `address` is the peer (the client's
/// `ip:port`, the broker for MQTT), `via` the door (`http`, `mqtt`,
/// `opcua`, `modbus`; empty for rows older than schema 2), last so that
/// readers of the former twelve columns keep their places.
pub const CSV_HEADER: &str = "id,time_ms,time_utc,user,address,action,target,old,new,detail,outcome,error,via\r\n";

/// Whether `s` is a plain number (which a spreadsheet does not run).
fn is_number(s: &str) -> bool {
    let digits = s.strip_prefix('-').unwrap_or(s);
    digits.starts_with(|c: char| c.is_ascii_digit()) && s.parse::<f64>().is_ok()
}

/// Appends `s` as one CSV field.
pub fn push_field(out: &mut String, s: &str) {
    let risky = s.starts_with(['=', '+', '-', '@', '\t', '\r', '\'']) && !is_number(s);
    let quote = s.contains([',', '"', '\r', '\n']);
    if quote {
        out.push('"');
    }
    if risky {
        out.push('\'');
    }
    for c in s.chars() {
        if c == '"' {
            out.push('"');
        }
        out.push(c);
    }
    if quote {
        out.push('"');
    }
}

/// Appends `row` as one CSV line (with its CRLF).
pub(crate) fn write_row(out: &mut String, row: &Row) {
    let opt = |s: &Option<String>| s.clone().unwrap_or_default();
    let fields = [
        row.id.to_string(),
        row.t_ms.to_string(),
        format_utc(row.t_ms),
        opt(&row.user),
        opt(&row.addr),
        row.action.clone(),
        opt(&row.target),
        opt(&row.old),
        opt(&row.new),
        opt(&row.detail),
        row.outcome.name().to_string(),
        match &row.outcome {
            crate::Outcome::Failed(e) => e.clone(),
            _ => String::new(),
        },
        opt(&row.via),
    ];
    for (i, f) in fields.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        push_field(out, f);
    }
    out.push_str("\r\n");
}

/// `t_ms` (Unix ms) as ISO 8601 UTC with milliseconds: `2026-11-24T18:15:14.123Z`.
pub fn format_utc(t_ms: i64) -> String {
    let days = t_ms.div_euclid(86_400_000);
    let ms = t_ms.rem_euclid(86_400_000);
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{:03}Z",
        ms / 3_600_000,
        ms / 60_000 % 60,
        ms / 1000 % 60,
        ms % 1000
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_times() {
        assert_eq!(format_utc(0), "1970-01-01T00:00:00.000Z");
        assert_eq!(format_utc(1_795_976_114_123), "2026-11-29T18:15:14.123Z");
        assert_eq!(format_utc(951_782_400_000), "2000-02-29T00:00:00.000Z");
        assert_eq!(format_utc(-1), "1969-12-31T23:59:59.999Z");
    }

    #[test]
    fn fields_are_quoted_and_formulas_defused() {
        let f = |s: &str| {
            let mut o = String::new();
            push_field(&mut o, s);
            o
        };
        assert_eq!(f("plain"), "plain");
        assert_eq!(f("a,b"), "\"a,b\"");
        assert_eq!(f("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(f("two\nlines"), "\"two\nlines\"");
        assert_eq!(f("=cmd|' /C calc'!A0"), "'=cmd|' /C calc'!A0");
        assert_eq!(f("@SUM(1)"), "'@SUM(1)");
        assert_eq!(f("-2+3"), "'-2+3");
        assert_eq!(f("'quoted"), "''quoted");
        assert_eq!(f("-3.5"), "-3.5");
        assert_eq!(f("=a,b"), "\"'=a,b\"");
    }
}
