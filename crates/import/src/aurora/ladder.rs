//! instructions.pl: AuroraLD's ladder (seed `000_…` §3.4, §3.10, §3.14).
//!
//! The file holds the counter of each of the 40 kinds (Fig. 206), then the
//! attributes of every instruction, kind after kind in the counters' order
//! (Fig. 208), each instruction's attributes one a line in the order of its
//! class (XIC: Fig. 207; CTU: Fig. 211). An instruction knows its rung
//! (`belong`) and its place in pixels (`x`, `y`) on the workspace's grid of
//! 70-pixel columns from x = 255, ten columns of conditions ("Saving") then
//! one blank and three of outputs ("Computing") (Figs. 49–51, 60). A branch
//! (`BST`) spans `arm_x` pixels from its `x` and joins the row `arm_y`
//! below its own: the conditions between its ends, on either row, are its
//! legs (Fig. 196), and several BSTs with the same ends make more legs
//! (§3.4.1.4).
//!
//! AuroraLD evaluates a rung by ANDing each leg's conditions, ORing the
//! legs of a branch, and ANDing the branches with the conditions on the rung
//! itself (Figs. 193–195); then every output of the rung gets that state,
//! kind by kind (Fig. 191). That is one Alba rung: the conditions, branches
//! as `[leg,leg]`, then the outputs in series — Alba's outputs pass the rung
//! condition on (docs/ladder.md §2.3), so each sees the state AuroraLD gave
//! it.

use super::{F, Held, INSTRUCTIONS, MAX_EACH, Reader, Rec, Tags, Ty, clip};
use crate::circuit::Structs;
use crate::{Error, Kind, Location, ProgramOut, Report};
use alba_ladder::TimeBase;
use std::collections::HashMap;

/// Alba's scan period for an AuroraLD program: the board sends its inputs
/// every 20 ms (§3.16–3.17), and AuroraLD runs the ladder as often as it can.
pub(crate) const SCAN_MS: u32 = 20;

/// Where the output columns start: column 10 of 70 pixels from x = 255 (Fig. 51).
const OUTPUT_X: i64 = 255 + 10 * 70;
/// Two `y` within this many pixels are the same row.
const Y_TOLERANCE: f64 = 1.0;

use F::{Bool as B, Float as Fl, Int as I, Str as S};

/// XIC, XIO, OTE, OTL, OTU (Fig. 207).
const BIT: &[(&str, F)] = &[
    ("name", S),
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("value", I),
    ("state", B),
    ("belong", I),
    ("row_tag", I),
    ("nn", I),
    ("exist", B),
    ("exist2", B),
];
/// NWR (Figs. 62–63).
const RUNG: &[(&str, F)] = &[("num", I), ("y", Fl)];
/// BRANCH (Figs. 75, 77).
const BRANCH: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("arm_x", I),
    ("arm_y", I),
    ("belong", I),
];
/// TIMER_ON, TIMER_OFF, TIMER_RTO: the constructor's attributes (Fig. 89),
/// then `row_tag` as CTU's load sets it (Fig. 211).
const TIMER: &[(&str, F)] = &[
    ("name", S),
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("state", B),
    ("belong", I),
    ("t_base", Fl),
    ("preset", I),
    ("acc", I),
    ("en", B),
    ("dn", B),
    ("row_tag", I),
];
/// COUNTER_UP, COUNTER_DOWN (Fig. 211).
const COUNTER: &[(&str, F)] = &[
    ("name", S),
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("state", B),
    ("belong", I),
    ("preset", I),
    ("acc", I),
    ("en", B),
    ("dn", B),
    ("row_tag", I),
];
/// RESET (Fig. 107), `row_tag` last as for the counters.
const RESET: &[(&str, F)] = &[
    ("name", S),
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("state", B),
    ("belong", I),
    ("row_tag", I),
];
/// LIMIT (Fig. 112).
const LIMIT: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("low_s", S),
    ("high_s", S),
    ("test_s", S),
    ("low", Fl),
    ("high", Fl),
    ("test", Fl),
    ("state", B),
    ("belong", I),
];
/// EQUAL and the other compares (Fig. 109).
const COMPARE: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("sourceA_s", S),
    ("sourceB_s", S),
    ("sourceA", Fl),
    ("sourceB", Fl),
    ("state", B),
    ("belong", I),
];
/// ADD, SUB, MUL, DIV, MOD (Fig. 126).
const MATH3: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("sourceA_s", S),
    ("sourceB_s", S),
    ("dest_s", S),
    ("sourceA", Fl),
    ("sourceB", Fl),
    ("dest", Fl),
    ("state", B),
    ("belong", I),
];
/// SQR, NEG, ABS (MUL without source B, §3.4.4.5), MOV (Fig. 152), the
/// trigonometric (Fig. 155) and conversion (Fig. 169) instructions.
const MATH2: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("sourceA_s", S),
    ("dest_s", S),
    ("sourceA", Fl),
    ("dest", Fl),
    ("state", B),
    ("belong", I),
];
/// COMPUTE (Fig. 145).
const COMPUTE: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("exp_s", S),
    ("dest_s", S),
    ("function", S),
    ("dest", Fl),
    ("state", B),
    ("belong", I),
];
/// SCALE_PARAMETERS (Fig. 148).
const SCALE: &[(&str, F)] = &[
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("input_s", S),
    ("output_s", S),
    ("input", Fl),
    ("output", Fl),
    ("input_min", Fl),
    ("input_max", Fl),
    ("scaled_min", Fl),
    ("scaled_max", Fl),
    ("state", B),
    ("belong", I),
];
/// CONTROL_PID (Fig. 179).
const PID: &[(&str, F)] = &[
    ("name", S),
    ("type", S),
    ("num", I),
    ("x", I),
    ("y", Fl),
    ("state", B),
    ("belong", I),
    ("PV_s", S),
    ("CV_s", S),
    ("SP_s", S),
    ("PV", Fl),
    ("CV", Fl),
    ("SP", Fl),
    ("error", Fl),
    ("kp", Fl),
    ("kd", Fl),
    ("ki", Fl),
];

