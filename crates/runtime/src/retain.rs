//! Retentive data: the values that survive a stop, a restart of `alba` and
//! a crash. Tags marked `retain` in tags.csv (every member of a retained
//! TIMER or COUNTER), and the accumulators of retentive instructions (RTO
//! and TONR timers, counters) whatever their tag says.
//!
//! They are saved by name — so a recompiled program finds them — to one
//! JSON file, written atomically (temporary file, fsync, rename) with the
//! previous save kept beside it (`retain.json.prev`): a crash leaves the
//! previous save or the new one, never a torn file, and a file damaged
//! anyway falls back to the generation before it (docs/reliability.md).

use crate::json::{from_json, to_json};
use alba_ir::{Op, Place, Program, TagSlot, Target};
use alba_model::fsutil::write_atomic_keeping;
use serde_json::{Map, Value as Json, json};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

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
            Op::Rto(t, _) => timer_tag(t.i).map(|n| format!("{n}.ACC")),
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

/// The previous generation of the retain file `path`: `retain.json.prev`.
pub fn previous(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".prev");
    path.with_file_name(name)
}

/// Saves `values` (name, value) atomically to `path`, keeping the file it
/// replaces as [`previous`] (two generations).
pub fn save(path: &Path, values: &[(String, alba_model::Value)], unix_ms: i64) -> std::io::Result<()> {
    let map: Map<String, Json> = values.iter().map(|(n, v)| (n.clone(), to_json(*v))).collect();
    let doc = json!({"format": FORMAT, "version": 1, "saved_unix_ms": unix_ms, "values": map});
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    write_atomic_keeping(path, &previous(path), |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

/// What to do when the retain file cannot be used (`[runtime]
/// on_retain_error` in alba.toml).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OnError {
    /// Start from the previous generation or the initial values, keep the
    /// bad file aside and report it (the default: a plant must come back
    /// after a power cut that damaged one file).
    #[default]
    Start,
    /// Refuse to start, leaving every file as it is.
    Refuse,
}

/// What a retain file gave: the values restored, what was skipped and
/// why, and where a damaged or partly unusable file was kept.
#[derive(Debug, Default)]
pub struct Restored {
    pub restored: usize,
    /// Values not restored, `name: why` (a tag no longer retained is not a
    /// loss and is not listed here).
    pub skipped: Vec<String>,
    /// The file could not be used at all (unreadable, not JSON, not a retain
    /// file): why. It was moved aside to `kept`.
    pub damaged: Option<String>,
    /// The values came from the previous generation (`retain.json.prev`).
    pub from_previous: bool,
    /// Where the file was kept: moved aside when damaged, copied when some
    /// values could not be restored (the next save would lose them).
    pub kept: Option<PathBuf>,
}

impl Restored {
    /// Some retained value did not come back as it was last saved.
    pub fn lost(&self) -> bool {
        self.damaged.is_some() || !self.skipped.is_empty()
    }

    /// What a user must hear about, one sentence (`None` when all went well).
    pub fn warning(&self) -> Option<String> {
        let mut w = Vec::new();
        if let Some(d) = &self.damaged {
            w.push(if self.from_previous {
                format!("{d}: restored the previous save instead")
            } else {
                format!("retentive data lost: {d}; started from the initial values")
            });
        } else if self.from_previous {
            w.push("the retain file was missing: restored the previous save".to_string());
        }
        if !self.skipped.is_empty() {
            w.push(format!(
                "{} retained value(s) not restored: {}",
                self.skipped.len(),
                self.skipped.join("; ")
            ));
        }
        if let Some(k) = &self.kept {
            w.push(format!("the file as it was is kept in {}", k.display()));
        }
        (!w.is_empty()).then(|| w.join("; "))
    }
}

/// `path` with `.<what>-<unix ms>` appended.
fn aside(path: &Path, what: &str) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(format!(".{what}-{}", crate::unix_ms()));
    path.with_file_name(name)
}

