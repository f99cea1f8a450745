//! Alarm KPIs of a time range after EEMUA 191 and ISA-18.2 (the shift
//! report, docs/alarms.md "Shift report"), computed from the alarm log's
//! events: pure, on the caller's range.
//!
//! - An **annunciation** is an alarm becoming active: an event to
//!   `active_unacked` from `normal` or `cleared_unacked`.
//! - **Alarms per 10 minutes** (one operator): annunciations in each
//!   10-minute window from `from`; a **flood** is a window with more than
//!   10, consecutive flood windows are one flood period.
//! - **Top ten**: the alarms annunciated most often (ties by id).
//! - **Standing**: alarms whose last event in the range leaves them active
//!   (`active_unacked`, `active_acked`), with when they became active.
//! - **Chattering**: alarms annunciated 3 times or more within 60 s.
//! - **Priority distribution**: annunciations by severity band against
//!   EEMUA 191's 80 / 15 / 5 %: low (< 500), medium (500 to 749), high
//!   (750 and above, critical included).

use crate::state::{Event, State};
use std::collections::BTreeMap;

/// The window of the alarm rate.
pub const WINDOW_MS: i64 = 10 * 60_000;
/// More annunciations than this in one window is a flood.
pub const FLOOD_ABOVE: u64 = 10;
/// Annunciations of one alarm within [`CHATTER_WINDOW_MS`] that make it chattering.
pub const CHATTER_COUNT: usize = 3;
pub const CHATTER_WINDOW_MS: i64 = 60_000;

/// A flood period: consecutive windows above [`FLOOD_ABOVE`].
#[derive(Debug, Clone, PartialEq)]
pub struct Flood {
    pub start_ms: i64,
    pub end_ms: i64,
    pub alarms: u64,
}

/// An alarm still active at the end of the range.
#[derive(Debug, Clone, PartialEq)]
pub struct Standing {
    pub id: String,
    pub state: State,
    /// When it became active (the range's start if before it).
    pub since_ms: i64,
}

/// A severity band of the priority distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    pub name: &'static str,
    pub count: u64,
    /// Share of the annunciations, in percent (0 when there are none).
    pub percent: f64,
    /// EEMUA 191's target share, in percent.
    pub target: f64,
}

/// The KPIs of `[from_ms, to_ms]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Kpis {
    pub from_ms: i64,
    pub to_ms: i64,
    /// Annunciations in the range.
    pub annunciations: u64,
    /// Each 10-minute window's start and annunciations.
    pub windows: Vec<(i64, u64)>,
    /// Mean and most annunciations per 10 minutes.
    pub mean_per_10min: f64,
    pub max_per_10min: u64,
    pub floods: Vec<Flood>,
    /// Share of the windows in flood, in percent.
    pub flood_percent: f64,
    /// At most ten `(alarm, annunciations)`, most first.
    pub top: Vec<(String, u64)>,
    pub standing: Vec<Standing>,
    /// `(alarm, most annunciations within 60 s)`.
    pub chattering: Vec<(String, u64)>,
    pub priorities: Vec<Band>,
}

fn annunciation(e: &Event) -> bool {
    e.to == State::ActiveUnacked && matches!(e.from, State::Normal | State::ClearedUnacked)
}

