//! `/api/ws`: live values, power flow and status (docs/api.md).
//!
//! Each client task waits on the runtime's snapshot channel, which keeps
//! only the latest snapshot: a client that falls behind skips scans and
//! gets one message with everything that changed meanwhile, so no queue
//! grows and the engine never waits. A client that cannot take a message
//! for 5 s is disconnected (a slow consumer costs one pending message at
//! most). Beyond `[http] max_ws_clients` a client is closed at once with
//! code 1013 ("try again later") and a reason saying why.
//!
//! A subscription names each value once (names that resolve to the same
//! value, repeated or not, are sent once), lists at most
//! [`MAX_NAMES`] names, and all clients together follow at most
//! [`MAX_SERVER_VALUES`] values: without this, 64 clients repeating one name
//! made 2 GB of traffic in 15 s (issue 31). `monitor` lists each program once.
//!
//! The handshake's `Origin` (required, the studio's own or allowed) is
//! checked before this by `crate::guard`.

use crate::api::status::status_of;
use crate::auth::SessionKey;
use crate::reply::{AlarmsMsg, ErrorMsg, PowerMsg, StatusMsg};
use crate::state::AppState;
use crate::{project, tags};
use alba_control::runtime::Snapshot;
use alba_control::runtime::json::to_json;
use alba_ir::model::Value;
use alba_ir::{Place, Program, Target};
use axum::Extension;
use axum::extract::State;
use axum::extract::ws::{CloseFrame, Message, WebSocket, WebSocketUpgrade, close_code};
use axum::response::Response;
use serde_json::Value as Json;
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

const SEND_TIMEOUT: Duration = Duration::from_secs(5);
/// Most names one `subscribe` lists (a screen shows far fewer; a message
/// holds 64 KiB at most anyway).
pub const MAX_NAMES: usize = 4096;
/// Most values all live clients together follow: each is compared with its
/// last sent value every scan, for every client.
pub const MAX_SERVER_VALUES: usize = 250_000;
const STATUS_EVERY: Duration = Duration::from_millis(500);
/// How often a client's session is checked: the connection closes
/// (1008, "session ended") within this time of a logout or expiry.
const SESSION_EVERY: Duration = Duration::from_secs(1);

pub async fn upgrade(
    ws: WebSocketUpgrade,
    State(st): State<Arc<AppState>>,
    session: Option<Extension<SessionKey>>,
) -> Response {
    let session = session.map(|Extension(k)| k);
    ws.max_message_size(64 * 1024)
        .on_upgrade(move |socket| client(socket, st, session))
}

enum Wanted {
    Nothing,
    All,
    Names(Vec<String>),
}

/// A subscribed value and what this client was last sent of it.
struct Sub {
    /// The name as a JSON key: `"Level":`.
    key: String,
    place: Place,
    sent: Option<Value>,
}

/// One client's view: what it asked for and what it was last sent.
struct Client {
    wanted: Wanted,
    /// Resolved for `program`.
    subs: Vec<Sub>,
    program: Option<Arc<Program>>,
    monitor: Vec<String>,
    /// Element ids of each unit of `program`.
    units: Vec<std::ops::Range<u32>>,
    /// The energised elements last sent, and the scan they were sent for.
    power_sent: HashMap<String, (Vec<u32>, u64)>,
    status_at: Option<Instant>,
    status_state: &'static str,
    /// The alarm hub's generation last sent (`None`: not yet).
    alarms_sent: Option<u64>,
    /// This client's share of the server's count of subscribed values.
    counted: Counted,
}

/// A client's subscribed values, counted in `AppState::subscribed` for as
/// long as it lives.
struct Counted {
    st: Arc<AppState>,
    n: usize,
}

impl Counted {
    fn set(&mut self, subs: &[Sub]) {
        self.st.subscribed.fetch_add(subs.len(), Ordering::Relaxed);
        self.st.subscribed.fetch_sub(self.n, Ordering::Relaxed);
        self.n = subs.len();
    }
}

impl Drop for Counted {
    fn drop(&mut self) {
        self.st.subscribed.fetch_sub(self.n, Ordering::Relaxed);
    }
}

