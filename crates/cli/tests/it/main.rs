//! Integration tests of the `alba` binary.

mod alarms;
mod analyze;
mod audit;
mod clock;
mod commands;
mod differential;
mod download;
mod examples;
mod export;
mod firmware;
mod historian;
mod import;
mod lang;
mod listen;
mod malformed;
mod modbus_listen;
mod retain;
mod spanish;
mod users;
mod verify;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `alba` with `args` in `cwd`.
pub fn alba(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(args)
        .current_dir(cwd)
        // English whatever the machine's locale: the tests compare messages.
        .env_remove("LC_ALL")
        .env_remove("LC_MESSAGES")
        .env_remove("LANG")
        .output()
        .expect("alba runs")
}

/// Runs `alba` with `args` in `cwd` and the environment variables `env`.
pub fn alba_env(cwd: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_alba"));
    c.args(args)
        .current_dir(cwd)
        .env_remove("LC_ALL")
        .env_remove("LC_MESSAGES")
        .env_remove("LANG");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("alba runs")
}

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh empty folder under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}
