//! The rules for operating the running PLC, once for every door.
//!
//! Four doors change the PLC: the HTTP API (and its WebSocket), MQTT, OPC UA
//! and Modbus TCP. Each builds an [`Actor`] (who, with what role, through
//! which door, from where) and asks [`Control`] to act; `Control` resolves
//! the name, checks the role, the type, the range and the writability,
//! writes the audit row first (docs/audit.md: "no acknowledged action
//! without its row") and only then asks the runtime. What it refuses comes
//! back as a [`Refused`], which each door maps once to its own protocol (an
//! HTTP status, an OPC UA status code, a Modbus exception, an MQTT error
//! message): the rules exist here, the doors only translate.
//!
//! See docs/adr/0014-one-control-layer-behind-every-door.md.

mod actor;
pub mod alarms;
pub mod names;
mod operate;
mod refused;
#[cfg(test)]
mod tests;

pub use actor::{Actor, Via};
pub use refused::{Refused, RowRefused};

/// The runtime's types the doors name: its handle, snapshots, states,
/// errors, and values as JSON.
pub mod runtime {
    pub use alba_runtime::json;
    pub use alba_runtime::{Error, Handle, Io, IoError, RunState, SimIo, Snapshot, io_kind};
}

/// The audit trail's types: the rows the doors read back and export.
pub mod audit {
    pub use alba_audit::{Action, Audit, Begun, Entry, Error, Filter, Outcome, Result, Row, diff, format_utc};
}

/// The historian's read side, for the doors that serve history (the HTTP
/// API): the store `alba run` records into, and its errors.
pub mod history {
    pub use alba_historian::{Backend, Column, Error, MAX_TIME_MS, csv_rows};
}

/// The relay-feedback tuning of a PID loop, run on a copy of the program
/// (`POST /api/pid/{name}/autotune`): the running PLC is not touched.
pub mod autotune {
    pub use alba_engine::autotune::*;
}

use alba_audit::{Action, Audit, Entry, Outcome};
use alba_auth::Role;
use alba_ir::Program;
use alba_ir::{Access, Place, Target};
use alba_model::Value;
use alba_runtime::json::{from_json, to_json};
use alba_runtime::{Handle, Snapshot};
use serde_json::Value as Json;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};

/// The role writing a tag needs (docs/security.md, "Sessions and roles").
pub const WRITE_ROLE: Role = Role::Operator;

/// The runtime handle and the audit log every door acts through; cheap to
/// clone (clones share both).
#[derive(Clone)]
pub struct Control {
    runtime: Handle,
    audit: Option<Audit>,
    /// The name of each place of the program last seen (audit rows of
    /// writes by place name their tag).
    names: Arc<Mutex<Option<Names>>>,
    /// The audit windows of writes by place (Modbus): per peer and tag, the
    /// second whose first write has its row, and the writes since.
    windows: Arc<Mutex<HashMap<String, HashMap<Place, Window>>>>,
    /// The project's alarms, set once by `alba run` when it has any.
    alarms: Arc<std::sync::OnceLock<Arc<alba_alarms::Hub>>>,
}

/// Writes of one peer to one tag within one second after the first (which
/// has its own row): recorded together (docs/audit.md, "Modbus").
#[derive(Debug, Clone)]
struct Window {
    name: String,
    second: i64,
    count: u64,
    last: Value,
}

/// The names of a program's places, and the program.
type Names = (Arc<Program>, Arc<HashMap<Place, String>>);

/// A JSON value as the text an audit row stores.
pub fn json_text(v: &Json) -> String {
    v.to_string()
}

/// The wall clock in Unix ms (audit rows are stamped by the server).
pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// Resolves `name` for a write, or says why it cannot be written.
pub fn writable(s: &Snapshot, name: &str) -> Result<Place, Refused> {
    match s.program.layout.resolve(name) {
        Err(e) => Err(Refused::UnknownTag(e.to_string())),
        Ok(Target::Timer(_) | Target::Counter(_)) => Err(Refused::NotWritable(format!(
            "`{name}` is a structure: write one of its members (`{name}.PRE`, `{name}.ACC`)"
        ))),
        Ok(Target::Pid(_)) => Err(Refused::NotWritable(format!(
            "`{name}` is a structure: write one of its members (`{name}.SP`, `{name}.KP`, `{name}.MAN`)"
        ))),
        Ok(Target::Value { place, access }) => match access {
            Access::ReadWrite => Ok(place),
            Access::Input => Err(Refused::NotWritable(format!(
                "`{name}` is an input, written by the I/O: force it instead"
            ))),
            Access::ReadOnly | Access::Output => Err(Refused::NotWritable(format!("`{name}` is read-only"))),
        },
    }
}

