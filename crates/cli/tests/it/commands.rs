//! The other commands: new, check, explain.

use crate::{alba, scratch};

#[test]
fn new_creates_a_project_that_checks_and_runs() {
    let dir = scratch("new");
    let proj = dir.join("my-plant");
    let out = alba(&dir, &["new", "my-plant"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let toml = std::fs::read_to_string(proj.join("alba.toml")).unwrap();
    assert!(toml.contains("name = \"my-plant\""), "{toml}");
    let out = alba(&dir, &["check", "my-plant"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = alba(
        &dir,
        &[
            "sim",
            "my-plant",
            "--until",
            "1500",
            "--every",
            "500",
            "--stimulus",
            "my-plant/stimulus.csv",
            "--tags",
            "Start,Motor",
        ],
    );
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "time_ms,Start,Motor\n0,0,0\n500,0,0\n1000,1,1\n1500,0,1\n"
    );
    // A second `new` into the same folder refuses instead of overwriting.
    let out = alba(&dir, &["new", "my-plant"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn new_net_creates_a_state_net_project_that_checks_and_runs() {
    let dir = scratch("new-net");
    let out = alba(&dir, &["new", "line", "--net"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let toml = std::fs::read_to_string(dir.join("line/alba.toml")).expect("alba.toml");
    assert!(
        toml.contains("name = \"line\"") && toml.contains("batch.pnml"),
        "{toml}"
    );
    let out = alba(&dir, &["check", "line"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = alba(
        &dir,
        &[
            "sim",
            "line",
            "--until",
            "7000",
            "--every",
            "3500",
            "--stimulus",
            "line/stimulus.csv",
            "--tags",
            "Valve,Mixer,batch.batches.count",
        ],
    );
    assert!(out.status.success());
    // Start at 1 s: filling until 3 s, mixing until 6 s, one batch counted.
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "time_ms,Valve,Mixer,batch.batches.count\n0,0,0,0\n3500,0,1,0\n7000,0,0,1\n"
    );
}

#[test]
fn explain_prints_a_code_and_refuses_unknown_ones() {
    let dir = scratch("explain");
    let out = alba(&dir, &["explain", "E301"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("E301: unknown tag"));
    let out = alba(&dir, &["explain", "E999"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn check_reports_every_error_of_a_file() {
    let dir = scratch("check-all");
    std::fs::write(dir.join("alba.toml"), "name = \"x\"\nprograms = [\"main.lad\"]\n").unwrap();
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\nN,DINT\nT,TIMER\n").unwrap();
    std::fs::write(
        dir.join("main.lad"),
        "XIC(A)OTE(Missing);\nXIC(A)XYZ(A);\nXIC(N)OTE(A);\nXIC(A)TON(N,10,0);\nXIC(A;\nXIC(A);\nXIC(A)JMP(Nowhere);\n",
    )
    .unwrap();
    let out = alba(&dir, &["check", ".", "--short"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    for want in [
        "./main.lad:1:11: error[E301]",
        "./main.lad:2:7: error[E201]",
        "./main.lad:3:5: error[E303]",
        "./main.lad:4:11: error[E303]",
        "./main.lad:5:4: error[E202]",
        "./main.lad:6:1: error[E308]",
        "./main.lad:7:11: error[E306]",
        "7 errors",
    ] {
        assert!(err.contains(want), "missing `{want}` in:\n{err}");
    }
}

#[test]
fn tune_runs_a_relay_experiment_and_summary_measures_a_step() {
    let root = crate::repo();
    let gp1 = root.join("examples/pid-gp1");
    let gp1 = gp1.to_str().unwrap();
    let out = alba(&root, &["tune", gp1, "--loop", "Loop", "--sp", "5"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("Ku = ") && text.contains("| Tyreus-Luyben PI |"),
        "{text}"
    );
    let out = alba(&root, &["tune", gp1, "--loop", "Meas"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("`Meas` is not a PID tag"));
    // --summary on the z-tuned case: the figures of docs/pid.md.
    let dir = scratch("summary");
    let trace = dir.join("t.csv");
    let stim = root.join("examples/pid-gp1/stimulus-z-tuned.csv");
    let args = [
        "sim",
        gp1,
        "--until",
        "60000",
        "--every",
        "320",
        "--stimulus",
        stim.to_str().unwrap(),
        "--tags",
        "Loop.SP,Loop.PV",
        "--trace",
        trace.to_str().unwrap(),
        "--summary",
        "Loop.PV:Loop.SP",
    ];
    let out = alba(&root, &args);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("overshoot 0.04 %") && text.contains("settling time (98 %) 11.52 s"),
        "{text}"
    );
    let mut bad = args;
    bad[13] = "Loop.CV";
    let out = alba(&root, &bad);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not traced"));
}

#[test]
fn hash_password_makes_a_hash_that_opcua_users_accept() {
    use std::io::Write;
    let dir = scratch("hash-password");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_alba"))
        .arg("hash-password")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(b"s3cret pass\n").unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let hash = String::from_utf8(out.stdout).unwrap().trim().to_string();
    assert!(hash.starts_with("$argon2id$v=19$"), "{hash}");
    assert!(alba_opcua::security::verify_password(&hash, "s3cret pass"));
    assert!(!alba_opcua::security::verify_password(&hash, "s3cret pass\n"));
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\n").unwrap();
    std::fs::write(dir.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
    let toml = |users: &str| {
        format!("name = \"x\"\nprograms = [\"main.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n[opcua.users]\n{users}\n")
    };
    std::fs::write(dir.join("alba.toml"), toml(&format!("operator = \"{hash}\""))).unwrap();
    let out = alba(&dir, &["check", ".", "--short"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // A plain-text password is refused, located on it.
    std::fs::write(dir.join("alba.toml"), toml("operator = \"s3cret pass\"")).unwrap();
    let out = alba(&dir, &["check", ".", "--short"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("./alba.toml:6:12: error[E102]: this is not a password hash"),
        "{err}"
    );
    // An empty password is refused.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_alba"))
        .arg("hash-password")
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}

/// `alba sim --alarms`: the project's alarms evaluated on every scan at
/// virtual time, each change of state written as CSV (docs/alarms.md).
#[test]
fn sim_reports_alarm_changes_at_virtual_time() {
    let dir = crate::scratch("sim-alarms");
    for (f, t) in [
        ("alba.toml", "name = \"a\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n"),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nCount,DINT,,,,\nReset,BOOL,DI:1/0,,,\n",
        ),
        ("main.lad", "XIO(Reset)ADD(Count,1,Count);\nXIC(Reset)MOV(0,Count);\n"),
        (
            "alarms.csv",
            "id,tag,condition,severity,delay_ms,deadband,message\nhigh,Count,>= 5,high,20,0,\"Count high, check\"\nreset,Reset,rising,low,0,0,Reset pressed\n",
        ),
        ("stimulus.csv", "time_ms,tag,value\n100,Reset,1\n150,Reset,0\n"),
    ] {
        std::fs::write(dir.join(f), t).expect("write");
    }
    let out = crate::alba(
        &dir,
        &[
            "sim",
            ".",
            "--until",
            "200",
            "--stimulus",
            "stimulus.csv",
            "--alarms",
            "events.csv",
            "--tags",
            "Count",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let events = std::fs::read_to_string(dir.join("events.csv")).expect("events.csv");
    // Count reaches 5 after the scan at 40 ms; the on-delay of 20 ms makes it active at 60 ms.
    // Reset at 100 ms: the edge alarm for one scan, Count back to 0 clears `high`.
    assert_eq!(
        events,
        "time_ms,alarm,tag,from,to,value,severity,message\n\
         60,high,Count,normal,active_unacked,7,750,\"Count high, check\"\n\
         100,high,Count,active_unacked,cleared_unacked,0,750,\"Count high, check\"\n\
         100,reset,Reset,normal,active_unacked,1,250,Reset pressed\n\
         110,reset,Reset,active_unacked,cleared_unacked,1,250,Reset pressed\n"
    );
    // Without alarms.csv there is nothing to evaluate: an empty log, not an error.
    std::fs::remove_file(dir.join("alarms.csv")).expect("rm");
    let out = crate::alba(&dir, &["sim", ".", "--until", "20", "--alarms", "none.csv"]);
    assert!(out.status.success());
    assert_eq!(
        std::fs::read_to_string(dir.join("none.csv"))
            .expect("none.csv")
            .lines()
            .count(),
        1
    );
}

/// `alba check` reads the project's screens too (hmi/*.json): a screen that
/// names a tag the program does not have fails the check, at its place.
#[test]
fn check_reports_a_bad_screen_at_its_place() {
    let dir = scratch("check-screen");
    std::fs::write(dir.join("alba.toml"), "name = \"s\"\nprograms = [\"main.lad\"]\n").unwrap();
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\nLevel,REAL\n").unwrap();
    std::fs::write(dir.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
    std::fs::create_dir_all(dir.join("hmi")).unwrap();
    let good = "{\"schema\": 1, \"width\": 100, \"height\": 100, \"elements\": [\n  {\"id\": \"t\", \"type\": \"tank\", \"x\": 0, \"y\": 0, \"w\": 10, \"h\": 10,\n   \"animations\": [{\"kind\": \"fill\", \"tag\": \"Level\"}]}]}\n";
    std::fs::write(dir.join("hmi/main.json"), good).unwrap();
    let out = alba(&dir, &["check", "."]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("1 screen)"));
    std::fs::write(dir.join("hmi/main.json"), good.replace("\"Level\"", "\"Levl\"")).unwrap();
    let out = alba(&dir, &["check", ".", "--short"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("hmi/main.json:3:43: error[E141]: `t`: animation `fill`: unknown tag `Levl`"),
        "{err}"
    );
}

/// `alba bench --st` runs the benchmark rung written in ST against the
/// hand-written Rust (it checks their results before timing), with the
/// programs of 1 000 and 10 000 lines.
#[test]
fn bench_runs_the_structured_text_contender() {
    let dir = scratch("bench-st");
    let out = alba(&dir, &["bench", "--st", "--quick", "--sizes", "3"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    for want in [
        "Structured Text",
        "     3     23 |",
        "   166   1001 |",
        "  1666  10001 |",
    ] {
        assert!(text.contains(want), "missing `{want}` in:\n{text}");
    }
}

/// `alba bench --listing` shows the benchmark rung's machine code (one
/// strided function for its 8 rungs); `--profile` runs one contender.
#[test]
fn bench_lists_native_code_and_profiles_one_contender() {
    let dir = scratch("bench-listing");
    let out = alba(&dir, &["bench", "--listing"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("; function 0 (rungs 0-7, strided)\n"), "{text}");
    assert_eq!(text.matches("; function").count(), 1, "{text}");
    assert!(text.contains("; machine code\n"), "{text}");
    for contender in ["interpreter", "native", "rust"] {
        let out = alba(
            &dir,
            &["bench", "--profile", contender, "--sizes", "20", "--scans", "5"],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).contains("5 scans of 20 rungs"));
    }
}
