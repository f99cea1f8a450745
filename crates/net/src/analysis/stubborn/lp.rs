//! A small exact feasibility test for linear programs, for the implicit-place rule of
//! [`super::reduce`]: is there a `y ≥ 0` with `A y ≤ c`? Phase one of the simplex
//! method on a dense tableau of rationals (`i128` numerator and denominator, reduced),
//! Bland's rule (so it never cycles), a budget of tableau-cell updates shared by all the
//! calls of one reduction, and `None` on any overflow: the answer is then "not proven".
//! A solution is returned as integers `Y = D·y` with their common denominator `D`, for
//! the caller to check exactly (it never trusts this module alone).

/// A rational `n / d`, `d > 0`, `gcd(n, d) = 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rat {
    n: i128,
    d: i128,
}

fn gcd(mut a: i128, mut b: i128) -> i128 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Rat {
    const ZERO: Rat = Rat { n: 0, d: 1 };

    fn int(n: i64) -> Rat {
        Rat { n: n.into(), d: 1 }
    }

    fn new(n: i128, d: i128) -> Option<Rat> {
        if d == 0 {
            return None;
        }
        let g = gcd(n, d);
        let s = if d < 0 { -1 } else { 1 };
        Some(Rat {
            n: s * (n / g),
            d: s * (d / g),
        })
    }

    fn sub(self, o: Rat) -> Option<Rat> {
        let g = gcd(self.d, o.d);
        let n = self.n.checked_mul(o.d / g)?.checked_sub(o.n.checked_mul(self.d / g)?)?;
        Rat::new(n, (self.d / g).checked_mul(o.d)?)
    }

    fn mul(self, o: Rat) -> Option<Rat> {
        let (g1, g2) = (gcd(self.n, o.d).max(1), gcd(o.n, self.d).max(1));
        Rat::new(
            (self.n / g1).checked_mul(o.n / g2)?,
            (self.d / g2).checked_mul(o.d / g1)?,
        )
    }

    fn div(self, o: Rat) -> Option<Rat> {
        if o.n == 0 {
            return None;
        }
        self.mul(Rat::new(o.d, o.n)?)
    }

    fn less(self, o: Rat) -> Option<bool> {
        Some(self.n.checked_mul(o.d)? < o.n.checked_mul(self.d)?)
    }
}

