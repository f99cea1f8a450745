//! alarms.csv, the ISA-18.2 state machine and the log, against hand-worked
//! sequences.

use alba_alarms::{Alarms, Condition, Log, State, def};
use alba_diag::{Files, Span};
use alba_ir::layout::Uses;
use alba_ir::{Layout, Memory, Place, Target};
use alba_model::{TagTable, Value};

const TAGS: &str = "name,type,address,initial,retain,description\n\
Level,REAL,,,,\nPump,BOOL,,,,\nCount,DINT,,,,\nMaint,BOOL,,,,\nDelay,TIMER,,,,\nRaw,INT,AI:3/0,,,\n";

struct Rig {
    layout: Layout,
    mem: Memory,
}

impl Rig {
    fn new() -> Rig {
        let mut files = Files::new();
        let f = files.add("tags.csv", TAGS);
        let (tags, d) = TagTable::parse(files.text(f), f);
        assert!(d.is_empty(), "{d:?}");
        let layout = Layout::new(&tags, &Uses::default());
        let mem = Memory::new(layout.counts, layout.marker_bytes);
        Rig { layout, mem }
    }

    fn place(&self, name: &str) -> Place {
        match self.layout.resolve(name) {
            Ok(Target::Value { place, .. }) => place,
            other => panic!("{name}: {other:?}"),
        }
    }

    fn set(&mut self, name: &str, v: Value) {
        let p = self.place(name);
        self.mem.write(p, v);
    }

    fn alarms(&self, rows: &str) -> Alarms {
        let text = format!("id,tag,condition,severity,delay_ms,deadband,message\n{rows}");
        let mut files = Files::new();
        let f = files.add("alarms.csv", &text);
        let (defs, diags) = def::parse(files.text(f), f, &self.layout);
        assert!(
            diags.is_empty(),
            "{}",
            diags.iter().map(|d| d.render(&files)).collect::<String>()
        );
        Alarms::new(defs)
    }
}

fn state(a: &Alarms, id: &str) -> State {
    a.get(id).expect("alarm").state
}

/// Errors of a file: `line:col message` for each.
fn errors(rig: &Rig, text: &str) -> Vec<String> {
    let mut files = Files::new();
    let f = files.add("alarms.csv", text);
    let (_, diags) = def::parse(files.text(f), f, &rig.layout);
    diags
        .iter()
        .map(|d| {
            let sp: Span = d.primary.as_ref().map_or(Span::new(f, 0..0), |l| l.span);
            let (l, c) = files.line_col(f, sp.start as usize);
            format!("{l}:{c} {}", d.message)
        })
        .collect()
}

#[test]
fn conditions_parse_and_print() {
    for (t, want) in [
        ("on", "on"),
        ("OFF", "off"),
        ("rising", "rising"),
        ("falling", "falling"),
        ("> 80", "> 80"),
        (">=80.5", ">= 80.5"),
        ("< -3", "< -3"),
        ("<= 0", "<= 0"),
        ("== 2", "== 2"),
        ("!= 2", "!= 2"),
    ] {
        assert_eq!(Condition::parse(t).expect(t).to_string(), want);
    }
    for bad in ["", "above 3", "> ", "> x", "=> 3", "> nan", "> inf"] {
        assert!(Condition::parse(bad).is_err(), "{bad}");
    }
    assert_eq!(def::parse_severity("high"), Ok(750));
    assert!(def::parse_severity("0").is_err() && def::parse_severity("1001").is_err());
}

