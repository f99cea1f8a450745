//! `[mqtt.sparkplug]`: `alba run` as a Sparkplug B 3.0 edge node
//! (docs/scale-out.md "Sparkplug B"). The node `spBv1.0/<group>/…/<node>`
//! has the devices of `[mqtt.sparkplug.devices]` and a default device with
//! the other published tags, each tag a metric (members as `Tag/MEMBER`).
//! On each connection: NBIRTH (bdSeq, `Node Control/Rebirth`) then a DBIRTH
//! per device (every metric with name, alias, type, value), `seq` from 0
//! wrapping at 255; changes as DDATA by alias, one message per device and
//! snapshot; the NDEATH registered as the connection's last will carries the
//! same bdSeq, which grows by one per connection and is kept across runs in
//! `.alba/sparkplug.json`. NCMD `Node Control/Rebirth = true` sends the
//! births again; DCMD writes a device's metrics with the HTTP API's rules.
//!
//! With `primary_host_id` the node is born only while that host's
//! `spBv1.0/STATE/<host>` says it is online; an offline STATE makes it send
//! its NDEATH and reconnect to wait. While it is not born (the host offline,
//! or no broker) each snapshot's changes go to the store-and-forward buffer
//! on disk ([`store`]); after the next birth they are sent, oldest first, as
//! DDATA flagged historical with their own timestamps, and then live data
//! goes on. The codec is `alba-sparkplug` (no I/O).

mod store;

use crate::Service;
use crate::mqtt::client::{self, Client, Ev, Will};
use crate::mqtt::{Credentials, Settings, Stats, backoff, goodbye, is_of, moved, pause, published, write};
use alba_model::Value;
use alba_sparkplug::{EdgeNode, HostState, PrimaryHost, REBIRTH, Value as SpValue};
use rumqttc::QoS;
use serde_json::Value as Json;
use std::collections::HashMap;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;
use store::Store;

/// What `[mqtt.sparkplug]` resolved to.
#[derive(Debug, Clone)]
pub(crate) struct SpSettings {
    pub group: String,
    pub node: String,
    pub device: String,
    /// Devices of their own and their tags; the rest is in `device`.
    pub devices: Vec<(String, Vec<String>)>,
    pub primary_host: Option<String>,
    pub buffer_max: u64,
}

/// Buffered records sent per wake of the publisher at most (it wakes at
/// least every [`REPLAY_TICK`] while replaying), so that a long replay
/// does not hold the session's lock for long.
const REPLAY_BATCH: usize = 500;
const REPLAY_TICK: Duration = Duration::from_millis(10);

/// A tag's value as a Sparkplug metric value.
fn metric_value(v: Value) -> SpValue {
    match v {
        Value::Bool(b) => SpValue::Bool(b),
        Value::Sint(x) => SpValue::Int8(x),
        Value::Int(x) => SpValue::Int16(x),
        Value::Dint(x) => SpValue::Int32(x),
        Value::Time(x) => SpValue::Int32(x),
        Value::Lint(x) => SpValue::Int64(x),
        Value::Real(x) => SpValue::Float(x),
        Value::Lreal(x) => SpValue::Double(x),
    }
}

/// Whether `new` is worth publishing after `old` (`[mqtt] deadband`, as
/// in JSON mode: REAL and LREAL move more than it, others change).
fn worth(old: Option<&SpValue>, new: &SpValue, deadband: f64) -> bool {
    match (old, new) {
        (None, _) => true,
        (Some(SpValue::Float(a)), SpValue::Float(b)) => moved(f64::from(*a), f64::from(*b), deadband),
        (Some(SpValue::Double(a)), SpValue::Double(b)) => moved(*a, *b, deadband),
        (Some(o), n) => o != n,
    }
}

