//! Relay-feedback autotuning (Åström–Hägglund) of a PID loop in simulation
//! (`alba tune`), with Ziegler–Nichols and Tyreus–Luyben rules.
//!
//! The loop is put in manual and its output driven by a relay around a bias:
//! `CV = bias + d` while the error is above `+h`, `bias − d` below `−h`
//! (hysteresis `h` against noise), otherwise unchanged. The plant then
//! oscillates at about its ultimate period. From the last whole cycles the
//! period Pu is the mean time between rising relay switches, and the
//! amplitude is taken from the **fundamental** of the measured PV over those
//! cycles (a Fourier coefficient), not from its peaks: the relay's square
//! wave has the fundamental 4d/π, so Ku = 4d/(π·a₁) is the describing
//! function without the error that the harmonics of a non-sinusoidal PV
//! bring into the peak method. With hysteresis, a₁ is replaced by
//! √(a₁² − h²) as in Åström–Hägglund.

use crate::engine::Engine;
use alba_ir::{Place, Target};
use alba_model::Value;

/// Why the relay experiment gave no result ([`tune`], [`relay`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TuneError {
    #[error("the program does not verify: {0}")]
    Program(crate::EngineError),
    #[error("`{0}` is not a value")]
    NotAValue(String),
    #[error("{0}")]
    Resolve(alba_ir::ResolveError),
    #[error("the relay amplitude must be more than 0 and the hysteresis 0 or more")]
    BadRelay,
    #[error("the relay's centre must be 0 to 100 % of CV, not {0}")]
    BadBias(f64),
    /// The simulation stopped on a major fault (its message).
    #[error("{0}")]
    Fault(String),
    #[error(
        "no sustained oscillation within {seconds} s ({cycles} relay cycles): increase the amplitude, lower the hysteresis or check the bias"
    )]
    NoOscillation { seconds: u64, cycles: usize },
    #[error("the oscillation is smaller than the hysteresis")]
    TooSmall,
}

/// The experiment on a fresh engine of `program` (from its initial state,
/// its plant models included), the loop's SP first set to `sp` when given:
/// what `alba tune` and the studio's autotune run.
pub fn tune(
    program: std::sync::Arc<alba_ir::Program>,
    pid: &str,
    sp: Option<f64>,
    opt: RelayOptions,
) -> Result<RelayResult, TuneError> {
    let mut engine = Engine::new(program).map_err(TuneError::Program)?;
    if let Some(sp) = sp
        && let Ok(Target::Value { place, .. }) = engine.program().layout.resolve(&format!("{pid}.SP"))
    {
        engine.write(place, Value::Real(sp as f32));
    }
    relay(&mut engine, pid, opt)
}

/// How to run the experiment.
#[derive(Debug, Clone, Copy)]
pub struct RelayOptions {
    /// Scan period, ms.
    pub scan_ms: u64,
    /// Relay amplitude d, % of CV.
    pub amplitude: f64,
    /// Relay centre, % of CV; `None`: the loop's own output once it holds
    /// the plant at the setpoint (see [`relay`]).
    pub bias: Option<f64>,
    /// Hysteresis h, in the units of the error (engineering units).
    pub hysteresis: f64,
    /// Give up after this long, ms.
    pub until_ms: u64,
    /// Whole cycles to average once the oscillation has settled.
    pub cycles: usize,
}

/// What the experiment found.
#[derive(Debug, Clone, PartialEq)]
pub struct RelayResult {
    /// Ultimate gain, %CV per % of the PV span (the loop's gain units).
    pub ku: f64,
    /// Ultimate period, s.
    pub pu: f64,
    /// Amplitude of the PV's fundamental, engineering units.
    pub a: f64,
    /// Peak-to-peak half amplitude of the PV, engineering units (for comparison).
    pub a_peak: f64,
    pub cycles: usize,
    /// The relay's centre used, % of CV.
    pub bias: f64,
}

/// A tuning rule's gains.
#[derive(Debug, Clone, PartialEq)]
pub struct Gains {
    pub rule: &'static str,
    pub kc: f64,
    /// s (0: none).
    pub ti: f64,
    /// s (0: none).
    pub td: f64,
}

