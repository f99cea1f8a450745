//! From a ladder circuit of another tool to Alba rungs.
//!
//! Importers describe the power flow of one source rung (LDmicro) or network
//! (PLCopen) with *conditions*: the rail, a contact ANDed to a condition, an
//! OR of conditions, the output of a timer. Each condition is kept as Alba
//! neutral text (`XIC(a)[XIC(b),XIC(c)]`) and is written in front of every
//! instruction it drives, one Alba rung per instruction, in source order.
//!
//! Repeating a condition's text in a later rung is only right while none of
//! the tags it reads has been written since the condition was formed (a coil
//! of the same rung may write a tag its own condition reads, and the source
//! evaluated the condition once). The emitter tracks this: every rung
//! reserves a *slot* where a condition is formed, every instruction records
//! the tags it writes, and a condition used after one of its tags was written
//! is first stored into a helper bit, in a rung placed at the slot where the
//! condition was formed, so every reader sees the value the source saw.

use crate::names::Names;
use std::collections::{BTreeSet, HashMap};

pub type Cond = usize;

#[derive(Debug, Clone, PartialEq, Eq)]
enum Shape {
    True,
    False,
    Expr,
    /// An OR not formed yet: its legs are checked and joined on first use,
    /// so an OR nobody reads costs nothing.
    Or(Vec<Cond>),
}

#[derive(Debug, Clone)]
struct CondData {
    text: String,
    reads: BTreeSet<String>,
    slot: usize,
    shape: Shape,
    /// Already a helper bit that nothing writes later.
    settled: bool,
}

/// The Alba rungs of one source rung or network.
pub struct Emitter<'a> {
    names: &'a mut Names,
    slots: Vec<Vec<(String, usize)>>,
    /// The caller's id of the source construct being converted (see
    /// [`Emitter::set_origin`]), kept with every line.
    origin: usize,
    conds: Vec<CondData>,
    writes: Vec<(usize, String)>,
    /// Helper bits added (internal BOOL tags), with what they hold.
    pub helpers: Vec<(String, String)>,
    helper_base: &'static str,
    bytes: usize,
}

/// Longest condition text kept inline (see [`Emitter::new_cond`]).
const MAX_COND_TEXT: usize = 2048;

/// The tag a written operand belongs to (`T.DN` → `t`).
pub fn base(operand: &str) -> String {
    operand
        .split(['.', '['])
        .next()
        .unwrap_or(operand)
        .trim()
        .to_ascii_lowercase()
}

