//! PLCopen TC6 XML export of Alba ladder programs (`alba export plcopen`):
//! each ladder program becomes a `program` POU with an LD body — contacts,
//! coils, branches as parallel connections, timers, counters and one-shots
//! as IEC function blocks, compares and math as IEC functions — with layout
//! positions, and the tag table becomes global variables with IEC
//! addresses. Importing the file again gives the same behaviour (tested by
//! simulation, `tests/export.rs`).
//!
//! Exported: `XIC` `XIO` `OTE` `OTL` `OTU`, branches; `TON` `TOF` `TP` with
//! a literal preset (a following element connects to the timer's input, as
//! Alba's timers pass the rung on); `CTU` and `CTD` (a counter counted only
//! up or only down) as IEC `CTU`/`CTD` with PV, `C.DN` as `C.Q` (CTU) or
//! `GE(C.CV, C.PV)` (CTD: IEC's Q is CV ≤ 0); `ONS` `OSR` `OSF` as
//! `R_TRIG`/`F_TRIG` instances named after their storage bit; compares as
//! `EQ`…`LE` functions, `ADD` `SUB` `MUL` `DIV` `MOD` `MOV` as functions
//! with EN wired to the rung, `CPT` as `MOVE` of an ST expression;
//! `T.DN`/`T.ACC`/`T.PRE` as `T.Q`/`T.ET`/`T.PT`, `C.ACC`/`C.PRE` as
//! `C.CV`/`C.PV`. Refused, with the rung's place: `RTO` and `RES` (IEC has
//! no retentive timer and resets through a block's own inputs), up/down
//! counters, one-shots whose storage bit is read elsewhere, every other
//! instruction, addresses as operands, and other members.

use crate::{Error, Kind, Location, Report};
use alba_model::Address;
use alba_model::address::MarkerWidth;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// An Alba address in IEC notation, when there is one.
fn iec_address(a: Address) -> Option<String> {
    Some(match a {
        Address::DigitalIn(n) => format!("%IX{}.{}", n / 8, n % 8),
        Address::DigitalOut(n) => format!("%QX{}.{}", n / 8, n % 8),
        Address::AnalogIn(n) => format!("%IW{n}"),
        Address::AnalogOut(n) => format!("%QW{n}"),
        Address::Marker { byte, width } => match width {
            MarkerWidth::Bit(b) => format!("%MX{byte}.{b}"),
            MarkerWidth::Byte => format!("%MB{byte}"),
            MarkerWidth::Word if byte % 2 == 0 => format!("%MW{}", byte / 2),
            MarkerWidth::DWord if byte % 4 == 0 => format!("%MD{}", byte / 4),
            _ => return None,
        },
    })
}

struct Graph {
    xml: String,
    next_id: usize,
    order: usize,
    /// Differences to report for the rung being written.
    notes: Vec<String>,
}

type Conn = (usize, Option<&'static str>);

fn conns(inputs: &[Conn]) -> String {
    let mut s = String::from("<connectionPointIn>");
    for (id, p) in inputs {
        match p {
            Some(p) => {
                let _ = write!(s, "<connection refLocalId=\"{id}\" formalParameter=\"{p}\"/>");
            }
            None => {
                let _ = write!(s, "<connection refLocalId=\"{id}\"/>");
            }
        }
    }
    s.push_str("</connectionPointIn>");
    s
}

struct Rung<'a> {
    timers: &'a HashMap<String, &'static str>,
    bools: &'a HashMap<String, String>,
    /// Numeric tags (lower case → name).
    numbers: &'a HashMap<String, String>,
    /// Counters (lower case → the IEC block, the name, the literal preset).
    counters: &'a HashMap<String, (&'static str, String, Option<String>)>,
    /// One-shot storage bits exported as instances (lower case → block, name).
    trigs: &'a HashMap<String, (&'static str, String)>,
    /// One-shot storage bits that cannot be instances (lower case → why).
    bad_trigs: &'a HashMap<String, String>,
}

impl Rung<'_> {
    fn counter(&self, name: &str) -> Option<&(&'static str, String, Option<String>)> {
        self.counters.get(&name.to_ascii_lowercase())
    }
}

