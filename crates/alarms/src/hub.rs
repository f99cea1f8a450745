//! The alarms of a running project shared by `alba run`'s evaluator and the
//! API: one lock around the state machine, and the log written before a
//! change is kept (an operator's action that cannot be logged is refused).

use crate::def::AlarmDef;
use crate::log::{Log, LogError};
use crate::state::{ActionError, Alarm, Alarms, Event};
use alba_ir::{Layout, Memory, Target};
use std::sync::{Mutex, MutexGuard, PoisonError};

#[derive(Debug, thiserror::Error)]
pub enum HubError {
    #[error(transparent)]
    Action(#[from] ActionError),
    #[error(transparent)]
    Log(#[from] LogError),
}

/// An operator's action on one alarm.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    Ack { comment: String },
    Shelve { minutes: u32, reason: String },
    Unshelve,
    OutOfService { on: bool, reason: String },
}

/// ISA-18.2's flood guidance: more than 10 new alarms in 10 minutes per operator.
pub const FLOOD_WINDOW_MS: i64 = 600_000;
pub const FLOOD_COUNT: usize = 10;

/// The alarm system at a glance (`GET /api/alarms/stats`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stats {
    pub alarms: usize,
    /// In alarm and not shelved, suppressed or out of service.
    pub active: usize,
    pub unacked: usize,
    pub shelved: usize,
    pub suppressed: usize,
    pub out_of_service: usize,
    /// Alarms that became active (from normal or cleared) in the last 10 minutes.
    pub new_in_window: usize,
    /// `new_in_window` > 10: an alarm flood.
    pub flood: bool,
    /// The most severe unacknowledged alarm (id, severity), for the banner.
    pub top_unacked: Option<(String, u16)>,
}

pub struct Hub {
    alarms: Mutex<Alarms>,
    /// Grows with every change of state: clients resend what they show only then.
    generation: std::sync::atomic::AtomicU64,
    /// When alarms became active, within the flood window.
    activations: Mutex<std::collections::VecDeque<i64>>,
    log: Option<Log>,
    /// The last error writing the log from the evaluator (shown by the status).
    log_error: Mutex<Option<String>>,
}

