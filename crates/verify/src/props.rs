//! `properties.toml` (SPEC §10.6, docs/verify.md): `[[property]]` tables
//! with a `name` and one kind, `[[assume]] expr = EXPR`, and `[domain]`, the
//! values explored for each numeric input.

use crate::expr::{Cond, Lowering, Probes};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::{Layout, Place, Target};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// What a property says of every end of scan of every run.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// The expression is false at the end of every scan.
    Never(Cond),
    /// The expression is true at the end of every scan.
    Always(Cond),
    /// Whenever `trigger` is true at the end of a scan at time t, `then` is
    /// true at the end of a scan at a time in [t, t + within_ms].
    Response { trigger: Cond, then: Cond, within_ms: u64 },
    /// At most one of the expressions is true at the end of any scan.
    Mutex(Vec<Cond>),
    /// Some run reaches a scan whose end makes the expression true.
    Reachable(Cond),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Property {
    pub name: String,
    pub kind: Kind,
    /// Where its table starts in properties.toml.
    pub span: Span,
}

/// A numeric input and the values explored for it.
#[derive(Debug, Clone, PartialEq)]
pub struct Domain {
    pub name: String,
    pub place: Place,
    pub values: Vec<alba_model::Value>,
}

/// A parsed properties.toml.
#[derive(Debug, Clone)]
pub struct Properties {
    pub properties: Vec<Property>,
    /// Runs are restricted to those where every assumption holds at the end
    /// of every scan.
    pub assumes: Vec<Cond>,
    pub domains: Vec<Domain>,
    /// Every expression above, lowered onto the IR (expr.rs).
    pub probes: Probes,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    #[serde(default)]
    property: Vec<Spanned<RawProperty>>,
    #[serde(default)]
    assume: Vec<RawAssume>,
    #[serde(default)]
    domain: BTreeMap<String, Spanned<Vec<toml::Value>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProperty {
    name: String,
    never: Option<Spanned<String>>,
    always: Option<Spanned<String>>,
    reachable: Option<Spanned<String>>,
    mutex: Option<Vec<Spanned<String>>>,
    response: Option<Spanned<RawResponse>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawResponse {
    trigger: Spanned<String>,
    then: Spanned<String>,
    within_ms: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAssume {
    expr: Spanned<String>,
}

/// Parses properties.toml (`file` in the caller's `Files`) against a program's
/// layout, reporting every problem.
pub fn parse(text: &str, file: FileId, layout: &Layout) -> Result<Properties, Vec<Diagnostic>> {
    let raw: Raw = match toml::from_str(text) {
        Ok(r) => r,
        Err(e) => {
            let span = Span::new(file, e.span().unwrap_or(0..0));
            let msg = e.message().trim().to_string();
            let code = if msg.contains("missing field") || msg.contains("unknown field") || msg.contains("invalid type")
            {
                Code::ConfigField
            } else {
                Code::TomlSyntax
            };
            return Err(vec![
                Diagnostic::new(code, format!("properties.toml: {msg}"), span, "here").with_help(
                    "a property is `[[property]]` with `name` and one of `never`, `always`, `reachable` \
                     (an expression), `mutex` (a list of expressions) or `response = { trigger, then, within_ms }`",
                ),
            ]);
        }
    };
    let mut diags = Vec::new();
    let mut low = Lowering::new(layout);
    let mut one = |s: &Spanned<String>, diags: &mut Vec<Diagnostic>| -> Option<Cond> {
        // The string's text starts after its opening quote, when it is
        // written as it reads (no escapes, not multi-line); else errors
        // point at the whole string.
        let base = s.span().start + 1;
        let verbatim = text.get(base..base + s.get_ref().len()) == Some(s.get_ref().as_str());
        let whole = Span::new(file, s.span());
        match low.add(s.get_ref(), file, base, whole) {
            Ok(c) => Some(c),
            Err(ds) => {
                diags.extend(ds.into_iter().map(|mut d| {
                    if !verbatim && let Some(l) = d.primary.as_mut() {
                        l.span = whole;
                    }
                    d
                }));
                None
            }
        }
    };
    let mut out = (Vec::new(), Vec::new(), Vec::new());
    let mut names = std::collections::HashSet::new();
    for p in &raw.property {
        let span = Span::new(file, p.span());
        let r = p.get_ref();
        if r.name.trim().is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "a property needs a non-empty `name`",
                span,
                "here",
            ));
            continue;
        }
        if !names.insert(r.name.clone()) {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("two properties are named `{}`", r.name),
                span,
                "second one",
            ));
            continue;
        }
        let kinds = [
            r.never.is_some(),
            r.always.is_some(),
            r.reachable.is_some(),
            r.mutex.is_some(),
            r.response.is_some(),
        ]
        .iter()
        .filter(|k| **k)
        .count();
        if kinds != 1 {
            diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    format!("property `{}` has {kinds} kinds; it needs exactly one", r.name),
                    span,
                    "here",
                )
                .with_help("one of `never`, `always`, `reachable`, `mutex`, `response`"),
            );
            continue;
        }
        let kind = if let Some(e) = &r.never {
            one(e, &mut diags).map(Kind::Never)
        } else if let Some(e) = &r.always {
            one(e, &mut diags).map(Kind::Always)
        } else if let Some(e) = &r.reachable {
            one(e, &mut diags).map(Kind::Reachable)
        } else if let Some(list) = &r.mutex {
            if list.len() < 2 {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("property `{}`: a mutex lists at least two expressions", r.name),
                    span,
                    "here",
                ));
                None
            } else {
                let c: Vec<Option<Cond>> = list.iter().map(|e| one(e, &mut diags)).collect();
                c.into_iter().collect::<Option<Vec<_>>>().map(Kind::Mutex)
            }
        } else if let Some(resp) = &r.response {
            let rr = resp.get_ref();
            let (t, h) = (one(&rr.trigger, &mut diags), one(&rr.then, &mut diags));
            match (t, h) {
                (Some(trigger), Some(then)) => Some(Kind::Response {
                    trigger,
                    then,
                    within_ms: rr.within_ms,
                }),
                _ => None,
            }
        } else {
            None
        };
        if let Some(kind) = kind {
            out.0.push(Property {
                name: r.name.clone(),
                kind,
                span,
            });
        }
    }
    for a in &raw.assume {
        if let Some(c) = one(&a.expr, &mut diags) {
            out.1.push(c);
        }
    }
    for (name, values) in &raw.domain {
        let span = Span::new(file, values.span());
        let place = match layout.resolve(name) {
            Ok(Target::Value { place, .. }) if layout.is_output(place) => {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("[domain] `{name}` is an output, driven by the program, not an input"),
                    span,
                    "here",
                ));
                continue;
            }
            Ok(Target::Value { place, .. }) => place,
            Ok(_) => {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("[domain] `{name}` is a structure, not an input"),
                    span,
                    "here",
                ));
                continue;
            }
            Err(e) => {
                diags.push(Diagnostic::new(
                    Code::UnknownTag,
                    format!("[domain]: {e}"),
                    span,
                    "here",
                ));
                continue;
            }
        };
        let mut vals = Vec::new();
        for v in values.get_ref() {
            let text = match v {
                toml::Value::Integer(i) => i.to_string(),
                toml::Value::Float(f) => f.to_string(),
                toml::Value::Boolean(b) => b.to_string(),
                other => other.to_string(),
            };
            match alba_model::Value::parse(&text, place.data_type()) {
                Ok(v) => vals.push(v),
                Err(m) => diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("[domain] `{name}`: bad value {text}: {m}"),
                    span,
                    "here",
                )),
            }
        }
        if vals.is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("[domain] `{name}` lists no value"),
                span,
                "here",
            ));
            continue;
        }
        out.2.push(Domain {
            name: name.clone(),
            place,
            values: vals,
        });
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    Ok(Properties {
        properties: out.0,
        assumes: out.1,
        domains: out.2,
        probes: low.finish(),
    })
}
