//! Sequential function charts (IEC 61131-3) in the standard's textual form
//! (docs/nets.md "SFC"): steps with their action associations, transitions
//! from steps to steps with a condition. Parsed here with located errors
//! (codes E650–E652) and turned into a 1-safe Petri-mode [`Net`]
//! ([`Sfc::to_net`]) that the compiler runs like any net. No I/O.
//!
//! ```text
//! INITIAL_STEP Idle: Ready(N); END_STEP
//! STEP Fill: Valve(N); Alarm(L, T#10s); END_STEP
//! TRANSITION FROM Idle TO Fill := Start AND NOT Full; END_TRANSITION
//! TRANSITION t2 (PRIORITY := 1) FROM (A, B) TO C := Done; END_TRANSITION
//! ```

use crate::model::{Arc, ArcKind, Extra, Guard, Net, Place, Transition};
use alba_diag::{Code, Diagnostic, FileId, Span};

/// The action qualifiers of IEC 61131-3.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Qualifier {
    N,
    S,
    R,
    L,
    D,
    P,
    P1,
    P0,
    SD,
    DS,
    SL,
}

impl Qualifier {
    fn parse(s: &str) -> Option<Qualifier> {
        Some(match s.to_ascii_uppercase().as_str() {
            "N" => Qualifier::N,
            "S" => Qualifier::S,
            "R" => Qualifier::R,
            "L" => Qualifier::L,
            "D" => Qualifier::D,
            "P" => Qualifier::P,
            "P1" => Qualifier::P1,
            "P0" => Qualifier::P0,
            "SD" => Qualifier::SD,
            "DS" => Qualifier::DS,
            "SL" => Qualifier::SL,
            _ => return None,
        })
    }

    /// Takes a time (L D SD DS SL).
    pub fn timed(self) -> bool {
        matches!(
            self,
            Qualifier::L | Qualifier::D | Qualifier::SD | Qualifier::DS | Qualifier::SL
        )
    }
}

/// An action association of a step: `Action(Q[, T#t])`.
#[derive(Debug, Clone, PartialEq)]
pub struct Association {
    /// The action: a BOOL tag the step drives.
    pub action: String,
    pub qualifier: Qualifier,
    /// Milliseconds, for the timed qualifiers.
    pub time_ms: Option<i64>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    pub name: String,
    pub initial: bool,
    pub actions: Vec<Association>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SfcTransition {
    pub name: Option<String>,
    pub priority: Option<i32>,
    pub from: Vec<(String, Span)>,
    pub to: Vec<(String, Span)>,
    /// The condition's text, and its span in the file.
    pub condition: Guard,
    /// `: <ST expression> END_TRANSITION`: the condition is ST, computed
    /// into a BOOL `<sfc>.<transition>.C` before the chart's turn, and
    /// `condition` is that expression (crates/compiler/src/sfc.rs).
    pub st: bool,
    pub span: Span,
}

/// An action whose body is Structured Text: `ACTION name: … END_ACTION`.
/// Its associations drive a BOOL `<sfc>.<name>`, and the body runs in the
/// scans where that is true (crates/compiler/src/sfc.rs).
#[derive(Debug, Clone, PartialEq)]
pub struct StAction {
    pub name: String,
    /// From `ACTION` to the `:` after the name.
    pub header: Span,
    /// The ST statements, between the `:` and `END_ACTION`.
    pub body: Span,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sfc {
    pub steps: Vec<Step>,
    pub transitions: Vec<SfcTransition>,
    pub actions: Vec<StAction>,
}

impl Sfc {
    /// The ST action called `name`, if there is one.
    pub fn st_action(&self, name: &str) -> Option<&StAction> {
        self.actions.iter().find(|a| a.name.eq_ignore_ascii_case(name))
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Word(String),
    /// `:=`
    Assign,
    Sym(char),
}

struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    file: FileId,
}

impl Lexer<'_> {
    fn span(&self, start: usize) -> Span {
        Span::new(self.file, start..self.pos.max(start))
    }

