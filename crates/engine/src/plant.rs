//! Plant models (SPEC §6): simulated processes between an actuator signal
//! and a measurement, stepped between scans by the simulator (`alba sim`,
//! virtual time: deterministic) and by the simulated I/O driver (`alba run
//! --io sim`, real time).
//!
//! Each step holds the actuator value read after the last scan (a zero-order
//! hold) and integrates the model with fourth-order Runge–Kutta on a fixed
//! grid of 1 ms (finer for fast models), so the result depends only on the
//! times of the steps, never on the wall clock. The measurement goes through
//! the dead-time line (1 ms resolution), gets seeded Gaussian noise, is
//! scaled to raw units and written to the output place.

use alba_ir::{Memory, Place, PlantSpec};
use alba_model::plant::{Drain, Dynamics};
use alba_model::{DataType, Value};
use std::collections::VecDeque;

/// The running state of one model.
#[derive(Debug, Clone)]
struct Sim {
    spec: PlantSpec,
    x: [f64; 2],
    /// Integration steps per millisecond.
    sub: u32,
    delay: VecDeque<f64>,
    /// The measurement after the dead time, before noise.
    y: f64,
    rng: u64,
}

/// Every plant model of a program, with its state.
#[derive(Debug, Clone, Default)]
pub struct Plants {
    sims: Vec<Sim>,
    last_ms: Option<u64>,
    /// The real time of the last `step_now`.
    epoch: Option<std::time::Instant>,
    /// Plant time on the real-time clock, µs (gaps capped at 1 s).
    real_us: u64,
}

impl Plants {
    pub fn new(specs: &[PlantSpec]) -> Plants {
        Plants {
            sims: specs.iter().map(Sim::new).collect(),
            last_ms: None,
            epoch: None,
            real_us: 0,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.sims.is_empty()
    }

    /// The specs these plants run.
    pub fn specs(&self) -> Vec<PlantSpec> {
        self.sims.iter().map(|s| s.spec.clone()).collect()
    }

    /// Advances every model to `now_ms` (the first call starts them at rest
    /// at their initial measurement) and writes the measurements.
    pub fn step(&mut self, mem: &mut Memory, now_ms: u64) {
        let dt = match self.last_ms {
            Some(t) if now_ms >= t => now_ms - t,
            _ => 0,
        };
        self.last_ms = Some(now_ms);
        for s in &mut self.sims {
            let u = s.actuator(mem);
            for _ in 0..dt {
                s.advance_ms(u);
            }
            let y = s.y + s.noise();
            mem.write(
                s.spec.output,
                raw_value(s.spec.output, s.spec.model.output_scale.to_raw(y)),
            );
        }
    }

    /// `step` on a monotonic real-time clock started by the first call.
    /// A gap of more than a second between calls (the engine was stopped)
    /// counts as one second: a paused engine pauses its plant, and a
    /// restart never integrates hours in one scan.
    pub fn step_now(&mut self, mem: &mut Memory) {
        let now = std::time::Instant::now();
        let last = *self.epoch.get_or_insert(now);
        self.epoch = Some(now);
        self.real_us += (now - last).as_micros().min(1_000_000) as u64;
        self.step(mem, self.real_us / 1000);
    }
}

/// A value of the place's type for a raw reading (integers rounded and
/// clamped to the type's range).
fn raw_value(p: Place, v: f64) -> Value {
    let ty = p.data_type();
    let int = |lo: f64, hi: f64| v.round().clamp(lo, hi);
    match ty {
        DataType::Sint => Value::Sint(int(i8::MIN.into(), i8::MAX.into()) as i8),
        DataType::Int => Value::Int(int(i16::MIN.into(), i16::MAX.into()) as i16),
        DataType::Dint | DataType::Time => Value::Dint(int(i32::MIN.into(), i32::MAX.into()) as i32),
        DataType::Lint => Value::Lint(int(-9.0e18, 9.0e18) as i64),
        DataType::Lreal => Value::Lreal(v),
        _ => Value::Real(v as f32),
    }
}

impl Sim {
    fn new(spec: &PlantSpec) -> Sim {
        let m = &spec.model;
        let y0 = m.initial;
        // At rest at the initial measurement.
        let x = match m.dynamics {
            Dynamics::FirstOrder { .. } | Dynamics::SecondOrder { .. } => [y0, 0.0],
            Dynamics::Tank { sensor, .. } => [if sensor != 0.0 { y0 / sensor } else { 0.0 }, 0.0],
            Dynamics::Motor { kt, b, sensor, .. } => {
                let w = if sensor != 0.0 { y0 / sensor } else { 0.0 };
                [b * w / kt, w]
            }
        };
        // Fastest time constant, for the integration step.
        let fastest = match m.dynamics {
            Dynamics::FirstOrder { tau, .. } => tau,
            Dynamics::SecondOrder { a2, a1, a0, .. } => {
                let mut t = f64::INFINITY;
                if a1 > 0.0 {
                    t = t.min(a2 / a1);
                }
                if a0 > 0.0 {
                    t = t.min((a2 / a0).sqrt());
                }
                t
            }
            Dynamics::Tank {
                area, outflow, drain, ..
            } => match drain {
                _ if outflow <= 0.0 => f64::INFINITY,
                Drain::Linear => area / outflow,
                // linearised at the initial level (at least 1 % of a unit)
                Drain::Orifice => 2.0 * area * x[0].max(0.01).sqrt() / outflow,
            },
            Dynamics::Motor { r, l, kt, ke, j, .. } => (l / r).min(j * r / (kt * ke)),
        };
        let sub = (0.005 / fastest).ceil().clamp(1.0, 1000.0) as u32;
        let n = (m.dead_time * 1000.0).round() as usize;
        let mut s = Sim {
            spec: spec.clone(),
            x,
            sub,
            delay: std::iter::repeat_n(y0, n).collect(),
            y: y0,
            rng: m.seed ^ 0x9E37_79B9_7F4A_7C15,
        };
        s.y = s.measure(&s.x);
        if n > 0 {
            s.y = y0;
        }
        s
    }

