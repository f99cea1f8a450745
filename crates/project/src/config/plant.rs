//! `[[plant_model]]` tables of `alba.toml`, read and checked into
//! [`PlantModel`]s (the types live in `alba_model::plant`).

use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_model::plant::{Drain, Dynamics, KINDS, MAX_DEAD_TIME, PlantModel, Scale};
use serde::Deserialize;
use serde_spanned::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPlant {
    kind: Spanned<String>,
    input: Spanned<String>,
    output: Spanned<String>,
    gain: Option<Spanned<f64>>,
    tau: Option<Spanned<f64>>,
    den: Option<Spanned<Vec<f64>>>,
    area: Option<Spanned<f64>>,
    inflow: Option<Spanned<f64>>,
    outflow: Option<Spanned<f64>>,
    sensor: Option<Spanned<f64>>,
    max_level: Option<Spanned<f64>>,
    drain: Option<Spanned<String>>,
    dead_zone: Option<Spanned<f64>>,
    r: Option<Spanned<f64>>,
    l: Option<Spanned<f64>>,
    kt: Option<Spanned<f64>>,
    ke: Option<Spanned<f64>>,
    j: Option<Spanned<f64>>,
    b: Option<Spanned<f64>>,
    input_scale: Option<Spanned<Vec<f64>>>,
    output_scale: Option<Spanned<Vec<f64>>>,
    saturation: Option<Spanned<Vec<f64>>>,
    dead_time: Option<Spanned<f64>>,
    noise: Option<Spanned<f64>>,
    seed: Option<Spanned<i64>>,
    initial: Option<Spanned<f64>>,
}