/// The 40 kinds in the order of the counters (Fig. 206) and of their
/// attributes (Fig. 208).
pub(crate) const KINDS: [(&str, &[(&str, F)]); 40] = [
    ("rung", RUNG),
    ("XIC", BIT),
    ("XIO", BIT),
    ("BST", BRANCH),
    ("OTE", BIT),
    ("OTL", BIT),
    ("OTU", BIT),
    ("TON", TIMER),
    ("TOF", TIMER),
    ("RTO", TIMER),
    ("CTU", COUNTER),
    ("CTD", COUNTER),
    ("RES", RESET),
    ("LIM", LIMIT),
    ("EQU", COMPARE),
    ("NEQ", COMPARE),
    ("LES", COMPARE),
    ("GRT", COMPARE),
    ("LEQ", COMPARE),
    ("GEQ", COMPARE),
    ("ADD", MATH3),
    ("SUB", MATH3),
    ("MUL", MATH3),
    ("DIV", MATH3),
    ("SQR", MATH2),
    ("NEG", MATH2),
    ("MOD", MATH3),
    ("ABS", MATH2),
    ("CPT", COMPUTE),
    ("SCP", SCALE),
    ("MOV", MATH2),
    ("ACS", MATH2),
    ("ASN", MATH2),
    ("ATN", MATH2),
    ("COS", MATH2),
    ("SIN", MATH2),
    ("TAN", MATH2),
    ("DEG", MATH2),
    ("RAD", MATH2),
    ("PID", PID),
];

/// The input (condition) instructions (§3.10); BST stands on both sides.
const INPUTS: &[&str] = &["XIC", "XIO", "LIM", "EQU", "NEQ", "LES", "GRT", "LEQ", "GEQ"];

/// The parsed file: the rungs, and every instruction with its kind.
pub(crate) struct Rows {
    pub rungs: Vec<Rec>,
    pub instrs: Vec<(&'static str, Rec)>,
}

/// Reads instructions.pl.
pub(crate) fn read(text: &str) -> Result<Rows, Error> {
    let mut r = Reader::new(INSTRUCTIONS, text);
    let mut counts = Vec::with_capacity(KINDS.len());
    for (name, _) in KINDS {
        let what = || {
            format!(
                "the number of {name} instructions (`{}_counter`)",
                name.to_ascii_lowercase()
            )
        };
        counts.push(r.count(&what, &|n| {
            format!("{n} {name}: AuroraLD holds 0 to {MAX_EACH} of each instruction (its arrays of 200, Fig. 67)")
        })?);
    }
    let mut rows = Rows {
        rungs: Vec::new(),
        instrs: Vec::new(),
    };
    for ((name, layout), n) in KINDS.iter().zip(counts) {
        for k in 0..n {
            let what = if *name == "rung" {
                format!("RUNG {k}")
            } else {
                format!("{name} {k}")
            };
            let rec = r.record(&what, layout)?;
            if layout.iter().any(|(f, _)| *f == "type") && rec.s("type").trim() != *name {
                return Err(Error::at(
                    rec.at("type"),
                    format!(
                        "`{}` where the `type` of {what} should be `{name}`: the counters at the top of {INSTRUCTIONS} do not match the attributes that follow",
                        clip(rec.s("type").trim())
                    ),
                ));
            }
            if *name == "rung" {
                rows.rungs.push(rec);
            } else {
                rows.instrs.push((name, rec));
            }
        }
    }
    r.finish("the attributes of the last instruction")?;
    Ok(rows)
}

/// A number as an Alba literal: an integer when it is one (so it does not
/// change the class of the computation), else a real.
pub(crate) fn lit(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 9.0e15 {
        format!("{}", v as i64)
    } else if v.abs() >= 1.0e15 || (v != 0.0 && v.abs() < 1.0e-6) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// What a converted rung needs besides the tags.
struct Ctx<'a> {
    tags: &'a Tags,
    /// Timer → its time base (s), from its first instruction.
    time_base: HashMap<String, f64>,
    /// Counter → (counted up, counted down).
    counting: HashMap<String, (bool, bool)>,
    /// Timer → its literal preset and accumulator (ms).
    timers: HashMap<String, (i64, i64)>,
    structs: Structs,
}

/// Notes of a rung, reported only if the rung converts.
type Notes = Vec<(Kind, Location, String)>;

impl Ctx<'_> {
    /// A bit operand (XIC, XIO): a Bool tag or a timer's or counter's DN/EN.
    fn bit(&self, name: &str, notes: &mut Notes, at: &Location) -> Result<String, String> {
        let (alba, held) = self.tags.resolve(name)?;
        if held != Held::Bit {
            return Err(format!(
                "`{}` is not a Bool (nor a timer's or counter's DN or EN)",
                name.trim()
            ));
        }
        // A counter's EN: Alba keeps the rung of CTU in CU and of CTD in CD.
        if let Some(base) = alba.strip_suffix(".EN")
            && let Some(&(up, down)) = self.counting.get(&base.to_ascii_lowercase())
        {
            let m = if down && !up { "CD" } else { "CU" };
            if up && down {
                notes.push((
                    Kind::Approximated,
                    at.clone(),
                    format!(
                        "`{}`: the counter is counted up and down; its EN is taken as CU (the CTU's rung)",
                        name.trim()
                    ),
                ));
            }
            return Ok(format!("{base}.{m}"));
        }
        Ok(alba)
    }

