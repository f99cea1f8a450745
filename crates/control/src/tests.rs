//! The rules over a real runtime and a real audit log.

use super::*;
use alba_runtime::{Options, Runtime, SimIo};
use serde_json::json;
use std::sync::Arc;

const TAGS: &str = "name,type,address,initial,retain,description\n\
Start,BOOL,%IX0.0,,,\nMotor,BOOL,%QX0.0,,,\nLevel,INT,%IW2,,,\nSpeed,INT,,,,\nDelay,TIMER,,,,\n";
const LAD: &str = "XIC(Start)OTE(Motor);\nXIC(Motor)TON(Delay,50,0);\n";

struct Plc {
    runtime: Option<Runtime>,
    control: Control,
    _dir: tempfile::TempDir,
}

impl Drop for Plc {
    fn drop(&mut self) {
        if let Some(rt) = self.runtime.take() {
            rt.shutdown();
        }
    }
}

fn plc(with_audit: bool) -> Plc {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("alba.toml"),
        "name = \"c\"\nscan_ms = 5\nprograms = [\"main.lad\"]\n",
    )
    .expect("project");
    std::fs::write(dir.path().join("tags.csv"), TAGS).expect("project");
    std::fs::write(dir.path().join("main.lad"), LAD).expect("project");
    let c = alba_load::compile_dir(dir.path());
    let program = c.program.unwrap_or_else(|| panic!("{:?}", c.diagnostics));
    let runtime = Runtime::start(Arc::new(program), Options::new(5), Box::new(SimIo)).expect("runtime");
    let audit =
        with_audit.then(|| Audit::open(dir.path().join("audit.db"), alba_audit::Config::default()).expect("audit log"));
    let control = Control::new(runtime.handle(), audit);
    Plc {
        runtime: Some(runtime),
        control,
        _dir: dir,
    }
}

fn operator(via: Via) -> Actor {
    Actor {
        via,
        user: Some("ana".into()),
        role: Role::Operator,
        peer: Some("127.0.0.1:5000".into()),
    }
}

fn rows(c: &Control) -> Vec<alba_audit::Row> {
    c.audit()
        .expect("an audit log")
        .query(&alba_audit::Filter::default(), None, 100)
        .expect("query")
        .rows
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_write_is_checked_recorded_with_its_door_then_applied() {
    let p = plc(true);
    let v = p
        .control
        .write(&operator(Via::Mqtt), "Speed", &json!(1200))
        .await
        .expect("write");
    assert_eq!(v, json!(1200));
    assert_eq!(p.control.read("speed").expect("read"), json!(1200));
    let r = rows(&p.control);
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].action, "write");
    assert_eq!(r[0].target.as_deref(), Some("Speed"));
    assert_eq!(r[0].via.as_deref(), Some("mqtt"));
    assert_eq!(r[0].addr.as_deref(), Some("127.0.0.1:5000"));
    assert_eq!(r[0].old.as_deref(), Some("0"));
    assert_eq!(r[0].new.as_deref(), Some("1200"));
    assert_eq!(r[0].outcome, Outcome::Ok);
}

/// Each refusal, its kind, and nothing written nor recorded for it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn refusals_are_typed_and_leave_no_trace() {
    let p = plc(true);
    let viewer = Actor {
        role: Role::Viewer,
        ..operator(Via::Http)
    };
    type Case<'a> = (&'a Actor, &'a str, Json, fn(&Refused) -> bool);
    let cases: [Case; 6] = [
        (&operator(Via::Http), "Nope", json!(1), |e| {
            matches!(e, Refused::UnknownTag(_))
        }),
        (&operator(Via::Http), "Start", json!(true), |e| {
            matches!(e, Refused::NotWritable(_))
        }),
        (&operator(Via::Http), "Delay", json!(1), |e| {
            matches!(e, Refused::NotWritable(_))
        }),
        (&operator(Via::Http), "Speed", json!(40000), |e| {
            matches!(e, Refused::OutOfRange(_))
        }),
        (&operator(Via::Http), "Delay.PRE", json!(-5), |e| {
            matches!(e, Refused::OutOfRange(_))
        }),
        (&viewer, "Speed", json!(1), |e| matches!(e, Refused::Role { .. })),
    ];
    for (actor, name, value, kind) in cases {
        let e = p
            .control
            .write(actor, name, &value)
            .await
            .expect_err(&format!("{name} = {value} was written"));
        assert!(kind(&e), "{name} = {value}: {e:?}");
        assert!(!e.to_string().is_empty());
    }
    let e = p
        .control
        .write(&operator(Via::Http), "Speed", &json!("fast"))
        .await
        .expect_err("a string into an INT");
    assert!(matches!(e, Refused::WrongType(_)), "{e:?}");
    assert_eq!(p.control.read("Speed").expect("read"), json!(0));
    assert!(rows(&p.control).is_empty(), "refused writes left rows");
}

