//! Aggregates of a run of samples: the content of a rollup row and of a query bucket.

/// Min, max, first and last value (with their times) and count of a set of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Agg {
    pub min: f64,
    pub max: f64,
    pub first_t: i64,
    pub first: f64,
    pub last_t: i64,
    pub last: f64,
    pub n: u64,
}

impl Agg {
    /// The aggregate of one sample.
    pub fn one(t: i64, v: f64) -> Self {
        Agg {
            min: v,
            max: v,
            first_t: t,
            first: v,
            last_t: t,
            last: v,
            n: 1,
        }
    }

    /// Adds the samples of `o` (in any time order relative to `self`).
    pub fn merge(&mut self, o: &Agg) {
        if o.min < self.min {
            self.min = o.min;
        }
        if o.max > self.max {
            self.max = o.max;
        }
        if o.first_t < self.first_t {
            self.first_t = o.first_t;
            self.first = o.first;
        }
        if o.last_t > self.last_t {
            self.last_t = o.last_t;
            self.last = o.last;
        }
        self.n += o.n;
    }
}

/// `floor(t / w) * w` for any sign of `t` (`w > 0`).
pub(crate) fn floor_to(t: i64, w: i64) -> i64 {
    t.div_euclid(w) * w
}

/// `ceil(t / w) * w` for any sign of `t` (`w > 0`).
pub(crate) fn ceil_to(t: i64, w: i64) -> i64 {
    let f = floor_to(t, w);
    if f == t { f } else { f + w }
}

/// `ceil(a / b)` for `a >= 0`, `b > 0`.
pub(crate) fn ceil_div(a: i64, b: i64) -> i64 {
    a / b + i64::from(a % b != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_handles_negative_times() {
        assert_eq!(floor_to(-1, 1000), -1000);
        assert_eq!(floor_to(-1000, 1000), -1000);
        assert_eq!(floor_to(999, 1000), 0);
        assert_eq!(ceil_to(-999, 1000), 0);
        assert_eq!(ceil_to(-1000, 1000), -1000);
        assert_eq!(ceil_to(1, 1000), 1000);
        assert_eq!(ceil_div(0, 7), 0);
        assert_eq!(ceil_div(7, 7), 1);
        assert_eq!(ceil_div(8, 7), 2);
    }

    #[test]
    fn merge_keeps_first_and_last_by_time() {
        let mut a = Agg::one(10, 5.0);
        a.merge(&Agg::one(5, 7.0));
        a.merge(&Agg::one(20, -1.0));
        assert_eq!(
            a,
            Agg {
                min: -1.0,
                max: 7.0,
                first_t: 5,
                first: 7.0,
                last_t: 20,
                last: -1.0,
                n: 3
            }
        );
    }
}
