//! The audit trail survives `kill -9` of `alba run`: every write the API
//! acknowledged has its row in `.alba/audit.db` when the file is reopened,
//! whether the kill comes right after a reply or in the middle of writes.

use crate::scratch;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Duration;

fn project() -> std::path::PathBuf {
    let dir = scratch("audit-kill");
    let files = [
        (
            "alba.toml",
            "name = \"audit\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n",
        ),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nSetpoint,DINT,,,,written by the test\nCount,DINT,,,,\n",
        ),
        ("main.lad", "ADD(Count,1,Count);\n"),
    ];
    for (f, t) in files {
        std::fs::write(dir.join(f), t).expect("write");
    }
    dir
}

fn start(dir: &std::path::Path) -> (Child, String) {
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
    (child, addr)
}

/// `PUT /api/tags/Setpoint {"value": v}`: whether it was acknowledged (200).
fn write(addr: &str, v: i64) -> bool {
    let Ok(mut s) = TcpStream::connect(addr) else {
        return false;
    };
    let body = format!("{{\"value\": {v}}}");
    let sent = write!(
        s,
        "PUT /api/tags/Setpoint HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    let mut text = String::new();
    sent.is_ok() && s.read_to_string(&mut text).is_ok() && text.starts_with("HTTP/1.1 200")
}

/// The values of every `write` row on Setpoint in the reopened log.
fn audited(dir: &std::path::Path) -> Vec<i64> {
    let log = alba_audit::Audit::open(dir.join(".alba/audit.db"), alba_audit::Config::default()).expect("reopen");
    let filter = alba_audit::Filter {
        actions: vec![alba_audit::Action::Write],
        target: Some("Setpoint".into()),
        ..Default::default()
    };
    let mut out = Vec::new();
    let mut before = None;
    loop {
        let page = log.query(&filter, before, alba_audit::MAX_PAGE).expect("query");
        out.extend(page.rows.iter().filter_map(|r| r.new.as_deref()?.parse::<i64>().ok()));
        match page.next {
            Some(n) => before = Some(n),
            None => return out,
        }
    }
}

#[test]
fn every_acknowledged_write_has_its_row_after_kill_9() {
    let dir = project();
    let mut next = 1i64;
    for round in 0..4 {
        let (mut child, addr) = start(&dir);
        // Right after replies: a few writes, then the kill.
        let mut acked = Vec::new();
        for _ in 0..5 {
            if write(&addr, next) {
                acked.push(next);
            }
            next += 1;
        }
        assert_eq!(
            acked.len(),
            5,
            "round {round}: writes to a running alba are acknowledged"
        );
        // In the middle of writes: two clients writing while the kill lands.
        let shared = Arc::new(Mutex::new(Vec::new()));
        let writers: Vec<_> = (0..2)
            .map(|w| {
                let (addr, shared) = (addr.clone(), shared.clone());
                let base = next + w * 1_000_000;
                std::thread::spawn(move || {
                    for k in 0..400 {
                        if !write(&addr, base + k) {
                            return;
                        }
                        shared.lock().expect("lock").push(base + k);
                    }
                })
            })
            .collect();
        std::thread::sleep(Duration::from_millis(150 + 100 * round as u64));
        child.kill().expect("kill -9");
        child.wait().expect("reaped");
        for w in writers {
            w.join().expect("writer");
        }
        next += 2_000_000;
        let during = shared.lock().expect("lock").clone();
        assert!(
            !during.is_empty(),
            "round {round}: no write was acknowledged before the kill"
        );
        eprintln!(
            "round {round}: {} writes acknowledged while writing, then killed",
            during.len()
        );
        acked.extend(during);
        let rows = audited(&dir);
        let missing: Vec<i64> = acked.iter().filter(|v| !rows.contains(v)).copied().collect();
        assert!(
            missing.is_empty(),
            "round {round}: acknowledged writes without their audit row: {missing:?}"
        );
    }
}

/// Runs `alba` with `args` in `cwd`, `stdin` piped in.
fn alba_in(cwd: &std::path::Path, args: &[&str], stdin: &str) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("alba runs");
    let _ = child.stdin.take().expect("stdin").write_all(stdin.as_bytes());
    child.wait_with_output().expect("alba ends")
}

/// A row as the user test compares it: action, target, old, new, outcome.
type UserRow = (
    String,
    Option<String>,
    Option<String>,
    Option<String>,
    alba_audit::Outcome,
);

/// `alba user` changes have their rows: added, role and password changed,
/// removed; a refused change is recorded as failed, a command refused
/// before it starts (unknown user) has none.
#[test]
fn user_changes_from_the_command_line_have_rows() {
    let dir = scratch("audit-users");
    std::fs::write(dir.join("alba.toml"), "name = \"x\"\nprograms = [\"main.lad\"]\n").expect("alba.toml");
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\n").expect("tags.csv");
    std::fs::write(dir.join("main.lad"), "XIC(A)OTE(A);\n").expect("main.lad");
    let ok = |args: &[&str], stdin: &str| {
        let out = alba_in(&dir, args, stdin);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    ok(
        &["user", "add", ".", "alice", "--role", "engineer"],
        "correct horse battery\n",
    );
    ok(&["user", "role", ".", "alice", "admin"], "");
    ok(&["user", "passwd", ".", "alice"], "a brand new secret\n");
    ok(&["user", "remove", ".", "alice"], "");
    assert!(!alba_in(&dir, &["user", "remove", ".", "nobody"], "").status.success());
    let log = alba_audit::Audit::open(dir.join(".alba/audit.db"), alba_audit::Config::default()).expect("reopen");
    let rows: Vec<UserRow> = log
        .query(&alba_audit::Filter::default(), None, 100)
        .expect("query")
        .rows
        .into_iter()
        .rev()
        .map(|r| {
            assert_eq!(r.user, None, "no Alba login on the command line");
            assert!(r.detail.as_deref().is_some_and(|d| d.contains("command line")), "{r:?}");
            (r.action, r.target, r.old, r.new, r.outcome)
        })
        .collect();
    let s = |v: &str| Some(v.to_string());
    let ok_row = |a: &str, old: Option<String>, new: Option<String>| {
        (a.to_string(), s("alice"), old, new, alba_audit::Outcome::Ok)
    };
    assert_eq!(
        rows[..4],
        [
            ok_row("user_added", None, s("\"engineer\"")),
            ok_row("user_changed", s("\"engineer\""), s("\"admin\"")),
            ok_row("user_changed", None, s("\"password changed\"")),
            ok_row("user_removed", s("\"admin\""), None),
        ]
    );
    // `nobody`: checked inside the change, so recorded as failed.
    assert_eq!(rows.len(), 5, "{rows:?}");
    assert_eq!(
        (rows[4].0.as_str(), rows[4].1.as_deref()),
        ("user_removed", Some("nobody"))
    );
    assert!(
        matches!(&rows[4].4, alba_audit::Outcome::Failed(e) if e.contains("nobody")),
        "{rows:?}"
    );
}
