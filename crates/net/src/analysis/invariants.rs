//! Minimal semi-positive P- and T-invariants by the Farkas algorithm (Martínez–Silva).
//!
//! Rows are `[D | Y]` with `D` starting as the incidence matrix (or its transpose) and
//! `Y` as the identity. Column by column, every pair of rows with opposite signs in
//! `D` is combined with positive factors (`|b|·r1 + |a|·r2`), divided by the gcd, and the
//! rows with a non-zero entry are dropped. `D` entries may be negative in between — only
//! `Y` must stay non-negative — so invariants that need negative intermediate
//! coefficients are kept (PIPE's variant loses some of them). After every column, rows
//! whose support contains another row's support are dropped (minimality), so the result
//! is exactly the set of minimal-support semi-positive invariants, each with gcd 1.

/// Why the invariants could not be computed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InvariantError {
    /// An intermediate coefficient did not fit in 64 bits.
    Overflow,
    /// The intermediate matrix grew beyond the row limit.
    TooManyRows(usize),
}

impl std::fmt::Display for InvariantError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InvariantError::Overflow => write!(f, "an intermediate coefficient overflowed 64 bits"),
            InvariantError::TooManyRows(n) => write!(f, "more than {n} intermediate rows"),
        }
    }
}

/// Default bound on the number of intermediate rows.
pub const MAX_ROWS: usize = 200_000;

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
/// row per variable. Each result is a vector of coefficients (gcd 1), sorted.
pub fn farkas(a: &[Vec<i64>], cols: usize, max_rows: usize) -> Result<Vec<Vec<i64>>, InvariantError> {
    let n = a.len();
    let words = n.div_ceil(64).max(1);
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
    for j in 0..cols {
        let (zero, nonzero): (Vec<Row>, Vec<Row>) = rows.into_iter().partition(|r| r.d[j] == 0);
        let (pos, neg): (Vec<&Row>, Vec<&Row>) = nonzero.iter().partition(|r| r.d[j] > 0);
        let mut next = zero;
        for p in &pos {
            for q in &neg {
                let support: Vec<u64> = p.support.iter().zip(&q.support).map(|(x, y)| x | y).collect();
                // A combination whose support contains a kept row's support is not minimal.
                if next
                    .iter()
                    .any(|r| subset(&r.support, &support) && r.support != support)
                {
                    continue;
                }
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
        if out.iter().any(|o| subset(&o.support, &r.support)) {
            continue;
        }
        out.retain(|o| !subset(&r.support, &o.support));
        out.push(r);
    }
    let mut result: Vec<Vec<i64>> = out.into_iter().map(|r| r.y).collect();
    result.sort_by(|a, b| {
        let sa: Vec<usize> = (0..a.len()).filter(|&i| a[i] != 0).collect();
        let sb: Vec<usize> = (0..b.len()).filter(|&i| b[i] != 0).collect();
        sa.cmp(&sb).then_with(|| a.cmp(b))
    });
    Ok(result)
}

/// Minimal semi-positive P-invariants (`y · C = 0`), one coefficient per place.
pub fn p_invariants(net: &crate::PtNet, max_rows: usize) -> Result<Vec<Vec<i64>>, InvariantError> {
    farkas(&net.incidence(), net.transitions.len(), max_rows)
}

/// Minimal semi-positive T-invariants (`C · x = 0`), one coefficient per transition.
pub fn t_invariants(net: &crate::PtNet, max_rows: usize) -> Result<Vec<Vec<i64>>, InvariantError> {
    let c = net.incidence();
    let transposed: Vec<Vec<i64>> = (0..net.transitions.len())
        .map(|t| c.iter().map(|row| row[t]).collect())
        .collect();
    farkas(&transposed, net.places.len(), max_rows)
}
