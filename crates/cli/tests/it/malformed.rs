//! Malformed inputs: each folder under `tests/malformed/` holds the files of
//! a case, `cmd` (the arguments of `alba`, run inside the folder) and
//! `expected` (one `place CODE` per line, place being `file:line:col` or `-`
//! for a problem with no place). The run must fail with exit code 1 (never a
//! panic, which exits 101), and stderr must name every expected place and code.

use crate::alba;
use std::path::Path;

#[test]
fn every_malformed_input_gets_a_located_error() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed");
    let mut cases: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    cases.sort();
    let mut failures = Vec::new();
    let mut count = 0;
    for dir in cases.iter().filter(|d| d.join("cmd").exists()) {
        count += 1;
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let cmd = std::fs::read_to_string(dir.join("cmd")).unwrap();
        let args: Vec<&str> = cmd.split_whitespace().collect();
        let out = alba(dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        if out.status.code() != Some(1) {
            failures.push(format!("{name}: exit {:?} (want 1)\n{stderr}", out.status.code()));
            continue;
        }
        let expected = std::fs::read_to_string(dir.join("expected")).unwrap_or_default();
        for line in expected.lines().filter(|l| !l.trim().is_empty()) {
            let (place, code) = line.trim().rsplit_once(' ').unwrap_or(("-", line.trim()));
            let code_ok = stderr.contains(&format!("error[{code}]"));
            // The place ends there: `main.lad:2:1` must not match `main.lad:2:15`.
            let place_ok = place == "-"
                || [":", "\n", " "]
                    .iter()
                    .any(|end| stderr.contains(&format!("{place}{end}")));
            if !code_ok || !place_ok {
                failures.push(format!("{name}: expected `{line}` in stderr:\n{stderr}"));
            }
        }
    }
    assert!(count >= 30, "expected at least 30 malformed cases, found {count}");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
