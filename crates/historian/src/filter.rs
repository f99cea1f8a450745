//! Deciding which values to store: on change beyond a deadband, and periodically.

use std::collections::HashMap;

use crate::Historian;
use crate::error::Result;

/// When a new value of a tag is worth storing.
///
/// A value is stored when the tag has no stored value yet (since the filter was made or
/// the tag forgotten), when it differs from the last *stored* value by more than
/// `deadband` (so a slow drift is recorded once it adds up), when `period_ms` is not 0
/// and at least `period_ms` have passed since the last stored value, or when time went
/// backwards. `deadband: 0.0` stores every change, a negative deadband every value. NaN is
/// never stored (the historian has no representation for it: it reads as a gap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filter {
    /// The change, in the tag's unit, that a value must exceed to be stored.
    pub deadband: f64,
    /// Store at least this often while the value stays within the deadband (0: never).
    pub period_ms: u64,
}

impl Filter {
    /// Every value is stored.
    pub const EVERY: Filter = Filter {
        deadband: -1.0,
        period_ms: 0,
    };
    /// Every change is stored, and an unchanged value once a minute.
    pub const ON_CHANGE: Filter = Filter {
        deadband: 0.0,
        period_ms: 60_000,
    };

    /// Whether value `v` at `t` is to be stored after `last` (time, value) was stored.
    pub fn admits(&self, last: Option<(i64, f64)>, t: i64, v: f64) -> bool {
        if v.is_nan() {
            return false;
        }
        let Some((last_t, last_v)) = last else {
            return true;
        };
        if t < last_t {
            return true;
        }
        if self.period_ms > 0 && t.abs_diff(last_t) >= self.period_ms {
            return true;
        }
        if v == last_v {
            return self.deadband < 0.0;
        }
        // Infinities of opposite signs give an infinite difference; the same infinity was
        // caught as equal above.
        (v - last_v).abs() > self.deadband
    }
}

impl Default for Filter {
    fn default() -> Self {
        Filter::ON_CHANGE
    }
}

/// The state of the on-change/deadband/periodic filter over many tags: a default
/// [`Filter`], per-tag overrides and the last stored value of each tag.
#[derive(Clone, Debug, Default)]
pub struct ChangeFilter {
    default: Filter,
    overrides: HashMap<String, Filter>,
    last: HashMap<String, (i64, f64)>,
}

impl ChangeFilter {
    /// A filter applying `default` to every tag without an override.
    pub fn new(default: Filter) -> Self {
        ChangeFilter {
            default,
            overrides: HashMap::new(),
            last: HashMap::new(),
        }
    }

    /// Uses `filter` for `tag` instead of the default.
    pub fn set_filter(&mut self, tag: &str, filter: Filter) {
        self.overrides.insert(tag.to_owned(), filter);
    }

    /// The filter that applies to `tag`.
    pub fn filter_for(&self, tag: &str) -> Filter {
        self.overrides.get(tag).copied().unwrap_or(self.default)
    }

    /// Whether `v` at `t` is to be stored for `tag`, without remembering it.
    pub fn check(&self, tag: &str, t: i64, v: f64) -> bool {
        self.filter_for(tag).admits(self.last.get(tag).copied(), t, v)
    }

    /// Remembers that `v` at `t` was stored for `tag`.
    pub fn mark_stored(&mut self, tag: &str, t: i64, v: f64) {
        match self.last.get_mut(tag) {
            Some(last) => *last = (t, v),
            None => {
                self.last.insert(tag.to_owned(), (t, v));
            }
        }
    }

    /// [`check`](Self::check), and [`mark_stored`](Self::mark_stored) when it says yes.
    pub fn admit(&mut self, tag: &str, t: i64, v: f64) -> bool {
        let yes = self.check(tag, t, v);
        if yes {
            self.mark_stored(tag, t, v);
        }
        yes
    }

