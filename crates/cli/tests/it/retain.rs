//! Retentive data survives `kill -9` of `alba run` at random moments: the
//! restored value is never older than one save interval (`retain_ms`), and
//! the file is never torn (a torn file would stop `alba run` from starting).

use crate::scratch;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const RETAIN_MS: u64 = 100;
/// Time allowed beyond one interval for the saver thread's write and fsync
/// and for scheduling on a loaded machine.
const SLACK_MS: u64 = 250;

fn project() -> std::path::PathBuf {
    let dir = scratch("retain-kill");
    let files = [
        (
            "alba.toml",
            format!("name = \"retain\"\nscan_ms = 10\nretain_ms = {RETAIN_MS}\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n"),
        ),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nCount,DINT,,,1,scans counted (retained)\nScratch,DINT,,,,not retained\nOn,TIMER,,,,\nHours,TIMER,,,,retentive timer\n"
                .to_string(),
        ),
        (
            "main.lad",
            "ADD(Count,1,Count)ADD(Scratch,1,Scratch);\nRTO(Hours,3600000,0);\n".to_string(),
        ),
    ];
    for (f, t) in files {
        std::fs::write(dir.join(f), t).expect("write");
    }
    dir
}

struct Run {
    child: Child,
    addr: String,
}

fn start(dir: &std::path::Path) -> Run {
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0"])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("alba run starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("banner");
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    Run { child, addr }
}

/// `GET /api/tags/{tag}` → its JSON value, with a bare HTTP/1.1 exchange.
fn get(addr: &str, tag: &str) -> serde_json::Value {
    let mut s = TcpStream::connect(addr).expect("connect");
    write!(
        s,
        "GET /api/tags/{tag} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .expect("send");
    let mut text = String::new();
    s.read_to_string(&mut text).expect("answer");
    let body = text
        .split("\r\n\r\n")
        .nth(1)
        .unwrap_or_else(|| panic!("no body in {text:?}"));
    let j: serde_json::Value = serde_json::from_str(body).unwrap_or_else(|e| panic!("{e}: {body:?}"));
    j["value"].clone()
}

fn count(addr: &str) -> i64 {
    get(addr, "Count").as_i64().expect("DINT")
}

/// A small deterministic generator (the seed is printed on failure).
struct Lcg(u64);
impl Lcg {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % n
    }
}

#[test]
fn retained_values_survive_kill_9_at_random_moments() {
    let dir = project();
    let seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.as_nanos() as u64);
    let mut rng = Lcg(seed);
    // The least value a restart must restore.
    let mut floor = 0i64;
    for round in 0..6 {
        let mut run = start(&dir);
        let first = count(&run.addr);
        assert!(
            first >= floor,
            "seed {seed}, round {round}: restored Count = {first}, but {floor} was reached more than {} ms before the kill",
            RETAIN_MS + SLACK_MS
        );
        if round > 0 {
            // Scratch (not retained) counts from 0 again, Count from its restored value.
            let scratch = get(&run.addr, "Scratch").as_i64().expect("DINT");
            assert!(scratch < count(&run.addr), "seed {seed}: Count was not restored");
        }
        // Observe while it runs, then kill at a random moment.
        let run_for = Duration::from_millis(300 + rng.below(700));
        let t0 = Instant::now();
        let mut seen: Vec<(Instant, i64)> = Vec::new();
        while t0.elapsed() < run_for {
            seen.push((Instant::now(), count(&run.addr)));
            std::thread::sleep(Duration::from_millis(rng.below(30)));
        }
        run.child.kill().expect("kill -9");
        let killed = Instant::now();
        run.child.wait().expect("reaped");
        let guaranteed = killed - Duration::from_millis(RETAIN_MS + SLACK_MS);
        if let Some(&(_, v)) = seen.iter().rev().find(|(t, _)| *t <= guaranteed) {
            floor = floor.max(v);
        }
    }
    // A graceful stop (SIGTERM) saves the last value exactly.
    let run = start(&dir);
    std::thread::sleep(Duration::from_millis(200));
    let hours_before = get(&run.addr, "Hours.ACC").as_i64().expect("ACC");
    let status = Command::new("kill")
        .args(["-TERM", &run.child.id().to_string()])
        .status()
        .expect("kill -TERM");
    assert!(status.success());
    let mut child = run.child;
    let exit = child.wait().expect("exits");
    assert!(exit.success(), "alba run exits cleanly on SIGTERM: {exit}");
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(".alba/retain.json")).expect("retain file"))
            .expect("JSON");
    let text = saved.to_string();
    assert!(text.contains("Count") && text.contains("Hours"), "{text}");
    assert!(!text.contains("Scratch"), "only retentive data is saved: {text}");
    let run = start(&dir);
    let hours_after = get(&run.addr, "Hours.ACC").as_i64().expect("ACC");
    assert!(
        hours_after >= hours_before,
        "RTO accumulator kept: {hours_before} → {hours_after}"
    );
    let mut child = run.child;
    child.kill().expect("kill");
    child.wait().expect("reaped");
}
