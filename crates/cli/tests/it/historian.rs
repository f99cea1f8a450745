//! `alba historian migrate` against a real PostgreSQL server.

use crate::{alba, scratch};
use alba_testkit::pg::{PASSWORD, PgServer};

fn project(name: &str, history: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"line1\"\nprograms = [\"main.lad\"]\n[history]\n{history}"),
    )
    .expect("alba.toml");
    // The programs need not compile for a migration.
    std::fs::write(dir.join("main.lad"), "XIC(Nope)OTE(\n").expect("main.lad");
    dir
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn historian_migrate_creates_the_schema_once_and_refuses_precisely() {
    let Some(pg) = PgServer::start() else { return };
    let url = pg.url();
    let pw = pg.password_file().display().to_string();
    let dir = project(
        "historian_migrate",
        &format!("backend = \"postgres\"\nurl = \"{url}\"\npassword_file = \"{pw}\"\n"),
    );
    let arg = dir.display().to_string();
    for _ in 0..2 {
        let out = alba(&dir, &["historian", "migrate", &arg]);
        assert!(out.status.success(), "{}{}", text(&out.stdout), text(&out.stderr));
        let stdout = text(&out.stdout);
        assert!(
            stdout.contains(
                "historian schema ready: the timescaledb extension is not installed: partitioned table (30-day ranges)"
            ),
            "{stdout}"
        );
    }
    // A wrong password: the server's refusal, never the password.
    let wrong = "wrong-pw-5678";
    std::fs::write(dir.join("bad-pw"), wrong).expect("password file");
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"x\"\nprograms = [\"main.lad\"]\n[history]\nbackend = \"postgres\"\nurl = \"{url}\"\npassword_file = \"bad-pw\"\n"),
    )
    .expect("alba.toml");
    let out = alba(&dir, &["historian", "migrate", &arg]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("password authentication failed"), "{stderr}");
    assert!(!stderr.contains(wrong) && !stderr.contains(PASSWORD), "{stderr}");
    // The embedded historian needs no migration.
    std::fs::write(dir.join("alba.toml"), "name = \"x\"\nprograms = [\"main.lad\"]\n").expect("alba.toml");
    let out = alba(&dir, &["historian", "migrate", &arg]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("backend is not \"postgres\""),
        "{}",
        text(&out.stderr)
    );
}

/// `GET path` of a running `alba run` at `addr` → (status, JSON body), with a bare HTTP/1.0 exchange (no chunks).
pub fn get(addr: &str, path: &str) -> (u16, serde_json::Value) {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(addr).expect("connect");
    write!(s, "GET {path} HTTP/1.0\r\nHost: {addr}\r\nConnection: close\r\n\r\n").expect("send");
    let mut text = String::new();
    s.read_to_string(&mut text).expect("answer");
    let status = text.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = text.split("\r\n\r\n").nth(1).unwrap_or_default();
    (
        status,
        serde_json::from_str(body).unwrap_or(serde_json::Value::String(body.to_owned())),
    )
}

/// A process of the test: stopped with SIGTERM by [`Proc::stop`], killed if the test fails
/// before (so that no server outlives it).
pub struct Proc(Option<std::process::Child>);

