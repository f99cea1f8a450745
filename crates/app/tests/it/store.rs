//! `alba run` when its stores fail (issue 15, docs/reliability.md): a damaged
//! retain file or history database, a full disk, the free-space floor. The
//! PLC keeps scanning, and `/api/status` says what is wrong until it clears.

use super::{copy_example, options, serve};
use serde_json::Value as Json;
use std::path::Path;
use std::time::Duration;

async fn status(addr: std::net::SocketAddr) -> Json {
    reqwest::get(format!("http://{addr}/api/status"))
        .await
        .expect("GET /api/status")
        .json()
        .await
        .expect("JSON")
}

async fn tag(addr: std::net::SocketAddr, name: &str) -> Json {
    let v: Json = reqwest::get(format!("http://{addr}/api/tags/{name}"))
        .await
        .expect("GET tag")
        .json()
        .await
        .expect("JSON");
    v["value"].clone()
}

/// Polls the tag `name` (up to 5 s: the engine copies the health into its
/// system tags at the next scan) until it is `want`.
async fn tag_is(addr: std::net::SocketAddr, name: &str, want: bool) {
    for _ in 0..50 {
        if tag(addr, name).await == want {
            return;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("{name} is not {want}");
}

/// Polls the status (up to 60 s: a bound for a loaded machine, not a speed
/// requirement) until `f` holds; the last status.
async fn status_until(addr: std::net::SocketAddr, what: &str, f: impl Fn(&Json) -> bool) -> Json {
    for _ in 0..600 {
        let s = status(addr).await;
        if f(&s) {
            return s;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("{what}: {}", status(addr).await)
}

fn sources(s: &Json) -> Vec<String> {
    s["problems"]
        .as_array()
        .map(|ps| {
            ps.iter()
                .map(|p| p["source"].as_str().unwrap_or("").to_string())
                .collect()
        })
        .unwrap_or_default()
}

fn append(dir: &Path, toml: &str) {
    let p = dir.join("alba.toml");
    let text = std::fs::read_to_string(&p).expect("alba.toml") + toml;
    std::fs::write(p, text).expect("alba.toml");
}

async fn stop(stop: tokio::sync::oneshot::Sender<()>, task: tokio::task::JoinHandle<()>) {
    let _ = stop.send(());
    let _ = tokio::time::timeout(Duration::from_secs(10), task).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_damaged_retain_file_starts_the_plc_and_says_so() {
    let dir = copy_example("tank", "retain-damaged");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    std::fs::write(
        dir.join(".alba/retain.json"),
        "{\"format\": \"alba-retain\", \"values\": ",
    )
    .expect("write");
    // Refused when so configured, the file untouched.
    let mut refusing = dir.clone().into_os_string();
    refusing.push("-refuse");
    let refusing = std::path::PathBuf::from(refusing);
    let _ = std::fs::remove_dir_all(&refusing);
    std::fs::create_dir_all(refusing.join(".alba")).expect("dir");
    for f in ["alba.toml", "main.lad", "tags.csv"] {
        std::fs::copy(dir.join(f), refusing.join(f)).expect("copy");
    }
    std::fs::copy(dir.join(".alba/retain.json"), refusing.join(".alba/retain.json")).expect("copy");
    append(&refusing, "\n[runtime]\non_retain_error = \"refuse\"\n");
    match alba_app::run(&refusing, options("sim"), |_| panic!("must not start"), async {}).await {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("on_retain_error = \"refuse\""), "{m}"),
        _ => panic!("expected a refusal"),
    }
    assert!(refusing.join(".alba/retain.json").exists());
    // The default: it starts, keeps the file aside and says so.
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let st = status(addr).await;
    assert_eq!(st["retain_lost"], true, "{st}");
    assert_eq!(st["store_ok"], false);
    assert!(sources(&st).contains(&"retain".to_string()), "{st}");
    assert!(
        st["problems"][0]["message"]
            .as_str()
            .unwrap_or("")
            .contains("retentive data lost")
    );
    tag_is(addr, "S:RETAINLOST", true).await;
    tag_is(addr, "S:STOREOK", false).await;
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > 10).await;
    stop(s, task).await;
    let aside = std::fs::read_dir(dir.join(".alba"))
        .expect("dir")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.file_name().to_string_lossy().starts_with("retain.json.damaged-"))
        })
        .count();
    assert_eq!(aside, 1);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&refusing);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_damaged_or_foreign_history_database_is_replaced_or_refused() {
    let dir = copy_example("tank", "history-damaged");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    std::fs::write(
        dir.join(".alba/history.db"),
        b"SQLite format 3\0 and then rubbish ".repeat(200),
    )
    .expect("db");
    append(&dir, "\n[history]\non_damage = \"refuse\"\n");
    match alba_app::run(&dir, options("sim"), |_| panic!("must not start"), async {}).await {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("not a usable history database"), "{m}"),
        _ => panic!("expected a refusal"),
    }
    let text = std::fs::read_to_string(dir.join("alba.toml"))
        .expect("toml")
        .replace("\"refuse\"", "\"fresh\"");
    std::fs::write(dir.join("alba.toml"), text).expect("toml");
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let st = status(addr).await;
    assert!(sources(&st).contains(&"history-damaged".to_string()), "{st}");
    assert_eq!(st["retain_lost"], false);
    // Recording goes on into the fresh database.
    let history = loop {
        let h: Json = reqwest::get(format!("http://{addr}/api/history/tags"))
            .await
            .expect("history")
            .json()
            .await
            .expect("JSON");
        if h.as_array().is_some_and(|a| !a.is_empty()) {
            break h;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert!(
        history.to_string().contains("LEVEL") || history.to_string().contains("S:SCANTIME"),
        "{history}"
    );
    stop(s, task).await;
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn below_the_free_space_floor_recording_pauses_with_a_flag() {
    let dir = copy_example("tank", "floor");
    append(&dir, "\n[history]\nmin_free_mb = 16777216\n");
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let st = status_until(addr, "history-disk", |s| {
        sources(s).contains(&"history-disk".to_string())
    })
    .await;
    assert!(
        st["problems"][0]["message"]
            .as_str()
            .unwrap_or("")
            .contains("history paused"),
        "{st}"
    );
    tag_is(addr, "S:STOREOK", false).await;
    // Scanning goes on.
    let scans = st["scans"].as_u64().unwrap_or(0);
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
    stop(s, task).await;
    let _ = std::fs::remove_dir_all(&dir);
}

/// A real full disk: `.alba` on a 2 MB tmpfs the test mounts (root only;
/// never skipped under CI).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_disk_is_reported_and_clears_when_space_returns() {
    let dir = copy_example("tank", "diskfull");
    let alba = dir.join(".alba");
    std::fs::create_dir_all(&alba).expect(".alba");
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=2m", "tmpfs"])
        .arg(&alba)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        assert!(
            std::env::var("CI").is_err(),
            "cannot mount a tmpfs (run the tests as root): the disk-full test must run under CI"
        );
        eprintln!("skipped: cannot mount a tmpfs here (not root)");
        return;
    }
    struct Unmount(std::path::PathBuf);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = std::process::Command::new("umount").arg(&self.0).status();
            let _ = std::fs::remove_dir_all(self.0.parent().unwrap_or(&self.0));
        }
    }
    let _unmount = Unmount(alba.clone());
    // Leave ~600 KB: the history database fills it within seconds. No floor,
    // so that the writes themselves fail.
    std::fs::write(alba.join("filler"), vec![0u8; 1400 * 1024]).expect("filler");
    append(&dir, "\nretain_ms = 100\n[history]\nmin_free_mb = 0\nsample_ms = 10\n");
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let st = status_until(addr, "a history problem", |s| {
        sources(s).contains(&"history".to_string())
    })
    .await;
    let msg = st["problems"]
        .as_array()
        .and_then(|ps| ps.iter().find(|p| p["source"] == "history"))
        .map(|p| p["message"].to_string())
        .unwrap_or_default();
    assert!(msg.contains("disk is full"), "{msg}");
    assert_eq!(st["store_ok"], false);
    let scans = st["scans"].as_u64().unwrap_or(0);
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
    // Space comes back: so does recording, and the problem clears.
    std::fs::remove_file(alba.join("filler")).expect("free space");
    status_until(addr, "the problems to clear", |s| s["store_ok"] == true).await;
    tag_is(addr, "S:STOREOK", true).await;
    stop(s, task).await;
}

