//! Retentive data: the values that survive a stop, a restart of `alba` and
//! a crash. Tags marked `retain` in tags.csv (every member of a retained
//! TIMER or COUNTER), and the accumulators of retentive instructions (RTO
//! and TONR timers, counters) whatever their tag says.
//!
//! They are saved by name — so a recompiled program finds them — to one
//! JSON file, written atomically (temporary file, fsync, rename): a crash
//! leaves the previous save or the new one, never a torn file.

use crate::json::{from_json, to_json};
use alba_ir::{Op, Place, Program, TagSlot, Target};
use alba_model::fsutil::write_atomic;
use serde_json::{Map, Value as Json, json};
use std::collections::BTreeSet;
use std::path::Path;

const FORMAT: &str = "alba-retain";

/// The retained places of a program, by name.
pub fn retained(p: &Program) -> Vec<(String, Place)> {
    let layout = &p.layout;
    let mut names = BTreeSet::new();
    for (idx, tag) in layout.tags.iter().enumerate() {
        if !tag.retain {
            continue;
        }
        match layout.slot(idx) {
            TagSlot::Timer(_) | TagSlot::Counter(_) | TagSlot::Pid(_) => {
                names.extend(tag.ty.members().iter().map(|m| format!("{}.{}", tag.name, m.name)));
            }
            _ => {
                names.insert(tag.name.clone());
            }
        }
    }
    // Accumulators of retentive instructions.
    let timer_tag = |i: alba_ir::I| {
        layout
            .tags
            .iter()
            .enumerate()
            .find_map(|(idx, t)| match layout.slot(idx) {
                TagSlot::Timer(tm) if tm.i == i => Some(t.name.clone()),
                TagSlot::Counter(c) if c.i == i => Some(t.name.clone()),
                _ => None,
            })
    };
    let s7 = |table: &std::collections::BTreeMap<u8, alba_ir::layout::S7Slots>, i: alba_ir::I, kind: char| {
        table
            .iter()
            .find(|(_, s)| s.i == i)
            .map(|(n, _)| format!("{kind}{n}.CV"))
    };
    for op in &p.ops {
        let name = match *op {
            Op::Rto(t) => timer_tag(t.i).map(|n| format!("{n}.ACC")),
            Op::Ctu(c) | Op::Ctd(c) => timer_tag(c.i).map(|n| format!("{n}.ACC")),
            Op::S7Tonr(t) => s7(&layout.timers, t.i, 'T'),
            Op::S7Ctu(c) | Op::S7Ctd(c) | Op::S7Ctud(c) => s7(&layout.counters, c.i, 'C'),
            _ => None,
        };
        names.extend(name);
    }
    names
        .into_iter()
        .filter_map(|n| match layout.resolve(&n) {
            Ok(Target::Value { place, .. }) => Some((n, place)),
            _ => None,
        })
        .collect()
}

/// Saves `values` (name, value) atomically to `path`.
pub fn save(path: &Path, values: &[(String, alba_model::Value)], unix_ms: i64) -> std::io::Result<()> {
    let map: Map<String, Json> = values.iter().map(|(n, v)| (n.clone(), to_json(*v))).collect();
    let doc = json!({"format": FORMAT, "version": 1, "saved_unix_ms": unix_ms, "values": map});
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

/// What a retain file gave: the values restored, and what was skipped and why.
#[derive(Debug, Default)]
pub struct Restored {
    pub restored: usize,
    pub skipped: Vec<String>,
}

/// Reads `path` and writes every value it holds for a retained place of
/// `p` into `write`. A missing file restores nothing; a file that is not
/// a retain file is an error (and is left alone).
pub fn load(path: &Path, p: &Program, mut write: impl FnMut(Place, alba_model::Value)) -> Result<Restored, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Restored::default()),
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    let doc: Json = serde_json::from_str(&text).map_err(|e| format!("{}: not a retain file ({e})", path.display()))?;
    if doc.get("format").and_then(Json::as_str) != Some(FORMAT) {
        return Err(format!("{}: not an Alba retain file", path.display()));
    }
    let Some(values) = doc.get("values").and_then(Json::as_object) else {
        return Err(format!("{}: no `values` object", path.display()));
    };
    let wanted: std::collections::HashMap<String, Place> = retained(p)
        .into_iter()
        .map(|(n, pl)| (n.to_ascii_lowercase(), pl))
        .collect();
    let mut r = Restored::default();
    for (name, j) in values {
        let Some(&place) = wanted.get(&name.to_ascii_lowercase()) else {
            r.skipped.push(format!("{name}: no longer retained"));
            continue;
        };
        match from_json(j, place.data_type()) {
            Ok(v) => {
                write(place, v);
                r.restored += 1;
            }
            Err(e) => r.skipped.push(format!("{name}: {e}")),
        }
    }
    Ok(r)
}