#[test]
fn malformed_files_are_refused_at_the_field() {
    let rig = Rig::new();
    let h = "id,tag,condition,severity,delay_ms,deadband,message\n";
    let cases: &[(&str, &str)] = &[
        ("", "1:1 alarms.csv is empty"),
        ("id,tag,cond\n", "1:1 the header of alarms.csv must be"),
        ("a,Nope,on,1,0,0,m\n", "2:3 unknown tag `Nope`"),
        ("a,Level,above 3,1,0,0,m\n", "2:9 `above 3` is not a condition"),
        ("a,Level,> x,1,0,0,m\n", "2:9 `>` needs a number"),
        ("a,Level,> 3,0,0,0,m\n", "2:13 `0` is not a severity"),
        ("a,Level,> 3,urgent,0,0,m\n", "2:13 `urgent` is not a severity"),
        ("a,Level,> 3,1,-5,0,m\n", "2:15 `-5` is not an on-delay"),
        ("a,Level,> 3,1,0,-1,m\n", "2:17 `-1` is not a deadband"),
        ("a,Level,> 3,1,0,0,\n", "2:19 an alarm needs a message"),
        ("a,Pump,> 3,1,0,0,m\n", "2:8 `Pump` is a BOOL"),
        ("a,Pump,on,1,0,2,m\n", "2:15 a deadband applies to comparisons"),
        ("a,Pump,rising,1,100,0,m\n", "2:17 `rising` is an edge"),
        ("a,Delay,on,1,0,0,m\n", "2:3 `Delay` is a structure"),
        ("a b,Pump,on,1,0,0,m\n", "2:1 `a b` is not an alarm id"),
        (
            "a,Pump,on,1,0,0,m\nA,Pump,off,1,0,0,m\n",
            "3:1 the alarm id `A` is used twice",
        ),
        ("a,Pump,on,1,0,0\n", "2:16 an alarm row has 7 fields, this one has 6"),
        ("a,Pump,\"on,1,0,0,m\n", "2:8"),
        (
            "a,Level,> 3,1,99999999999,0,m\n",
            "2:15 `99999999999` is not an on-delay",
        ),
    ];
    for (body, want) in cases {
        let text = if body.starts_with("id,tag,cond\n") || body.is_empty() {
            body.to_string()
        } else {
            format!("{h}{body}")
        };
        let got = errors(&rig, &text);
        assert!(
            got.iter().any(|g| g.starts_with(want)),
            "{body:?}: want {want:?}, got {got:?}"
        );
    }
    // The optional suppressed_by column must name a BOOL.
    let got = errors(
        &rig,
        &format!("{},suppressed_by\na,Level,> 3,1,0,0,m,Count\n", h.trim_end()),
    );
    assert!(got.iter().any(|g| g.contains("`Count` is not a BOOL")), "{got:?}");
}

#[test]
fn a_high_level_alarm_goes_through_every_state() {
    let mut rig = Rig::new();
    let mut a = rig.alarms("hi,Level,> 80,high,0,5,Level high\n");
    assert!(a.update(0, &rig.mem).is_empty());
    rig.set("Level", Value::Real(81.0));
    let e = a.update(100, &rig.mem);
    assert_eq!(
        (e[0].from, e[0].to, e[0].t_ms),
        (State::Normal, State::ActiveUnacked, 100)
    );
    assert_eq!(a.get("hi").map(|x| x.since_ms), Some(100));
    // Deadband 5: 78 is still in alarm; 74.9 clears it.
    rig.set("Level", Value::Real(78.0));
    assert!(a.update(200, &rig.mem).is_empty());
    rig.set("Level", Value::Real(74.9));
    assert_eq!(a.update(300, &rig.mem)[0].to, State::ClearedUnacked);
    // Back in alarm before anyone acknowledged: unacknowledged again.
    rig.set("Level", Value::Real(90.0));
    assert_eq!(a.update(400, &rig.mem)[0].to, State::ActiveUnacked);
    let e = a.ack("HI", "ana", "pump checked", 450).expect("ack");
    assert_eq!(
        (e.to, e.user.as_deref(), e.comment.as_deref()),
        (State::ActiveAcked, Some("ana"), Some("pump checked"))
    );
    assert!(a.ack("hi", "ana", "", 460).is_err(), "acknowledged twice");
    rig.set("Level", Value::Real(10.0));
    assert_eq!(a.update(500, &rig.mem)[0].to, State::Normal);
    // Cleared first, acknowledged after: normal at the acknowledgement.
    rig.set("Level", Value::Real(85.0));
    a.update(600, &rig.mem);
    rig.set("Level", Value::Real(0.0));
    a.update(700, &rig.mem);
    assert_eq!(state(&a, "hi"), State::ClearedUnacked);
    assert_eq!(a.ack("hi", "bo", "", 800).expect("ack").to, State::Normal);
    assert!(a.not_normal().is_empty());
}