/// A received metric value as the JSON the write rules take.
fn json_value(v: SpValue) -> Json {
    match v {
        SpValue::Bool(b) => Json::Bool(b),
        SpValue::Int8(x) => x.into(),
        SpValue::Int16(x) => x.into(),
        SpValue::Int32(x) => x.into(),
        SpValue::Int64(x) => x.into(),
        SpValue::UInt64(x) => x.into(),
        SpValue::Float(x) => serde_json::Number::from_f64(f64::from(x)).map_or(Json::Null, Json::Number),
        SpValue::Double(x) => serde_json::Number::from_f64(x).map_or(Json::Null, Json::Number),
    }
}

/// Metric names: a member `Delay.ACC` is `Delay/ACC` (Sparkplug's folders).
fn metric_name(tag: &str) -> String {
    tag.replace('.', "/")
}

/// The published values of `layout` by device, each as (metric name,
/// place): the devices of `[mqtt.sparkplug.devices]` in their order, then
/// the default device with the rest (left out when nothing is left). A name
/// listed by no tag is left out here; [`check_devices`] refuses it at start.
fn by_device(
    layout: &alba_ir::Layout,
    set: &Settings,
    sp: &SpSettings,
) -> Vec<(String, Vec<(String, alba_ir::Place)>)> {
    let mut rest = published(layout, &set.tags);
    let mut out = Vec::new();
    for (device, tags) in &sp.devices {
        let (mine, others) = rest.into_iter().partition(|(n, _)| tags.iter().any(|t| is_of(n, t)));
        rest = others;
        out.push((device.clone(), named(mine)));
    }
    if !rest.is_empty() || out.is_empty() {
        out.push((sp.device.clone(), named(rest)));
    }
    out
}

fn named(places: Vec<(String, alba_ir::Place)>) -> Vec<(String, alba_ir::Place)> {
    places.into_iter().map(|(n, p)| (metric_name(&n), p)).collect()
}

/// `[mqtt.sparkplug.devices]` against the program: every name a published
/// tag, in one device only, no device twice or the default one again.
fn check_devices(layout: &alba_ir::Layout, set: &Settings, sp: &SpSettings) -> Result<(), String> {
    let published = published(layout, &set.tags);
    let mut owner: HashMap<String, &str> = HashMap::new();
    for (device, tags) in &sp.devices {
        if device == &sp.device {
            return Err(format!(
                "[mqtt.sparkplug.devices] {device}: the default device (device_id) holds the tags no device lists"
            ));
        }
        for t in tags {
            let mine: Vec<&String> = published.iter().map(|(n, _)| n).filter(|n| is_of(n, t)).collect();
            if mine.is_empty() {
                return Err(format!(
                    "[mqtt.sparkplug.devices] {device}: `{t}` is not a published tag (see [mqtt] tags)"
                ));
            }
            for n in mine {
                if let Some(other) = owner.insert(n.to_ascii_lowercase(), device)
                    && other != device
                {
                    return Err(format!(
                        "[mqtt.sparkplug.devices]: `{n}` is in both {other} and {device}"
                    ));
                }
            }
        }
    }
    Ok(())
}

fn now_ms() -> u64 {
    u64::try_from(alba_server::now_ms()).unwrap_or(0)
}

/// The state both tasks share: the codec's node, whether it is born on this
/// connection, and the primary host as its STATE said.
struct Session {
    node: EdgeNode,
    /// Births sent on this connection: DDATA may flow.
    born: bool,
    /// Set by a birth: the values it carried, the publisher's new baseline.
    birth: Option<HashMap<String, SpValue>>,
    host: PrimaryHost,
    /// `.alba/sparkplug.json`: the bdSeq of the latest connection, so that
    /// the next `alba run` goes on from it.
    bd_file: std::path::PathBuf,
}

impl Session {
    /// The connection is over: the next one has the next bdSeq, saved
    /// before it is registered in its will.
    fn next_connection(&mut self) {
        self.born = false;
        self.node.disconnected();
        self.save_bd_seq();
    }

    fn save_bd_seq(&self) {
        let body = serde_json::json!({ "bd_seq": self.node.bd_seq() }).to_string();
        if let Err(e) = alba_model::fsutil::write_atomic(&self.bd_file, |w| w.write_all(body.as_bytes())) {
            eprintln!(
                "mqtt: cannot save the Sparkplug bdSeq in {}: {e} (the next run may repeat it)",
                self.bd_file.display()
            );
        }
    }
}