/// A write the audit cannot record is not done.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_write_the_audit_cannot_record_is_refused() {
    let p = plc(true);
    let path = p.control.audit().expect("audit").path().to_path_buf();
    let db = rusqlite::Connection::open(path).expect("open the audit log");
    db.execute_batch("CREATE TRIGGER full BEFORE INSERT ON audit BEGIN SELECT RAISE(ABORT, 'disk full'); END;")
        .expect("make inserts fail");
    let e = p.control.write(&operator(Via::Opcua), "Speed", &json!(7)).await;
    assert!(matches!(e, Err(Refused::AuditUnavailable(_))), "{e:?}");
    assert_eq!(
        p.control.read("Speed").expect("read"),
        json!(0),
        "the write was performed"
    );
    let s = p.control.runtime().snapshot();
    let place = writable(&s, "Speed").expect("Speed is writable");
    let c = p.control.clone();
    let peer: std::net::SocketAddr = "127.0.0.1:5020".parse().expect("address");
    let e = tokio::task::spawn_blocking(move || {
        c.write_places_blocking(&Actor::modbus(peer, Role::Operator), vec![(place, Value::Int(9))])
    })
    .await
    .expect("task");
    assert!(matches!(e, Err(Refused::AuditUnavailable(_))), "{e:?}");
    assert_eq!(
        p.control.read("Speed").expect("read"),
        json!(0),
        "the write was performed"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn modbus_writes_places_under_rows_named_by_their_tags() {
    let p = plc(true);
    let s = p.control.runtime().snapshot();
    let place = writable(&s, "Speed").expect("Speed is writable");
    let peer: std::net::SocketAddr = "127.0.0.1:5020".parse().expect("address");
    let c = p.control.clone();
    tokio::task::spawn_blocking(move || {
        c.write_places_blocking(&Actor::modbus(peer, Role::Operator), vec![(place, Value::Int(9))])
    })
    .await
    .expect("task")
    .expect("write");
    assert_eq!(p.control.read("Speed").expect("read"), json!(9));
    let r = rows(&p.control);
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].target.as_deref(), Some("Speed"));
    assert_eq!(r[0].via.as_deref(), Some("modbus"));
    assert_eq!(r[0].user.as_deref(), Some("modbus:127.0.0.1:5020"));
    assert_eq!(r[0].addr.as_deref(), Some("127.0.0.1:5020"));
    let viewer = Actor::modbus(peer, Role::Viewer);
    let c = p.control.clone();
    let e = tokio::task::spawn_blocking(move || c.write_places_blocking(&viewer, vec![(place, Value::Int(1))]))
        .await
        .expect("task");
    assert!(matches!(e, Err(Refused::Role { .. })), "{e:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn write_many_is_all_or_nothing() {
    let p = plc(false);
    let writes = vec![("Speed".to_string(), json!(3)), ("Start".to_string(), json!(true))];
    let e = p.control.write_many(&operator(Via::Http), &writes).await;
    assert!(matches!(e, Err(Refused::NotWritable(_))), "{e:?}");
    assert_eq!(p.control.read("Speed").expect("read"), json!(0));
    let writes = vec![("Speed".to_string(), json!(3)), ("Delay.PRE".to_string(), json!(80))];
    p.control
        .write_many(&operator(Via::Http), &writes)
        .await
        .expect("write");
    assert_eq!(p.control.read("Speed").expect("read"), json!(3));
    assert_eq!(p.control.read("Delay.PRE").expect("read"), json!(80));
}

/// A refusal of one write of several names it, and nothing is written or
/// recorded; accepted, each write has its row with the detail given.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn write_rows_names_the_refused_row_and_records_each_write() {
    let p = plc(true);
    let writes = vec![
        ("Speed".to_string(), json!(7)),
        ("Delay.PRE".to_string(), json!(-5)),
        ("Start".to_string(), json!(true)),
    ];
    let e = p
        .control
        .write_rows(&operator(Via::Http), &writes, Some("recipe r"))
        .await
        .expect_err("a negative preset is refused");
    assert_eq!(e.row, Some(1), "{e:?}");
    assert!(matches!(e.refused, Refused::OutOfRange(_)), "{e:?}");
    assert_eq!(p.control.read("Speed").expect("read"), json!(0));
    assert!(rows(&p.control).is_empty(), "nothing recorded");
    let writes = vec![("Speed".to_string(), json!(7)), ("Delay.PRE".to_string(), json!(90))];
    p.control
        .write_rows(&operator(Via::Http), &writes, Some("recipe r"))
        .await
        .expect("written");
    assert_eq!(p.control.read("Speed").expect("read"), json!(7));
    let r = rows(&p.control);
    assert_eq!(r.len(), 2);
    assert!(
        r.iter()
            .all(|r| r.action == "write" && r.detail.as_deref() == Some("recipe r")),
        "{r:?}"
    );
}

