//! Settings shared by several tables: integers in a range, listen addresses.

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde_spanned::Spanned;

/// An integer setting within `range`, or `default` with a located E102.
pub fn int_setting(
    key: &str,
    v: Option<Spanned<i64>>,
    range: std::ops::RangeInclusive<u32>,
    default: u32,
    unit: &str,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> u32 {
    let Some(s) = v else { return default };
    match u32::try_from(*s.get_ref()) {
        Ok(v) if range.contains(&v) => v,
        _ => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("{key} = {} is out of range", s.get_ref()),
                Span::new(file, s.span()),
                format!("expected {} to {} {unit}", range.start(), range.end()),
            ));
            default
        }
    }
}

/// An `IP:PORT` setting, or a diagnostic.
pub fn listen(l: &Spanned<String>, file: FileId, diags: &mut Vec<Diagnostic>) -> Option<std::net::SocketAddr> {
    match l.get_ref().parse::<std::net::SocketAddr>() {
        Ok(a) => Some(a),
        Err(_) => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("listen = \"{}\" is not an address and port", l.get_ref()),
                Span::new(file, l.span()),
                "expected IP:PORT, like \"127.0.0.1:5020\"",
            ));
            None
        }
    }
}
