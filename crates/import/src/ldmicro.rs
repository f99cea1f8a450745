//! LDmicro `.ld` files (`LDmicro0.1` and `LDmicro0.2`).
//!
//! The file is a header (`MICRO=`, `CYCLE=` …), an optional `VAR LIST`, an
//! `IO LIST` (`Xname at PIN`), and `PROGRAM`: rungs `RUNG … END` whose
//! lines are elements in series, `PARALLEL … END` blocks of elements and
//! `SERIES … END` blocks in parallel. LDmicro passes power through each
//! element; timers, counters and one-shots *replace* the power with their
//! own output, which Alba's instructions do not (they pass the rung on), so
//! the conversion goes through [`crate::circuit`]: each element becomes one
//! Alba rung driven by the condition in front of it, and the output of a
//! timer is `XIC(T.DN)`.
//!
//! Semantics followed are those of LDmicro's `intcode.cpp` (the classic
//! Westhues behaviour, which LDmicro 4/5 keeps for `LDmicro0.1` files):
//! timers count scan cycles (`delay / CYCLE` cycles, one less for 0.1
//! files), counters count rising edges with `count >= max` as output, CTC
//! wraps from max to its initial value and gives a one-scan pulse then,
//! OSR/OSF are one-scan edges, `RES` sets a counter back to its initial
//! value and a timer or variable to 0. See docs/interchange.md.

use crate::circuit::{Cond, Emitter, Structs};
use crate::names::Names;
use crate::{BoardOut, Error, Kind, Location, Options, ProgramOut, Project, Report, TagOut};
use alba_model::board::{Dir, Model, Pin, PinMap};
use std::collections::HashMap;

const MAX_DEPTH: usize = 64;
/// Elements in one rung (LDmicro's editor allows far fewer).
const MAX_RUNG_ELEMENTS: usize = 4096;

#[derive(Debug, Clone)]
struct Line<'a> {
    no: u32,
    col: u32,
    text: &'a str,
}

#[derive(Debug, Clone)]
enum Elem {
    Leaf(Leaf, Location),
    Series(Vec<Elem>),
    Parallel(Vec<Elem>),
}

#[derive(Debug, Clone)]
enum Arg {
    Lit(i64),
    Var(String),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum CounterKind {
    Up,
    Down,
    Circular,
}

#[derive(Debug, Clone)]
enum Leaf {
    Comment(String),
    Contact {
        name: String,
        negated: bool,
    },
    Coil {
        name: String,
        negated: bool,
        set: bool,
        reset: bool,
        toggle: bool,
    },
    Short,
    Open,
    Timer {
        kind: &'static str,
        name: String,
        delay: Arg,
        adjust: i64,
    },
    Counter {
        kind: CounterKind,
        name: String,
        max: Arg,
        init: Arg,
        input_kind: char,
    },
    Res {
        name: String,
    },
    OneShot {
        falling: bool,
    },
    Move {
        dest: String,
        src: Arg,
    },
    Math {
        op: &'static str,
        dest: String,
        a: Arg,
        b: Arg,
    },
    Unary {
        op: &'static str,
        dest: String,
        a: Arg,
    },
    Cmp {
        op: &'static str,
        a: Arg,
        b: Arg,
    },
    ReadAdc {
        name: String,
    },
    /// A real LDmicro element that Alba does not convert.
    Unsupported(String),
}

#[derive(Debug)]
struct IoEntry {
    name: String,
    pin: u32,
    loc: Location,
}

#[derive(Debug)]
struct Rung {
    elems: Vec<Elem>,
    loc: Location,
}

/// Every element LDmicro writes that Alba does not convert (refused with
/// its place), so an unknown word is told apart from a known one.
const UNSUPPORTED: &[&str] = &[
    "MASTER_RELAY",
    "SHIFT_REGISTER",
    "LOOK_UP_TABLE",
    "PIECEWISE_LINEAR",
    "FORMATTED_STRING",
    "STRING",
    "PERSIST",
    "SET_PWM",
    "RANDOM",
    "SEED_RANDOM",
    "UART_SEND",
    "UART_RECV",
    "UART_SEND_READY",
    "UART_SEND_BUSY",
    "UART_RECV_AVAIL",
    "UART_UDRE",
    "GOTO",
    "GOSUB",
    "RETURN",
    "LABEL",
    "SUBPROG",
    "ENDSUB",
    "DELAY",
    "SLEEP",
    "CLRWDT",
    "LOCK",
    "BIN2BCD",
    "BCD2BIN",
    "SWAP",
    "OPPOSITE",
    "BUS",
    "SPI",
    "SPI_WR",
    "I2C_RD",
    "I2C_WR",
    "7SEGMENTS",
    "9SEGMENTS",
    "14SEGMENTS",
    "16SEGMENTS",
    "STEPPER",
    "PULSER",
    "NPULSE",
    "NPULSE_OFF",
    "QUAD_ENCOD",
    "SHL",
    "SHR",
    "SR0",
    "ROL",
    "ROR",
    "SET_BIT",
    "CLEAR_BIT",
    "IF_BIT_SET",
    "IF_BIT_CLEAR",
    "RTL",
    "TCY",
    "THI",
    "TLO",
    "TIME2COUNT",
    "TIME2DELAY",
    "CTR",
    "OSL",
    "ODF",
    "ODR",
    "OSC",
    "PLACEHOLDER",
    "RSFR",
    "WSFR",
    "SSFR",
    "CSFR",
    "TSFR",
    "TCSFR",
];

struct Parser<'a> {
    file: &'a str,
    lines: Vec<Line<'a>>,
    pos: usize,
    version: &'a str,
}

fn split_lines(text: &str) -> Vec<Line<'_>> {
    let mut out = Vec::new();
    for (i, raw) in text.split('\n').enumerate() {
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = raw.trim_start();
        let col = raw.len() - trimmed.len();
        let col = raw[..col].chars().count() as u32 + 1;
        let text = trimmed.trim_end();
        out.push(Line {
            no: u32::try_from(i + 1).unwrap_or(u32::MAX),
            col,
            text,
        });
    }
    out
}

impl<'a> Parser<'a> {
    fn loc(&self, l: &Line<'_>) -> Location {
        Location::new(self.file, l.no, l.col)
    }

    fn eof_loc(&self) -> Location {
        let (no, col) = self
            .lines
            .last()
            .map(|l| (l.no, l.col + l.text.chars().count() as u32))
            .unwrap_or((1, 1));
        Location::new(self.file, no, col)
    }