/// An Alba CPT expression as an ST expression (the same precedence and
/// associativity: operands are bracketed only where Alba's grammar needs it;
/// ST's own levels of `<`… and `=`/`<>` are bracketed apart).
fn st_expr(r: &Rung<'_>, e: &alba_ladder::expr::Expr, out: &mut String) -> Result<(), String> {
    use alba_ladder::expr::{BinE, Expr, Func};
    fn prec(op: BinE) -> u8 {
        match op {
            BinE::Or => 1,
            BinE::Xor => 2,
            BinE::And => 3,
            BinE::Eq | BinE::Ne | BinE::Lt | BinE::Gt | BinE::Le | BinE::Ge => 4,
            BinE::Add | BinE::Sub => 5,
            BinE::Mul | BinE::Div | BinE::Mod => 6,
            BinE::Pow => 8,
        }
    }
    fn level(e: &Expr) -> u8 {
        match e {
            Expr::Bin(op, ..) => prec(*op),
            Expr::Neg(_) | Expr::Not(..) => 7,
            _ => 9,
        }
    }
    fn child(r: &Rung<'_>, e: &Expr, paren: bool, out: &mut String) -> Result<(), String> {
        if paren {
            out.push('(');
        }
        st_expr(r, e, out)?;
        if paren {
            out.push(')');
        }
        Ok(())
    }
    match e {
        Expr::Lit(l, _) => match l {
            alba_model::Literal::Int(v) | alba_model::Literal::Time(v) => out.push_str(&v.to_string()),
            alba_model::Literal::Real(v) => {
                let t = format!("{v:?}");
                // ST reals need a dot before their exponent: 1.0E-7.
                out.push_str(&if t.contains(['e', 'E']) && !t.contains('.') {
                    t.replacen('e', ".0E", 1)
                } else {
                    t
                });
            }
            alba_model::Literal::Bool(_) => return Err("a BOOL literal in CPT".into()),
        },
        Expr::Name(n, _) => {
            let name = match n.split_once('.') {
                Some((t, m)) => {
                    if let Some(k) = r.timers.keys().find(|k| k.eq_ignore_ascii_case(t)) {
                        match m.to_ascii_uppercase().as_str() {
                            "ACC" => format!("{k}.ET"),
                            "PRE" => format!("{k}.PT"),
                            _ => return Err(format!("`{n}` in CPT")),
                        }
                    } else if let Some((_, c, _)) = r.counter(t) {
                        match m.to_ascii_uppercase().as_str() {
                            "ACC" => format!("{c}.CV"),
                            "PRE" => format!("{c}.PV"),
                            _ => return Err(format!("`{n}` in CPT")),
                        }
                    } else {
                        return Err(format!("`{n}`: only timers' and counters' ACC and PRE are exported"));
                    }
                }
                None => r
                    .numbers
                    .get(&n.to_ascii_lowercase())
                    .cloned()
                    .ok_or_else(|| format!("`{n}` is not exported (a numeric tag; addresses are not)"))?,
            };
            out.push_str(&name);
        }
        Expr::Const(v) => out.push_str(&format!("{v:?}")),
        Expr::Neg(a) | Expr::Not(a, _) => {
            out.push_str(if matches!(e, Expr::Neg(_)) { "-" } else { "NOT " });
            child(r, a, level(a) < 7 || matches!(**a, Expr::Neg(_) | Expr::Not(..)), out)?;
        }
        Expr::Bin(op, a, b, _) => {
            let p = prec(*op);
            let cmp = p == 4;
            let (la, lb) = (level(a), level(b));
            let pa = la < p || (op == &BinE::Pow && la == p) || (cmp && la == 4);
            let pb = lb < p || (op != &BinE::Pow && lb == p) || (cmp && lb == 4) || lb == 7;
            child(r, a, pa, out)?;
            out.push_str(match op {
                BinE::Or => " OR ",
                BinE::Xor => " XOR ",
                BinE::And => " AND ",
                BinE::Eq => " = ",
                BinE::Ne => " <> ",
                BinE::Lt => " < ",
                BinE::Gt => " > ",
                BinE::Le => " <= ",
                BinE::Ge => " >= ",
                BinE::Add => " + ",
                BinE::Sub => " - ",
                BinE::Mul => " * ",
                BinE::Div => " / ",
                BinE::Mod => " MOD ",
                BinE::Pow => " ** ",
            });
            child(r, b, pb, out)?;
        }
        Expr::Call(f, args, _) => {
            let name = match f {
                Func::Sqrt => "SQRT",
                Func::Abs => "ABS",
                Func::Sin => "SIN",
                Func::Cos => "COS",
                Func::Tan => "TAN",
                Func::Asn => "ASIN",
                Func::Acs => "ACOS",
                Func::Atn => "ATAN",
                Func::Ln => "LN",
                Func::Log => "LOG",
                Func::Trn => "TRUNC",
                other => return Err(format!("CPT's {other:?} has no IEC 61131-3 function")),
            };
            out.push_str(name);
            out.push('(');
            for (k, a) in args.iter().enumerate() {
                if k > 0 {
                    out.push_str(", ");
                }
                st_expr(r, a, out)?;
            }
            out.push(')');
        }
    }
    Ok(())
}

impl Graph {
    fn id(&mut self) -> usize {
        self.next_id += 1;
        self.next_id
    }

    fn series(
        &mut self,
        r: &Rung<'_>,
        elems: &[alba_ladder::Element],
        mut inputs: Vec<Conn>,
        x: &mut i64,
        y: i64,
    ) -> Result<Vec<Conn>, String> {
        for e in elems {
            match e {
                alba_ladder::Element::Branch(b) => {
                    let mut outs = Vec::new();
                    let x0 = *x;
                    let mut xmax = x0;
                    for (i, leg) in b.legs.iter().enumerate() {
                        let mut lx = x0;
                        let o = self.series(r, leg, inputs.clone(), &mut lx, y + 40 * i as i64)?;
                        xmax = xmax.max(lx);
                        outs.extend(o);
                    }
                    *x = xmax;
                    outs.dedup();
                    inputs = outs;
                }
                alba_ladder::Element::Instr(i) => {
                    inputs = self.instr(r, i, inputs, x, y)?;
                }
            }
        }
        Ok(inputs)
    }

    /// A numeric operand: a numeric tag, a timer's ACC/PRE (ET/PT), or a
    /// literal (durations in ms).
    fn number(&self, r: &Rung<'_>, op: &str) -> Result<String, String> {
        if let Some(n) = r.numbers.get(&op.to_ascii_lowercase()) {
            return Ok(n.clone());
        }
        let literal = op.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+');
        if let Some((t, m)) = op.split_once('.').filter(|_| !literal) {
            if let Some(name) = r.timers.keys().find(|k| k.eq_ignore_ascii_case(t)) {
                match m.to_ascii_uppercase().as_str() {
                    "ACC" => return Ok(format!("{name}.ET")),
                    "PRE" => return Ok(format!("{name}.PT")),
                    _ => {}
                }
            }
            if let Some((_, name, _)) = r.counter(t) {
                match m.to_ascii_uppercase().as_str() {
                    "ACC" => return Ok(format!("{name}.CV")),
                    "PRE" => return Ok(format!("{name}.PV")),
                    _ => {}
                }
            }
            return Err(format!(
                "`{op}`: only a timer's or counter's ACC and PRE are exported as numbers"
            ));
        }
        let up = op.to_ascii_uppercase();
        if let Some(ms) = up
            .strip_prefix("T#")
            .or_else(|| up.strip_prefix("TIME#"))
            .and_then(crate::plcopen::duration_ms)
        {
            return Ok(ms.to_string());
        }
        let plain = op.replace('_', "");
        if plain.parse::<i64>().is_ok() || (plain.contains('.') && plain.parse::<f64>().is_ok_and(f64::is_finite)) {
            return Ok(plain);
        }
        Err(format!("`{op}` is not exported (a numeric tag or a literal)"))
    }

    /// A standard function block with EN wired to `inputs`, its inputs from
    /// input variables; returns its localId.
    fn function(&mut self, f: &str, inputs: &[Conn], args: &[(&str, String)], x: i64, y: i64) -> usize {
        let mut vars = String::new();
        let mut ins = format!("<variable formalParameter=\"EN\">{}</variable>", conns(inputs));
        for (k, (param, v)) in args.iter().enumerate() {
            let iv = self.id();
            let _ = writeln!(
                vars,
                "          <inVariable localId=\"{iv}\" width=\"60\" height=\"20\"><position x=\"{}\" y=\"{}\"/><connectionPointOut/><expression>{}</expression></inVariable>",
                x - 10,
                y + 30 + 20 * k as i64,
                esc(v)
            );
            let _ = write!(
                ins,
                "<variable formalParameter=\"{param}\">{}</variable>",
                conns(&[(iv, None)])
            );
        }
        self.xml.push_str(&vars);
        let id = self.id();
        self.order += 1;
        let _ = writeln!(
            self.xml,
            "          <block localId=\"{id}\" typeName=\"{f}\" executionOrderId=\"{}\" width=\"60\" height=\"60\"><position x=\"{}\" y=\"{y}\"/><inputVariables>{ins}</inputVariables><inOutVariables/><outputVariables><variable formalParameter=\"ENO\"><connectionPointOut/></variable><variable formalParameter=\"OUT\"><connectionPointOut/></variable></outputVariables></block>",
            self.order,
            x + 80
        );
        id
    }

