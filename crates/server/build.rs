//! Embeds the studio (`web/dist`) in the binary: generates a table of
//! (path, bytes) with `include_bytes!`.
//!
//! The studio is built here first when it is missing or older than its
//! sources and npm is on the PATH (`npm ci` when `node_modules` is missing or
//! older than the lock file, then `npm run build`), so a plain `cargo build
//! -p alba-cli` gives the whole product (ADR 0013). Without npm, an existing
//! build is embedded as it is, with a warning; with none, the table is empty
//! and the server says how to make one. `ALBA_SKIP_WEB=1` skips building.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

fn walk(dir: &Path, root: &Path, out: &mut Vec<(String, PathBuf)>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, root, out);
        } else if let Ok(rel) = p.strip_prefix(root) {
            out.push((rel.to_string_lossy().replace('\\', "/"), p));
        }
    }
}

fn mtime(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

/// The newest modification time under `p` (a file or a directory).
fn newest(p: &Path) -> Option<SystemTime> {
    let mut files = Vec::new();
    if p.is_dir() {
        walk(p, p, &mut files);
    } else {
        files.push((String::new(), p.to_path_buf()));
    }
    files.iter().filter_map(|(_, f)| mtime(f)).max()
}

/// The sources of the studio's build, as `build_web` in scripts/common.sh sees them.
const SOURCES: [&str; 4] = ["src", "index.html", "package-lock.json", "vite.config.ts"];

fn stale(web: &Path) -> bool {
    let Some(built) = mtime(&web.join("dist/index.html")) else {
        return true;
    };
    SOURCES.iter().filter_map(|s| newest(&web.join(s))).any(|t| t > built)
}

fn npm(web: &Path, args: &[&str]) -> Result<(), String> {
    let status = Command::new("npm")
        .args(args)
        .current_dir(web)
        .status()
        .map_err(|e| format!("cannot run npm: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`npm {}` failed ({status})", args.join(" ")))
    }
}

fn build_web(web: &Path) -> Result<(), String> {
    let modules = web.join("node_modules/.package-lock.json");
    if mtime(&modules).is_none_or(|m| mtime(&web.join("package-lock.json")).is_some_and(|l| l > m)) {
        npm(web, &["ci", "--no-audit", "--no-fund", "--loglevel=error"])?;
    }
    npm(web, &["run", "-s", "build"])
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let web = manifest.join("../../web");
    let dist = web.join("dist");
    println!("cargo:rerun-if-env-changed=ALBA_SKIP_WEB");
    for s in SOURCES {
        println!("cargo:rerun-if-changed={}", web.join(s).display());
    }
    if web.join("package.json").exists() && std::env::var_os("ALBA_SKIP_WEB").is_none() && stale(&web) {
        let npm_found = Command::new("npm")
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !npm_found {
            println!(
                "cargo:warning=the studio (web/) is not built or is older than its sources, and npm is not \
                 installed: {} (install Node.js and npm, or run ./demo.sh, which does)",
                if dist.join("index.html").exists() {
                    "embedding the old build"
                } else {
                    "the binary has no studio"
                }
            );
        } else if let Err(e) = build_web(&web) {
            // A broken web build must not pass unnoticed as a binary without its studio.
            panic!("building the studio failed: {e}");
        }
    }
    println!("cargo:rerun-if-changed={}", dist.display());
    let mut files = Vec::new();
    walk(&dist, &dist, &mut files);
    files.sort();
    for (_, p) in &files {
        println!("cargo:rerun-if-changed={}", p.display());
    }
    let mut code = String::from("pub static ASSETS: &[(&str, &[u8])] = &[\n");
    for (rel, p) in &files {
        code.push_str(&format!(
            "    ({rel:?}, include_bytes!({:?})),\n",
            p.display().to_string()
        ));
    }
    code.push_str("];\n");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default()).join("assets.rs");
    if let Err(e) = std::fs::write(&out, code) {
        panic!("cannot write {}: {e}", out.display());
    }
}