/// The KPIs of the events with `from_ms <= t <= to_ms` among `events`
/// (in the order they happened). `to_ms < from_ms` is an empty range.
pub fn kpis(events: &[Event], from_ms: i64, to_ms: i64) -> Kpis {
    let in_range: Vec<&Event> = events.iter().filter(|e| e.t_ms >= from_ms && e.t_ms <= to_ms).collect();
    let ann: Vec<&Event> = in_range.iter().copied().filter(|e| annunciation(e)).collect();
    // Windows.
    let span = (to_ms - from_ms).max(0);
    let n = usize::try_from(span / WINDOW_MS + 1).unwrap_or(1).min(1_000_000);
    let mut counts = vec![0u64; n];
    for e in &ann {
        let k = usize::try_from((e.t_ms - from_ms) / WINDOW_MS).unwrap_or(0).min(n - 1);
        counts[k] += 1;
    }
    let windows: Vec<(i64, u64)> = counts
        .iter()
        .enumerate()
        .map(|(k, &c)| (from_ms + k as i64 * WINDOW_MS, c))
        .collect();
    let mut floods: Vec<Flood> = Vec::new();
    let mut in_flood = 0usize;
    let mut open = false;
    for &(start, c) in &windows {
        if c > FLOOD_ABOVE {
            in_flood += 1;
            let end = (start + WINDOW_MS).min(to_ms);
            match floods.last_mut() {
                Some(f) if open => {
                    f.end_ms = end;
                    f.alarms += c;
                }
                _ => floods.push(Flood {
                    start_ms: start,
                    end_ms: end,
                    alarms: c,
                }),
            }
            open = true;
        } else {
            open = false;
        }
    }
    // Per alarm.
    let mut per: BTreeMap<&str, Vec<i64>> = BTreeMap::new();
    for e in &ann {
        per.entry(e.id.as_str()).or_default().push(e.t_ms);
    }
    let mut top: Vec<(String, u64)> = per.iter().map(|(id, t)| (id.to_string(), t.len() as u64)).collect();
    top.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    top.truncate(10);
    let chattering: Vec<(String, u64)> = per
        .iter()
        .filter_map(|(id, times)| {
            let mut most = 0usize;
            let mut lo = 0usize;
            for hi in 0..times.len() {
                while times[hi] - times[lo] >= CHATTER_WINDOW_MS {
                    lo += 1;
                }
                most = most.max(hi - lo + 1);
            }
            (most >= CHATTER_COUNT).then(|| (id.to_string(), most as u64))
        })
        .collect();
    // Standing: the last event of each alarm in the range.
    let mut last: BTreeMap<&str, (&Event, Option<i64>)> = BTreeMap::new();
    for e in &in_range {
        let since = if annunciation(e) { Some(e.t_ms) } else { None };
        let prev = last.get(e.id.as_str()).and_then(|(_, s)| *s);
        let since = if matches!(e.to, State::ActiveUnacked | State::ActiveAcked) {
            since.or(prev)
        } else {
            None
        };
        last.insert(e.id.as_str(), (e, since));
    }
    let standing: Vec<Standing> = last
        .iter()
        .filter(|(_, (e, _))| matches!(e.to, State::ActiveUnacked | State::ActiveAcked))
        .map(|(id, (e, since))| Standing {
            id: id.to_string(),
            state: e.to,
            since_ms: since.unwrap_or(from_ms),
        })
        .collect();
    // Priorities.
    let total = ann.len() as u64;
    let band = |lo: u32, hi: u32| {
        ann.iter()
            .filter(|e| u32::from(e.severity) >= lo && u32::from(e.severity) < hi)
            .count() as u64
    };
    let pct = |c: u64| {
        if total == 0 {
            0.0
        } else {
            c as f64 * 100.0 / total as f64
        }
    };
    let priorities = [
        ("low", 0, 500, 80.0),
        ("medium", 500, 750, 15.0),
        ("high", 750, u32::MAX, 5.0),
    ]
    .into_iter()
    .map(|(name, lo, hi, target)| {
        let count = band(lo, hi);
        Band {
            name,
            count,
            percent: pct(count),
            target,
        }
    })
    .collect();
    Kpis {
        from_ms,
        to_ms,
        annunciations: total,
        mean_per_10min: total as f64 / n as f64,
        max_per_10min: counts.iter().copied().max().unwrap_or(0),
        flood_percent: in_flood as f64 * 100.0 / n as f64,
        windows,
        floods,
        top,
        standing,
        chattering,
        priorities,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(t_ms: i64, id: &str, from: State, to: State, severity: u16) -> Event {
        Event {
            t_ms,
            id: id.into(),
            tag: "T".into(),
            from,
            to,
            value: 0.0,
            user: None,
            comment: None,
            severity,
            message: String::new(),
        }
    }

    #[test]
    fn a_known_history_gives_its_kpis() {
        use State::*;
        let mut e = Vec::new();
        // 12 annunciations of A (severity 250) in the first window: a flood, chattering.
        for k in 0..12 {
            e.push(ev(k * 5_000, "A", Normal, ActiveUnacked, 250));
            e.push(ev(k * 5_000 + 1_000, "A", ActiveUnacked, ClearedUnacked, 250));
        }
        // B (600) twice, 5 min apart, in the second window; C (800) once, left active.
        e.push(ev(700_000, "B", Normal, ActiveUnacked, 600));
        e.push(ev(701_000, "B", ActiveUnacked, ActiveAcked, 600));
        e.push(ev(702_000, "B", ActiveAcked, Normal, 600));
        e.push(ev(1_000_000, "B", Normal, ActiveUnacked, 600));
        e.push(ev(1_300_000, "C", Normal, ActiveUnacked, u16::MAX));
        // Outside the range.
        e.push(ev(5_000_000, "D", Normal, ActiveUnacked, 100));
        let k = kpis(&e, 0, 1_800_000);
        assert_eq!(k.annunciations, 15);
        assert_eq!(k.windows, vec![(0, 12), (600_000, 2), (1_200_000, 1), (1_800_000, 0)]);
        assert_eq!(k.max_per_10min, 12);
        assert!((k.mean_per_10min - 3.75).abs() < 1e-9);
        assert_eq!(
            k.floods,
            vec![Flood {
                start_ms: 0,
                end_ms: 600_000,
                alarms: 12
            }]
        );
        assert!((k.flood_percent - 25.0).abs() < 1e-9);
        assert_eq!(k.top, vec![("A".into(), 12), ("B".into(), 2), ("C".into(), 1)]);
        assert_eq!(k.chattering, vec![("A".into(), 12)]);
        assert_eq!(
            k.standing,
            vec![
                Standing {
                    id: "B".into(),
                    state: ActiveUnacked,
                    since_ms: 1_000_000
                },
                Standing {
                    id: "C".into(),
                    state: ActiveUnacked,
                    since_ms: 1_300_000
                },
            ]
        );
        let counts: Vec<u64> = k.priorities.iter().map(|b| b.count).collect();
        assert_eq!(counts, vec![12, 2, 1]);
        assert!((k.priorities[0].percent - 80.0).abs() < 1e-9);
    }

    #[test]
    fn an_empty_range_has_one_empty_window() {
        let k = kpis(&[], 100, 50);
        assert_eq!(k.annunciations, 0);
        assert_eq!(k.windows, vec![(100, 0)]);
        assert!(k.priorities.iter().all(|b| b.percent == 0.0));
    }
}
