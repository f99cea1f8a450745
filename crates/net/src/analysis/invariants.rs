//! P- and T-invariants, in two parts with budgets of their own.
//!
//! - **Flows** ([`p_flows`], [`t_flows`]): a basis of the rational solutions of `y · C = 0`
//!   (P) or `C · x = 0` (T), integer coefficients of any sign, by fraction-free Gaussian
//!   elimination on sparse rows `[D | Y]` (`D` the incidence matrix or its transpose, `Y`
//!   the identity): for each column a pivot row (the shortest with a non-zero entry there)
//!   eliminates the column from every other row, and rows are divided by their gcd. Rows
//!   whose `D` part ends empty are the basis. Polynomial: at most `n` rows, each
//!   elimination touches `O(n + m)` entries per row. Coefficients are checked 64-bit; a
//!   basis vector that would not fit is reported as an overflow.
//! - **Minimal semi-positive invariants** ([`p_invariants`], [`t_invariants`]) by the
//!   Farkas algorithm (Martínez–Silva), whose cost may be exponential: every pair of rows
//!   with opposite signs in a column is combined with positive factors
//!   (`|b|·r1 + |a|·r2`), divided by the gcd, and the rows with a non-zero entry are
//!   dropped. `D` entries may be negative in between — only `Y` must stay non-negative —
//!   so invariants that need negative intermediate coefficients are kept. After every
//!   column, rows whose support contains another row's support are dropped
//!   (minimality), so the result is exactly the set of minimal-support semi-positive
//!   invariants, each with gcd 1. It runs under a [`Budget`]: a number of work units
//!   (one per coefficient combined and per support compared), a cap on the rows kept,
//!   and a cancellation flag polled as it goes.

use std::sync::atomic::{AtomicBool, Ordering};

/// Why invariants could not be computed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InvariantError {
    /// An intermediate coefficient did not fit in 64 bits.
    Overflow,
    /// The intermediate matrix grew beyond the row limit.
    TooManyRows(usize),
    /// The work budget ran out.
    Budget(u64),
    /// The cancellation flag was raised.
    Cancelled,
}

impl std::fmt::Display for InvariantError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InvariantError::Overflow => write!(f, "an intermediate coefficient overflowed 64 bits"),
            InvariantError::TooManyRows(n) => write!(f, "more than {n} intermediate rows"),
            InvariantError::Budget(n) => write!(f, "the work budget ({n} steps) ran out"),
            InvariantError::Cancelled => write!(f, "cancelled"),
        }
    }
}

/// Default bound on the number of intermediate rows.
pub const MAX_ROWS: usize = 200_000;

/// Bytes the Farkas algorithm's rows may take.
pub const MAX_BYTES: usize = 256 << 20;

/// Default work budget of the minimal invariants (about a second on this machine).
pub const DEFAULT_WORK: u64 = 200_000_000;

/// The limits of one invariant computation.
#[derive(Clone, Copy, Debug)]
pub struct Budget<'a> {
    /// Work units (coefficients combined, supports compared) allowed.
    pub work: u64,
    /// Largest number of intermediate rows.
    pub max_rows: usize,
    /// Raised to stop the computation.
    pub cancel: &'a AtomicBool,
}

static NEVER: AtomicBool = AtomicBool::new(false);

impl Budget<'static> {
    /// `max_rows` rows, the default work, never cancelled.
    pub fn rows(max_rows: usize) -> Budget<'static> {
        Budget {
            work: DEFAULT_WORK,
            max_rows,
            cancel: &NEVER,
        }
    }
}

/// A running count of work against a budget.
struct Meter<'a> {
    budget: Budget<'a>,
    spent: u64,
    next_poll: u64,
}

impl Meter<'_> {
    fn new(budget: Budget<'_>) -> Meter<'_> {
        Meter {
            budget,
            spent: 0,
            next_poll: 0,
        }
    }

    #[inline]
    fn spend(&mut self, units: u64) -> Result<(), InvariantError> {
        self.spent += units;
        if self.spent > self.budget.work {
            return Err(InvariantError::Budget(self.budget.work));
        }
        if self.spent >= self.next_poll {
            self.next_poll = self.spent + 100_000;
            if self.budget.cancel.load(Ordering::Relaxed) {
                return Err(InvariantError::Cancelled);
            }
        }
        Ok(())
    }
}

#[derive(Clone)]
struct Row {
    d: Vec<i64>,
    y: Vec<i64>,
    support: Vec<u64>,
}

fn gcd(mut a: i64, mut b: i64) -> i64 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

fn subset(a: &[u64], b: &[u64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x & !y == 0)
}