impl<'a> Emitter<'a> {
    pub fn new(names: &'a mut Names, helper_base: &'static str) -> Emitter<'a> {
        Emitter {
            names,
            slots: Vec::new(),
            origin: 0,
            conds: Vec::new(),
            writes: Vec::new(),
            helpers: Vec::new(),
            helper_base,
            bytes: 0,
        }
    }

    pub fn names(&mut self) -> &mut Names {
        self.names
    }

    fn new_cond(&mut self, text: String, reads: BTreeSet<String>, shape: Shape) -> Cond {
        let slot = self.slots.len();
        self.slots.push(Vec::new());
        if shape == Shape::Expr && text.len() > MAX_COND_TEXT {
            // A long condition (deeply shared branches double it at every
            // level) is stored once in a helper bit, so texts stay bounded.
            let helper = self.names.fresh(self.helper_base);
            let line = format!("{text}OTE({helper})");
            self.bytes += line.len();
            let origin = self.origin;
            self.slots[slot].push((line, origin));
            self.helpers.push((helper.clone(), "a long condition".into()));
            self.conds.push(CondData {
                text: format!("XIC({helper})"),
                reads: [helper.to_ascii_lowercase()].into_iter().collect(),
                slot,
                shape,
                settled: true,
            });
            return self.conds.len() - 1;
        }
        self.conds.push(CondData {
            text,
            reads,
            slot,
            shape,
            settled: false,
        });
        self.conds.len() - 1
    }

    /// Bytes of rung text written so far.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// The power rail: always true.
    pub fn rail(&mut self) -> Cond {
        self.new_cond(String::new(), BTreeSet::new(), Shape::True)
    }

    /// An open circuit: always false.
    pub fn open(&mut self) -> Cond {
        self.new_cond("AFI()".into(), BTreeSet::new(), Shape::False)
    }

    /// Makes `c` safe to evaluate now, storing it in a helper bit at the
    /// place it was formed if a tag it reads was written since.
    fn touch(&mut self, c: Cond) {
        self.resolve(c);
        let d = &self.conds[c];
        if d.settled || d.shape != Shape::Expr {
            return;
        }
        let stale = self
            .writes
            .iter()
            .any(|(slot, name)| *slot > d.slot && d.reads.contains(name));
        if !stale {
            return;
        }
        let helper = self.names.fresh(self.helper_base);
        let d = &self.conds[c];
        let text = format!("{}OTE({helper})", d.text);
        self.bytes += text.len();
        let what = format!("the condition `{}`", d.text);
        let slot = d.slot;
        let origin = self.origin;
        self.slots[slot].push((text, origin));
        self.helpers.push((helper.clone(), what));
        let d = &mut self.conds[c];
        d.text = format!("XIC({helper})");
        d.reads = [helper.to_ascii_lowercase()].into_iter().collect();
        d.settled = true;
    }

    /// `c` AND an input instruction (`XIC(a)`, `GRT(a,b)`) reading `reads`.
    pub fn and(&mut self, c: Cond, frag: &str, reads: &[String]) -> Cond {
        self.touch(c);
        let d = self.conds[c].clone();
        if d.shape == Shape::False {
            return c;
        }
        let mut r = d.reads.clone();
        r.extend(reads.iter().map(|s| base(s)));
        self.new_cond(format!("{}{}", d.text, frag), r, Shape::Expr)
    }

    /// `a` AND `b` (two circuits in series).
    pub fn and_cond(&mut self, a: Cond, b: Cond) -> Cond {
        self.touch(a);
        self.touch(b);
        let (da, db) = (self.conds[a].clone(), self.conds[b].clone());
        match (&da.shape, &db.shape) {
            (Shape::False, _) => a,
            (_, Shape::False) => b,
            (Shape::True, _) => b,
            (_, Shape::True) => a,
            _ => {
                let mut r = da.reads.clone();
                r.extend(db.reads.iter().cloned());
                // A leg that is an OR keeps its brackets; series is concatenation.
                self.new_cond(format!("{}{}", da.text, db.text), r, Shape::Expr)
            }
        }
    }

    /// A comment line (`// text`) at this point of the output.
    pub fn comment(&mut self, text: &str) {
        self.slots.push(vec![(format!("// {text}"), self.origin)]);
    }

    /// A condition that is just an input instruction, independent of any
    /// rung (the output of a timer: `XIC(T.DN)`).
    pub fn input(&mut self, frag: &str, reads: &[String]) -> Cond {
        let rail = self.rail();
        self.and(rail, frag, reads)
    }

    /// The OR of conditions (a parallel circuit), formed when first used.
    pub fn or(&mut self, cs: &[Cond]) -> Cond {
        if cs.len() == 1 {
            return cs[0];
        }
        self.conds.push(CondData {
            text: String::new(),
            reads: BTreeSet::new(),
            slot: 0,
            shape: Shape::Or(cs.to_vec()),
            settled: false,
        });
        self.conds.len() - 1
    }

    /// Forms a pending OR now: every leg is valid now (or stored), so the
    /// OR's text is valid from here on.
    fn resolve(&mut self, c: Cond) {
        let Shape::Or(cs) = self.conds[c].shape.clone() else {
            return;
        };
        let mut legs: Vec<Cond> = Vec::new();
        let mut always = false;
        for &l in &cs {
            self.touch(l);
            match self.conds[l].shape {
                Shape::True => always = true,
                Shape::False | Shape::Or(_) => {}
                Shape::Expr => {
                    if !legs.iter().any(|&x| self.conds[x].text == self.conds[l].text) {
                        legs.push(l);
                    }
                }
            }
        }
        let slot = self.slots.len();
        self.slots.push(Vec::new());
        let (text, reads, shape) = if always {
            (String::new(), BTreeSet::new(), Shape::True)
        } else if legs.is_empty() {
            ("AFI()".to_string(), BTreeSet::new(), Shape::False)
        } else if legs.len() == 1 {
            let d = &self.conds[legs[0]];
            (d.text.clone(), d.reads.clone(), Shape::Expr)
        } else {
            let mut reads = BTreeSet::new();
            let texts: Vec<String> = legs
                .iter()
                .map(|&l| {
                    reads.extend(self.conds[l].reads.iter().cloned());
                    self.conds[l].text.clone()
                })
                .collect();
            (format!("[{}]", texts.join(",")), reads, Shape::Expr)
        };
        let d = &mut self.conds[c];
        d.text = text;
        d.reads = reads;
        d.slot = slot;
        d.shape = shape;
    }

    /// Whether `c` is always true (the rail, or an OR with the rail in it).
    pub fn is_true(&mut self, c: Cond) -> bool {
        self.resolve(c);
        self.conds[c].shape == Shape::True
    }

    /// The condition's text, for a rung written now.
    pub fn text(&mut self, c: Cond) -> String {
        self.touch(c);
        self.conds[c].text.clone()
    }

    /// Writes the rung `prefix` + condition + `instr`, which writes `writes`.
    pub fn emit(&mut self, c: Cond, prefix: &str, instr: &str, writes: &[String]) {
        let text = format!("{prefix}{}{instr}", self.text(c));
        self.bytes += text.len();
        let slot = self.slots.len();
        self.slots.push(vec![(text, self.origin)]);
        for w in writes {
            self.writes.push((slot, base(w)));
        }
    }

    /// The id of the source construct the next lines come from.
    pub fn set_origin(&mut self, origin: usize) {
        self.origin = origin;
    }

    /// The rungs, in order.
    pub fn finish(self) -> Vec<String> {
        self.slots.into_iter().flatten().map(|(t, _)| t).collect()
    }

    /// The rungs, in order, each with the origin it was written for.
    pub fn finish_with_origins(self) -> Vec<(String, usize)> {
        self.slots.into_iter().flatten().collect()
    }
}