/// The bdSeq saved by the last run, if any; a damaged file is said and ignored.
fn load_bd_seq(path: &std::path::Path) -> Option<u64> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => {
            eprintln!("mqtt: cannot read {}: {e}; bdSeq starts at 0", path.display());
            return None;
        }
    };
    let v = serde_json::from_str::<Json>(&text)
        .ok()
        .and_then(|j| j.get("bd_seq")?.as_u64())
        .filter(|v| *v < 256);
    if v.is_none() {
        eprintln!("mqtt: {} is not a saved bdSeq; bdSeq starts at 0", path.display());
    }
    v
}

type Shared = Arc<Mutex<Session>>;

fn lock(s: &Shared) -> MutexGuard<'_, Session> {
    s.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Publishes NBIRTH and DBIRTH with the current values; the session is born.
/// Births and data go at QoS 0, as Sparkplug 3.0 requires.
fn birth(s: &mut Session, client: &Client, st: &alba_server::AppState, set: &Settings, sp: &SpSettings) {
    let snap = st.runtime.snapshot();
    let devices: Vec<(String, Vec<(String, SpValue)>)> = by_device(&snap.program.layout, set, sp)
        .into_iter()
        .map(|(d, m)| (d, m.into_iter().map(|(n, p)| (n, metric_value(snap.read(p)))).collect()))
        .collect();
    let (nbirth, dbirths) = s.node.birth(now_ms(), &devices);
    let mut sent = client.try_publish(s.node.topic("NBIRTH"), QoS::AtMostOnce, false, nbirth);
    for (device, dbirth) in dbirths {
        sent = sent
            .and_then(|()| client.try_publish(s.node.device_topic("DBIRTH", &device), QoS::AtMostOnce, false, dbirth));
    }
    if let Err(e) = sent {
        eprintln!("mqtt: the births could not be queued ({e}); a rebirth request or the next connection sends them");
        return;
    }
    s.born = true;
    s.birth = Some(devices.into_iter().flat_map(|(_, m)| m).collect());
    eprintln!("mqtt: Sparkplug B node born (bdSeq {})", s.node.bd_seq());
}