/// The range rules beyond the type's own: a timer's preset is a duration,
/// never negative (the instruction would fault on it every scan).
pub fn in_range(s: &Snapshot, name: &str, v: Value) -> Result<(), Refused> {
    if let Some((base, member)) = name.rsplit_once('.')
        && member.eq_ignore_ascii_case("PRE")
        && matches!(s.program.layout.resolve(base), Ok(Target::Timer(_)))
        && v.as_i64() < 0
    {
        return Err(Refused::OutOfRange(format!(
            "`{name}` is a timer's preset: it cannot be negative"
        )));
    }
    Ok(())
}

/// `value` (JSON) as a value of `place`'s type, or why not.
pub fn typed(name: &str, place: Place, value: &Json) -> Result<Value, Refused> {
    from_json(value, place.data_type()).map_err(|e| {
        if e.is_out_of_range() {
            Refused::OutOfRange(format!("`{name}`: {e}"))
        } else {
            Refused::WrongType(format!("`{name}`: {e}"))
        }
    })
}

impl Control {
    pub fn new(runtime: Handle, audit: Option<Audit>) -> Control {
        Control {
            runtime,
            audit,
            names: Arc::default(),
            windows: Arc::default(),
            alarms: Arc::default(),
        }
    }

    /// The name of the value at `place` (a tag, a member, a system tag),
    /// else the place itself (`MWord(4)`: Modbus-only marker memory).
    pub fn place_name(&self, s: &Snapshot, place: Place) -> String {
        let names = {
            let mut cache = self.names.lock().unwrap_or_else(PoisonError::into_inner);
            match cache.as_ref() {
                Some((p, n)) if Arc::ptr_eq(p, &s.program) => n.clone(),
                _ => {
                    let mut n = HashMap::new();
                    for (name, p) in names::every_value(&s.program.layout) {
                        n.entry(p).or_insert(name);
                    }
                    let n = Arc::new(n);
                    *cache = Some((s.program.clone(), n.clone()));
                    n
                }
            }
        };
        names.get(&place).cloned().unwrap_or_else(|| format!("{place:?}"))
    }

    pub fn runtime(&self) -> &Handle {
        &self.runtime
    }

    /// The audit log (`None`: this PLC records nothing: tests, embedders).
    pub fn audit(&self) -> Option<&Audit> {
        self.audit.as_ref()
    }

    /// The value of `name` in the latest snapshot.
    pub fn read(&self, name: &str) -> Result<Json, Refused> {
        let s = self.runtime.snapshot();
        match s.program.layout.resolve(name) {
            Ok(Target::Value { place, .. }) => Ok(to_json(s.read(place))),
            Ok(_) => Err(Refused::NotWritable(format!(
                "`{name}` is a structure: read one of its members"
            ))),
            Err(e) => Err(Refused::UnknownTag(e.to_string())),
        }
    }

    /// Checks a write of `name` = `value` (JSON) by `actor` without doing
    /// it: role, name, writability, type, range. The place and the value.
    pub fn check(&self, s: &Snapshot, actor: &Actor, name: &str, value: &Json) -> Result<(Place, Value), Refused> {
        actor.needs(WRITE_ROLE, "writing tags")?;
        let place = writable(s, name)?;
        let v = typed(name, place, value)?;
        in_range(s, name, v)?;
        Ok((place, v))
    }

    /// Writes `name` = `value` (JSON) for `actor` under its audit row; the
    /// value the tag then holds.
    pub async fn write(&self, actor: &Actor, name: &str, value: &Json) -> Result<Json, Refused> {
        let s = self.runtime.snapshot();
        let (place, v) = self.check(&s, actor, name, value)?;
        let entry = Entry {
            target: Some(name.to_string()),
            old: Some(json_text(&to_json(s.read(place)))),
            new: Some(json_text(&to_json(v))),
            ..actor.entry(Action::Write)
        };
        self.audited(entry, async {
            self.runtime.write(place, v).await.map_err(Refused::from)
        })
        .await?;
        Ok(to_json(self.runtime.snapshot().read(place)))
    }

