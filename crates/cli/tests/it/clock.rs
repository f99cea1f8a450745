//! `alba run` under a wall clock before 1970 (issue 31): hyper formatted its
//! `Date` header from the clock and panicked in every answer, so the PLC
//! scanned on behind a dead API. The clock is faked for the process with
//! libfaketime (Debian's `libfaketime`, installed by test.sh).

use crate::repo;
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};

fn libfaketime() -> Option<std::path::PathBuf> {
    ["x86_64-linux-gnu", "aarch64-linux-gnu"]
        .iter()
        .map(|a| std::path::PathBuf::from(format!("/usr/lib/{a}/faketime/libfaketime.so.1")))
        .find(|p| p.exists())
}

/// `GET path` on `addr`: the status line and the body.
fn get(addr: &str, path: &str) -> (String, String) {
    let Ok(mut s) = std::net::TcpStream::connect(addr) else {
        return (String::new(), String::new());
    };
    let _ = write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n");
    let mut text = String::new();
    let _ = s.read_to_string(&mut text);
    let status = text.lines().next().unwrap_or("").to_string();
    let body = text.split("\r\n\r\n").nth(1).unwrap_or("").to_string();
    (status, body)
}

#[test]
fn the_api_answers_under_a_clock_before_1970() {
    let Some(lib) = libfaketime() else {
        assert!(
            std::env::var("CI").is_err(),
            "libfaketime is missing: test.sh installs it (need_faketime)"
        );
        eprintln!("skipped: libfaketime is not installed (apt-get install libfaketime)");
        return;
    };
    let dir = crate::scratch("clock-1960");
    for f in ["alba.toml", "main.lad", "tags.csv"] {
        std::fs::copy(repo().join("examples/tank").join(f), dir.join(f)).expect("copy");
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0"])
        .current_dir(&dir)
        .env("LD_PRELOAD", &lib)
        .env("FAKETIME", "@1960-01-01 00:00:00")
        // The engine's deadlines and tokio's timers keep the real monotonic clock.
        .env("FAKETIME_DONT_FAKE_MONOTONIC", "1")
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
    let scans = |body: &str| -> u64 {
        serde_json::from_str::<serde_json::Value>(body)
            .ok()
            .and_then(|j| j["scans"].as_u64())
            .unwrap_or(0)
    };
    let (status, body) = get(&addr, "/api/status");
    let first = scans(&body);
    let mut later = first;
    for _ in 0..100 {
        later = scans(&get(&addr, "/api/status").1);
        if later > first {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(status.starts_with("HTTP/1.1 200"), "{status:?} {body}");
    assert!(later > first, "the PLC scans and the API says so: {first} then {later}");
    let _ = std::fs::remove_dir_all(&dir);
}
