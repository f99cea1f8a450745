//! The names of values: tags, structures' members and system tags, with
//! their places (for subscriptions, MQTT, the historian, and the audit rows
//! of doors that address places: Modbus).

use alba_ir::layout::SYSTEM_TAGS;
use alba_ir::model::DataType;
use alba_ir::{Ctr, Layout, Place, TagSlot, Target, Tmr};

/// The places of a TIMER or COUNTER's members, by member name.
pub fn members(ty: DataType, i: alba_ir::I, b: alba_ir::B) -> Vec<(&'static str, Place)> {
    ty.members()
        .iter()
        .map(|m| {
            let place = if m.ty == DataType::Bool {
                Place::Bool(alba_ir::B(b.0 + m.index as u32))
            } else {
                Place::Int(alba_ir::I(i.0 + m.index as u32), m.ty)
            };
            (m.name, place)
        })
        .collect()
}

/// The places of a PID's members, by member name.
pub fn pid_members(p: alba_ir::Pidt) -> Vec<(&'static str, Place)> {
    DataType::Pid.members().iter().map(|m| (m.name, p.member(m))).collect()
}

/// Every name `subscribe "*"` covers: tags (structures as their members)
/// and the system tags, with their places.
pub fn every_value(layout: &Layout) -> Vec<(String, Place)> {
    let mut out = Vec::new();
    for (idx, tag) in layout.tags.iter().enumerate() {
        match layout.slot(idx) {
            TagSlot::Timer(Tmr { i, b }) | TagSlot::Counter(Ctr { i, b }) => {
                for (m, p) in members(tag.ty, i, b) {
                    out.push((format!("{}.{m}", tag.name), p));
                }
            }
            TagSlot::Pid(pid) => {
                for (m, p) in pid_members(pid) {
                    out.push((format!("{}.{m}", tag.name), p));
                }
            }
            _ => {
                if let Ok(Target::Value { place, .. }) = layout.resolve(&tag.name) {
                    out.push((tag.name.clone(), place));
                }
            }
        }
    }
    for (name, _) in SYSTEM_TAGS {
        if let Ok(Target::Value { place, .. }) = layout.resolve(name) {
            out.push((name.to_string(), place));
        }
    }
    out
}