    /// [`Self::function`] with its OUT written to the variable `dest`.
    fn function_to(&mut self, f: &str, inputs: &[Conn], args: &[(&str, String)], dest: &str, x: i64, y: i64) {
        let id = self.function(f, inputs, args, x, y);
        let ov = self.id();
        let _ = writeln!(
            self.xml,
            "          <outVariable localId=\"{ov}\" width=\"60\" height=\"20\"><position x=\"{}\" y=\"{}\"/>{}<expression>{}</expression></outVariable>",
            x + 80,
            y + 30,
            conns(&[(id, Some("OUT"))]),
            esc(dest)
        );
    }

    fn bit(&self, r: &Rung<'_>, op: &str) -> Result<String, String> {
        if let Some((t, m)) = op.split_once('.')
            && let Some((kind, name, _)) = r.counter(t)
        {
            return match (*kind, m.to_ascii_uppercase().as_str()) {
                ("CTU", "DN") => Ok(format!("{name}.Q")),
                _ => Err(format!("`{op}`: only a CTU counter's DN is exported as a bit")),
            };
        }
        if let Some((t, m)) = op.split_once('.') {
            let name = r
                .timers
                .keys()
                .find(|k| k.eq_ignore_ascii_case(t))
                .ok_or_else(|| format!("`{op}`: only a timer's DN is exported"))?;
            if !m.eq_ignore_ascii_case("DN") {
                return Err(format!("`{op}`: only a timer's DN is exported"));
            }
            return Ok(format!("{name}.Q"));
        }
        r.bools
            .get(&op.to_ascii_lowercase())
            .cloned()
            .ok_or_else(|| format!("`{op}` is not a BOOL tag (addresses are not exported)"))
    }

