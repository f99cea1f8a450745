//! Compiling an ST program over a tags.csv and running it in every engine
//! mode (fused interpreter, monitored interpreter, native code), which must
//! agree on every scan; string variables read as text.

#![allow(dead_code)]

use alba_diag::{Files, render_all};
use alba_engine::Engine;
use alba_ir::{Builder, Layout, Program, Target};
use alba_model::{TagTable, Value};
use std::sync::Arc;

pub fn build(csv: &str, st: &str) -> Result<Program, String> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", csv);
    let sf = files.add("main.st", st);
    let (mut tags, mut diags) = TagTable::parse(files.text(tf), tf);
    let (ast, d) = alba_st::parse(files.text(sf), sf);
    diags.extend(d);
    alba_st::declare(&ast, &mut tags, &mut diags);
    let mut b = Builder::new(Layout::new(&tags, &Default::default()));
    diags.extend(alba_st::compile(&ast, "main.st", &mut b));
    if !diags.is_empty() {
        return Err(render_all(&diags, &files));
    }
    let p = b.finish(files);
    p.verify().map_err(|e| e.to_string())?;
    Ok(p)
}

pub fn program(csv: &str, st: &str) -> Program {
    build(csv, st).unwrap_or_else(|e| panic!("does not compile:\n{e}"))
}

pub fn errors(csv: &str, st: &str) -> String {
    match build(csv, st) {
        Ok(_) => panic!("compiled, but errors were expected"),
        Err(e) => e,
    }
}

const MODES: [&str; 3] = ["fused", "monitored", "native"];

pub fn engine(p: &Program, mode: &str) -> Engine {
    let mut e = Engine::new(Arc::new(p.clone())).expect("verifies");
    match mode {
        "monitored" => e.set_monitor(true),
        "native" => e.compile_native().expect("native code"),
        _ => {}
    }
    e
}

pub fn read(e: &Engine, name: &str) -> Value {
    match e.program().layout.resolve(name) {
        Ok(Target::Value { place, .. }) => e.read(place),
        other => panic!("`{name}`: {other:?}"),
    }
}

pub fn write(e: &mut Engine, name: &str, v: Value) {
    match e.program().layout.resolve(name) {
        Ok(Target::Value { place, .. }) => e.write(place, v),
        other => panic!("`{name}`: {other:?}"),
    }
}

pub fn int(v: Value) -> i64 {
    match v {
        Value::Bool(b) => i64::from(b),
        Value::Sint(x) => i64::from(x),
        Value::Int(x) => i64::from(x),
        Value::Dint(x) => i64::from(x),
        Value::Lint(x) => x,
        other => panic!("not an integer: {other:?}"),
    }
}

/// The text of the string variable whose tags start with `tag` (its
/// `.LEN` and its characters `[1]`…), checking that every character past
/// the length is 0.
pub fn text(e: &Engine, tag: &str) -> String {
    let len = int(read(e, &format!("{tag}.LEN"))) as usize;
    let mut units = Vec::new();
    let mut k = 1;
    while let Ok(Target::Value { place, .. }) = e.program().layout.resolve(&format!("{tag}[{k}]")) {
        let c = int(e.read(place));
        if k > len {
            assert_eq!(c, 0, "{tag}[{k}] past the length {len}");
        } else {
            units.push(c as u16);
        }
        k += 1;
    }
    String::from_utf16_lossy(&units)
}

/// What is watched: a string variable's text, or another tag's value.
pub enum W<'a> {
    S(&'a str),
    V(&'a str),
}

/// Runs `scans` scans in every mode (`before` writes tags before scan k);
/// returns each scan's watched values, checking that the modes agree and
/// counting the faults.
pub fn run(p: &Program, scans: u64, before: &dyn Fn(&mut Engine, u64), watch: &[W]) -> (Vec<Vec<String>>, u64) {
    let mut all: Vec<(Vec<Vec<String>>, u64)> = Vec::new();
    for mode in MODES {
        let mut e = engine(p, mode);
        let mut rows = Vec::new();
        for k in 0..scans {
            before(&mut e, k);
            e.scan(k * 10)
                .unwrap_or_else(|f| panic!("{mode}: major fault {}", f.message));
            rows.push(
                watch
                    .iter()
                    .map(|w| match w {
                        W::S(t) => text(&e, t),
                        W::V(t) => read(&e, t).to_string(),
                    })
                    .collect(),
            );
        }
        all.push((rows, e.faults().count));
    }
    for (k, r) in all.iter().enumerate().skip(1) {
        assert_eq!(all[0], *r, "{} and {} disagree", MODES[0], MODES[k]);
    }
    all.swap_remove(0)
}

pub fn once(csv: &str, st: &str, watch: &[W]) -> (Vec<String>, u64) {
    let p = program(csv, st);
    let (mut rows, faults) = run(&p, 1, &|_, _| {}, watch);
    (rows.swap_remove(0), faults)
}