    fn skip(&mut self) -> Result<(), Diagnostic> {
        loop {
            let rest = &self.text[self.pos..];
            let trimmed = rest.trim_start();
            self.pos += rest.len() - trimmed.len();
            if trimmed.starts_with("//") {
                self.pos += trimmed.find('\n').unwrap_or(trimmed.len());
            } else if trimmed.starts_with("(*") {
                let start = self.pos;
                match trimmed.find("*)") {
                    Some(k) => self.pos += k + 2,
                    None => {
                        self.pos = self.text.len();
                        return Err(err("a `(*` comment is not closed", self.span(start), "comment"));
                    }
                }
            } else {
                return Ok(());
            }
        }
    }

    /// The next token and where it starts (`None` at the end).
    fn next(&mut self) -> Result<Option<(Tok, usize)>, Diagnostic> {
        self.skip()?;
        let start = self.pos;
        let rest = &self.text[self.pos..];
        let Some(c) = rest.chars().next() else { return Ok(None) };
        if rest.starts_with(":=") {
            self.pos += 2;
            return Ok(Some((Tok::Assign, start)));
        }
        if c.is_ascii_alphanumeric() || c == '_' || c == '#' {
            let len = rest
                .find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_' || ch == '#' || ch == '.'))
                .unwrap_or(rest.len());
            self.pos += len;
            return Ok(Some((Tok::Word(rest[..len].to_string()), start)));
        }
        self.pos += c.len_utf8();
        Ok(Some((Tok::Sym(c), start)))
    }

    /// An ST action's body: the text up to the word `END_ACTION` outside
    /// comments and strings; the position is left after it.
    fn action_body(&mut self) -> Result<Span, Diagnostic> {
        let start = self.pos;
        match self.until_word(start, "END_ACTION") {
            Some(end) => {
                self.pos = end + "END_ACTION".len();
                Ok(Span::new(self.file, start..end))
            }
            None => {
                self.pos = self.text.len();
                Err(err("the action is not ended by END_ACTION", self.span(start), "action"))
            }
        }
    }

    /// A condition in ST after `:`: the text up to the word
    /// `END_TRANSITION` (outside comments and strings), left before it.
    fn st_condition(&mut self) -> Result<(String, usize), Diagnostic> {
        let start = self.pos;
        let end = self.until_word(start, "END_TRANSITION").ok_or_else(|| {
            err(
                "the condition is not ended by END_TRANSITION",
                self.span(start),
                "condition",
            )
        })?;
        self.pos = end;
        Ok((self.text[start..end].to_string(), start))
    }