/// Issue 31: with the disk full every action was refused, Stop and removing
/// forces included, because the audit row could not be written. Those two
/// now always work: their rows go to the preallocated `audit.journal` and
/// into audit.db once it can be written again. Other actions are still
/// refused. A real full disk: `.alba` on a 2 MB tmpfs (root only).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn with_the_disk_full_stop_and_unforce_still_work_and_are_audited_later() {
    let dir = copy_example("tank", "auditfull");
    let alba = dir.join(".alba");
    std::fs::create_dir_all(&alba).expect(".alba");
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=2m", "tmpfs"])
        .arg(&alba)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        assert!(
            std::env::var("CI").is_err(),
            "cannot mount a tmpfs (run the tests as root): the disk-full test must run under CI"
        );
        eprintln!("skipped: cannot mount a tmpfs here (not root)");
        return;
    }
    struct Unmount(std::path::PathBuf);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = std::process::Command::new("umount").arg(&self.0).status();
            let _ = std::fs::remove_dir_all(self.0.parent().unwrap_or(&self.0));
        }
    }
    let _unmount = Unmount(alba.clone());
    append(&dir, "\n[history]\nenabled = false\n");
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let http = reqwest::Client::new();
    let call = |method: reqwest::Method, path: &str, body: Option<Json>| {
        let req = http
            .request(method, format!("http://{addr}{path}"))
            .header("content-type", "application/json")
            .body(body.map(|b| b.to_string()).unwrap_or_else(|| "{}".into()));
        async move { req.send().await.expect("request").status().as_u16() }
    };
    let force = |v: bool| serde_json::json!({ "value": v });
    assert_eq!(
        call(reqwest::Method::PUT, "/api/forces/Bomba1", Some(force(true))).await,
        200
    );
    // Fill the disk to the last byte.
    {
        use std::io::Write;
        let mut f = std::fs::File::create(alba.join("filler")).expect("filler");
        let block = vec![0u8; 64 * 1024];
        while f.write_all(&block).is_ok() {}
        while f.write_all(&[0u8; 512]).is_ok() {}
        let _ = f.sync_all();
    }
    // Ordinary actions are refused once the log cannot be written (SQLite
    // may still fit a few rows in its write-ahead log first).
    let mut refused = false;
    for i in 0..500 {
        if call(
            reqwest::Method::PUT,
            "/api/tags/Llenar",
            Some(serde_json::json!({ "value": i % 2 == 0 })),
        )
        .await
            == 500
        {
            refused = true;
            break;
        }
    }
    assert!(refused, "a write was never refused on a full disk");
    // Safety actions are not.
    assert_eq!(call(reqwest::Method::DELETE, "/api/forces/Bomba1", None).await, 204);
    assert_eq!(call(reqwest::Method::POST, "/api/stop", None).await, 200);
    let st = status(addr).await;
    assert_eq!(st["state"], "stopped", "{st}");
    assert_eq!(st["forces"].as_array().map(Vec::len), Some(0), "{st}");
    // Space comes back: the next row written brings the journal's in.
    std::fs::remove_file(alba.join("filler")).expect("free space");
    assert_eq!(call(reqwest::Method::POST, "/api/run", None).await, 200);
    let scans = status(addr).await["scans"].as_u64().unwrap_or(0);
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 5).await;
    stop(s, task).await;
    let log = alba_audit::Audit::open(alba.join("audit.db"), alba_audit::Config::default()).expect("audit");
    let rows = log
        .query(&alba_audit::Filter::default(), None, 1000)
        .expect("query")
        .rows;
    for action in [alba_audit::Action::Stop, alba_audit::Action::Unforce] {
        let row = rows
            .iter()
            .find(|r| r.action == action.name())
            .unwrap_or_else(|| panic!("no {action:?} row: {rows:?}"));
        assert_eq!(row.outcome, alba_audit::Outcome::Ok, "{row:?}");
        assert!(row.detail.as_deref().unwrap_or("").contains("audit.journal"), "{row:?}");
    }
}

