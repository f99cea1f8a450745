//! Operating the PLC beyond writes: forces, run/stop/step, applying a
//! program online, each under its audit row. Stopping and removing forces
//! are safety actions: never refused for want of their row (issue 31: with
//! the disk full, the PLC could not be stopped), see
//! [`Control::audited_safety`].

use crate::{Actor, Control, Refused, json_text, typed};
use alba_audit::{Action, Entry, Outcome};
use alba_auth::Role;
use alba_ir::{Program, Target};
use alba_model::Value;
use alba_runtime::json::to_json;
use alba_runtime::{RunState, Snapshot};
use serde_json::Value as Json;
use std::sync::Arc;

/// The role forcing, run/stop/step and online edits need (docs/security.md).
pub const ENGINEER: Role = Role::Engineer;

/// A run state as the API names it (`running`, `stopped`, `faulted`).
pub fn state_name(s: RunState) -> &'static str {
    match s {
        RunState::Running => "running",
        RunState::Stopped => "stopped",
        RunState::Faulted => "faulted",
    }
}

/// The forced value of `name` in `s`, if it is forced.
pub fn forced(s: &Snapshot, name: &str) -> Option<Value> {
    s.forces
        .iter()
        .find(|f| f.name.eq_ignore_ascii_case(name))
        .map(|f| f.value)
}

impl Control {
    /// Forces I/O `name` to `value` (JSON) for `actor` under its audit row
    /// (`force`: the old value is the former force, else the live value);
    /// the value forced.
    pub async fn force(&self, actor: &Actor, name: &str, value: &Json) -> Result<Value, Refused> {
        actor.needs(ENGINEER, "forcing I/O")?;
        let s = self.runtime.snapshot();
        let place = match s.program.layout.resolve(name) {
            Ok(Target::Value { place, .. }) => place,
            Ok(_) => return Err(Refused::NotForceable(format!("`{name}` is a structure, not I/O"))),
            Err(e) => return Err(Refused::UnknownTag(e.to_string())),
        };
        if alba_runtime::io_kind(&s.program.layout, place).is_none() {
            return Err(Refused::NotForceable(format!(
                "`{name}` is not an input or an output: only I/O can be forced (write internal tags instead)"
            )));
        }
        let v = typed(name, place, value)?;
        let entry = Entry {
            target: Some(name.to_string()),
            old: Some(json_text(&to_json(forced(&s, name).unwrap_or_else(|| s.read(place))))),
            new: Some(json_text(&to_json(v))),
            ..actor.entry(Action::Force)
        };
        self.audited(entry, async {
            self.runtime
                .force(name.to_string(), place, v)
                .await
                .map_err(Refused::from)
        })
        .await?;
        Ok(v)
    }

    /// Removes the force of `name` (`None`: every force) for `actor`: a
    /// safety action (`unforce`; the old value is the forced one, or an
    /// object of every force).
    pub async fn unforce(&self, actor: &Actor, name: Option<&str>) -> Result<(), Refused> {
        actor.needs(ENGINEER, "removing forces")?;
        let s = self.runtime.snapshot();
        let entry = match name {
            Some(name) => {
                let Some(value) = forced(&s, name) else {
                    return Err(Refused::NotForced(format!("`{name}` is not forced")));
                };
                Entry {
                    target: Some(name.to_string()),
                    old: Some(json_text(&to_json(value))),
                    ..actor.entry(Action::Unforce)
                }
            }
            None => {
                let all: serde_json::Map<String, Json> =
                    s.forces.iter().map(|f| (f.name.clone(), to_json(f.value))).collect();
                Entry {
                    old: Some(json_text(&Json::Object(all))),
                    ..actor.entry(Action::Unforce)
                }
            }
        };
        let name = name.map(str::to_string);
        self.audited_safety(entry, async { self.runtime.unforce(name).await.map_err(Refused::from) })
            .await
    }

