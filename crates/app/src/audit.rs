//! The audit trail of `alba run` (docs/audit.md): `.alba/audit.db`, opened
//! before the server starts (`alba run` does not start without it: every
//! state-changing request writes its row there first), with its retention
//! (`[audit] retention_days`) applied at start and then daily.

use crate::Service;
use alba_audit::Audit;
use std::path::Path;
use std::time::Duration;

/// Retention runs this often after the start.
const RETENTION_EVERY: Duration = Duration::from_secs(24 * 3600);

fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// Opens the project's audit log and applies its retention once.
pub fn open(dir: &Path, cfg: &alba_project::config::Audit) -> Result<Audit, String> {
    let config = alba_audit::Config {
        retention_days: (cfg.retention_days > 0).then_some(cfg.retention_days),
    };
    let audit = Audit::open_project(dir, config).map_err(|e| e.to_string())?;
    audit
        .apply_retention(now_ms())
        .map_err(|e| format!("audit retention: {e}"))?;
    Ok(audit)
}

/// Applies the retention daily until the server closes.
pub fn start(s: &Service<'_>) {
    let Some(audit) = s.state.audit.clone() else {
        return;
    };
    if audit.config().retention_days.is_none() {
        return;
    }
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        loop {
            tokio::select! {
                _ = tokio::time::sleep(RETENTION_EVERY) => {}
                _ = closing.changed() => return,
            }
            let a = audit.clone();
            match tokio::task::spawn_blocking(move || a.apply_retention(now_ms())).await {
                Ok(Ok(_)) => {}
                Ok(Err(e)) => eprintln!("audit retention: {e}"),
                Err(e) => eprintln!("audit retention: {e}"),
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_audit::{Action, Entry, Filter, Outcome};

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("alba-app-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn open_creates_the_log_and_applies_retention_at_start() {
        let dir = scratch("audit-retention");
        let keep = alba_project::config::Audit { retention_days: 0 };
        let a = open(&dir, &keep).expect("open creates .alba/audit.db");
        let recent = now_ms() - 3_600_000;
        for t in [0, 86_400_000, recent] {
            a.record(&Entry::new(t, Action::Write), &Outcome::Ok).expect("record");
        }
        drop(a);
        let a = open(&dir, &keep).expect("reopen, keeping everything");
        assert_eq!(a.query(&Filter::default(), None, 10).expect("query").rows.len(), 3);
        drop(a);
        let a = open(&dir, &alba_project::config::Audit { retention_days: 1 }).expect("reopen with retention");
        let times: Vec<i64> = a
            .query(&Filter::default(), None, 10)
            .expect("query")
            .rows
            .iter()
            .map(|r| r.t_ms)
            .collect();
        assert_eq!(times, vec![recent], "rows older than a day deleted at start");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
