//! Alarm states survive a restart of `alba run`, `kill -9` included (SPEC
//! §10.6, docs/alarms.md "Restarts"): an unacknowledged alarm is still listed
//! by `GET /api/alarms` until someone acknowledges it.

use crate::historian::{get, start_run};
use std::time::{Duration, Instant};

/// `method path` with a JSON body → (status, body text), HTTP/1.0.
fn send(addr: &str, method: &str, path: &str, body: &str) -> (u16, String) {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(addr).expect("connect");
    write!(
        s,
        "{method} {path} HTTP/1.0\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .expect("send");
    let mut text = String::new();
    s.read_to_string(&mut text).expect("answer");
    let status = text.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    (status, text.split("\r\n\r\n").nth(1).unwrap_or_default().to_string())
}

/// The (id, state) pairs of `GET /api/alarms`.
fn alarms(addr: &str) -> Vec<(String, String)> {
    let (status, body) = get(addr, "/api/alarms");
    assert_eq!(status, 200, "{body}");
    body.as_array()
        .expect("a list")
        .iter()
        .map(|a| {
            (
                a["id"].as_str().unwrap_or_default().to_string(),
                a["state"].as_str().unwrap_or_default().to_string(),
            )
        })
        .collect()
}

#[test]
fn an_unacknowledged_alarm_is_still_listed_after_kill_9() {
    let dir = crate::scratch("alarms-restart");
    for (f, t) in [
        (
            "alba.toml",
            "name = \"a\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n",
        ),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nLevel,REAL,,,,\nScans,DINT,,,,\n",
        ),
        ("main.lad", "ADD(Scans,1,Scans);\n"),
        (
            "alarms.csv",
            "id,tag,condition,severity,delay_ms,deadband,message\nhi,Level,> 50,high,0,0,Level high\n",
        ),
    ] {
        std::fs::write(dir.join(f), t).expect("write");
    }
    let (run, addr) = start_run(&dir);
    assert_eq!(alarms(&addr), vec![]);
    let (status, body) = send(&addr, "PUT", "/api/tags/Level", r#"{"value": 60.0}"#);
    assert!(status < 300, "{status} {body}");
    let t0 = Instant::now();
    while alarms(&addr) != [("hi".to_string(), "active_unacked".to_string())] {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "the alarm never became active: {:?}",
            alarms(&addr)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    drop(run); // SIGKILL
    let (run, addr) = start_run(&dir);
    // Level is not retained: it starts at 0, so the alarm is no longer active,
    // but nobody acknowledged it.
    let listed = alarms(&addr);
    assert_eq!(listed.len(), 1, "{listed:?}");
    assert_eq!(listed[0].0, "hi");
    assert!(
        ["active_unacked", "cleared_unacked"].contains(&listed[0].1.as_str()),
        "{listed:?}"
    );
    let t0 = Instant::now();
    while alarms(&addr)[0].1 != "cleared_unacked" {
        assert!(t0.elapsed() < Duration::from_secs(20));
        std::thread::sleep(Duration::from_millis(20));
    }
    let (status, body) = send(
        &addr,
        "POST",
        "/api/alarms/hi/ack",
        r#"{"comment": "seen after the restart"}"#,
    );
    assert!(status < 300, "{status} {body}");
    assert_eq!(alarms(&addr), vec![]);
    // Acknowledged stays acknowledged across the next restart (a graceful one).
    run.stop();
    let (run, addr) = start_run(&dir);
    assert_eq!(alarms(&addr), vec![]);
    run.stop();
}