    /// The audit entry of run/stop: the state before and the one asked for.
    fn run_entry(&self, actor: &Actor, action: Action, to: RunState) -> Entry {
        let before = self.runtime.snapshot().state;
        let text = |s: RunState| Some(json_text(&Json::String(state_name(s).into())));
        Entry {
            old: text(before),
            new: text(to),
            ..actor.entry(action)
        }
    }

    /// Starts the scan for `actor` under its audit row (`run`).
    pub async fn run(&self, actor: &Actor) -> Result<(), Refused> {
        actor.needs(ENGINEER, "starting the PLC")?;
        let e = self.run_entry(actor, Action::Run, RunState::Running);
        self.audited(e, async { self.runtime.run().await.map_err(Refused::from) })
            .await
    }

    /// Stops the scan for `actor`: a safety action (`stop`).
    pub async fn stop(&self, actor: &Actor) -> Result<(), Refused> {
        actor.needs(ENGINEER, "stopping the PLC")?;
        let e = self.run_entry(actor, Action::Stop, RunState::Stopped);
        self.audited_safety(e, async { self.runtime.stop().await.map_err(Refused::from) })
            .await
    }

    /// One scan while stopped, for `actor` under its audit row (`step`).
    pub async fn step(&self, actor: &Actor) -> Result<(), Refused> {
        actor.needs(ENGINEER, "stepping the PLC")?;
        let before = self.runtime.snapshot().scans;
        let e = Entry {
            old: Some(before.to_string()),
            new: Some(before.saturating_add(1).to_string()),
            detail: Some("one scan".to_string()),
            ..actor.entry(Action::Step)
        };
        self.audited(e, async { self.runtime.step().await.map_err(Refused::from) })
            .await
    }

    /// An edit of the project for `actor` (`save_program`, `online_edit`,
    /// `save_tags`: the caller has compiled it and built `entry`, with the
    /// file and its diff): the role, the audit row first, then `save` (the
    /// caller writes its files), then, with `online`, the new program
    /// replaces the running one between two scans ([`Refused::NotApplied`]
    /// if the runtime refuses it: the files stay saved).
    pub async fn edit<E>(
        &self,
        actor: &Actor,
        entry: Entry,
        save: impl FnOnce() -> Result<(), E>,
        online: Option<Arc<Program>>,
    ) -> Result<(), E>
    where
        E: From<Refused> + std::fmt::Display,
    {
        actor.needs(ENGINEER, "editing the project")?;
        self.audited(entry, async {
            save()?;
            if let Some(program) = online {
                self.runtime
                    .replace(program)
                    .await
                    .map_err(|e| E::from(Refused::NotApplied(e)))?;
            }
            Ok(())
        })
        .await
    }

    /// Attaches a board as the running PLC's I/O for `actor` (issue 33):
    /// the role, the audit row `entry` first (`attach`: the caller names the
    /// port, the drivers and the mode), then `open` (the caller opens the
    /// board's driver), then the driver is swapped in between two scans
    /// without stopping the PLC. The driver displaced, for the caller to
    /// put back at [`detach`](Self::detach).
    pub async fn attach<E>(
        &self,
        actor: &Actor,
        entry: Entry,
        open: impl Future<Output = Result<Box<dyn alba_runtime::Io>, E>>,
    ) -> Result<Box<dyn alba_runtime::Io>, E>
    where
        E: From<Refused> + std::fmt::Display,
    {
        actor.needs(ENGINEER, "attaching a board")?;
        let id = self.begin(entry).await.map_err(E::from)?;
        let result = async {
            let io = open.await?;
            self.runtime.set_io(io).await.map_err(|e| E::from(Refused::from(e)))
        }
        .await;
        // The outcome alone crosses the await (a driver is not `Sync`).
        let outcome = result.as_ref().map(|_| ()).map_err(|e| e.to_string());
        self.finish(id, &outcome).await;
        result
    }