#[test]
fn a_noisy_signal_does_not_chatter_with_a_deadband() {
    let mut rig = Rig::new();
    let mut a = rig.alarms("hi,Level,>= 80,500,0,2,Level high\nraw,Level,>= 80,500,0,0,Level high (no deadband)\n");
    let mut changes = [0, 0];
    for k in 0..200 {
        // 80 ± 1.5 of noise
        let noise = ((k * 7919) % 31) as f32 / 10.0 - 1.5;
        rig.set("Level", Value::Real(80.0 + noise));
        for e in a.update(k * 10, &rig.mem) {
            changes[usize::from(e.id == "raw")] += 1;
        }
    }
    assert_eq!(changes[0], 1, "with a deadband: one activation, no clearing");
    assert!(changes[1] > 20, "without one it chatters: {}", changes[1]);
}

#[test]
fn the_on_delay_needs_the_condition_to_hold() {
    let mut rig = Rig::new();
    let mut a = rig.alarms("run,Pump,on,1,1000,0,Pump running long\n");
    rig.set("Pump", Value::Bool(true));
    assert!(a.update(0, &rig.mem).is_empty());
    assert!(a.update(999, &rig.mem).is_empty());
    // A drop restarts the delay.
    rig.set("Pump", Value::Bool(false));
    a.update(1000, &rig.mem);
    rig.set("Pump", Value::Bool(true));
    assert!(a.update(1100, &rig.mem).is_empty());
    assert!(a.update(2099, &rig.mem).is_empty());
    assert_eq!(a.update(2100, &rig.mem)[0].to, State::ActiveUnacked);
}

#[test]
fn every_condition_kind() {
    let mut rig = Rig::new();
    let mut a = rig.alarms(
        "on,Pump,on,1,0,0,m\noff,Pump,off,1,0,0,m\nup,Pump,rising,1,0,0,m\ndown,Pump,falling,1,0,0,m\n\
         gt,Count,> 5,1,0,0,m\nge,Count,>= 5,1,0,0,m\nlt,Count,< 5,1,0,0,m\nle,Count,<= 5,1,0,0,m\n\
         eq,Count,== 5,1,0,0,m\nne,Count,!= 5,1,0,0,m\nraw,AI:3/0,> 100,1,0,0,m\n",
    );
    let active = |a: &Alarms| -> Vec<String> {
        let mut v: Vec<String> = a.all().iter().filter(|x| x.active).map(|x| x.def.id.clone()).collect();
        v.sort();
        v
    };
    a.update(0, &rig.mem);
    assert_eq!(active(&a), ["le", "lt", "ne", "off"]);
    rig.set("Pump", Value::Bool(true));
    rig.set("Count", Value::Dint(5));
    rig.set("Raw", Value::Int(101));
    a.update(10, &rig.mem);
    assert_eq!(active(&a), ["eq", "ge", "le", "on", "raw", "up"]);
    a.update(20, &rig.mem);
    assert_eq!(
        active(&a),
        ["eq", "ge", "le", "on", "raw"],
        "an edge lasts one evaluation"
    );
    assert_eq!(
        state(&a, "up"),
        State::ClearedUnacked,
        "and waits for its acknowledgement"
    );
    rig.set("Pump", Value::Bool(false));
    rig.set("Count", Value::Dint(6));
    a.update(30, &rig.mem);
    assert_eq!(active(&a), ["down", "ge", "gt", "ne", "off", "raw"]);
}