pub(crate) fn start(s: &Service<'_>, set: Settings, stats: Arc<Stats>) -> Result<(), String> {
    let Some(sp) = set.sparkplug.clone() else {
        return Ok(());
    };
    let store = match &sp.primary_host {
        Some(_) => Some(Store::open(
            &s.dir.join(".alba").join("sparkplug-buffer.db"),
            sp.buffer_max,
        )?),
        None => None,
    };
    if let Some(st) = &store {
        stats.buffered.store(st.len(), Ordering::Relaxed);
    }
    check_devices(&s.state.runtime.snapshot().program.layout, &set, &sp)?;
    let mut node = EdgeNode::new(&sp.group, &sp.node);
    let bd_file = s.dir.join(".alba").join("sparkplug.json");
    if let Some(last) = load_bd_seq(&bd_file) {
        node.resume_after(last);
    }
    let session = Arc::new(Mutex::new(Session {
        node,
        born: false,
        birth: None,
        host: PrimaryHost::default(),
        bd_file,
    }));
    lock(&session).save_bd_seq();
    let death = |n: &EdgeNode| Will {
        topic: n.topic("NDEATH"),
        payload: n.death(now_ms()),
        qos: QoS::AtLeastOnce,
        retain: false,
    };
    let (client, mut eventloop) = client::new(&set, death(&lock(&session).node));
    println!(
        "mqtt: Sparkplug B edge node {}/{} (bdSeq {}) on {}:{}{}",
        sp.group,
        sp.node,
        lock(&session).node.bd_seq(),
        set.host,
        set.port,
        sp.primary_host
            .as_ref()
            .map(|h| format!(", primary host {h}"))
            .unwrap_or_default()
    );
    let state_topic = sp.primary_host.as_deref().map(alba_sparkplug::state_topic);
    let set = Arc::new(set);
    // Wakes the publisher on a birth (a replay may be due).
    let wake = Arc::new(tokio::sync::Notify::new());

    // The event loop: births on connection (or on the host's online STATE),
    // commands, back-off.
    let spc = sp.clone();
    let (st, c, cfg, sess, woken, sts) = (
        s.state.clone(),
        client.clone(),
        set.clone(),
        session.clone(),
        wake.clone(),
        stats.clone(),
    );
    let mut closing = s.state.closing();
    let mut creds = set.credentials.clone();
    tokio::spawn(async move {
        let mut wait = Duration::from_millis(100);
        let mut leaving = false;
        loop {
            let ev = tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                ev = eventloop.poll() => ev,
            };
            match ev {
                Ok(Ev::Connected) => {
                    wait = Duration::from_millis(100);
                    sts.connected_now();
                    if let Some(h) = &spc.primary_host {
                        Stats::set(
                            &sts.held,
                            Some(format!("waiting for the primary host {h} to be online")),
                        );
                    }
                    let mut s = lock(&sess);
                    let _ = c.try_subscribe(s.node.topic("NCMD"), QoS::AtLeastOnce);
                    if cfg.writes {
                        let _ = c.try_subscribe(s.node.device_topic("DCMD", "+"), QoS::AtLeastOnce);
                    }
                    match &state_topic {
                        // Born once the host's STATE (retained) says online.
                        Some(t) => {
                            let _ = c.try_subscribe(t.as_str(), QoS::AtLeastOnce);
                        }
                        None => birth(&mut s, &c, &st, &cfg, &spc),
                    }
                    drop(s);
                    woken.notify_one();
                }
                Ok(Ev::Message { topic, payload, .. }) => {
                    if state_topic.as_deref() == Some(topic.as_str()) {
                        let state = match HostState::parse(&payload) {
                            Ok(h) => h,
                            Err(e) => {
                                eprintln!("mqtt: {topic}: {e}");
                                continue;
                            }
                        };
                        let mut s = lock(&sess);
                        if !s.host.update(state) {
                            continue;
                        }
                        if state.online {
                            Stats::set(&sts.held, None);
                        } else if let Some(h) = &spc.primary_host {
                            Stats::set(&sts.held, Some(format!("the primary host {h} is offline: buffering")));
                        }
                        if state.online && !s.born {
                            birth(&mut s, &c, &st, &cfg, &spc);
                            drop(s);
                            woken.notify_one();
                        } else if !state.online && s.born {
                            // Sparkplug 3.0 §5.4: an NDEATH, then a new session
                            // that waits for the host; data is buffered meanwhile.
                            s.born = false;
                            let _ =
                                c.try_publish(s.node.topic("NDEATH"), QoS::AtLeastOnce, false, s.node.death(now_ms()));
                            let _ = c.try_disconnect();
                            leaving = true;
                            eprintln!("mqtt: the primary host is offline: NDEATH sent; buffering until it is back");
                        }
                        continue;
                    }
                    let cmds = match lock(&sess).node.command(&payload) {
                        Ok(c) => c,
                        Err(e) => {
                            eprintln!("mqtt: {topic}: {e}");
                            continue;
                        }
                    };
                    let topic = alba_sparkplug::Topic::parse(&topic);
                    match topic.as_ref().map(|t| (t.kind.as_str(), t.device.as_deref())) {
                        Some(("NCMD", None))
                            if cmds
                                .iter()
                                .any(|(name, v)| name == REBIRTH && *v == SpValue::Bool(true)) =>
                        {
                            let mut s = lock(&sess);
                            // Not while the primary host is offline: the node waits for it.
                            if s.born {
                                birth(&mut s, &c, &st, &cfg, &spc);
                                drop(s);
                                woken.notify_one();
                            }
                        }
                        Some(("DCMD", Some(device))) => {
                            for (name, v) in cmds {
                                // A device writes its own metrics only.
                                let of = lock(&sess).node.device_of(&name).map(str::to_string);
                                let result = match of {
                                    Some(d) if d == device => {
                                        write(&st, &cfg, &name.replace('/', "."), &json_value(v)).await
                                    }
                                    Some(d) => Err(format!("it is a metric of device {d}")),
                                    None => Err("no such metric".to_string()),
                                };
                                if let Err(e) = result {
                                    eprintln!("mqtt: DCMD {device} {name}: refused: {e}");
                                }
                            }
                        }
                        _ => {}
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    if sts.connected.swap(false, Ordering::Relaxed) && !leaving {
                        eprintln!("mqtt: connection lost ({e}); reconnecting");
                    }
                    if !leaving {
                        sts.failed(&e);
                    }
                    leaving = false;
                    // The next connection has the next bdSeq, in its will and its NBIRTH;
                    // nothing of the old session is sent again (a new birth comes first).
                    let will = {
                        let mut s = lock(&sess);
                        s.next_connection();
                        death(&s.node)
                    };
                    eventloop.renew(Some(will), creds.as_mut().map(Credentials::refresh));
                    let (w, next) = backoff(wait);
                    wait = next;
                    tokio::select! {
                        _ = closing.wait_for(|c| *c) => break,
                        _ = tokio::time::sleep(w) => {}
                    }
                }
            }
        }
        // A clean goodbye: the NDEATH the broker would otherwise send.
        let (topic, death) = {
            let s = lock(&sess);
            (s.node.topic("NDEATH"), s.node.death(now_ms()))
        };
        goodbye(&c, eventloop, topic, false, death).await;
    });

    // The publisher: one DDATA per device and snapshot with what changed
    // since the birth; while not born, the changes go to the buffer (if any).
    let mut rx = s.state.runtime.subscribe();
    let mut closing = s.state.closing();
    let mut p = Publisher {
        session,
        client,
        st: s.state.clone(),
        set,
        sp,
        stats,
        store,
        program: None,
        devices: Vec::new(),
        last: None,
        replaying: false,
    };
    tokio::spawn(async move {
        loop {
            tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                r = rx.changed() => if r.is_err() { break },
                _ = wake.notified() => {}
                _ = tokio::time::sleep(REPLAY_TICK), if p.replaying => {}
            }
            let snap = rx.borrow_and_update().clone();
            if p.pass(&snap) && !pause(p.set.interval, &mut closing).await {
                break;
            }
        }
    });
    Ok(())
}

