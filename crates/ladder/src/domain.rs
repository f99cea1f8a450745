//! The language as the browser studio needs it, in one serialisable
//! description (`GET /api/domain`, docs/api.md): data types with the members
//! of structures, the instruction table with operand labels and titles, what
//! fits each kind of operand, and every notation of an address. The studio
//! takes all of this from here instead of writing it a second time.

use crate::ast::{Arg, Group, Mnemonic, Optional};
use alba_ir::values::{Class, class_of_type};
use alba_model::address::MarkerWidth;
use alba_model::{Address, DataType};
use serde::Serialize;

/// The reply of `GET /api/domain`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Domain {
    /// Every data type a tag may have, elementary ones first.
    pub types: Vec<TypeInfo>,
    /// Palette groups in palette order.
    pub groups: Vec<GroupInfo>,
    /// Kinds of operands (the `args` of instructions).
    pub args: Vec<ArgInfo>,
    /// Every ladder instruction, grouped in palette order.
    pub instructions: Vec<InstructionInfo>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct TypeInfo {
    pub name: &'static str,
    /// `bool`, `integer`, `real` or `structure`.
    #[cfg_attr(feature = "ts", ts(type = "'bool' | 'integer' | 'real' | 'structure'"))]
    pub kind: &'static str,
    /// Members of a structure, in order (empty for elementary types).
    pub members: Vec<MemberInfo>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct MemberInfo {
    pub name: &'static str,
    #[serde(rename = "type")]
    #[cfg_attr(feature = "ts", ts(rename = "type"))]
    pub ty: &'static str,
    /// Programs and the API may write it (else the instruction sets it).
    pub writable: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct GroupInfo {
    pub name: &'static str,
    pub title: &'static str,
}

/// A kind of operand and the tags that fit it (for the tag picker).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ArgInfo {
    pub name: &'static str,
    /// What the checker expects there.
    pub doc: &'static str,
    /// Types of the tags (and members) that fit; empty when only literals or
    /// labels do.
    pub types: Vec<&'static str>,
    /// Only writable tags and members fit.
    pub writable: bool,
    /// Members of structures of those types fit too (`T1.DN`, `T1.PRE`).
    pub members: bool,
    /// The operand names one tag, member or address whose value can be shown
    /// (false for labels, expressions and literal-only places).
    pub tag: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct InstructionInfo {
    pub mnemonic: &'static str,
    pub group: &'static str,
    /// Output instructions may end a rung; inputs are conditions.
    pub output: bool,
    /// How the ladder diagram draws it: `contact`, `coil` or `box`.
    #[cfg_attr(feature = "ts", ts(type = "'contact' | 'coil' | 'box'"))]
    pub shape: &'static str,
    /// One argument kind per operand (names of `args`).
    pub args: Vec<&'static str>,
    /// One label per operand.
    pub labels: Vec<&'static str>,
    pub title: &'static str,
    pub doc: &'static str,
    /// Status bits of the structure in the first operand, shown in the box header.
    pub bits: Vec<&'static str>,
    /// Per operand, the live value shown beside it: `null` none, `""` the
    /// operand's own value, else that member of the first operand (a
    /// timer's literal preset row shows `PRE`).
    pub shows: Vec<Option<&'static str>>,
    /// Operands that may follow the ones of `args`, in order, each with
    /// its default when left out (a TON's time base: `TON(T,5,0,s)`).
    pub optional: Vec<OptionalInfo>,
}

/// An operand an instruction may be written without. It is never a tag:
/// the studio offers its `choices` and shows no value beside it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct OptionalInfo {
    /// Its kind (`time_base`).
    pub name: &'static str,
    pub label: &'static str,
    /// What fits there, in words.
    pub doc: &'static str,
    /// The values to offer (the checker also takes other spellings, such
    /// as a time base in seconds, `0.01`).
    pub choices: Vec<&'static str>,
    /// What applies when the operand is left out.
    pub default: &'static str,
}

fn optional_info(o: Optional) -> OptionalInfo {
    OptionalInfo {
        name: o.name(),
        label: o.label(),
        doc: o.doc(),
        choices: o.choices(),
        default: o.default_value(),
    }
}

pub fn group_name(g: Group) -> &'static str {
    match g {
        Group::Bit => "bit",
        Group::Timer => "timer",
        Group::Counter => "counter",
        Group::Compare => "compare",
        Group::Math => "math",
        Group::MoveLogic => "move",
        Group::Trig => "trig",
        Group::Flow => "flow",
        Group::Special => "special",
    }
}