#[test]
fn shelving_expires_and_suppression_and_maintenance_silence() {
    let mut rig = Rig::new();
    let text = "id,tag,condition,severity,delay_ms,deadband,message,suppressed_by\nhi,Level,> 80,1,0,0,m,Maint\n";
    let mut files = Files::new();
    let f = files.add("alarms.csv", text);
    let (defs, d) = def::parse(files.text(f), f, &rig.layout);
    assert!(d.is_empty(), "{d:?}");
    let mut a = Alarms::new(defs);
    assert!(a.shelve("hi", 5, "", "ana", 0).is_err(), "a reason is required");
    assert!(a.shelve("hi", 0, "x", "ana", 0).is_err());
    assert_eq!(
        a.shelve("hi", 1, "sensor swap", "ana", 0).expect("shelve").to,
        State::Shelved
    );
    rig.set("Level", Value::Real(90.0));
    assert!(a.update(30_000, &rig.mem).is_empty(), "shelved: not annunciated");
    let e = a.update(60_000, &rig.mem);
    assert_eq!(
        (e[0].from, e[0].to),
        (State::Shelved, State::ActiveUnacked),
        "expired: back, unacknowledged"
    );
    a.ack("hi", "ana", "", 60_001).expect("ack");
    // Suppressed by design while Maint.
    rig.set("Maint", Value::Bool(true));
    assert_eq!(a.update(61_000, &rig.mem)[0].to, State::Suppressed);
    rig.set("Level", Value::Real(0.0));
    assert!(a.update(62_000, &rig.mem).is_empty());
    rig.set("Maint", Value::Bool(false));
    rig.set("Level", Value::Real(95.0));
    assert_eq!(a.update(63_000, &rig.mem)[0].to, State::ActiveUnacked);
    // Out of service: nothing until it is back.
    assert!(a.set_out_of_service("hi", true, "", "eng", 64_000).is_err());
    assert_eq!(
        a.set_out_of_service("hi", true, "valve replaced", "eng", 64_000)
            .expect("oos")
            .to,
        State::OutOfService
    );
    rig.set("Level", Value::Real(0.0));
    assert!(a.update(65_000, &rig.mem).is_empty());
    assert!(a.ack("hi", "ana", "", 65_001).is_err());
    assert_eq!(
        a.set_out_of_service("hi", false, "", "eng", 66_000).expect("back").to,
        State::Normal
    );
    assert!(matches!(
        a.ack("nope", "a", "", 0),
        Err(alba_alarms::ActionError::Unknown(_))
    ));
}

#[test]
fn the_log_keeps_every_event_and_exports_csv() {
    let mut rig = Rig::new();
    let dir = tempfile::tempdir().expect("tmp");
    let log = Log::open(&dir.path().join("alarms.db"), 0).expect("open");
    let mut a = rig.alarms("hi,Level,> 80,high,0,0,\"Level high, =check\"\n");
    for k in 0..300 {
        rig.set("Level", Value::Real(if k % 2 == 0 { 90.0 } else { 0.0 }));
        log.append(&a.update(k * 10, &rig.mem), &[]).expect("append");
    }
    log.append(&[a.ack("hi", "ana", "seen", 5000).expect("ack")], &[])
        .expect("append");
    assert_eq!(log.count().expect("count"), 301, "no 100-event limit");
    let mut out = Vec::new();
    let n = log.export_csv(Some(2980), None, 1000, &mut out).expect("csv");
    let text = String::from_utf8(out).expect("utf8");
    assert_eq!(n, 3, "{text}");
    let last = text.lines().last().expect("a row");
    assert!(
        last.contains(",hi,Level,cleared_unacked,normal,0,750,ana,seen,\"Level high, =check\""),
        "{last}"
    );
    // Another application's database is refused.
    let other = dir.path().join("other.db");
    rusqlite_free_file(&other);
    assert!(Log::open(&other, 0).is_err());
}

/// A file that is not an SQLite database.
fn rusqlite_free_file(p: &std::path::Path) {
    std::fs::write(
        p,
        b"this is not a database, just text that is long enough to have a header",
    )
    .expect("write");
}

/// The child half of `the_log_survives_kill_9`: appends events forever,
/// printing the count after each durable append.
#[test]
#[ignore = "run by the_log_survives_kill_9 in a child process"]
fn child_appends_until_killed() {
    let Some(path) = std::env::var_os("ALBA_ALARM_LOG") else {
        return;
    };
    let log = Log::open(std::path::Path::new(&path), 0).expect("open");
    let e = alba_alarms::Event {
        t_ms: 0,
        id: "hi".into(),
        tag: "Level".into(),
        from: State::Normal,
        to: State::ActiveUnacked,
        value: 1.0,
        user: None,
        comment: None,
        severity: 1,
        message: "m".into(),
    };
    for k in 1.. {
        log.append(std::slice::from_ref(&e), &[]).expect("append");
        println!("{k}");
    }
}

