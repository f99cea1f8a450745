//! `[mqtt.sparkplug]`: `alba run` as a Sparkplug B 3.0 edge node
//! (docs/scale-out.md "Sparkplug B"). The node `spBv1.0/<group>/…/<node>`
//! has one device holding every published tag as a metric (members as
//! `Tag/MEMBER`). On each connection: NBIRTH (bdSeq, `Node Control/Rebirth`)
//! then DBIRTH (every metric with name, alias, type, value), `seq` from 0
//! wrapping at 255; changes as DDATA by alias, one message per snapshot; the
//! NDEATH registered as the connection's last will carries the same bdSeq,
//! which grows by one per connection. NCMD `Node Control/Rebirth = true`
//! sends the births again; DCMD writes metrics with the HTTP API's rules.
//!
//! With `primary_host_id` the node is born only while that host's
//! `spBv1.0/STATE/<host>` says it is online; an offline STATE makes it send
//! its NDEATH and reconnect to wait. While it is not born (the host offline,
//! or no broker) each snapshot's changes go to the store-and-forward buffer
//! on disk ([`store`]); after the next birth they are sent, oldest first, as
//! DDATA flagged historical with their own timestamps, and then live data
//! goes on. The codec is `alba-sparkplug` (no I/O).

mod store;

use crate::mqtt::{Settings, Stats, backoff, goodbye, options, published, write};
use crate::{Service, Started};
use alba_model::Value;
use alba_sparkplug::{EdgeNode, HostState, PrimaryHost, REBIRTH, Value as SpValue};
use rumqttc::{AsyncClient, Event, LastWill, Packet, QoS};
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
}

type Shared = Arc<Mutex<Session>>;

fn lock(s: &Shared) -> MutexGuard<'_, Session> {
    s.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Publishes NBIRTH and DBIRTH with the current values; the session is born.
/// Births and data go at QoS 0, as Sparkplug 3.0 requires.
fn birth(s: &mut Session, client: &AsyncClient, st: &alba_server::AppState, set: &Settings) {
    let snap = st.runtime.snapshot();
    let m: Vec<(String, SpValue)> = published(&snap.program.layout, &set.tags)
        .into_iter()
        .map(|(n, p)| (metric_name(&n), metric_value(snap.read(p))))
        .collect();
    let (nbirth, dbirth) = s.node.birth(now_ms(), &m);
    let sent = client
        .try_publish(s.node.topic("NBIRTH"), QoS::AtMostOnce, false, nbirth)
        .and_then(|()| client.try_publish(s.node.topic("DBIRTH"), QoS::AtMostOnce, false, dbirth));
    if let Err(e) = sent {
        eprintln!("mqtt: the births could not be queued ({e}); they go again on the next connection");
        return;
    }
    s.born = true;
    s.birth = Some(m.into_iter().collect());
    eprintln!("mqtt: Sparkplug B node born (bdSeq {})", s.node.bd_seq());
}