impl Gains {
    /// Independent gains: KP, KI (1/s), KD (s).
    pub fn independent(&self) -> (f64, f64, f64) {
        let ki = if self.ti > 0.0 { self.kc / self.ti } else { 0.0 };
        (self.kc, ki, self.kc * self.td)
    }
}

/// Ziegler–Nichols and Tyreus–Luyben settings from Ku and Pu.
pub fn rules(ku: f64, pu: f64) -> Vec<Gains> {
    let g = |rule, kc, ti, td| Gains { rule, kc, ti, td };
    vec![
        g("Ziegler-Nichols P", 0.5 * ku, 0.0, 0.0),
        g("Ziegler-Nichols PI", 0.45 * ku, pu / 1.2, 0.0),
        g("Ziegler-Nichols PID", 0.6 * ku, pu / 2.0, pu / 8.0),
        g("Tyreus-Luyben PI", ku / 3.2, 2.2 * pu, 0.0),
        g("Tyreus-Luyben PID", ku / 2.2, 2.2 * pu, pu / 6.3),
    ]
}

fn place(engine: &Engine, name: &str) -> Result<Place, TuneError> {
    match engine.program().layout.resolve(name) {
        Ok(Target::Value { place, .. }) => Ok(place),
        Ok(_) => Err(TuneError::NotAValue(name.to_string())),
        Err(e) => Err(TuneError::Resolve(e)),
    }
}

/// How long the loop must hold the PV at SP in auto before the relay starts
/// around its output, ms (and the window its CV is averaged over).
const SETTLED_MS: u64 = 10_000;
/// Longest wait for the loop to settle, ms.
const SETTLE_LIMIT_MS: u64 = 300_000;

/// The relay's centre when none is given: the loop runs in auto with its own
/// gains until it has held the PV within 1 % of the span of SP, with its CV
/// steady within 1 %, for [`SETTLED_MS`] (at most [`SETTLE_LIMIT_MS`] or half
/// the experiment's time); the centre is its mean CV over that window — the
/// output that holds the plant at SP, as an operator would wait for a steady
/// state before starting a relay test. A loop at rest at its SP settles at
/// once, around its CV now. Returns the centre and the time reached.
fn settle(
    engine: &mut Engine,
    sp: Place,
    pv: Place,
    cv: Place,
    man: Place,
    span: f64,
    opt: &RelayOptions,
) -> Result<(f64, u64), TuneError> {
    let limit = SETTLE_LIMIT_MS.min(opt.until_ms / 2);
    let window = (SETTLED_MS / opt.scan_ms).max(1) as usize;
    let mut recent: std::collections::VecDeque<(f64, f64)> = std::collections::VecDeque::with_capacity(window + 1);
    let mut t = 0u64;
    loop {
        engine.step_plants(t);
        engine.write(man, Value::Bool(false));
        engine.scan(t).map_err(|m| TuneError::Fault(m.message))?;
        recent.push_back((
            engine.read(sp).as_f64() - engine.read(pv).as_f64(),
            engine.read(cv).as_f64(),
        ));
        if recent.len() > window {
            recent.pop_front();
        }
        let full = recent.len() == window;
        let (lo, hi) = recent
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (_, u)| {
                (l.min(*u), h.max(*u))
            });
        let held = recent.iter().all(|(e, _)| e.abs() <= 0.01 * span);
        if (full && held && hi - lo <= 1.0) || t >= limit {
            let mean = recent.iter().map(|(_, u)| u).sum::<f64>() / recent.len() as f64;
            return Ok((mean, t + opt.scan_ms));
        }
        t += opt.scan_ms;
    }
}

