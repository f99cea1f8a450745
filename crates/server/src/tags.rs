//! Tags as the API shows them: definitions with live values, members of
//! structures, system tags, and the names a client may subscribe to.

use crate::reply::{self, TagInfo, TagReply, TagValue};
use alba_control::runtime::Snapshot;
use alba_control::runtime::json::to_json;
use alba_ir::layout::SYSTEM_TAGS;
use alba_ir::model::DataType;
use alba_ir::{Access, Ctr, Target, Tmr};
use serde_json::{Map, Value as Json};

pub use alba_control::names::{every_value, members, pid_members};

/// A structure's value: an object of its members.
fn structure(s: &Snapshot, ty: DataType, i: alba_ir::I, b: alba_ir::B) -> Json {
    let m: Map<String, Json> = members(ty, i, b)
        .into_iter()
        .map(|(n, p)| (n.to_string(), to_json(s.read(p))))
        .collect();
    Json::Object(m)
}

/// The value of whatever `target` names.
pub fn target_value(s: &Snapshot, target: Target) -> Json {
    match target {
        Target::Value { place, .. } => to_json(s.read(place)),
        Target::Timer(Tmr { i, b }) => structure(s, DataType::Timer, i, b),
        Target::Counter(Ctr { i, b }) => structure(s, DataType::Counter, i, b),
        Target::Pid(p) => Json::Object(
            pid_members(p)
                .into_iter()
                .map(|(n, pl)| (n.to_string(), to_json(s.read(pl))))
                .collect(),
        ),
    }
}

pub fn access(a: Access) -> reply::Access {
    match a {
        Access::ReadWrite => reply::Access::Readwrite,
        Access::Input => reply::Access::Input,
        Access::ReadOnly | Access::Output => reply::Access::Readonly,
    }
}

fn forced(s: &Snapshot, name: &str) -> Json {
    s.forces
        .iter()
        .find(|f| f.name.eq_ignore_ascii_case(name))
        .map_or(Json::Null, |f| to_json(f.value))
}

/// A tag of `tags.csv` as the API shows it.
fn tag_json(s: &Snapshot, tag: &alba_ir::model::Tag, target: Target) -> TagInfo {
    let a = match target {
        Target::Value { access, .. } => access,
        _ => Access::ReadWrite,
    };
    TagInfo {
        name: tag.name.clone(),
        ty: tag.ty.name().to_string(),
        address: tag.address.map(|a| a.to_string()),
        notations: tag
            .address
            .map(alba_compiler::ladder::domain::notations)
            .unwrap_or_default(),
        description: tag.description.clone(),
        retain: tag.retain,
        access: access(a),
        value: target_value(s, target),
        forced: forced(s, &tag.name),
    }
}

/// `GET /api/tags`: every tag in file order, then the system tags.
pub fn all(s: &Snapshot) -> Vec<TagInfo> {
    let layout = &s.program.layout;
    let mut out = Vec::new();
    for tag in layout.tags.iter() {
        let Ok(target) = layout.resolve(&tag.name) else {
            continue;
        };
        out.push(tag_json(s, tag, target));
    }
    for (name, what) in SYSTEM_TAGS {
        if let Ok(target @ Target::Value { place, .. }) = layout.resolve(name) {
            out.push(TagInfo {
                name: name.to_string(),
                ty: place.data_type().name().to_string(),
                address: None,
                notations: Vec::new(),
                description: what.to_string(),
                retain: false,
                access: reply::Access::Readonly,
                value: target_value(s, target),
                forced: Json::Null,
            });
        }
    }
    out
}

/// `GET /api/tags/{name}` for a tag, member or address.
pub fn one(s: &Snapshot, name: &str) -> Option<TagReply> {
    let layout = &s.program.layout;
    let target = layout.resolve(name).ok()?;
    if let Some(tag) = layout.tags.get(name) {
        return Some(TagReply::Tag(tag_json(s, tag, target)));
    }
    let (ty, a) = match target {
        Target::Value { place, access } => (place.data_type(), access),
        Target::Timer(_) => (DataType::Timer, Access::ReadWrite),
        Target::Counter(_) => (DataType::Counter, Access::ReadWrite),
        Target::Pid(_) => (DataType::Pid, Access::ReadWrite),
    };
    Some(TagReply::Other(TagValue {
        name: name.to_string(),
        ty: ty.name().to_string(),
        access: access(a),
        value: target_value(s, target),
        forced: forced(s, name),
    }))
}