impl RawPlant {
    /// Checks one table; `None` (with diagnostics) when it cannot be used.
    pub(super) fn check(self, file: FileId, diags: &mut Vec<Diagnostic>) -> Option<PlantModel> {
        let sp = |r: std::ops::Range<usize>| Span::new(file, r);
        let before = diags.len();
        let kind_span = sp(self.kind.span());
        let mut bad = |span: Span, msg: String, label: &str| {
            diags.push(Diagnostic::new(Code::PlantModel, msg, span, label));
        };
        // A number, finite and in a range; `what` says which.
        let num = |v: &Option<Spanned<f64>>,
                   key: &str,
                   default: Option<f64>,
                   positive: bool,
                   bad: &mut dyn FnMut(Span, String, &str)|
         -> f64 {
            match v {
                None => {
                    if default.is_none() {
                        bad(
                            kind_span,
                            format!("a {} plant model needs `{key}`", self.kind.get_ref()),
                            "missing parameter",
                        );
                    }
                    default.unwrap_or(1.0)
                }
                Some(s) => {
                    let x = *s.get_ref();
                    let ok = x.is_finite() && if positive { x > 0.0 } else { x >= 0.0 };
                    if !ok {
                        let want = if positive { "more than 0" } else { "0 or more" };
                        bad(
                            sp(s.span()),
                            format!("{key} = {x} must be a number {want}"),
                            "out of range",
                        );
                    }
                    x
                }
            }
        };
        let dynamics = match self.kind.get_ref().as_str() {
            "first_order" => Dynamics::FirstOrder {
                gain: self.gain.as_ref().map_or(1.0, |g| *g.get_ref()),
                tau: num(&self.tau, "tau", None, true, &mut bad),
            },
            "second_order" => {
                let (a2, a1, a0) = match &self.den {
                    Some(d) if d.get_ref().len() == 3 && d.get_ref().iter().all(|x| x.is_finite()) => {
                        let v = d.get_ref();
                        if v[0] <= 0.0 || v[1] < 0.0 || v[2] < 0.0 {
                            bad(
                                sp(d.span()),
                                format!("den = {v:?}: a2 must be more than 0 and a1, a0 not negative"),
                                "not a stable second order",
                            );
                        }
                        (v[0], v[1], v[2])
                    }
                    Some(d) => {
                        bad(
                            sp(d.span()),
                            "den must be three numbers [a2, a1, a0] for gain/(a2·s² + a1·s + a0)".into(),
                            "expected [a2, a1, a0]",
                        );
                        (1.0, 1.0, 1.0)
                    }
                    None => {
                        bad(
                            kind_span,
                            "a second_order plant model needs `den = [a2, a1, a0]`".into(),
                            "missing parameter",
                        );
                        (1.0, 1.0, 1.0)
                    }
                };
                Dynamics::SecondOrder {
                    gain: self.gain.as_ref().map_or(1.0, |g| *g.get_ref()),
                    a2,
                    a1,
                    a0,
                }
            }
            "tank" => Dynamics::Tank {
                area: num(&self.area, "area", Some(1.0), true, &mut bad),
                inflow: num(&self.inflow, "inflow", None, false, &mut bad),
                outflow: num(&self.outflow, "outflow", Some(0.0), false, &mut bad),
                sensor: self.sensor.as_ref().map_or(1.0, |g| *g.get_ref()),
                max_level: self
                    .max_level
                    .as_ref()
                    .map(|_| num(&self.max_level, "max_level", None, true, &mut bad)),
                drain: match self.drain.as_ref().map(|d| (d.get_ref().as_str(), d.span())) {
                    None | Some(("linear", _)) => Drain::Linear,
                    Some(("orifice", _)) => Drain::Orifice,
                    Some((other, span)) => {
                        bad(
                            sp(span),
                            format!("drain = \"{other}\" is not a drain law"),
                            "expected \"linear\" or \"orifice\"",
                        );
                        Drain::Linear
                    }
                },
                dead_zone: num(&self.dead_zone, "dead_zone", Some(0.0), false, &mut bad),
            },
            "motor" => {
                let kt = num(&self.kt, "kt", None, true, &mut bad);
                Dynamics::Motor {
                    r: num(&self.r, "r", None, true, &mut bad),
                    l: num(&self.l, "l", None, true, &mut bad),
                    kt,
                    ke: num(&self.ke, "ke", Some(kt), true, &mut bad),
                    j: num(&self.j, "j", None, true, &mut bad),
                    b: num(&self.b, "b", Some(0.0), false, &mut bad),
                    sensor: self.sensor.as_ref().map_or(1.0, |g| *g.get_ref()),
                }
            }
            other => {
                bad(
                    kind_span,
                    format!("unknown plant model kind `{other}`"),
                    &format!("expected one of {}", KINDS.join(", ")),
                );
                return None;
            }
        };
        // Parameters that do not belong to the kind are refused (typos).
        let kind = self.kind.get_ref().as_str();
        let allowed: &[&str] = match kind {
            "first_order" => &["gain", "tau"],
            "second_order" => &["gain", "den"],
            "tank" => &["area", "inflow", "outflow", "sensor", "max_level", "drain", "dead_zone"],
            _ => &["r", "l", "kt", "ke", "j", "b", "sensor"],
        };
        let given = [
            ("gain", self.gain.as_ref().map(|s| s.span())),
            ("tau", self.tau.as_ref().map(|s| s.span())),
            ("den", self.den.as_ref().map(|s| s.span())),
            ("area", self.area.as_ref().map(|s| s.span())),
            ("inflow", self.inflow.as_ref().map(|s| s.span())),
            ("outflow", self.outflow.as_ref().map(|s| s.span())),
            ("sensor", self.sensor.as_ref().map(|s| s.span())),
            ("max_level", self.max_level.as_ref().map(|s| s.span())),
            ("drain", self.drain.as_ref().map(|s| s.span())),
            ("dead_zone", self.dead_zone.as_ref().map(|s| s.span())),
            ("r", self.r.as_ref().map(|s| s.span())),
            ("l", self.l.as_ref().map(|s| s.span())),
            ("kt", self.kt.as_ref().map(|s| s.span())),
            ("ke", self.ke.as_ref().map(|s| s.span())),
            ("j", self.j.as_ref().map(|s| s.span())),
            ("b", self.b.as_ref().map(|s| s.span())),
        ];
        for (k, span) in given {
            if let Some(r) = span
                && !allowed.contains(&k)
            {
                bad(
                    sp(r),
                    format!("`{k}` is not a parameter of a {kind} model"),
                    &format!("{kind} takes {}", allowed.join(", ")),
                );
            }
        }
        for (k, v) in [("gain", &self.gain), ("sensor", &self.sensor)] {
            if let Some(s) = v
                && !s.get_ref().is_finite()
            {
                bad(
                    sp(s.span()),
                    format!("{k} = {} is not a number", s.get_ref()),
                    "not finite",
                );
            }
        }
        let mut scale = |v: &Option<Spanned<Vec<f64>>>, key: &str| -> Scale {
            let Some(s) = v else { return Scale::IDENTITY };
            let x = s.get_ref();
            if x.len() != 4 || !x.iter().all(|v| v.is_finite()) || x[0] == x[1] || x[2] == x[3] {
                bad(
                    sp(s.span()),
                    format!("{key} must be [raw_lo, raw_hi, lo, hi] with raw_lo ≠ raw_hi and lo ≠ hi"),
                    "bad scale",
                );
                return Scale::IDENTITY;
            }
            Scale {
                raw_lo: x[0],
                raw_hi: x[1],
                lo: x[2],
                hi: x[3],
            }
        };
        let input_scale = scale(&self.input_scale, "input_scale");
        let output_scale = scale(&self.output_scale, "output_scale");
        let saturation = self.saturation.as_ref().and_then(|s| {
            let x = s.get_ref();
            if x.len() == 2 && x.iter().all(|v| v.is_finite()) && x[0] <= x[1] {
                Some((x[0], x[1]))
            } else {
                bad(
                    sp(s.span()),
                    "saturation must be [lo, hi] with lo <= hi".into(),
                    "bad limits",
                );
                None
            }
        });
        let dead_time = self.dead_time.as_ref().map_or(0.0, |d| {
            let x = *d.get_ref();
            if !(0.0..=MAX_DEAD_TIME).contains(&x) {
                bad(
                    sp(d.span()),
                    format!("dead_time = {x} must be from 0 to {MAX_DEAD_TIME} s"),
                    "out of range",
                );
            }
            x
        });
        let noise = self.noise.as_ref().map_or(0.0, |n| {
            let x = *n.get_ref();
            if !(x.is_finite() && x >= 0.0) {
                bad(sp(n.span()), format!("noise = {x} must be 0 or more"), "out of range");
            }
            x
        });
        let seed = self.seed.as_ref().map_or(1, |s| *s.get_ref() as u64);
        let initial = self.initial.as_ref().map_or(0.0, |i| {
            let x = *i.get_ref();
            if !x.is_finite() {
                bad(sp(i.span()), format!("initial = {x} is not a number"), "not finite");
            }
            x
        });
        if diags.len() > before {
            return None;
        }
        Some(PlantModel {
            dynamics,
            input: (self.input.get_ref().clone(), sp(self.input.span())),
            output: (self.output.get_ref().clone(), sp(self.output.span())),
            input_scale,
            output_scale,
            saturation,
            dead_time,
            noise,
            seed,
            initial,
        })
    }
}
