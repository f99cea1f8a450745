//! PLCopen TC6 XML export of Alba ladder programs (the first part of
//! `alba export plcopen`): each ladder program becomes a `program` POU with
//! an LD body — contacts, coils, branches as parallel connections, timers as
//! IEC `TON`/`TOF`/`TP` blocks — with layout positions, and the tag table
//! becomes global variables with IEC addresses. Importing the file again
//! gives the same behaviour (tested on the examples by simulation).
//!
//! Exported: `XIC` `XIO` `OTE` `OTL` `OTU`, branches, `TON` `TOF` `TP` with a
//! literal preset (a following element connects to the timer's input, as
//! Alba's timers pass the rung on), compares as `EQ`…`LE` functions and
//! `ADD` `SUB` `MUL` `DIV` `MOD` `MOV` as functions with EN wired to the
//! rung; `T.DN`/`T.ACC`/`T.PRE` as `T.Q`/`T.ET`/`T.PT`. Refused, with the
//! rung's place: every other instruction, addresses as operands, counters,
//! RTO, and other members.

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
            return Err(format!("`{op}`: only a timer's ACC and PRE are exported as numbers"));
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

    fn bit(&self, r: &Rung<'_>, op: &str) -> Result<String, String> {
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
                let id = self.function(f, &inputs, &ins, *x, y);
                let ov = self.id();
                let _ = writeln!(
                    self.xml,
                    "          <outVariable localId=\"{ov}\" width=\"60\" height=\"20\"><position x=\"{}\" y=\"{}\"/>{}<expression>{}</expression></outVariable>",
                    *x + 80,
                    y + 30,
                    conns(&[(id, Some("OUT"))]),
                    esc(&d)
                );
                *x += 60;
                // Alba's math passes the rung on.
                Ok(inputs)
            }
            other => Err(format!("{other} is not exported to PLCopen (yet)")),
        }
    }
}

/// Exports the ladder programs of the project in `dir` as PLCopen TC6 XML.
pub fn export_plcopen(dir: &Path) -> Result<(String, Report), Error> {
    let c = alba_compiler::compile_dir(dir);
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
    for p in &project.programs {
        if p.plant || !p.name.to_ascii_lowercase().ends_with(".lad") {
            report.push(
                Kind::Refused,
                Location::new(&p.name, 1, 1),
                format!("`{}` is not a control ladder program; not exported", p.name),
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
                if let Some(t) = i.operands.first().map(|o| o.text.trim().to_string()) {
                    let key = t.to_ascii_lowercase();
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
        parsed.push((p, prog));
    }
    // Variables.
    let mut vars = String::new();
    let mut ext = String::new();
    let mut bools: HashMap<String, String> = HashMap::new();
    let mut numbers: HashMap<String, String> = HashMap::new();
    let mut timer_names: HashMap<String, &'static str> = HashMap::new();
    for t in project.tags.iter() {
        let ty = t.ty.name();
        let type_xml = match ty {
            "BOOL" | "SINT" | "INT" | "DINT" | "LINT" | "REAL" | "LREAL" | "TIME" => format!("<{ty}/>"),
            "TIMER" => {
                let k = timers.get(&t.name.to_ascii_lowercase()).copied().unwrap_or("TON");
                timer_names.insert(t.name.clone(), k);
                format!("<derived name=\"{k}\"/>")
            }
            other => {
                report.push(
                    Kind::Refused,
                    Location::new("tags.csv", 1, 1),
                    format!("tag `{}`: {other} is not exported", t.name),
                );
                continue;
            }
        };
        if ty == "BOOL" {
            bools.insert(t.name.to_ascii_lowercase(), t.name.clone());
        } else if ty != "TIMER" {
            numbers.insert(t.name.to_ascii_lowercase(), t.name.clone());
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
    };
    // Programs.
    let mut pous = String::new();
    let mut instances = String::new();
    for (p, prog) in &parsed {
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
        };
        let mut y = 20i64;
        for r in &prog.rungs {
            let (line, col) = files.line_col(p.file, r.span.start as usize);
            let loc = Location::new(&p.name, line as u32, col as u32);
            let mut rg = Graph {
                xml: String::new(),
                next_id: g.next_id,
                order: g.order,
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
                    report.push(Kind::Converted, loc, "rung exported".to_string());
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
        let _ = write!(
            pous,
            "      <pou name=\"{pou}\" pouType=\"program\">\n        <interface>\n          <externalVars>\n{ext}          </externalVars>\n        </interface>\n        <body>\n          <LD>\n{}          </LD>\n        </body>\n      </pou>\n",
            g.xml
        );
        let _ = writeln!(
            instances,
            "            <pouInstance name=\"{pou}_instance\" typeName=\"{pou}\"/>"
        );
    }
    let name = project
        .config
        .as_ref()
        .map(|c| c.name.clone())
        .unwrap_or_else(|| "alba".into());
    let scan = project.scan_ms();
    let xml = format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<project xmlns=\"http://www.plcopen.org/xml/tc6_0201\" xmlns:xhtml=\"http://www.w3.org/1999/xhtml\">\n  <fileHeader companyName=\"Alba\" productName=\"Alba\" productVersion=\"{}\" creationDateTime=\"1970-01-01T00:00:00\"/>\n  <contentHeader name=\"{}\">\n    <coordinateInfo><fbd><scaling x=\"0\" y=\"0\"/></fbd><ld><scaling x=\"0\" y=\"0\"/></ld><sfc><scaling x=\"0\" y=\"0\"/></sfc></coordinateInfo>\n  </contentHeader>\n  <types>\n    <dataTypes/>\n    <pous>\n{pous}    </pous>\n  </types>\n  <instances>\n    <configurations>\n      <configuration name=\"config\">\n        <resource name=\"resource\">\n          <task name=\"main\" interval=\"T#{scan}ms\" priority=\"0\">\n{instances}          </task>\n          <globalVars>\n{vars}          </globalVars>\n        </resource>\n      </configuration>\n    </configurations>\n  </instances>\n</project>\n",
        env!("CARGO_PKG_VERSION"),
        esc(&name)
    );
    Ok((xml, report))
}
