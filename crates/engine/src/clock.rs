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