/// Literal presets given to timers and counters: Alba wants every
/// instruction on one structure to give the same literals (or `?`).
#[derive(Debug, Default)]
pub struct Structs {
    timers: HashMap<String, i64>,
    counters: HashMap<String, (i64, i64)>,
}

impl Structs {
    /// `TON(name,pre,0)` arguments, or why not.
    pub fn timer(&mut self, name: &str, pre: i64) -> Result<String, String> {
        let key = name.to_ascii_lowercase();
        match self.timers.get(&key) {
            None => {
                self.timers.insert(key, pre);
                Ok(format!("{name},{pre},0"))
            }
            Some(&p) if p == pre => Ok(format!("{name},{pre},0")),
            Some(&p) => Err(format!(
                "timer `{name}` is used with two delays ({p} ms and {pre} ms); Alba keeps one preset per timer"
            )),
        }
    }

    /// `CTU(name,pre,acc)` arguments: the literals the first time, `?`
    /// where a later instruction differs. The second value: whether `.DN`
    /// means ACC ≥ `pre` for this instruction.
    pub fn counter(&mut self, name: &str, pre: i64, acc: i64) -> (String, bool) {
        let key = name.to_ascii_lowercase();
        match self.counters.get(&key) {
            None => {
                self.counters.insert(key, (pre, acc));
                (format!("{name},{pre},{acc}"), true)
            }
            Some(&(p, a)) => {
                let ps = if p == pre { pre.to_string() } else { "?".into() };
                let acs = if a == acc { acc.to_string() } else { "?".into() };
                (format!("{name},{ps},{acs}"), p == pre)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_condition_is_stored_where_it_was_formed() {
        let mut names = Names::new();
        let mut e = Emitter::new(&mut names, "pwr");
        let rail = e.rail();
        let a = e.and(rail, "XIC(A)", &["A".into()]);
        e.emit(a, "", "OTU(A)", &["A".into()]);
        e.emit(a, "", "OTE(B)", &["B".into()]);
        assert_eq!(e.finish(), vec!["XIC(A)OTE(pwr1)", "XIC(A)OTU(A)", "XIC(pwr1)OTE(B)"]);
    }

    #[test]
    fn fresh_condition_is_repeated() {
        let mut names = Names::new();
        let mut e = Emitter::new(&mut names, "pwr");
        let rail = e.rail();
        let a = e.and(rail, "XIC(A)", &["A".into()]);
        e.emit(a, "", "OTE(C)", &["C".into()]);
        let b = e.and(a, "XIC(B)", &["B".into()]);
        let o = e.or(&[a, b]);
        e.emit(o, "", "OTE(D)", &["D".into()]);
        assert_eq!(e.finish(), vec!["XIC(A)OTE(C)", "[XIC(A),XIC(A)XIC(B)]OTE(D)"]);
    }
}