/// Whether some `y ≥ 0` (one per column of `a`) has `a[i]·y ≤ c[i]` for every row `i`:
/// `Some((Y, D))` with `y = Y / D`, `D > 0`, every `Y[j] ≥ 0`; `None` when there is
/// none, or when the budget (tableau-cell updates, decreased by what this call used) ran
/// out, or a number outgrew `i128`.
pub fn feasible(a: &[Vec<i64>], c: &[i64], budget: &mut u64) -> Option<(Vec<i128>, i128)> {
    let (m, n) = (a.len(), a.first().map_or(0, Vec::len));
    if a.iter().any(|r| r.len() != n) || c.len() != m {
        return None;
    }
    let artificial: Vec<usize> = (0..m).filter(|&i| c[i] < 0).collect();
    // Columns: y (n), slacks (m), artificials, right-hand side.
    let cols = n + m + artificial.len() + 1;
    let rhs = cols - 1;
    let mut t = vec![vec![Rat::ZERO; cols]; m + 1];
    let mut basis = vec![0usize; m];
    for i in 0..m {
        let s = if c[i] < 0 { -1 } else { 1 };
        for j in 0..n {
            t[i][j] = Rat::int(s * a[i][j]);
        }
        t[i][n + i] = Rat::int(s);
        t[i][rhs] = Rat::int(s * c[i]);
        basis[i] = n + i;
    }
    for (k, &i) in artificial.iter().enumerate() {
        t[i][n + m + k] = Rat::int(1);
        basis[i] = n + m + k;
        // Objective row: minus the sum of the artificial rows (reduced costs).
        let row = t[i].clone();
        for j in (0..n + m).chain([rhs]) {
            t[m][j] = t[m][j].sub(row[j])?;
        }
    }
    // Entering: the first column with a negative reduced cost (Bland).
    while let Some(e) = (0..rhs).find(|&j| t[m][j].n < 0) {
        // Leaving: the least ratio, ties to the least basic variable (Bland).
        let mut leave: Option<(usize, Rat)> = None;
        for i in 0..m {
            if t[i][e].n > 0 {
                let r = t[i][rhs].div(t[i][e])?;
                let better = match leave {
                    None => true,
                    Some((l, best)) => r.less(best)? || (r == best && basis[i] < basis[l]),
                };
                if better {
                    leave = Some((i, r));
                }
            }
        }
        // Unbounded below cannot happen (the objective is at least 0).
        let (l, _) = leave?;
        *budget = budget.checked_sub((cols * (m + 1)) as u64)?;
        let p = t[l][e];
        for x in t[l].iter_mut() {
            *x = x.div(p)?;
        }
        let pivot = t[l].clone();
        for (i, row) in t.iter_mut().enumerate() {
            let f = row[e];
            if i == l || f.n == 0 {
                continue;
            }
            for (x, &v) in row.iter_mut().zip(&pivot) {
                if v.n != 0 {
                    *x = x.sub(f.mul(v)?)?;
                }
            }
        }
        basis[l] = e;
    }
    if t[m][rhs].n != 0 {
        return None;
    }
    let mut y = vec![Rat::ZERO; n];
    for i in 0..m {
        if basis[i] < n {
            y[basis[i]] = t[i][rhs];
        }
    }
    let mut d: i128 = 1;
    for v in &y {
        d = (d / gcd(d, v.d)).checked_mul(v.d)?;
    }
    let ys = y
        .iter()
        .map(|v| v.n.checked_mul(d / v.d))
        .collect::<Option<Vec<i128>>>()?;
    ys.iter().all(|&v| v >= 0).then_some((ys, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(a: &[Vec<i64>], c: &[i64], (y, d): &(Vec<i128>, i128)) {
        assert!(*d > 0);
        for (row, &ci) in a.iter().zip(c) {
            let lhs: i128 = row.iter().zip(y).map(|(&x, &v)| i128::from(x) * v).sum();
            assert!(lhs <= i128::from(ci) * d, "{row:?} · {y:?} / {d} > {ci}");
        }
        assert!(y.iter().all(|&v| v >= 0));
    }

    #[test]
    fn finds_a_fractional_solution_and_refuses_an_empty_polytope() {
        // 2 y0 >= 1, 2 y0 <= 1, y1 - y0 >= 1/2 ... written as rows of a·y <= c:
        let a = vec![vec![-2, 0], vec![2, 0], vec![2, -2]];
        let c = vec![-1, 1, -1];
        let mut budget = 10_000;
        let got = feasible(&a, &c, &mut budget).expect("feasible");
        check(&a, &c, &got);
        assert_eq!(got.1 % 2, 0, "y0 = 1/2: {got:?}");
        assert!(budget < 10_000);
        // y0 >= 1 and y0 <= 1/2: none.
        let a = vec![vec![-1], vec![2]];
        assert!(feasible(&a, &[-1, 1], &mut 10_000).is_none());
        // Negative y is not allowed: y0 <= -1 has none.
        assert!(feasible(&[vec![1]], &[-1], &mut 10_000).is_none());
        // No rows: y = 0.
        assert_eq!(feasible(&[], &[], &mut 10), Some((vec![], 1)));
    }

    #[test]
    fn a_spent_budget_answers_none() {
        let a = vec![vec![-2, 0], vec![2, 0], vec![2, -2]];
        let c = vec![-1, 1, -1];
        assert!(feasible(&a, &c, &mut 5).is_none());
        let mut budget = 0;
        // Feasible at the start (c >= 0): no pivot needed.
        assert!(feasible(&a, &[1, 1, 1], &mut budget).is_some());
    }

    #[test]
    fn random_systems_agree_with_brute_force_on_small_integer_points() {
        // A solution found is checked exactly; a system with a small integer solution
        // (found by enumeration) is never declared infeasible.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |k: i64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % (2 * k as u64 + 1)) as i64 - k
        };
        for _ in 0..400 {
            let (m, n) = (
                1 + next(2).unsigned_abs() as usize * 2,
                1 + next(1).unsigned_abs() as usize * 2,
            );
            let a: Vec<Vec<i64>> = (0..m).map(|_| (0..n).map(|_| next(3)).collect()).collect();
            let c: Vec<i64> = (0..m).map(|_| next(4)).collect();
            let got = feasible(&a, &c, &mut 1_000_000);
            if let Some(s) = &got {
                check(&a, &c, s);
            }
            let points =
                (0..4i64.pow(n as u32)).map(|k| (0..n).map(|j| (k / 4i64.pow(j as u32)) % 4).collect::<Vec<_>>());
            let integer = points.into_iter().any(|y| {
                a.iter()
                    .zip(&c)
                    .all(|(r, &ci)| r.iter().zip(&y).map(|(x, v)| x * v).sum::<i64>() <= ci)
            });
            if integer {
                assert!(got.is_some(), "{a:?} {c:?}");
            }
        }
    }
}
