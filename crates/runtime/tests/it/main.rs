//! The runtime in real time: deadlines, statistics, requests at the scan
//! boundary, forces, run/stop, online edit, watchdog, retentive data.
//! Times are only bounded generously (the machine is shared): tests check
//! what happened, never how fast.

mod no_alloc;
mod retain;

use alba_diag::Files;
use alba_ir::{Place, Program, Target};
use alba_model::Value;
use alba_runtime::{IoError, Options, RunState, Runtime, SimIo, Snapshot, StartError};
use std::sync::Arc;
use std::time::Duration;

fn compile(tags: &str, lad: &str) -> Arc<Program> {
    compile_with_plant(tags, lad, None)
}

/// `lad`, then the plant program `plant` (which may write inputs).
fn compile_with_plant(tags: &str, lad: &str, plant: Option<&str>) -> Arc<Program> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags);
    let lf = files.add("main.lad", lad);
    let pf = plant.map(|p| files.add("plant.lad", p));
    let (t, d1) = alba_model::TagTable::parse(files.text(tf), tf);
    let (ast, d2) = alba_ladder::parse(files.text(lf), lf);
    let plant_ast = pf.map(|f| alba_ladder::parse(files.text(f), f));
    let mut asts = vec![&ast];
    asts.extend(plant_ast.as_ref().map(|(a, _)| a));
    let mut b = alba_ir::Builder::new(alba_ladder::layout_for(&t, &asts));
    let mut presets = alba_ladder::Presets::default();
    let src = files.text(lf).to_string();
    let mut diags = alba_ladder::compile(&ast, &src, "main.lad", &mut b, &mut presets);
    if let (Some(f), Some((a, d))) = (pf, &plant_ast) {
        diags.extend(d.iter().cloned());
        b.begin_plant();
        let src = files.text(f).to_string();
        diags.extend(alba_ladder::compile(a, &src, "plant.lad", &mut b, &mut presets));
    }
    assert!(
        d1.is_empty() && d2.is_empty() && diags.is_empty(),
        "{d1:?} {d2:?} {diags:?}"
    );
    Arc::new(b.finish(files))
}

fn place(p: &Program, name: &str) -> Place {
    match p.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    }
}

fn value(s: &Snapshot, name: &str) -> Value {
    s.read(place(&s.program, name))
}

/// Waits (up to 5 s) for a snapshot that satisfies `f`.
async fn until(rt: &Runtime, what: &str, f: impl Fn(&Snapshot) -> bool) -> Arc<Snapshot> {
    let mut rx = rt.handle().subscribe();
    let deadline = tokio::time::Instant::now() + Duration::from_secs(5);
    loop {
        let s = rx.borrow_and_update().clone();
        if f(&s) {
            return s;
        }
        if tokio::time::timeout_at(deadline, rx.changed()).await.is_err() {
            panic!(
                "timed out waiting for {what}; last state {:?}, scans {}",
                s.state, s.scans
            );
        }
    }
}

const TAGS: &str = "name,type,address,initial,retain,description\n\
In,BOOL,DI:1/0,,,\nOut,BOOL,DO:2/0,,,\nA,BOOL,,,,\nCount,DINT,,,,\nKept,DINT,,,1,\nDelay,TIMER,,,,\nAcc,TIMER,,,,\n";
const LAD: &str =
    "XIC(In)OTE(Out);\nADD(Count,1,Count);\nADD(Kept,1,Kept);\nXIC(A)TON(Delay,100000,0);\nRTO(Acc,100000,0);\n";

fn opts(scan_ms: u32) -> Options {
    let mut o = Options::new(scan_ms);
    o.native = false;
    o
}