/// The publisher's state between snapshots.
struct Publisher {
    session: Shared,
    client: Client,
    st: Arc<alba_server::AppState>,
    set: Arc<Settings>,
    sp: SpSettings,
    stats: Arc<Stats>,
    store: Option<Store>,
    /// The program of the last snapshot and its metrics by device.
    program: Option<Arc<alba_ir::Program>>,
    devices: Vec<(String, Vec<(String, alba_ir::Place)>)>,
    /// What the host has (or will have, after the replay) of each metric.
    last: Option<HashMap<String, SpValue>>,
    replaying: bool,
}

impl Publisher {
    /// Each device's values of `snap` worth publishing after `last` (all of them without).
    fn changes(&self, snap: &alba_runtime::Snapshot) -> Vec<(String, Vec<(String, SpValue)>)> {
        let last = self.last.as_ref();
        self.devices
            .iter()
            .map(|(d, places)| {
                let c = places
                    .iter()
                    .map(|(n, p)| (n.clone(), metric_value(snap.read(*p))))
                    .filter(|(n, v)| last.is_none_or(|l| worth(l.get(n), v, self.set.deadband)))
                    .collect::<Vec<_>>();
                (d.clone(), c)
            })
            .filter(|(_, c)| !c.is_empty())
            .collect()
    }

