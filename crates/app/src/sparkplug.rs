//! `[mqtt.sparkplug]`: `alba run` as a Sparkplug B 3.0 edge node
//! (docs/scale-out.md "Sparkplug B"). The node `spBv1.0/<group>/…/<node>`
//! has one device holding every published tag as a metric (members as
//! `Tag/MEMBER`). On each connection: NBIRTH (bdSeq, `Node Control/Rebirth`)
//! then DBIRTH (every metric with name, alias, type, value), `seq` from 0
//! wrapping at 255; changes as DDATA by alias, one message per snapshot; the
//! NDEATH registered as the connection's last will carries the same bdSeq,
//! which grows by one per connection. NCMD `Node Control/Rebirth = true`
//! sends the births again; DCMD writes metrics with the HTTP API's rules.
//! The codec is `alba-sparkplug` (no I/O).

use crate::mqtt::{Settings, backoff, goodbye, options, published, write};
use crate::{Service, Started};
use alba_model::Value;
use alba_sparkplug::{EdgeNode, REBIRTH, Value as SpValue};
use rumqttc::{AsyncClient, Event, LastWill, Packet, QoS};
use serde_json::Value as Json;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

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

/// Every published metric with its current value.
fn metrics(st: &alba_server::AppState, set: &Settings) -> Vec<(String, SpValue)> {
    let snap = st.runtime.snapshot();
    published(&snap.program.layout, &set.tags)
        .into_iter()
        .map(|(n, p)| (metric_name(&n), metric_value(snap.read(p))))
        .collect()
}

pub(crate) fn start(s: &Service<'_>, set: Settings) -> Result<Started, String> {
    let Some((group, node_id, device)) = set.sparkplug.clone() else {
        return Ok(Started::Off);
    };
    let node = Arc::new(Mutex::new(EdgeNode::new(&group, &node_id, &device)));
    let lock = |n: &Arc<Mutex<EdgeNode>>| -> EdgeNode { n.lock().unwrap_or_else(PoisonError::into_inner).clone() };
    let death = |n: &EdgeNode| LastWill::new(n.topic("NDEATH"), n.death(now_ms()), QoS::AtLeastOnce, false);
    let (client, mut eventloop) = AsyncClient::new(options(&set, death(&lock(&node))), set.queue);
    println!(
        "mqtt: Sparkplug B edge node {group}/{node_id} (device {device}) on {}:{}",
        set.host, set.port
    );
    let set = Arc::new(set);
    // Set on a (re)birth: the publisher's last values start from the birth's.
    let born = Arc::new(Mutex::new(None::<HashMap<String, SpValue>>));
    // Connected and born: the publisher sends DDATA only then.
    let up = Arc::new(AtomicBool::new(false));

    let birth = {
        let (node, client, set, born) = (node.clone(), client.clone(), set.clone(), born.clone());
        move |st: &alba_server::AppState| {
            let m = metrics(st, &set);
            let (nbirth, dbirth) = node.lock().unwrap_or_else(PoisonError::into_inner).birth(now_ms(), &m);
            let n = node.lock().unwrap_or_else(PoisonError::into_inner).clone();
            let _ = client.try_publish(n.topic("NBIRTH"), QoS::AtLeastOnce, false, nbirth);
            let _ = client.try_publish(n.topic("DBIRTH"), QoS::AtLeastOnce, false, dbirth);
            *born.lock().unwrap_or_else(PoisonError::into_inner) = Some(m.into_iter().collect());
        }
    };

    // The event loop: births on connection, commands, back-off.
    let (st, c, cfg, n, is_up) = (s.state.clone(), client.clone(), set.clone(), node.clone(), up.clone());
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        let mut wait = Duration::from_millis(100);
        let mut connected = false;
        loop {
            let ev = tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                ev = eventloop.poll() => ev,
            };
            match ev {
                Ok(Event::Incoming(Packet::ConnAck(_))) => {
                    wait = Duration::from_millis(100);
                    connected = true;
                    let node = lock(&n);
                    let _ = c.try_subscribe(node.topic("NCMD"), QoS::AtLeastOnce);
                    if cfg.writes {
                        let _ = c.try_subscribe(node.topic("DCMD"), QoS::AtLeastOnce);
                    }
                    // Up first: the publisher then waits for the births' values.
                    is_up.store(true, Ordering::SeqCst);
                    birth(&st);
                    eprintln!("mqtt: Sparkplug B node born (bdSeq {})", node.bd_seq());
                }
                Ok(Event::Incoming(Packet::Publish(p))) => {
                    let node = lock(&n);
                    let cmds = match node.command(&p.payload) {
                        Ok(c) => c,
                        Err(e) => {
                            eprintln!("mqtt: {}: {e}", p.topic);
                            continue;
                        }
                    };
                    if p.topic == node.topic("NCMD") {
                        if cmds
                            .iter()
                            .any(|(name, v)| name == REBIRTH && *v == SpValue::Bool(true))
                        {
                            birth(&st);
                        }
                    } else if p.topic == node.topic("DCMD") {
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
                    if connected {
                        connected = false;
                        eprintln!("mqtt: connection lost ({e}); reconnecting");
                    }
                    // The next connection has the next bdSeq, in its will and its NBIRTH;
                    // nothing of the old session is sent again (a new birth comes first).
                    is_up.store(false, Ordering::SeqCst);
                    n.lock().unwrap_or_else(PoisonError::into_inner).disconnected();
                    eventloop.mqtt_options.set_last_will(death(&lock(&n)));
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
        let node = lock(&n);
        goodbye(&c, eventloop, node.topic("NDEATH"), false, node.death(now_ms())).await;
    });

    // The publisher: one DDATA per snapshot with what changed since the birth.
    let mut rx = s.state.runtime.subscribe();
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        let mut program = None;
        let mut places = Vec::new();
        let mut last: Option<HashMap<String, SpValue>> = None;
        loop {
            tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                r = rx.changed() => if r.is_err() { break },
            }
            let snap = rx.borrow_and_update().clone();
            if !program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &snap.program)) {
                places = published(&snap.program.layout, &set.tags);
                program = Some(snap.program.clone());
            }
            if let Some(b) = born.lock().unwrap_or_else(PoisonError::into_inner).take() {
                last = Some(b);
            }
            if !up.load(Ordering::SeqCst) {
                last = None;
            }
            let Some(last) = last.as_mut() else { continue };
            let changes: Vec<(String, SpValue)> = places
                .iter()
                .map(|(n, p)| (metric_name(n), metric_value(snap.read(*p))))
                .filter(|(n, v)| last.get(n) != Some(v))
                .collect();
            if changes.is_empty() {
                continue;
            }
            let mut node = node.lock().unwrap_or_else(PoisonError::into_inner);
            // A metric not in the birth (an online edit added a tag): a rebirth is due.
            let Some(payload) = node.data(u64::try_from(snap.unix_ms).unwrap_or(0), &changes) else {
                continue;
            };
            if client.try_publish(node.topic("DDATA"), set.qos, false, payload).is_ok() {
                last.extend(changes);
            }
        }
    });
    Ok(Started::On)
}