/// Writes by place of one peer to one tag within a second share a row;
/// the rest are counted and recorded with the last value (docs/audit.md).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn writes_by_place_are_coalesced_per_peer_tag_and_second() {
    let p = plc(true);
    let s = p.control.runtime().snapshot();
    let place = writable(&s, "Speed").expect("Speed is writable");
    let peer: std::net::SocketAddr = "127.0.0.1:5021".parse().expect("address");
    let c = p.control.clone();
    tokio::task::spawn_blocking(move || {
        let actor = Actor::modbus(peer, Role::Operator);
        for v in 1..=5 {
            c.write_places_blocking(&actor, vec![(place, Value::Int(v))])
                .expect("write");
        }
        c.flush(&actor);
    })
    .await
    .expect("task");
    assert_eq!(p.control.read("Speed").expect("read"), json!(5));
    let r = rows(&p.control);
    // Every write is accounted for: a row of its own, or counted in a
    // `coalesced` row.
    let accounted: u64 = r
        .iter()
        .map(|row| match row.detail.as_deref() {
            None => 1,
            Some(d) => d
                .strip_prefix("coalesced: ")
                .and_then(|t| t.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("detail {d}")),
        })
        .sum();
    assert_eq!(accounted, 5, "{r:#?}");
    assert!(r.len() < 5, "not coalesced: {r:#?}");
    assert_eq!(r[0].new.as_deref(), Some("5"), "the last value is recorded");
}

fn engineer(via: Via) -> Actor {
    Actor {
        role: Role::Engineer,
        ..operator(via)
    }
}

/// Forcing is an engineer's: an operator of any door is refused before any
/// row is written; an engineer's force is recorded (old: the live value),
/// applied, and its removal recorded (old: the forced value).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn forces_are_judged_recorded_then_applied() {
    let p = plc(true);
    for via in [Via::Http, Via::Mqtt, Via::Opcua, Via::Modbus] {
        match p.control.force(&operator(via), "Motor", &json!(true)).await {
            Err(Refused::Role {
                needed: Role::Engineer, ..
            }) => {}
            other => panic!("{via}: {other:?}"),
        }
    }
    assert!(rows(&p.control).is_empty(), "a refusal writes no row");
    match p.control.force(&engineer(Via::Http), "Speed", &json!(1)).await {
        Err(Refused::NotForceable(m)) => assert!(m.contains("only I/O"), "{m}"),
        other => panic!("{other:?}"),
    }
    match p.control.force(&engineer(Via::Http), "Nope", &json!(1)).await {
        Err(Refused::UnknownTag(_)) => {}
        other => panic!("{other:?}"),
    }
    match p.control.force(&engineer(Via::Http), "Level", &json!(70000)).await {
        Err(Refused::OutOfRange(_)) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(
        p.control
            .force(&engineer(Via::Http), "Motor", &json!(true))
            .await
            .expect("force"),
        Value::Bool(true)
    );
    assert_eq!(p.control.runtime().snapshot().forces.len(), 1);
    match p.control.unforce(&engineer(Via::Http), Some("Start")).await {
        Err(Refused::NotForced(_)) => {}
        other => panic!("{other:?}"),
    }
    p.control
        .unforce(&engineer(Via::Http), Some("motor"))
        .await
        .expect("unforce");
    assert!(p.control.runtime().snapshot().forces.is_empty());
    let r = rows(&p.control);
    assert_eq!(r.len(), 2, "{r:?}");
    assert_eq!(
        (r[1].action.as_str(), r[1].old.as_deref(), r[1].new.as_deref()),
        ("force", Some("false"), Some("true"))
    );
    assert_eq!((r[0].action.as_str(), r[0].old.as_deref()), ("unforce", Some("true")));
    assert!(
        r.iter()
            .all(|r| r.via.as_deref() == Some("http") && r.outcome == Outcome::Ok)
    );
}

/// Stop is a safety action: with no audit trail it is still done; run and
/// stop record the state before and the one asked for.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn run_and_stop_are_an_engineers_and_recorded() {
    let p = plc(true);
    match p.control.stop(&operator(Via::Http)).await {
        Err(Refused::Role { .. }) => {}
        other => panic!("{other:?}"),
    }
    p.control.stop(&engineer(Via::Http)).await.expect("stop");
    p.control.run(&engineer(Via::Http)).await.expect("run");
    let r = rows(&p.control);
    assert_eq!(r.len(), 2);
    assert_eq!(
        (r[1].action.as_str(), r[1].old.as_deref(), r[1].new.as_deref()),
        ("stop", Some("\"running\""), Some("\"stopped\""))
    );
    assert_eq!(
        (r[0].action.as_str(), r[0].old.as_deref(), r[0].new.as_deref()),
        ("run", Some("\"stopped\""), Some("\"running\""))
    );
    let off = plc(false);
    off.control
        .stop(&engineer(Via::Http))
        .await
        .expect("stop without a trail");
}