    /// A numeric source: a tag, a member, `NUM` (the value in `value`) or a number.
    fn num(&self, name: &str, value: f64, notes: &mut Notes, at: &Location) -> Result<String, String> {
        let t = name.trim();
        if t.eq_ignore_ascii_case("NUM") {
            return Ok(lit(value));
        }
        if let Ok(v) = t.parse::<f64>() {
            return if v.is_finite() {
                Ok(lit(v))
            } else {
                Err(format!("`{t}` is not a number Alba holds"))
            };
        }
        self.number(t, notes, at)
    }

    fn number(&self, t: &str, notes: &mut Notes, at: &Location) -> Result<String, String> {
        let (alba, held) = self.tags.resolve(t)?;
        match held {
            Held::Number => {
                if let Some((base, m)) = alba.rsplit_once('.')
                    && let Some(tb) = self.time_base.get(&base.to_ascii_lowercase())
                    && TimeBase::from_seconds(*tb).is_none()
                {
                    notes.push((
                        Kind::Approximated,
                        at.clone(),
                        format!(
                            "`{t}`: Alba's timers count {m} in ms; AuroraLD counts it in the time base of `{base}` ({tb} s)"
                        ),
                    ));
                }
                Ok(alba)
            }
            Held::Bit => Err(format!("`{t}` is a Bool; this operand is a number")),
            Held::Structure(_) => Err(format!("`{t}` is a structure; use its ACC or PRE")),
        }
    }

    /// A numeric destination: an Int or Real tag, or a timer's or counter's ACC/PRE.
    fn dest(&self, name: &str, notes: &mut Notes, at: &Location) -> Result<String, String> {
        let t = name.trim();
        if t.eq_ignore_ascii_case("NUM") || t.parse::<f64>().is_ok() {
            return Err(format!("the destination `{t}` is not a tag"));
        }
        self.number(t, notes, at)
    }

    /// Whether an Alba operand is an Int tag (a DINT).
    fn is_int(&self, alba: &str) -> bool {
        self.tags
            .map
            .values()
            .any(|s| s.ty == Ty::Int && s.alba.eq_ignore_ascii_case(alba))
    }

    /// A structure operand (timer, counter) of the wanted type.
    fn structure(&self, name: &str, want: &[Ty]) -> Result<String, String> {
        let (alba, held) = self.tags.resolve(name)?;
        match held {
            Held::Structure(t) if want.contains(&t) => Ok(alba),
            _ => Err(format!(
                "`{}` is not a {}",
                name.trim(),
                want.iter()
                    .map(|t| t.alba().to_ascii_lowercase())
                    .collect::<Vec<_>>()
                    .join(" or ")
            )),
        }
    }

    /// The input fragment of a condition instruction.
    fn input(&self, kind: &str, rec: &Rec, notes: &mut Notes) -> Result<String, String> {
        let at = rec.loc.clone();
        match kind {
            "XIC" | "XIO" => Ok(format!("{kind}({})", self.bit(rec.s("name"), notes, &at)?)),
            "LIM" => {
                // Low <= Test < High (§3.4.3.1), not Logix's bounds-included LIM.
                let low = self.num(rec.s("low_s"), rec.f("low"), notes, &at)?;
                let test = self.num(rec.s("test_s"), rec.f("test"), notes, &at)?;
                let high = self.num(rec.s("high_s"), rec.f("high"), notes, &at)?;
                Ok(format!("GEQ({test},{low})LES({test},{high})"))
            }
            _ => {
                let a = self.num(rec.s("sourceA_s"), rec.f("sourceA"), notes, &at)?;
                let b = self.num(rec.s("sourceB_s"), rec.f("sourceB"), notes, &at)?;
                Ok(format!("{kind}({a},{b})"))
            }
        }
    }