    /// The actuator signal in physical units, saturated.
    fn actuator(&self, mem: &Memory) -> f64 {
        let m = &self.spec.model;
        let raw = mem.read(self.spec.input).as_f64();
        let mut u = m.input_scale.to_physical(if raw.is_finite() { raw } else { 0.0 });
        if let Some((lo, hi)) = m.saturation {
            u = u.clamp(lo, hi);
        }
        u
    }

    fn measure(&self, x: &[f64; 2]) -> f64 {
        match self.spec.model.dynamics {
            Dynamics::FirstOrder { .. } | Dynamics::SecondOrder { .. } => x[0],
            Dynamics::Tank { sensor, .. } => sensor * x[0],
            Dynamics::Motor { sensor, .. } => sensor * x[1],
        }
    }

    fn deriv(&self, x: &[f64; 2], u: f64) -> [f64; 2] {
        match self.spec.model.dynamics {
            Dynamics::FirstOrder { gain, tau } => [(gain * u - x[0]) / tau, 0.0],
            Dynamics::SecondOrder { gain, a2, a1, a0 } => [x[1], (gain * u - a1 * x[1] - a0 * x[0]) / a2],
            Dynamics::Tank {
                area,
                inflow,
                outflow,
                drain,
                dead_zone,
                ..
            } => {
                let out = match drain {
                    Drain::Linear => x[0],
                    Drain::Orifice => x[0].max(0.0).sqrt(),
                };
                // with a dead zone, a pump: nothing below it, never backwards
                let pumped = if dead_zone > 0.0 { (u - dead_zone).max(0.0) } else { u };
                [(inflow * pumped - outflow * out) / area, 0.0]
            }
            Dynamics::Motor { r, l, kt, ke, j, b, .. } => [(u - r * x[0] - ke * x[1]) / l, (kt * x[0] - b * x[1]) / j],
        }
    }

