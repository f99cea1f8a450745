//! The ISA-18.2 alarm state machine, evaluated on caller-supplied time
//! (docs/alarms.md "States"). No I/O: the caller reads the values, passes the
//! time, and logs the [`Event`]s each call returns.

use crate::def::{AlarmDef, Cmp, Condition};
use alba_ir::Memory;
use alba_model::Value;
use std::fmt;

/// Longest shelving: 7 days.
pub const MAX_SHELVE_MINUTES: u32 = 7 * 24 * 60;
/// Longest comment or reason kept.
pub const MAX_TEXT: usize = 500;

/// Where an alarm is in ISA-18.2's state model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum State {
    Normal,
    ActiveUnacked,
    ActiveAcked,
    ClearedUnacked,
    Shelved,
    Suppressed,
    OutOfService,
}

impl State {
    /// The stable name (API, log): `normal`, `active_unacked`, …
    pub fn name(self) -> &'static str {
        match self {
            State::Normal => "normal",
            State::ActiveUnacked => "active_unacked",
            State::ActiveAcked => "active_acked",
            State::ClearedUnacked => "cleared_unacked",
            State::Shelved => "shelved",
            State::Suppressed => "suppressed",
            State::OutOfService => "out_of_service",
        }
    }

    /// Waiting for an operator's acknowledgement.
    pub fn unacked(self) -> bool {
        matches!(self, State::ActiveUnacked | State::ClearedUnacked)
    }
}

impl std::str::FromStr for State {
    type Err = String;
    fn from_str(s: &str) -> Result<State, String> {
        [
            State::Normal,
            State::ActiveUnacked,
            State::ActiveAcked,
            State::ClearedUnacked,
            State::Shelved,
            State::Suppressed,
            State::OutOfService,
        ]
        .into_iter()
        .find(|st| st.name() == s)
        .ok_or_else(|| format!("no alarm state `{s}`"))
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A value as the log and the CSV exports write it: the shortest form that
/// reads back (a REAL's 59.824047, not the f64 widening 59.82404708862305).
pub fn format_value(v: f64) -> String {
    let narrow = v as f32;
    if f64::from(narrow) == v {
        narrow.to_string()
    } else {
        v.to_string()
    }
}

/// A change of state, for the log and the WebSocket.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub t_ms: i64,
    pub id: String,
    pub tag: String,
    pub from: State,
    pub to: State,
    /// The tag's value when it happened.
    pub value: f64,
    /// Who did it (acknowledge, shelve, out of service); `None` for the process.
    pub user: Option<String>,
    pub comment: Option<String>,
    pub severity: u16,
    pub message: String,
}

/// Why an operator action was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ActionError {
    #[error("no alarm `{0}`")]
    Unknown(String),
    #[error(
        "alarm `{id}` is {state}: only an unacknowledged alarm (active_unacked, cleared_unacked) can be acknowledged"
    )]
    NotUnacked { id: String, state: State },
    #[error("alarm `{0}` is out of service: put it back in service first")]
    OutOfService(String),
    #[error("{0}")]
    Invalid(String),
}

/// One alarm's live state.
#[derive(Debug, Clone, PartialEq)]
pub struct Alarm {
    pub def: AlarmDef,
    pub state: State,
    /// When it entered `state` (caller's time, ms).
    pub since_ms: i64,
    /// The condition holds (after on-delay and deadband): the process is in alarm.
    pub active: bool,
    pub value: f64,
    /// The last acknowledgement: user, comment, time.
    pub acked: Option<(String, String, i64)>,
    /// Shelved until (ms), by whom, why.
    pub shelved: Option<(i64, String, String)>,
    pub out_of_service: Option<(String, String)>,
    /// The raw condition has held since (for the on-delay).
    pending_since: Option<i64>,
    /// The previous value (edges).
    prev: Option<f64>,
    suppressed: bool,
}

/// What of an alarm outlives `alba run` (docs/alarms.md, "Restarts"): kept
/// in the alarm log's `states` table with every change, read back at start.
#[derive(Debug, Clone, PartialEq)]
pub struct Persisted {
    pub id: String,
    pub state: State,
    pub since_ms: i64,
    pub active: bool,
    pub value: f64,
    pub acked: Option<(String, String, i64)>,
    pub shelved: Option<(i64, String, String)>,
    pub out_of_service: Option<(String, String)>,
}

/// Every alarm of a project.
#[derive(Debug, Clone, Default)]
pub struct Alarms {
    alarms: Vec<Alarm>,
}

fn bounded(s: &str) -> String {
    let s = s.trim();
    if s.len() <= MAX_TEXT {
        return s.to_string();
    }
    let mut end = MAX_TEXT;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    s[..end].to_string()
}

