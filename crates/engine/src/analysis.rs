//! Step-response figures of a traced signal (`alba sim --summary`): what a
//! user compares tunings by, measured the way the `004_…` source reports
//! them (overshoot Mp, settling time ts(98 %)), plus rise time and IAE.

use std::fmt;

/// Figures of one signal's response.
#[derive(Debug, Clone, PartialEq)]
pub struct StepInfo {
    /// The value at the first sample.
    pub initial: f64,
    /// Where it should end: the reference's last value, or its own.
    pub target: f64,
    pub peak: f64,
    pub peak_ms: u64,
    /// Overshoot beyond the target, % of the step (0 when none).
    pub overshoot_pct: f64,
    /// 10 % to 90 % of the step, ms (`None` if never reached).
    pub rise_ms: Option<u64>,
    /// From the first sample to the start of the final stay within ±2 % of
    /// the step around the target, ms (`None` if it never stays).
    pub settling_ms: Option<u64>,
    /// Integral of |reference − signal| over the trace, unit·s.
    pub iae: f64,
}

/// The figures of `y` sampled at `t` (ms), against the reference `r` (or,
/// without one, against its own last value). `None` for fewer than two
/// samples or a step of zero.
pub fn step_info(t: &[u64], y: &[f64], r: Option<&[f64]>) -> Option<StepInfo> {
    if t.len() < 2 || y.len() != t.len() || r.is_some_and(|r| r.len() != t.len()) {
        return None;
    }
    let initial = y[0];
    let target = r.map_or(y[y.len() - 1], |r| r[r.len() - 1]);
    let step = target - initial;
    if step == 0.0 || !step.is_finite() {
        return None;
    }
    let up = step > 0.0;
    let (mut peak, mut peak_ms) = (initial, t[0]);
    for (&ti, &yi) in t.iter().zip(y) {
        if (up && yi > peak) || (!up && yi < peak) {
            (peak, peak_ms) = (yi, ti);
        }
    }
    let overshoot_pct = ((peak - target) / step * 100.0).max(0.0);
    let frac = |yi: f64| (yi - initial) / step;
    let first = |level: f64| t.iter().zip(y).find(|(_, yi)| frac(**yi) >= level).map(|(ti, _)| *ti);
    let rise_ms = match (first(0.1), first(0.9)) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    let band = 0.02 * step.abs();
    let last_out = y.iter().rposition(|yi| (yi - target).abs() > band);
    let settling_ms = match last_out {
        None => Some(0),
        Some(k) if k + 1 < t.len() => Some(t[k + 1] - t[0]),
        Some(_) => None,
    };
    let mut iae = 0.0;
    for k in 1..t.len() {
        let reference = r.map_or(target, |r| r[k]);
        iae += (reference - y[k]).abs() * (t[k] - t[k - 1]) as f64 / 1000.0;
    }
    Some(StepInfo {
        initial,
        target,
        peak,
        peak_ms,
        overshoot_pct,
        rise_ms,
        settling_ms,
        iae,
    })
}

impl fmt::Display for StepInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = |ms: Option<u64>| ms.map_or("not reached".to_string(), |v| format!("{:.2} s", v as f64 / 1000.0));
        write!(
            f,
            "from {} to {}: overshoot {:.2} %, peak {} at {:.2} s, rise time (10-90 %) {}, settling time (98 %) {}, IAE {:.4}",
            self.initial,
            self.target,
            self.overshoot_pct,
            self.peak,
            self.peak_ms as f64 / 1000.0,
            s(self.rise_ms),
            s(self.settling_ms),
            self.iae
        )
    }
}

/// Why a trace CSV cannot be read ([`columns`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TraceError {
    #[error("the trace is empty")]
    Empty,
    #[error("`{0}` is not traced (add it to --tags)")]
    NotTraced(String),
    /// The row's number in the file (the header is row 1).
    #[error("trace row {0} is malformed")]
    BadRow(usize),
}

/// Parses a trace CSV (as `alba sim` writes it) into its times and the
/// columns named; errors name a missing column or a bad row.
pub fn columns(trace: &str, names: &[&str]) -> Result<(Vec<u64>, Vec<Vec<f64>>), TraceError> {
    let mut lines = trace.lines();
    let header: Vec<&str> = lines.next().ok_or(TraceError::Empty)?.split(',').collect();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h.eq_ignore_ascii_case(n))
                .ok_or_else(|| TraceError::NotTraced(n.to_string()))
        })
        .collect::<Result<_, _>>()?;
    let mut t = Vec::new();
    let mut cols = vec![Vec::new(); names.len()];
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || TraceError::BadRow(k + 2);
        t.push(f.first().and_then(|v| v.parse().ok()).ok_or_else(bad)?);
        for (c, &i) in cols.iter_mut().zip(&idx) {
            c.push(f.get(i).and_then(|v| v.parse().ok()).ok_or_else(bad)?);
        }
    }
    Ok((t, cols))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_hand_made_response() {
        let t: Vec<u64> = (0..=10).map(|k| k * 1000).collect();
        let y = [0.0, 2.0, 6.0, 9.5, 11.0, 10.5, 10.1, 9.9, 10.0, 10.0, 10.0];
        let s = step_info(&t, &y, None).unwrap();
        assert_eq!(s.target, 10.0);
        assert!((s.overshoot_pct - 10.0).abs() < 1e-9);
        assert_eq!((s.peak, s.peak_ms), (11.0, 4000));
        assert_eq!(s.rise_ms, Some(2000)); // 10 % at 1 s (2.0), 90 % at 3 s (9.5)
        assert_eq!(s.settling_ms, Some(6000)); // 10.5 at 5 s is outside ±0.2
        // IAE: 8+4+0.5+1+0.5+0.1+0.1 = 14.2 (the first sample has no width).
        assert!((s.iae - 14.2).abs() < 1e-9, "{}", s.iae);
        let r = vec![10.0; 11];
        assert_eq!(step_info(&t, &y, Some(&r)).unwrap().iae, s.iae);
        assert!(step_info(&t, &[1.0; 11], None).is_none());
    }

    #[test]
    fn columns_are_found_by_name() {
        let (t, c) = columns("time_ms,A,B\n0,1,2\n10,3,4.5\n", &["b"]).unwrap();
        assert_eq!(t, [0, 10]);
        assert_eq!(c, [vec![2.0, 4.5]]);
        assert_eq!(
            columns("time_ms,A\n0,1\n", &["C"]).unwrap_err().to_string(),
            "`C` is not traced (add it to --tags)"
        );
        assert_eq!(columns("time_ms,A\n0,x\n", &["A"]), Err(TraceError::BadRow(2)));
    }
}