/// The values of the retain file `path`: `Ok(None)` when there is none,
/// `Err(why)` when it cannot be used.
fn read_values(path: &Path) -> Result<Option<Map<String, Json>>, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    let doc: Json =
        serde_json::from_slice(&bytes).map_err(|e| format!("{} is not a retain file ({e})", path.display()))?;
    if doc.get("format").and_then(Json::as_str) != Some(FORMAT) {
        return Err(format!("{} is not an Alba retain file", path.display()));
    }
    match doc.get("values") {
        Some(Json::Object(values)) => Ok(Some(values.clone())),
        _ => Err(format!("{} has no `values` object", path.display())),
    }
}

/// Why the retained values cannot be restored ([`load`]).
#[derive(Debug, thiserror::Error)]
pub enum RetainError {
    /// `on_retain_error = "refuse"` and the file cannot be used (why).
    #[error("{0} (on_retain_error = \"refuse\": fix or remove the file to start)")]
    Refused(String),
    /// The bad file cannot be moved aside (the next save would destroy it).
    #[error("{why}; and it cannot be moved aside to {}: {source}", to.display())]
    CannotMoveAside {
        why: String,
        to: std::path::PathBuf,
        source: std::io::Error,
    },
    /// The file with unrestorable values cannot be copied aside.
    #[error("cannot keep a copy of {} at {}: {source}", from.display(), to.display())]
    CannotCopy {
        from: std::path::PathBuf,
        to: std::path::PathBuf,
        source: std::io::Error,
    },
}

/// Reads `path` (or its previous generation) and writes every value it
/// holds for a retained place of `p` into `write`. A missing file restores
/// nothing.
///
/// With [`OnError::Start`] nothing keeps the PLC from starting: a file that
/// cannot be used (unreadable, truncated, not JSON, not a retain file) is
/// moved aside (`retain.json.damaged-<ms>`) and the previous generation is
/// restored if it is good; values that cannot be restored (wrong type) are
/// listed by name and the file is copied aside before a save overwrites it.
/// The only error is failing to keep the bad file (the next save would
/// destroy it). With [`OnError::Refuse`] either case is an error and no file
/// is touched.
pub fn load(
    path: &Path,
    p: &Program,
    on_error: OnError,
    mut write: impl FnMut(Place, alba_model::Value),
) -> Result<Restored, RetainError> {
    let refuse = RetainError::Refused;
    let mut r = Restored::default();
    let prev = previous(path);
    let values = match read_values(path) {
        Ok(Some(v)) => v,
        Ok(None) => match read_values(&prev) {
            Ok(Some(v)) => {
                r.from_previous = true;
                v
            }
            _ => return Ok(r),
        },
        Err(why) => {
            if on_error == OnError::Refuse {
                return Err(refuse(why));
            }
            let to = aside(path, "damaged");
            if let Err(source) = std::fs::rename(path, &to) {
                return Err(RetainError::CannotMoveAside { why, to, source });
            }
            r.damaged = Some(why);
            r.kept = Some(to);
            match read_values(&prev) {
                Ok(Some(v)) => {
                    r.from_previous = true;
                    v
                }
                _ => return Ok(r),
            }
        }
    };
    let wanted: std::collections::HashMap<String, Place> = retained(p)
        .into_iter()
        .map(|(n, pl)| (n.to_ascii_lowercase(), pl))
        .collect();
    let mut restore = Vec::new();
    for (name, j) in &values {
        // A tag no longer retained (or gone) is not a loss.
        let Some(&place) = wanted.get(&name.to_ascii_lowercase()) else {
            continue;
        };
        match from_json(j, place.data_type()) {
            Ok(v) => restore.push((place, v)),
            Err(e) => r.skipped.push(format!("{name}: {e}")),
        }
    }
    if !r.skipped.is_empty() {
        if on_error == OnError::Refuse {
            return Err(refuse(format!(
                "{}: {} value(s) cannot be restored: {}",
                path.display(),
                r.skipped.len(),
                r.skipped.join("; ")
            )));
        }
        if r.kept.is_none() {
            let from = if r.from_previous { &prev } else { path };
            let to = aside(path, "unrestored");
            if let Err(source) = std::fs::copy(from, &to) {
                return Err(RetainError::CannotCopy {
                    from: from.to_path_buf(),
                    to,
                    source,
                });
            }
            r.kept = Some(to);
        }
    }
    r.restored = restore.len();
    for (place, v) in restore {
        write(place, v);
    }
    Ok(r)
}