pub(crate) fn start(s: &Service<'_>, set: Settings, stats: Arc<Stats>) -> Result<Started, String> {
    let Some(sp) = set.sparkplug.clone() else {
        return Ok(Started::Off);
    };
    let mut store = match &sp.primary_host {
        Some(_) => Some(Store::open(
            &s.dir.join(".alba").join("sparkplug-buffer.db"),
            sp.buffer_max,
        )?),
        None => None,
    };
    if let Some(st) = &store {
        stats.buffered.store(st.len(), Ordering::Relaxed);
    }
    let session = Arc::new(Mutex::new(Session {
        node: EdgeNode::new(&sp.group, &sp.node, &sp.device),
        born: false,
        birth: None,
        host: PrimaryHost::default(),
    }));
    let death = |n: &EdgeNode| LastWill::new(n.topic("NDEATH"), n.death(now_ms()), QoS::AtLeastOnce, false);
    let (client, mut eventloop) = AsyncClient::new(options(&set, death(&lock(&session).node)), set.queue);
    println!(
        "mqtt: Sparkplug B edge node {}/{} (device {}) on {}:{}{}",
        sp.group,
        sp.node,
        sp.device,
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
    let (st, c, cfg, sess, woken, sts) = (
        s.state.clone(),
        client.clone(),
        set.clone(),
        session.clone(),
        wake.clone(),
        stats.clone(),
    );
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        let mut wait = Duration::from_millis(100);
        let mut leaving = false;
        loop {
            let ev = tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                ev = eventloop.poll() => ev,
            };
            match ev {
                Ok(Event::Incoming(Packet::ConnAck(_))) => {
                    wait = Duration::from_millis(100);
                    sts.connected.store(true, Ordering::Relaxed);
                    sts.connects.fetch_add(1, Ordering::Relaxed);
                    let mut s = lock(&sess);
                    let _ = c.try_subscribe(s.node.topic("NCMD"), QoS::AtLeastOnce);
                    if cfg.writes {
                        let _ = c.try_subscribe(s.node.topic("DCMD"), QoS::AtLeastOnce);
                    }
                    match &state_topic {
                        // Born once the host's STATE (retained) says online.
                        Some(t) => {
                            let _ = c.try_subscribe(t.as_str(), QoS::AtLeastOnce);
                        }
                        None => birth(&mut s, &c, &st, &cfg),
                    }
                    drop(s);
                    woken.notify_one();
                }
                Ok(Event::Incoming(Packet::Publish(p))) => {
                    if state_topic.as_deref() == Some(p.topic.as_str()) {
                        let state = match HostState::parse(&p.payload) {
                            Ok(h) => h,
                            Err(e) => {
                                eprintln!("mqtt: {}: {e}", p.topic);
                                continue;
                            }
                        };
                        let mut s = lock(&sess);
                        if !s.host.update(state) {
                            continue;
                        }
                        if state.online && !s.born {
                            birth(&mut s, &c, &st, &cfg);
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
                    let cmds = match lock(&sess).node.command(&p.payload) {
                        Ok(c) => c,
                        Err(e) => {
                            eprintln!("mqtt: {}: {e}", p.topic);
                            continue;
                        }
                    };
                    let (ncmd, dcmd) = {
                        let s = lock(&sess);
                        (s.node.topic("NCMD"), s.node.topic("DCMD"))
                    };
                    if p.topic == ncmd {
                        if cmds
                            .iter()
                            .any(|(name, v)| name == REBIRTH && *v == SpValue::Bool(true))
                        {
                            let mut s = lock(&sess);
                            // Not while the primary host is offline: the node waits for it.
                            if s.born {
                                birth(&mut s, &c, &st, &cfg);
                                drop(s);
                                woken.notify_one();
                            }
                        }
                    } else if p.topic == dcmd {
                        for (name, v) in cmds {
                            let tag = name.replace('/', ".");
                            if let Err(e) = write(&st, &cfg, &tag, &json_value(v)).await {
                                eprintln!("mqtt: DCMD {name}: refused: {e}");
                            }
                        }
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    if sts.connected.swap(false, Ordering::Relaxed) && !leaving {
                        eprintln!("mqtt: connection lost ({e}); reconnecting");
                        sts.errors.fetch_add(1, Ordering::Relaxed);
                    }
                    leaving = false;
                    // The next connection has the next bdSeq, in its will and its NBIRTH;
                    // nothing of the old session is sent again (a new birth comes first).
                    {
                        let mut s = lock(&sess);
                        s.born = false;
                        s.node.disconnected();
                        eventloop.mqtt_options.set_last_will(death(&s.node));
                    }
                    eventloop.clean();
                    eventloop.pending.clear();
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

    // The publisher: one DDATA per snapshot with what changed since the
    // birth; while not born, the changes go to the buffer (if any).
    let st = s.state.clone();
    let mut rx = s.state.runtime.subscribe();
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        let mut program = None;
        let mut places = Vec::new();
        // What the host has (or will have, after the replay) of each metric.
        let mut last: Option<HashMap<String, SpValue>> = None;
        let mut replaying = false;
        loop {
            tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                r = rx.changed() => if r.is_err() { break },
                _ = wake.notified() => {}
                _ = tokio::time::sleep(REPLAY_TICK), if replaying => {}
            }
            let snap = rx.borrow_and_update().clone();
            if !program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &snap.program)) {
                places = published(&snap.program.layout, &set.tags);
                program = Some(snap.program.clone());
            }
            let changes = |last: Option<&HashMap<String, SpValue>>| -> Vec<(String, SpValue)> {
                places
                    .iter()
                    .map(|(n, p)| (metric_name(n), metric_value(snap.read(*p))))
                    .filter(|(n, v)| last.is_none_or(|l| l.get(n) != Some(v)))
                    .collect()
            };
            let mut s = lock(&session);
            if let Some(b) = s.birth.take() {
                last = Some(b);
                replaying = store.as_ref().is_some_and(|st| st.len() > 0);
            }
            if !s.born {
                drop(s);
                replaying = false;
                let Some(store) = store.as_mut() else {
                    last = None;
                    continue;
                };
                // Held: buffered from what the host last had (all of it, the first time).
                let c = changes(last.as_ref());
                if c.is_empty() {
                    continue;
                }
                let record = alba_sparkplug::encode_record(u64::try_from(snap.unix_ms).unwrap_or(0), &c);
                match store.push(&sp.device, &record) {
                    Ok(dropped) => {
                        stats.dropped.fetch_add(dropped, Ordering::Relaxed);
                    }
                    Err((dropped, e)) => {
                        stats.dropped.fetch_add(dropped, Ordering::Relaxed);
                        if stats.store_errors.fetch_add(1, Ordering::Relaxed) == 0 {
                            eprintln!("mqtt: the store-and-forward buffer cannot be written: {e}");
                        }
                    }
                }
                stats.buffered.store(store.len(), Ordering::Relaxed);
                last.get_or_insert_default().extend(c);
                continue;
            }
            if replaying && let Some(store) = store.as_mut() {
                replaying = replay(&mut s, store, &client, &stats);
                stats.buffered.store(store.len(), Ordering::Relaxed);
                if replaying {
                    continue;
                }
            }
            let Some(last) = last.as_mut() else { continue };
            let c = changes(Some(last));
            if c.is_empty() {
                continue;
            }
            // A metric not in the birth (an online edit added a tag): a rebirth.
            let Some(payload) = s.node.data(u64::try_from(snap.unix_ms).unwrap_or(0), &c) else {
                birth(&mut s, &client, &st, &set);
                continue;
            };
            match client.try_publish(s.node.topic("DDATA"), QoS::AtMostOnce, false, payload) {
                Ok(()) => {
                    stats.published.fetch_add(1, Ordering::Relaxed);
                    last.extend(c);
                }
                // The queue is full: these changes go with a later snapshot.
                Err(_) => {
                    s.node.not_sent();
                    stats.deferred.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    });
    Ok(Started::On)
}

/// Sends buffered records, oldest first, as historical DDATA, as many as
/// the client's queue takes (at most [`REPLAY_BATCH`]); whether some are
/// left. A record that cannot be read is dropped (and counted).
fn replay(s: &mut Session, store: &mut Store, client: &AsyncClient, stats: &Stats) -> bool {
    let batch = match store.oldest(REPLAY_BATCH) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("mqtt: the store-and-forward buffer cannot be read: {e}");
            return false;
        }
    };
    let mut done = None;
    for (id, _device, record) in &batch {
        match alba_sparkplug::decode_record(record) {
            Ok((t, values)) => {
                let (payload, left_out) = s.node.historical(t, &values);
                stats.dropped.fetch_add(left_out as u64, Ordering::Relaxed);
                if let Some(p) = payload {
                    if client
                        .try_publish(s.node.topic("DDATA"), QoS::AtMostOnce, false, p)
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
