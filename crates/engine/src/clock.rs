//! Clocks. The engine never reads a clock itself: callers pass the time of
//! each scan. Simulation uses a [`VirtualClock`] (deterministic, faster than
//! real time); the real-time loop uses a [`MonotonicClock`].

use std::time::Instant;

pub trait Clock {
    /// Milliseconds since the clock's origin.
    fn now_ms(&mut self) -> u64;
}

/// A clock that moves only when told to.
#[derive(Debug, Clone, Default)]
pub struct VirtualClock {
    now: u64,
}

impl VirtualClock {
    pub fn new() -> VirtualClock {
        VirtualClock::default()
    }

    pub fn set(&mut self, ms: u64) {
        self.now = ms;
    }

    pub fn advance(&mut self, ms: u64) {
        self.now += ms;
    }
}

impl Clock for VirtualClock {
    fn now_ms(&mut self) -> u64 {
        self.now
    }
}

/// Milliseconds of a monotonic clock since the clock was made.
#[derive(Debug, Clone)]
pub struct MonotonicClock {
    origin: Instant,
}

impl Default for MonotonicClock {
    fn default() -> Self {
        MonotonicClock { origin: Instant::now() }
    }
}

impl Clock for MonotonicClock {
    fn now_ms(&mut self) -> u64 {
        self.origin.elapsed().as_millis() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn virtual_time_moves_only_when_told() {
        let mut c = VirtualClock::new();
        assert_eq!(c.now_ms(), 0);
        c.advance(10);
        c.advance(5);
        assert_eq!(c.now_ms(), 15);
        c.set(1000);
        assert_eq!(c.now_ms(), 1000);
    }

    #[test]
    fn monotonic_time_never_goes_back() {
        let mut c = MonotonicClock::default();
        let mut last = c.now_ms();
        for _ in 0..1000 {
            let now = c.now_ms();
            assert!(now >= last);
            last = now;
        }
    }
}
