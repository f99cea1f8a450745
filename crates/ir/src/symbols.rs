//! Name resolution: tag names, members, addresses and system tags to places.
//! Front ends, the simulator, and later the API and protocols all resolve
//! names here, so every part of Alba means the same thing by a name.

use crate::layout::{Layout, Place, TagSlot};
use crate::op::{B, Ctr, F, I, Pidt, Tmr};
use alba_model::slc::{self, Slc, SlcStruct};
use alba_model::{Address, DataType};
use std::fmt;

/// Who may write a place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    ReadWrite,
    /// An input: written by the I/O driver (or a stimulus), read-only for programs.
    Input,
    /// Status bits and system tags.
    ReadOnly,
    /// An output, seen from a plant model: the control program drives it.
    Output,
}

impl Access {
    /// Why a program may not write a place with this access.
    pub fn why_not_writable(self) -> &'static str {
        match self {
            Access::ReadWrite => "",
            Access::Input => "it is an input, written only by the I/O (or a plant model)",
            Access::ReadOnly => "it is read-only (a status bit or a system tag)",
            Access::Output => "it is an output: a plant model reads outputs and writes inputs",
        }
    }
}

/// What a name resolves to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Value { place: Place, access: Access },
    Timer(Tmr),
    Counter(Ctr),
    Pid(Pidt),
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ResolveError {
    UnknownTag(String),
    UnknownMember { tag: String, ty: DataType, member: String },
    NotAStructure { tag: String, ty: DataType },
    BadAddress(String),
    OutsideImage(Address),
}

impl fmt::Display for ResolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ResolveError::UnknownTag(n) => write!(f, "unknown tag `{n}`"),
            ResolveError::UnknownMember { tag, ty, member } => {
                let members: Vec<_> = ty.members().iter().map(|m| m.name).collect();
                write!(
                    f,
                    "{ty} `{tag}` has no member `{member}` (members: {})",
                    members.join(" ")
                )
            }
            ResolveError::NotAStructure { tag, ty } => {
                write!(f, "`{tag}` is a {ty}, not a structure with members")
            }
            ResolveError::BadAddress(m) => write!(f, "{m}"),
            ResolveError::OutsideImage(a) => write!(f, "{a} is outside this project's I/O image"),
        }
    }
}

impl Pidt {
    /// The place of a member of `alba_model::types::PID_MEMBERS`.
    pub fn member(&self, m: &alba_model::types::Member) -> Place {
        let k = m.index as u32;
        match m.ty {
            DataType::Bool => Place::Bool(B(self.b.0 + k)),
            DataType::Real => Place::Real(F(self.f.0 + k)),
            t => Place::Int(I(self.i.0 + k), t),
        }
    }
}

/// A member of a TIMER or COUNTER whose slots start at `i` and `b`.
fn member_of(name: &str, ty: DataType, i: I, b: B, m: &str) -> Result<Target, ResolveError> {
    let mem = ty.member(m).ok_or_else(|| ResolveError::UnknownMember {
        tag: name.to_string(),
        ty,
        member: m.to_string(),
    })?;
    let place = if mem.ty == DataType::Bool {
        Place::Bool(B(b.0 + mem.index as u32))
    } else {
        Place::Int(I(i.0 + mem.index as u32), mem.ty)
    };
    let access = if mem.writable {
        Access::ReadWrite
    } else {
        Access::ReadOnly
    };
    Ok(Target::Value { place, access })
}