/// Minimal semi-positive solutions `y >= 0, y != 0` of `y · A = 0`, where `a` has one
/// row per variable. Each result is a vector of coefficients (gcd 1), sorted by support.
pub fn farkas(a: &[Vec<i64>], cols: usize, budget: Budget<'_>) -> Result<Vec<Vec<i64>>, InvariantError> {
    let mut meter = Meter::new(budget);
    let n = a.len();
    let words = n.div_ceil(64).max(1);
    // Rows are dense: the row cap also keeps them within MAX_BYTES.
    let max_rows = budget.max_rows.min(MAX_BYTES / ((cols + n + words) * 8).max(1));
    if n > max_rows {
        return Err(InvariantError::TooManyRows(max_rows));
    }
    let w = words as u64;
    let mut rows: Vec<Row> = (0..n)
        .map(|i| {
            let mut y = vec![0; n];
            y[i] = 1;
            let mut support = vec![0u64; words];
            support[i / 64] |= 1 << (i % 64);
            Row {
                d: a[i].clone(),
                y,
                support,
            }
        })
        .collect();
    // Columns with fewest sign-opposed pairs first: the usual heuristic that keeps the
    // intermediate matrix small.
    let mut done = vec![false; cols];
    for step in 0..cols {
        meter.spend((rows.len() * (cols - step)) as u64)?;
        let j = (0..cols)
            .filter(|&j| !done[j])
            .min_by_key(|&j| {
                let pos = rows.iter().filter(|r| r.d[j] > 0).count();
                let neg = rows.iter().filter(|r| r.d[j] < 0).count();
                (pos * neg) as i64 - (pos + neg) as i64
            })
            .unwrap_or(0);
        done[j] = true;
        let (zero, nonzero): (Vec<Row>, Vec<Row>) = rows.into_iter().partition(|r| r.d[j] == 0);
        let (pos, neg): (Vec<&Row>, Vec<&Row>) = nonzero.iter().partition(|r| r.d[j] > 0);
        let mut next = zero;
        for p in &pos {
            for q in &neg {
                // The subset test, the duplicate test and the clean-up each read the kept rows' supports.
                meter.spend(3 * (next.len() as u64 + 1) * w)?;
                let support: Vec<u64> = p.support.iter().zip(&q.support).map(|(x, y)| x | y).collect();
                // A combination whose support contains a kept row's support is not minimal.
                if next
                    .iter()
                    .any(|r| subset(&r.support, &support) && r.support != support)
                {
                    continue;
                }
                meter.spend((p.d.len() + p.y.len()) as u64)?;
                let fp = q.d[j].checked_abs().ok_or(InvariantError::Overflow)?;
                let fq = p.d[j];
                let comb = |x: &[i64], y: &[i64]| -> Result<Vec<i64>, InvariantError> {
                    x.iter()
                        .zip(y)
                        .map(|(&u, &v)| {
                            u.checked_mul(fp)
                                .and_then(|s| v.checked_mul(fq).and_then(|t| s.checked_add(t)))
                                .ok_or(InvariantError::Overflow)
                        })
                        .collect()
                };
                let mut d = comb(&p.d, &q.d)?;
                let mut y = comb(&p.y, &q.y)?;
                let g = d.iter().chain(&y).fold(0, |g, &v| gcd(g, v));
                if g > 1 {
                    d.iter_mut().chain(y.iter_mut()).for_each(|v| *v /= g);
                }
                if next.iter().any(|r| r.support == support && r.y == y) {
                    continue;
                }
                // Drop kept rows that this one makes non-minimal.
                next.retain(|r| !(subset(&support, &r.support) && support != r.support));
                next.push(Row { d, y, support });
                if next.len() > max_rows {
                    return Err(InvariantError::TooManyRows(max_rows));
                }
            }
        }
        rows = next;
    }
    // Final minimality pass (equal supports: keep one) and canonical order.
    let mut out: Vec<Row> = Vec::new();
    for r in rows {
        meter.spend((out.len() as u64 + 1) * w)?;
        if out.iter().any(|o| subset(&o.support, &r.support)) {
            continue;
        }
        out.retain(|o| !subset(&r.support, &o.support));
        out.push(r);
    }
    let mut result: Vec<Vec<i64>> = out.into_iter().map(|r| r.y).collect();
    sort_by_support(&mut result);
    Ok(result)
}

fn sort_by_support(v: &mut [Vec<i64>]) {
    v.sort_by(|a, b| {
        let sa = a.iter().enumerate().filter(|(_, c)| **c != 0).map(|(i, _)| i);
        let sb = b.iter().enumerate().filter(|(_, c)| **c != 0).map(|(i, _)| i);
        sa.cmp(sb).then_with(|| a.cmp(b))
    });
}

/// A sparse row: sorted `(column, coefficient)`, columns `0..cols` for `D`, then
/// `cols + i` for `Y`'s variable `i`.
type Sparse = Vec<(u32, i64)>;