fn group_title(g: Group) -> &'static str {
    match g {
        Group::Bit => "Bit",
        Group::Timer => "Timer",
        Group::Counter => "Counter",
        Group::Compare => "Compare",
        Group::Math => "Math",
        Group::MoveLogic => "Move/Logic",
        Group::Trig => "Trig",
        Group::Flow => "Flow",
        Group::Special => "Special",
    }
}

const ARGS: &[Arg] = &[
    Arg::BitIn,
    Arg::BitOut,
    Arg::Timer,
    Arg::Counter,
    Arg::TimerOrCounter,
    Arg::Preset,
    Arg::Accum,
    Arg::NumIn,
    Arg::NumOut,
    Arg::Label,
    Arg::Expr,
    Arg::Pid,
];

pub fn arg_name(a: Arg) -> &'static str {
    match a {
        Arg::BitIn => "bit_in",
        Arg::BitOut => "bit_out",
        Arg::Timer => "timer",
        Arg::Counter => "counter",
        Arg::TimerOrCounter => "timer_or_counter",
        Arg::Preset => "preset",
        Arg::Accum => "accum",
        Arg::NumIn => "num_in",
        Arg::NumOut => "num_out",
        Arg::Label => "label",
        Arg::Expr => "expr",
        Arg::Pid => "pid",
    }
}

fn types_where(f: impl Fn(DataType) -> bool) -> Vec<&'static str> {
    DataType::ALL
        .iter()
        .copied()
        .filter(|t| f(*t))
        .map(DataType::name)
        .collect()
}

/// What fits an operand kind: the same rules as the checker (`lower.rs`).
fn arg_info(a: Arg) -> ArgInfo {
    let (doc, types, writable, members, tag) = match a {
        Arg::BitIn => (
            "a BOOL to read",
            types_where(|t| t == DataType::Bool),
            false,
            true,
            true,
        ),
        Arg::BitOut => (
            "a BOOL tag to write",
            types_where(|t| t == DataType::Bool),
            true,
            true,
            true,
        ),
        Arg::Timer => ("a TIMER tag", types_where(|t| t == DataType::Timer), false, false, true),
        Arg::Counter => (
            "a COUNTER tag",
            types_where(|t| t == DataType::Counter),
            false,
            false,
            true,
        ),
        Arg::TimerOrCounter => (
            "a TIMER or COUNTER tag",
            types_where(|t| matches!(t, DataType::Timer | DataType::Counter)),
            false,
            false,
            true,
        ),
        Arg::Preset => (
            "an integer preset (literal, `?` or integer tag)",
            types_where(|t| t.is_numeric() && class_of_type(t) == Class::I),
            false,
            true,
            true,
        ),
        Arg::Accum => ("an integer literal or `?`", Vec::new(), false, false, false),
        Arg::NumIn => (
            "a number (tag or literal)",
            types_where(DataType::is_numeric),
            false,
            true,
            true,
        ),
        Arg::NumOut => (
            "a numeric tag to write",
            types_where(DataType::is_numeric),
            true,
            true,
            true,
        ),
        Arg::Label => ("a label (LBL)", Vec::new(), false, false, false),
        Arg::Expr => (
            "an expression (CPT)",
            types_where(DataType::is_numeric),
            false,
            true,
            false,
        ),
        Arg::Pid => ("a PID tag", types_where(|t| t == DataType::Pid), false, false, true),
    };
    ArgInfo {
        name: arg_name(a),
        doc,
        types,
        writable,
        members,
        tag,
    }
}

/// Contacts and coils are the one-operand bit instructions; everything else is a box.
pub fn shape(m: Mnemonic) -> &'static str {
    match (m.group(), m.args().len(), m.is_output()) {
        (Group::Bit, 1, false) => "contact",
        (Group::Bit, 1, true) => "coil",
        _ => "box",
    }
}