    fn instr(
        &mut self,
        r: &Rung<'_>,
        i: &alba_ladder::Instr,
        inputs: Vec<Conn>,
        x: &mut i64,
        y: i64,
    ) -> Result<Vec<Conn>, String> {
        let m = i.mnemonic.name();
        let op = |k: usize| i.operands.get(k).map(|o| o.text.trim().to_string()).unwrap_or_default();
        *x += 80;
        let pos = format!("<position x=\"{x}\" y=\"{y}\"/>");
        match m {
            "XIC" | "XIO"
                if op(0).split_once('.').is_some_and(|(t, mb)| {
                    mb.eq_ignore_ascii_case("DN") && r.counter(t).is_some_and(|c| c.0 == "CTD")
                }) =>
            {
                // IEC's CTD.Q is CV <= 0; Alba's DN is ACC >= PRE.
                let c = op(0);
                let (_, name, _) = r.counter(c.split('.').next().unwrap_or("")).cloned().unwrap_or_default();
                let f = if m == "XIC" { "GE" } else { "LT" };
                let id = self.function(f, &inputs, &[("IN1", format!("{name}.CV")), ("IN2", format!("{name}.PV"))], *x, y);
                *x += 60;
                Ok(vec![(id, Some("OUT"))])
            }
            "XIC" | "XIO" => {
                let v = self.bit(r, &op(0))?;
                let id = self.id();
                let _ = writeln!(
                    self.xml,
                    "          <contact localId=\"{id}\" negated=\"{}\" width=\"21\" height=\"15\">{pos}{}<connectionPointOut/><variable>{}</variable></contact>",
                    m == "XIO",
                    conns(&inputs),
                    esc(&v)
                );
                Ok(vec![(id, None)])
            }
            "OTE" | "OTL" | "OTU" => {
                let v = self.bit(r, &op(0))?;
                if v.ends_with(".Q") {
                    return Err(format!("`{}` cannot be written", op(0)));
                }
                let id = self.id();
                self.order += 1;
                let storage = match m {
                    "OTL" => " storage=\"set\"",
                    "OTU" => " storage=\"reset\"",
                    _ => "",
                };
                let _ = writeln!(
                    self.xml,
                    "          <coil localId=\"{id}\" executionOrderId=\"{}\" negated=\"false\"{storage} width=\"21\" height=\"15\">{pos}{}<connectionPointOut/><variable>{}</variable></coil>",
                    self.order,
                    conns(&inputs),
                    esc(&v)
                );
                Ok(vec![(id, None)])
            }
            "TON" | "TOF" | "TP" => {
                let t = op(0);
                let name = r
                    .timers
                    .keys()
                    .find(|k| k.eq_ignore_ascii_case(&t))
                    .cloned()
                    .ok_or_else(|| format!("`{t}` is not a timer"))?;
                let pre = op(1);
                let ms = pre
                    .parse::<i64>()
                    .ok()
                    .or_else(|| {
                        let up = pre.to_ascii_uppercase();
                        up.strip_prefix("T#")
                            .or_else(|| up.strip_prefix("TIME#"))
                            .and_then(crate::plcopen::duration_ms)
                    })
                    .filter(|v| *v >= 0)
                    .ok_or_else(|| format!("{m}: the preset `{pre}` is not a literal"))?;
                // A time base other than ms: the preset in milliseconds (exact).
                let ms = match i.operands.get(3) {
                    None => ms,
                    Some(o) => {
                        let b = alba_ladder::TimeBase::parse(&o.text)
                            .ok_or_else(|| format!("{m}: `{}` is not a time base", o.text))?;
                        ms.checked_mul(i64::from(b.ms()))
                            .ok_or_else(|| format!("{m}: the preset `{pre}` {} is too long", b.name()))?
                    }
                };
                let acc = op(2);
                if acc != "0" && acc != "?" {
                    return Err(format!("{m}: an initial accumulator `{acc}` has no IEC equivalent"));
                }
                let pt = self.id();
                let _ = writeln!(
                    self.xml,
                    "          <inVariable localId=\"{pt}\" width=\"60\" height=\"20\"><position x=\"{}\" y=\"{}\"/><connectionPointOut/><expression>T#{ms}ms</expression></inVariable>",
                    *x - 70,
                    y + 30
                );
                let id = self.id();
                self.order += 1;
                let _ = writeln!(
                    self.xml,
                    "          <block localId=\"{id}\" typeName=\"{m}\" instanceName=\"{}\" executionOrderId=\"{}\" width=\"60\" height=\"60\">{pos}<inputVariables><variable formalParameter=\"IN\">{}</variable><variable formalParameter=\"PT\">{}</variable></inputVariables><inOutVariables/><outputVariables><variable formalParameter=\"Q\"><connectionPointOut/></variable><variable formalParameter=\"ET\"><connectionPointOut/></variable></outputVariables></block>",
                    esc(&name),
                    self.order,
                    conns(&inputs),
                    conns(&[(pt, None)])
                );
                *x += 60;
                // Alba's timers pass the rung on: what follows is wired to
                // the timer's input.
                Ok(inputs)
            }
            "EQU" | "NEQ" | "GRT" | "GEQ" | "LES" | "LEQ" => {
                let f = match m {
                    "EQU" => "EQ",
                    "NEQ" => "NE",
                    "GRT" => "GT",
                    "GEQ" => "GE",
                    "LES" => "LT",
                    _ => "LE",
                };
                let a = self.number(r, &op(0))?;
                let b = self.number(r, &op(1))?;
                let id = self.function(f, &inputs, &[("IN1", a), ("IN2", b)], *x, y);
                *x += 60;
                Ok(vec![(id, Some("OUT"))])
            }
            "ADD" | "SUB" | "MUL" | "DIV" | "MOD" | "MOV" => {
                let (ins, dest) = if m == "MOV" {
                    (vec![("IN", self.number(r, &op(0))?)], op(1))
                } else {
                    (
                        vec![("IN1", self.number(r, &op(0))?), ("IN2", self.number(r, &op(1))?)],
                        op(2),
                    )
                };
                let d = r
                    .numbers
                    .get(&dest.to_ascii_lowercase())
                    .cloned()
                    .ok_or_else(|| format!("{m}: the destination `{dest}` is not a numeric tag"))?;
                let f = if m == "MOV" { "MOVE" } else { m };
                self.function_to(f, &inputs, &ins, &d, *x, y);
                *x += 60;
                // Alba's math passes the rung on.
                Ok(inputs)
            }
            "CTU" | "CTD" => {
                let c = op(0);
                let (kind, name, lit) = r.counter(&c).cloned().ok_or_else(|| format!("`{c}` is not a counter"))?;
                if kind != m {
                    return Err(format!(
                        "`{name}` is counted up and down: IEC's CTUD evaluates both inputs in one call, Alba's CTU and CTD each at its own rung"
                    ));
                }
                let acc = op(2);
                if acc != "0" && acc != "?" {
                    return Err(format!("{m}: an initial count `{acc}` has no IEC equivalent"));
                }
                let pre = op(1);
                let pv = if pre == "?" {
                    lit.ok_or_else(|| format!("{m}: the preset of `{name}` is given by no instruction"))?
                } else {
                    self.number(r, &pre)?
                };
                let pv_id = self.id();
                let _ = writeln!(
                    self.xml,
                    "          <inVariable localId=\"{pv_id}\" width=\"60\" height=\"20\"><position x=\"{}\" y=\"{}\"/><connectionPointOut/><expression>{}</expression></inVariable>",
                    *x - 70,
                    y + 30,
                    esc(&pv)
                );
                let id = self.id();
                self.order += 1;
                let input = if m == "CTU" { "CU" } else { "CD" };
                let _ = writeln!(
                    self.xml,
                    "          <block localId=\"{id}\" typeName=\"{m}\" instanceName=\"{}\" executionOrderId=\"{}\" width=\"60\" height=\"80\">{pos}<inputVariables><variable formalParameter=\"{input}\">{}</variable><variable formalParameter=\"PV\">{}</variable></inputVariables><inOutVariables/><outputVariables><variable formalParameter=\"Q\"><connectionPointOut/></variable><variable formalParameter=\"CV\"><connectionPointOut/></variable></outputVariables></block>",
                    esc(&name),
                    self.order,
                    conns(&inputs),
                    conns(&[(pv_id, None)])
                );
                *x += 60;
                // Alba's counters pass the rung on.
                Ok(inputs)
            }
            "ONS" | "OSR" | "OSF" => {
                let s = op(0);
                let key = s.to_ascii_lowercase();
                if let Some(why) = r.bad_trigs.get(&key) {
                    return Err(why.clone());
                }
                let (block, name) = r.trigs.get(&key).cloned().ok_or_else(|| format!("`{s}` is not a BOOL tag"))?;
                let out = if m == "ONS" {
                    None
                } else {
                    let o = self.bit(r, &op(1))?;
                    if o.contains('.') {
                        return Err(format!("`{}` cannot be written", op(1)));
                    }
                    Some(o)
                };
                if m == "OSF" {
                    self.notes.push(format!(
                        "OSF({s},…) is F_TRIG `{name}`: IEC's F_TRIG gives a pulse on the first scan when CLK is false, Alba's OSF does not (an import into Alba keeps Alba's)"
                    ));
                }
                let id = self.id();
                self.order += 1;
                let _ = writeln!(
                    self.xml,
                    "          <block localId=\"{id}\" typeName=\"{block}\" instanceName=\"{}\" executionOrderId=\"{}\" width=\"60\" height=\"40\">{pos}<inputVariables><variable formalParameter=\"CLK\">{}</variable></inputVariables><inOutVariables/><outputVariables><variable formalParameter=\"Q\"><connectionPointOut/></variable></outputVariables></block>",
                    esc(&name),
                    self.order,
                    conns(&inputs)
                );
                *x += 60;
                let Some(o) = out else {
                    // ONS passes on its pulse.
                    return Ok(vec![(id, Some("Q"))]);
                };
                let cid = self.id();
                self.order += 1;
                let _ = writeln!(
                    self.xml,
                    "          <coil localId=\"{cid}\" executionOrderId=\"{}\" negated=\"false\" width=\"21\" height=\"15\"><position x=\"{}\" y=\"{}\"/>{}<connectionPointOut/><variable>{}</variable></coil>",
                    self.order,
                    *x + 20,
                    y + 40,
                    conns(&[(id, Some("Q"))]),
                    esc(&o)
                );
                // OSR and OSF pass the rung on.
                Ok(inputs)
            }
            "CPT" => {
                let dest = op(0);
                let d = r
                    .numbers
                    .get(&dest.to_ascii_lowercase())
                    .cloned()
                    .ok_or_else(|| format!("CPT: the destination `{dest}` is not a numeric tag"))?;
                let text = op(1);
                let e = alba_ladder::expr::parse(&text, alba_diag::FileId(0), 0)
                    .map_err(|(m, _)| format!("CPT: {m}"))?;
                let mut st = String::new();
                st_expr(r, &e, &mut st)?;
                self.function_to("MOVE", &inputs, &[("IN", st)], &d, *x, y);
                *x += 60;
                Ok(inputs)
            }
            "RTO" => Err(
                "RTO has no IEC 61131-3 equivalent: the standard timers are TON, TOF and TP (a retentive timer is a vendor's library block)"
                    .into(),
            ),
            "RES" => Err(
                "RES has no IEC 61131-3 equivalent: an IEC counter is reset by R of its own call, a timer by its IN".into(),
            ),
            other => Err(format!("{other} is not exported to PLCopen (yet)")),
        }
    }
}