impl Client {
    /// Re-resolves the subscription after a program change; unknown names
    /// are returned.
    fn resolve(&mut self, program: &Arc<Program>) -> Vec<String> {
        let layout = &program.layout;
        let mut unknown = Vec::new();
        let places = match &self.wanted {
            Wanted::Nothing => Vec::new(),
            Wanted::All => tags::every_value(layout),
            Wanted::Names(names) => names
                .iter()
                .flat_map(|n| match layout.resolve(n) {
                    Ok(Target::Value { place, .. }) => vec![(n.clone(), place)],
                    Ok(Target::Timer(t)) => tags::members(alba_ir::model::DataType::Timer, t.i, t.b)
                        .into_iter()
                        .map(|(m, p)| (format!("{n}.{m}"), p))
                        .collect(),
                    Ok(Target::Counter(c)) => tags::members(alba_ir::model::DataType::Counter, c.i, c.b)
                        .into_iter()
                        .map(|(m, p)| (format!("{n}.{m}"), p))
                        .collect(),
                    Ok(Target::Pid(pid)) => tags::pid_members(pid)
                        .into_iter()
                        .map(|(m, p)| (format!("{n}.{m}"), p))
                        .collect(),
                    Err(_) => {
                        unknown.push(n.clone());
                        Vec::new()
                    }
                })
                .collect(),
        };
        // What was sent under a name stays sent (an online edit re-sends only what changed).
        let mut sent: HashMap<String, Value> = std::mem::take(&mut self.subs)
            .into_iter()
            .filter_map(|s| Some((s.key, s.sent?)))
            .collect();
        // Each value once, under the first name that reached it.
        let mut seen = std::collections::HashSet::new();
        self.subs = places
            .into_iter()
            .filter(|(_, place)| seen.insert(*place))
            .map(|(name, place)| {
                let key = format!("{}:", Json::String(name));
                let sent = sent.remove(&key);
                Sub { key, place, sent }
            })
            .collect();
        self.units = project::unit_elements(program);
        self.program = Some(program.clone());
        self.counted.set(&self.subs);
        unknown
    }

    /// The messages `s` calls for.
    fn updates(&mut self, s: &Snapshot, st: &AppState) -> Vec<String> {
        let mut out = Vec::new();
        if !self.program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &s.program)) {
            self.resolve(&s.program);
            self.power_sent.clear();
        }
        // Written directly: with 10 000 tags this runs 100 times a second per client.
        let mut values = String::new();
        for sub in &mut self.subs {
            let v = s.read(sub.place);
            if sub.sent != Some(v) {
                sub.sent = Some(v);
                values.push(if values.is_empty() { '{' } else { ',' });
                values.push_str(&sub.key);
                values.push_str(&to_json(v).to_string());
            }
        }
        if !values.is_empty() {
            out.push(format!(
                "{{\"type\":\"values\",\"scan\":{},\"t_ms\":{},\"values\":{values}}}}}",
                s.scans, s.unix_ms
            ));
        }
        // Not running: nothing is energised.
        if s.power().is_some() || s.state != alba_control::runtime::RunState::Running {
            for name in &self.monitor {
                let Some(unit) = s.program.units.iter().position(|u| u.name.eq_ignore_ascii_case(name)) else {
                    continue;
                };
                let range = self.units.get(unit).cloned().unwrap_or(0..0);
                let on: Vec<u32> = range.filter(|e| s.energised(*e) == Some(true)).collect();
                // A net's transitions that fire scan after scan leave `on` as it
                // was: a net's power flow is sent for every new scan in which
                // something is energised (its "fired" elements, docs/nets.md).
                let net = name.to_ascii_lowercase().ends_with(".pnml");
                let again = |(was, scan): &(Vec<u32>, u64)| *was != on || (net && !on.is_empty() && *scan != s.scans);
                if self.power_sent.get(name).is_none_or(again) {
                    out.push(json_text(&PowerMsg {
                        kind: "power",
                        scan: s.scans,
                        program: name.clone(),
                        on: on.clone(),
                    }));
                    self.power_sent.insert(name.clone(), (on, s.scans));
                }
            }
        }
        let state = s.state.name();
        if state != self.status_state || self.status_at.is_none_or(|t| t.elapsed() >= STATUS_EVERY) {
            out.push(json_text(&StatusMsg {
                kind: "status",
                status: status_of(s, st),
            }));
            self.status_at = Some(Instant::now());
            self.status_state = state;
        }
        if let Some(hub) = st.control.alarms() {
            let g = hub.generation();
            if self.alarms_sent != Some(g) {
                self.alarms_sent = Some(g);
                out.push(json_text(&AlarmsMsg {
                    kind: "alarms",
                    stats: crate::api::alarms::stats_of(st),
                }));
            }
        }
        out
    }
}

/// A message as JSON text (these types always serialize).
fn json_text(m: &impl serde::Serialize) -> String {
    serde_json::to_string(m).unwrap_or_default()
}

async fn send(socket: &mut WebSocket, msgs: Vec<String>) -> bool {
    for m in msgs {
        let sent = tokio::time::timeout(SEND_TIMEOUT, socket.send(Message::Text(m.into()))).await;
        if !matches!(sent, Ok(Ok(()))) {
            return false;
        }
    }
    true
}