fn instruction_info(m: Mnemonic) -> InstructionInfo {
    let args = m.args();
    let bits: &[&str] = match args.first() {
        Some(Arg::Timer) => &["EN", "TT", "DN"],
        Some(Arg::Counter) if m == Mnemonic::CTD => &["CD", "DN"],
        Some(Arg::Counter) => &["CU", "DN"],
        Some(Arg::Pid) => &["EN", "DN", "MAN"],
        _ => &[],
    };
    let shows = args
        .iter()
        .map(|a| match a {
            Arg::Preset => Some("PRE"),
            Arg::Accum => Some("ACC"),
            a if arg_info(*a)
                .types
                .iter()
                .all(|t| DataType::parse(t).is_some_and(DataType::is_struct)) =>
            {
                None
            }
            a if !arg_info(*a).tag => None,
            _ => Some(""),
        })
        .collect();
    InstructionInfo {
        mnemonic: m.name(),
        group: group_name(m.group()),
        output: m.is_output(),
        shape: shape(m),
        args: args.iter().map(|a| arg_name(*a)).collect(),
        labels: m.labels().to_vec(),
        title: m.title(),
        doc: m.doc(),
        bits: bits.to_vec(),
        shows,
        optional: m.optional().iter().map(|o| optional_info(*o)).collect(),
    }
}

/// The instruction table in palette order.
pub fn instructions() -> Vec<InstructionInfo> {
    Mnemonic::ALL.iter().map(|m| instruction_info(*m)).collect()
}

fn type_info(t: DataType) -> TypeInfo {
    let kind = if t == DataType::Bool {
        "bool"
    } else if t.is_integer() {
        "integer"
    } else if t.is_real() {
        "real"
    } else {
        "structure"
    };
    TypeInfo {
        name: t.name(),
        kind,
        members: t
            .members()
            .iter()
            .map(|m| MemberInfo {
                name: m.name,
                ty: m.ty.name(),
                writable: m.writable,
            })
            .collect(),
    }
}

/// The whole description.
pub fn domain() -> Domain {
    let mut groups: Vec<Group> = Vec::new();
    for m in Mnemonic::ALL {
        if !groups.contains(&m.group()) {
            groups.push(m.group());
        }
    }
    Domain {
        types: DataType::ALL.iter().map(|t| type_info(*t)).collect(),
        groups: groups
            .into_iter()
            .map(|g| GroupInfo {
                name: group_name(g),
                title: group_title(g),
            })
            .collect(),
        args: ARGS.iter().map(|a| arg_info(*a)).collect(),
        instructions: instructions(),
    }
}

