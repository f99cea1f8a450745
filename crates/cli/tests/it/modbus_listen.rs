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
    Command::new(env!("CARGO_BIN_EXE_alba"))
        .args([
            "run",
            ".",
            "--http",
            "127.0.0.1:0",
            "--modbus",
            "0.0.0.0:0",
            "--no-native",
        ])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("alba run starts")
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
    let mut child = alba_run(&dir);
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
    let out = lines.join("\n");
    assert!(out.contains("Modbus TCP server: 0.0.0.0:"), "{out}");
    assert!(out.contains("clients: 127.0.0.1; read-only"), "{out}");
}