    /// The Alba instruction of an output.
    fn output(&mut self, kind: &str, rec: &Rec, notes: &mut Notes) -> Result<String, String> {
        let at = rec.loc.clone();
        let float_into_int = |dest: &str, notes: &mut Notes, ctx: &Ctx<'_>| {
            if ctx.is_int(dest) {
                notes.push((
                    Kind::Approximated,
                    at.clone(),
                    format!(
                        "{kind} into the Int `{dest}`: AuroraLD computes in float (§3.4.4) and the seed does not say how an Int stores the result; Alba rounds to the nearest integer (integer division truncates)"
                    ),
                ));
            }
        };
        match kind {
            "OTE" | "OTL" | "OTU" => {
                let (alba, held) = self.tags.resolve(rec.s("name"))?;
                match held {
                    Held::Bit if alba.contains('.') => Err(format!(
                        "`{}` is a status bit of a timer or counter; Alba's programs do not write those",
                        rec.s("name").trim()
                    )),
                    Held::Bit => Ok(format!("{kind}({alba})")),
                    _ => Err(format!("`{}` is not a Bool", rec.s("name").trim())),
                }
            }
            "TON" | "TOF" | "RTO" => {
                let t = self.structure(rec.s("name"), &[Ty::Timer])?;
                let tb = rec.f("t_base");
                // One timer counts in one base in Alba: its first instruction's.
                let first = self.time_base.get(&t.to_ascii_lowercase()).copied().unwrap_or(tb);
                if (first - tb).abs() > 1e-9 {
                    notes.push((
                        Kind::Approximated,
                        rec.at("t_base"),
                        format!(
                            "{kind} `{t}`: the time base {tb} s differs from the {first} s of the timer's first instruction; Alba counts a timer in one base ({first} s, preset and accumulator as given)"
                        ),
                    ));
                }
                let base = TimeBase::from_seconds(first);
                if base.is_none() {
                    notes.push((
                        Kind::Approximated,
                        rec.at("t_base"),
                        format!("{kind} `{t}`: the time base {first} s is not one of AuroraLD's (Table 7); the timer counts in ms"),
                    ));
                }
                // Table 7's bases are kept: PRE and ACC as given, in the base's units.
                // Another base is converted to milliseconds.
                let scale = if base.is_some() { 1.0 } else { first * 1000.0 };
                let units = |v: i64| (v as f64) * scale;
                let (pre, acc) = (units(rec.i("preset")), units(rec.i("acc")));
                if pre < 0.0 || acc < 0.0 {
                    return Err(format!("{kind} `{t}`: a negative preset or accumulator"));
                }
                if pre > f64::from(i32::MAX) || acc > f64::from(i32::MAX) {
                    return Err(format!("{kind} `{t}`: a preset beyond a DINT"));
                }
                if (pre - pre.round()).abs() > 1e-6 {
                    notes.push((
                        Kind::Approximated,
                        rec.at("preset"),
                        format!("{kind} `{t}`: {pre} ms is rounded to whole milliseconds"),
                    ));
                }
                let suffix = match base {
                    Some(b) if b != TimeBase::Ms => format!(",{}", b.name()),
                    _ => String::new(),
                };
                let (pre, acc) = (pre.round() as i64, acc.round() as i64);
                let key = t.to_ascii_lowercase();
                let args = match self.timers.get(&key) {
                    None => {
                        self.timers.insert(key, (pre, acc));
                        format!("{t},{pre},{acc}{suffix}")
                    }
                    Some(&(p, a)) => {
                        if p != pre {
                            notes.push((
                                Kind::Approximated,
                                rec.at("preset"),
                                format!(
                                    "{kind} `{t}`: a second preset ({pre}, the first is {p}); Alba keeps one per timer"
                                ),
                            ));
                        }
                        let ps = if p == pre { pre.to_string() } else { "?".into() };
                        let acs = if a == acc { acc.to_string() } else { "?".into() };
                        format!("{t},{ps},{acs}{suffix}")
                    }
                };
                Ok(format!("{kind}({args})"))
            }
            "CTU" | "CTD" => {
                let c = self.structure(rec.s("name"), &[Ty::Counter])?;
                let (args, same) = self.structs.counter(&c, rec.i("preset"), rec.i("acc"));
                if !same {
                    notes.push((
                        Kind::Approximated,
                        rec.at("preset"),
                        format!(
                            "{kind} `{c}`: a second preset {}; Alba keeps one per counter",
                            rec.i("preset")
                        ),
                    ));
                }
                Ok(format!("{kind}({args})"))
            }
            "RES" => Ok(format!(
                "RES({})",
                self.structure(rec.s("name"), &[Ty::Timer, Ty::Counter])?
            )),
            "ADD" | "SUB" | "MUL" | "DIV" | "MOD" => {
                let a = self.num(rec.s("sourceA_s"), rec.f("sourceA"), notes, &at)?;
                let b = self.num(rec.s("sourceB_s"), rec.f("sourceB"), notes, &at)?;
                let d = self.dest(rec.s("dest_s"), notes, &at)?;
                if kind == "DIV" {
                    float_into_int(&d, notes, self);
                }
                Ok(format!("{kind}({a},{b},{d})"))
            }
            "SQR" | "NEG" | "ABS" | "MOV" | "ACS" | "ASN" | "ATN" | "COS" | "SIN" | "TAN" | "DEG" | "RAD" => {
                let a = self.num(rec.s("sourceA_s"), rec.f("sourceA"), notes, &at)?;
                let d = self.dest(rec.s("dest_s"), notes, &at)?;
                if !matches!(kind, "NEG" | "ABS" | "MOV") {
                    float_into_int(&d, notes, self);
                }
                Ok(format!("{kind}({a},{d})"))
            }
            "CPT" => {
                let d = self.dest(rec.s("dest_s"), notes, &at)?;
                let expr = qscript(rec.s("function"), self, notes, &at)?;
                float_into_int(&d, notes, self);
                Ok(format!("CPT({d},{expr})"))
            }
            "SCP" => {
                let input = self.num(rec.s("input_s"), rec.f("input"), notes, &at)?;
                let out = self.dest(rec.s("output_s"), notes, &at)?;
                float_into_int(&out, notes, self);
                Ok(format!(
                    "SCP({input},{},{},{},{},{out})",
                    lit(rec.f("input_min")),
                    lit(rec.f("input_max")),
                    lit(rec.f("scaled_min")),
                    lit(rec.f("scaled_max"))
                ))
            }
            _ => Err(format!(
                "{kind} is not converted: the attributes AuroraLD saves (Fig. 179: the tags of PV, CV and SP, and KP, KI, KD) lack the sampling time, the scaling and the control direction an Alba PID loop needs"
            )),
        }
    }
}

/// An instruction placed on a rung.
struct Item<'r> {
    kind: &'static str,
    order: usize,
    rec: &'r Rec,
    x: i64,
    y: f64,
}

/// A branch: its ends and the rows of its legs.
struct Group {
    x0: i64,
    x1: i64,
    rows: Vec<f64>,
}

