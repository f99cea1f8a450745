//! Audit rows for the commands that change a project without a server
//! (`alba user`): the same log as `alba run`'s, `.alba/audit.db`
//! (docs/audit.md). The row is written first; if it cannot be, the change
//! is not made.

use alba_audit::{Action, Audit, Entry, Outcome};
use std::path::Path;

fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// A JSON string.
pub fn json_string(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Makes `change` to `project` under an audit row of `action` on `target`
/// (no Alba user: the command line; the detail names the command and the
/// system account that ran it).
pub fn audited<T>(
    project: &Path,
    action: Action,
    target: &str,
    (old, new): (Option<String>, Option<String>),
    command: &str,
    change: impl FnOnce() -> Result<T, String>,
) -> Result<T, String> {
    let account = std::env::var("USER")
        .or_else(|_| std::env::var("USERNAME"))
        .unwrap_or_else(|_| "unknown".into());
    let log = Audit::open_project(project, alba_audit::Config::default())
        .map_err(|e| format!("not done: the audit trail cannot be opened ({e})"))?;
    let entry = Entry {
        target: Some(target.to_string()),
        old,
        new,
        detail: Some(format!("{command} (command line, system account `{account}`)")),
        ..Entry::new(now_ms(), action)
    };
    let id = log
        .begin(&entry)
        .map_err(|e| format!("not done: the audit trail cannot be written ({e})"))?;
    let result = change();
    let outcome = match &result {
        Ok(_) => Outcome::Ok,
        Err(e) => Outcome::Failed(e.clone()),
    };
    if let Err(e) = log.finish(id, &outcome) {
        eprintln!("warning: audit row {id} keeps outcome `pending`: {e}");
    }
    result
}