impl Hub {
    /// The alarms of `defs`, in the states the log kept before a restart.
    /// A log whose states cannot be read leaves every alarm normal and says
    /// why in [`Hub::log_error`].
    pub fn new(defs: Vec<AlarmDef>, log: Option<Log>) -> Hub {
        let mut alarms = Alarms::new(defs);
        let mut log_error = None;
        if let Some(log) = &log {
            match log.load_states() {
                Ok(saved) => {
                    alarms.restore(&saved);
                }
                Err(e) => log_error = Some(format!("alarm states were not restored: {e}")),
            }
        }
        Hub {
            alarms: Mutex::new(alarms),
            generation: std::sync::atomic::AtomicU64::new(0),
            activations: Mutex::new(std::collections::VecDeque::new()),
            log,
            log_error: Mutex::new(log_error),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Alarms> {
        self.alarms.lock().unwrap_or_else(PoisonError::into_inner)
    }

    pub fn log(&self) -> Option<&Log> {
        self.log.as_ref()
    }

    /// Evaluates the alarms on a snapshot's memory at `now_ms` and logs the
    /// changes, with the alarms' new states, before anyone can see them (so
    /// what a client was shown survives a `kill -9`). A log failure does not
    /// stop alarms (the operator must still see them): it is kept for
    /// [`Hub::log_error`] and returned.
    pub fn update(&self, now_ms: i64, mem: &Memory) -> Result<Vec<Event>, LogError> {
        let mut alarms = self.lock();
        let events = alarms.update(now_ms, mem);
        if events.is_empty() {
            return Ok(events);
        }
        let logged = match &self.log {
            Some(log) => log.append(&events, &alarms.persisted_for(&events)),
            None => Ok(()),
        };
        drop(alarms);
        self.count_activations(now_ms, &events);
        self.bump();
        if self.log.is_some() {
            *self.log_error.lock().unwrap_or_else(PoisonError::into_inner) =
                logged.as_ref().err().map(|e| e.to_string());
        }
        logged?;
        Ok(events)
    }

    fn count_activations(&self, now_ms: i64, events: &[Event]) {
        let mut a = self.activations.lock().unwrap_or_else(PoisonError::into_inner);
        a.extend(
            events
                .iter()
                .filter(|e| e.to == crate::State::ActiveUnacked)
                .map(|e| e.t_ms),
        );
        while a.front().is_some_and(|t| *t <= now_ms - FLOOD_WINDOW_MS) || a.len() > 10_000 {
            a.pop_front();
        }
    }

    /// Counts by state, the activation rate and the most severe unacknowledged alarm.
    pub fn stats(&self, now_ms: i64) -> Stats {
        let a = self.lock();
        let all = a.all();
        let count = |s: crate::State| all.iter().filter(|x| x.state == s).count();
        let top = all
            .iter()
            .filter(|x| x.state.unacked())
            .max_by(|x, y| x.def.severity.cmp(&y.def.severity).then(y.since_ms.cmp(&x.since_ms)))
            .map(|x| (x.def.id.clone(), x.def.severity));
        let new_in_window = self
            .activations
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .iter()
            .filter(|t| **t > now_ms - FLOOD_WINDOW_MS)
            .count();
        Stats {
            alarms: all.len(),
            active: count(crate::State::ActiveUnacked) + count(crate::State::ActiveAcked),
            unacked: all.iter().filter(|x| x.state.unacked()).count(),
            shelved: count(crate::State::Shelved),
            suppressed: count(crate::State::Suppressed),
            out_of_service: count(crate::State::OutOfService),
            new_in_window,
            flood: new_in_window > FLOOD_COUNT,
            top_unacked: top,
        }
    }

    /// The last error of the evaluator's log writes, if the last write failed.
    pub fn log_error(&self) -> Option<String> {
        self.log_error.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// Applies an operator's action: on a copy first, logged, then kept.
    pub fn act(&self, id: &str, req: &Request, user: &str, now_ms: i64) -> Result<Event, HubError> {
        let mut alarms = self.lock();
        let mut next = alarms.clone();
        let event = match req {
            Request::Ack { comment } => next.ack(id, user, comment, now_ms)?,
            Request::Shelve { minutes, reason } => next.shelve(id, *minutes, reason, user, now_ms)?,
            Request::Unshelve => next.unshelve(id, user, now_ms)?,
            Request::OutOfService { on, reason } => next.set_out_of_service(id, *on, reason, user, now_ms)?,
        };
        if let Some(log) = &self.log {
            log.append(
                std::slice::from_ref(&event),
                &next.persisted_for(std::slice::from_ref(&event)),
            )?;
        }
        *alarms = next;
        self.bump();
        Ok(event)
    }

    fn bump(&self) {
        self.generation.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// Changes of state so far (evaluator and operators): a client resends
    /// the alarm summary when this moved.
    pub fn generation(&self) -> u64 {
        self.generation.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The alarms not in `normal` (most severe first), or every alarm.
    pub fn list(&self, all: bool) -> Vec<Alarm> {
        let a = self.lock();
        if all {
            a.all().to_vec()
        } else {
            a.not_normal().into_iter().cloned().collect()
        }
    }

    /// After an online edit: every alarm's tag found again by name in the new
    /// layout. An alarm whose tag no longer resolves is taken out of service
    /// (returned, to be reported) rather than left reading a stale slot.
    pub fn relink(&self, layout: &Layout, now_ms: i64) -> Vec<String> {
        let mut a = self.lock();
        let mut lost = Vec::new();
        let mut events = Vec::new();
        for alarm in a.all_mut() {
            match layout.resolve(&alarm.def.tag) {
                Ok(Target::Value { place, .. }) if place.data_type() == alarm.def.place.data_type() => {
                    alarm.def.place = place;
                }
                _ => lost.push(alarm.def.id.clone()),
            }
            if let Some((name, p)) = &mut alarm.def.suppressed_by {
                match layout.resolve(name) {
                    Ok(Target::Value { place, .. }) if place.data_type() == alba_model::DataType::Bool => *p = place,
                    _ => lost.push(alarm.def.id.clone()),
                }
            }
        }
        lost.dedup();
        if !lost.is_empty() {
            self.bump();
        }
        for id in &lost {
            let why = "its tag is no longer in the program (online edit)";
            if let Ok(e) = a.set_out_of_service(id, true, why, "system", now_ms) {
                events.push(e);
            }
        }
        let states = a.persisted_for(&events);
        drop(a);
        if let Some(log) = &self.log
            && let Err(e) = log.append(&events, &states)
        {
            *self.log_error.lock().unwrap_or_else(PoisonError::into_inner) = Some(e.to_string());
        }
        lost
    }
}