/// Every notation of an address (SPEC §2.2, and the SLC 500's), upper case, the API's own
/// (AuroraLD for I/O, S7 for markers) first: what an operand may write to
/// name it. Each one parses back to `a` (tested).
pub fn notations(a: Address) -> Vec<String> {
    let mut out = vec![a.to_string()];
    match a {
        Address::DigitalIn(n) | Address::DigitalOut(n) => {
            let io = if matches!(a, Address::DigitalIn(_)) { 'I' } else { 'Q' };
            let (byte, bit) = (n / 8, n % 8);
            out.push(format!("%{io}X{byte}.{bit}"));
            out.push(format!("%{io}{byte}.{bit}"));
            out.push(format!("{io}{byte}.{bit}"));
        }
        Address::AnalogIn(n) => {
            out.push(format!("%IW{n}"));
            out.push(format!("AIW{}", n * 2));
            out.push(format!("AIN{n}"));
        }
        Address::AnalogOut(n) => {
            out.push(format!("%QW{n}"));
            out.push(format!("AQW{}", n * 2));
        }
        Address::Marker { byte, width } => match width {
            MarkerWidth::Bit(bit) => {
                out.push(format!("%MX{byte}.{bit}"));
                out.push(format!("%M{byte}.{bit}"));
            }
            MarkerWidth::Byte => out.push(format!("%MB{byte}")),
            MarkerWidth::Word if byte % 2 == 0 => out.push(format!("%MW{}", byte / 2)),
            MarkerWidth::DWord if byte % 4 == 0 => out.push(format!("%MD{}", byte / 4)),
            MarkerWidth::Word | MarkerWidth::DWord => {}
        },
    }
    // The SLC 500's, where it has one (digital channels, the B, N and F files).
    out.extend(alba_model::slc::notation(a));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_notation_parses_back_to_its_address() {
        let mut addrs = Vec::new();
        for n in [0, 1, 7, 8, 13, 8191] {
            addrs.push(Address::DigitalIn(n));
            addrs.push(Address::DigitalOut(n));
        }
        for n in [0, 1, 2, 1023] {
            addrs.push(Address::AnalogIn(n));
            addrs.push(Address::AnalogOut(n));
        }
        for byte in [0, 1, 2, 3, 4, 6, 4092] {
            for width in [
                MarkerWidth::Bit(0),
                MarkerWidth::Bit(7),
                MarkerWidth::Byte,
                MarkerWidth::Word,
                MarkerWidth::DWord,
            ] {
                addrs.push(Address::Marker { byte, width });
            }
        }
        for a in addrs {
            let all = notations(a);
            assert_eq!(all[0], a.to_string());
            for n in &all {
                assert_eq!(Address::parse(n), Ok(Some(a)), "{n}");
                assert_eq!(n, &n.to_ascii_uppercase());
            }
            let mut unique = all.clone();
            unique.dedup();
            assert_eq!(unique.len(), all.len(), "{all:?}");
        }
        assert_eq!(
            notations(Address::DigitalIn(13)),
            ["DI:1/13", "%IX1.5", "%I1.5", "I1.5", "I:0/13"]
        );
        assert_eq!(
            notations(Address::Marker {
                byte: 516,
                width: MarkerWidth::Word
            }),
            ["MW516", "%MW258", "N7:2"]
        );
        assert_eq!(notations(Address::AnalogIn(2)), ["AI:3/2", "%IW2", "AIW4", "AIN2"]);
        assert_eq!(
            notations(Address::Marker {
                byte: 4,
                width: MarkerWidth::DWord
            }),
            ["MD4", "%MD1"]
        );
    }

    #[test]
    fn every_instruction_has_a_label_per_operand_and_known_kinds() {
        let d = domain();
        let kinds: Vec<&str> = d.args.iter().map(|a| a.name).collect();
        for i in &d.instructions {
            assert_eq!(i.labels.len(), i.args.len(), "{}", i.mnemonic);
            assert_eq!(i.shows.len(), i.args.len(), "{}", i.mnemonic);
            assert!(i.args.iter().all(|a| kinds.contains(a)), "{}", i.mnemonic);
            assert!(!i.title.is_empty() && !i.doc.is_empty(), "{}", i.mnemonic);
            assert!(d.groups.iter().any(|g| g.name == i.group), "{}", i.mnemonic);
        }
        let pid = d.instructions.iter().find(|i| i.mnemonic == "PID").expect("PID");
        assert_eq!(pid.args, ["pid", "num_in", "num_out"]);
        assert_eq!(pid.labels, ["PID", "Process Var", "Control Var"]);
        assert_eq!(pid.shows, [None, Some(""), Some("")]);
        let ton = d.instructions.iter().find(|i| i.mnemonic == "TON").expect("TON");
        assert_eq!(ton.shows, [None, Some("PRE"), Some("ACC")]);
        assert_eq!(ton.optional.len(), 1);
        assert_eq!(ton.optional[0].name, "time_base");
        assert_eq!(ton.optional[0].label, "Time base");
        assert_eq!(ton.optional[0].choices, ["ms", "cs", "ds", "s", "min"]);
        assert_eq!(ton.optional[0].default, "ms");
        for i in &d.instructions {
            let timed = matches!(i.mnemonic, "TON" | "TOF" | "RTO");
            assert_eq!(!i.optional.is_empty(), timed, "{}", i.mnemonic);
            for o in &i.optional {
                assert!(
                    !kinds.contains(&o.name),
                    "{}: an optional kind is not a tag kind",
                    o.name
                );
                // every choice is one the checker takes
                assert!(o.choices.iter().all(|c| crate::TimeBase::parse(c).is_some()));
            }
        }
        let shapes: Vec<(&str, &str)> = d
            .instructions
            .iter()
            .filter(|i| i.shape != "box")
            .map(|i| (i.mnemonic, i.shape))
            .collect();
        assert_eq!(
            shapes,
            [
                ("XIC", "contact"),
                ("XIO", "contact"),
                ("OTE", "coil"),
                ("OTL", "coil"),
                ("OTU", "coil"),
                ("ONS", "contact")
            ]
        );
    }

    #[test]
    fn structures_come_with_their_members() {
        let d = domain();
        for t in DataType::ALL {
            let info = d.types.iter().find(|i| i.name == t.name()).expect("type");
            assert_eq!(info.members.len(), t.members().len());
            assert_eq!(info.kind == "structure", t.is_struct(), "{t}");
        }
        let pid = d.types.iter().find(|i| i.name == "PID").expect("PID");
        assert!(
            pid.members
                .iter()
                .any(|m| m.name == "SP" && m.ty == "REAL" && m.writable)
        );
    }
}
