//! Plant models: simulated processes attached to the I/O (SPEC §6). They
//! are written as `[[plant_model]]` tables of `alba.toml` (read and checked
//! by `alba-project`); the engine's `plant` module runs them.
//!
//! ```toml
//! [[plant_model]]
//! kind = "first_order"          # first_order, second_order, tank, motor
//! input = "AO:4/0"              # the actuator signal the model reads
//! output = "AI:3/0"             # the measurement it writes
//! gain = 1.0
//! tau = 10.0                    # s
//! input_scale = [0, 10000, 0, 10]   # raw 0..10000 is 0..10 (V)
//! output_scale = [0, 10000, 0, 10]
//! saturation = [0, 10]          # actuator limits, in input units
//! dead_time = 0.5               # s
//! noise = 0.01                  # standard deviation, output units
//! seed = 1
//! ```

use alba_diag::Span;

/// The dynamics of a model (units: seconds, and the physical units the
/// scales give to the signals).
#[derive(Debug, Clone, PartialEq)]
pub enum Dynamics {
    /// `gain / (tau·s + 1)`.
    FirstOrder { gain: f64, tau: f64 },
    /// `gain / (a2·s² + a1·s + a0)`.
    SecondOrder { gain: f64, a2: f64, a1: f64, a0: f64 },
    /// A tank: `area·dh/dt = inflow·q(u) − outflow·d(h)`, q(u) = u, or with a
    /// dead zone max(0, u − dead_zone),
    /// level h ≥ 0 (and ≤ `max_level` when given), where the drain `d(h)` is
    /// h (a linear resistance) or √h (an orifice: Torricelli's law); the
    /// measurement is `sensor·h`. With `outflow = 0` it is a pure integrator.
    Tank {
        area: f64,
        inflow: f64,
        outflow: f64,
        sensor: f64,
        max_level: Option<f64>,
        drain: Drain,
        /// The input below which the pump delivers nothing (a DC motor's
        /// friction, a centrifugal pump's shut-off head), input units.
        dead_zone: f64,
    },
    /// A DC motor driven by its armature voltage u:
    /// `L·di/dt = u − R·i − ke·ω`, `J·dω/dt = kt·i − b·ω`; the measurement
    /// is `sensor·ω`.
    Motor {
        r: f64,
        l: f64,
        kt: f64,
        ke: f64,
        j: f64,
        b: f64,
        sensor: f64,
    },
}

/// How a tank's outflow depends on its level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Drain {
    /// `outflow·h`: a linear resistance (the linearised model).
    #[default]
    Linear,
    /// `outflow·√h`: an orifice or valve at the bottom (Torricelli's law;
    /// `outflow` = the opening's area × √(2g) in the level's units).
    Orifice,
}

/// A linear map raw ↔ physical: `[raw_lo, raw_hi, lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    pub raw_lo: f64,
    pub raw_hi: f64,
    pub lo: f64,
    pub hi: f64,
}

impl Scale {
    pub const IDENTITY: Scale = Scale {
        raw_lo: 0.0,
        raw_hi: 1.0,
        lo: 0.0,
        hi: 1.0,
    };

    pub fn to_physical(&self, raw: f64) -> f64 {
        self.lo + (raw - self.raw_lo) * (self.hi - self.lo) / (self.raw_hi - self.raw_lo)
    }

    pub fn to_raw(&self, x: f64) -> f64 {
        self.raw_lo + (x - self.lo) * (self.raw_hi - self.raw_lo) / (self.hi - self.lo)
    }
}

/// One checked `[[plant_model]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlantModel {
    pub dynamics: Dynamics,
    /// Names (tag, member or address) as written, with where.
    pub input: (String, Span),
    pub output: (String, Span),
    pub input_scale: Scale,
    pub output_scale: Scale,
    /// Actuator limits, physical input units.
    pub saturation: Option<(f64, f64)>,
    /// Transport delay of the measurement, s.
    pub dead_time: f64,
    /// Standard deviation of the measurement noise, physical output units.
    pub noise: f64,
    pub seed: u64,
    /// The measurement at the start (physical), the model at rest there.
    pub initial: f64,
}

pub const KINDS: [&str; 4] = ["first_order", "second_order", "tank", "motor"];

/// Longest dead time accepted (s): the delay line holds one sample per ms.
pub const MAX_DEAD_TIME: f64 = 600.0;