impl Layout {
    /// Resolves a tag name, `tag.member`, an address in any notation, or a
    /// system tag (`S:FS`), case-insensitively.
    pub fn resolve(&self, text: &str) -> Result<Target, ResolveError> {
        let name = text.trim();
        if let Some(sys) = self.system_tag(name) {
            return Ok(sys);
        }
        match Address::parse(name) {
            Err(msg) => return Err(ResolveError::BadAddress(msg.to_string())),
            Ok(Some(addr)) => {
                // A tag on exactly this address gives its type and access.
                if let Some(tag) = self.tags.iter().find(|t| t.address == Some(addr)) {
                    return self.resolve(&tag.name);
                }
                // An SLC 500 F element is a REAL.
                let ty = match slc::parse(&name.to_ascii_uppercase(), name) {
                    Ok(Some(Slc::Address(_, ty))) => ty,
                    _ => addr.natural_type(),
                };
                let place = self.address_place(addr, ty).ok_or(ResolveError::OutsideImage(addr))?;
                return Ok(Target::Value {
                    place,
                    access: self.io_access(Some(addr)),
                });
            }
            Ok(None) => {}
        }
        if let Ok(Some(Slc::Struct(st, member))) = slc::parse(&name.to_ascii_uppercase(), name) {
            return self.slc_struct(st, member.as_deref());
        }
        if self.tags.get(name).is_none()
            && let Some(t) = self.s7_name(name)
        {
            return Ok(t);
        }
        // A net's tags have dots in their names (`line.filling`, and the
        // timer `line.t1.timer` whose member is `line.t1.timer.DN`): a whole
        // name first, else the member after the last dot.
        let (base, member) = match name.rsplit_once('.') {
            Some(_) if self.tags.get(name).is_some() => (name, None),
            Some((b, m)) => (b, Some(m)),
            None => (name, None),
        };
        let idx = self
            .tags
            .position(base)
            .ok_or_else(|| ResolveError::UnknownTag(base.to_string()))?;
        let tag = self
            .tags
            .iter()
            .nth(idx)
            .ok_or_else(|| ResolveError::UnknownTag(base.to_string()))?;
        let slot = self.slot(idx);
        let access = self.io_access(tag.address);
        let value = |place| Ok(Target::Value { place, access });
        match (slot, member) {
            (TagSlot::Bool(b), None) => value(Place::Bool(b)),
            (TagSlot::Int(i), None) => value(Place::Int(i, tag.ty)),
            (TagSlot::Real(f), None) => value(Place::Real(f)),
            (TagSlot::Lint(l), None) => value(Place::Lint(l)),
            (TagSlot::Lreal(d), None) => value(Place::Lreal(d)),
            (TagSlot::Marker(a), None) => {
                value(Layout::marker_place(a, tag.ty).ok_or_else(|| ResolveError::BadAddress(a.to_string()))?)
            }
            (TagSlot::Timer(t), None) => Ok(Target::Timer(t)),
            (TagSlot::Counter(c), None) => Ok(Target::Counter(c)),
            (TagSlot::Pid(p), None) => Ok(Target::Pid(p)),
            (TagSlot::Pid(p), Some(m)) => {
                let mem = tag.ty.member(m).ok_or_else(|| ResolveError::UnknownMember {
                    tag: tag.name.clone(),
                    ty: tag.ty,
                    member: m.to_string(),
                })?;
                Ok(Target::Value {
                    place: p.member(mem),
                    access: if mem.writable {
                        Access::ReadWrite
                    } else {
                        Access::ReadOnly
                    },
                })
            }
            (TagSlot::Timer(Tmr { i, b }) | TagSlot::Counter(Ctr { i, b }), Some(m)) => {
                member_of(&tag.name, tag.ty, i, b, m)
            }
            (_, Some(_)) => Err(ResolveError::NotAStructure {
                tag: tag.name.clone(),
                ty: tag.ty,
            }),
        }
    }

    /// Who may write a value at `addr`: inputs belong to the I/O, except
    /// for a plant model, which writes inputs and only reads outputs.
    fn io_access(&self, addr: Option<Address>) -> Access {
        match addr {
            Some(a) if a.is_input() && !self.plant => Access::Input,
            Some(Address::DigitalOut(_) | Address::AnalogOut(_)) if self.plant => Access::Output,
            _ => Access::ReadWrite,
        }
    }

    fn system_tag(&self, name: &str) -> Option<Target> {
        let upper = name.to_ascii_uppercase();
        let s = &self.system;
        let place = match upper.as_str() {
            "S:FS" | "SM0.1" => Place::Bool(s.first_scan),
            "S:MINOR" => Place::Bool(s.minor_fault),
            "S:FAULTCODE" => Place::Int(s.fault_code, DataType::Dint),
            "SM0.0" => Place::Bool(s.always_on),
            "SM0.4" => Place::Bool(s.clock_60s),
            "SM0.5" => Place::Bool(s.clock_1s),
            "SM0.6" => Place::Bool(s.scan_toggle),
            "SMW22" => Place::Int(s.scan_time, DataType::Int),
            "S:IOOK" => Place::Bool(s.io_ok),
            "S:IOERRORS" => Place::Int(s.io_errors, DataType::Dint),
            "S:RETAINLOST" => Place::Bool(s.retain_lost),
            "S:STOREOK" => Place::Bool(s.store_ok),
            _ => {
                let k = crate::layout::STAT_TAGS.iter().position(|t| *t == upper)?;
                Place::Int(I(s.stats.0 + k as u32), DataType::Dint)
            }
        };
        Some(Target::Value {
            place,
            access: Access::ReadOnly,
        })
    }