    /// Where the word `word` (upper case) is next, from `from`, outside
    /// comments and strings.
    fn until_word(&self, from: usize, word: &str) -> Option<usize> {
        let b = self.text.as_bytes();
        let n = word.len();
        let mut i = from;
        while i < b.len() {
            let rest = &self.text[i..];
            if rest.starts_with("(*") {
                i += rest.find("*)").map_or(rest.len(), |k| k + 2);
            } else if rest.starts_with("/*") {
                i += rest.find("*/").map_or(rest.len(), |k| k + 2);
            } else if rest.starts_with("//") {
                i += rest.find('\n').unwrap_or(rest.len());
            } else if b[i] == b'\'' || b[i] == b'"' {
                let q = b[i];
                i += 1;
                while i < b.len() && b[i] != q {
                    i += if b[i] == b'$' { 2 } else { 1 };
                }
                i += 1;
            } else if rest.len() >= n
                && rest.is_char_boundary(n)
                && rest[..n].eq_ignore_ascii_case(word)
                && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'))
                && !rest[n..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_')
            {
                return Some(i);
            } else {
                i += rest.chars().next().map_or(1, char::len_utf8);
            }
        }
        None
    }

    /// The condition after `:=`: the text up to the next `;`.
    fn condition(&mut self) -> Result<(String, usize), Diagnostic> {
        let start = self.pos;
        match self.text[self.pos..].find(';') {
            Some(k) => {
                self.pos += k;
                Ok((self.text[start..self.pos].to_string(), start))
            }
            None => Err(err("the condition is not ended by `;`", self.span(start), "condition")),
        }
    }
}

fn err(msg: impl Into<String>, span: Span, label: &str) -> Diagnostic {
    Diagnostic::new(Code::SfcSyntax, msg, span, label)
}

/// Largest SFC file read.
pub const MAX_FILE_BYTES: usize = 4 << 20;

/// Parses an SFC file; the chart or every problem found (E650 syntax,
/// E651 structure).
pub fn parse(file: FileId, text: &str) -> Result<Sfc, Vec<Diagnostic>> {
    if text.len() > MAX_FILE_BYTES {
        return Err(vec![err(
            format!("an SFC file is at most {} MiB", MAX_FILE_BYTES >> 20),
            Span::new(file, 0..0),
            "too large",
        )]);
    }
    let mut lx = Lexer { text, pos: 0, file };
    let mut sfc = Sfc::default();
    let mut diags = Vec::new();
    // One error of syntax stops the file: what follows would only echo it.
    if let Err(d) = parse_items(&mut lx, &mut sfc) {
        diags.push(d);
        return Err(diags);
    }
    check(&sfc, file, &mut diags);
    if diags.is_empty() { Ok(sfc) } else { Err(diags) }
}

fn expect_word(lx: &mut Lexer, what: &str) -> Result<(String, usize), Diagnostic> {
    match lx.next()? {
        Some((Tok::Word(w), at)) => Ok((w, at)),
        Some((_, at)) => Err(err(format!("expected {what}"), Span::new(lx.file, at..lx.pos), "here")),
        None => Err(err(
            format!("expected {what}, found the end of the file"),
            lx.span(lx.pos),
            "end",
        )),
    }
}

fn expect_sym(lx: &mut Lexer, c: char) -> Result<usize, Diagnostic> {
    match lx.next()? {
        Some((Tok::Sym(s), at)) if s == c => Ok(at),
        Some((_, at)) => Err(err(format!("expected `{c}`"), Span::new(lx.file, at..lx.pos), "here")),
        None => Err(err(
            format!("expected `{c}`, found the end of the file"),
            lx.span(lx.pos),
            "end",
        )),
    }
}

fn is_name(w: &str) -> bool {
    w.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `T#5s`, `T#250ms`, `T#1m30s`, or plain milliseconds.
fn duration(w: &str) -> Option<i64> {
    match alba_model::Literal::parse(w) {
        Ok(alba_model::Literal::Time(ms)) if ms >= 0 => Some(ms),
        Ok(alba_model::Literal::Int(ms)) if ms >= 0 => Some(ms),
        _ => None,
    }
}

fn parse_items(lx: &mut Lexer, sfc: &mut Sfc) -> Result<(), Diagnostic> {
    while let Some((tok, at)) = lx.next()? {
        let Tok::Word(w) = tok else {
            return Err(err(
                "expected INITIAL_STEP, STEP, ACTION or TRANSITION",
                Span::new(lx.file, at..lx.pos),
                "here",
            ));
        };
        match w.to_ascii_uppercase().as_str() {
            kw @ ("INITIAL_STEP" | "STEP") => {
                let (name, nat) = expect_word(lx, "the step's name")?;
                if !is_name(&name) {
                    return Err(err(
                        format!("`{name}` is not a step name"),
                        Span::new(lx.file, nat..nat + name.len()),
                        "name",
                    ));
                }
                expect_sym(lx, ':')?;
                let mut actions = Vec::new();
                loop {
                    let (w, wat) = expect_word(lx, "an action or END_STEP")?;
                    if w.eq_ignore_ascii_case("END_STEP") {
                        break;
                    }
                    expect_sym(lx, '(')?;
                    let (q, qat) = expect_word(lx, "a qualifier (N S R L D P P1 P0 SD DS SL)")?;
                    let qualifier = Qualifier::parse(&q).ok_or_else(|| {
                        err(
                            format!("`{q}` is not a qualifier: N S R L D P P1 P0 SD DS SL"),
                            Span::new(lx.file, qat..qat + q.len()),
                            "qualifier",
                        )
                    })?;
                    let mut time_ms = None;
                    let close = match lx.next()? {
                        Some((Tok::Sym(','), _)) => {
                            let (t, tat) = expect_word(lx, "a time (T#5s)")?;
                            time_ms = Some(duration(&t).ok_or_else(|| {
                                err(
                                    format!("`{t}` is not a time: write T#5s, T#250ms or milliseconds"),
                                    Span::new(lx.file, tat..tat + t.len()),
                                    "time",
                                )
                            })?);
                            expect_sym(lx, ')')?
                        }
                        Some((Tok::Sym(')'), a)) => a,
                        Some((_, a)) => return Err(err("expected `,` or `)`", Span::new(lx.file, a..lx.pos), "here")),
                        None => return Err(err("expected `)`", lx.span(lx.pos), "end")),
                    };
                    expect_sym(lx, ';')?;
                    actions.push(Association {
                        action: w,
                        qualifier,
                        time_ms,
                        span: Span::new(lx.file, wat..close + 1),
                    });
                }
                sfc.steps.push(Step {
                    name,
                    initial: kw == "INITIAL_STEP",
                    actions,
                    span: Span::new(lx.file, at..nat + 1),
                });
            }
            "ACTION" => {
                let (name, nat) = expect_word(lx, "the action's name")?;
                if !is_name(&name) {
                    return Err(err(
                        format!("`{name}` is not an action name"),
                        Span::new(lx.file, nat..nat + name.len()),
                        "name",
                    ));
                }
                let colon = expect_sym(lx, ':')?;
                let body = lx.action_body()?;
                sfc.actions.push(StAction {
                    name,
                    header: Span::new(lx.file, at..colon + 1),
                    body,
                });
            }
            "TRANSITION" => {
                let mut name = None;
                let mut priority = None;
                let (mut w, mut wat) = expect_word(lx, "FROM or the transition's name")?;
                if !w.eq_ignore_ascii_case("FROM") {
                    name = Some(w.clone());
                    // `(PRIORITY := n)`?
                    let save = lx.pos;
                    match lx.next()? {
                        Some((Tok::Sym('('), _)) => {
                            let (p, pat) = expect_word(lx, "PRIORITY")?;
                            if !p.eq_ignore_ascii_case("PRIORITY") {
                                return Err(err("expected PRIORITY", Span::new(lx.file, pat..pat + p.len()), "here"));
                            }
                            match lx.next()? {
                                Some((Tok::Assign, _)) => {}
                                _ => return Err(err("expected `:=` after PRIORITY", lx.span(pat), "here")),
                            }
                            let (n, nat) = expect_word(lx, "a number")?;
                            priority = Some(n.parse::<i32>().map_err(|_| {
                                err(
                                    format!("`{n}` is not a priority"),
                                    Span::new(lx.file, nat..nat + n.len()),
                                    "priority",
                                )
                            })?);
                            expect_sym(lx, ')')?;
                        }
                        _ => lx.pos = save,
                    }
                    (w, wat) = expect_word(lx, "FROM")?;
                }
                if !w.eq_ignore_ascii_case("FROM") {
                    return Err(err("expected FROM", Span::new(lx.file, wat..wat + w.len()), "here"));
                }
                let from = step_list(lx)?;
                let (t, tat) = expect_word(lx, "TO")?;
                if !t.eq_ignore_ascii_case("TO") {
                    return Err(err("expected TO", Span::new(lx.file, tat..tat + t.len()), "here"));
                }
                let to = step_list(lx)?;
                let st = match lx.next()? {
                    Some((Tok::Assign, _)) => false,
                    Some((Tok::Sym(':'), _)) => true,
                    Some((_, a)) => {
                        return Err(err(
                            "expected `:=` and the condition (or `:` and a condition in ST)",
                            Span::new(lx.file, a..lx.pos),
                            "here",
                        ));
                    }
                    None => return Err(err("expected `:=` and the condition", lx.span(lx.pos), "end")),
                };
                let (c, cat) = if st { lx.st_condition()? } else { lx.condition()? };
                let lead = c.len() - c.trim_start().len();
                let text_c = c.trim().to_string();
                if text_c.is_empty() {
                    return Err(err(
                        "the condition is empty",
                        Span::new(lx.file, cat..lx.pos),
                        "condition",
                    ));
                }
                let cond_span = Span::new(lx.file, cat + lead..cat + lead + text_c.len());
                if !st {
                    expect_sym(lx, ';')?;
                }
                let (e, eat) = expect_word(lx, "END_TRANSITION")?;
                if !e.eq_ignore_ascii_case("END_TRANSITION") {
                    return Err(err(
                        "expected END_TRANSITION",
                        Span::new(lx.file, eat..eat + e.len()),
                        "here",
                    ));
                }
                sfc.transitions.push(SfcTransition {
                    name,
                    priority,
                    from,
                    to,
                    condition: Guard {
                        text: text_c,
                        span: cond_span,
                    },
                    st,
                    span: Span::new(lx.file, at..at + "TRANSITION".len()),
                });
            }
            _ => {
                return Err(err(
                    format!("expected INITIAL_STEP, STEP, ACTION or TRANSITION, found `{w}`"),
                    Span::new(lx.file, at..lx.pos),
                    "here",
                ));
            }
        }
    }
    Ok(())
}

fn step_list(lx: &mut Lexer) -> Result<Vec<(String, Span)>, Diagnostic> {
    let save = lx.pos;
    match lx.next()? {
        Some((Tok::Sym('('), _)) => {
            let mut out = Vec::new();
            loop {
                let (n, at) = expect_word(lx, "a step")?;
                out.push((n.clone(), Span::new(lx.file, at..at + n.len())));
                match lx.next()? {
                    Some((Tok::Sym(','), _)) => continue,
                    Some((Tok::Sym(')'), _)) => return Ok(out),
                    _ => return Err(err("expected `,` or `)` in a list of steps", lx.span(at), "here")),
                }
            }
        }
        _ => {
            lx.pos = save;
            let (n, at) = expect_word(lx, "a step")?;
            Ok(vec![(n.clone(), Span::new(lx.file, at..at + n.len()))])
        }
    }
}

/// The structure: one initial step, unique names, known steps, times where
/// the qualifier needs one and nowhere else.
fn check(sfc: &Sfc, file: FileId, diags: &mut Vec<Diagnostic>) {
    let st = |msg: String, span: Span, label: &str| Diagnostic::new(Code::SfcStructure, msg, span, label);
    let initials: Vec<&Step> = sfc.steps.iter().filter(|s| s.initial).collect();
    match initials.len() {
        0 => diags.push(st(
            "an SFC needs one INITIAL_STEP".into(),
            sfc.steps.first().map_or(Span::new(file, 0..0), |s| s.span),
            "no initial step",
        )),
        1 => {}
        _ => diags.push(st(
            format!("an SFC has one initial step; `{}` is another", initials[1].name),
            initials[1].span,
            "second initial step",
        )),
    }
    for (k, s) in sfc.steps.iter().enumerate() {
        if sfc.steps[..k].iter().any(|o| o.name.eq_ignore_ascii_case(&s.name)) {
            diags.push(st(format!("the step `{}` is declared twice", s.name), s.span, "again"));
        }
        for a in &s.actions {
            match (a.qualifier.timed(), a.time_ms) {
                (true, None) => diags.push(st(
                    format!(
                        "the qualifier {:?} needs a time: `{}({:?}, T#5s)`",
                        a.qualifier, a.action, a.qualifier
                    ),
                    a.span,
                    "no time",
                )),
                (false, Some(_)) => diags.push(st(
                    format!("the qualifier {:?} takes no time", a.qualifier),
                    a.span,
                    "time",
                )),
                _ => {}
            }
        }
    }
    // A transition without a name is `t<k>` (its place in the file, see
    // `to_net`): a named one must not take a name already in use.
    let mut ids: Vec<String> = Vec::new();
    for (k, t) in sfc.transitions.iter().enumerate() {
        let id = t.name.clone().unwrap_or_else(|| format!("t{}", k + 1));
        if let Some(first) = ids.iter().position(|i| i.eq_ignore_ascii_case(&id)) {
            diags.push(st(
                format!(
                    "the transition name `{id}` is already transition {}'s (an unnamed transition k is named t<k>)",
                    first + 1
                ),
                t.span,
                "again",
            ));
        }
        ids.push(id);
    }
    for (k, a) in sfc.actions.iter().enumerate() {
        if sfc.actions[..k].iter().any(|o| o.name.eq_ignore_ascii_case(&a.name)) {
            diags.push(st(
                format!("the action `{}` is declared twice", a.name),
                a.header,
                "again",
            ));
        }
    }
    let known = |n: &str| sfc.steps.iter().any(|s| s.name.eq_ignore_ascii_case(n));
    for t in &sfc.transitions {
        for (n, sp) in t.from.iter().chain(&t.to) {
            if !known(n) {
                diags.push(st(format!("no step `{n}`"), *sp, "unknown step"));
            }
        }
    }
}

impl Sfc {
    /// The chart as a 1-safe Petri-mode net: a place per step (marked when
    /// initial), a transition per transition (its condition as the guard,
    /// its priority kept, named `t<k>` unless named), arcs from its steps and
    /// to its steps. Names are the steps' own (case as declared).
    pub fn to_net(&self, id: &str, file: FileId) -> Net {
        let canonical = |n: &str| {
            self.steps
                .iter()
                .find(|s| s.name.eq_ignore_ascii_case(n))
                .map_or_else(|| n.to_string(), |s| s.name.clone())
        };
        let mut arcs = Vec::new();
        let transitions = self
            .transitions
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let tid = t.name.clone().unwrap_or_else(|| format!("t{}", k + 1));
                for (n, sp) in &t.from {
                    arcs.push(arc(format!("{tid}.in.{n}"), canonical(n), tid.clone(), *sp));
                }
                for (n, sp) in &t.to {
                    arcs.push(arc(format!("{tid}.out.{n}"), tid.clone(), canonical(n), *sp));
                }
                // An ST condition is computed into `<sfc>.<transition>.C`.
                let guard = if t.st {
                    Guard {
                        text: format!("{id}.{tid}.C"),
                        span: t.condition.span,
                    }
                } else {
                    t.condition.clone()
                };
                Transition {
                    id: tid,
                    name: None,
                    guard: Some(guard),
                    priority: t.priority,
                    kind: crate::ElementKind::Transition,
                    props: Default::default(),
                    extra: Extra::default(),
                    span: t.span,
                }
            })
            .collect();
        let mut net = Net::new(id);
        net.places = self
            .steps
            .iter()
            .map(|s| Place {
                id: s.name.clone(),
                name: None,
                initial: u32::from(s.initial),
                tag: None,
                kind: crate::ElementKind::State,
                props: Default::default(),
                script: None,
                extra: Extra::default(),
                span: s.span,
            })
            .collect();
        net.transitions = transitions;
        net.arcs = arcs;
        net.span = Span::new(file, 0..0);
        net
    }
}

fn arc(id: String, source: String, target: String, span: Span) -> Arc {
    Arc {
        id,
        source,
        target,
        weight: 1,
        kind: ArcKind::Normal,
        extra: Extra::default(),
        span,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn file() -> FileId {
        alba_diag::Files::new().add("seq.sfc", "")
    }

    #[test]
    fn a_transition_name_may_not_repeat_another_or_an_automatic_one() {
        let text = "INITIAL_STEP A: END_STEP\nSTEP B: END_STEP\n\
                    TRANSITION FROM A TO B := X; END_TRANSITION\n\
                    TRANSITION t1 (PRIORITY := 1) FROM B TO A := Y; END_TRANSITION\n";
        let e = parse(file(), text).expect_err("t1 is taken");
        assert!(
            e[0].message
                .contains("the transition name `t1` is already transition 1's"),
            "{}",
            e[0].message
        );
    }

    #[test]
    fn an_st_action_is_its_body_up_to_end_action_outside_comments_and_strings() {
        let text = "INITIAL_STEP A: Fill(N); END_STEP\n\
                    ACTION Fill:\n  (* END_ACTION *) x := 'END_ACTION'; // END_ACTION\n  y := 1;\nEND_ACTION\n\
                    TRANSITION FROM A TO A := FALSE; END_TRANSITION\n";
        let sfc = parse(file(), text).expect("parses");
        let a = sfc.st_action("fill").expect("the action");
        assert_eq!(&text[a.header.range()], "ACTION Fill:");
        let body = &text[a.body.range()];
        assert!(
            body.starts_with("\n  (* END_ACTION *)") && body.ends_with("y := 1;\n"),
            "{body:?}"
        );
        assert_eq!(sfc.transitions.len(), 1);
        // Twice the same name: E651; no END_ACTION: E650.
        let twice = text.replace("TRANSITION FROM", "ACTION FILL: END_ACTION\nTRANSITION FROM");
        let e = parse(file(), &twice).expect_err("twice");
        assert!(
            e[0].message.contains("the action `FILL` is declared twice"),
            "{}",
            e[0].message
        );
        let e = parse(file(), "INITIAL_STEP A: END_STEP ACTION Fill: x := 1;").expect_err("unended");
        assert_eq!(e[0].code, Code::SfcSyntax);
        assert!(e[0].message.contains("not ended by END_ACTION"), "{}", e[0].message);
    }

    #[test]
    fn a_condition_in_st_is_its_text_up_to_end_transition_and_a_flag_in_the_net() {
        let text = "INITIAL_STEP A: END_STEP\nSTEP B: END_STEP\n\
                    TRANSITION FROM A TO B : MIN(x, 3) > 2 (* ; END_TRANSITION *) END_TRANSITION\n\
                    TRANSITION go FROM B TO A := y; END_TRANSITION\n";
        let sfc = parse(file(), text).expect("parses");
        let t = &sfc.transitions[0];
        assert!(t.st && !sfc.transitions[1].st);
        assert_eq!(&text[t.condition.span.range()], "MIN(x, 3) > 2 (* ; END_TRANSITION *)");
        let net = sfc.to_net("seq", file());
        let g = |k: usize| net.transitions[k].guard.as_ref().map(|g| g.text.clone());
        assert_eq!(g(0).as_deref(), Some("seq.t1.C"));
        assert_eq!(g(1).as_deref(), Some("y"));
        let e = parse(file(), "INITIAL_STEP A: END_STEP TRANSITION FROM A TO A : x").expect_err("unended");
        assert!(e[0].message.contains("not ended by END_TRANSITION"), "{}", e[0].message);
    }

    #[test]
    fn a_chart_parses_into_a_one_safe_net() {
        let text = "INITIAL_STEP Idle: END_STEP\nSTEP A: Lamp(N); Alarm(D, T#2s); END_STEP\nSTEP B: END_STEP\n\
                    TRANSITION go (PRIORITY := 2) FROM Idle TO (A, B) := Start; END_TRANSITION\n\
                    TRANSITION FROM (a, b) TO idle := TRUE; END_TRANSITION\n";
        let sfc = parse(file(), text).expect("parses");
        assert_eq!(sfc.steps.len(), 3);
        assert_eq!(sfc.steps[1].actions[1].time_ms, Some(2000));
        let t = &sfc.transitions[0];
        assert_eq!(
            (t.name.as_deref(), t.priority, t.condition.text.as_str()),
            (Some("go"), Some(2), "Start")
        );
        assert_eq!(
            &text[t.condition.span.start as usize..t.condition.span.end as usize],
            "Start"
        );
        let net = sfc.to_net("seq", file());
        assert_eq!(net.places.iter().map(|p| p.initial).collect::<Vec<_>>(), [1, 0, 0]);
        assert_eq!(
            net.transitions.iter().map(|t| t.id.as_str()).collect::<Vec<_>>(),
            ["go", "t2"]
        );
        // Step names in transitions are case-insensitive; arcs use the declared case.
        assert!(net.arcs.iter().any(|a| a.source == "A" && a.target == "t2"));
        assert_eq!(net.arcs.len(), 6);
    }

    proptest! {
        /// Any text: a chart or located errors inside the text, never a panic.
        #[test]
        fn any_text_is_parsed_or_refused(text in "(INITIAL_STEP|STEP|END_STEP|TRANSITION|FROM|TO|END_TRANSITION|[A-Za-z(),;:=#*/ \n0-9])*") {
            match parse(file(), &text) {
                Ok(s) => prop_assert!(s.steps.iter().filter(|x| x.initial).count() == 1),
                Err(d) => for x in &d {
                    let sp = x.primary.as_ref().map(|l| l.span);
                    prop_assert!(sp.is_none_or(|s| s.end as usize <= text.len()));
                },
            }
        }
    }
}