/// Issue 31: a wall clock 800 days ahead at start made retention delete the
/// whole audit trail and all history (1 808 rows → 0). Stores whose newest
/// rows are 800 days older than the clock look exactly like that; retention
/// is held, the problem `clock` says why, nothing is deleted, the PLC scans.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_clock_far_ahead_of_the_stores_holds_retention_and_deletes_nothing() {
    let dir = copy_example("tank", "clockjump");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("clock")
        .as_millis() as i64;
    let then = now - 800 * 86_400_000;
    {
        let a = alba_audit::Audit::open_project(&dir, alba_audit::Config::default()).expect("audit");
        for k in 0..20 {
            let e = alba_audit::Entry::new(then + k * 60_000, alba_audit::Action::Write);
            a.record(&e, &alba_audit::Outcome::Ok).expect("row");
        }
        let h = alba_historian::Historian::open(dir.join(".alba/history.db"), alba_historian::Config::default())
            .expect("history");
        for k in 0..50 {
            h.record(then + k * 1000, &[("Nivel_L", k as f64)]).expect("sample");
        }
        h.flush().expect("flush");
    }
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let st = status_until(addr, "the clock problem", |s| sources(s).contains(&"clock".to_string())).await;
    let msg = st["problems"]
        .as_array()
        .and_then(|ps| ps.iter().find(|p| p["source"] == "clock"))
        .map(|p| p["message"].to_string())
        .unwrap_or_default();
    assert!(
        msg.contains("799 days after the newest row") && msg.contains("retention-held"),
        "{msg}"
    );
    let scans = st["scans"].as_u64().unwrap_or(0);
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
    stop(s, task).await;
    let a = alba_audit::Audit::open_project(&dir, alba_audit::Config::default()).expect("audit");
    let old_rows = a
        .query(
            &alba_audit::Filter {
                to_ms: Some(then + 3_600_000),
                ..Default::default()
            },
            None,
            100,
        )
        .expect("query")
        .rows
        .len();
    assert_eq!(old_rows, 20, "the audit trail was cut");
    let h = alba_historian::Historian::open(dir.join(".alba/history.db"), alba_historian::Config::default())
        .expect("history");
    let kept = h.raw("Nivel_L", then, then + 3_600_000, 100).expect("raw").len();
    assert_eq!(kept, 50, "history was cut");
    assert!(dir.join(".alba/retention-held").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The ways a store file gets damaged: random bytes, a damaged header, torn
/// pages in the middle, a truncation.
fn damage(path: &Path, kind: &str) {
    let mut bytes = std::fs::read(path).expect("store file");
    let mut x: u32 = 0x1234_5678;
    let mut noise = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x as u8
    };
    match kind {
        "random" => bytes.iter_mut().for_each(|b| *b = noise()),
        "header" => bytes[..100].iter_mut().for_each(|b| *b = noise()),
        "torn" => {
            let mid = bytes.len() / 2 / 4096 * 4096;
            bytes[mid..mid + 4096].iter_mut().for_each(|b| *b = noise());
        }
        "truncated" => bytes.truncate(bytes.len() / 2),
        _ => unreachable!(),
    }
    std::fs::write(path, bytes).expect("damage");
}