    /// Writes several tags at the same scan boundary (all or none), under
    /// one audit row per tag written before any is applied.
    pub async fn write_many(&self, actor: &Actor, writes: &[(String, Json)]) -> Result<(), Refused> {
        self.write_rows(actor, writes, None).await.map_err(|e| e.refused)
    }

    /// [`write_many`](Self::write_many) saying which write was refused
    /// ([`RowRefused::row`]), each audit row with `detail` (a recipe
    /// applied: `recipe <name>`). Every write is checked — role, name,
    /// writability, type, range — before any row is written or any value
    /// applied: a refusal writes nothing.
    pub async fn write_rows(
        &self,
        actor: &Actor,
        writes: &[(String, Json)],
        detail: Option<&str>,
    ) -> Result<(), RowRefused> {
        let s = self.runtime.snapshot();
        let mut checked = Vec::with_capacity(writes.len());
        let mut entries = Vec::with_capacity(writes.len());
        for (row, (name, value)) in writes.iter().enumerate() {
            let (place, v) = self.check(&s, actor, name, value).map_err(|refused| RowRefused {
                row: Some(row),
                refused,
            })?;
            checked.push((place, v));
            entries.push(Entry {
                target: Some(name.clone()),
                old: Some(json_text(&to_json(s.read(place)))),
                new: Some(json_text(&to_json(v))),
                detail: detail.map(str::to_string),
                ..actor.entry(Action::Write)
            });
        }
        let ids = self.begin_all(entries).await.map_err(RowRefused::from)?;
        let result = self.runtime.write_many(checked).await.map_err(Refused::from);
        for id in ids {
            self.finish(Some(id), &result).await;
        }
        result.map_err(RowRefused::from)
    }

    /// Performs `action` under its audit row: the row first (the action is
    /// not performed if it cannot be written: [`Refused::AuditUnavailable`]),
    /// then the action, then its outcome. A row whose outcome cannot be set
    /// stays `pending` (said on stderr); the action stands.
    pub async fn audited<T, E>(&self, entry: Entry, action: impl Future<Output = Result<T, E>>) -> Result<T, E>
    where
        E: From<Refused> + std::fmt::Display,
    {
        let id = self.begin(entry).await.map_err(E::from)?;
        let result = action.await;
        self.finish(id, &result).await;
        result
    }

    /// Writes the `pending` row of an action about to be performed; `None`
    /// when no audit trail is kept.
    pub async fn begin(&self, entry: Entry) -> Result<Option<i64>, Refused> {
        let Some(audit) = self.audit.clone() else {
            return Ok(None);
        };
        blocking(move || audit.begin(&entry)).await.map(Some)
    }

    async fn begin_all(&self, entries: Vec<Entry>) -> Result<Vec<i64>, Refused> {
        let Some(audit) = self.audit.clone() else {
            return Ok(Vec::new());
        };
        blocking(move || entries.iter().map(|e| audit.begin(e)).collect()).await
    }

    /// Sets the outcome of the row [`begin`](Self::begin) wrote.
    pub async fn finish<T, E: std::fmt::Display>(&self, id: Option<i64>, result: &Result<T, E>) {
        let (Some(audit), Some(id)) = (self.audit.clone(), id) else {
            return;
        };
        let outcome = outcome(result);
        let done = tokio::task::spawn_blocking(move || audit.finish(id, &outcome)).await;
        match done {
            Ok(Ok(())) => {}
            Ok(Err(e)) => eprintln!("audit: row {id} keeps outcome `pending`: {e}"),
            Err(e) => eprintln!("audit: row {id} keeps outcome `pending`: {e}"),
        }
    }

