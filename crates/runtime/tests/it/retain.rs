//! Retentive data under damage (issue 15): corrupt, truncated, foreign and
//! wrong-typed retain files; the two generations; `kill -9` during saves.

use super::{LAD, TAGS, compile};
use alba_model::Value;
use alba_runtime::retain::{self, OnError};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("alba-retain-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("test I/O");
    d
}

/// Loads `file` for the test program: the restore report and what was
/// written, by name.
fn load(file: &Path, on: OnError) -> Result<(retain::Restored, Vec<(String, Value)>), String> {
    let p = compile(TAGS, LAD);
    let names = retain::retained(&p);
    let mut got = Vec::new();
    let r = retain::load(file, &p, on, |place, v| {
        let n = names.iter().find(|(_, pl)| *pl == place).map(|(n, _)| n.clone());
        got.push((n.unwrap_or_default(), v));
    })
    .map_err(|e| e.to_string())?;
    Ok((r, got))
}

fn kept(dir: &Path, what: &str) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .expect("test I/O")
        .map(|e| e.expect("test I/O").path())
        .filter(|p| p.to_string_lossy().contains(what))
        .collect()
}

#[test]
fn a_damaged_file_is_kept_aside_and_the_plc_starts() {
    let good = |v: i32| format!("{{\"format\":\"alba-retain\",\"version\":1,\"values\":{{\"Kept\":{v}}}}}");
    let cases: [(&str, Vec<u8>, &str); 5] = [
        ("garbage", vec![0xff, 0x00, 0x13, 0x37], "is not a retain file"),
        ("truncated", good(5).as_bytes()[..20].to_vec(), "is not a retain file"),
        (
            "foreign",
            b"{\"format\":\"other\",\"values\":{}}".to_vec(),
            "is not an Alba retain file",
        ),
        (
            "novalues",
            b"{\"format\":\"alba-retain\",\"values\":[1]}".to_vec(),
            "has no `values` object",
        ),
        ("empty", Vec::new(), "is not a retain file"),
    ];
    for (name, bytes, why) in cases {
        let d = dir(name);
        let file = d.join("retain.json");
        std::fs::write(&file, &bytes).expect("test I/O");
        // Refused when so configured, and nothing touched.
        let err = load(&file, OnError::Refuse).expect_err("an error");
        assert!(err.contains(why) && err.contains("on_retain_error"), "{name}: {err}");
        assert_eq!(std::fs::read(&file).expect("test I/O"), bytes);
        // Else: started from the initial values, the file kept aside as it was.
        let (r, got) = load(&file, OnError::Start).expect("test I/O");
        assert!(got.is_empty() && r.lost(), "{name}: {got:?}");
        assert!(r.warning().expect("test I/O").contains("retentive data lost"), "{name}");
        assert!(!file.exists());
        let aside = kept(&d, ".damaged-");
        assert_eq!(aside.len(), 1, "{name}");
        assert_eq!(std::fs::read(&aside[0]).expect("test I/O"), bytes);
        // With a previous generation, that one is restored.
        std::fs::write(retain::previous(&file), good(41)).expect("test I/O");
        std::fs::write(&file, &bytes).expect("test I/O");
        let (r, got) = load(&file, OnError::Start).expect("test I/O");
        assert_eq!(got, vec![("Kept".to_string(), Value::Dint(41))], "{name}");
        assert!(r.from_previous && r.warning().expect("test I/O").contains("restored the previous save"));
        let _ = std::fs::remove_dir_all(&d);
    }
}