    /// An SLC 500 timer or counter element (`T4:0`), or one of its members
    /// (`T4:0.ACC`): the structure a program naming it made.
    fn slc_struct(&self, st: SlcStruct, m: Option<&str>) -> Result<Target, ResolveError> {
        let slots = self.slc.get(&st).ok_or_else(|| {
            ResolveError::BadAddress(format!(
                "`{st}`: no program of this project uses the SLC 500 {} {st}; it exists once a program names it",
                if st.counter { "counter" } else { "timer" }
            ))
        })?;
        match (m, st.counter) {
            (None, false) => Ok(Target::Timer(Tmr { i: slots.i, b: slots.b })),
            (None, true) => Ok(Target::Counter(Ctr { i: slots.i, b: slots.b })),
            (Some(m), _) => member_of(&st.to_string(), st.ty(), slots.i, slots.b, m),
        }
    }

    /// `T37` (the timer bit) or `T37.CV` (its current value) of an S7-200
    /// timer in use, likewise `C5`/`C5.CV` for counters.
    pub fn s7_name(&self, name: &str) -> Option<Target> {
        let upper = name.to_ascii_uppercase();
        let (base, cv) = match upper.strip_suffix(".CV") {
            Some(b) => (b, true),
            None => (upper.as_str(), false),
        };
        let (table, digits) = match base.split_at_checked(1)? {
            ("T", d) => (&self.timers, d),
            ("C", d) => (&self.counters, d),
            _ => return None,
        };
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let slots = table.get(&digits.parse::<u8>().ok()?)?;
        Some(if cv {
            Target::Value {
                place: Place::Int(slots.i, DataType::Int),
                access: Access::ReadWrite,
            }
        } else {
            Target::Value {
                place: Place::Bool(slots.b),
                access: Access::ReadOnly,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::Files;
    use alba_model::TagTable;

    fn layout(csv: &str, used: &[Address]) -> Layout {
        let mut files = Files::new();
        let f = files.add("tags.csv", csv);
        let (t, d) = TagTable::parse(csv, f);
        assert!(d.is_empty(), "{d:?}");
        let uses = crate::layout::Uses {
            addresses: used.to_vec(),
            ..Default::default()
        };
        Layout::new(&t, &uses)
    }

    #[test]
    fn every_notation_resolves_to_the_tag_on_it() {
        let l = layout(
            "name,type,address\nStart,BOOL,DI:1/9\nLevel,DINT,AI:3/1\nW,REAL,MD4\n",
            &[],
        );
        let start = l.resolve("start").unwrap();
        assert_eq!(l.resolve("%IX1.1").unwrap(), start);
        assert_eq!(l.resolve("I1.1").unwrap(), start);
        assert!(matches!(
            start,
            Target::Value {
                access: Access::Input,
                ..
            }
        ));
        assert_eq!(l.resolve("AIW2").unwrap(), l.resolve("Level").unwrap());
        assert_eq!(
            l.resolve("%MD1").unwrap(),
            Target::Value {
                place: Place::MReal(4),
                access: Access::ReadWrite
            }
        );
        // The digital image is whole bytes: 16 inputs for DI 9.
        assert_eq!(l.di.len, 16);
        assert!(l.resolve("DI:1/15").is_ok());
        assert_eq!(
            l.resolve("DI:1/16"),
            Err(ResolveError::OutsideImage(Address::DigitalIn(16)))
        );
    }

    #[test]
    fn members_and_system_tags_have_their_access() {
        let l = layout("name,type\nT,TIMER\nC,COUNTER\nX,DINT\n", &[]);
        let Target::Value { place, access } = l.resolve("t.dn").unwrap() else {
            panic!()
        };
        assert_eq!(access, Access::ReadOnly);
        assert_eq!(place.data_type(), DataType::Bool);
        let Target::Value { access, .. } = l.resolve("C.PRE").unwrap() else {
            panic!()
        };
        assert_eq!(access, Access::ReadWrite);
        assert!(matches!(l.resolve("T").unwrap(), Target::Timer(_)));
        assert!(matches!(
            l.resolve("s:fs").unwrap(),
            Target::Value {
                access: Access::ReadOnly,
                ..
            }
        ));
        assert!(matches!(l.resolve("T.CU"), Err(ResolveError::UnknownMember { .. })));
        assert!(matches!(l.resolve("X.PRE"), Err(ResolveError::NotAStructure { .. })));
        assert!(matches!(l.resolve("Y"), Err(ResolveError::UnknownTag(_))));
        assert!(matches!(l.resolve("DI:5/0"), Err(ResolveError::BadAddress(_))));
    }
}