/// The files moved aside next to `name` in `.alba`.
fn aside(dir: &Path, name: &str) -> Vec<String> {
    std::fs::read_dir(dir.join(".alba"))
        .expect("dir")
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with(&format!("{name}.damaged-")))
        .collect()
}

/// Issue 31: a damaged `audit.db` stopped `alba run` from starting. It is
/// moved aside with its `-wal`/`-shm`, a fresh trail starts, the problem
/// `audit-damaged` says so, the PLC runs and actions are audited again.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_damaged_audit_trail_is_moved_aside_and_the_plc_starts() {
    for kind in ["random", "header", "torn", "truncated"] {
        let dir = copy_example("tank", &format!("audit-damaged-{kind}"));
        {
            let a = alba_audit::Audit::open_project(&dir, alba_audit::Config::default()).expect("audit");
            let long = "x".repeat(2000);
            for k in 0..200 {
                let e = alba_audit::Entry {
                    detail: Some(long.clone()),
                    ..alba_audit::Entry::new(1_700_000_000_000 + k, alba_audit::Action::Write)
                };
                a.record(&e, &alba_audit::Outcome::Ok).expect("row");
            }
        }
        damage(&dir.join(".alba/audit.db"), kind);
        let (addr, s, task) = serve(&dir, options("sim")).await;
        let st = status(addr).await;
        assert!(sources(&st).contains(&"audit-damaged".to_string()), "{kind}: {st}");
        assert_eq!(st["store_ok"], false);
        let scans = st["scans"].as_u64().unwrap_or(0);
        status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
        let res = reqwest::Client::new()
            .put(format!("http://{addr}/api/tags/Llenar"))
            .json(&serde_json::json!({ "value": true }))
            .send()
            .await
            .expect("write");
        assert_eq!(res.status(), 200, "{kind}: a write is audited in the fresh trail");
        stop(s, task).await;
        let moved = aside(&dir, "audit.db");
        assert!(
            moved
                .iter()
                .any(|n| n["audit.db.damaged-".len()..].chars().all(|c| c.is_ascii_digit())),
            "{kind}: {moved:?}"
        );
        let a = alba_audit::Audit::open_project(&dir, alba_audit::Config::default()).expect("fresh");
        assert_eq!(
            a.query(&alba_audit::Filter::default(), None, 10)
                .expect("rows")
                .rows
                .len(),
            1,
            "{kind}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// An alarm log at `dir` with 200 events (several pages), closed.
fn alarm_log_with_events(dir: &Path) {
    let path = dir.join(".alba/alarms.db");
    drop(alba_alarms::Log::open(&path, 0).expect("log"));
    let db = rusqlite::Connection::open(&path).expect("sqlite");
    let long = "m".repeat(1000);
    for k in 0..200 {
        db.execute(
            "INSERT INTO events(t, alarm, tag, from_state, to_state, value, severity, message)
             VALUES(?1, 'estop', 'STOP', 'normal', 'active_unacked', 1, 900, ?2)",
            rusqlite::params![1_700_000_000_000i64 + k, long],
        )
        .expect("event");
    }
}

/// Issue 31: a damaged `alarms.db` stopped `alba run` from starting. It is
/// moved aside with its `-wal`/`-shm`, a fresh log starts, the problem
/// `alarms-damaged` says so, the PLC runs.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_damaged_alarm_log_is_moved_aside_and_the_plc_starts() {
    for kind in ["random", "header", "torn", "truncated"] {
        let dir = copy_example("tank-plant", &format!("alarms-damaged-{kind}"));
        std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
        alarm_log_with_events(&dir);
        damage(&dir.join(".alba/alarms.db"), kind);
        let (addr, s, task) = serve(&dir, options("sim")).await;
        let st = status(addr).await;
        assert!(sources(&st).contains(&"alarms-damaged".to_string()), "{kind}: {st}");
        assert_eq!(st["store_ok"], false, "{kind}");
        let scans = st["scans"].as_u64().unwrap_or(0);
        status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
        stop(s, task).await;
        let moved = aside(&dir, "alarms.db");
        assert!(
            moved
                .iter()
                .any(|n| n["alarms.db.damaged-".len()..].chars().all(|c| c.is_ascii_digit())),
            "{kind}: {moved:?}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Issue 31: with pages of `alarms.db` damaged while running, acknowledging
/// answered 500, `log.csv` was cut off and `/api/status` said `store_ok:
/// true`. The damage is found by the first read or write of those pages,
/// the file moved aside for a fresh log (later writes made there), and the
/// problem `alarms-damaged` shown; the PLC scans on.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn alarm_log_pages_damaged_while_running_are_reported_and_recovered() {
    let dir = copy_example("tank-plant", "alarms-torn-live");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    alarm_log_with_events(&dir);
    let (addr, s, task) = serve(&dir, options("sim")).await;
    let http = reqwest::Client::new();
    let url = |p: &str| format!("http://{addr}{p}");
    // The emergency stop raises `estop`.
    let res = http
        .put(url("/api/forces/STOP"))
        .json(&serde_json::json!({ "value": true }))
        .send()
        .await
        .expect("force");
    assert_eq!(res.status(), 200);
    let mut raised = false;
    for _ in 0..300 {
        let all: Json = http
            .get(url("/api/alarms"))
            .send()
            .await
            .expect("alarms")
            .json()
            .await
            .expect("json");
        if all.as_array().is_some_and(|a| {
            a.iter()
                .any(|x| x["id"] == "estop" && x["state"].as_str().is_some_and(|st| st.ends_with("_unacked")))
        }) {
            raised = true;
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let all: Json = http
        .get(url("/api/alarms?all=true"))
        .send()
        .await
        .expect("alarms")
        .json()
        .await
        .expect("json");
    let estop = all
        .as_array()
        .and_then(|a| a.iter().find(|x| x["id"] == "estop"))
        .cloned();
    assert!(raised, "estop was not raised: {estop:?}");
    // Damage the log behind the server's back, as a bad sector would: the
    // table of events now points at a page past the end of the file (a
    // damaged schema page; torn data pages show the same way, but only once
    // SQLite reads them back from disk, which a test cannot force).
    let path = dir.join(".alba/alarms.db");
    let other = rusqlite::Connection::open(&path).expect("sqlite");
    let cookie: i64 = other
        .query_row("PRAGMA schema_version", [], |r| r.get(0))
        .expect("schema version");
    // The new schema cookie makes the server's connection read the damage.
    other
        .execute_batch(&format!(
            "PRAGMA writable_schema = ON;
             UPDATE sqlite_master SET rootpage = 99999 WHERE name = 'events';
             PRAGMA schema_version = {};
             PRAGMA writable_schema = OFF;",
            cookie + 1
        ))
        .expect("damage");
    drop(other);
    // The export reads every page: it finds the damage (its answer is cut
    // off or refused), the file is moved aside and the problem shown.
    let _ = http
        .get(url("/api/alarms/log.csv"))
        .send()
        .await
        .expect("csv")
        .text()
        .await;
    let st = status_until(addr, "the damage reported", |s| {
        sources(s).contains(&"alarms-damaged".to_string())
    })
    .await;
    assert_eq!(st["store_ok"], false);
    assert!(!aside(&dir, "alarms.db").is_empty());
    // Acknowledging works, into the fresh log, which exports whole.
    let res = http
        .post(url("/api/alarms/estop/ack"))
        .json(&serde_json::json!({ "comment": "seen" }))
        .send()
        .await
        .expect("ack");
    assert_eq!(res.status(), 200, "{}", res.text().await.unwrap_or_default());
    let csv = http.get(url("/api/alarms/log.csv")).send().await.expect("csv");
    assert_eq!(csv.status(), 200);
    let text = csv.text().await.expect("text");
    assert!(text.contains("seen"), "{text}");
    let scans = st["scans"].as_u64().unwrap_or(0);
    status_until(addr, "scanning", |s| s["scans"].as_u64().unwrap_or(0) > scans + 10).await;
    stop(s, task).await;
    let _ = std::fs::remove_dir_all(&dir);
}