/// The program: main.lad.
pub(crate) fn convert(rows: &Rows, tags: &Tags, report: &mut Report) -> Result<ProgramOut, Error> {
    let mut ctx = Ctx {
        tags,
        time_base: HashMap::new(),
        counting: HashMap::new(),
        timers: HashMap::new(),
        structs: Structs::default(),
    };
    for (kind, rec) in &rows.instrs {
        let Ok((alba, _)) = tags.resolve(rec.s("name")) else {
            continue;
        };
        let key = alba.to_ascii_lowercase();
        match *kind {
            "TON" | "TOF" | "RTO" => {
                ctx.time_base.entry(key).or_insert(rec.f("t_base"));
            }
            "CTU" => ctx.counting.entry(key).or_default().0 = true,
            "CTD" => ctx.counting.entry(key).or_default().1 = true,
            _ => {}
        }
    }
    let mut by_rung: Vec<Vec<Item<'_>>> = (0..rows.rungs.len()).map(|_| Vec::new()).collect();
    for (kind, rec) in &rows.instrs {
        let belong = rec.i("belong");
        let order = KINDS.iter().position(|(k, _)| k == kind).unwrap_or(0);
        match usize::try_from(belong).ok().and_then(|b| by_rung.get_mut(b)) {
            Some(v) => v.push(Item {
                kind,
                order,
                rec,
                x: rec.i("x"),
                y: rec.f("y"),
            }),
            None => report.push(
                Kind::Refused,
                rec.loc.clone(),
                format!(
                    "{}: it belongs to rung {belong}, and there are {} rungs; left out",
                    rec.what,
                    rows.rungs.len()
                ),
            ),
        }
    }
    let mut prog = ProgramOut::new("main.lad".into());
    for (u, (rung, items)) in rows.rungs.iter().zip(&mut by_rung).enumerate() {
        let mut notes = Notes::new();
        match rung_text(u, rung.f("y"), items, &mut ctx, &mut notes) {
            Ok(Some(text)) => {
                prog.line(&format!("{text};"), Some(&rung.loc));
                report.push(
                    Kind::Converted,
                    rung.loc.clone(),
                    format!("rung {u}: `{}`", clip(&text)),
                );
                for (k, l, m) in notes {
                    report.push(k, l, m);
                }
            }
            Ok(None) => report.push(
                Kind::Refused,
                rung.loc.clone(),
                format!("rung {u} is blank (AuroraLD's compiler refuses blank rungs, §3.13); left out"),
            ),
            Err((at, why)) => {
                let at = at.unwrap_or_else(|| rung.loc.clone());
                report.push(Kind::Refused, at, format!("rung {u}: {why}; left out"));
                prog.line(&format!("// REFUSED by alba import: rung {u}: {why}"), Some(&rung.loc));
            }
        }
    }
    if rows.rungs.is_empty() {
        prog.line("// AuroraLD's program has no rungs", None);
        prog.line("AFI()NOP();", None);
    }
    Ok(prog)
}

type RungError = (Option<Location>, String);

