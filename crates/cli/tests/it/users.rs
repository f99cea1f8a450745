//! `alba user`: the user store from the command line, passwords on stdin.

use crate::{alba, scratch};
use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// Runs `alba` with `args` in `cwd`, `stdin` piped in.
fn alba_in(cwd: &Path, args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("alba runs");
    // A command that fails before reading may have closed its stdin.
    let _ = child.stdin.take().expect("stdin").write_all(stdin.as_bytes());
    child.wait_with_output().expect("alba ends")
}

fn project(name: &str, extra_toml: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"x\"\nprograms = [\"main.lad\"]\n{extra_toml}"),
    )
    .expect("alba.toml");
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\n").expect("tags.csv");
    std::fs::write(dir.join("main.lad"), "XIC(A)OTE(A);\n").expect("main.lad");
    dir
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn add_list_passwd_role_remove() {
    let dir = project("users-cli", "");
    let out = alba_in(
        &dir,
        &["user", "add", ".", "alice", "--role", "engineer"],
        "correct horse battery\n",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(dir.join("users.toml")).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600, "users.toml is the owner's only");
    }
    let stored = std::fs::read_to_string(dir.join("users.toml")).unwrap();
    assert!(!stored.contains("correct horse"), "never the password itself");
    let out = alba_in(
        &dir,
        &["user", "add", ".", "op", "--role", "operator"],
        "staple of the plant\r\n",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));

    let users = alba_auth::Users::load(&dir).unwrap();
    assert_eq!(
        users.verify("alice", "correct horse battery"),
        Some(alba_auth::Role::Engineer)
    );
    assert_eq!(
        users.verify("op", "staple of the plant"),
        Some(alba_auth::Role::Operator),
        "CR LF line end dropped"
    );

    let out = alba(&dir, &["user", "list", "."]);
    assert!(out.status.success());
    let list = text(&out.stdout);
    assert_eq!(list, "alice\tengineer\nop\toperator\n");
    assert!(!list.contains("argon2"));

    let out = alba_in(&dir, &["user", "passwd", ".", "op"], "a brand new secret\n");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = alba(&dir, &["user", "role", ".", "op", "viewer"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let users = alba_auth::Users::load(&dir).unwrap();
    assert_eq!(users.verify("op", "staple of the plant"), None);
    assert_eq!(users.verify("op", "a brand new secret"), Some(alba_auth::Role::Viewer));

    let out = alba(&dir, &["user", "remove", ".", "op"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&alba(&dir, &["user", "list", "."]).stdout), "alice\tengineer\n");
    // The project still checks, users.toml with it.
    let out = alba(&dir, &["check", "."]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn refusals_are_clear_and_fail() {
    let dir = project("users-cli-refusals", "");
    let fails = |args: &[&str], stdin: &str, why: &str| {
        let out = alba_in(&dir, args, stdin);
        assert_eq!(out.status.code(), Some(1), "{args:?} should fail");
        let err = text(&out.stderr);
        assert!(err.contains(why), "{args:?}: `{err}` does not say `{why}`");
    };
    let add = |name: &'static str| ["user", "add", ".", name, "--role", "operator"];
    fails(&add("bob"), "short\n", "too short");
    fails(&add("bob"), "Password123\n", "most common");
    fails(&add("bobby.tables"), "Bobby.Tables\n", "user name");
    fails(&add("bob"), "", "no password");
    fails(&add("bob"), "\n", "no password");
    fails(&add("two words"), "correct horse battery\n", "not a valid user name");
    fails(
        &["user", "add", ".", "bob", "--role", "boss"],
        "correct horse battery\n",
        "not a role",
    );
    fails(
        &["user", "add", "nowhere", "bob", "--role", "viewer"],
        "correct horse battery\n",
        "not an Alba project",
    );
    // No password from an argument.
    fails(
        &[
            "user",
            "add",
            ".",
            "bob",
            "--role",
            "viewer",
            "--password",
            "correct horse battery",
        ],
        "",
        "unexpected argument",
    );
    assert!(!dir.join("users.toml").exists(), "nothing written by a refusal");
    assert!(alba_in(&dir, &add("bob"), "correct horse battery\n").status.success());
    fails(&add("bob"), "another good secret\n", "already exists");
    fails(
        &["user", "passwd", ".", "zed"],
        "another good secret\n",
        "no user `zed`",
    );
    fails(&["user", "remove", ".", "zed"], "", "no user `zed`");
    fails(&["user", "role", ".", "zed", "admin"], "", "no user `zed`");
    fails(&["user", "passwd", ".", "bob"], "qwertyuiop\n", "most common");
    // A broken users.toml is reported with its place, never taken as empty.
    std::fs::write(
        dir.join("users.toml"),
        "[users.bob]\nrole = \"chief\"\npassword = \"x\"\n",
    )
    .unwrap();
    fails(&["user", "list", "."], "", "users.toml:2:8");
    let out = alba(&dir, &["check", ".", "--short"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("users.toml:2:8: error[E107]"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn opcua_users_still_load_with_a_warning_and_migrate() {
    let hash = alba_auth::hash_password("old opcua secret").unwrap();
    let dir = project(
        "users-cli-opcua",
        &format!("[opcua]\nread_only = [\"ro\"]\n[opcua.users]\nop = \"{hash}\"\nro = \"{hash}\"\n"),
    );
    let out = alba(&dir, &["check", "."]);
    assert!(out.status.success(), "a warning is not an error: {}", text(&out.stderr));
    let err = text(&out.stderr);
    assert!(err.contains("warning[E109]") && err.contains("alba user"), "{err}");
    let out = alba(&dir, &["check", ".", "--short"]);
    assert!(
        text(&out.stderr).contains("./alba.toml:6:1: warning[E109]"),
        "{}",
        text(&out.stderr)
    );
    let out = alba(&dir, &["user", "list", "."]);
    let list = text(&out.stdout);
    assert!(
        list.starts_with("op\toperator") && list.contains("\nro\tviewer"),
        "{list}"
    );
    // Users of alba.toml are removed there, not here.
    let out = alba(&dir, &["user", "remove", ".", "op"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("[opcua.users]"));
    let out = alba(&dir, &["user", "migrate", "."]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("delete [opcua.users]"));
    std::fs::write(dir.join("alba.toml"), "name = \"x\"\nprograms = [\"main.lad\"]\n").unwrap();
    let users = alba_auth::Users::load(&dir).unwrap();
    assert!(users.warnings().is_empty());
    assert_eq!(users.verify("op", "old opcua secret"), Some(alba_auth::Role::Operator));
    assert_eq!(users.verify("ro", "old opcua secret"), Some(alba_auth::Role::Viewer));
}

/// Issue 31: the audit row of `alba user` named the account `$USER` said,
/// so anyone could sign a change with someone else's name. It now names the
/// process's real user id (and its name in the system's user database).
#[test]
fn the_audit_row_names_the_real_account_not_user_from_the_environment() {
    let dir = project("users-forged", "");
    let out = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["user", "add", ".", "mallory", "--role", "viewer"])
        .current_dir(&dir)
        .env("USER", "the-plant-manager")
        .env("USERNAME", "the-plant-manager")
        .env("LOGNAME", "the-plant-manager")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .and_then(|mut c| {
            c.stdin.take().expect("stdin").write_all(b"correct horse battery\n")?;
            c.wait_with_output()
        })
        .expect("alba runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let log = alba_audit::Audit::open(dir.join(".alba/audit.db"), alba_audit::Config::default()).expect("audit");
    let rows = log.query(&alba_audit::Filter::default(), None, 10).expect("query").rows;
    let detail = rows
        .iter()
        .find(|r| r.target.as_deref() == Some("mallory"))
        .and_then(|r| r.detail.clone())
        .expect("a row for the change");
    assert!(!detail.contains("the-plant-manager"), "{detail}");
    let uid = std::fs::metadata("/proc/self").map(|m| std::os::unix::fs::MetadataExt::uid(&m));
    if let Ok(uid) = uid {
        assert!(detail.contains(&format!("uid {uid}")), "{detail}");
    }
}