impl Alarms {
    pub fn new(defs: Vec<AlarmDef>) -> Alarms {
        Alarms {
            alarms: defs
                .into_iter()
                .map(|def| Alarm {
                    def,
                    state: State::Normal,
                    since_ms: 0,
                    active: false,
                    value: 0.0,
                    acked: None,
                    shelved: None,
                    out_of_service: None,
                    pending_since: None,
                    prev: None,
                    suppressed: false,
                })
                .collect(),
        }
    }

    /// Every alarm, in the order of alarms.csv.
    pub fn all(&self) -> &[Alarm] {
        &self.alarms
    }

    /// The alarms not in `normal`, most severe first, then oldest first.
    pub fn not_normal(&self) -> Vec<&Alarm> {
        let mut v: Vec<&Alarm> = self.alarms.iter().filter(|a| a.state != State::Normal).collect();
        v.sort_by(|a, b| b.def.severity.cmp(&a.def.severity).then(a.since_ms.cmp(&b.since_ms)));
        v
    }

    pub(crate) fn all_mut(&mut self) -> &mut [Alarm] {
        &mut self.alarms
    }

    pub fn get(&self, id: &str) -> Option<&Alarm> {
        self.alarms.iter().find(|a| a.def.id.eq_ignore_ascii_case(id))
    }

    fn find(&mut self, id: &str) -> Result<&mut Alarm, ActionError> {
        self.alarms
            .iter_mut()
            .find(|a| a.def.id.eq_ignore_ascii_case(id))
            .ok_or_else(|| ActionError::Unknown(id.to_string()))
    }

    /// What to keep of the alarms named by `events` (each once).
    pub fn persisted_for(&self, events: &[Event]) -> Vec<Persisted> {
        let mut out: Vec<Persisted> = Vec::new();
        for e in events {
            if !out.iter().any(|p| p.id == e.id)
                && let Some(a) = self.get(&e.id)
            {
                out.push(a.persisted());
            }
        }
        out
    }

    /// Puts back the states kept before a restart, by alarm id (ids no
    /// longer in alarms.csv are ignored); returns how many were restored.
    /// An alarm that was active is taken as still active, its on-delay
    /// already served, so the first evaluation clears it (→
    /// `cleared_unacked` or `normal`) only when its condition no longer
    /// holds: an unacknowledged alarm stays until someone acknowledges it.
    pub fn restore(&mut self, saved: &[Persisted]) -> usize {
        let mut n = 0;
        for p in saved {
            let Ok(a) = self.find(&p.id) else { continue };
            a.state = p.state;
            a.since_ms = p.since_ms;
            a.active = p.active;
            a.value = p.value;
            a.acked = p.acked.clone();
            a.shelved = p.shelved.clone();
            a.out_of_service = p.out_of_service.clone();
            a.pending_since = p.active.then_some(i64::MIN);
            a.suppressed = p.state == State::Suppressed;
            n += 1;
        }
        n
    }

    /// Evaluates every alarm on `mem` at `now_ms` (a published snapshot and
    /// the engine's time); returns the changes of state.
    pub fn update(&mut self, now_ms: i64, mem: &Memory) -> Vec<Event> {
        let mut events = Vec::new();
        for a in &mut self.alarms {
            let value = mem.read(a.def.place).as_f64();
            let suppressed = a
                .def
                .suppressed_by
                .as_ref()
                .is_some_and(|(_, p)| mem.read(*p) == Value::Bool(true));
            a.step(now_ms, value, suppressed, &mut events);
        }
        events
    }

    /// Acknowledges `id` for `user`.
    pub fn ack(&mut self, id: &str, user: &str, comment: &str, now_ms: i64) -> Result<Event, ActionError> {
        let a = self.find(id)?;
        let to = match a.state {
            State::ActiveUnacked => State::ActiveAcked,
            State::ClearedUnacked => State::Normal,
            state => {
                return Err(ActionError::NotUnacked {
                    id: a.def.id.clone(),
                    state,
                });
            }
        };
        let comment = bounded(comment);
        a.acked = Some((user.to_string(), comment.clone(), now_ms));
        Ok(a.go(to, now_ms, Some(user), Some(comment)))
    }

    /// Shelves `id` for `minutes` (1 to 7 days): it is not annunciated until
    /// then, whatever its condition; a reason is required.
    pub fn shelve(
        &mut self,
        id: &str,
        minutes: u32,
        reason: &str,
        user: &str,
        now_ms: i64,
    ) -> Result<Event, ActionError> {
        let a = self.find(id)?;
        if a.out_of_service.is_some() {
            return Err(ActionError::OutOfService(a.def.id.clone()));
        }
        if !(1..=MAX_SHELVE_MINUTES).contains(&minutes) {
            return Err(ActionError::Invalid(format!(
                "shelve for 1 to {MAX_SHELVE_MINUTES} minutes, not {minutes}"
            )));
        }
        let reason = bounded(reason);
        if reason.is_empty() {
            return Err(ActionError::Invalid("shelving needs a reason".into()));
        }
        a.shelved = Some((now_ms + i64::from(minutes) * 60_000, user.to_string(), reason.clone()));
        Ok(a.go(State::Shelved, now_ms, Some(user), Some(reason)))
    }

