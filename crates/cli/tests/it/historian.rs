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
            stdout.contains("historian schema ready: the timescaledb extension is not installed"),
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

/// `alba run` with `[history] backend = "postgres"` records its tags under its node id.
#[test]
fn alba_run_records_into_the_shared_postgres_historian() {
    use std::process::{Command, Stdio};
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
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("alba run starts");
    let mut config = alba_historian::PgConfig::new(url, "reader", dir.join("reader-buffer.db"));
    config.password = Some(PASSWORD.to_owned());
    let reader = alba_historian::PgHistorian::open(config).expect("reader");
    let deadline = Instant::now() + Duration::from_secs(120);
    let found = loop {
        let tags = reader.tags_of("cell-7").unwrap_or_default();
        if tags.iter().any(|t| t.name == "B") || Instant::now() > deadline {
            break tags;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let _ = Command::new("kill").args(["-TERM", &child.id().to_string()]).status();
    let exit = child.wait().expect("exits");
    assert!(exit.success(), "{exit}");
    let names: Vec<&str> = found.iter().map(|t| t.name.as_str()).collect();
    assert!(names.contains(&"A") && names.contains(&"B"), "{names:?}");
    let b = reader.raw_node("cell-7", "B", 0, i64::MAX, 10).expect("raw");
    assert!(b.iter().all(|p| p.v == 1.0), "{b:?}");
    assert_eq!(reader.nodes().expect("nodes"), ["cell-7"]);
}