    /// The next non-blank line that is not a `;` comment.
    fn next(&mut self) -> Option<Line<'a>> {
        while self.pos < self.lines.len() {
            let l = self.lines[self.pos].clone();
            self.pos += 1;
            if l.text.is_empty() || l.text.starts_with(';') {
                continue;
            }
            return Some(l);
        }
        None
    }

    fn check_depth(&self, open: &Line<'_>, depth: usize) -> Result<(), Error> {
        if depth > MAX_DEPTH {
            return Err(Error::at(
                self.loc(open),
                format!("circuits nested deeper than {MAX_DEPTH} levels"),
            ));
        }
        Ok(())
    }

    fn series(&mut self, open: &Line<'_>, what: &str, depth: usize) -> Result<Vec<Elem>, Error> {
        self.check_depth(open, depth)?;
        let mut elems = Vec::new();
        loop {
            let Some(l) = self.next() else {
                return Err(Error::at(
                    self.eof_loc(),
                    format!(
                        "the file ends inside the {what} opened at line {}: `END` expected",
                        open.no
                    ),
                ));
            };
            match l.text {
                "END" => return Ok(elems),
                "PARALLEL" => elems.push(Elem::Parallel(self.parallel(&l, depth + 1)?)),
                "SERIES" => {
                    return Err(Error::at(
                        self.loc(&l),
                        "`SERIES` directly inside a series (only inside PARALLEL)",
                    ));
                }
                _ => elems.push(Elem::Leaf(self.leaf(&l)?, self.loc(&l))),
            }
        }
    }

    fn parallel(&mut self, open: &Line<'_>, depth: usize) -> Result<Vec<Elem>, Error> {
        self.check_depth(open, depth)?;
        let mut elems = Vec::new();
        loop {
            let Some(l) = self.next() else {
                return Err(Error::at(
                    self.eof_loc(),
                    format!(
                        "the file ends inside the PARALLEL opened at line {}: `END` expected",
                        open.no
                    ),
                ));
            };
            match l.text {
                "END" => {
                    if elems.is_empty() {
                        return Err(Error::at(self.loc(&l), "an empty PARALLEL"));
                    }
                    return Ok(elems);
                }
                "SERIES" => elems.push(Elem::Series(self.series(&l, "SERIES", depth + 1)?)),
                "PARALLEL" => {
                    return Err(Error::at(
                        self.loc(&l),
                        "`PARALLEL` directly inside a PARALLEL (only inside SERIES)",
                    ));
                }
                _ => elems.push(Elem::Leaf(self.leaf(&l)?, self.loc(&l))),
            }
        }
    }

    fn leaf(&self, l: &Line<'_>) -> Result<Leaf, Error> {
        let words: Vec<&str> = l.text.split_whitespace().collect();
        let Some(&kw) = words.first() else {
            return Err(Error::at(self.loc(l), "empty element"));
        };
        let args = &words[1..];
        // Column of argument `i` (for messages).
        let arg_loc = |i: usize| -> Location {
            let mut col = l.col;
            let mut rest = l.text;
            for _ in 0..=i {
                let skip = rest.len() - rest.trim_start().len();
                col += rest[..skip].chars().count() as u32;
                rest = &rest[skip..];
                let w = rest.split_whitespace().next().unwrap_or("");
                col += w.chars().count() as u32;
                rest = &rest[w.len()..];
            }
            let skip = rest.len() - rest.trim_start().len();
            col += rest[..skip].chars().count() as u32;
            Location::new(self.file, l.no, col)
        };
        let need = |n: usize, max: usize, form: &str| -> Result<(), Error> {
            if args.len() < n || args.len() > max {
                Err(Error::at(
                    self.loc(l),
                    format!("`{kw}` takes {form}; found {} operand(s)", args.len()),
                ))
            } else {
                Ok(())
            }
        };
        let name = |i: usize| -> Result<String, Error> {
            let w = args.get(i).copied().unwrap_or("");
            if is_name(w) {
                Ok(w.to_string())
            } else {
                Err(Error::at(arg_loc(i), format!("`{w}` is not a name")))
            }
        };
        let arg = |i: usize| -> Result<Arg, Error> {
            let w = args.get(i).copied().unwrap_or("");
            parse_arg(w).ok_or_else(|| Error::at(arg_loc(i), format!("`{w}` is neither a number nor a name")))
        };
        let flag = |i: usize| -> Result<bool, Error> {
            match args.get(i).copied() {
                None => Ok(false),
                Some(w) => match w.parse::<i64>() {
                    Ok(v) => Ok(v != 0),
                    Err(_) => Err(Error::at(arg_loc(i), format!("`{w}` is not 0 or 1"))),
                },
            }
        };
        Ok(match kw {
            "COMMENT" => {
                let rest = l.text.strip_prefix("COMMENT").unwrap_or("");
                Leaf::Comment(unescape(rest.strip_prefix(' ').unwrap_or(rest)))
            }
            "CONTACTS" => {
                need(2, 3, "a name and a negated flag")?;
                Leaf::Contact {
                    name: name(0)?,
                    negated: flag(1)?,
                }
            }
            "COIL" => {
                need(4, 5, "a name and the negated, set-only and reset-only flags")?;
                Leaf::Coil {
                    name: name(0)?,
                    negated: flag(1)?,
                    set: flag(2)?,
                    reset: flag(3)?,
                    toggle: flag(4)?,
                }
            }
            "SHORT" => Leaf::Short,
            "OPEN" => Leaf::Open,
            "TON" | "TOF" | "RTO" => {
                need(2, 3, "a name, a delay in µs and an optional adjustment")?;
                let adjust = match args.get(2) {
                    Some(w) => w
                        .parse::<i64>()
                        .map_err(|_| Error::at(arg_loc(2), format!("`{w}` is not a number")))?,
                    None if self.version == "0.1" => -1,
                    None => 0,
                };
                Leaf::Timer {
                    kind: match kw {
                        "TON" => "TON",
                        "TOF" => "TOF",
                        _ => "RTO",
                    },
                    name: name(0)?,
                    delay: arg(1)?,
                    adjust,
                }
            }
            "CTU" | "CTD" | "CTC" => {
                need(2, 4, "a name, a limit, an optional initial value and input kind")?;
                let input_kind = match args.get(3) {
                    None => '/',
                    Some(w) => {
                        let mut cs = w.chars();
                        match (cs.next(), cs.next()) {
                            (Some(c @ ('/' | '\\' | '-' | 'o')), None) => c,
                            _ => return Err(Error::at(arg_loc(3), format!("`{w}` is not an input kind (/ \\ - o)"))),
                        }
                    }
                };
                Leaf::Counter {
                    kind: match kw {
                        "CTU" => CounterKind::Up,
                        "CTD" => CounterKind::Down,
                        _ => CounterKind::Circular,
                    },
                    name: name(0)?,
                    max: arg(1)?,
                    init: if args.len() > 2 { arg(2)? } else { Arg::Lit(0) },
                    input_kind,
                }
            }
            "RES" => {
                need(1, 1, "one name")?;
                Leaf::Res { name: name(0)? }
            }
            "OSR" | "OSF" if args.is_empty() => Leaf::OneShot { falling: kw == "OSF" },
            "MOVE" => {
                need(2, 2, "a destination and a source")?;
                Leaf::Move {
                    dest: name(0)?,
                    src: arg(1)?,
                }
            }
            "ADD" | "SUB" | "MUL" | "DIV" | "MOD" | "AND" | "OR" | "XOR" => {
                need(3, 3, "a destination and two operands")?;
                Leaf::Math {
                    op: match kw {
                        "ADD" => "ADD",
                        "SUB" => "SUB",
                        "MUL" => "MUL",
                        "DIV" => "DIV",
                        "MOD" => "MOD",
                        "AND" => "AND",
                        "OR" => "OR",
                        _ => "XOR",
                    },
                    dest: name(0)?,
                    a: arg(1)?,
                    b: arg(2)?,
                }
            }
            "NOT" | "NEG" => {
                need(2, 2, "a destination and an operand")?;
                Leaf::Unary {
                    op: if kw == "NOT" { "NOT" } else { "NEG" },
                    dest: name(0)?,
                    a: arg(1)?,
                }
            }
            "EQU" | "NEQ" | "GRT" | "GEQ" | "LES" | "LEQ" => {
                need(2, 2, "two operands")?;
                Leaf::Cmp {
                    op: match kw {
                        "EQU" => "EQU",
                        "NEQ" => "NEQ",
                        "GRT" => "GRT",
                        "GEQ" => "GEQ",
                        "LES" => "LES",
                        _ => "LEQ",
                    },
                    a: arg(0)?,
                    b: arg(1)?,
                }
            }
            "READ_ADC" => {
                need(1, 2, "an ADC name")?;
                Leaf::ReadAdc { name: name(0)? }
            }
            k if UNSUPPORTED.contains(&k) || (k == "OSR" || k == "OSF") => Leaf::Unsupported(k.to_string()),
            k => {
                return Err(Error::at(self.loc(l), format!("unknown LDmicro element `{k}`")));
            }
        })
    }
}