/// The Alba text of rung `u` (at `rung_y`), `None` for a blank rung.
fn rung_text(
    u: usize,
    rung_y: f64,
    items: &mut [Item<'_>],
    ctx: &mut Ctx<'_>,
    notes: &mut Notes,
) -> Result<Option<String>, RungError> {
    if items.iter().all(|i| i.kind == "BST") {
        return Ok(None);
    }
    items.sort_by_key(|i| (i.x, i.order, i.rec.i("num")));
    let here = |i: &Item<'_>| Some(i.rec.loc.clone());
    let mut groups: Vec<Group> = Vec::new();
    for b in items.iter().filter(|i| i.kind == "BST" && i.x < OUTPUT_X) {
        let (ax, ay) = (b.rec.i("arm_x"), b.rec.i("arm_y"));
        if ax <= 0 || ay <= 0 {
            return Err((
                here(b),
                format!("{} has no extent (arm_x {ax}, arm_y {ay})", b.rec.what),
            ));
        }
        let rows = [b.y, b.y + ay as f64];
        match groups.iter_mut().find(|g| g.x0 == b.x && g.x1 == b.x + ax) {
            Some(g) => g.rows.extend(rows),
            None => groups.push(Group {
                x0: b.x,
                x1: b.x.saturating_add(ax),
                rows: rows.to_vec(),
            }),
        }
    }
    for g in &mut groups {
        g.rows.sort_by(f64::total_cmp);
        g.rows.dedup_by(|a, b| (*a - *b).abs() <= Y_TOLERANCE);
    }
    groups.sort_by_key(|g| g.x0);
    if let Some(w) = groups.windows(2).find(|w| w[0].x1 > w[1].x0) {
        return Err((
            None,
            format!(
                "branches overlap or nest (x {}–{} and {}–{}); AuroraLD's evaluator ORs the legs of each branch and ANDs the branches (Figs. 193–195), which gives nested branches no meaning",
                w[0].x0, w[0].x1, w[1].x0, w[1].x1
            ),
        ));
    }
    // Conditions: on the rung, or on a leg of a branch.
    let mut main: Vec<(i64, String)> = Vec::new();
    let mut legs: Vec<Vec<Vec<String>>> = groups.iter().map(|g| vec![Vec::new(); g.rows.len()]).collect();
    let mut outputs: Vec<&Item<'_>> = Vec::new();
    for it in items.iter() {
        let input = INPUTS.contains(&it.kind);
        if it.kind == "BST" {
            continue;
        }
        if input != (it.x < OUTPUT_X) {
            let side = if input {
                "outputs (Computing)"
            } else {
                "conditions (Saving)"
            };
            return Err((
                here(it),
                format!("{} at x = {} stands among the {side} (Fig. 60)", it.rec.what, it.x),
            ));
        }
        if !input {
            outputs.push(it);
            continue;
        }
        let frag = ctx
            .input(it.kind, it.rec, notes)
            .map_err(|why| (here(it), format!("{}: {why}", it.rec.what)))?;
        match groups.iter().position(|g| g.x0 <= it.x && it.x < g.x1) {
            Some(gi) => {
                let Some(row) = groups[gi].rows.iter().position(|r| (r - it.y).abs() <= Y_TOLERANCE) else {
                    return Err((
                        here(it),
                        format!(
                            "{} (x = {}, y = {}) is inside the branch at x = {} but on none of its legs",
                            it.rec.what, it.x, it.y, groups[gi].x0
                        ),
                    ));
                };
                legs[gi][row].push(frag);
            }
            None if (it.y - rung_y).abs() <= Y_TOLERANCE => main.push((it.x, frag)),
            None => {
                return Err((
                    here(it),
                    format!(
                        "{} (x = {}, y = {}) is neither on rung {u} (y = {rung_y}) nor on a leg of one of its branches",
                        it.rec.what, it.x, it.y
                    ),
                ));
            }
        }
    }
    for (g, legs) in groups.iter().zip(legs) {
        // A leg without conditions conducts (its product starts true,
        // Fig. 196), and so does the branch.
        if legs.iter().any(Vec::is_empty) {
            continue;
        }
        let texts: Vec<String> = legs.iter().map(|l| l.concat()).collect();
        main.push((g.x0, format!("[{}]", texts.join(","))));
    }
    main.sort_by_key(|(x, _)| *x);
    if outputs.is_empty() {
        return Err((None, "it has no output instruction".into()));
    }
    // Outputs kind by kind, as AuroraLD's scan runs them (Fig. 191).
    outputs.sort_by_key(|i| (i.order, i.rec.i("num")));
    let mut text: String = main.into_iter().map(|(_, t)| t).collect();
    for o in outputs {
        let instr = ctx
            .output(o.kind, o.rec, notes)
            .map_err(|why| (here(o), format!("{}: {why}", o.rec.what)))?;
        text.push_str(&instr);
    }
    Ok(Some(text))
}

/// Deepest nesting and longest text of a translated CPT expression.
const MAX_DEPTH: usize = 64;
const MAX_TEXT: usize = 8192;

/// A CPT expression in AuroraLD's language (QScript's, Table 8; names are
/// case-sensitive), as an Alba CPT expression (docs/ladder.md §4.7).
fn qscript(src: &str, ctx: &Ctx<'_>, notes: &mut Notes, at: &Location) -> Result<String, String> {
    let toks = tokens(src)?;
    let mut p = Parser {
        toks,
        pos: 0,
        ctx,
        notes: Vec::new(),
        at,
    };
    let e = p.expr(0)?;
    if let Some(t) = p.toks.get(p.pos) {
        return Err(format!("CPT `{}`: `{}` is not expected here", clip(src), t.text()));
    }
    if e.len > MAX_TEXT {
        return Err(format!(
            "CPT `{}`: the expression is too long once translated",
            clip(src)
        ));
    }
    notes.extend(p.notes);
    let mut out = String::new();
    e.emit(0, false, &mut out);
    Ok(out)
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(String),
    Id(String),
    Op(char),
}

impl Tok {
    fn text(&self) -> String {
        match self {
            Tok::Num(s) | Tok::Id(s) => s.clone(),
            Tok::Op(c) => c.to_string(),
        }
    }
}

fn tokens(src: &str) -> Result<Vec<Tok>, String> {
    let b: Vec<char> = src.chars().collect();
    let mut v = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || (c == '.' && b.get(i + 1).is_some_and(char::is_ascii_digit)) {
            let s = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == '.') {
                i += 1;
            }
            if i < b.len() && (b[i] == 'e' || b[i] == 'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == '+' || b[j] == '-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    i = j;
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let n: String = b[s..i].iter().collect();
            if n.parse::<f64>().is_err() {
                return Err(format!("CPT: `{n}` is not a number"));
            }
            v.push(Tok::Num(n));
        } else if c.is_alphabetic() || c == '_' {
            let s = i;
            while i < b.len() && (b[i].is_alphanumeric() || b[i] == '_' || b[i] == '.') {
                i += 1;
            }
            v.push(Tok::Id(b[s..i].iter().collect()));
        } else if "+-*/^(),".contains(c) {
            v.push(Tok::Op(c));
            i += 1;
        } else {
            return Err(format!("CPT: `{c}` is not part of AuroraLD's expressions (Table 8)"));
        }
    }
    Ok(v)
}

/// An expression tree, with the length of its text (saturating), so that a
/// duplicated argument (`cosh`) cannot blow up.
#[derive(Debug, Clone)]
struct E {
    node: Node,
    len: usize,
}

