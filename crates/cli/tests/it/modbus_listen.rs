//! `alba run --modbus` beyond loopback: refused with a message and a
//! non-zero exit without `[modbus] allow`, served with it
//! (docs/security.md, "Modbus").

use crate::scratch;
use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn project(name: &str, modbus: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let files = [
        (
            "alba.toml",
            format!("name = \"mb\"\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n{modbus}"),
        ),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nStart,BOOL,%IX0.0,,,\nMotor,BOOL,%QX0.0,,,\n".into(),
        ),
        ("main.lad", "XIC(Start)OTE(Motor);\n".into()),
    ];
    for (f, t) in files {
        std::fs::write(dir.join(f), t).expect("write");
    }
    dir
}

fn alba_run(dir: &std::path::Path) -> std::process::Child {
    alba_run_with(dir, &["--modbus", "0.0.0.0:0"])
}

fn alba_run_with(dir: &std::path::Path, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0", "--no-native"])
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("alba run starts")
}

/// What `alba run` prints up to its banner (the studio's address); then it is stopped.
fn startup(mut child: std::process::Child) -> String {
    let mut lines = Vec::new();
    for line in BufReader::new(child.stdout.take().expect("stdout")).lines() {
        let Ok(line) = line else { break };
        let done = line.contains("http://");
        lines.push(line);
        if done {
            break;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    lines.join("\n")
}

#[test]
fn a_modbus_address_beyond_loopback_without_allow_is_refused() {
    let dir = project("modbus-refused", "");
    let mut child = alba_run(&dir);
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("alba run --modbus 0.0.0.0:0 without [modbus] allow kept running");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("stderr");
    assert!(!status.success(), "{err}");
    assert!(
        err.contains("error: refusing to serve Modbus TCP on 0.0.0.0:0: Modbus has no authentication"),
        "{err}"
    );
    assert!(err.contains("allow = ["), "{err}");
}

#[test]
fn a_modbus_address_beyond_loopback_with_allow_is_served() {
    let dir = project(
        "modbus-allowed",
        "[modbus]\nallow = [\"127.0.0.1\"]\nread_only = true\n",
    );
    let out = startup(alba_run(&dir));
    assert!(out.contains("Modbus TCP server: 0.0.0.0:"), "{out}");
    assert!(out.contains("clients: 127.0.0.1; read-only"), "{out}");
}

#[test]
fn modbus_is_off_unless_an_address_is_given() {
    // A [modbus] table without `listen`, and no --modbus: no server.
    let dir = project("modbus-off", "[modbus]\nunit_id = 1\n");
    let out = startup(alba_run_with(&dir, &[]));
    assert!(out.contains("http://"), "{out}");
    assert!(!out.contains("Modbus"), "{out}");
    // On loopback without `allow`: served, to loopback clients.
    let out = startup(alba_run_with(&dir, &["--modbus", "127.0.0.1:0"]));
    assert!(out.contains("Modbus TCP server: 127.0.0.1:"), "{out}");
    assert!(out.contains("clients: loopback only; reads and writes"), "{out}");
}