#[test]
fn wrong_typed_values_are_reported_by_name_and_the_file_copied() {
    let d = dir("typed");
    let file = d.join("retain.json");
    let text = "{\"format\":\"alba-retain\",\"version\":1,\"values\":\
                {\"Kept\":\"many\",\"Acc.ACC\":99,\"Acc.PRE\":1e300,\"Gone\":3}}";
    std::fs::write(&file, text).expect("test I/O");
    let err = load(&file, OnError::Refuse).expect_err("an error");
    assert!(err.contains("1 value(s) cannot be restored"), "{err}");
    let (r, got) = load(&file, OnError::Start).expect("test I/O");
    // The good value is restored, the bad one named; names no longer
    // retained (`Gone`, `Acc.PRE`: only an RTO's ACC is) are not a loss.
    assert_eq!(got, vec![("Acc.ACC".to_string(), Value::Dint(99))]);
    assert_eq!(r.skipped.len(), 1, "{:?}", r.skipped);
    let w = r.warning().expect("test I/O");
    assert!(w.contains("Kept: expected an integer for a DINT, got a string"), "{w}");
    let copy = kept(&d, ".unrestored-");
    assert_eq!(copy.len(), 1);
    assert_eq!(std::fs::read_to_string(&copy[0]).expect("test I/O"), text);
    assert_eq!(
        std::fs::read_to_string(&file).expect("test I/O"),
        text,
        "the file itself stays"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn saves_keep_two_generations_and_a_torn_file_falls_back() {
    let d = dir("generations");
    let file = d.join("retain.json");
    retain::save(&file, &[("Kept".into(), Value::Dint(1))], 0).expect("test I/O");
    retain::save(&file, &[("Kept".into(), Value::Dint(2))], 0).expect("test I/O");
    assert!(
        std::fs::read_to_string(retain::previous(&file))
            .expect("test I/O")
            .contains("\"Kept\": 1")
    );
    // A torn sector: the newest file cut short.
    let text = std::fs::read(&file).expect("test I/O");
    std::fs::write(&file, &text[..text.len() / 2]).expect("test I/O");
    let (r, got) = load(&file, OnError::Start).expect("test I/O");
    assert_eq!(got, vec![("Kept".to_string(), Value::Dint(1))]);
    assert!(r.from_previous && r.damaged.is_some());
    // Between the two renames of a save: no file, the previous one restored,
    // and nothing was lost.
    std::fs::remove_file(kept(&d, ".damaged-")[0].clone()).expect("test I/O");
    let (r, got) = load(&file, OnError::Start).expect("test I/O");
    assert_eq!(got, vec![("Kept".to_string(), Value::Dint(1))]);
    assert!(r.from_previous && !r.lost());
    let _ = std::fs::remove_dir_all(&d);
}

/// Saves `Kept` = 0, 1, 2, … into `$ALBA_RETAIN_CHILD` as fast as it can,
/// for [`kill_9_during_saves_never_loses_the_file`] (runs as a child
/// process; a no-op in a normal test run).
#[test]
fn child_writer() {
    let Some(file) = std::env::var_os("ALBA_RETAIN_CHILD") else {
        return;
    };
    let file = PathBuf::from(file);
    let filler: Vec<(String, Value)> = (0..400).map(|i| (format!("Pad{i}"), Value::Dint(i))).collect();
    for i in 0.. {
        let mut values = vec![("Kept".to_string(), Value::Dint(i))];
        values.extend(filler.iter().cloned());
        retain::save(&file, &values, 0).expect("test I/O");
    }
}

#[test]
fn kill_9_during_saves_never_loses_the_file() {
    let d = dir("kill9");
    let file = d.join("retain.json");
    let exe = std::env::current_exe().expect("test I/O");
    let mut last = -1;
    for round in 0..15u64 {
        let mut child = std::process::Command::new(&exe)
            .args(["--exact", "retain::child_writer", "--nocapture", "--test-threads=1"])
            .env("ALBA_RETAIN_CHILD", &file)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("test I/O");
        // Wait until it has saved at least once, then a little more: the
        // kill lands at a different point of a save each round.
        while !file.exists() && !retain::previous(&file).exists() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        std::thread::sleep(std::time::Duration::from_micros(2_000 + round * 1_337));
        child.kill().expect("test I/O"); // SIGKILL
        child.wait().expect("test I/O");
        let (r, got) = load(&file, OnError::Start).expect("test I/O");
        assert!(r.damaged.is_none() && !r.lost(), "round {round}: {:?}", r.warning());
        let Some((_, Value::Dint(v))) = got.into_iter().find(|(n, _)| n == "Kept") else {
            panic!("round {round}: nothing restored")
        };
        // Each child starts again from 0: only a value was restored.
        assert!(v >= 0, "round {round}: {v}");
        last = v;
        let _ = std::fs::remove_file(&file);
        let _ = std::fs::remove_file(retain::previous(&file));
    }
    assert!(last >= 0);
    let _ = std::fs::remove_dir_all(&d);
}