/// Runs the relay experiment on the PID tag `pid` of a running simulation
/// (plants attached), from virtual time 0.
pub fn relay(engine: &mut Engine, pid: &str, opt: RelayOptions) -> Result<RelayResult, TuneError> {
    let p = |m: &str| place(engine, &format!("{pid}.{m}"));
    let (sp, pv, cv, man, direct, maxs, mins) = (
        p("SP")?,
        p("PV")?,
        p("CV")?,
        p("MAN")?,
        p("DIRECT")?,
        p("MAXS")?,
        p("MINS")?,
    );
    if !(opt.amplitude > 0.0 && opt.hysteresis >= 0.0 && opt.scan_ms > 0) {
        return Err(TuneError::BadRelay);
    }
    let span = engine.read(maxs).as_f64() - engine.read(mins).as_f64();
    let (bias, mut t) = match opt.bias {
        Some(b) => (b, 0),
        None => settle(engine, sp, pv, cv, man, if span > 0.0 { span } else { 1.0 }, &opt)?,
    };
    if !(0.0..=100.0).contains(&bias) {
        return Err(TuneError::BadBias(bias));
    }
    let mut high = true;
    let mut times = Vec::new();
    let mut pvs = Vec::new();
    let mut rises: Vec<usize> = Vec::new();
    let mut us = Vec::new();
    while t <= opt.until_ms {
        engine.step_plants(t);
        let sign = if engine.read(direct).as_bool() { -1.0 } else { 1.0 };
        let e = sign * (engine.read(sp).as_f64() - engine.read(pv).as_f64());
        if high && e < -opt.hysteresis {
            high = false;
        } else if !high && e > opt.hysteresis {
            high = true;
            rises.push(times.len());
        }
        let u = bias + if high { opt.amplitude } else { -opt.amplitude };
        engine.write(man, Value::Bool(true));
        engine.write(cv, Value::Real(u as f32));
        engine.scan(t).map_err(|m| TuneError::Fault(m.message))?;
        times.push(t);
        pvs.push(engine.read(pv).as_f64());
        us.push(u);
        // Enough cycles: the first two are the transient.
        if rises.len() > opt.cycles + 2 {
            break;
        }
        t += opt.scan_ms;
    }
    if rises.len() < opt.cycles + 2 {
        return Err(TuneError::NoOscillation {
            seconds: opt.until_ms / 1000,
            cycles: rises.len().saturating_sub(1),
        });
    }
    let last = &rises[rises.len() - 1 - opt.cycles..];
    let (i0, i1) = (last[0], last[last.len() - 1]);
    let span_s = (times[i1] - times[i0]) as f64 / 1000.0;
    let pu = span_s / opt.cycles as f64;
    // Fundamental of PV over the whole cycles [i0, i1).
    let w = std::f64::consts::TAU / pu;
    let n = (i1 - i0) as f64;
    let mean = pvs[i0..i1].iter().sum::<f64>() / n;
    let (mut c, mut s) = (0.0, 0.0);
    for k in i0..i1 {
        let tk = (times[k] - times[i0]) as f64 / 1000.0;
        c += (pvs[k] - mean) * (w * tk).cos();
        s += (pvs[k] - mean) * (w * tk).sin();
    }
    let a1 = 2.0 * (c * c + s * s).sqrt() / n;
    let (lo, hi) = pvs[i0..i1]
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    let a_eff = (a1 * a1 - opt.hysteresis * opt.hysteresis).max(0.0).sqrt();
    if a_eff <= 0.0 {
        return Err(TuneError::TooSmall);
    }
    let a_pct = if span > 0.0 { a_eff * 100.0 / span } else { a_eff };
    Ok(RelayResult {
        ku: 4.0 * opt.amplitude / (std::f64::consts::PI * a_pct),
        pu,
        a: a1,
        a_peak: (hi - lo) / 2.0,
        cycles: opt.cycles,
        bias,
    })
}

/// The ultimate gain and period of K·e^(−Ls)/(τs + 1): the frequency where
/// the phase is −π (bisection), Ku = √(1 + (ωτ)²)/K, Pu = 2π/ω.
pub fn fopdt_ultimate(k: f64, tau: f64, dead: f64) -> (f64, f64) {
    let phase = |w: f64| -w * dead - (w * tau).atan();
    let (mut lo, mut hi) = (1e-9, std::f64::consts::PI / dead);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if phase(mid) > -std::f64::consts::PI {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let w = 0.5 * (lo + hi);
    ((1.0 + (w * tau).powi(2)).sqrt() / k, std::f64::consts::TAU / w)
}
