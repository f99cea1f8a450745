//! The operators' actions on alarms (acknowledge, shelve, unshelve, out of
//! service), under the same rules as every other action: the role, the
//! audit row first, then the alarm hub (which logs the change in the alarm
//! log before it keeps it).

use crate::{Actor, Control, Refused, json_text, now_ms};
use alba_audit::{Action, Entry};
use alba_auth::Role;
use serde_json::Value as Json;
use std::sync::Arc;

pub use alba_alarms::{ActionError, Alarm, Hub, HubError, Log, LogError, Request, Stats, kpi};

/// The role an action on an alarm needs (docs/security.md): an operator
/// acknowledges and shelves, an engineer takes an alarm out of service.
pub fn role_for(req: &Request) -> Role {
    match req {
        Request::Ack { .. } | Request::Shelve { .. } | Request::Unshelve => Role::Operator,
        Request::OutOfService { .. } => Role::Engineer,
    }
}

/// The audit entry of `req` on alarm `id` by `actor`.
fn entry(actor: &Actor, id: &str, req: &Request) -> Entry {
    let (action, new, detail) = match req {
        Request::Ack { comment } => (Action::AlarmAck, None, (!comment.is_empty()).then(|| comment.clone())),
        Request::Shelve { minutes, reason } => (Action::AlarmShelve, None, Some(format!("{minutes} min: {reason}"))),
        Request::Unshelve => (Action::AlarmUnshelve, None, None),
        Request::OutOfService { on, reason } => (
            Action::AlarmOutOfService,
            Some(json_text(&Json::Bool(*on))),
            (!reason.is_empty()).then(|| reason.clone()),
        ),
    };
    Entry {
        target: Some(id.to_string()),
        new,
        detail,
        ..actor.entry(action)
    }
}

impl Control {
    /// Gives the control layer the project's alarms (once: `alba run` when
    /// the project has an alarms.csv); false if it already has them.
    pub fn set_alarms(&self, hub: Arc<Hub>) -> bool {
        self.alarms.set(hub).is_ok()
    }

    /// The project's alarms, if it has any.
    pub fn alarms(&self) -> Option<&Arc<Hub>> {
        self.alarms.get()
    }

    /// The alarm summary now (every count zero without alarms).
    pub fn alarm_stats(&self) -> Stats {
        self.alarms.get().map(|h| h.stats(now_ms())).unwrap_or(Stats {
            alarms: 0,
            active: 0,
            unacked: 0,
            shelved: 0,
            suppressed: 0,
            out_of_service: 0,
            new_in_window: 0,
            flood: false,
            top_unacked: None,
        })
    }

    /// Applies `req` to alarm `id` for `actor` under its audit row; the
    /// alarm as it then is. A user-less actor (HTTP on loopback without
    /// users) is recorded by the alarm as `local`.
    pub async fn alarm_act(&self, actor: &Actor, id: &str, req: Request) -> Result<Alarm, Refused> {
        actor.needs(role_for(&req), "this action on an alarm")?;
        let hub = self
            .alarms
            .get()
            .cloned()
            .ok_or_else(|| Refused::UnknownAlarm(format!("no alarm `{id}` (the project has no alarms.csv)")))?;
        let user = actor.user.clone().unwrap_or_else(|| "local".into());
        let (h, id2) = (hub.clone(), id.to_string());
        self.audited(entry(actor, id, &req), async move {
            tokio::task::spawn_blocking(move || h.act(&id2, &req, &user, now_ms()))
                .await
                .map_err(|e| Refused::Internal(format!("the alarm task ended: {e}")))?
                .map_err(Refused::Alarm)
        })
        .await?;
        hub.list(true)
            .into_iter()
            .find(|a| a.def.id.eq_ignore_ascii_case(id))
            .ok_or_else(|| Refused::UnknownAlarm(format!("no alarm `{id}`")))
    }
}