    /// One millisecond of the model with the actuator at `u`.
    fn advance_ms(&mut self, u: f64) {
        let h = 0.001 / f64::from(self.sub);
        for _ in 0..self.sub {
            let x = self.x;
            let add = |a: [f64; 2], k: [f64; 2], c: f64| [a[0] + c * k[0], a[1] + c * k[1]];
            let k1 = self.deriv(&x, u);
            let k2 = self.deriv(&add(x, k1, h / 2.0), u);
            let k3 = self.deriv(&add(x, k2, h / 2.0), u);
            let k4 = self.deriv(&add(x, k3, h), u);
            for i in 0..2 {
                self.x[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            if let Dynamics::Tank { max_level, .. } = self.spec.model.dynamics {
                self.x[0] = self.x[0].max(0.0);
                if let Some(m) = max_level {
                    self.x[0] = self.x[0].min(m);
                }
            }
        }
        let y = self.measure(&self.x);
        self.y = if self.delay.is_empty() {
            y
        } else {
            self.delay.push_back(y);
            self.delay.pop_front().unwrap_or(y)
        };
    }

    /// Gaussian noise with the model's standard deviation (xorshift64* and
    /// Box–Muller: the same numbers on every platform for one seed).
    fn noise(&mut self) -> f64 {
        let sd = self.spec.model.noise;
        if sd == 0.0 {
            return 0.0;
        }
        let mut next = || {
            self.rng ^= self.rng >> 12;
            self.rng ^= self.rng << 25;
            self.rng ^= self.rng >> 27;
            let v = self.rng.wrapping_mul(0x2545_F491_4F6C_DD1D);
            ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (a, b) = (next(), next());
        sd * (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::{FileId, Span};
    use alba_ir::{F, I};
    use alba_model::plant::{PlantModel, Scale};

    fn spec(d: Dynamics, dead: f64) -> (PlantSpec, Memory) {
        let sp = Span::new(FileId(0), 0..0);
        let model = PlantModel {
            dynamics: d,
            input: ("U".into(), sp),
            output: ("Y".into(), sp),
            input_scale: Scale::IDENTITY,
            output_scale: Scale::IDENTITY,
            saturation: Some((0.0, 10.0)),
            dead_time: dead,
            noise: 0.0,
            seed: 1,
            initial: 0.0,
        };
        let mut mem = Memory::new(
            alba_ir::Counts {
                f: 2,
                i: 1,
                ..Default::default()
            },
            0,
        );
        mem.f[0] = 0.0;
        let _ = I(0);
        (
            PlantSpec {
                model,
                input: Place::Real(F(0)),
                output: Place::Real(F(1)),
            },
            mem,
        )
    }

    #[test]
    fn first_order_step_reaches_63_percent_at_tau() {
        let (s, mut mem) = spec(Dynamics::FirstOrder { gain: 2.0, tau: 1.5 }, 0.0);
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 1.0;
        p.step(&mut mem, 1500);
        let y = f64::from(mem.f[1]);
        let want = 2.0 * (1.0 - (-1.0f64).exp());
        assert!((y - want).abs() < 1e-6, "{y} vs {want}");
    }

    #[test]
    fn dead_time_delays_and_saturation_limits() {
        let (s, mut mem) = spec(Dynamics::FirstOrder { gain: 1.0, tau: 1.0 }, 0.5);
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 50.0; // saturated to 10
        p.step(&mut mem, 500);
        assert_eq!(mem.f[1], 0.0);
        p.step(&mut mem, 1500);
        let y = f64::from(mem.f[1]);
        let want = 10.0 * (1.0 - (-1.0f64).exp());
        assert!((y - want).abs() < 1e-6, "{y} vs {want}");
    }

    #[test]
    fn second_order_and_tank_match_closed_forms() {
        // 1/((s+1)(s+2)) = 1/(s² + 3s + 2): step response 1/2 - e^-t + e^-2t/2.
        let (s, mut mem) = spec(
            Dynamics::SecondOrder {
                gain: 1.0,
                a2: 1.0,
                a1: 3.0,
                a0: 2.0,
            },
            0.0,
        );
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 1.0;
        p.step(&mut mem, 1000);
        let want = 0.5 - (-1.0f64).exp() + (-2.0f64).exp() / 2.0;
        assert!((f64::from(mem.f[1]) - want).abs() < 1e-6);
        // A tank without outflow integrates: h = inflow·u·t/area.
        let (s, mut mem) = spec(
            Dynamics::Tank {
                area: 2.0,
                inflow: 0.5,
                outflow: 0.0,
                sensor: 1.0,
                max_level: Some(3.0),
                drain: Drain::Linear,
                dead_zone: 0.0,
            },
            0.0,
        );
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 4.0;
        p.step(&mut mem, 2000);
        assert!((f64::from(mem.f[1]) - 2.0).abs() < 1e-6);
        p.step(&mut mem, 10_000);
        assert!((f64::from(mem.f[1]) - 3.0).abs() < 1e-6, "overflows at max_level");
    }

    #[test]
    fn an_orifice_tank_behind_a_pump_with_a_dead_zone() {
        // At rest: inflow·(u − dead_zone) = outflow·√h, so h = (2·(6 − 1)/2.5)² = 16
        // (linearised there, τ = 2·area·√h/outflow = 320 s).
        let tank = Dynamics::Tank {
            area: 100.0,
            inflow: 2.0,
            outflow: 2.5,
            sensor: 1.0,
            max_level: None,
            drain: Drain::Orifice,
            dead_zone: 1.0,
        };
        let (s, mut mem) = spec(tank, 0.0);
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 6.0;
        p.step(&mut mem, 4_000_000);
        assert!((f64::from(mem.f[1]) - 16.0).abs() < 1e-3, "{}", mem.f[1]);
        // Below the dead zone the pump delivers nothing: Torricelli's drain alone,
        // √h falls linearly, 2.5/(2·100) per second: from 4 to 2 in 160 s.
        mem.f[0] = 0.5;
        p.step(&mut mem, 4_160_000);
        assert!((f64::from(mem.f[1]) - 4.0).abs() < 1e-2, "{}", mem.f[1]);
    }

    #[test]
    fn motor_settles_at_its_steady_speed() {
        // ω∞ = kt·u / (R·b + kt·ke).
        let (s, mut mem) = spec(
            Dynamics::Motor {
                r: 1.0,
                l: 0.01,
                kt: 0.05,
                ke: 0.05,
                j: 0.001,
                b: 0.0001,
                sensor: 1.0,
            },
            0.0,
        );
        let mut p = Plants::new(&[s]);
        p.step(&mut mem, 0);
        mem.f[0] = 10.0;
        p.step(&mut mem, 5000);
        let want = 0.05 * 10.0 / (1.0 * 0.0001 + 0.05 * 0.05);
        assert!(
            (f64::from(mem.f[1]) - want).abs() < 1e-3 * want,
            "{} vs {want}",
            mem.f[1]
        );
    }

    #[test]
    fn noise_is_seeded_and_has_its_standard_deviation() {
        let run = |seed: u64| {
            let (mut s, mut mem) = spec(Dynamics::FirstOrder { gain: 1.0, tau: 1.0 }, 0.0);
            s.model.noise = 0.5;
            s.model.seed = seed;
            let mut p = Plants::new(&[s]);
            (0..4000u64)
                .map(|k| {
                    p.step(&mut mem, k);
                    f64::from(mem.f[1])
                })
                .collect::<Vec<_>>()
        };
        let a = run(7);
        assert_eq!(a, run(7));
        assert_ne!(a, run(8));
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        let sd = (a.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
        assert!(mean.abs() < 0.05 && (sd - 0.5).abs() < 0.05, "mean {mean} sd {sd}");
    }
}