async fn client(mut socket: WebSocket, st: Arc<AppState>, session: Option<SessionKey>) {
    if st.clients.fetch_add(1, Ordering::Relaxed) >= st.max_ws_clients {
        st.clients.fetch_sub(1, Ordering::Relaxed);
        let frame = CloseFrame {
            code: close_code::AGAIN,
            reason: format!(
                "too many live clients ({}): close another studio, or raise [http] max_ws_clients",
                st.max_ws_clients
            )
            .into(),
        };
        let _ = tokio::time::timeout(SEND_TIMEOUT, socket.send(Message::Close(Some(frame)))).await;
        return;
    }
    let mut rx = st.runtime.subscribe();
    let mut c = Client {
        wanted: Wanted::Nothing,
        subs: Vec::new(),
        program: None,
        monitor: Vec::new(),
        units: Vec::new(),
        power_sent: HashMap::new(),
        status_at: None,
        status_state: "",
        alarms_sent: None,
        counted: Counted { st: st.clone(), n: 0 },
    };
    let mut monitoring = false;
    let mut closing = st.closing.subscribe();
    let mut check = tokio::time::interval(SESSION_EVERY);
    let mut ended = false;
    loop {
        let msgs = tokio::select! {
            _ = closing.wait_for(|c| *c) => break,
            _ = check.tick(), if session.is_some() => {
                if session.as_ref().is_some_and(|k| !st.auth.alive(k)) {
                    ended = true;
                }
                Vec::new()
            }
            m = socket.recv() => match m {
                Some(Ok(Message::Text(t))) => {
                    let mut out = command(&mut c, &st, t.as_str());
                    let s = rx.borrow_and_update().clone();
                    if monitoring == c.monitor.is_empty() {
                        monitoring = !monitoring;
                        st.runtime.monitor(monitoring);
                    }
                    out.extend(c.updates(&s, &st));
                    out
                }
                Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                Some(Ok(_)) => continue,
            },
            changed = rx.changed() => {
                if changed.is_err() {
                    break;
                }
                let s = rx.borrow_and_update().clone();
                c.updates(&s, &st)
            }
        };
        if ended {
            let frame = CloseFrame {
                code: close_code::POLICY,
                reason: "session ended: log in again".into(),
            };
            let _ = tokio::time::timeout(SEND_TIMEOUT, socket.send(Message::Close(Some(frame)))).await;
            break;
        }
        if !send(&mut socket, msgs).await {
            break;
        }
    }
    if monitoring {
        st.runtime.monitor(false);
    }
    st.clients.fetch_sub(1, Ordering::Relaxed);
}

/// Applies a client command; answers with error messages if any.
fn command(c: &mut Client, st: &AppState, text: &str) -> Vec<String> {
    let err = |m: String| {
        vec![json_text(&ErrorMsg {
            kind: "error",
            error: m,
        })]
    };
    let Ok(j) = serde_json::from_str::<Json>(text) else {
        return err("malformed JSON command".into());
    };
    if let Some(sub) = j.get("subscribe") {
        c.wanted = match sub {
            Json::String(s) if s == "*" => Wanted::All,
            Json::Array(a) if a.len() > MAX_NAMES => {
                return err(format!("`subscribe` lists {} names: at most {MAX_NAMES}", a.len()));
            }
            Json::Array(a) => {
                let mut names: Vec<String> = a.iter().filter_map(|v| v.as_str().map(str::to_string)).collect();
                let mut seen = std::collections::HashSet::new();
                names.retain(|n| seen.insert(n.clone()));
                Wanted::Names(names)
            }
            _ => return err("`subscribe` takes \"*\" or an array of tag names".into()),
        };
        c.subs.clear();
        let program = st.runtime.snapshot().program.clone();
        let unknown = c.resolve(&program);
        // Counted with this client's new subscription in: over the server's
        // budget, it follows nothing.
        let total = st.subscribed.load(Ordering::Relaxed);
        if total > MAX_SERVER_VALUES {
            let n = c.subs.len();
            c.wanted = Wanted::Nothing;
            c.subs.clear();
            c.counted.set(&c.subs);
            return err(format!(
                "this subscription of {n} values would make {total} for all live clients, more than {MAX_SERVER_VALUES}: \
                 subscribe to fewer"
            ));
        }
        if !unknown.is_empty() {
            return err(format!("unknown tags: {}", unknown.join(", ")));
        }
        return Vec::new();
    }
    if let Some(m) = j.get("monitor") {
        let Some(a) = m.as_array() else {
            return err("`monitor` takes an array of program names".into());
        };
        c.monitor = Vec::new();
        for name in a.iter().filter_map(Json::as_str) {
            if !c.monitor.iter().any(|m| m.eq_ignore_ascii_case(name)) {
                c.monitor.push(name.to_string());
            }
        }
        c.power_sent.clear();
        let program = st.runtime.snapshot().program.clone();
        let unknown: Vec<&str> = c
            .monitor
            .iter()
            .filter(|n| !program.units.iter().any(|u| u.name.eq_ignore_ascii_case(n)))
            .map(String::as_str)
            .collect();
        if !unknown.is_empty() {
            return err(format!("unknown programs: {}", unknown.join(", ")));
        }
        return Vec::new();
    }
    err("unknown command: expected `subscribe` or `monitor`".into())
}