/// Exports the ladder programs of the project in `dir` as PLCopen TC6 XML.
pub fn export_plcopen(dir: &Path) -> Result<(String, Report), Error> {
    let c = alba_load::compile_dir(dir);
    if let Some(d) = c.diagnostics.first() {
        return Err(Error::plain(format!(
            "the project does not check: {}",
            d.short(c.files())
        )));
    }
    let project = &c.project;
    let mut report = Report::default();
    let files = &project.files;
    // Which timer instruction each timer is used with.
    let mut parsed = Vec::new();
    let mut timers: HashMap<String, &'static str> = HashMap::new();
    let mut bad_timers: HashMap<String, String> = HashMap::new();
    // Counters: counted up, down, the first literal preset.
    let mut counting: HashMap<String, (bool, bool, Option<String>)> = HashMap::new();
    // One-shot storage bits: the block, how many one-shots use them; and
    // how often every tag is named by any operand.
    let mut oneshots: HashMap<String, (&'static str, usize)> = HashMap::new();
    let mut named: HashMap<String, usize> = HashMap::new();
    // ST programs' POUs, by their place in `programs`.
    let mut st_out: Vec<(usize, String, String)> = Vec::new();
    // Their FUNCTIONs and FUNCTION_BLOCKs (no task instance) and TYPEs.
    let mut st_lib = String::new();
    let mut data_types = String::new();
    let mut st_globals = String::new();
    for (k, p) in project.programs.iter().enumerate() {
        if !p.plant && p.name.to_ascii_lowercase().ends_with(".st") {
            let st = st_pous(files, p, &mut report);
            for (name, xml, program) in st.pous {
                if program {
                    st_out.push((k, name, xml));
                } else {
                    st_lib.push_str(&xml);
                }
            }
            data_types.push_str(&st.types);
            st_globals.push_str(&st.globals);
            continue;
        }
        if p.plant || !p.name.to_ascii_lowercase().ends_with(".lad") {
            report.push(
                Kind::Refused,
                Location::new(&p.name, 1, 1),
                format!("`{}` is not a control ladder or ST program; not exported", p.name),
            );
            continue;
        }
        let (prog, _) = alba_ladder::parse(files.text(p.file), p.file);
        fn scan(elems: &[alba_ladder::Element], f: &mut dyn FnMut(&alba_ladder::Instr)) {
            for e in elems {
                match e {
                    alba_ladder::Element::Instr(i) => f(i),
                    alba_ladder::Element::Branch(b) => {
                        for l in &b.legs {
                            scan(l, f);
                        }
                    }
                }
            }
        }
        for r in &prog.rungs {
            scan(&r.elements, &mut |i| {
                let m = i.mnemonic.name();
                for o in &i.operands {
                    let base = o.text.trim().split('.').next().unwrap_or("").to_ascii_lowercase();
                    *named.entry(base).or_default() += 1;
                }
                if let Some(t) = i.operands.first().map(|o| o.text.trim().to_string()) {
                    let key = t.to_ascii_lowercase();
                    match m {
                        "CTU" | "CTD" => {
                            let e = counting.entry(key.clone()).or_default();
                            if m == "CTU" {
                                e.0 = true;
                            } else {
                                e.1 = true;
                            }
                            let pre = i.operands.get(1).map(|o| o.text.trim().to_string()).unwrap_or_default();
                            if e.2.is_none() && pre.parse::<i64>().is_ok() {
                                e.2 = Some(pre);
                            }
                        }
                        "ONS" | "OSR" | "OSF" => {
                            let block = if m == "OSF" { "F_TRIG" } else { "R_TRIG" };
                            let e = oneshots.entry(key.clone()).or_insert((block, 0));
                            if e.0 != block {
                                e.1 += 1;
                            }
                            e.1 += 1;
                        }
                        _ => {}
                    }
                    let kind: Option<&'static str> = match m {
                        "TON" => Some("TON"),
                        "TOF" => Some("TOF"),
                        "TP" => Some("TP"),
                        _ => None,
                    };
                    if let Some(k) = kind {
                        match timers.get(&key) {
                            Some(old) if *old != k => {
                                bad_timers.insert(key.clone(), format!("timer `{t}` is used as {old} and {k}"));
                            }
                            _ => {
                                timers.insert(key, k);
                            }
                        }
                    }
                }
            });
        }
        parsed.push((k, p, prog));
    }
    // Variables.
    let mut vars = String::new();
    let mut ext = String::new();
    let mut bools: HashMap<String, String> = HashMap::new();
    let mut numbers: HashMap<String, String> = HashMap::new();
    let mut timer_names: HashMap<String, &'static str> = HashMap::new();
    let mut counters: HashMap<String, (&'static str, String, Option<String>)> = HashMap::new();
    let mut trigs: HashMap<String, (&'static str, String)> = HashMap::new();
    let mut bad_trigs: HashMap<String, String> = HashMap::new();
    for t in project.tags.iter() {
        let ty = t.ty.name();
        let key = t.name.to_ascii_lowercase();
        // A one-shot's storage bit becomes the instance of its R_TRIG/F_TRIG
        // when nothing else reads or writes it.
        let trig = match (ty, oneshots.get(&key)) {
            ("BOOL", Some(&(block, 1))) if named.get(&key) == Some(&1) && t.address.is_none() => Some(block),
            ("BOOL", Some(&(_, n))) => {
                let why = if n > 1 {
                    format!(
                        "`{}` is the storage bit of {n} one-shots; an R_TRIG/F_TRIG instance serves one",
                        t.name
                    )
                } else {
                    format!(
                        "`{}` is a one-shot's storage bit and is also used elsewhere (or has an address); it cannot become an R_TRIG/F_TRIG instance",
                        t.name
                    )
                };
                bad_trigs.insert(key.clone(), why);
                None
            }
            _ => None,
        };
        let type_xml = match (ty, trig) {
            (_, Some(block)) => {
                trigs.insert(key.clone(), (block, t.name.clone()));
                format!("<derived name=\"{block}\"/>")
            }
            ("BOOL" | "SINT" | "INT" | "DINT" | "LINT" | "REAL" | "LREAL" | "TIME", _) => format!("<{ty}/>"),
            ("TIMER", _) => {
                let k = timers.get(&t.name.to_ascii_lowercase()).copied().unwrap_or("TON");
                timer_names.insert(t.name.clone(), k);
                format!("<derived name=\"{k}\"/>")
            }
            ("COUNTER", _) => {
                let (up, down, pre) = counting.get(&key).cloned().unwrap_or((true, false, None));
                let k = match (up, down) {
                    (true, true) => "CTUD",
                    (false, true) => "CTD",
                    _ => "CTU",
                };
                counters.insert(key.clone(), (k, t.name.clone(), pre));
                format!("<derived name=\"{k}\"/>")
            }
            (other, _) => {
                report.push(
                    Kind::Refused,
                    Location::new("tags.csv", 1, 1),
                    format!("tag `{}`: {other} is not exported", t.name),
                );
                continue;
            }
        };
        match ty {
            _ if trig.is_some() => {}
            "BOOL" => {
                bools.insert(key, t.name.clone());
            }
            "TIMER" | "COUNTER" => {}
            _ => {
                numbers.insert(key, t.name.clone());
            }
        }
        let addr = match t.address {
            Some(a) => match iec_address(a) {
                Some(s) => format!(" address=\"{s}\""),
                None => {
                    report.push(
                        Kind::Approximated,
                        Location::new("tags.csv", 1, 1),
                        format!("tag `{}`: {a} has no IEC notation; exported without an address", t.name),
                    );
                    String::new()
                }
            },
            None => String::new(),
        };
        let init = match (&t.initial, ty) {
            (Some(v), "TIME") => format!("<initialValue><simpleValue value=\"T#{v}ms\"/></initialValue>"),
            (Some(v), _) => format!(
                "<initialValue><simpleValue value=\"{}\"/></initialValue>",
                esc(&v.to_string())
            ),
            (None, _) => String::new(),
        };
        let doc = if t.description.is_empty() {
            String::new()
        } else {
            format!(
                "<documentation><xhtml:p>{}</xhtml:p></documentation>",
                esc(&t.description)
            )
        };
        let _ = writeln!(
            vars,
            "            <variable name=\"{}\"{addr}><type>{type_xml}</type>{init}{doc}</variable>",
            esc(&t.name)
        );
        let _ = writeln!(
            ext,
            "            <variable name=\"{}\"><type>{type_xml}</type></variable>",
            esc(&t.name)
        );
    }
    let rung_ctx = Rung {
        timers: &timer_names,
        bools: &bools,
        numbers: &numbers,
        counters: &counters,
        trigs: &trigs,
        bad_trigs: &bad_trigs,
    };
    // Programs.
    let mut pous = String::new();
    let mut instances = String::new();
    let mut out_pous: Vec<(usize, String, String)> = Vec::new();
    for (k, p, prog) in &parsed {
        let pou = Path::new(&p.name)
            .file_stem()
            .map(|s| {
                s.to_string_lossy()
                    .replace(|c: char| !c.is_ascii_alphanumeric() && c != '_', "_")
            })
            .unwrap_or_else(|| "main".into());
        let mut g = Graph {
            xml: String::new(),
            next_id: 0,
            order: 0,
            notes: Vec::new(),
        };
        let mut y = 20i64;
        for r in &prog.rungs {
            let (line, col) = files.line_col(p.file, r.span.start as usize);
            let loc = Location::new(&p.name, line as u32, col as u32);
            let mut rg = Graph {
                xml: String::new(),
                next_id: g.next_id,
                order: g.order,
                notes: Vec::new(),
            };
            let rail = rg.id();
            let _ = writeln!(
                rg.xml,
                "          <leftPowerRail localId=\"{rail}\" width=\"3\" height=\"40\"><position x=\"0\" y=\"{y}\"/><connectionPointOut formalParameter=\"\"/></leftPowerRail>"
            );
            let mut x = 0i64;
            let result = rg.series(&rung_ctx, &r.elements, vec![(rail, None)], &mut x, y);
            let result = result.and_then(|outs| {
                for (k, why) in &bad_timers {
                    if rg.xml.contains(&format!("instanceName=\"{}\"", esc(k))) {
                        return Err(why.clone());
                    }
                }
                Ok(outs)
            });
            match result {
                Ok(outs) => {
                    if !r.comment.is_empty() {
                        let id = rg.id();
                        let _ = writeln!(
                            g.xml,
                            "          <comment localId=\"{id}\" width=\"400\" height=\"20\"><position x=\"0\" y=\"{}\"/><content><xhtml:p>{}</xhtml:p></content></comment>",
                            y - 15,
                            esc(&r.comment.join("\n"))
                        );
                    }
                    let rid = rg.id();
                    let _ = writeln!(
                        rg.xml,
                        "          <rightPowerRail localId=\"{rid}\" width=\"3\" height=\"40\"><position x=\"{}\" y=\"{y}\"/>{}</rightPowerRail>",
                        x + 100,
                        conns(&outs)
                    );
                    g.xml.push_str(&rg.xml);
                    g.next_id = rg.next_id;
                    g.order = rg.order;
                    report.push(Kind::Converted, loc.clone(), "rung exported".to_string());
                    for n in rg.notes.drain(..) {
                        report.push(Kind::Approximated, loc.clone(), n);
                    }
                }
                Err(why) => {
                    report.push(Kind::Refused, loc, format!("rung not exported: {why}"));
                }
            }
            let legs = r
                .elements
                .iter()
                .map(|e| match e {
                    alba_ladder::Element::Branch(b) => b.legs.len() as i64,
                    _ => 1,
                })
                .max()
                .unwrap_or(1);
            y += 60 + 40 * legs;
        }
        out_pous.push((
            *k,
            pou.clone(),
            format!(
                "      <pou name=\"{pou}\" pouType=\"program\">\n        <interface>\n          <externalVars>\n{ext}          </externalVars>\n        </interface>\n        <body>\n          <LD>\n{}          </LD>\n        </body>\n      </pou>\n",
                g.xml
            ),
        ));
    }
    out_pous.extend(st_out);
    out_pous.sort_by_key(|(k, _, _)| *k);
    pous.push_str(&st_lib);
    for (_, pou, xml) in &out_pous {
        pous.push_str(xml);
        let _ = writeln!(
            instances,
            "            <pouInstance name=\"{pou}_instance\" typeName=\"{pou}\"/>"
        );
    }
    let data_types = if data_types.is_empty() {
        "<dataTypes/>".to_string()
    } else {
        format!("<dataTypes>\n{data_types}    </dataTypes>")
    };
    let name = project
        .config
        .as_ref()
        .map(|c| c.name.clone())
        .unwrap_or_else(|| "alba".into());
    let scan = project.scan_ms();
    let xml = format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<project xmlns=\"http://www.plcopen.org/xml/tc6_0201\" xmlns:xhtml=\"http://www.w3.org/1999/xhtml\">\n  <fileHeader companyName=\"Alba\" productName=\"Alba\" productVersion=\"{}\" creationDateTime=\"1970-01-01T00:00:00\"/>\n  <contentHeader name=\"{}\">\n    <coordinateInfo><fbd><scaling x=\"0\" y=\"0\"/></fbd><ld><scaling x=\"0\" y=\"0\"/></ld><sfc><scaling x=\"0\" y=\"0\"/></sfc></coordinateInfo>\n  </contentHeader>\n  <types>\n    {data_types}\n    <pous>\n{pous}    </pous>\n  </types>\n  <instances>\n    <configurations>\n      <configuration name=\"config\">\n        <resource name=\"resource\">\n          <task name=\"main\" interval=\"T#{scan}ms\" priority=\"0\">\n{instances}          </task>\n          <globalVars>\n{vars}          </globalVars>\n{st_globals}        </resource>\n      </configuration>\n    </configurations>\n  </instances>\n</project>\n",
        env!("CARGO_PKG_VERSION"),
        esc(&name)
    );
    Ok((xml, report))
}

/// The PLCopen `<type>` content of an ST type, or why there is none.
fn st_type_xml(t: &alba_compiler::st::ast::TypeRef) -> Result<String, String> {
    use alba_compiler::st::ast::{TypeRef, expr};
    const ELEMENTARY: &[&str] = &[
        "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "TIME", "LTIME",
        "DATE", "TOD", "DT", "BYTE", "WORD", "DWORD", "LWORD",
    ];
    Ok(match t {
        TypeRef::Named(i) => {
            let up = i.name.to_ascii_uppercase();
            if ELEMENTARY.contains(&up.as_str()) {
                format!("<{up}/>")
            } else {
                format!("<derived name=\"{}\"/>", esc(&i.name))
            }
        }
        TypeRef::String { wide, len, .. } => {
            let tag = if *wide { "wstring" } else { "string" };
            match len {
                Some(l) => format!("<{tag} length=\"{}\"/>", esc(&expr(l))),
                None => format!("<{tag}/>"),
            }
        }
        TypeRef::Array { dims, of, .. } => {
            let mut s = String::from("<array>");
            for (lo, hi) in dims {
                let _ = write!(
                    s,
                    "<dimension lower=\"{}\" upper=\"{}\"/>",
                    esc(&expr(lo)),
                    esc(&expr(hi))
                );
            }
            let _ = write!(s, "<baseType>{}</baseType></array>", st_type_xml(of)?);
            s
        }
        TypeRef::Struct { .. } => return Err("an inline STRUCT type".into()),
        TypeRef::Enum { .. } => return Err("an inline enumeration".into()),
        TypeRef::Subrange { .. } => return Err("an inline subrange".into()),
    })
}

/// What an ST file exports.
struct StPous {
    /// (POU name, XML, whether it is a PROGRAM) in file order.
    pous: Vec<(String, String, bool)>,
    /// The `<dataType>`s of its TYPEs.
    types: String,
    /// Its file-level VAR_GLOBAL blocks, as the resource's `globalVars` lists.
    globals: String,
}

/// The POUs of the ST file `p` — PROGRAMs, FUNCTIONs and FUNCTION_BLOCKs,
/// with ST bodies — and its TYPEs as `<dataType>`s; what else it holds is
/// refused with its place.
fn st_pous(files: &alba_diag::Files, p: &alba_compiler::project::ProgramSource, report: &mut Report) -> StPous {
    use alba_compiler::st::ast::{PouKind, TypeRef, VarKind, expr};
    let text = files.text(p.file);
    let loc = |at: u32| {
        let (l, c) = files.line_col(p.file, at as usize);
        Location::new(&p.name, l as u32, c as u32)
    };
    let (file, _) = alba_compiler::st::parse(text, p.file);
    let mut types = String::new();
    for t in &file.types {
        let base = match &t.ty {
            TypeRef::Struct { members, .. } => {
                let mut s = String::from("<struct>");
                let mut bad = None;
                for m in members {
                    let ty = match st_type_xml(&m.ty) {
                        Ok(ty) => ty,
                        Err(why) => {
                            bad = Some(why);
                            break;
                        }
                    };
                    let init = match init_xml(m.init.as_ref()) {
                        Ok(init) => init,
                        Err(why) => {
                            bad = Some(why);
                            break;
                        }
                    };
                    for n in &m.names {
                        let _ = write!(
                            s,
                            "<variable name=\"{}\"><type>{ty}</type>{init}</variable>",
                            esc(&n.name)
                        );
                    }
                }
                s.push_str("</struct>");
                bad.map_or(Ok(s), Err)
            }
            TypeRef::Enum { values, .. } => {
                let mut s = String::from("<enum><values>");
                for (n, v) in values {
                    match v {
                        Some(v) => {
                            let _ = write!(s, "<value name=\"{}\" value=\"{}\"/>", esc(&n.name), esc(&expr(v)));
                        }
                        None => {
                            let _ = write!(s, "<value name=\"{}\"/>", esc(&n.name));
                        }
                    }
                }
                s.push_str("</values></enum>");
                Ok(s)
            }
            TypeRef::Subrange { base, lo, hi, .. } => {
                let up = base.name.to_ascii_uppercase();
                let kind = if up.starts_with('U') {
                    "subrangeUnsigned"
                } else {
                    "subrangeSigned"
                };
                Ok(format!(
                    "<{kind}><range lower=\"{}\" upper=\"{}\"/><baseType><{up}/></baseType></{kind}>",
                    esc(&expr(lo)),
                    esc(&expr(hi))
                ))
            }
            ty => st_type_xml(ty),
        };
        let init = init_xml(t.init.as_ref());
        match (base, init) {
            (Ok(b), Ok(i)) => {
                let _ = writeln!(
                    types,
                    "      <dataType name=\"{}\"><baseType>{b}</baseType>{i}</dataType>",
                    esc(&t.name.name)
                );
                report.push(
                    Kind::Converted,
                    loc(t.name.span.start),
                    format!("TYPE `{}` exported as a data type", t.name.name),
                );
            }
            (Err(why), _) | (_, Err(why)) => report.push(
                Kind::Refused,
                loc(t.name.span.start),
                format!("TYPE `{}`: {why} is not exported", t.name.name),
            ),
        }
    }
    // File-level VAR_GLOBAL blocks (an import's `globals.st`): the resource's
    // global variables, a `globalVars` list each, which an import reads back there.
    let mut globals = String::new();
    for b in &file.globals {
        let mut list = String::new();
        if var_list(b, "globalVars", "          ", &mut list, &loc, report) {
            globals.push_str(&list);
            report.push(
                Kind::Converted,
                loc(b.span.start),
                "VAR_GLOBAL exported as the resource's global variables".to_string(),
            );
        } else {
            report.push(
                Kind::Refused,
                loc(b.span.start),
                "this VAR_GLOBAL block is not exported".to_string(),
            );
        }
    }
    let mut out = Vec::new();
    for pou in &file.pous {
        let (pou_type, end_kw) = match pou.kind {
            PouKind::Program => ("program", "END_PROGRAM"),
            PouKind::Function => ("function", "END_FUNCTION"),
            PouKind::FunctionBlock => ("functionBlock", "END_FUNCTION_BLOCK"),
        };
        let mut iface = String::new();
        let mut refused = false;
        if let Some(r) = &pou.ret {
            match st_type_xml(r) {
                Ok(t) => {
                    let _ = writeln!(iface, "          <returnType>{t}</returnType>");
                }
                Err(why) => {
                    report.push(Kind::Refused, loc(r.span().start), format!("{why} is not exported"));
                    refused = true;
                }
            }
        }
        for b in &pou.vars {
            let list = match b.kind {
                VarKind::Var => "localVars",
                VarKind::Input => "inputVars",
                VarKind::Output => "outputVars",
                VarKind::InOut => "inOutVars",
                VarKind::Temp => "tempVars",
                VarKind::Global => "globalVars",
                VarKind::External => "externalVars",
            };
            refused |= !var_list(b, list, "          ", &mut iface, &loc, report);
        }
        let keyword = pou.kind.keyword();
        if refused {
            report.push(
                Kind::Refused,
                loc(pou.name.span.start),
                format!("{keyword} `{}` not exported", pou.name.name),
            );
            continue;
        }
        // The body as written: from the end of the declarations (or of the
        // result type) to the END_ keyword.
        let start = pou
            .vars
            .last()
            .map(|b| b.span.end)
            .into_iter()
            .chain(pou.ret.as_ref().map(|r| r.span().end))
            .max()
            .unwrap_or(pou.name.span.end) as usize;
        let end = pou.span.end as usize;
        let body = text.get(start..end).unwrap_or("").trim();
        let cut = body.len().saturating_sub(end_kw.len());
        let body = match (body.get(cut..), body.get(..cut)) {
            (Some(end), Some(rest)) if end.eq_ignore_ascii_case(end_kw) => rest.trim_end(),
            _ => body,
        };
        let body = body.trim_start_matches(['\n', '\r']);
        let cdata = body.replace("]]>", "]]]]><![CDATA[>");
        report.push(
            Kind::Converted,
            loc(pou.name.span.start),
            format!("{keyword} `{}` exported as an ST body", pou.name.name),
        );
        out.push((
            pou.name.name.clone(),
            format!(
                "      <pou name=\"{}\" pouType=\"{pou_type}\">\n        <interface>\n{iface}        </interface>\n        <body>\n          <ST>\n            <xhtml:p><![CDATA[{cdata}]]></xhtml:p>\n          </ST>\n        </body>\n      </pou>\n",
                esc(&pou.name.name)
            ),
            pou.kind == PouKind::Program,
        ));
    }
    StPous {
        pous: out,
        types,
        globals,
    }
}

/// The `<initialValue>` of an initial value (nothing for none), or why it has
/// no PLCopen form here.
fn init_xml(init: Option<&alba_compiler::st::ast::Init>) -> Result<String, String> {
    use alba_compiler::st::ast::{Init, expr};
    match init {
        None => Ok(String::new()),
        Some(Init::Expr(e)) => Ok(format!(
            "<initialValue><simpleValue value=\"{}\"/></initialValue>",
            esc(&expr(e))
        )),
        Some(_) => Err("an array or structure initialiser".to_string()),
    }
}

/// Writes the variable block `b` as the PLCopen list `list` (`localVars`,
/// `globalVars`…) into `out`; false, each reason reported at its place, when a
/// variable's type or initial value has no PLCopen form.
fn var_list(
    b: &alba_compiler::st::ast::VarBlock,
    list: &str,
    indent: &str,
    out: &mut String,
    loc: &dyn Fn(u32) -> Location,
    report: &mut Report,
) -> bool {
    let attrs = format!(
        "{}{}",
        if b.retain { " retain=\"true\"" } else { "" },
        if b.constant { " constant=\"true\"" } else { "" }
    );
    let mut ok = true;
    let _ = writeln!(out, "{indent}<{list}{attrs}>");
    for d in &b.vars {
        let ty = match st_type_xml(&d.ty) {
            Ok(t) => t,
            Err(why) => {
                report.push(Kind::Refused, loc(d.span.start), format!("{why} is not exported"));
                ok = false;
                continue;
            }
        };
        let init = match init_xml(d.init.as_ref()) {
            Ok(init) => init,
            Err(why) => {
                report.push(Kind::Refused, loc(d.span.start), format!("{why} is not exported"));
                ok = false;
                continue;
            }
        };
        for n in &d.names {
            let _ = writeln!(
                out,
                "{indent}  <variable name=\"{}\"><type>{ty}</type>{init}</variable>",
                esc(&n.name)
            );
        }
    }
    let _ = writeln!(out, "{indent}</{list}>");
    ok
}
