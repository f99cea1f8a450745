//! The edge node's messages decoded back with the same protobuf schema:
//! births, aliases, sequence numbers, death, commands.

use alba_sparkplug::proto::{Metric, Payload, metric};
use alba_sparkplug::{
    BD_SEQ, DataType, EdgeNode, HostState, PrimaryHost, REBIRTH, Topic, Value, decode_record, encode_record,
    state_topic,
};
use prost::Message;

fn metrics() -> Vec<(String, Value)> {
    vec![
        ("Start".into(), Value::Bool(true)),
        ("Level".into(), Value::Int16(-5)),
        ("Delay/ACC".into(), Value::Int32(-70_000)),
        ("Speed".into(), Value::Float(1.5)),
        ("Big".into(), Value::Int64(-1)),
    ]
}

/// One device, `d`, with every metric.
fn one(m: &[(String, Value)]) -> Vec<(String, Vec<(String, Value)>)> {
    vec![("d".to_string(), m.to_vec())]
}

#[test]
fn births_name_alias_and_type_every_metric() {
    let mut n = EdgeNode::new("plant", "line1");
    assert_eq!(n.topic("NBIRTH"), "spBv1.0/plant/NBIRTH/line1");
    assert_eq!(n.device_topic("DDATA", "plc"), "spBv1.0/plant/DDATA/line1/plc");
    let (nb, db) = n.birth(1000, &one(&metrics()));
    assert_eq!(db.len(), 1);
    let db = &db[0].1;
    let nb = Payload::decode(nb.as_slice()).expect("nbirth");
    assert_eq!(nb.seq, Some(0));
    assert_eq!(nb.metrics[0].name.as_deref(), Some(BD_SEQ));
    assert_eq!(nb.metrics[1].name.as_deref(), Some(REBIRTH));
    let db = Payload::decode(db.as_slice()).expect("dbirth");
    assert_eq!(db.seq, Some(1));
    let level = &db.metrics[1];
    assert_eq!((level.alias, level.datatype), (Some(1), Some(DataType::Int16 as u32)));
    // Two's complement in the 32-bit field, as Sparkplug 3.0 says.
    assert_eq!(level.value, Some(metric::Value::IntValue(0xFFFB)));
    assert_eq!(db.metrics[2].value, Some(metric::Value::IntValue((-70_000i32) as u32)));
    assert_eq!(db.metrics[4].value, Some(metric::Value::LongValue(u64::MAX)));
    for (m, (name, v)) in db.metrics.iter().zip(metrics()) {
        assert_eq!(m.name.as_deref(), Some(name.as_str()));
        let back = Value::decode(m.datatype.expect("type"), m.value.as_ref().expect("value")).expect("decode");
        assert_eq!(back, v);
    }
}

#[test]
fn data_goes_by_alias_and_seq_wraps() {
    let mut n = EdgeNode::new("g", "n");
    n.birth(0, &one(&metrics()));
    let mut last = 1;
    for k in 0..600u64 {
        let d = n
            .data("d", k, &[("Level".into(), Value::Int16(k as i16))])
            .expect("born");
        let d = Payload::decode(d.as_slice()).expect("ddata");
        let seq = d.seq.expect("seq");
        assert_eq!(seq, (last + 1) % 256);
        last = seq;
        assert_eq!((d.metrics[0].name.as_deref(), d.metrics[0].alias), (None, Some(1)));
    }
    assert!(
        n.data("d", 0, &[("Unborn".into(), Value::Bool(true))]).is_none(),
        "a rebirth is due"
    );
    assert!(
        n.data("e", 0, &[("Level".into(), Value::Int16(1))]).is_none(),
        "not a metric of that device"
    );
    // A rebirth restarts seq at 0 and keeps the aliases.
    let (nb, _) = n.birth(0, &one(&metrics()));
    assert_eq!(Payload::decode(nb.as_slice()).expect("nbirth").seq, Some(0));
}