impl Proc {
    /// SIGTERM, and what it printed once it exited (successfully: asserted).
    pub fn stop(mut self) -> String {
        let Some(child) = self.0.take() else {
            return String::new();
        };
        let _ = std::process::Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let out = child.wait_with_output().expect("exits");
        assert!(out.status.success(), "{}: {}", out.status, text(&out.stderr));
        text(&out.stdout)
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        if let Some(c) = self.0.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// `alba run .` in `dir`, and the address its studio listens on.
pub fn start_run(dir: &std::path::Path) -> (Proc, String) {
    use std::io::BufRead;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0"])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("alba run starts");
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("banner");
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    (Proc(Some(child)), addr)
}

/// `alba run` with `[history] backend = "postgres"` records its tags under its node id,
/// and its studio's API reads them, and another node's, from the shared database.
#[test]
fn alba_run_records_into_the_shared_postgres_historian() {
    use std::time::{Duration, Instant};
    let Some(pg) = PgServer::start() else { return };
    let url = pg.url();
    let pw = pg.password_file().display().to_string();
    let dir = project(
        "historian_run",
        &format!(
            "backend = \"postgres\"\nurl = \"{url}\"\npassword_file = \"{pw}\"\nnode = \"cell-7\"\nsample_ms = 100\n"
        ),
    );
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\nB,BOOL\n").expect("tags.csv");
    std::fs::write(dir.join("main.lad"), "XIO(A)OTE(B);\n").expect("main.lad");
    let out = alba(&dir, &["historian", "migrate", &dir.display().to_string()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Another node's samples in the same database.
    let mut config = alba_historian::PgConfig::new(url, "line-9", dir.join("other-buffer.db"));
    config.password = Some(PASSWORD.to_owned());
    let other = alba_historian::PgHistorian::open(config).expect("other node");
    let flow: Vec<alba_historian::Sample<'_>> = (0..1_000)
        .map(|i| alba_historian::Sample {
            tag: "Flow",
            t_ms: 1_000_000 + i * 100,
            v: i as f64,
        })
        .collect();
    assert_eq!(other.record_batch(&flow).expect("record"), 1_000);
    let (child, addr) = start_run(&dir);
    let deadline = Instant::now() + Duration::from_secs(120);
    let found = loop {
        let (_, tags) = get(&addr, "/api/history/tags");
        let names: Vec<String> = tags
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|t| t["name"].as_str().map(str::to_owned))
            .collect();
        if names.iter().any(|t| t == "B") || Instant::now() > deadline {
            break names;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    assert!(
        found.contains(&"A".to_owned()) && found.contains(&"B".to_owned()),
        "{found:?}"
    );
    let (code, nodes) = get(&addr, "/api/history/nodes");
    assert_eq!(
        (code, nodes),
        (
            200,
            serde_json::json!({"node": "cell-7", "shared": true, "nodes": ["cell-7", "line-9"]})
        )
    );
    // On after the first scan (the first sample may be the memory before it,
    // and the next one reaches the database with the recorder's next batch).
    let deadline = Instant::now() + Duration::from_secs(60);
    let (on, b) = loop {
        let (code, b) = get(&addr, "/api/history/raw?tag=B&from=0&to=9999999999999&limit=10");
        assert_eq!(code, 200, "{b}");
        let on = b["points"]
            .as_array()
            .and_then(|p| p.last())
            .is_some_and(|x| x[1] == 1.0);
        if on || Instant::now() > deadline {
            break (on, b);
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    assert!(on, "{b}");
    // line-9's tag through this runtime's API: tags, buckets, raw samples and CSV.
    let (code, tags) = get(&addr, "/api/history/tags?node=line-9");
    assert_eq!(
        (code, tags),
        (
            200,
            serde_json::json!([{"name": "Flow", "first_ms": 1_000_000, "last_ms": 1_099_900}])
        )
    );
    let (code, q) = get(
        &addr,
        "/api/history?tag=Flow&node=line-9&from=1000000&to=1099999&points=10",
    );
    assert_eq!(code, 200, "{q}");
    assert_eq!(q["node"], "line-9");
    assert_eq!(
        q["buckets"][0],
        serde_json::json!([1_000_000, 0.0, 99.0, 0.0, 99.0]),
        "{q}"
    );
    assert_eq!(q["buckets"].as_array().map(Vec::len), Some(10), "{q}");
    let (code, e) = get(&addr, "/api/history?tag=Flow&from=1000000&to=1099999");
    assert_eq!(
        (code, e["error"].as_str()),
        (404, Some("no history for `Flow`")),
        "its own tags only"
    );
    let (code, csv) = get(
        &addr,
        "/api/history.csv?tags=Flow@line-9,B&from=1000000&to=1000200&step=100",
    );
    assert_eq!(code, 200);
    assert_eq!(
        csv,
        serde_json::Value::String("Time (ms),Flow@line-9,B\n0,0,\n100,1,\n200,2,\n".into())
    );
    child.stop();
    let b = other.raw_node("cell-7", "B", 0, i64::MAX, 10).expect("raw");
    assert!(b.last().is_some_and(|p| p.v == 1.0), "{b:?}");
}

/// The per-node SQLite files in `files`, once they hold 5 samples of `node`'s `C`.
fn five_counts_in(files: &std::path::Path, node: &str) -> alba_historian::SqliteNodes {
    use std::time::{Duration, Instant};
    let store = alba_historian::SqliteNodes::open(files, alba_historian::Config::default()).expect("files");
    let deadline = Instant::now() + Duration::from_secs(120);
    while store
        .historian(node)
        .and_then(|h| h.raw("C", 0, i64::MAX, 100))
        .map_or(0, |c| c.len())
        < 5
    {
        assert!(Instant::now() < deadline, "{node}'s samples in {}", files.display());
        std::thread::sleep(Duration::from_millis(200));
    }
    store
}

/// A project that counts: `C` goes up by one every `every_ms` (so there are always changes
/// to publish and record, and a lost sample shows as a gap), `B` is on.
fn counting_project(name: &str, every_ms: u32, toml: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::write(dir.join("alba.toml"), toml).expect("alba.toml");
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\nB,BOOL\nT,TIMER\nC,DINT\n").expect("tags.csv");
    std::fs::write(
        dir.join("main.lad"),
        format!("XIO(T.DN)TON(T,{every_ms},0);\nXIC(T.DN)ADD(C,1,C);\nXIO(A)OTE(B);\n"),
    )
    .expect("main.lad");
    dir
}

/// `alba historian --mqtt` between a real Mosquitto and a real PostgreSQL: one `alba run
/// --mqtt` publishing JSON, one publishing Sparkplug B (born before the service started:
/// the service asks it for a rebirth), each runtime's samples in the database under its
/// node; the service stopped for a while loses nothing the broker kept for its session.
#[test]
fn alba_historian_consumes_json_and_sparkplug_from_mosquitto_into_postgres() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let Some(pg) = PgServer::start() else { return };
    let Some(mut broker) = alba_testkit::mqtt::Broker::start() else {
        return;
    };
    let work = scratch("historian_service");
    let spark = counting_project(
        "historian_service_sp",
        100,
        "name = \"edge2\"\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n[mqtt.sparkplug]\ngroup_id = \"Plant\"\ndevice_id = \"PLC\"\n",
    );
    let json = counting_project(
        "historian_service_json",
        100,
        "name = \"line1\"\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n",
    );
    let run = |dir: &std::path::Path| {
        Proc(Some(
            Command::new(env!("CARGO_BIN_EXE_alba"))
                .args(["run", ".", "--http", "127.0.0.1:0", "--mqtt", &broker.addr()])
                .current_dir(dir)
                .stdout(Stdio::null())
                .stderr(Stdio::inherit())
                .spawn()
                .expect("alba run starts"),
        ))
    };
    let pw = pg.password_file().display().to_string();
    let buffer = work.join("buffer.db").display().to_string();
    let service = || {
        let child = Command::new(env!("CARGO_BIN_EXE_alba"))
            .args([
                "historian",
                "--mqtt",
                &broker.addr(),
                "--postgres",
                &pg.url(),
                "--password-file",
                &pw,
                "--buffer",
                &buffer,
                "--primary-host",
                "central",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("alba historian starts");
        Proc(Some(child))
    };
    // The Sparkplug runtime is born before the service listens.
    let sp_run = run(&spark);
    std::thread::sleep(Duration::from_secs(2));
    let svc = service();
    let json_run = run(&json);
    let mut config = alba_historian::PgConfig::new(pg.url(), "reader", work.join("reader.db"));
    config.password = Some(PASSWORD.to_owned());
    let reader = alba_historian::PgHistorian::open(config).expect("reader");
    let sp_node = "Plant/edge2/PLC";
    let wait_for = |node: &str, tag: &str, more_than: usize| {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            let n = reader.raw_node(node, tag, 0, i64::MAX, 100_000).map_or(0, |r| r.len());
            if n > more_than {
                return n;
            }
            assert!(Instant::now() < deadline, "{node} {tag}: {n} samples");
            std::thread::sleep(Duration::from_millis(200));
        }
    };
    wait_for("line1", "C", 5);
    wait_for(sp_node, "C", 5);
    for node in ["line1", sp_node] {
        let tags: Vec<String> = reader
            .tags_of(node)
            .expect("tags")
            .into_iter()
            .map(|t| t.name)
            .collect();
        for t in ["A", "B", "C", "T.ACC"] {
            assert!(tags.iter().any(|x| x == t), "{node}: {tags:?}");
        }
        let b = reader.raw_node(node, "B", 0, i64::MAX, 100).expect("raw");
        assert!(!b.is_empty() && b.iter().all(|p| p.v == 1.0), "{node}: {b:?}");
        let c = reader.raw_node(node, "C", 0, i64::MAX, 100_000).expect("raw");
        assert!(c.windows(2).all(|w| w[0].v < w[1].v), "{node}: C counts up: {c:?}");
    }
    let first = svc.stop();
    assert!(
        first.contains("rebirths asked for") && !first.contains(" 0 rebirths"),
        "{first}"
    );
    // While the service is away the broker keeps its session's messages.
    let away_from = unix_ms();
    std::thread::sleep(Duration::from_secs(3));
    let away_to = unix_ms();
    let svc = service();
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let c = reader
            .raw_node("line1", "C", away_from + 500, away_to - 500, 1_000)
            .expect("raw");
        if c.len() >= 10 {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the samples sent while the service was away: {c:?}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    // A second service, into SQLite files (one per node), JSON only, its own session.
    let files = work.join("nodes");
    let sqlite = Proc(Some(
        Command::new(env!("CARGO_BIN_EXE_alba"))
            .args([
                "historian",
                "--mqtt",
                &broker.addr(),
                "--no-sparkplug",
                "--client-id",
                "to-sqlite",
            ])
            .arg("--sqlite")
            .arg(&files)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("alba historian --sqlite starts"),
    ));
    let store = five_counts_in(&files, "line1");
    sp_run.stop();
    json_run.stop();
    // Stopped while the broker is gone (reconnecting), it stores what it has and exits.
    broker.stop();
    let last = svc.stop();
    assert!(last.contains("historian: stopped after"), "{last}");
    assert_eq!(reader.nodes().expect("nodes"), [sp_node, "line1"]);
    sqlite.stop();
    assert_eq!(store.nodes().expect("nodes"), ["line1"], "JSON only");
}

fn unix_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// The history problem in a runtime's `/api/status`, if any.
fn history_problem(addr: &str) -> Option<String> {
    let (_, status) = get(addr, "/api/status");
    status["problems"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|p| p["source"] == "history")
        .map(|p| p["message"].as_str().unwrap_or_default().to_owned())
}

/// Two `alba run` processes record into one PostgreSQL, each under its own node id; the
/// database is stopped for 30 s (the acceptance's outage) and started again: every sample
/// of both arrives (their local buffers, then back-fill), in order, none lost.
#[test]
fn two_runtimes_share_postgres_and_lose_nothing_while_it_is_down_for_30_s() {
    use std::time::{Duration, Instant};
    let Some(pg) = PgServer::start() else { return };
    let pw = pg.password_file().display().to_string();
    let dirs: Vec<std::path::PathBuf> = ["cell-1", "cell-2"]
        .into_iter()
        .map(|node| {
            counting_project(
                &format!("historian_outage_{node}"),
                500,
                &format!(
                    "name = \"{node}\"\nprograms = [\"main.lad\"]\n[history]\nbackend = \"postgres\"\nurl = \"{}\"\npassword_file = \"{pw}\"\n",
                    pg.url()
                ),
            )
        })
        .collect();
    let out = alba(&dirs[0], &["historian", "migrate", &dirs[0].display().to_string()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let runs: Vec<(Proc, String)> = dirs.iter().map(|d| start_run(d)).collect();
    let mut config = alba_historian::PgConfig::new(pg.url(), "reader", dirs[0].join("reader.db"));
    config.password = Some(PASSWORD.to_owned());
    let reader = alba_historian::PgHistorian::open(config).expect("reader");
    let counted = |node: &str, after: i64| {
        reader
            .raw_node(node, "C", after, i64::MAX, 100_000)
            .map_or(0, |c| c.len())
    };
    let deadline = Instant::now() + Duration::from_secs(120);
    while counted("cell-1", 0) < 3 || counted("cell-2", 0) < 3 {
        assert!(Instant::now() < deadline, "both runtimes record");
        std::thread::sleep(Duration::from_millis(200));
    }
    let down_at = unix_ms();
    pg.stop();
    // Each runtime says so, and keeps recording into its buffer.
    for (_, addr) in &runs {
        let deadline = Instant::now() + Duration::from_secs(20);
        loop {
            if let Some(p) = history_problem(addr) {
                assert!(p.contains("buffering in .alba/history-buffer.db"), "{p}");
                assert!(!p.contains(PASSWORD), "{p}");
                break;
            }
            assert!(
                Instant::now() < deadline,
                "{addr}: no history problem while the database is down"
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
    let outage = Duration::from_secs(30);
    let elapsed = Duration::from_millis(u64::try_from(unix_ms() - down_at).unwrap_or(0));
    std::thread::sleep(outage.saturating_sub(elapsed));
    pg.start_again();
    let up_at = unix_ms();
    // Back-filled: the problem clears, and recording goes on past the outage.
    let deadline = Instant::now() + Duration::from_secs(120);
    for (_, addr) in &runs {
        while history_problem(addr).is_some()
            || counted("cell-1", up_at + 1_000) < 2
            || counted("cell-2", up_at + 1_000) < 2
        {
            assert!(Instant::now() < deadline, "{addr}: {:?}", history_problem(addr));
            std::thread::sleep(Duration::from_millis(200));
        }
    }
    for (child, _) in runs {
        child.stop();
    }
    assert_eq!(reader.nodes().expect("nodes"), ["cell-1", "cell-2"]);
    for node in ["cell-1", "cell-2"] {
        let c = reader.raw_node(node, "C", 0, i64::MAX, 100_000).expect("raw");
        // Every count from the first recorded to the last: none lost, none out of order.
        for w in c.windows(2) {
            assert!(
                w[1].v == w[0].v + 1.0 && w[1].t_ms > w[0].t_ms,
                "{node}: a gap at {w:?}"
            );
        }
        let during = c.iter().filter(|p| p.t_ms > down_at && p.t_ms < up_at).count();
        // Two counts a second for 30 s, recorded while the database was down.
        assert!(during >= 50, "{node}: {during} samples recorded during the outage");
    }
}

/// `alba historian --mqtt` to a broker that speaks TLS only and asks for client
/// certificates: with the broker's CA and a client certificate, an `alba run` that
/// publishes over TLS reaches the SQLite files; with another CA the service says why it
/// cannot connect (once, not at every retry) and stores nothing.
#[test]
fn alba_historian_reaches_a_tls_broker_with_its_ca_and_a_client_certificate() {
    use std::io::BufRead;
    use std::process::{Command, Stdio};
    use std::time::Duration;
    let Some(mut broker) = alba_testkit::mqtt::Broker::start() else {
        return;
    };
    let tls = broker.enable_tls();
    let (ca, cert, key) = (tls.ca.display(), tls.client_cert.display(), tls.client_key.display());
    let project = counting_project(
        "historian_tls_json",
        100,
        &format!(
            "name = \"tls1\"\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n[mqtt]\nca_file = \"{ca}\"\nclient_cert = \"{cert}\"\nclient_key = \"{key}\"\n"
        ),
    );
    let _run = Proc(Some(
        Command::new(env!("CARGO_BIN_EXE_alba"))
            .args(["run", ".", "--http", "127.0.0.1:0", "--mqtt", &broker.addr()])
            .current_dir(&project)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("alba run starts"),
    ));
    let service = |files: &std::path::Path, ca: &std::path::Path, id: &str| {
        Command::new(env!("CARGO_BIN_EXE_alba"))
            .args([
                "historian",
                "--mqtt",
                &broker.addr(),
                "--no-sparkplug",
                "--client-id",
                id,
            ])
            .arg("--sqlite")
            .arg(files)
            .arg("--mqtt-ca-file")
            .arg(ca)
            .arg("--mqtt-client-cert")
            .arg(&tls.client_cert)
            .arg("--mqtt-client-key")
            .arg(&tls.client_key)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("alba historian starts")
    };
    let work = scratch("historian_tls");
    // Another CA: the broker's certificate is refused, said once.
    let refused_files = work.join("refused");
    let mut refused = Proc(Some(service(&refused_files, &tls.other_ca, "refused")));
    let stderr = refused.0.as_mut().and_then(|c| c.stderr.take()).expect("stderr");
    let (tx, rx) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let said = loop {
        let line = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("the service says why it cannot connect");
        if line.contains("cannot connect") {
            break line;
        }
    };
    assert!(
        said.contains("cannot connect to 127.0.0.1") && said.to_lowercase().contains("certificate"),
        "{said}"
    );
    // The good service.
    let files = work.join("nodes");
    let good = Proc(Some(service(&files, &tls.ca, "good")));
    five_counts_in(&files, "tls1");
    let out = good.stop();
    assert!(out.contains("samples stored"), "{out}");
    // Meanwhile the refused service retried without saying it again, and stored nothing.
    refused.stop();
    reader.join().expect("stderr read");
    let again: Vec<String> = rx.try_iter().filter(|l| l.contains("cannot connect")).collect();
    assert!(again.is_empty(), "said again: {again:?}");
    let none = alba_historian::SqliteNodes::open(&refused_files, alba_historian::Config::default()).expect("files");
    assert!(none.nodes().expect("nodes").is_empty());
}
