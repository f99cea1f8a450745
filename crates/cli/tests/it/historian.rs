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