#[tokio::test(flavor = "current_thread")]
async fn scans_on_deadlines_and_publishes_statistics_as_tags() {
    let rt = Runtime::start(compile(TAGS, LAD), opts(5), Box::new(SimIo)).unwrap();
    let s = until(&rt, "20 scans", |s| s.scans >= 20).await;
    assert_eq!(s.state, RunState::Running);
    assert_eq!(value(&s, "Count"), Value::Dint(s.scans as i32));
    // 20 scans of 5 ms take about 100 ms of clock.
    assert!(s.clock_ms >= 90, "{} scans in {} ms", s.scans, s.clock_ms);
    assert!(s.stats.max_us >= s.stats.min_us && s.stats.scans + 1 >= s.scans);
    assert_eq!(value(&s, "S:SCANMAX"), Value::Dint(s.stats.max_us as i32));
    assert_eq!(value(&s, "S:OVERRUNS"), Value::Dint(s.stats.overruns as i32));
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn writes_forces_and_stop_apply_between_scans() {
    let rt = Runtime::start(compile(TAGS, LAD), opts(2), Box::new(SimIo)).unwrap();
    let h = rt.handle();
    let p = h.snapshot().program.clone();
    // An internal write is applied and then seen by the program.
    h.write(place(&p, "Count"), Value::Dint(-1000)).await.unwrap();
    let s = h.snapshot();
    assert!(
        matches!(value(&s, "Count"), Value::Dint(v) if v < 0),
        "{:?}",
        value(&s, "Count")
    );
    // A forced input drives the program; a forced output holds whatever the program says.
    h.force("In".into(), place(&p, "In"), Value::Bool(true)).await.unwrap();
    until(&rt, "Out on", |s| value(s, "Out") == Value::Bool(true)).await;
    h.force("In".into(), place(&p, "In"), Value::Bool(false)).await.unwrap();
    h.force("Out".into(), place(&p, "Out"), Value::Bool(true))
        .await
        .unwrap();
    let s = until(&rt, "a scan with In off", |s| {
        value(s, "In") == Value::Bool(false) && s.forces.len() == 2
    })
    .await;
    assert_eq!(value(&s, "Out"), Value::Bool(true), "the forced output stays on");
    assert!(s.forces.iter().any(|f| f.name == "In" && f.input));
    assert!(s.forces.iter().any(|f| f.name == "Out" && !f.input));
    h.unforce(None).await.unwrap();
    until(&rt, "Out off once unforced", |s| {
        value(s, "Out") == Value::Bool(false) && s.forces.is_empty()
    })
    .await;
    // Stop: outputs to their safe state, and nothing scans.
    h.force("In".into(), place(&p, "In"), Value::Bool(true)).await.unwrap();
    until(&rt, "Out on", |s| value(s, "Out") == Value::Bool(true)).await;
    h.stop().await.unwrap();
    let s = h.snapshot();
    assert_eq!(s.state, RunState::Stopped);
    assert_eq!(value(&s, "Out"), Value::Bool(false));
    let scans = s.scans;
    tokio::time::sleep(Duration::from_millis(50)).await;
    assert_eq!(h.snapshot().scans, scans);
    // Run again: a first scan, memory kept.
    h.run().await.unwrap();
    let s = until(&rt, "running", |s| s.scans > scans + 2).await;
    assert_eq!(value(&s, "Out"), Value::Bool(true));
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn a_forced_input_wins_over_the_plant_program_in_every_snapshot() {
    // The plant program (after main.lad) clears In on every scan.
    let prog = compile_with_plant(TAGS, LAD, Some("OTU(In);\n"));
    for native in [false, true] {
        let mut o = opts(2);
        o.native = native;
        let rt = Runtime::start(prog.clone(), o, Box::new(SimIo)).unwrap();
        let h = rt.handle();
        h.force("In".into(), place(&prog, "In"), Value::Bool(true))
            .await
            .unwrap();
        let mut rx = h.subscribe();
        let first = until(&rt, "the program sees the force", |s| {
            value(s, "Out") == Value::Bool(true)
        })
        .await;
        // Every snapshot from then on shows the forced value, never the plant's.
        let mut seen = 0;
        while seen < 20 {
            rx.changed().await.unwrap();
            let s = rx.borrow_and_update().clone();
            if s.scans > first.scans {
                assert_eq!(value(&s, "In"), Value::Bool(true), "scan {} (native {native})", s.scans);
                assert_eq!(
                    value(&s, "Out"),
                    Value::Bool(true),
                    "scan {} (native {native})",
                    s.scans
                );
                seen += 1;
            }
        }
        // Unforced, the plant program writes it again.
        h.unforce(Some("In".into())).await.unwrap();
        until(&rt, "the plant's value", |s| value(s, "In") == Value::Bool(false)).await;
        rt.shutdown();
    }
}

#[tokio::test(flavor = "current_thread")]
async fn online_edit_keeps_timers_counters_and_values() {
    let rt = Runtime::start(compile(TAGS, LAD), opts(2), Box::new(SimIo)).unwrap();
    let h = rt.handle();
    let p = h.snapshot().program.clone();
    h.write(place(&p, "A"), Value::Bool(true)).await.unwrap();
    let before = until(
        &rt,
        "Delay timing",
        |s| matches!(value(s, "Delay.ACC"), Value::Dint(v) if v >= 20),
    )
    .await;
    // The new program adds a rung before the others and drops the RTO.
    let edited = compile(
        TAGS,
        "XIC(A)OTE(Out);\nADD(Count,1,Count);\nADD(Kept,1,Kept);\nXIC(A)TON(Delay,100000,0);\n",
    );
    h.replace(edited.clone()).await.unwrap();
    let after = until(&rt, "a scan of the new program", |s| {
        Arc::ptr_eq(&s.program, &edited) && s.scans > before.scans + 2
    })
    .await;
    let acc = |s: &Snapshot| match value(s, "Delay.ACC") {
        Value::Dint(v) => v,
        v => panic!("{v:?}"),
    };
    assert!(
        acc(&after) >= acc(&before),
        "Delay.ACC went from {} to {}",
        acc(&before),
        acc(&after)
    );
    assert_eq!(value(&after, "Out"), Value::Bool(true), "the new rung runs");
    assert!(matches!(value(&after, "Count"), Value::Dint(v) if v as u64 >= before.scans));
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn a_scan_longer_than_the_watchdog_faults_with_outputs_off() {
    // A backward-jump loop of 200 000 passes: far longer than 1 ms.
    let tags = "name,type,address,initial,retain,description\nOut,BOOL,DO:2/0,,,\nI,DINT,,,,\n";
    let lad = "OTE(Out);\nCLR(I);\nLBL(top)ADD(I,1,I);\nLES(I,200000)JMP(top);\n";
    let mut o = opts(10);
    o.watchdog_ms = 1;
    let rt = Runtime::start(compile(tags, lad), o, Box::new(SimIo)).unwrap();
    let s = until(&rt, "the watchdog", |s| s.state == RunState::Faulted).await;
    let fault = s.fault.clone().unwrap_or_default();
    assert!(fault.starts_with("watchdog: a scan took"), "{fault}");
    assert_eq!(value(&s, "Out"), Value::Bool(false));
    // No single step from a fault: nothing scanned.
    match rt.handle().step().await {
        Err(alba_runtime::Error::Faulted(f)) => assert_eq!(f, fault),
        other => panic!("{other:?}"),
    }
    assert_eq!(rt.handle().snapshot().scans, s.scans);
    // Run clears the fault.
    rt.handle().run().await.unwrap();
    assert_eq!(rt.handle().snapshot().state, RunState::Running);
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn overruns_are_counted_and_skipped() {
    // About 20 000 loop passes per scan against a 1 ms period.
    let tags = "name,type,address,initial,retain,description\nI,DINT,,,,\n";
    let lad = "CLR(I);\nLBL(top)ADD(I,1,I);\nLES(I,20000)JMP(top);\n";
    let mut o = opts(1);
    o.watchdog_ms = 10_000;
    let rt = Runtime::start(compile(tags, lad), o, Box::new(SimIo)).unwrap();
    let s = until(&rt, "overruns", |s| s.stats.overruns > 0 && s.scans > 10).await;
    // Every scan started late or on time, never more than one per period:
    // scans + overruns ≈ elapsed periods.
    assert!(
        s.scans + s.stats.overruns <= s.clock_ms + 2,
        "{} scans, {} overruns, {} ms",
        s.scans,
        s.stats.overruns,
        s.clock_ms
    );
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn retentive_values_survive_a_restart() {
    let dir = std::env::temp_dir().join(format!("alba-retain-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let file = dir.join("retain.json");
    let mut o = opts(2);
    o.retain_file = Some(file.clone());
    o.retain_interval_ms = 20;
    let program = compile(TAGS, LAD);
    let rt = Runtime::start(program.clone(), o.clone(), Box::new(SimIo)).unwrap();
    let s = until(&rt, "50 scans", |s| s.scans >= 50).await;
    let kept = value(&s, "Kept");
    rt.shutdown();
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("\"Kept\"") && text.contains("\"Acc.ACC\""), "{text}");
    assert!(!text.contains("\"Count\""), "Count is not retained: {text}");
    // A new runtime starts from the saved values (Kept: retain; Acc: RTO).
    o.start_running = false;
    let rt = Runtime::start(program, o, Box::new(SimIo)).unwrap();
    let s = rt.handle().snapshot();
    assert!(
        matches!((value(&s, "Kept"), kept), (Value::Dint(a), Value::Dint(b)) if a >= b),
        "{:?} < {kept:?}",
        value(&s, "Kept")
    );
    assert_eq!(value(&s, "Count"), Value::Dint(0));
    assert!(matches!(value(&s, "Acc.ACC"), Value::Dint(v) if v > 0));
    rt.shutdown();
    // Not a retain file: refused and left alone when so configured …
    std::fs::write(&file, "{\"hello\": 1}").unwrap();
    let mut refuse = opts(2).with_retain(file.clone());
    refuse.on_retain_error = alba_runtime::retain::OnError::Refuse;
    let err = Runtime::start(compile(TAGS, LAD), refuse, Box::new(SimIo)).err();
    assert!(
        err.is_some_and(|e| matches!(e, StartError::Retain(_)) && e.to_string().contains("not an Alba retain file"))
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "{\"hello\": 1}");
    // … else moved aside, and the previous save restored.
    let mut start = opts(2).with_retain(file.clone());
    start.start_running = false;
    let rt = Runtime::start(compile(TAGS, LAD), start, Box::new(SimIo)).unwrap();
    let s = rt.handle().snapshot();
    assert!(matches!(value(&s, "Acc.ACC"), Value::Dint(v) if v > 0));
    assert_eq!(value(&s, "S:RETAINLOST"), Value::Bool(true));
    assert_eq!(value(&s, "S:STOREOK"), Value::Bool(false));
    let problems = rt.handle().health().problems();
    assert!(
        problems.len() == 1 && problems[0].message.contains("restored the previous save"),
        "{problems:?}"
    );
    rt.shutdown();
    assert!(!file.exists() || !std::fs::read_to_string(&file).unwrap().contains("hello"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Attach mode with a board whose memory is a shared `Memory`: the program
/// counts `Count` up on every scan, but the board's memory holds 7 and does
/// not move, so a snapshot showing 7 proves the engine mirrored and did not scan.
struct Board {
    mem: Arc<std::sync::Mutex<alba_ir::Memory>>,
    writes: Arc<std::sync::Mutex<Vec<(Place, Value)>>>,
}

impl alba_runtime::Io for Board {
    fn name(&self) -> &str {
        "test board"
    }
    fn read_inputs(&mut self, engine: &mut alba_engine::Engine) -> Result<(), IoError> {
        let m = self.mem.lock().map_err(|e| IoError::Link(e.to_string()))?.clone();
        engine
            .load_memory(&m)
            .map_err(|e| IoError::MemoryMismatch(e.to_string()))
    }
    fn write_outputs(&mut self, _: &alba_engine::Engine) -> Result<(), IoError> {
        Err(IoError::DoesNotFit("attach mode never writes outputs".into()))
    }
    fn runs_program(&self) -> bool {
        true
    }
    fn write_remote(&mut self, place: Place, value: Value) -> Option<Result<(), IoError>> {
        if value == Value::Dint(-1) {
            return Some(Err(IoError::Refused("the board refused".into())));
        }
        self.writes.lock().ok()?.push((place, value));
        if let Ok(mut m) = self.mem.lock() {
            m.write(place, value);
        }
        Some(Ok(()))
    }
}

#[tokio::test(flavor = "current_thread")]
async fn attach_mode_mirrors_the_board_and_sends_writes_to_it() {
    let program = compile(TAGS, LAD);
    let mut board_mem = program.init.clone();
    board_mem.write(place(&program, "Count"), Value::Dint(7));
    board_mem.write(place(&program, "Out"), Value::Bool(true));
    let board = Board {
        mem: Arc::new(std::sync::Mutex::new(board_mem)),
        writes: Arc::default(),
    };
    let writes = board.writes.clone();
    let rt = Runtime::start(program.clone(), opts(2), Box::new(board)).unwrap();
    let s = until(&rt, "10 mirror cycles", |s| s.stats.scans >= 10).await;
    assert_eq!(
        value(&s, "Count"),
        Value::Dint(7),
        "the engine scanned instead of mirroring"
    );
    assert_eq!(value(&s, "Out"), Value::Bool(true));
    assert_eq!(s.state, RunState::Running, "{:?}", s.fault);
    let h = rt.handle();
    h.write(place(&program, "Kept"), Value::Dint(42)).await.unwrap();
    assert_eq!(*writes.lock().unwrap(), [(place(&program, "Kept"), Value::Dint(42))]);
    until(&rt, "the written value read back from the board", |s| {
        value(s, "Kept") == Value::Dint(42)
    })
    .await;
    let err = h.write(place(&program, "Kept"), Value::Dint(-1)).await.unwrap_err();
    assert!(
        matches!(
            err,
            alba_runtime::Error::Io {
                source: IoError::Refused(_),
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("the board refused"), "{err}");
    let err = h
        .force("In".into(), place(&program, "In"), Value::Bool(true))
        .await
        .unwrap_err();
    assert!(matches!(err, alba_runtime::Error::Attached { .. }), "{err}");
    assert!(err.to_string().contains("the board runs the program"), "{err}");
    assert!(matches!(h.stop().await, Err(alba_runtime::Error::Attached { .. })));
    assert!(matches!(h.step().await, Err(alba_runtime::Error::Attached { .. })));
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn a_handle_to_a_runtime_that_ended_says_so() {
    let program = compile(TAGS, LAD);
    let rt = Runtime::start(program.clone(), opts(2), Box::new(SimIo)).unwrap();
    let h = rt.handle();
    rt.shutdown();
    let err = h.write(place(&program, "Kept"), Value::Dint(1)).await.unwrap_err();
    assert_eq!(err, alba_runtime::Error::Stopped);
    assert_eq!(err.to_string(), "the runtime has stopped");
    assert_eq!(h.run().await, Err(alba_runtime::Error::Stopped));
}

/// `[runtime] priority`: the engine thread runs at SCHED_FIFO where the
/// system allows it (root here and in CI), and at normal priority with a
/// warning where it does not; read back from /proc, not assumed.
#[cfg(target_os = "linux")]
#[tokio::test(flavor = "current_thread")]
async fn the_engine_thread_gets_the_realtime_priority_asked_for() {
    let mut o = opts(5);
    o.realtime = alba_runtime::realtime::Realtime {
        priority: 20,
        cpu: Some(0),
        lock_memory: false,
    };
    let rt = Runtime::start(compile(TAGS, LAD), o, Box::new(SimIo)).unwrap();
    until(&rt, "a few scans", |s| s.scans >= 5).await;
    // The engine threads' scheduling policy and priority: fields 41 and 40 of
    // their stat lines. Other tests run runtimes in this process at the same
    // time, so every `alba-engine` thread is read; only this one asked for
    // SCHED_FIFO 20 on CPU 0.
    let mut found = Vec::new();
    for task in std::fs::read_dir("/proc/self/task").unwrap() {
        let dir = task.unwrap().path();
        if std::fs::read_to_string(dir.join("comm")).unwrap_or_default().trim() == "alba-engine" {
            let stat = std::fs::read_to_string(dir.join("stat")).unwrap();
            let after = stat.rsplit_once(") ").unwrap().1;
            let fields: Vec<&str> = after.split(' ').collect();
            // `after` starts at field 3 (state).
            let (rt_priority, policy) = (fields[40 - 3].to_string(), fields[41 - 3].to_string());
            let cpus = std::fs::read_to_string(dir.join("status"))
                .unwrap()
                .lines()
                .find(|l| l.starts_with("Cpus_allowed_list:"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string());
            found.push((policy, rt_priority, cpus));
        }
    }
    assert!(!found.is_empty(), "no alba-engine thread");
    let root = std::fs::read_to_string("/proc/self/status")
        .unwrap()
        .lines()
        .any(|l| l.starts_with("Uid:") && l.split_whitespace().nth(1) == Some("0"));
    if root {
        let ours = (String::from("1"), String::from("20"), Some(String::from("0")));
        assert!(
            found.contains(&ours),
            "no engine thread at SCHED_FIFO 20 on CPU 0: {found:?}"
        );
    } else {
        assert!(
            found.iter().all(|(policy, ..)| policy == "0"),
            "normal scheduling when SCHED_FIFO is refused: {found:?}"
        );
    }
    rt.shutdown();
}

/// A flood of requests (a protocol client writing as fast as it can) is
/// bounded: beyond `REQUEST_QUEUE` waiting, requests are refused as busy
/// instead of queued, and the engine keeps scanning while it works through
/// the ones it accepted. Asserted by counting, not by timing.
#[tokio::test(flavor = "current_thread")]
async fn a_flood_of_requests_is_bounded_and_scans_go_on() {
    let rt = Runtime::start(compile(TAGS, LAD), opts(2), Box::new(SimIo)).unwrap();
    let h = rt.handle();
    let s = until(&rt, "running", |s| s.scans > 5).await;
    let kept = place(&s.program, "Kept");
    let before = h.snapshot().scans;
    let mut tasks = tokio::task::JoinSet::new();
    let total = 4 * alba_runtime::REQUEST_QUEUE;
    for i in 0..total {
        let h = h.clone();
        tasks.spawn(async move { h.write(kept, Value::Dint(i as i32)).await });
    }
    let (mut ok, mut busy) = (0, 0);
    while let Some(r) = tasks.join_next().await {
        match r.unwrap() {
            Ok(()) => ok += 1,
            Err(alba_runtime::Error::Busy) => busy += 1,
            Err(e) => panic!("{e}"),
        }
    }
    assert_eq!(ok + busy, total);
    assert!(
        busy > 0,
        "{total} requests at once and none refused: the queue is not bounded"
    );
    assert!(ok >= alba_runtime::REQUEST_QUEUE / 2, "only {ok} accepted");
    // (+1: the count may see one request queued while the engine takes another.)
    assert!(h.queue_peak() <= alba_runtime::REQUEST_QUEUE + 1, "{}", h.queue_peak());
    // Scans went on while the accepted ones were applied.
    let after = h.snapshot().scans;
    assert!(after > before, "no scan while {ok} requests were applied");
    until(&rt, "scans after the flood", |s| s.scans > after + 5).await;
    rt.shutdown();
}

#[tokio::test(flavor = "current_thread")]
async fn single_steps_run_one_scan_each_and_are_refused_while_running() {
    let mut o = opts(2);
    o.start_running = false;
    let rt = Runtime::start(compile(TAGS, LAD), o, Box::new(SimIo)).unwrap();
    let h = rt.handle();
    let p = h.snapshot().program.clone();
    // Stopped: nothing scans on its own.
    tokio::time::sleep(Duration::from_millis(30)).await;
    assert_eq!(h.snapshot().scans, 0);
    assert_eq!(h.snapshot().state, RunState::Stopped);
    h.write(place(&p, "In"), Value::Bool(true)).await.unwrap();
    for n in 1..=5u64 {
        h.step().await.unwrap();
        // Answered after the scan, its snapshot already published.
        let s = h.snapshot();
        assert_eq!(s.scans, n);
        assert_eq!(s.state, RunState::Stopped);
        assert_eq!(value(&s, "Count"), Value::Dint(n as i32));
        // Outputs are written by the step.
        assert_eq!(value(&s, "Out"), Value::Bool(true));
    }
    tokio::time::sleep(Duration::from_millis(30)).await;
    assert_eq!(h.snapshot().scans, 5, "a stopped runtime does not scan between steps");
    // Refused while running, with nothing done.
    h.run().await.unwrap();
    assert_eq!(h.step().await, Err(alba_runtime::Error::Running));
    assert_eq!(
        alba_runtime::Error::Running.to_string(),
        "the runtime is running: stop it before stepping one scan"
    );
    h.stop().await.unwrap();
    let before = h.snapshot();
    let count = |s: &Snapshot| match value(s, "Count") {
        Value::Dint(v) => v,
        v => panic!("{v:?}"),
    };
    h.step().await.unwrap();
    let after = h.snapshot();
    assert_eq!(after.scans, before.scans + 1);
    assert_eq!(count(&after), count(&before) + 1);
    rt.shutdown();
}

/// A board's pins as a remote-I/O driver sees them (controller mode): its
/// input pin `In` read into the program, the program's `Out` written to it.
#[derive(Clone, Default)]
struct Pins {
    input: Arc<std::sync::atomic::AtomicBool>,
    output: Arc<std::sync::Mutex<Vec<bool>>>,
}

impl alba_runtime::Io for Pins {
    fn name(&self) -> &str {
        "pins"
    }
    fn read_inputs(&mut self, engine: &mut alba_engine::Engine) -> Result<(), IoError> {
        let v = self.input.load(std::sync::atomic::Ordering::Relaxed);
        let p = place(engine.program(), "In");
        engine.write(p, Value::Bool(v));
        engine.set_io_status(true, 3);
        Ok(())
    }
    fn write_outputs(&mut self, engine: &alba_engine::Engine) -> Result<(), IoError> {
        let p = place(engine.program(), "Out");
        let on = engine.memory().read(p) == Value::Bool(true);
        self.output.lock().map_err(|e| IoError::Link(e.to_string()))?.push(on);
        Ok(())
    }
}

#[tokio::test(flavor = "current_thread")]
async fn the_io_driver_is_swapped_between_two_scans_and_back_without_stopping() {
    let rt = Runtime::start(compile(TAGS, LAD), opts(2), Box::new(SimIo)).unwrap();
    let h = rt.handle();
    let p = h.snapshot().program.clone();
    // The simulated I/O: In is the operator's to write.
    h.write(place(&p, "In"), Value::Bool(true)).await.unwrap();
    until(&rt, "Out on", |s| value(s, "Out") == Value::Bool(true)).await;
    let count = |s: &Snapshot| match value(s, "Count") {
        Value::Dint(v) => v,
        v => panic!("{v:?}"),
    };
    // Attach: the board's pin (off) drives In from the next scan.
    let board = Pins::default();
    let before = count(&h.snapshot());
    let old = h.set_io(Box::new(board.clone())).await.unwrap();
    assert_eq!(old.name(), "sim", "the displaced driver comes back");
    let s = until(&rt, "Out off: In follows the board's pin", |s| {
        value(s, "Out") == Value::Bool(false)
    })
    .await;
    assert_eq!(s.state, RunState::Running, "never stopped: {:?}", s.fault);
    assert!(
        count(&s) > before,
        "the program's memory was kept: {} then {}",
        before,
        count(&s)
    );
    assert_eq!(value(&s, "S:IOERRORS"), Value::Dint(3), "the new driver's status");
    board.input.store(true, std::sync::atomic::Ordering::Relaxed);
    until(&rt, "Out on from the board's pin", |s| {
        value(s, "Out") == Value::Bool(true)
    })
    .await;
    until(&rt, "Out on the board's output", |_| {
        board.output.lock().unwrap().last() == Some(&true)
    })
    .await;
    // Detach: the board's output put off through it, the simulated I/O back.
    let was = h.set_io(old).await.unwrap();
    assert_eq!(was.name(), "pins");
    assert_eq!(
        board.output.lock().unwrap().last(),
        Some(&false),
        "the detached board's outputs are off"
    );
    let n = board.output.lock().unwrap().len();
    let scans = h.snapshot().scans;
    let s = until(&rt, "more scans", |s| s.scans > scans + 3).await;
    assert_eq!(
        board.output.lock().unwrap().len(),
        n,
        "the detached board is not written any more"
    );
    assert_eq!(value(&s, "S:IOERRORS"), Value::Dint(0));
    // In keeps its last value (the board said on), the operator's again.
    assert_eq!(value(&s, "Out"), Value::Bool(true));
    h.write(place(&p, "In"), Value::Bool(false)).await.unwrap();
    until(&rt, "Out off", |s| value(s, "Out") == Value::Bool(false)).await;
    drop(was);

    // A board that runs the program itself: refused while a force is on …
    h.force("Out".into(), place(&p, "Out"), Value::Bool(true))
        .await
        .unwrap();
    let mirror = Board {
        mem: Arc::new(std::sync::Mutex::new(p.init.clone())),
        writes: Arc::default(),
    };
    let err = h.set_io(Box::new(mirror)).await.err().expect("refused");
    assert!(
        matches!(&err, alba_runtime::Error::Rejected(m) if m.contains("1 force(s) are on")),
        "{err}"
    );
    assert_eq!(h.snapshot().forces.len(), 1);
    // … and, once forces are off, takes a stopped runtime into run: the board runs.
    h.unforce(None).await.unwrap();
    h.stop().await.unwrap();
    let mut board_mem = p.init.clone();
    board_mem.write(place(&p, "Count"), Value::Dint(7));
    let mirror = Board {
        mem: Arc::new(std::sync::Mutex::new(board_mem)),
        writes: Arc::default(),
    };
    let sim = h.set_io(Box::new(mirror)).await.unwrap();
    assert_eq!(h.snapshot().state, RunState::Running);
    until(&rt, "the board's memory mirrored", |s| {
        value(s, "Count") == Value::Dint(7)
    })
    .await;
    let _ = h.set_io(sim).await.unwrap();
    until(&rt, "the program scanning again from the board's memory", |s| {
        count(s) > 7
    })
    .await;
    rt.shutdown();
}
