//! `/api/ws`: live values, power flow and status (docs/api.md).
//!
//! Each client task waits on the runtime's snapshot channel, which keeps
//! only the latest snapshot: a client that falls behind skips scans and
//! gets one message with everything that changed meanwhile, so no queue
//! grows and the engine never waits. A client that cannot take a message
//! for 5 s is disconnected.

use crate::{AppState, project, status_json, tags};
use alba_ir::{Place, Program, Target};
use alba_runtime::Snapshot;
use alba_runtime::json::to_json;
use axum::extract::State;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::response::Response;
use serde_json::{Map, Value as Json, json};
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

const SEND_TIMEOUT: Duration = Duration::from_secs(5);
const STATUS_EVERY: Duration = Duration::from_millis(500);

pub async fn upgrade(ws: WebSocketUpgrade, State(st): State<Arc<AppState>>) -> Response {
    ws.max_message_size(64 * 1024)
        .on_upgrade(move |socket| client(socket, st))
}

enum Wanted {
    Nothing,
    All,
    Names(Vec<String>),
}

/// One client's view: what it asked for and what it was last sent.
struct Client {
    wanted: Wanted,
    /// Resolved for `program`.
    places: Vec<(String, Place)>,
    program: Option<Arc<Program>>,
    sent: HashMap<String, Json>,
    monitor: Vec<String>,
    /// Element ids of each unit of `program`.
    units: Vec<std::ops::Range<u32>>,
    power_sent: HashMap<String, Vec<u32>>,
    status_at: Option<Instant>,
    status_state: &'static str,
}

impl Client {
    /// Re-resolves the subscription after a program change; unknown names
    /// are returned.
    fn resolve(&mut self, program: &Arc<Program>) -> Vec<String> {
        let layout = &program.layout;
        let mut unknown = Vec::new();
        self.places = match &self.wanted {
            Wanted::Nothing => Vec::new(),
            Wanted::All => tags::every_value(layout),
            Wanted::Names(names) => names
                .iter()
                .flat_map(|n| match layout.resolve(n) {
                    Ok(Target::Value { place, .. }) => vec![(n.clone(), place)],
                    Ok(Target::Timer(t)) => tags::members(alba_model::DataType::Timer, t.i, t.b)
                        .into_iter()
                        .map(|(m, p)| (format!("{n}.{m}"), p))
                        .collect(),
                    Ok(Target::Counter(c)) => tags::members(alba_model::DataType::Counter, c.i, c.b)
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
        self.units = project::unit_elements(program);
        self.program = Some(program.clone());
        unknown
    }

    /// The messages `s` calls for.
    fn updates(&mut self, s: &Snapshot, st: &AppState) -> Vec<Json> {
        let mut out = Vec::new();
        if !self.program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &s.program)) {
            self.resolve(&s.program);
            self.power_sent.clear();
        }
        let mut values = Map::new();
        for (name, place) in &self.places {
            let v = to_json(s.read(*place));
            if self.sent.get(name) != Some(&v) {
                self.sent.insert(name.clone(), v.clone());
                values.insert(name.clone(), v);
            }
        }
        if !values.is_empty() {
            out.push(json!({"type": "values", "scan": s.scans, "t_ms": s.unix_ms, "values": values}));
        }
        // Not running: nothing is energised.
        if s.power.is_some() || s.state != alba_runtime::RunState::Running {
            for name in &self.monitor {
                let Some(unit) = s.program.units.iter().position(|u| u.name.eq_ignore_ascii_case(name)) else {
                    continue;
                };
                let range = self.units.get(unit).cloned().unwrap_or(0..0);
                let on: Vec<u32> = range.filter(|e| s.energised(*e) == Some(true)).collect();
                if self.power_sent.get(name) != Some(&on) {
                    out.push(json!({"type": "power", "scan": s.scans, "program": name, "on": on}));
                    self.power_sent.insert(name.clone(), on);
                }
            }
        }
        let state = s.state.name();
        if state != self.status_state || self.status_at.is_none_or(|t| t.elapsed() >= STATUS_EVERY) {
            let mut j = status_json(s, st);
            j["type"] = json!("status");
            out.push(j);
            self.status_at = Some(Instant::now());
            self.status_state = state;
        }
        out
    }
}

async fn send(socket: &mut WebSocket, msgs: Vec<Json>) -> bool {
    for m in msgs {
        let sent = tokio::time::timeout(SEND_TIMEOUT, socket.send(Message::Text(m.to_string().into()))).await;
        if !matches!(sent, Ok(Ok(()))) {
            return false;
        }
    }
    true
}

async fn client(mut socket: WebSocket, st: Arc<AppState>) {
    st.clients.fetch_add(1, Ordering::Relaxed);
    let mut rx = st.runtime.subscribe();
    let mut c = Client {
        wanted: Wanted::Nothing,
        places: Vec::new(),
        program: None,
        sent: HashMap::new(),
        monitor: Vec::new(),
        units: Vec::new(),
        power_sent: HashMap::new(),
        status_at: None,
        status_state: "",
    };
    let mut monitoring = false;
    let mut closing = st.closing.subscribe();
    loop {
        let msgs = tokio::select! {
            _ = closing.wait_for(|c| *c) => break,
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
fn command(c: &mut Client, st: &AppState, text: &str) -> Vec<Json> {
    let err = |m: String| vec![json!({"type": "error", "error": m})];
    let Ok(j) = serde_json::from_str::<Json>(text) else {
        return err("malformed JSON command".into());
    };
    if let Some(sub) = j.get("subscribe") {
        c.wanted = match sub {
            Json::String(s) if s == "*" => Wanted::All,
            Json::Array(a) => Wanted::Names(a.iter().filter_map(|v| v.as_str().map(str::to_string)).collect()),
            _ => return err("`subscribe` takes \"*\" or an array of tag names".into()),
        };
        c.sent.clear();
        let program = st.runtime.snapshot().program.clone();
        let unknown = c.resolve(&program);
        if !unknown.is_empty() {
            return err(format!("unknown tags: {}", unknown.join(", ")));
        }
        return Vec::new();
    }
    if let Some(m) = j.get("monitor") {
        let Some(a) = m.as_array() else {
            return err("`monitor` takes an array of program names".into());
        };
        c.monitor = a.iter().filter_map(|v| v.as_str().map(str::to_string)).collect();
        c.power_sent.clear();
        return Vec::new();
    }
    err("unknown command: expected `subscribe` or `monitor`".into())
}