#[test]
fn the_log_survives_kill_9() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().expect("tmp");
    let path = dir.path().join("alarms.db");
    let mut child = std::process::Command::new(std::env::current_exe().expect("exe"))
        .args([
            "--ignored",
            "--exact",
            "child_appends_until_killed",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("ALBA_ALARM_LOG", &path)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("spawn");
    let stdout = child.stdout.take().expect("stdout");
    let mut durable = 0u64;
    for line in std::io::BufReader::new(stdout).lines() {
        if let Ok(n) = line.expect("line").trim().parse::<u64>() {
            durable = n;
            if n >= 50 {
                break;
            }
        }
    }
    child.kill().expect("kill -9");
    child.wait().expect("wait");
    let log = Log::open(&path, 0).expect("reopen after kill -9");
    assert!(
        log.count().expect("count") >= durable,
        "every acknowledged append is there"
    );
}

proptest::proptest! {
    /// Any text: diagnostics or alarms, never a panic; every alarm's id is unique.
    #[test]
    fn any_text_is_parsed_or_refused_without_panicking(body in "[a-zA-Z0-9_,.<>=!\" \\-\n]{0,200}") {
        let rig = Rig::new();
        let text = format!("id,tag,condition,severity,delay_ms,deadband,message\n{body}");
        let mut files = Files::new();
        let f = files.add("alarms.csv", &text);
        let (defs, _) = def::parse(files.text(f), f, &rig.layout);
        let mut ids: Vec<String> = defs.iter().map(|d| d.id.to_ascii_lowercase()).collect();
        ids.sort();
        ids.dedup();
        proptest::prop_assert_eq!(ids.len(), defs.len());
    }
}

#[test]
fn the_hub_counts_states_and_detects_a_flood() {
    let mut rig = Rig::new();
    let rows: String = (0..12)
        .map(|k| format!("a{k},Count,> {k},{},0,0,m{k}\n", 100 + k))
        .collect();
    let text = format!("id,tag,condition,severity,delay_ms,deadband,message\n{rows}");
    let mut files = Files::new();
    let f = files.add("alarms.csv", &text);
    let (defs, d) = def::parse(files.text(f), f, &rig.layout);
    assert!(d.is_empty(), "{d:?}");
    let hub = alba_alarms::Hub::new(defs, None);
    // Count rises one by one: a new alarm every minute.
    for k in 1..=12 {
        rig.set("Count", Value::Dint(k));
        hub.update(i64::from(k) * 60_000, &rig.mem).expect("update");
    }
    let s = hub.stats(12 * 60_000);
    assert_eq!((s.alarms, s.active, s.unacked), (12, 12, 12));
    // Activations at 1..=12 min; the window (2, 12] min holds 10: no flood yet.
    assert_eq!((s.new_in_window, s.flood), (10, false));
    assert_eq!(s.top_unacked, Some(("a11".to_string(), 111)));
    hub.act(
        "a11",
        &alba_alarms::Request::Ack { comment: String::new() },
        "ana",
        12 * 60_000,
    )
    .expect("ack");
    hub.act(
        "a10",
        &alba_alarms::Request::Shelve {
            minutes: 5,
            reason: "x".into(),
        },
        "ana",
        12 * 60_000,
    )
    .expect("shelve");
    let s = hub.stats(12 * 60_000);
    assert_eq!((s.unacked, s.shelved, s.active), (10, 1, 11));
    assert_eq!(s.top_unacked, Some(("a9".to_string(), 109)));
    // Everything clears and comes back within a minute: 12 new activations, a flood.
    rig.set("Count", Value::Dint(-1));
    hub.update(12 * 60_000 + 10, &rig.mem).expect("update");
    rig.set("Count", Value::Dint(100));
    hub.update(12 * 60_000 + 20, &rig.mem).expect("update");
    let s = hub.stats(12 * 60_000 + 20);
    assert!(s.flood && s.new_in_window > 10, "{s:?}");
}

/// Alarm states survive a restart (issue 30, point 20): an unacknowledged
/// alarm is still there after the hub is made again from the same log, a
/// shelved one keeps its end and reason, and an acknowledged one whose
/// condition went away in the meantime returns to normal on the first
/// evaluation without a new activation.
#[test]
fn alarm_states_survive_a_restart_through_the_log() {
    let mut rig = Rig::new();
    let dir = tempfile::tempdir().expect("tmp");
    let path = dir.path().join("alarms.db");
    let rows =
        "hi,Level,> 80,high,2000,0,Level high\nlo,Level,< 10,medium,0,0,Level low\nsh,Level,> 50,low,0,0,Shelved\n";
    let defs = |rig: &Rig| {
        let mut files = Files::new();
        let f = files.add(
            "alarms.csv",
            format!("id,tag,condition,severity,delay_ms,deadband,message\n{rows}"),
        );
        let (defs, diags) = def::parse(files.text(f), f, &rig.layout);
        assert!(diags.is_empty());
        defs
    };
    {
        let hub = alba_alarms::Hub::new(defs(&rig), Some(Log::open(&path, 0).expect("open")));
        rig.set("Level", Value::Real(90.0));
        hub.update(1_000, &rig.mem).expect("update");
        hub.update(3_500, &rig.mem).expect("update");
        hub.act(
            "sh",
            &alba_alarms::Request::Shelve {
                minutes: 60,
                reason: "sensor swap".into(),
            },
            "ana",
            4_000,
        )
        .expect("shelve");
        let states: Vec<_> = hub.list(true).iter().map(|a| (a.def.id.clone(), a.state)).collect();
        assert_eq!(
            states,
            [
                ("hi".to_string(), State::ActiveUnacked),
                ("lo".into(), State::Normal),
                ("sh".into(), State::Shelved)
            ]
        );
        // the hub is dropped without any shutdown: what is kept was kept at each change
    }
    let hub = alba_alarms::Hub::new(defs(&rig), Some(Log::open(&path, 0).expect("reopen")));
    assert_eq!(hub.log_error(), None);
    let get = |hub: &alba_alarms::Hub, id: &str| hub.list(true).into_iter().find(|a| a.def.id == id).expect(id);
    assert_eq!(
        get(&hub, "hi").state,
        State::ActiveUnacked,
        "still unacknowledged after the restart"
    );
    assert_eq!(get(&hub, "hi").since_ms, 3_500);
    let sh = get(&hub, "sh");
    assert_eq!(sh.state, State::Shelved);
    assert_eq!(
        sh.shelved,
        Some((4_000 + 3_600_000, "ana".to_string(), "sensor swap".to_string()))
    );
    // Still in alarm: no event at all (the on-delay is not served again).
    assert_eq!(hub.update(10_000, &rig.mem).expect("update"), vec![]);
    hub.act(
        "hi",
        &alba_alarms::Request::Ack { comment: "seen".into() },
        "bob",
        11_000,
    )
    .expect("ack");
    // Restart again with the level back to normal: the acknowledged alarm clears.
    drop(hub);
    let hub = alba_alarms::Hub::new(defs(&rig), Some(Log::open(&path, 0).expect("reopen")));
    let hi = get(&hub, "hi");
    assert_eq!(hi.state, State::ActiveAcked);
    assert_eq!(hi.acked, Some(("bob".to_string(), "seen".to_string(), 11_000)));
    rig.set("Level", Value::Real(20.0));
    let ev = hub.update(12_000, &rig.mem).expect("update");
    assert_eq!(
        ev.iter().map(|e| (e.id.as_str(), e.to)).collect::<Vec<_>>(),
        [("hi", State::Normal)]
    );
}

/// A log written by the first version of the schema (no `states` table) is
/// upgraded in place and keeps its events.
#[test]
fn a_version_1_log_is_upgraded() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = dir.path().join("alarms.db");
    {
        let c = rusqlite::Connection::open(&path).expect("sqlite");
        c.execute_batch(
            "CREATE TABLE events(id INTEGER PRIMARY KEY AUTOINCREMENT, t INTEGER NOT NULL, alarm TEXT NOT NULL,
             tag TEXT NOT NULL, from_state TEXT NOT NULL, to_state TEXT NOT NULL, value REAL, severity INTEGER NOT NULL,
             user_name TEXT, comment TEXT, message TEXT NOT NULL);
             INSERT INTO events(t, alarm, tag, from_state, to_state, severity, message) VALUES(1, 'hi', 'L', 'normal', 'active_unacked', 700, 'm');
             PRAGMA application_id = 1097622092; PRAGMA user_version = 1;",
        )
        .expect("v1");
    }
    let log = Log::open(&path, 0).expect("upgraded");
    assert_eq!(log.count().expect("count"), 1);
    assert_eq!(log.load_states().expect("states"), vec![]);
}
