//! No users, no open door: `alba run` and `alba demo` refuse a
//! non-loopback `--http` address while the project has no users.

use crate::{repo, scratch};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `alba args`; its exit status and standard error, or a failure if
/// it is still running after 60 s (it would be serving).
fn refused(args: &[&str]) -> (bool, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("alba starts");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            let mut err = String::new();
            if let Some(mut e) = child.stderr.take() {
                use std::io::Read;
                let _ = e.read_to_string(&mut err);
            }
            return (status.success(), err);
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`alba {}` is serving instead of refusing", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn a_non_loopback_http_address_without_users_is_refused() {
    let dir = scratch("listen-run");
    for f in ["alba.toml", "tags.csv", "main.lad"] {
        std::fs::copy(repo().join("examples/tank").join(f), dir.join(f)).expect("copy");
    }
    let d = dir.to_str().expect("utf-8 path");
    let (ok, err) = refused(&["run", d, "--http", "0.0.0.0:0"]);
    assert!(!ok, "{err}");
    assert!(err.contains("refusing to serve the studio on 0.0.0.0:0"), "{err}");
    assert!(err.contains("no users") && err.contains("alba user add"), "{err}");

    let demo = scratch("listen-demo").join("demo");
    let (ok, err) = refused(&[
        "demo",
        "--dir",
        demo.to_str().expect("utf-8 path"),
        "--http",
        "0.0.0.0:0",
    ]);
    assert!(!ok, "{err}");
    assert!(err.contains("refusing to serve the studio"), "{err}");
    // The demo's project was written whole: its screen and alarms too, and it checks.
    for f in ["alarms.csv", "hmi/tank.json"] {
        assert!(demo.join(f).exists(), "the demo writes {f}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["check", demo.to_str().expect("utf-8 path")])
        .output()
        .expect("alba check");
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && text.contains("1 screen") && text.contains("5 alarms"),
        "{text}"
    );
}
