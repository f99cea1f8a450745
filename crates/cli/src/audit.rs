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

/// The account that runs this process: its real user id and, if the
/// system's user database (`/etc/passwd`) names it, its name — never the
/// environment (`$USER`), which whoever runs the command sets at will.
pub fn system_account() -> String {
    #[cfg(unix)]
    {
        let uid = rustix::process::getuid().as_raw();
        let name = std::fs::read_to_string("/etc/passwd")
            .ok()
            .and_then(|t| user_name(&t, uid));
        match name {
            Some(n) => format!("{n}, uid {uid}"),
            None => format!("uid {uid}"),
        }
    }
    #[cfg(not(unix))]
    {
        "unknown".to_string()
    }
}

/// The name of `uid` in the text of `/etc/passwd` (`name:x:uid:…`).
fn user_name(passwd: &str, uid: u32) -> Option<String> {
    passwd.lines().find_map(|l| {
        let mut f = l.split(':');
        let name = f.next()?;
        (f.nth(1)?.parse::<u32>().ok()? == uid && !name.is_empty()).then(|| name.to_string())
    })
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
    let account = system_account();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uid_is_named_from_the_user_database() {
        let passwd = "root:x:0:0:root:/root:/bin/bash\n# comment\nalice:x:1000:1000::/home/alice:/bin/sh\n";
        assert_eq!(user_name(passwd, 0).as_deref(), Some("root"));
        assert_eq!(user_name(passwd, 1000).as_deref(), Some("alice"));
        assert_eq!(user_name(passwd, 7), None);
    }
}