    /// Puts `io` (the project's own I/O) back in place of an attached
    /// board's for `actor` (`detach`): a safety action like stop (the
    /// board's outputs go off), never refused for want of its row. The
    /// board's driver, for the caller to drop.
    pub async fn detach(
        &self,
        actor: &Actor,
        entry: Entry,
        io: Box<dyn alba_runtime::Io>,
    ) -> Result<Box<dyn alba_runtime::Io>, (Refused, Option<Box<dyn alba_runtime::Io>>)> {
        if let Err(r) = actor.needs(ENGINEER, "detaching a board") {
            return Err((r, Some(io)));
        }
        self.audited_safety(entry, async { self.runtime.set_io(io).await.map_err(Refused::from) })
            .await
            .map_err(|r| (r, None))
    }

    /// Performs a safety action — stop, removing forces — under its audit
    /// row, which is never a reason to refuse it: when the log cannot be
    /// written the row goes to its fallback journal, or at worst to stderr
    /// (`alba_audit::Audit::begin_safety`).
    pub async fn audited_safety<T, E>(&self, entry: Entry, action: impl Future<Output = Result<T, E>>) -> Result<T, E>
    where
        E: std::fmt::Display,
    {
        let Some(audit) = self.audit.clone() else {
            return action.await;
        };
        let log = audit.clone();
        let begun = tokio::task::spawn_blocking(move || log.begin_safety(&entry))
            .await
            .unwrap_or(alba_audit::Begun::Nowhere);
        let result = action.await;
        let outcome = match &result {
            Ok(_) => Outcome::Ok,
            Err(e) => Outcome::Failed(e.to_string()),
        };
        let b = begun.clone();
        match tokio::task::spawn_blocking(move || audit.finish_safety(&b, &outcome)).await {
            Ok(Ok(())) => {}
            Ok(Err(e)) => eprintln!("audit: the outcome of {begun:?} is not recorded: {e}"),
            Err(e) => eprintln!("audit: the outcome of {begun:?} is not recorded: {e}"),
        }
        result
    }

    /// Records an action already done or refused (a login, a failed login,
    /// a logout): the caller's reply waits for it, and fails if it fails.
    pub async fn record(&self, entry: Entry, outcome: Outcome) -> Result<(), Refused> {
        let Some(audit) = self.audit.clone() else {
            return Ok(());
        };
        crate::blocking(move || audit.record(&entry, &outcome))
            .await
            .map(|_| ())
    }
}

impl Control {
    /// Gives every marking tag of net `program` its initial value, all at
    /// one scan boundary, for `actor` under its audit row (`reset_marking`:
    /// target the program, new the marking as `[{"tag", "value"}]`).
    /// [`Refused::NotWritable`] when the running program has not got a tag
    /// of the marking (the net saved but not applied online).
    pub async fn reset_marking(&self, actor: &Actor, program: &str, marking: &[(String, i32)]) -> Result<(), Refused> {
        actor.needs(ENGINEER, "resetting a net")?;
        let s = self.runtime.snapshot();
        let mut writes = Vec::with_capacity(marking.len());
        for (tag, v) in marking {
            match s.program.layout.resolve(tag) {
                Ok(Target::Value { place, .. }) => writes.push((place, Value::Dint(*v))),
                _ => {
                    return Err(Refused::NotWritable(format!(
                        "the running program has no marking tag `{tag}`: save the net and apply it online first"
                    )));
                }
            }
        }
        let new: Vec<Json> = marking
            .iter()
            .map(|(tag, value)| serde_json::json!({ "tag": tag, "value": value }))
            .collect();
        let e = Entry {
            target: Some(program.to_string()),
            new: Some(json_text(&Json::Array(new))),
            ..actor.entry(Action::ResetMarking)
        };
        self.audited(e, async {
            self.runtime.write_many(writes).await.map_err(Refused::from)
        })
        .await
    }
}