#[test]
fn death_carries_the_births_bd_seq_and_grows_per_connection() {
    let mut n = EdgeNode::new("g", "n");
    let bd = |p: &[u8]| match Payload::decode(p).expect("payload").metrics[0].value {
        Some(metric::Value::LongValue(v)) => v,
        ref v => panic!("{v:?}"),
    };
    let will = n.death(0);
    let (nb, _) = n.birth(0, &one(&metrics()));
    assert_eq!(bd(&will), bd(&nb));
    n.disconnected();
    assert_eq!(bd(&n.death(0)), bd(&will) + 1);
    // Kept across restarts: a new run goes on after the last one, wrapping at 255.
    n.resume_after(41);
    assert_eq!(bd(&n.death(0)), 42);
    n.resume_after(255);
    assert_eq!(bd(&n.death(0)), 0);
}

#[test]
fn commands_by_name_or_alias_with_or_without_a_type() {
    let mut n = EdgeNode::new("g", "n");
    n.birth(0, &one(&metrics()));
    let cmd = Payload {
        metrics: vec![
            Metric {
                name: Some("Level".into()),
                value: Some(metric::Value::IntValue(0xFFFF)),
                ..Default::default()
            },
            Metric {
                alias: Some(3),
                datatype: Some(DataType::Float as u32),
                value: Some(metric::Value::FloatValue(2.5)),
                ..Default::default()
            },
        ],
        ..Default::default()
    };
    assert_eq!(
        n.command(&cmd.encode_to_vec()).expect("command"),
        [
            ("Level".to_string(), Value::Int16(-1)),
            ("Speed".to_string(), Value::Float(2.5))
        ]
    );
    for bad in [
        Payload {
            metrics: vec![Metric {
                alias: Some(99),
                value: Some(metric::Value::BooleanValue(true)),
                ..Default::default()
            }],
            ..Default::default()
        },
        Payload {
            metrics: vec![Metric {
                name: Some("X".into()),
                value: Some(metric::Value::BooleanValue(true)),
                ..Default::default()
            }],
            ..Default::default()
        },
        Payload {
            metrics: vec![Metric {
                name: Some("Level".into()),
                value: Some(metric::Value::StringValue("a".into())),
                ..Default::default()
            }],
            ..Default::default()
        },
        Payload {
            metrics: vec![Metric {
                name: Some("Level".into()),
                ..Default::default()
            }],
            ..Default::default()
        },
    ] {
        assert!(n.command(&bad.encode_to_vec()).is_err(), "{bad:?}");
    }
    assert!(n.command(b"\xff\xff\xff garbage").is_err());
    assert_eq!(
        Topic::parse("spBv1.0/g/DCMD/n/d"),
        Some(Topic {
            group: "g".into(),
            kind: "DCMD".into(),
            node: "n".into(),
            device: Some("d".into())
        })
    );
    assert_eq!(Topic::parse("spBv1.0/g/DCMD/n/d/x"), None);
    for empty in [
        "spBv1.0//DDATA/n",
        "spBv1.0/g//n",
        "spBv1.0/g/NDATA/",
        "spBv1.0/g/DDATA/n/",
    ] {
        assert_eq!(Topic::parse(empty), None, "{empty}: an empty level names nothing");
    }
}

#[test]
fn data_leaves_the_type_to_the_birth_and_an_unsent_seq_is_given_again() {
    let mut n = EdgeNode::new("g", "n");
    n.birth(0, &one(&metrics()));
    let d = Payload::decode(
        n.data("d", 5, &[("Level".into(), Value::Int16(3))])
            .expect("born")
            .as_slice(),
    )
    .expect("ddata");
    assert_eq!(
        (d.seq, d.metrics[0].datatype, d.metrics[0].is_historical),
        (Some(2), None, None)
    );
    n.not_sent();
    let d = Payload::decode(
        n.data("d", 6, &[("Level".into(), Value::Int16(4))])
            .expect("born")
            .as_slice(),
    )
    .expect("ddata");
    assert_eq!(d.seq, Some(2), "the queue did not take seq 2: the next message has it");
}