    /// Ends a shelving early.
    pub fn unshelve(&mut self, id: &str, user: &str, now_ms: i64) -> Result<Event, ActionError> {
        let a = self.find(id)?;
        if a.shelved.take().is_none() {
            return Err(ActionError::Invalid(format!("alarm `{}` is not shelved", a.def.id)));
        }
        let to = a.resumed();
        Ok(a.go(to, now_ms, Some(user), None))
    }

    /// Takes `id` out of service (maintenance) or puts it back.
    pub fn set_out_of_service(
        &mut self,
        id: &str,
        on: bool,
        reason: &str,
        user: &str,
        now_ms: i64,
    ) -> Result<Event, ActionError> {
        let a = self.find(id)?;
        if on {
            let reason = bounded(reason);
            if reason.is_empty() {
                return Err(ActionError::Invalid(
                    "taking an alarm out of service needs a reason".into(),
                ));
            }
            a.shelved = None;
            a.out_of_service = Some((user.to_string(), reason.clone()));
            Ok(a.go(State::OutOfService, now_ms, Some(user), Some(reason)))
        } else {
            if a.out_of_service.take().is_none() {
                return Err(ActionError::Invalid(format!("alarm `{}` is in service", a.def.id)));
            }
            let to = a.resumed();
            Ok(a.go(to, now_ms, Some(user), None))
        }
    }
}

impl Alarm {
    pub fn persisted(&self) -> Persisted {
        Persisted {
            id: self.def.id.clone(),
            state: self.state,
            since_ms: self.since_ms,
            active: self.active,
            value: self.value,
            acked: self.acked.clone(),
            shelved: self.shelved.clone(),
            out_of_service: self.out_of_service.clone(),
        }
    }

    /// The raw condition on `v` (the deadband keeps an active alarm active
    /// until the value is back past the limit by the deadband).
    fn raw(&self, v: f64) -> bool {
        let db = self.def.deadband;
        let on = v != 0.0;
        match self.def.condition {
            Condition::On => on,
            Condition::Off => !on,
            Condition::Rising => on && self.prev.is_some_and(|p| p == 0.0),
            Condition::Falling => !on && self.prev.is_some_and(|p| p != 0.0),
            Condition::Compare(c, x) => {
                let hold = if self.active { db } else { 0.0 };
                match c {
                    Cmp::Gt => v > x - hold,
                    Cmp::Ge => v >= x - hold,
                    Cmp::Lt => v < x + hold,
                    Cmp::Le => v <= x + hold,
                    // For equality the deadband is a tolerance.
                    Cmp::Eq => (v - x).abs() <= db,
                    Cmp::Ne => (v - x).abs() > db,
                }
            }
        }
    }

    /// The state an alarm returns to after shelving, suppression or
    /// maintenance: active → unacknowledged again, else normal.
    fn resumed(&self) -> State {
        if self.active {
            State::ActiveUnacked
        } else {
            State::Normal
        }
    }

    fn go(&mut self, to: State, now_ms: i64, user: Option<&str>, comment: Option<String>) -> Event {
        let from = self.state;
        self.state = to;
        self.since_ms = now_ms;
        Event {
            t_ms: now_ms,
            id: self.def.id.clone(),
            tag: self.def.tag.clone(),
            from,
            to,
            value: self.value,
            user: user.map(str::to_string),
            comment,
            severity: self.def.severity,
            message: self.def.message.clone(),
        }
    }

    fn step(&mut self, now: i64, v: f64, suppressed: bool, events: &mut Vec<Event>) {
        let raw = if v.is_nan() { self.active } else { self.raw(v) };
        self.prev = Some(v);
        self.value = v;
        self.active = if raw {
            let since = *self.pending_since.get_or_insert(now);
            now.saturating_sub(since) >= self.def.delay_ms as i64
        } else {
            self.pending_since = None;
            false
        };
        if self.out_of_service.is_some() {
            return;
        }
        if let Some((until, ..)) = self.shelved {
            if now < until {
                return;
            }
            self.shelved = None;
            let to = self.resumed();
            events.push(self.go(to, now, None, Some("shelving expired".into())));
        }
        if suppressed != self.suppressed {
            self.suppressed = suppressed;
            let to = if suppressed { State::Suppressed } else { self.resumed() };
            if to != self.state {
                events.push(self.go(to, now, None, None));
            }
        }
        if self.suppressed {
            return;
        }
        let to = match (self.state, self.active) {
            (State::Normal, true) => State::ActiveUnacked,
            (State::ActiveUnacked, false) => State::ClearedUnacked,
            (State::ActiveAcked, false) => State::Normal,
            (State::ClearedUnacked, true) => State::ActiveUnacked,
            _ => return,
        };
        events.push(self.go(to, now, None, None));
    }
}
