//! Retention and the wall clock (issue 31, docs/reliability.md): a wall clock
//! 800 days ahead at start made retention delete the whole audit trail and
//! all history. Retention — the audit trail's and the historian's — now asks
//! this guard first, and it refuses after a clock jump it cannot explain:
//!
//! - at start, when retention would delete every row of a store (its newest
//!   row is older than the retention period by the clock): a clock far ahead
//!   looks exactly like that, and no automatic rule should empty a store;
//! - while running, when the wall clock moved more than [`TOLERANCE_MS`]
//!   away from what the monotonic clock says has passed since the last check
//!   (NTP corrects by seconds; a jump of an hour is a person or a fault).
//!
//! It then raises the problem `clock` (`/api/status`, `S:STOREOK`) and keeps
//! retention off — across restarts, through the file `.alba/retention-held` —
//! until a person checks the clock and deletes that file; nothing is deleted
//! meanwhile. Recording goes on.

use alba_runtime::health::Health;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

/// The problem's source in `Health`.
const SOURCE: &str = "clock";
/// The file that keeps retention held across restarts.
pub const HELD_FILE: &str = "retention-held";
/// A wall-clock step beyond this against the monotonic clock is unexplained.
pub const TOLERANCE_MS: i64 = 3_600_000;
const DAY_MS: i64 = 86_400_000;

/// What the start check knows of one store.
pub struct Store {
    pub name: &'static str,
    /// Its newest row (Unix ms), if it has any.
    pub newest_ms: Option<i64>,
    /// Its retention, if any.
    pub retention_days: Option<u32>,
}

pub struct ClockGuard {
    marker: PathBuf,
    health: Arc<Health>,
    /// The wall clock and the monotonic clock at the last check allowed.
    anchor: Mutex<(i64, Instant)>,
    /// Held (and said so); released when the file is gone.
    held: AtomicBool,
    /// The file could not be written: held until `alba run` restarts.
    unwritten: AtomicBool,
}

impl ClockGuard {
    /// The guard of the project in `dir`, checked against its stores at
    /// wall-clock time `now_ms`.
    pub fn start(dir: &std::path::Path, health: Arc<Health>, now_ms: i64, stores: &[Store]) -> Arc<ClockGuard> {
        let g = Arc::new(ClockGuard {
            marker: dir.join(".alba").join(HELD_FILE),
            health,
            anchor: Mutex::new((now_ms, Instant::now())),
            held: AtomicBool::new(false),
            unwritten: AtomicBool::new(false),
        });
        for s in stores {
            if let (Some(newest), Some(days)) = (s.newest_ms, s.retention_days)
                && now_ms.saturating_sub(i64::from(days) * DAY_MS) > newest
            {
                g.hold(&format!(
                    "the clock reads {} days after the newest row of the {} ({} days of retention): retention \
                     would delete all of it",
                    now_ms.saturating_sub(newest) / DAY_MS,
                    s.name,
                    days
                ));
                break;
            }
        }
        // Said once, whatever held it (this start or an earlier one).
        g.allows_at(now_ms, Instant::now());
        g
    }

    /// Whether retention may delete by the wall-clock time `now_ms` now.
    pub fn allows(&self, now_ms: i64) -> bool {
        self.allows_at(now_ms, Instant::now())
    }

    /// [`allows`](Self::allows) with the monotonic clock reading `mono` (tests).
    pub fn allows_at(&self, now_ms: i64, mono: Instant) -> bool {
        let mut anchor = self.anchor.lock().unwrap_or_else(PoisonError::into_inner);
        if self.marker.exists() || self.unwritten.load(Ordering::Relaxed) {
            self.held.store(true, Ordering::Relaxed);
            let why = std::fs::read_to_string(&self.marker).unwrap_or_default();
            self.health.report(
                SOURCE,
                format!(
                    "retention is held: {}. Nothing is deleted until a person checks the clock and then deletes {}",
                    why.trim(),
                    self.marker.display()
                ),
            );
            return false;
        }
        if self.held.swap(false, Ordering::Relaxed) {
            // Released by a person: the clock is taken as it is now.
            self.health.clear(SOURCE);
            *anchor = (now_ms, mono);
            return true;
        }
        let (wall, at) = *anchor;
        let expected = wall.saturating_add(mono.saturating_duration_since(at).as_millis() as i64);
        let jump = now_ms.saturating_sub(expected);
        if jump.unsigned_abs() > TOLERANCE_MS as u64 {
            drop(anchor);
            self.hold(&format!(
                "the wall clock jumped {} by {} minutes while running, more than the monotonic clock explains",
                if jump > 0 { "ahead" } else { "back" },
                jump.unsigned_abs() / 60_000
            ));
            return self.allows_at(now_ms, mono);
        }
        *anchor = (now_ms, mono);
        true
    }

    fn hold(&self, reason: &str) {
        self.held.store(true, Ordering::Relaxed);
        if !self.marker.exists()
            && let Err(e) = alba_model::fsutil::write_atomic(&self.marker, |w| writeln!(w, "{reason}"))
        {
            self.unwritten.store(true, Ordering::Relaxed);
            eprintln!(
                "warning: cannot write {} ({e}): retention stays held until `alba run` restarts",
                self.marker.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("alba-clock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join(".alba")).expect("dir");
        d
    }

    const NOW: i64 = 1_800_000_000_000;

    #[test]
    fn a_start_that_would_empty_a_store_holds_retention_until_the_file_goes() {
        let dir = scratch("start");
        let health = Arc::new(Health::default());
        let stores = [Store {
            name: "audit trail",
            newest_ms: Some(NOW - 800 * DAY_MS),
            retention_days: Some(365),
        }];
        let g = ClockGuard::start(&dir, health.clone(), NOW, &stores);
        assert!(!g.allows(NOW));
        assert!(!health.ok());
        let p = &health.problems()[0];
        assert_eq!(p.source, "clock");
        assert!(
            p.message.contains("800 days after the newest row of the audit trail"),
            "{}",
            p.message
        );
        // A restart does not release it.
        let g = ClockGuard::start(&dir, health.clone(), NOW, &[]);
        assert!(!g.allows(NOW));
        // A person does.
        std::fs::remove_file(dir.join(".alba").join(HELD_FILE)).expect("rm");
        assert!(g.allows(NOW));
        assert!(health.ok());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_store_within_its_retention_is_not_a_jump() {
        let dir = scratch("fine");
        let health = Arc::new(Health::default());
        let stores = [Store {
            name: "history",
            newest_ms: Some(NOW - 30 * DAY_MS),
            retention_days: Some(365),
        }];
        let g = ClockGuard::start(&dir, health.clone(), NOW, &stores);
        assert!(g.allows(NOW) && health.ok());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_jump_while_running_holds_retention() {
        let dir = scratch("running");
        let health = Arc::new(Health::default());
        let t0 = Instant::now();
        let g = ClockGuard::start(&dir, health.clone(), NOW, &[]);
        // Faked clocks: an hour of each passes, then the wall clock leaps.
        let hour = Duration::from_secs(3600);
        assert!(g.allows_at(NOW + 3_600_000, t0 + hour));
        assert!(
            g.allows_at(NOW + 7_200_000 + 30_000, t0 + hour * 2),
            "NTP-sized steps are fine"
        );
        assert!(!g.allows_at(NOW + 7_200_000 + 800 * DAY_MS, t0 + hour * 2 + Duration::from_secs(1)));
        assert!(
            health.problems()[0].message.contains("jumped ahead"),
            "{:?}",
            health.problems()
        );
        assert!(dir.join(".alba").join(HELD_FILE).exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
