//! The audit trail of `alba run` (docs/audit.md): `.alba/audit.db`, opened
//! before the server starts (`alba run` does not start without it: every
//! state-changing request writes its row there first), with its retention
//! (`[audit] retention_days`) applied at start and then daily — when the
//! clock guard allows (`crate::clock`).

use crate::Service;
use crate::clock::ClockGuard;
use alba_audit::Audit;
use alba_runtime::health::Health;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

/// Retention runs this often after the start.
const RETENTION_EVERY: Duration = Duration::from_secs(24 * 3600);

pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// Opens the project's audit log. One that is damaged (random bytes, torn
/// or truncated pages) or not an audit log is moved aside with its `-wal`
/// and `-shm` (`audit.db.damaged-<ms>`) for a fresh one, and the problem
/// `audit-damaged` says so until the next start: `alba run` starts (issue
/// 31), as with a damaged history database.
pub fn open(dir: &Path, cfg: &alba_settings::Audit, health: &Health) -> Result<Audit, String> {
    let config = alba_audit::Config {
        retention_days: (cfg.retention_days > 0).then_some(cfg.retention_days),
    };
    match Audit::open_project(dir, config.clone()) {
        Err(e) if e.is_damage() => {
            // The historian's helper: the same three files of an SQLite store.
            let to = alba_historian::move_aside(&alba_audit::project_path(dir))
                .map_err(|m| format!("{e}; and it cannot be moved aside: {m}"))?;
            health.report(
                "audit-damaged",
                format!(
                    "{e}: moved to {} and a fresh audit trail started (the old rows are in that file)",
                    to.display()
                ),
            );
            Audit::open_project(dir, config).map_err(|e| e.to_string())
        }
        r => r.map_err(|e| e.to_string()),
    }
}

/// The time of the newest row, for the clock guard.
pub fn newest(audit: &Audit) -> Option<i64> {
    let page = audit.query(&alba_audit::Filter::default(), None, 1).ok()?;
    page.rows.first().map(|r| r.t_ms)
}

/// Applies the retention now, if the clock guard allows.
pub fn retain(audit: &Audit, guard: &ClockGuard) -> Result<(), String> {
    let now = now_ms();
    if audit.config().retention_days.is_some() && guard.allows(now) {
        audit
            .apply_retention(now)
            .map_err(|e| format!("audit retention: {e}"))?;
    }
    Ok(())
}

/// Applies the retention daily until the server closes.
pub fn start(s: &Service<'_>, guard: Arc<ClockGuard>) {
    let Some(audit) = s.state.control.audit().cloned() else {
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
            let (a, g) = (audit.clone(), guard.clone());
            match tokio::task::spawn_blocking(move || retain(&a, &g)).await {
                Ok(Ok(())) => {}
                Ok(Err(e)) => eprintln!("{e}"),
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
        let keep = alba_settings::Audit { retention_days: 0 };
        let guard = |dir: &Path| {
            crate::clock::ClockGuard::start(dir, Arc::new(alba_runtime::health::Health::default()), now_ms(), &[])
        };
        let health = Health::default();
        let a = open(&dir, &keep, &health).expect("open creates .alba/audit.db");
        let recent = now_ms() - 3_600_000;
        for t in [0, 86_400_000, recent] {
            a.record(&Entry::new(t, Action::Write), &Outcome::Ok).expect("record");
        }
        drop(a);
        let a = open(&dir, &keep, &health).expect("reopen, keeping everything");
        retain(&a, &guard(&dir)).expect("retain");
        assert_eq!(a.query(&Filter::default(), None, 10).expect("query").rows.len(), 3);
        drop(a);
        let a = open(&dir, &alba_settings::Audit { retention_days: 1 }, &health).expect("reopen with retention");
        retain(&a, &guard(&dir)).expect("retain");
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