#[derive(Debug, Clone)]
enum Node {
    Leaf(String),
    Neg(Box<E>),
    Bin(&'static str, Box<E>, Box<E>),
    Call(&'static str, Vec<E>),
}

fn prec(op: &str) -> u8 {
    match op {
        ">" | "<" => 4,
        "+" | "-" => 5,
        "*" | "/" => 6,
        _ => 8,
    }
}

impl E {
    fn leaf(s: String) -> E {
        E {
            len: s.len(),
            node: Node::Leaf(s),
        }
    }
    fn neg(a: E) -> E {
        E {
            len: a.len.saturating_add(3),
            node: Node::Neg(Box::new(a)),
        }
    }
    fn bin(op: &'static str, a: E, b: E) -> E {
        E {
            len: a.len.saturating_add(b.len).saturating_add(5),
            node: Node::Bin(op, Box::new(a), Box::new(b)),
        }
    }
    fn call(f: &'static str, args: Vec<E>) -> E {
        let len = args
            .iter()
            .fold(f.len() + 2, |n, a| n.saturating_add(a.len).saturating_add(1));
        E {
            len,
            node: Node::Call(f, args),
        }
    }

    /// Writes the expression with the brackets Alba's precedence needs.
    fn emit(&self, parent: u8, right: bool, out: &mut String) {
        match &self.node {
            Node::Leaf(s) => out.push_str(s),
            Node::Call(f, args) => {
                out.push_str(f);
                out.push('(');
                for (k, a) in args.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    a.emit(0, false, out);
                }
                out.push(')');
            }
            Node::Neg(a) => {
                // `-x` as a right operand is bracketed: `A*(-B)`, `E^(-A)`.
                let paren = parent > 7 || (right && parent > 0);
                if paren {
                    out.push('(');
                }
                out.push('-');
                a.emit(7, true, out);
                if paren {
                    out.push(')');
                }
            }
            Node::Bin(op, a, b) => {
                let p = prec(op);
                let paren = p < parent || (p == parent && (right != (*op == "^")));
                if paren {
                    out.push('(');
                }
                a.emit(p, false, out);
                out.push_str(op);
                b.emit(p, true, out);
                if paren {
                    out.push(')');
                }
            }
        }
    }
}

struct Parser<'a, 'c> {
    toks: Vec<Tok>,
    pos: usize,
    ctx: &'a Ctx<'c>,
    notes: Notes,
    at: &'a Location,
}

impl Parser<'_, '_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }

    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(&Tok::Op(c)) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    fn deep(depth: usize) -> Result<(), String> {
        if depth > MAX_DEPTH {
            Err(format!("CPT: the expression nests deeper than {MAX_DEPTH} levels"))
        } else {
            Ok(())
        }
    }

    /// One left-associative level: `next { op next }` for the two operators of `ops`.
    fn left(
        &mut self,
        depth: usize,
        ops: [&'static str; 2],
        next: fn(&mut Self, usize) -> Result<E, String>,
    ) -> Result<E, String> {
        Self::deep(depth)?;
        let mut a = next(self, depth + 1)?;
        while let Some(op) = ops
            .into_iter()
            .find(|op| op.chars().next().is_some_and(|c| self.eat(c)))
        {
            let b = next(self, depth + 1)?;
            a = E::bin(op, a, b);
        }
        Ok(a)
    }

    /// sum := product { (+|-) product }
    fn expr(&mut self, depth: usize) -> Result<E, String> {
        self.left(depth, ["+", "-"], Self::product)
    }

    /// product := unary { (*|/) unary }
    fn product(&mut self, depth: usize) -> Result<E, String> {
        self.left(depth, ["*", "/"], Self::unary)
    }

    /// unary := - unary | + unary | power
    fn unary(&mut self, depth: usize) -> Result<E, String> {
        Self::deep(depth)?;
        if self.eat('-') {
            return Ok(E::neg(self.unary(depth + 1)?));
        }
        if self.eat('+') {
            return self.unary(depth + 1);
        }
        self.power(depth + 1)
    }

    /// power := primary [ ^ unary ]   (right-associative)
    fn power(&mut self, depth: usize) -> Result<E, String> {
        Self::deep(depth)?;
        let a = self.primary(depth + 1)?;
        if self.eat('^') {
            let b = self.unary(depth + 1)?;
            return Ok(E::bin("^", a, b));
        }
        Ok(a)
    }

    fn primary(&mut self, depth: usize) -> Result<E, String> {
        Self::deep(depth)?;
        match self.peek().cloned() {
            Some(Tok::Num(n)) => {
                self.pos += 1;
                Ok(E::leaf(n))
            }
            Some(Tok::Op('(')) => {
                self.pos += 1;
                let e = self.expr(depth + 1)?;
                if !self.eat(')') {
                    return Err("CPT: a `(` is not closed".into());
                }
                Ok(e)
            }
            Some(Tok::Id(name)) => {
                self.pos += 1;
                if self.eat('(') {
                    let mut args = Vec::new();
                    if !self.eat(')') {
                        loop {
                            args.push(self.expr(depth + 1)?);
                            if self.eat(')') {
                                break;
                            }
                            if !self.eat(',') {
                                return Err(format!("CPT: `{name}(`: `,` or `)` expected"));
                            }
                        }
                    }
                    return self.function(&name, args);
                }
                match name.as_str() {
                    "E" | "PI" => Ok(E::leaf(name)),
                    _ => Ok(E::leaf(self.ctx.number(&name, &mut self.notes, self.at)?)),
                }
            }
            Some(t) => Err(format!("CPT: `{}` where a value is expected", t.text())),
            None => Err("CPT: the expression ends where a value is expected".into()),
        }
    }

    /// QScript's functions (Table 8; case-sensitive) in Alba's.
    fn function(&mut self, name: &str, mut args: Vec<E>) -> Result<E, String> {
        let want = |n: usize, args: &Vec<E>| {
            if args.len() == n {
                Ok(())
            } else {
                Err(format!("CPT: {name} takes {n} argument(s), not {}", args.len()))
            }
        };
        let one = |f: &'static str, args: Vec<E>| -> Result<E, String> {
            want(1, &args)?;
            Ok(E::call(f, args))
        };
        let exp = |a: &E, neg: bool| {
            let x = if neg { E::neg(a.clone()) } else { a.clone() };
            E::bin("^", E::leaf("E".into()), x)
        };
        match name {
            "abs" => one("ABS", args),
            "Int" => one("TRN", args),
            "log10" => one("LOG", args),
            "logE" => one("LN", args),
            "sqrt" => {
                self.notes.push((
                    Kind::Approximated,
                    self.at.clone(),
                    "CPT sqrt: of a negative number QScript gives 0, Alba the root of its absolute value".into(),
                ));
                one("SQRT", args)
            }
            "round" => {
                self.notes.push((
                    Kind::Approximated,
                    self.at.clone(),
                    "CPT round: QScript rounds halves up (Java's Math.round), Alba to even".into(),
                ));
                one("ROUND", args)
            }
            "acos" => one("ACS", args),
            "asin" => one("ASN", args),
            "atan" => one("ATN", args),
            "cos" => one("COS", args),
            "sin" => one("SIN", args),
            "tan" => one("TAN", args),
            "radians" => one("RAD", args),
            "degrees" => one("DEG", args),
            "atan2" => {
                want(2, &args)?;
                Ok(E::call("ATAN2", args))
            }
            "log" => {
                want(2, &args)?;
                let b = args.pop().map(|b| E::call("LN", vec![b]));
                let a = args.pop().map(|a| E::call("LN", vec![a]));
                match (a, b) {
                    (Some(a), Some(b)) => Ok(E::bin("/", a, b)),
                    _ => Err("CPT: log takes 2 arguments".into()),
                }
            }
            "signum" => {
                want(1, &args)?;
                let a = args.pop().unwrap_or_else(|| E::leaf("0".into()));
                let pos = E::bin(">", a.clone(), E::leaf("0".into()));
                let neg = E::bin("<", a, E::leaf("0".into()));
                // A call without a name is a bracketed expression.
                Ok(E::bin("-", E::call("", vec![pos]), E::call("", vec![neg])))
            }
            "cosh" | "sinh" | "tanh" => {
                want(1, &args)?;
                let a = args.pop().unwrap_or_else(|| E::leaf("0".into()));
                let sum = E::bin("+", exp(&a, false), exp(&a, true));
                let diff = E::bin("-", exp(&a, false), exp(&a, true));
                Ok(match name {
                    "cosh" => E::bin("/", sum, E::leaf("2".into())),
                    "sinh" => E::bin("/", diff, E::leaf("2".into())),
                    _ => E::bin("/", diff, sum),
                })
            }
            // Alba's CPT has AuroraLD's generator (docs/ladder.md, CPT).
            "rnd" => {
                want(2, &args)?;
                Ok(E::call("rnd", args))
            }
            _ => Err(format!(
                "CPT: `{name}` is not one of AuroraLD's functions (Table 8; they are case-sensitive)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tags() -> Tags {
        let mut t = Tags::default();
        for (n, ty) in [("A", Ty::Int), ("B", Ty::Real), ("T1", Ty::Timer), ("Run", Ty::Bool)] {
            t.map.insert(n.into(), super::super::Sym { alba: n.into(), ty });
        }
        t
    }

    fn cpt(src: &str) -> Result<String, String> {
        let t = tags();
        let ctx = Ctx {
            tags: &t,
            time_base: HashMap::new(),
            counting: HashMap::new(),
            timers: HashMap::new(),
            structs: Structs::default(),
        };
        let mut notes = Vec::new();
        qscript(src, &ctx, &mut notes, &Location::new("i", 1, 1))
    }

    #[test]
    fn qscript_translates_with_alba_precedence() {
        assert_eq!(cpt("A + B * 2").as_deref(), Ok("A+B*2"));
        assert_eq!(cpt("(A + B) * 2").as_deref(), Ok("(A+B)*2"));
        assert_eq!(cpt("A - (B - 1)").as_deref(), Ok("A-(B-1)"));
        assert_eq!(cpt("2^3^2").as_deref(), Ok("2^3^2"));
        assert_eq!(cpt("(2^3)^2").as_deref(), Ok("(2^3)^2"));
        assert_eq!(cpt("-A^2").as_deref(), Ok("-A^2"));
        assert_eq!(cpt("(-A)^2").as_deref(), Ok("(-A)^2"));
        assert_eq!(
            cpt("sqrt(abs(A)) + log(A, 2)").as_deref(),
            Ok("SQRT(ABS(A))+LN(A)/LN(2)")
        );
        assert_eq!(cpt("signum(B)").as_deref(), Ok("(B>0)-(B<0)"));
        assert_eq!(cpt("cosh(A)").as_deref(), Ok("(E^A+E^(-A))/2"));
        assert_eq!(cpt("A * -B - -1").as_deref(), Ok("A*(-B)-(-1)"));
        assert_eq!(cpt("T1.ACC / 1000 + PI").as_deref(), Ok("T1.ACC/1000+PI"));
        assert_eq!(cpt("atan2(B, A) * degrees(1)").as_deref(), Ok("ATAN2(B,A)*DEG(1)"));
        assert_eq!(cpt("rnd(0, A) + 1").as_deref(), Ok("rnd(0,A)+1"));
        assert!(cpt("rnd(1)").unwrap_err().contains("takes 2 argument"));
    }

    #[test]
    fn qscript_refuses_what_alba_lacks() {
        assert!(cpt("SQRT(A)").unwrap_err().contains("case-sensitive"));
        assert!(cpt("Run + 1").unwrap_err().contains("Bool"));
        assert!(cpt("A $ 2").unwrap_err().contains("`$`"));
        assert!(cpt("(A").unwrap_err().contains("not closed"));
        let deep = format!("{}A{}", "(".repeat(100), ")".repeat(100));
        assert!(cpt(&deep).unwrap_err().contains("deeper"));
        let blow = format!("{}A{}", "cosh(".repeat(10), ")".repeat(10));
        assert!(cpt(&blow).unwrap_err().contains("too long"));
    }

    #[test]
    fn literals_keep_integers_integral() {
        assert_eq!(lit(12.0), "12");
        assert_eq!(lit(-3.0), "-3");
        assert_eq!(lit(2.5), "2.5");
        assert_eq!(lit(1.0e20), "1e20");
    }
}
