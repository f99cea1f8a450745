//! Messages in Spanish (issue 34 point 11): `LANG`/`LC_ALL` = es* or
//! `--lang es`, English by default; and the Spanish guide's commands.

use crate::{alba, alba_env, repo, scratch};

/// The README's tour project with `Strat` for `Start` in the first rung.
fn broken_project(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let out = alba(&dir, &["new", "mi-planta"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lad = dir.join("mi-planta/main.lad");
    let text = std::fs::read_to_string(&lad).expect("main.lad");
    std::fs::write(&lad, text.replacen("XIC(Start)", "XIC(Strat)", 1)).expect("write main.lad");
    dir
}

#[test]
fn check_speaks_spanish_when_lang_is_es() {
    let dir = broken_project("lang-es");
    let out = alba_env(&dir, &["check", "mi-planta"], &[("LANG", "es_ES.UTF-8")]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    for want in [
        "error[E301]: variable desconocida `Strat`",
        "^^^^^ aquí",
        "= ayuda: ¿quiso decir `Start`?",
        "1 error",
    ] {
        assert!(err.contains(want), "missing `{want}` in:\n{err}");
    }
    assert!(!err.contains("unknown tag"), "{err}");
    // LC_ALL wins over LANG; the one-line form too.
    let out = alba_env(
        &dir,
        &["check", "mi-planta", "--short"],
        &[("LC_ALL", "es_MX.UTF-8"), ("LANG", "en_US.UTF-8")],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("error[E301]: variable desconocida `Strat`"), "{err}");
}

#[test]
fn lang_flag_overrides_the_environment_and_english_stays_the_default() {
    let dir = broken_project("lang-flag");
    let out = alba(&dir, &["check", "mi-planta", "--lang", "es"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("variable desconocida `Strat`"), "{err}");
    let out = alba(&dir, &["--lang=es", "check", "mi-planta"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("variable desconocida"));
    let out = alba_env(
        &dir,
        &["check", "mi-planta", "--lang", "en"],
        &[("LANG", "es_ES.UTF-8")],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("error[E301]: unknown tag `Strat`"), "{err}");
    assert!(err.contains("help: did you mean `Start`?"), "{err}");
    let out = alba(&dir, &["check", "mi-planta"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown tag `Strat`"), "{err}");
    // An unknown language is refused as a bad argument.
    let out = alba(&dir, &["check", "mi-planta", "--lang", "xx"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("error[E404]"));
}

#[test]
fn explain_and_a_good_check_speak_spanish() {
    let dir = scratch("lang-explain");
    let out = alba(&dir, &["explain", "E301", "--lang", "es"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(text.starts_with("E301: variable desconocida"), "{text}");
    assert!(text.contains("Los operandos nombran variables de tags.csv"), "{text}");
    // every code is explained in Spanish, the nets' too
    let out = alba(&dir, &["explain", "E631", "--lang", "es"]);
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(text.contains("Un elemento Expression (modo normal)"), "{text}");
    assert!(!text.contains("An Expression element"), "{text}");
    let out = alba(&dir, &["new", "ok"]);
    assert!(out.status.success());
    let out = alba_env(&dir, &["check", "ok"], &[("LANG", "es_ES.UTF-8")]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ok (1 programa, 3 peldaños, 5 variables"), "{err}");
}

/// The commands of the ```sh blocks of a Markdown file, one per line (`\`
/// continuations joined, comments dropped), each with whether it must fail:
/// the commands of a block right after a `<!-- falla -->` line.
fn sh_commands(md: &str) -> Vec<(String, bool)> {
    let mut out = Vec::new();
    let mut inside = false;
    let mut fails = false;
    let mut marked = false;
    let mut pending = String::new();
    for line in md.lines() {
        let t = line.trim();
        if t == "<!-- falla -->" {
            marked = true;
            continue;
        }
        if t.starts_with("```") {
            if inside {
                inside = false;
            } else {
                inside = t == "```sh";
                fails = marked;
                marked = false;
            }
            continue;
        }
        if !inside {
            continue;
        }
        let t = t.split(" #").next().unwrap_or("").trim();
        if let Some(head) = t.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(t);
        if !pending.trim().is_empty() && !pending.trim_start().starts_with('#') {
            out.push((pending.trim().to_string(), fails));
        }
        pending.clear();
    }
    out
}

/// Every `alba …` command of docs/es/*.md, run in order per file in a fresh
/// folder holding a copy of the examples (the guide's commands are typed from
/// the repository's root), with `LANG=es_ES.UTF-8`. A command in a block
/// after a `<!-- falla -->` line must fail, every other must succeed. A
/// failing `alba check mi-planta` is the tour's break: the test writes
/// `Strat` for `Start` as the reader does, checks the Spanish message and
/// puts it back. Other commands (`cat`, `cargo`, `export`) and those that
/// need a board or run until stopped are not run.
#[test]
fn the_spanish_guide_commands_run() {
    let docs = repo().join("docs/es");
    let mut files: Vec<_> = std::fs::read_dir(&docs)
        .expect("docs/es exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    files.sort();
    assert!(files.len() >= 4, "the guide has its four parts: {files:?}");
    let mut ran = 0;
    for f in &files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        let dir = scratch(&format!("guia-{name}"));
        copy_dir(&repo().join("examples"), &dir.join("examples"));
        let md = std::fs::read_to_string(f).unwrap();
        for (cmd, should_fail) in sh_commands(&md) {
            let Some(rest) = cmd.strip_prefix("alba ") else {
                continue;
            };
            if rest.contains("--upload") || rest.starts_with("run ") || rest.contains("--build") {
                continue;
            }
            let lad = dir.join("mi-planta/main.lad");
            let tour_break = should_fail && rest.starts_with("check mi-planta");
            if tour_break {
                let text = std::fs::read_to_string(&lad).expect("main.lad");
                std::fs::write(&lad, text.replacen("XIC(Start)", "XIC(Strat)", 1)).expect("write main.lad");
            }
            let args: Vec<&str> = rest.split_whitespace().collect();
            let out = alba_env(&dir, &args, &[("LANG", "es_ES.UTF-8")]);
            assert_eq!(
                out.status.success(),
                !should_fail,
                "{}: `{cmd}`\n{}{}",
                f.display(),
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
            if tour_break {
                let err = String::from_utf8_lossy(&out.stderr);
                assert!(err.contains("variable desconocida `Strat`"), "{err}");
                let text = std::fs::read_to_string(&lad).expect("main.lad");
                std::fs::write(&lad, text.replacen("XIC(Strat)", "XIC(Start)", 1)).unwrap();
            }
        }
    }
    assert!(ran >= 8, "only {ran} commands ran");
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).expect("create the copy");
    for e in std::fs::read_dir(from).expect("read the examples").flatten() {
        let p = e.path();
        let q = to.join(e.file_name());
        if p.is_dir() {
            copy_dir(&p, &q);
        } else {
            std::fs::copy(&p, &q).expect("copy a file");
        }
    }
}