/// Without alarms an alarm action is an unknown alarm, after the role check.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_alarm_action_needs_its_role_and_an_alarm() {
    let p = plc(true);
    let viewer = Actor {
        role: Role::Viewer,
        ..operator(Via::Opcua)
    };
    let ack = || alba_alarms::Request::Ack { comment: String::new() };
    match p.control.alarm_act(&viewer, "HiLevel", ack()).await {
        Err(Refused::Role { .. }) => {}
        other => panic!("{other:?}"),
    }
    let oos = alba_alarms::Request::OutOfService {
        on: true,
        reason: String::new(),
    };
    match p.control.alarm_act(&operator(Via::Http), "HiLevel", oos).await {
        Err(Refused::Role {
            needed: Role::Engineer, ..
        }) => {}
        other => panic!("{other:?}"),
    }
    match p.control.alarm_act(&operator(Via::Http), "HiLevel", ack()).await {
        Err(Refused::UnknownAlarm(m)) => assert!(m.contains("no alarms.csv"), "{m}"),
        other => panic!("{other:?}"),
    }
    assert!(rows(&p.control).is_empty());
}

/// A driver whose inputs hold `Start` on (a board's pin pressed).
struct Pressed;

impl alba_runtime::Io for Pressed {
    fn name(&self) -> &str {
        "pressed"
    }
    fn read_inputs(&mut self, engine: &mut alba_engine::Engine) -> Result<(), alba_runtime::IoError> {
        if let Ok(Target::Value { place, .. }) = engine.program().layout.resolve("Start") {
            engine.write(place, Value::Bool(true));
        }
        Ok(())
    }
    fn write_outputs(&mut self, _: &alba_engine::Engine) -> Result<(), alba_runtime::IoError> {
        Ok(())
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn attaching_a_board_needs_an_engineer_and_its_row_and_detaching_is_a_safety_action() {
    let p = plc(true);
    let engineer = Actor {
        role: Role::Engineer,
        ..operator(Via::Http)
    };
    let entry = |a: &Actor, action| Entry {
        target: Some("/dev/ttyUSB0".into()),
        ..a.entry(action)
    };
    let open = || async { Ok::<Box<dyn alba_runtime::Io>, Refused>(Box::new(Pressed)) };
    // An operator: refused before anything is opened or recorded.
    let r = p
        .control
        .attach(
            &operator(Via::Http),
            entry(&operator(Via::Http), Action::Attach),
            open(),
        )
        .await;
    assert!(matches!(r, Err(Refused::Role { .. })), "{:?}", r.err());
    assert!(rows(&p.control).is_empty());
    // An engineer: the row, then the swap; the program sees the board's input.
    let sim = p
        .control
        .attach(&engineer, entry(&engineer, Action::Attach), open())
        .await
        .expect("attached");
    assert_eq!(sim.name(), "sim");
    for _ in 0..200 {
        if p.control.read("Motor").expect("read") == json!(true) {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(5)).await;
    }
    assert_eq!(p.control.read("Motor").expect("read"), json!(true));
    // A failed opening is recorded as such, and changes nothing.
    let failed = p
        .control
        .attach(&engineer, entry(&engineer, Action::Attach), async {
            Err::<Box<dyn alba_runtime::Io>, Refused>(Refused::Internal("no such port".into()))
        })
        .await;
    assert!(failed.is_err());
    // Detach: the project's own I/O back.
    let (r, back) = match p
        .control
        .detach(&operator(Via::Http), entry(&operator(Via::Http), Action::Detach), sim)
        .await
    {
        Err((r, Some(back))) => (r, back),
        other => panic!("an operator detached: {:?}", other.err().map(|e| e.0)),
    };
    assert!(matches!(r, Refused::Role { .. }));
    let board = p
        .control
        .detach(&engineer, entry(&engineer, Action::Detach), back)
        .await
        .map_err(|e| e.0)
        .expect("detached");
    assert_eq!(board.name(), "pressed");
    let r = rows(&p.control);
    let actions: Vec<(&str, bool)> = r
        .iter()
        .map(|r| (r.action.as_str(), r.outcome == Outcome::Ok))
        .collect();
    assert_eq!(actions.len(), 3, "{actions:?}");
    assert!(
        actions.contains(&("attach", true)) && actions.contains(&("attach", false)),
        "{actions:?}"
    );
    assert!(actions.contains(&("detach", true)), "{actions:?}");
}