    /// Writes typed values at places (a door that addresses places, not
    /// names: Modbus) for `actor`: the role, then the audit rows (one per
    /// place, named by its tag when it has one), then the runtime, all at
    /// the same scan boundary. Blocking: for the caller's own thread.
    pub fn write_places_blocking(&self, actor: &Actor, writes: Vec<(Place, Value)>) -> Result<(), Refused> {
        actor.needs(WRITE_ROLE, "writing tags")?;
        let s = self.runtime.snapshot();
        // The range rules beyond the type's concern negative values only.
        for &(place, v) in &writes {
            if v.as_i64() < 0 {
                in_range(&s, &self.place_name(&s, place), v)?;
            }
        }
        let mut ids = Vec::new();
        if let Some(audit) = &self.audit {
            let second = now_ms().div_euclid(1000);
            let peer = actor.peer.as_deref().unwrap_or_default();
            // Which writes need a row (the lock is not held while rows are
            // written: other peers' writes go on meanwhile).
            let mut need = Vec::new();
            {
                let mut windows = self.windows.lock().unwrap_or_else(PoisonError::into_inner);
                let mine = match windows.get_mut(peer) {
                    Some(m) => m,
                    None => windows.entry(peer.to_string()).or_default(),
                };
                for &(place, v) in &writes {
                    match mine.get_mut(&place) {
                        // Covered by this second's row: counted, recorded with the window.
                        Some(w) if w.second == second => {
                            w.count += 1;
                            w.last = v;
                        }
                        _ => need.push((place, v, mine.remove(&place))),
                    }
                }
            }
            let mut opened = Vec::with_capacity(need.len());
            for (place, v, old) in need {
                if let Some(w) = old {
                    summary(audit, actor, &w).map_err(Refused::AuditUnavailable)?;
                }
                let name = self.place_name(&s, place);
                let entry = Entry {
                    target: Some(name.clone()),
                    old: Some(json_text(&to_json(s.read(place)))),
                    new: Some(json_text(&to_json(v))),
                    ..actor.entry(Action::Write)
                };
                ids.push(audit.begin(&entry).map_err(Refused::AuditUnavailable)?);
                opened.push((
                    place,
                    Window {
                        name,
                        second,
                        count: 0,
                        last: v,
                    },
                ));
            }
            if !opened.is_empty() {
                let mut windows = self.windows.lock().unwrap_or_else(PoisonError::into_inner);
                windows.entry(peer.to_string()).or_default().extend(opened);
            }
        }
        let result = self.runtime.write_many_blocking(writes).map_err(Refused::from);
        if let Some(audit) = &self.audit {
            let outcome = outcome(&result);
            for id in ids {
                if let Err(e) = audit.finish(id, &outcome) {
                    eprintln!("audit: row {id} keeps outcome `pending`: {e}");
                }
            }
        }
        result
    }
}

impl Control {
    /// Records the writes `actor` made since the last row of each tag
    /// (coalesced by [`write_places_blocking`](Self::write_places_blocking));
    /// a door calls it when the peer goes (a Modbus connection closes).
    pub fn flush(&self, actor: &Actor) {
        let Some(audit) = &self.audit else { return };
        let peer = actor.peer.as_deref().unwrap_or_default();
        let mine = self
            .windows
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(peer)
            .unwrap_or_default();
        for w in mine.values() {
            if let Err(e) = summary(audit, actor, w) {
                eprintln!(
                    "audit: {} coalesced writes of `{}` by {peer} not recorded: {e}",
                    w.count, w.name
                );
            }
        }
    }
}

/// The row of a window's writes after its first: how many, the last value.
fn summary(audit: &Audit, actor: &Actor, w: &Window) -> alba_audit::Result<()> {
    if w.count == 0 {
        return Ok(());
    }
    let entry = Entry {
        target: Some(w.name.clone()),
        new: Some(json_text(&to_json(w.last))),
        detail: Some(format!(
            "coalesced: {} more writes in the second from {} ms (the last value shown; docs/audit.md)",
            w.count,
            w.second * 1000
        )),
        ..actor.entry(Action::Write)
    };
    audit.record(&entry, &Outcome::Ok).map(|_| ())
}

fn outcome<T, E: std::fmt::Display>(result: &Result<T, E>) -> Outcome {
    match result {
        Ok(_) => Outcome::Ok,
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

async fn blocking<T: Send + 'static>(f: impl FnOnce() -> alba_audit::Result<T> + Send + 'static) -> Result<T, Refused> {
    match tokio::task::spawn_blocking(f).await {
        Ok(r) => r.map_err(Refused::AuditUnavailable),
        Err(e) => Err(Refused::AuditUnavailable(alba_audit::Error::InvalidArgument(format!(
            "the audit task ended: {e}"
        )))),
    }
}
