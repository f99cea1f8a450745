//! Login back-off: after a few failed logins for one key (a user name, a
//! client address), each further attempt must wait, longer every time, up
//! to a cap. The caller passes the time in, so tests need no clock.

use std::collections::HashMap;
use std::time::{Duration, Instant};

/// Failures allowed before any wait.
pub const FREE_FAILURES: u32 = 3;
/// The first wait; it doubles with every further failure.
pub const FIRST_WAIT: Duration = Duration::from_secs(1);
/// The longest wait.
pub const MAX_WAIT: Duration = Duration::from_secs(60);
/// A key with no failure for this long is forgotten.
pub const FORGET_AFTER: Duration = Duration::from_secs(15 * 60);
/// Keys kept at most (the oldest are dropped first): a flood of client
/// addresses costs bounded memory.
pub const MAX_KEYS: usize = 10_000;

#[derive(Debug, Clone, Copy)]
struct Entry {
    failures: u32,
    last: Instant,
}

/// Failed-login accounting per key. Not thread-safe by itself: keep it in
/// a `Mutex`.
#[derive(Debug, Default)]
pub struct Backoff {
    keys: HashMap<String, Entry>,
}

impl Backoff {
    pub fn new() -> Backoff {
        Backoff::default()
    }

    /// The wait after `failures` failures.
    pub fn wait_after(failures: u32) -> Duration {
        if failures < FREE_FAILURES {
            return Duration::ZERO;
        }
        let doublings = (failures - FREE_FAILURES).min(16);
        FIRST_WAIT.saturating_mul(1 << doublings).min(MAX_WAIT)
    }

    /// `Ok` when `key` may try to log in at `now`, else how long it must
    /// still wait.
    pub fn check(&self, key: &str, now: Instant) -> Result<(), Duration> {
        let Some(e) = self.keys.get(key) else { return Ok(()) };
        let until = e.last + Backoff::wait_after(e.failures);
        match until.checked_duration_since(now) {
            Some(left) if !left.is_zero() => Err(left),
            _ => Ok(()),
        }
    }

    /// Counts a failed login of `key` at `now`.
    pub fn failure(&mut self, key: &str, now: Instant) {
        self.keys
            .retain(|_, e| now.saturating_duration_since(e.last) < FORGET_AFTER);
        if !self.keys.contains_key(key)
            && self.keys.len() >= MAX_KEYS
            && let Some(oldest) = self.keys.iter().min_by_key(|(_, e)| e.last).map(|(k, _)| k.clone())
        {
            self.keys.remove(&oldest);
        }
        let e = self
            .keys
            .entry(key.to_string())
            .or_insert(Entry { failures: 0, last: now });
        e.failures = e.failures.saturating_add(1);
        e.last = now;
    }

    /// A successful login of `key`: its failures are forgotten.
    pub fn success(&mut self, key: &str) {
        self.keys.remove(key);
    }

    /// The keys with at least `n` failures not yet forgotten at `now`, with their count.
    pub fn at_least(&self, n: u32, now: Instant) -> Vec<(String, u32)> {
        self.keys
            .iter()
            .filter(|(_, e)| e.failures >= n && now.saturating_duration_since(e.last) < FORGET_AFTER)
            .map(|(k, e)| (k.clone(), e.failures))
            .collect()
    }

    /// The failures counted for `key`.
    pub fn failures(&self, key: &str) -> u32 {
        self.keys.get(key).map_or(0, |e| e.failures)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waits_grow_then_cap_and_success_clears() {
        let t0 = Instant::now();
        let mut b = Backoff::new();
        for i in 0..FREE_FAILURES {
            assert_eq!(b.check("u:alice", t0), Ok(()), "failure {i}");
            b.failure("u:alice", t0);
        }
        assert_eq!(b.check("u:alice", t0), Err(Duration::from_secs(1)));
        assert_eq!(b.check("u:bob", t0), Ok(()), "keys are apart");
        assert_eq!(b.check("u:alice", t0 + Duration::from_secs(1)), Ok(()));
        b.failure("u:alice", t0);
        assert_eq!(b.check("u:alice", t0), Err(Duration::from_secs(2)));
        for _ in 0..20 {
            b.failure("u:alice", t0);
        }
        assert_eq!(b.check("u:alice", t0), Err(MAX_WAIT));
        b.success("u:alice");
        assert_eq!(b.check("u:alice", t0), Ok(()));
        assert_eq!(b.failures("u:alice"), 0);
    }

    #[test]
    fn old_failures_are_forgotten_and_keys_bounded() {
        let t0 = Instant::now();
        let mut b = Backoff::new();
        for _ in 0..5 {
            b.failure("a", t0);
        }
        b.failure("b", t0 + FORGET_AFTER);
        assert_eq!(b.failures("a"), 0);
        for i in 0..MAX_KEYS + 50 {
            b.failure(&format!("k{i}"), t0 + FORGET_AFTER + Duration::from_millis(i as u64));
        }
        assert!(b.keys.len() <= MAX_KEYS);
        assert_eq!(b.failures(&format!("k{}", MAX_KEYS + 49)), 1);
        assert_eq!(b.failures("k0"), 0, "the oldest went first");
    }
}