    /// Forgets the last stored value of `tag`: its next value is stored.
    pub fn forget(&mut self, tag: &str) {
        self.last.remove(tag);
    }

    /// Forgets every last stored value.
    pub fn reset(&mut self) {
        self.last.clear();
    }
}

/// Records values through a [`ChangeFilter`]: what the recording task of a server holds.
///
/// By default every [`record`](Self::record) call is one transaction. With
/// [`set_max_delay`](Self::set_max_delay) the admitted values are buffered and written in
/// one transaction once the oldest is that old (in record time) or [`MAX_BUFFERED`]
/// values wait: fewer, larger transactions write several times faster (each transaction
/// rewrites the database pages of every tag it touches), at the price of queries seeing
/// the values that much later. The buffer is written on [`flush`](Self::flush) and when
/// the recorder is dropped.
#[derive(Debug)]
pub struct Recorder {
    historian: Historian,
    filter: ChangeFilter,
    max_delay_ms: u64,
    /// Tag names met, indexed by `buffer` entries.
    names: Vec<String>,
    index: HashMap<String, usize>,
    buffer: Vec<(usize, i64, f64)>,
}

/// The most values a [`Recorder`] buffers before writing.
pub const MAX_BUFFERED: usize = 100_000;

impl Recorder {
    /// A recorder writing to `historian` what `filter` admits, one transaction per call.
    pub fn new(historian: Historian, filter: ChangeFilter) -> Self {
        Recorder {
            historian,
            filter,
            max_delay_ms: 0,
            names: Vec::new(),
            index: HashMap::new(),
            buffer: Vec::new(),
        }
    }

    /// Buffers admitted values for up to `ms` of record time before writing them (0:
    /// write on every call).
    pub fn set_max_delay(&mut self, ms: u64) {
        self.max_delay_ms = ms;
    }

    /// Passes `values` (tag name, value) at `t_ms` through the filter and stores those it
    /// admits: now in one transaction, or buffered (see
    /// [`set_max_delay`](Self::set_max_delay)). Returns how many were admitted. If
    /// writing fails, the buffered values are dropped and the filter forgets every tag, so
    /// that the next values are admitted again.
    pub fn record(&mut self, t_ms: i64, values: &[(&str, f64)]) -> Result<usize> {
        let mut admitted = 0;
        for &(name, v) in values {
            if !self.filter.admit(name, t_ms, v) {
                continue;
            }
            let i = match self.index.get(name) {
                Some(&i) => i,
                None => {
                    self.names.push(name.to_owned());
                    self.index.insert(name.to_owned(), self.names.len() - 1);
                    self.names.len() - 1
                }
            };
            self.buffer.push((i, t_ms, v));
            admitted += 1;
        }
        let oldest = self.buffer.first().map_or(t_ms, |b| b.1);
        if !self.buffer.is_empty() && (t_ms.abs_diff(oldest) >= self.max_delay_ms || self.buffer.len() >= MAX_BUFFERED)
        {
            self.flush()?;
        }
        Ok(admitted)
    }

    /// Writes the buffered values in one transaction. Returns how many were stored.
    pub fn flush(&mut self) -> Result<usize> {
        if self.buffer.is_empty() {
            return Ok(0);
        }
        let names = &self.names;
        let out = self
            .historian
            .write(self.buffer.iter().map(|&(i, t, v)| (names[i].as_str(), t, v)));
        self.buffer.clear();
        if out.is_err() {
            self.filter.reset();
        }
        out
    }

    /// The number of values waiting to be written.
    pub fn buffered(&self) -> usize {
        self.buffer.len()
    }

    /// The filter, to change per-tag settings or forget tags.
    pub fn filter_mut(&mut self) -> &mut ChangeFilter {
        &mut self.filter
    }

    /// The historian written to.
    pub fn historian(&self) -> &Historian {
        &self.historian
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        // Best effort; a caller that cares calls `flush` and sees the error.
        let _ = self.flush();
    }
}
