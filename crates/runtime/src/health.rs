//! What is wrong with the runtime's persistence right now (issue 15): retentive
//! data lost at start, a retain save or a historian write failing, a damaged
//! history database, the disk-space floor reached. Every part that keeps data
//! reports here; `GET /api/status`, the studio's status bar and the system tags
//! `S:RETAINLOST` and `S:STOREOK` read it.
//!
//! Logging is rate-limited by construction: a problem is written to stderr
//! when it appears or its message changes, and once more when it clears,
//! never on every failing write.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// One current problem.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// What reported it: `retain` (restoring at start), `retain-save`,
    /// `history`, `history-disk`, … (one problem per source).
    pub source: &'static str,
    pub message: String,
    /// When it appeared (Unix ms).
    pub since_unix_ms: i64,
}

/// The problems of one runtime; shared by every part that keeps data.
#[derive(Debug)]
pub struct Health {
    problems: Mutex<Vec<Problem>>,
    /// No problem is current (for `S:STOREOK`, read every scan).
    ok: AtomicBool,
    /// Retentive data was lost at start (`S:RETAINLOST`).
    retain_lost: AtomicBool,
}

impl Default for Health {
    fn default() -> Health {
        Health {
            problems: Mutex::new(Vec::new()),
            ok: AtomicBool::new(true),
            retain_lost: AtomicBool::new(false),
        }
    }
}

impl Health {
    fn with<T>(&self, f: impl FnOnce(&mut Vec<Problem>) -> T) -> T {
        let mut p = self.problems.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let out = f(&mut p);
        self.ok.store(p.is_empty(), Ordering::Relaxed);
        out
    }

    /// `source` has this problem now (replacing its previous one). Logged
    /// when new or changed.
    pub fn report(&self, source: &'static str, message: impl Into<String>) {
        let message = message.into();
        let changed = self.with(|ps| match ps.iter_mut().find(|p| p.source == source) {
            Some(p) if p.message == message => false,
            Some(p) => {
                p.message.clone_from(&message);
                true
            }
            None => {
                ps.push(Problem {
                    source,
                    message: message.clone(),
                    since_unix_ms: crate::unix_ms(),
                });
                true
            }
        });
        if changed {
            eprintln!("warning: {message}");
        }
    }

    /// `source` works again. Logged if it had a problem.
    pub fn clear(&self, source: &'static str) {
        let had = self.with(|ps| {
            let n = ps.len();
            ps.retain(|p| p.source != source);
            n != ps.len()
        });
        if had {
            eprintln!("{source}: working again");
        }
    }

    /// Records that retentive data was lost at start (sticky).
    pub fn set_retain_lost(&self) {
        self.retain_lost.store(true, Ordering::Relaxed);
    }

    pub fn retain_lost(&self) -> bool {
        self.retain_lost.load(Ordering::Relaxed)
    }

    /// No problem is current.
    pub fn ok(&self) -> bool {
        self.ok.load(Ordering::Relaxed)
    }

    /// The current problems, oldest first.
    pub fn problems(&self) -> Vec<Problem> {
        self.with(|ps| ps.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_problem_per_source_until_cleared() {
        let h = Health::default();
        assert!(h.ok());
        h.report("history", "disk full");
        h.report("history", "disk full");
        h.report("retain-save", "read-only file system");
        assert!(!h.ok());
        assert_eq!(h.problems().len(), 2);
        h.clear("history");
        assert_eq!(h.problems()[0].source, "retain-save");
        h.clear("retain-save");
        assert!(h.ok() && h.problems().is_empty());
    }
}