/// `a·x - b·y` of two sparse rows, divided by the gcd of the result.
fn eliminate(x: &Sparse, a: i64, y: &Sparse, b: i64) -> Option<Sparse> {
    let mut out = Vec::with_capacity(x.len() + y.len());
    let (mut i, mut k) = (0, 0);
    while i < x.len() || k < y.len() {
        let (c, v) = match (x.get(i), y.get(k)) {
            (Some(&(cx, vx)), Some(&(cy, _))) if cx < cy => {
                i += 1;
                (cx, vx.checked_mul(a)?)
            }
            (Some(&(cx, vx)), Some(&(cy, vy))) if cx == cy => {
                i += 1;
                k += 1;
                (cx, vx.checked_mul(a)?.checked_sub(vy.checked_mul(b)?)?)
            }
            (_, Some(&(cy, vy))) => {
                k += 1;
                (cy, vy.checked_mul(b)?.checked_neg()?)
            }
            (Some(&(cx, vx)), None) => {
                i += 1;
                (cx, vx.checked_mul(a)?)
            }
            (None, None) => break,
        };
        if v != 0 {
            out.push((c, v));
        }
    }
    let g = out.iter().fold(0, |g, &(_, v)| gcd(g, v));
    if g > 1 {
        out.iter_mut().for_each(|(_, v)| *v /= g);
    }
    Some(out)
}

/// A basis of the rational solutions of `y · A = 0` (`a` one row per variable, `cols`
/// columns): integer vectors of any sign, gcd 1, each with a positive first coefficient.
pub fn kernel_basis(a: &[Vec<i64>], cols: usize, cancel: &AtomicBool) -> Result<Vec<Vec<i64>>, InvariantError> {
    let n = a.len();
    let mut rows: Vec<Sparse> = a
        .iter()
        .enumerate()
        .map(|(i, r)| {
            r.iter()
                .enumerate()
                .filter(|(_, v)| **v != 0)
                .map(|(j, &v)| (j as u32, v))
                .chain(std::iter::once(((cols + i) as u32, 1)))
                .collect()
        })
        .collect();
    for j in 0..cols as u32 {
        if cancel.load(Ordering::Relaxed) {
            return Err(InvariantError::Cancelled);
        }
        // Columns before j are eliminated: a row touches j iff its first entry is j.
        let Some(p) = (0..rows.len())
            .filter(|&r| rows[r][0].0 == j)
            .min_by_key(|&r| rows[r].len())
        else {
            continue;
        };
        let pivot = rows.swap_remove(p);
        let pv = pivot[0].1;
        for r in rows.iter_mut().filter(|r| r[0].0 == j) {
            let rv = r[0].1;
            let g = gcd(pv, rv);
            *r = eliminate(r, pv / g, &pivot, rv / g).ok_or(InvariantError::Overflow)?;
        }
    }
    let mut out: Vec<Vec<i64>> = rows
        .into_iter()
        .map(|r| {
            let mut y = vec![0i64; n];
            for (c, v) in r {
                y[c as usize - cols] = v;
            }
            if y.iter().find(|&&v| v != 0).is_some_and(|&v| v < 0) {
                y.iter_mut().for_each(|v| *v = -*v);
            }
            y
        })
        .collect();
    sort_by_support(&mut out);
    Ok(out)
}

fn transpose(net: &crate::PtNet) -> Vec<Vec<i64>> {
    let c = net.incidence();
    (0..net.transitions.len())
        .map(|t| c.iter().map(|row| row[t]).collect())
        .collect()
}

/// A basis of the P-flows (`y · C = 0`), one coefficient per place.
pub fn p_flows(net: &crate::PtNet, cancel: &AtomicBool) -> Result<Vec<Vec<i64>>, InvariantError> {
    kernel_basis(&net.incidence(), net.transitions.len(), cancel)
}

/// A basis of the T-flows (`C · x = 0`), one coefficient per transition.
pub fn t_flows(net: &crate::PtNet, cancel: &AtomicBool) -> Result<Vec<Vec<i64>>, InvariantError> {
    kernel_basis(&transpose(net), net.places.len(), cancel)
}

/// Minimal semi-positive P-invariants (`y · C = 0`), one coefficient per place.
pub fn p_invariants(net: &crate::PtNet, budget: Budget<'_>) -> Result<Vec<Vec<i64>>, InvariantError> {
    farkas(&net.incidence(), net.transitions.len(), budget)
}

/// Minimal semi-positive T-invariants (`C · x = 0`), one coefficient per transition.
pub fn t_invariants(net: &crate::PtNet, budget: Budget<'_>) -> Result<Vec<Vec<i64>>, InvariantError> {
    farkas(&transpose(net), net.places.len(), budget)
}