    /// One pass over the latest snapshot: buffer its changes, replay, or
    /// publish them. Whether the pass took data (the interval then applies).
    fn pass(&mut self, snap: &alba_runtime::Snapshot) -> bool {
        if !self.program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &snap.program)) {
            self.devices = by_device(&snap.program.layout, &self.set, &self.sp);
            self.program = Some(snap.program.clone());
        }
        let t = u64::try_from(snap.unix_ms).unwrap_or(0);
        let session = self.session.clone();
        let mut s = lock(&session);
        if let Some(b) = s.birth.take() {
            self.last = Some(b);
            self.replaying = self.store.as_ref().is_some_and(|st| st.len() > 0);
        }
        if !s.born {
            drop(s);
            self.replaying = false;
            if self.store.is_none() {
                self.last = None;
                return false;
            }
            // Held: buffered from what the host last had (all of it, the first time).
            for (device, c) in self.changes(snap) {
                self.buffer(&device, t, &c);
                self.last.get_or_insert_default().extend(c);
            }
            return true;
        }
        if self.replaying
            && let Some(store) = self.store.as_mut()
        {
            self.replaying = replay(&mut s, store, &self.client, &self.stats);
            self.stats.buffered.store(store.len(), Ordering::Relaxed);
            if self.replaying {
                return false;
            }
        }
        if self.last.is_none() {
            return false;
        }
        for (device, c) in self.changes(snap) {
            // A metric not in the birth (an online edit added a tag): a rebirth.
            let Some(payload) = s.node.data(&device, t, &c) else {
                birth(&mut s, &self.client, &self.st, &self.set, &self.sp);
                break;
            };
            let topic = s.node.device_topic("DDATA", &device);
            match self.client.try_publish(topic, QoS::AtMostOnce, false, payload) {
                Ok(()) => {
                    self.stats.published.fetch_add(1, Ordering::Relaxed);
                    self.last.get_or_insert_default().extend(c);
                }
                // The queue is full: these changes go with a later snapshot.
                Err(_) => {
                    s.node.not_sent();
                    self.stats.deferred.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
        true
    }

    /// One record into the store-and-forward buffer.
    fn buffer(&mut self, device: &str, t: u64, values: &[(String, SpValue)]) {
        let Some(store) = self.store.as_mut() else { return };
        let dropped = match store.push(device, &alba_sparkplug::encode_record(t, values)) {
            Ok(dropped) => dropped,
            Err((dropped, e)) => {
                if self.stats.store_errors.fetch_add(1, Ordering::Relaxed) == 0 {
                    eprintln!("mqtt: the store-and-forward buffer cannot be written: {e}");
                }
                dropped
            }
        };
        self.stats.dropped.fetch_add(dropped, Ordering::Relaxed);
        self.stats.buffered.store(store.len(), Ordering::Relaxed);
    }
}

/// Sends buffered records, oldest first, as historical DDATA, as many as
/// the client's queue takes (at most [`REPLAY_BATCH`]); whether some are
/// left. A record that cannot be read is dropped (and counted).
fn replay(s: &mut Session, store: &mut Store, client: &Client, stats: &Stats) -> bool {
    let batch = match store.oldest(REPLAY_BATCH) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("mqtt: the store-and-forward buffer cannot be read: {e}");
            return false;
        }
    };
    let mut done = None;
    for (id, device, record) in &batch {
        match alba_sparkplug::decode_record(record) {
            Ok((t, values)) => {
                let (payload, left_out) = s.node.historical(device, t, &values);
                stats.dropped.fetch_add(left_out as u64, Ordering::Relaxed);
                if let Some(p) = payload {
                    if client
                        .try_publish(s.node.device_topic("DDATA", device), QoS::AtMostOnce, false, p)
                        .is_err()
                    {
                        // The queue is full: the rest at the next wake.
                        s.node.not_sent();
                        break;
                    }
                    stats.published.fetch_add(1, Ordering::Relaxed);
                    stats.replayed.fetch_add(1, Ordering::Relaxed);
                }
            }
            Err(e) => {
                eprintln!("mqtt: a buffered record is dropped: {e}");
                stats.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
        done = Some(*id);
    }
    if let Some(id) = done
        && let Err(e) = store.remove_through(id)
    {
        eprintln!("mqtt: the store-and-forward buffer cannot be updated: {e}");
        return false;
    }
    store.len() > 0
}