#[test]
fn stored_values_go_as_historical_data_with_their_time() {
    let record = encode_record(1234, &metrics());
    assert_eq!(decode_record(&record), Ok((1234, metrics())));
    assert!(decode_record(b"\xff\x01").is_err());
    let mut n = EdgeNode::new("g", "n");
    n.birth(2000, &one(&metrics()[..3]));
    // `Speed` is not in this birth, `Level` is born with another type: left out.
    let (p, left_out) = n.historical(
        "d",
        1234,
        &[
            ("Start".into(), Value::Bool(false)),
            ("Level".into(), Value::Int32(1)),
            ("Speed".into(), Value::Float(1.0)),
        ],
    );
    assert_eq!(left_out, 2);
    let p = Payload::decode(p.expect("one left").as_slice()).expect("ddata");
    assert_eq!((p.timestamp, p.seq), (Some(1234), Some(2)));
    let m = &p.metrics[0];
    assert_eq!(
        (m.alias, m.timestamp, m.is_historical, m.value.clone()),
        (
            Some(0),
            Some(1234),
            Some(true),
            Some(metric::Value::BooleanValue(false))
        )
    );
    assert_eq!(n.historical("d", 1, &[("Speed".into(), Value::Float(1.0))]), (None, 1));
    assert_eq!(
        n.historical("other", 1, &[("Start".into(), Value::Bool(true))]),
        (None, 1),
        "a value buffered for another device"
    );
    // A metric dropped from the program is not born again: its old values are left out.
    n.birth(3000, &one(&metrics()[..1]));
    assert_eq!(n.historical("d", 1, &[("Level".into(), Value::Int16(1))]), (None, 1));
}

#[test]
fn the_primary_hosts_state_counts_unless_it_is_older() {
    assert_eq!(state_topic("scada"), "spBv1.0/STATE/scada");
    let s = |online, timestamp| HostState { online, timestamp };
    assert_eq!(
        HostState::parse(br#"{"online": true, "timestamp": 17}"#),
        Ok(s(true, 17))
    );
    for bad in [
        &b"ONLINE"[..],
        br#"{"online": "yes", "timestamp": 1}"#,
        br#"{"online": true}"#,
    ] {
        assert!(HostState::parse(bad).is_err(), "{bad:?}");
    }
    let mut h = PrimaryHost::default();
    // The first message counts whatever its time.
    assert!(h.update(s(false, 100)) && !h.online);
    assert!(!h.update(s(true, 50)), "an online older than the last STATE is stale");
    assert!(h.update(s(true, 200)) && h.online);
    // A will carries its birth's timestamp: equal counts, older does not.
    assert!(!h.update(s(false, 150)) && h.online);
    assert!(h.update(s(false, 200)) && !h.online);
    assert!(h.update(s(true, 300)) && h.online);
}

#[test]
fn devices_have_their_own_births_and_aliases_unique_in_the_node() {
    let mut n = EdgeNode::new("g", "n");
    let m = metrics();
    let devices = vec![
        ("pumps".to_string(), m[..2].to_vec()),
        // `Start` again: the first device has it.
        ("line".to_string(), vec![m[2].clone(), m[0].clone()]),
    ];
    let (_, db) = n.birth(0, &devices);
    let decoded: Vec<(String, Payload)> = db
        .iter()
        .map(|(d, p)| (d.clone(), Payload::decode(p.as_slice()).expect("dbirth")))
        .collect();
    assert_eq!((decoded[0].0.as_str(), decoded[1].0.as_str()), ("pumps", "line"));
    assert_eq!((decoded[0].1.seq, decoded[1].1.seq), (Some(1), Some(2)));
    let names: Vec<_> = decoded[1].1.metrics.iter().map(|m| m.name.clone()).collect();
    assert_eq!(names, [Some("Delay/ACC".to_string())]);
    let aliases: Vec<_> = decoded
        .iter()
        .flat_map(|(_, p)| p.metrics.iter().map(|m| m.alias))
        .collect();
    assert_eq!(aliases, [Some(0), Some(1), Some(2)]);
    assert_eq!(
        (n.device_of("Start"), n.device_of("Delay/ACC")),
        (Some("pumps"), Some("line"))
    );
    assert!(n.data("line", 1, &[("Delay/ACC".into(), Value::Int32(1))]).is_some());
    assert!(n.data("line", 1, &[("Start".into(), Value::Bool(false))]).is_none());
}

proptest::proptest! {
    /// Any bytes as a command: an error or metrics, never a panic.
    #[test]
    fn any_bytes_as_a_command_never_panic(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..200)) {
        let mut n = EdgeNode::new("g", "n");
        n.birth(0, &one(&metrics()));
        let _ = n.command(&bytes);
    }
}