fn is_name(w: &str) -> bool {
    let mut cs = w.chars();
    cs.next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '$' || c == '#')
        && cs.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$' || c == '#')
}

fn parse_arg(w: &str) -> Option<Arg> {
    if is_name(w) {
        return Some(Arg::Var(w.to_string()));
    }
    let (neg, digits) = match w.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, w.strip_prefix('+').unwrap_or(w)),
    };
    let v = if let Some(h) = digits.strip_prefix("0x").or_else(|| digits.strip_prefix("0X")) {
        i64::from_str_radix(h, 16).ok()?
    } else if let Some(b) = digits.strip_prefix("0b").or_else(|| digits.strip_prefix("0B")) {
        i64::from_str_radix(b, 2).ok()?
    } else if digits.len() == 3 && digits.starts_with('\'') && digits.ends_with('\'') {
        digits.chars().nth(1)? as i64
    } else if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        digits.parse::<i64>().ok()?
    } else {
        return None;
    };
    if v > i64::from(i32::MAX) {
        return None;
    }
    Some(Arg::Lit(if neg { -v } else { v }))
}

/// LDmicro's escapes in comments: `\r\n` (as two characters each), `\\`.
fn unescape(s: &str) -> String {
    let mut out = String::new();
    let mut cs = s.chars().peekable();
    while let Some(c) = cs.next() {
        if c == '\\' {
            match cs.next() {
                Some('n') => out.push('\n'),
                Some('r') => {}
                Some('\\') => out.push('\\'),
                Some('t') => out.push(' '),
                Some(o) => {
                    out.push('\\');
                    out.push(o);
                }
                None => out.push('\\'),
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The leading integer of a header value (`10000 us at Timer1` → 10000).
fn leading_int(s: &str) -> Option<i64> {
    let digits: String = s.trim().chars().take_while(|c| c.is_ascii_digit()).collect();
    digits.parse().ok()
}

struct Parsed {
    micro: Option<(String, Location)>,
    cycle_us: Option<(i64, Location)>,
    var_sizes: HashMap<String, u32>,
    io: Vec<IoEntry>,
    rungs: Vec<Rung>,
}

fn parse(file: &str, text: &str) -> Result<Parsed, Error> {
    let lines = split_lines(text);
    let first = lines.iter().find(|l| !l.text.is_empty()).cloned();
    let version = match &first {
        Some(l) if l.text == "LDmicro0.1" => "0.1",
        Some(l) if l.text == "LDmicro0.2" => "0.2",
        Some(l) if l.text.starts_with("LDmicro") => {
            return Err(Error::at(
                Location::new(file, l.no, l.col),
                format!("`{}`: only LDmicro0.1 and LDmicro0.2 files are read", l.text),
            ));
        }
        Some(l) => {
            return Err(Error::at(
                Location::new(file, l.no, l.col),
                "not an LDmicro file: the first line must be `LDmicro0.1` or `LDmicro0.2`",
            ));
        }
        None => return Err(Error::at(Location::new(file, 1, 1), "the file is empty")),
    };
    let mut p = Parser {
        file,
        pos: first.as_ref().map(|l| l.no as usize).unwrap_or(1),
        lines,
        version,
    };
    let mut parsed = Parsed {
        micro: None,
        cycle_us: None,
        var_sizes: HashMap::new(),
        io: Vec::new(),
        rungs: Vec::new(),
    };
    // Header and lists, up to PROGRAM.
    loop {
        let Some(l) = p.next() else {
            return Err(Error::at(p.eof_loc(), "no `PROGRAM` section"));
        };
        match l.text {
            "PROGRAM" => break,
            "IO LIST" => loop {
                let Some(e) = p.next() else {
                    return Err(Error::at(
                        p.eof_loc(),
                        format!("the IO LIST of line {} has no `END`", l.no),
                    ));
                };
                if e.text == "END" {
                    break;
                }
                let w: Vec<&str> = e.text.split_whitespace().collect();
                let ok = w.len() >= 3 && w[1] == "at" && is_name(w[0]);
                let pin = w.get(2).and_then(|s| s.parse::<u32>().ok());
                match (ok, pin) {
                    (true, Some(pin)) => parsed.io.push(IoEntry {
                        name: w[0].to_string(),
                        pin,
                        loc: p.loc(&e),
                    }),
                    _ => {
                        return Err(Error::at(p.loc(&e), format!("`{}` is not `NAME at PIN`", e.text)));
                    }
                }
            },
            "VAR LIST" => loop {
                let Some(e) = p.next() else {
                    return Err(Error::at(
                        p.eof_loc(),
                        format!("the VAR LIST of line {} has no `END`", l.no),
                    ));
                };
                if e.text == "END" {
                    break;
                }
                let w: Vec<&str> = e.text.split_whitespace().collect();
                match (w.first().and_then(|s| s.parse::<u32>().ok()), w.get(1), w.get(2)) {
                    (Some(n), Some(&"bytes"), Some(name)) => {
                        parsed.var_sizes.insert((*name).to_string(), n);
                    }
                    _ => {
                        return Err(Error::at(p.loc(&e), format!("`{}` is not `N bytes NAME`", e.text)));
                    }
                }
            },
            t if t.starts_with("LDmicro") && l.no == first.as_ref().map(|f| f.no).unwrap_or(0) => {}
            t => match t.split_once('=') {
                Some((key, value)) if key.chars().all(|c| c.is_ascii_uppercase() || c == '_') => match key {
                    "MICRO" => parsed.micro = Some((value.trim().to_string(), p.loc(&l))),
                    "CYCLE" => match leading_int(value) {
                        Some(v) if v > 0 => parsed.cycle_us = Some((v, p.loc(&l))),
                        _ => {
                            return Err(Error::at(
                                p.loc(&l),
                                format!("`{t}`: the cycle time is not a number of µs"),
                            ));
                        }
                    },
                    _ => {}
                },
                _ => {
                    return Err(Error::at(
                        p.loc(&l),
                        format!("`{t}` is not a header line (`KEY=value`), a list or `PROGRAM`"),
                    ));
                }
            },
        }
    }
    // The program.
    while let Some(l) = p.next() {
        let w: Vec<&str> = l.text.split_whitespace().collect();
        if w.first() == Some(&"RUNG") && w.len() <= 2 {
            let elems = p.series(&l, "RUNG", 0)?;
            let mut leaves = 0usize;
            walk(&elems, &mut |_, _| leaves += 1);
            if leaves > MAX_RUNG_ELEMENTS {
                return Err(Error::at(
                    p.loc(&l),
                    format!("a rung of {leaves} elements (at most {MAX_RUNG_ELEMENTS})"),
                ));
            }
            parsed.rungs.push(Rung { elems, loc: p.loc(&l) });
        } else {
            return Err(Error::at(
                p.loc(&l),
                format!("`{}`: a rung must start with `RUNG`", l.text),
            ));
        }
    }
    Ok(parsed)
}

// ---------------------------------------------------------------------------
// Conversion.

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Use {
    Bit,
    Int,
    Timer,
    Counter,
}

struct Conv<'a> {
    file: &'a str,
    report: Report,
    names: Names,
    structs: Structs,
    uses: HashMap<String, Use>,
    /// Source name → Alba name.
    alba: HashMap<String, String>,
    counter_init: HashMap<String, i64>,
    helpers: Vec<(String, String)>,
    scan_ms: i64,
    cycle_us: i64,
    version: String,
    out_bytes: usize,
}

fn walk<'e>(elems: &'e [Elem], f: &mut dyn FnMut(&'e Leaf, &'e Location)) {
    for e in elems {
        match e {
            Elem::Leaf(l, loc) => f(l, loc),
            Elem::Series(v) | Elem::Parallel(v) => walk(v, f),
        }
    }
}

/// Why a rung is refused: where and what.
type Refusal = (Location, String);

impl Conv<'_> {
    fn name(&self, source: &str) -> String {
        self.alba.get(source).cloned().unwrap_or_else(|| source.to_string())
    }

    /// An operand as Alba text.
    fn operand(&mut self, a: &Arg, loc: &Location) -> Result<String, Refusal> {
        match a {
            Arg::Lit(v) => Ok(v.to_string()),
            Arg::Var(v) => self.var(v, loc),
        }
    }

    /// A variable as a number: counters and timers are their `.ACC`.
    fn var(&mut self, v: &str, loc: &Location) -> Result<String, Refusal> {
        if v.starts_with(['#', '$']) {
            return Err((
                loc.clone(),
                format!("`{v}`: LDmicro's special variables (ports, `$` names) have no Alba equivalent"),
            ));
        }
        let n = self.name(v);
        Ok(match self.uses.get(v) {
            Some(Use::Counter) => format!("{n}.ACC"),
            Some(Use::Timer) => {
                self.report.push(
                    Kind::Approximated,
                    loc.clone(),
                    format!(
                        "`{v}` as a number is the timer's `{n}.ACC` in ms; LDmicro counts scan cycles ({} ms each)",
                        self.scan_ms
                    ),
                );
                format!("{n}.ACC")
            }
            Some(Use::Bit) => {
                return Err((loc.clone(), format!("`{v}` is a bit and is used as a number")));
            }
            _ => n,
        })
    }

    fn reads(args: &[&String]) -> Vec<String> {
        args.iter()
            .filter(|a| a.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_'))
            .map(|a| (*a).clone())
            .collect()
    }

    fn elems(&mut self, e: &mut Emitter<'_>, elems: &[Elem], mut c: Cond) -> Result<Cond, Refusal> {
        for el in elems {
            c = self.elem(e, el, c)?;
        }
        Ok(c)
    }

    fn elem(&mut self, e: &mut Emitter<'_>, el: &Elem, c: Cond) -> Result<Cond, Refusal> {
        match el {
            Elem::Series(v) => self.elems(e, v, c),
            Elem::Parallel(v) => {
                let mut outs = Vec::new();
                for b in v {
                    outs.push(self.elem(e, b, c)?);
                }
                Ok(e.or(&outs))
            }
            Elem::Leaf(l, loc) => self.leaf(e, l, loc, c),
        }
    }

    fn leaf(&mut self, e: &mut Emitter<'_>, l: &Leaf, loc: &Location, c: Cond) -> Result<Cond, Refusal> {
        let refuse = |m: String| -> Result<Cond, Refusal> { Err((loc.clone(), m)) };
        match l {
            Leaf::Comment(_) => Ok(c),
            Leaf::Short => Ok(c),
            Leaf::Open => Ok(e.open()),
            Leaf::Contact { name, negated } => {
                let n = self.name(name);
                let frag = if *negated {
                    format!("XIO({n})")
                } else {
                    format!("XIC({n})")
                };
                Ok(e.and(c, &frag, std::slice::from_ref(&n)))
            }
            Leaf::Coil {
                name,
                negated,
                set,
                reset,
                toggle,
            } => {
                let n = self.name(name);
                let w = std::slice::from_ref(&n);
                if *toggle {
                    return refuse(format!("toggle coil `{name}` (T) has no Alba equivalent"));
                }
                if *negated {
                    e.emit(c, &format!("OTL({n})"), &format!("OTU({n})"), w);
                } else if *set {
                    e.emit(c, "", &format!("OTL({n})"), w);
                } else if *reset {
                    e.emit(c, "", &format!("OTU({n})"), w);
                } else {
                    e.emit(c, "", &format!("OTE({n})"), w);
                }
                Ok(c)
            }
            Leaf::Timer {
                kind,
                name,
                delay,
                adjust,
            } => {
                let Arg::Lit(delay) = delay else {
                    return refuse(format!("timer `{name}` has a variable delay; Alba needs a number"));
                };
                let cycles = delay / self.cycle_us + adjust;
                if cycles < 1 {
                    return refuse(format!(
                        "timer `{name}`: {delay} µs is less than one cycle of {} µs",
                        self.cycle_us
                    ));
                }
                let pre = cycles * self.scan_ms;
                let n = self.name(name);
                let args = match self.structs.timer(&n, pre) {
                    Ok(a) => a,
                    Err(m) => return refuse(m),
                };
                e.emit(c, "", &format!("{kind}({args})"), std::slice::from_ref(&n));
                let mut msg = format!(
                    "{kind} `{name}` {delay} µs: LDmicro counts {cycles} scan cycle(s) of {} µs{}; Alba's {kind} measures time: preset {pre} ms, the same scan at scan_ms = {}",
                    self.cycle_us,
                    if *adjust != 0 {
                        format!(
                            " (delay / cycle {adjust:+}, as LDmicro does for {} files)",
                            self.version
                        )
                    } else {
                        String::new()
                    },
                    self.scan_ms
                );
                if *kind == "TOF" {
                    msg.push_str("; it starts timed out (output off), as classic LDmicro's does (LDmicro 4/5 hold it on for the delay after a start)");
                }
                if *kind == "RTO" {
                    msg.push_str("; after the rung was false, Alba's RTO counts from the second true scan, LDmicro's from the first");
                }
                self.report.push(Kind::Approximated, loc.clone(), msg);
                let dn = format!("{n}.DN");
                Ok(e.input(&format!("XIC({dn})"), &[n]))
            }
            Leaf::Counter {
                kind,
                name,
                max,
                init,
                input_kind,
            } => {
                let Arg::Lit(max) = max else {
                    return refuse(format!("counter `{name}` has a variable limit; Alba needs a number"));
                };
                let Arg::Lit(init) = init else {
                    return refuse(format!(
                        "counter `{name}` has a variable initial value; Alba needs a number"
                    ));
                };
                if *input_kind != '/' {
                    return refuse(format!(
                        "counter `{name}` counts on `{input_kind}`; Alba's counters count rising edges (`/`) only"
                    ));
                }
                let n = self.name(name);
                let w = std::slice::from_ref(&n);
                match kind {
                    CounterKind::Up | CounterKind::Down => {
                        let (args, dn) = self.structs.counter(&n, *max, *init);
                        let m = if *kind == CounterKind::Up { "CTU" } else { "CTD" };
                        e.emit(c, "", &format!("{m}({args})"), w);
                        self.report.push(
                            Kind::Converted,
                            loc.clone(),
                            format!("{m} `{name}` {max}: {m}({args}), output `{n}.ACC >= {max}`"),
                        );
                        if dn {
                            Ok(e.input(&format!("XIC({n}.DN)"), w))
                        } else {
                            Ok(e.input(&format!("GEQ({n}.ACC,{max})"), w))
                        }
                    }
                    CounterKind::Circular => {
                        let (args, _) = self.structs.counter(&n, *max, *init);
                        e.emit(c, "", &format!("CTU({args})"), w);
                        let wrap = e.names().fresh(&format!("{n}_wrap"));
                        self.helpers
                            .push((wrap.clone(), format!("pulse of the circular counter {n} wrapping")));
                        let rail = e.rail();
                        e.emit(
                            rail,
                            "",
                            &format!("GRT({n}.ACC,{max})OTE({wrap})MOV({init},{n}.ACC)"),
                            &[wrap.clone(), n.clone()],
                        );
                        self.report.push(
                            Kind::Converted,
                            loc.clone(),
                            format!(
                                "CTC `{name}` 0..{max}: a CTU and a rung that puts {init} back above {max}; its output is the one-scan pulse `{wrap}`"
                            ),
                        );
                        Ok(e.input(&format!("XIC({wrap})"), &[wrap]))
                    }
                }
            }
            Leaf::Res { name } => {
                let n = self.name(name);
                let w = std::slice::from_ref(&n);
                match self.uses.get(name.as_str()) {
                    Some(Use::Timer) => e.emit(c, "", &format!("RES({n})"), w),
                    Some(Use::Counter) => {
                        let init = self.counter_init.get(name.as_str()).copied().unwrap_or(0);
                        e.emit(c, "", &format!("MOV({init},{n}.ACC)"), w);
                    }
                    Some(Use::Int) | None => e.emit(c, "", &format!("CLR({n})"), w),
                    Some(Use::Bit) => return refuse(format!("RES of the bit `{name}`")),
                }
                Ok(c)
            }
            Leaf::OneShot { falling } => {
                let store = e.names().fresh(if *falling { "osf_mem" } else { "osr_mem" });
                let out = e.names().fresh(if *falling { "osf_out" } else { "osr_out" });
                self.helpers.push((store.clone(), "one-shot memory".into()));
                self.helpers.push((out.clone(), "one-shot output".into()));
                let m = if *falling { "OSF" } else { "OSR" };
                e.emit(c, "", &format!("{m}({store},{out})"), &[store, out.clone()]);
                Ok(e.input(&format!("XIC({out})"), &[out]))
            }
            Leaf::Move { dest, src } => {
                let d = self.var(dest, loc)?;
                let s = self.operand(src, loc)?;
                e.emit(c, "", &format!("MOV({s},{d})"), std::slice::from_ref(&d));
                Ok(c)
            }
            Leaf::Math { op, dest, a, b } => {
                let d = self.var(dest, loc)?;
                let a = self.operand(a, loc)?;
                let b = self.operand(b, loc)?;
                e.emit(c, "", &format!("{op}({a},{b},{d})"), std::slice::from_ref(&d));
                Ok(c)
            }
            Leaf::Unary { op, dest, a } => {
                let d = self.var(dest, loc)?;
                let a = self.operand(a, loc)?;
                e.emit(c, "", &format!("{op}({a},{d})"), std::slice::from_ref(&d));
                Ok(c)
            }
            Leaf::Cmp { op, a, b } => {
                let a = self.operand(a, loc)?;
                let b = self.operand(b, loc)?;
                if !a.starts_with(|ch: char| ch.is_ascii_alphabetic() || ch == '_')
                    && !b.starts_with(|ch: char| ch.is_ascii_alphabetic() || ch == '_')
                {
                    return refuse(format!("{op} of two numbers"));
                }
                let r = Conv::reads(&[&a, &b]);
                Ok(e.and(c, &format!("{op}({a},{b})"), &r))
            }
            Leaf::ReadAdc { name } => {
                self.report.push(
                    Kind::Converted,
                    loc.clone(),
                    format!(
                        "READ_ADC `{name}`: nothing to write, Alba reads its analog inputs into `{}` every scan",
                        self.name(name)
                    ),
                );
                Ok(c)
            }
            Leaf::Unsupported(k) if k == "MASTER_RELAY" => {
                refuse("LDmicro's MASTER_RELAY has no Alba conversion (the rungs it governs run unconditioned)".into())
            }
            Leaf::Unsupported(k) => refuse(format!("LDmicro's {k} has no Alba conversion")),
        }
    }
}

/// Pins of a 28-pin ATmega328P/168/88/48/8 (DIP) by package pin: the
/// Arduino Uno's and Nano's microcontroller.
fn atmega328_pin(pin: u32) -> Option<Pin> {
    Some(match pin {
        2 => Pin::D(0),
        3 => Pin::D(1),
        4 => Pin::D(2),
        5 => Pin::D(3),
        6 => Pin::D(4),
        11 => Pin::D(5),
        12 => Pin::D(6),
        13 => Pin::D(7),
        14..=19 => Pin::D(u8::try_from(pin - 6).ok()?),
        23..=28 => Pin::A(u8::try_from(pin - 23).ok()?),
        _ => return None,
    })
}

/// Pins of the ATmega2560 (100-TQFP) by package pin: the Arduino Mega's.
fn atmega2560_pin(pin: u32) -> Option<Pin> {
    const D: &[(u32, u8)] = &[
        (1, 4),
        (2, 0),
        (3, 1),
        (5, 5),
        (6, 2),
        (7, 3),
        (12, 17),
        (13, 16),
        (15, 6),
        (16, 7),
        (17, 8),
        (18, 9),
        (19, 53),
        (20, 52),
        (21, 51),
        (22, 50),
        (23, 10),
        (24, 11),
        (25, 12),
        (26, 13),
        (35, 49),
        (36, 48),
        (37, 47),
        (38, 46),
        (39, 45),
        (40, 44),
        (41, 43),
        (42, 42),
        (43, 21),
        (44, 20),
        (45, 19),
        (46, 18),
        (50, 38),
        (51, 41),
        (52, 40),
        (53, 37),
        (54, 36),
        (55, 35),
        (56, 34),
        (57, 33),
        (58, 32),
        (59, 31),
        (60, 30),
        (63, 15),
        (64, 14),
        (70, 39),
        (71, 29),
        (72, 28),
        (73, 27),
        (74, 26),
        (75, 25),
        (76, 24),
        (77, 23),
        (78, 22),
    ];
    if let Some((_, d)) = D.iter().find(|(p, _)| *p == pin) {
        return Some(Pin::D(*d));
    }
    match pin {
        82..=89 => Some(Pin::A(u8::try_from(89 - pin + 8).ok()?)),
        90..=97 => Some(Pin::A(u8::try_from(97 - pin).ok()?)),
        _ => None,
    }
}

/// The Arduino pin of an LDmicro pin number for this microcontroller.
fn arduino_pin(micro: &str, pin: u32) -> Option<Pin> {
    let m = micro.to_ascii_lowercase();
    let small = ["atmega328", "atmega168", "atmega88", "atmega48", "atmega8 "]
        .iter()
        .any(|k| m.contains(k));
    if small && m.contains("28-pdip") {
        atmega328_pin(pin)
    } else if m.contains("atmega2560") && m.contains("100-tqfp") {
        atmega2560_pin(pin)
    } else {
        None
    }
}

fn all_pins(model: Model) -> Vec<Pin> {
    let (d, a) = match model {
        Model::Uno => (14u8, 6u8),
        Model::Nano => (14, 8),
        Model::Mega => (54, 16),
    };
    (2..d).map(Pin::D).chain((0..a).map(Pin::A)).collect()
}

/// Converts an LDmicro file.
pub fn convert(file: &str, stem: &str, text: &str, opts: &Options) -> Result<(Project, Report), Error> {
    let parsed = parse(file, text)?;
    let version = if text.trim_start().starts_with("LDmicro0.1") {
        "0.1"
    } else {
        "0.2"
    };
    let mut report = Report::default();
    let (cycle_us, cycle_loc) = match &parsed.cycle_us {
        Some((c, l)) => (*c, l.clone()),
        None => (10_000, Location::new(file, 1, 1)),
    };
    let scan_ms = (cycle_us / 1000).clamp(1, 60_000);
    if cycle_us % 1000 != 0 || !(1000..=60_000_000).contains(&cycle_us) {
        report.push(
            Kind::Approximated,
            cycle_loc.clone(),
            format!("cycle time {cycle_us} µs: Alba scans in whole ms, scan_ms = {scan_ms}"),
        );
    } else {
        report.push(
            Kind::Converted,
            cycle_loc.clone(),
            format!("cycle time {cycle_us} µs: scan_ms = {scan_ms}"),
        );
    }

    // How each name is used.
    let mut uses: HashMap<String, Use> = HashMap::new();
    let mut order: Vec<String> = Vec::new();
    let mut counter_init: HashMap<String, i64> = HashMap::new();
    let mut conflict: Option<(Location, String)> = None;
    {
        let mut note = |name: &str, u: Use, loc: &Location| {
            if name.starts_with(['#', '$']) {
                return;
            }
            match uses.get(name) {
                None => {
                    uses.insert(name.to_string(), u);
                    order.push(name.to_string());
                }
                Some(&old) if old == u => {}
                // A counter or timer read as a number stays what it is.
                Some(Use::Counter | Use::Timer) if u == Use::Int => {}
                Some(Use::Int) if matches!(u, Use::Counter | Use::Timer) => {
                    uses.insert(name.to_string(), u);
                }
                Some(&old) => {
                    if conflict.is_none() {
                        conflict = Some((
                            loc.clone(),
                            format!("`{name}` is used as a {} and as a {}", use_name(old), use_name(u)),
                        ));
                    }
                }
            }
        };
        for io in &parsed.io {
            let u = if io.name.starts_with(['A', 'P']) {
                Use::Int
            } else {
                Use::Bit
            };
            note(&io.name, u, &io.loc);
        }
        for r in &parsed.rungs {
            walk(&r.elems, &mut |l, loc| {
                let arg = |a: &Arg, note: &mut dyn FnMut(&str, Use, &Location)| {
                    if let Arg::Var(v) = a {
                        note(v, Use::Int, loc);
                    }
                };
                match l {
                    Leaf::Contact { name, .. } | Leaf::Coil { name, .. } => note(name, Use::Bit, loc),
                    Leaf::Timer { name, .. } => note(name, Use::Timer, loc),
                    Leaf::Counter { name, init, .. } => {
                        note(name, Use::Counter, loc);
                        if let Arg::Lit(v) = init {
                            counter_init.entry(name.clone()).or_insert(*v);
                        }
                    }
                    Leaf::Move { dest, src } => {
                        note(dest, Use::Int, loc);
                        arg(src, &mut note);
                    }
                    Leaf::Math { dest, a, b, .. } => {
                        note(dest, Use::Int, loc);
                        arg(a, &mut note);
                        arg(b, &mut note);
                    }
                    Leaf::Unary { dest, a, .. } => {
                        note(dest, Use::Int, loc);
                        arg(a, &mut note);
                    }
                    Leaf::Cmp { a, b, .. } => {
                        arg(a, &mut note);
                        arg(b, &mut note);
                    }
                    Leaf::ReadAdc { name } => note(name, Use::Int, loc),
                    _ => {}
                }
            });
        }
        // RES of a name nothing else uses: a variable.
        for r in &parsed.rungs {
            walk(&r.elems, &mut |l, loc| {
                if let Leaf::Res { name } = l {
                    note(name, Use::Int, loc);
                }
            });
        }
    }
    if let Some((loc, m)) = conflict {
        return Err(Error::at(loc, m));
    }

    // Names.
    let mut names = Names::new();
    let mut alba = HashMap::new();
    let mut first_loc: HashMap<String, Location> = HashMap::new();
    for io in &parsed.io {
        first_loc.entry(io.name.clone()).or_insert(io.loc.clone());
    }
    for r in &parsed.rungs {
        walk(&r.elems, &mut |l, loc| {
            let n = match l {
                Leaf::Contact { name, .. }
                | Leaf::Coil { name, .. }
                | Leaf::Timer { name, .. }
                | Leaf::Counter { name, .. }
                | Leaf::Res { name }
                | Leaf::ReadAdc { name } => Some(name),
                Leaf::Move { dest, .. } | Leaf::Math { dest, .. } | Leaf::Unary { dest, .. } => Some(dest),
                _ => None,
            };
            if let Some(n) = n {
                first_loc.entry(n.clone()).or_insert(loc.clone());
            }
        });
    }
    for n in &order {
        let (a, why) = names.alba(n);
        if let Some(why) = why {
            let loc = first_loc.get(n).cloned().unwrap_or_else(|| Location::new(file, 1, 1));
            report.push(Kind::Approximated, loc, format!("{why}: renamed `{a}`"));
        }
        alba.insert(n.clone(), a);
    }

    // I/O: channels in the order of the I/O list, then names not listed.
    let model = match &opts.board {
        None => None,
        Some(b) => {
            Some(Model::parse(b).ok_or_else(|| Error::plain(format!("unknown board `{b}`: uno, nano or mega")))?)
        }
    };
    let micro = parsed.micro.as_ref().map(|(m, _)| m.as_str()).unwrap_or("");
    let mut tags: Vec<TagOut> = Vec::new();
    let mut counts = [0usize; 4];
    let mut wired: [Vec<String>; 4] = Default::default();
    let mut used_pins: Vec<Pin> = Vec::new();
    let preset = PinMap::preset("aurora").unwrap_or_default();
    let mut io_names: Vec<(&str, u32, Location)> = parsed
        .io
        .iter()
        .map(|i| (i.name.as_str(), i.pin, i.loc.clone()))
        .collect();
    for n in &order {
        if n.starts_with(['X', 'Y']) && uses.get(n) == Some(&Use::Bit) && !parsed.io.iter().any(|i| &i.name == n) {
            let loc = first_loc.get(n).cloned().unwrap_or_else(|| Location::new(file, 1, 1));
            io_names.push((n.as_str(), 0, loc));
        }
    }
    let dir_of = |src: &str| match (src.chars().next(), uses.get(src)) {
        (Some('X'), Some(Use::Bit)) => Some(Dir::DigitalIn),
        (Some('Y'), Some(Use::Bit)) => Some(Dir::DigitalOut),
        (Some('A'), Some(Use::Int)) => Some(Dir::AnalogIn),
        (Some('P'), Some(Use::Int)) => Some(Dir::AnalogOut),
        _ => None,
    };
    // Pins claimed by their own I/O (the first one naming a pin owns it), so
    // that an I/O moved elsewhere never takes a pin a later one needs.
    let mut owner: HashMap<String, String> = HashMap::new();
    if let Some(model) = model {
        for (src, pin, _) in &io_names {
            if let (Some(dir), Some(p)) = (dir_of(src), arduino_pin(micro, *pin))
                && model.refuses(p, dir).is_none()
            {
                owner.entry(p.to_string()).or_insert_with(|| (*src).to_string());
            }
        }
    }
    let mut done: Vec<String> = Vec::new();
    for (src, pin, loc) in &io_names {
        if done.iter().any(|d| d == src) {
            continue;
        }
        done.push((*src).to_string());
        let dir = match dir_of(src) {
            Some(d) => d,
            None => {
                report.push(
                    Kind::Approximated,
                    loc.clone(),
                    format!("`{src}` in the I/O list is neither X, Y, A nor P: an internal tag"),
                );
                continue;
            }
        };
        let k = Dir::ALL.iter().position(|d| *d == dir).unwrap_or(0);
        let ch = counts[k];
        counts[k] += 1;
        let name = alba.get(*src).cloned().unwrap_or_else(|| (*src).to_string());
        let ty = if matches!(dir, Dir::DigitalIn | Dir::DigitalOut) {
            "BOOL"
        } else {
            "INT"
        };
        let mut description = if *pin > 0 {
            format!("LDmicro {src}, pin {pin}")
        } else {
            format!("LDmicro {src}")
        };
        if let Some(model) = model {
            let from_source = arduino_pin(micro, *pin);
            let fits = |p: Pin, used: &[Pin]| model.refuses(p, dir).is_none() && !used.contains(&p);
            let own = |p: Pin| owner.get(&p.to_string()).is_some_and(|o| o == src);
            let chosen = match from_source {
                Some(p) if fits(p, &used_pins) && own(p) => {
                    report.push(
                        Kind::Converted,
                        loc.clone(),
                        format!(
                            "`{src}` (pin {pin} of the {micro}) is {} on {p} of the {}",
                            dir.address(ch),
                            model.title()
                        ),
                    );
                    p
                }
                _ => {
                    let cands: Vec<Pin> = preset
                        .pins(dir)
                        .iter()
                        .copied()
                        .chain(all_pins(model))
                        .filter(|p| fits(*p, &used_pins) && !owner.contains_key(&p.to_string()))
                        .collect();
                    let Some(&p) = cands.first() else {
                        return Err(Error::at(
                            loc.clone(),
                            format!("the {} has no free pin left for `{src}` ({})", model.title(), dir.key()),
                        ));
                    };
                    let why = match from_source {
                        Some(sp) => match model.refuses(sp, dir) {
                            Some(w) => format!("its pin {pin} is {sp}, but {w}"),
                            None => format!("its pin {pin} is {sp}, already used"),
                        },
                        None if *pin == 0 => "it has no pin in LDmicro".to_string(),
                        None if micro.is_empty() => "the file names no microcontroller".to_string(),
                        None => format!("pin {pin} of the {micro} is not an Arduino pin Alba knows"),
                    };
                    report.push(
                        Kind::Approximated,
                        loc.clone(),
                        format!("`{src}`: {why}; wired to {p} ({}) instead", dir.address(ch)),
                    );
                    p
                }
            };
            used_pins.push(chosen);
            wired[k].push(chosen.to_string());
            description.push_str(&format!(", Arduino {chosen}"));
        } else {
            report.push(Kind::Converted, loc.clone(), format!("`{src}` is {}", dir.address(ch)));
        }
        tags.push(TagOut {
            name,
            ty: ty.into(),
            address: dir.address(ch),
            initial: String::new(),
            description,
        });
    }
    let declared: Vec<String> = done;

    let mut conv = Conv {
        file,
        report,
        names,
        structs: Structs::default(),
        uses: uses.clone(),
        alba,
        counter_init,
        helpers: Vec::new(),
        scan_ms,
        cycle_us,
        version: version.to_string(),
        out_bytes: 0,
    };

    // The rungs.
    let mut prog = ProgramOut::new("main.lad".into());
    let mut pending: Vec<String> = Vec::new();
    for r in &parsed.rungs {
        let comments: Vec<&String> = r
            .elems
            .iter()
            .filter_map(|e| match e {
                Elem::Leaf(Leaf::Comment(c), _) => Some(c),
                _ => None,
            })
            .collect();
        for c in comments {
            for line in c.lines() {
                pending.push(line.trim_end().to_string());
            }
        }
        let logic: Vec<Elem> = r
            .elems
            .iter()
            .filter(|e| !matches!(e, Elem::Leaf(Leaf::Comment(_), _)))
            .cloned()
            .collect();
        if logic.is_empty() {
            continue;
        }
        let mut names = std::mem::take(&mut conv.names);
        let result = {
            let mut e = Emitter::new(&mut names, "pwr");
            let rail = e.rail();
            match conv.elems(&mut e, &logic, rail) {
                Ok(_) => {
                    let helpers = std::mem::take(&mut e.helpers);
                    Ok((e.finish(), helpers))
                }
                Err(r) => Err(r),
            }
        };
        conv.names = names;
        if let Ok((rungs, _)) = &result {
            conv.out_bytes += rungs.iter().map(String::len).sum::<usize>();
            if conv.out_bytes > crate::MAX_OUTPUT_BYTES {
                return Err(Error::at(
                    r.loc.clone(),
                    format!(
                        "the converted program would exceed {} MiB",
                        crate::MAX_OUTPUT_BYTES >> 20
                    ),
                ));
            }
        }
        match result {
            Ok((rungs, helpers)) => {
                conv.helpers.extend(helpers);
                if rungs.is_empty() {
                    continue;
                }
                for p in pending.drain(..) {
                    prog.line(&comment_line(&p), None);
                }
                for rung in rungs {
                    if rung.starts_with("//") {
                        prog.line(&rung, Some(&r.loc));
                    } else {
                        prog.line(&format!("{rung};"), Some(&r.loc));
                    }
                }
            }
            Err((loc, why)) => {
                conv.report.push(
                    Kind::Refused,
                    loc.clone(),
                    format!("{why}: the rung of line {} is left out", r.loc.line),
                );
                for p in pending.drain(..) {
                    prog.line(&comment_line(&p), None);
                }
                prog.line(
                    &format!(
                        "// REFUSED by alba import: the LDmicro rung of {}:{} ({why})",
                        conv.file, r.loc.line
                    ),
                    Some(&r.loc),
                );
            }
        }
    }
    for p in pending.drain(..) {
        prog.line(&comment_line(&p), None);
    }

    // The other tags, in order of first use.
    for n in &order {
        if declared.contains(n) {
            continue;
        }
        let name = conv.name(n);
        let (ty, description) = match uses.get(n) {
            Some(Use::Bit) => ("BOOL".to_string(), format!("LDmicro relay {n}")),
            Some(Use::Timer) => ("TIMER".to_string(), format!("LDmicro timer {n}")),
            Some(Use::Counter) => ("COUNTER".to_string(), format!("LDmicro counter {n}")),
            _ => {
                let ty = match parsed.var_sizes.get(n) {
                    Some(1) => "SINT",
                    Some(3 | 4) => "DINT",
                    _ => "INT",
                };
                (ty.to_string(), format!("LDmicro variable {n}"))
            }
        };
        tags.push(TagOut {
            name,
            ty,
            address: String::new(),
            initial: String::new(),
            description,
        });
    }
    for (h, what) in &conv.helpers {
        tags.push(TagOut {
            name: h.clone(),
            ty: "BOOL".into(),
            address: String::new(),
            initial: String::new(),
            description: format!("alba import: {what}"),
        });
    }

    let board = model.map(|m| {
        let [di, r#do, ai, ao] = wired;
        BoardOut {
            model: m.name().to_string(),
            di,
            r#do,
            ai,
            ao,
        }
    });
    let project = Project {
        name: stem.to_string(),
        description: String::new(),
        scan_ms: u32::try_from(scan_ms).unwrap_or(10),
        board,
        tags,
        programs: vec![prog],
        ..Project::default()
    };
    let mut report = conv.report;
    report.entries.sort_by_key(|e| (e.location.line, e.location.col));
    Ok((project, report))
}

fn comment_line(c: &str) -> String {
    if c.is_empty() {
        "//".to_string()
    } else {
        format!("// {c}")
    }
}

fn use_name(u: Use) -> &'static str {
    match u {
        Use::Bit => "bit",
        Use::Int => "number",
        Use::Timer => "timer",
        Use::Counter => "counter",
    }
}
