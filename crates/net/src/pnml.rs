//! PNML (ISO/IEC 15909-2, ptnet grammar 2009): load and save.
//!
//! The mapping is written down in docs/nets.md, section "pnml". In short:
//! one `<net>` per file; pages are flattened (the first page's id is kept
//! and written back; reference nodes are resolved to the node they stand
//! for); `<name><text>`, `<initialMarking><text>` and `<inscription><text>`
//! are read, PIPE's legacy `<value>Default,N</value>` too; `<graphics>` and
//! other tools' `<toolspecific>` blocks are kept verbatim; Alba's data is in
//! `<toolspecific tool="alba" version="1">`.

use crate::model::*;
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_xml::{self as xml, Elem};
use std::collections::{BTreeMap, HashMap, HashSet};

/// Largest file read (bytes).
pub const MAX_FILE_BYTES: usize = 16 * 1024 * 1024;
/// Largest initial marking.
pub const MAX_MARKING: u32 = 1_000_000;
/// Largest arc weight.
pub const MAX_WEIGHT: u32 = 1_000_000;
/// The value of `tool` for Alba's blocks, and the version it reads.
pub const TOOL: &str = "alba";
pub const TOOL_VERSION: &str = "1";

/// Whether a diagnostic of [`load`] is a warning (the net still loads).
pub fn is_warning(d: &Diagnostic) -> bool {
    d.code == Code::PnmlIgnored
}

struct Loader<'a> {
    file: FileId,
    text: &'a str,
    diags: Vec<Diagnostic>,
    warned: HashSet<String>,
    ids: HashMap<String, Span>,
    /// Reference node id → (referenced id, span).
    refs: HashMap<String, (String, Span)>,
    /// Reference node id → the node it stands for (`None`: a cycle).
    resolved: HashMap<String, Option<String>>,
    net: Net,
    first_page: bool,
}

fn parse_int(s: &str) -> Result<i64, String> {
    let t = s.trim();
    if t.is_empty() {
        return Err("is empty".into());
    }
    if let Ok(n) = t.parse::<i64>() {
        return Ok(n);
    }
    if t.trim_start_matches(['-', '+']).chars().all(|c| c.is_ascii_digit()) {
        return Err(format!("`{t}` is far too large"));
    }
    if t.parse::<f64>().is_ok() {
        return Err(format!("`{t}` is not a whole number"));
    }
    Err(format!("`{t}` is not a number"))
}

impl<'a> Loader<'a> {
    fn span(&self, a: usize, b: usize) -> Span {
        let a = a.min(self.text.len());
        let b = b.clamp(a, self.text.len());
        Span::new(self.file, a..b)
    }

    fn tag_span(&self, e: &Elem) -> Span {
        self.span(e.start, e.start_end)
    }

    fn text_span(&self, e: &Elem) -> Span {
        match e.text_range {
            Some((a, b)) => self.span(a, b),
            None => self.tag_span(e),
        }
    }

    /// The span of attribute `name` in `e`'s start tag (the tag if not found).
    fn attr_span(&self, e: &Elem, name: &str) -> Span {
        let tag = &self.text[e.start.min(self.text.len())..e.start_end.min(self.text.len())];
        let mut from = 0;
        while let Some(i) = tag[from..].find(name) {
            let at = from + i;
            let before_ok = at > 0 && tag.as_bytes()[at - 1].is_ascii_whitespace();
            let rest = tag[at + name.len()..].trim_start();
            if before_ok && rest.starts_with('=') {
                // The whole `name="value"`.
                let q = tag[at..].find(['"', '\'']).map(|q| at + q);
                if let Some(q) = q {
                    let quote = tag.as_bytes()[q] as char;
                    if let Some(close) = tag[q + 1..].find(quote) {
                        return self.span(e.start + at, e.start + q + 2 + close);
                    }
                }
                return self.span(e.start + at, e.start + at + name.len());
            }
            from = at + name.len();
        }
        self.tag_span(e)
    }

    fn raw(&self, e: &Elem) -> String {
        self.text[e.start.min(self.text.len())..e.end.min(self.text.len())].to_string()
    }

    fn error(&mut self, code: Code, msg: impl Into<String>, span: Span, label: impl Into<String>) -> &mut Diagnostic {
        self.diags.push(Diagnostic::new(code, msg, span, label));
        let last = self.diags.len() - 1;
        &mut self.diags[last]
    }

    fn help(&mut self, help: &str) {
        if let Some(d) = self.diags.last_mut() {
            d.help = Some(help.to_string());
        }
    }

    fn ignored(&mut self, e: &Elem, inside: &str) {
        if self.warned.insert(format!("{inside}/{}", e.name)) {
            let span = self.tag_span(e);
            self.error(
                Code::PnmlIgnored,
                format!(
                    "<{}> in <{inside}> is not part of a place/transition net: ignored",
                    e.name
                ),
                span,
                "ignored",
            );
            self.help(
                "Alba keeps only other tools' <toolspecific> blocks; this element is dropped when the net is saved",
            );
        }
    }

    /// Registers an id; reports a duplicate.
    fn id(&mut self, e: &Elem) -> Option<String> {
        let Some(id) = e.attr("id") else {
            let span = self.tag_span(e);
            self.error(
                Code::PnmlStructure,
                format!("<{}> has no `id`", e.name),
                span,
                "id missing",
            );
            self.help("every PNML node, arc and page has an id unique in the document");
            return None;
        };
        let span = self.attr_span(e, "id");
        if id.trim().is_empty() {
            self.error(
                Code::PnmlStructure,
                format!("<{}> has an empty `id`", e.name),
                span,
                "empty id",
            );
            self.help("every PNML node, arc and page has a non-empty id unique in the document");
            return None;
        }
        if let Some(first) = self.ids.get(id).copied() {
            let d = Diagnostic::new(
                Code::PnmlDuplicateId,
                format!("the id `{id}` is used twice"),
                span,
                "second use",
            )
            .with_note(first, "first use")
            .with_help("ids are unique in the whole PNML document (places, transitions, arcs and pages)");
            self.diags.push(d);
            return None;
        }
        self.ids.insert(id.to_string(), span);
        Some(id.to_string())
    }

    /// `<name><text>..</text></name>` and friends: the text child.
    fn label_text<'e>(&mut self, label: &'e Elem) -> Option<&'e Elem> {
        match label.child("text") {
            Some(t) => Some(t),
            None => {
                // PIPE's legacy form: <value>Default,3</value>.
                if let Some(v) = label.child("value") {
                    return Some(v);
                }
                let span = self.tag_span(label);
                self.error(
                    Code::PnmlStructure,
                    format!("<{}> has no <text>", label.name),
                    span,
                    "text missing",
                );
                self.help(&format!("write <{0}><text>...</text></{0}>", label.name));
                None
            }
        }
    }

    fn once(&mut self, seen: &mut HashSet<&'static str>, key: &'static str, e: &Elem) -> bool {
        if seen.insert(key) {
            return true;
        }
        let span = self.tag_span(e);
        self.error(
            Code::PnmlStructure,
            format!("a second <{}> on one element", e.name),
            span,
            "second one",
        );
        self.help("each label (name, initialMarking, inscription) appears at most once on an element; remove one");
        false
    }

    fn keep_label_graphics(&mut self, label: &Elem, extra: &mut Extra) {
        if let Some(g) = label.child("graphics") {
            extra.label_graphics.insert(label.name.clone(), self.raw(g));
        }
    }

    fn number(&mut self, t: &Elem, what: &str, lo: i64, hi: i64) -> Option<i64> {
        // PIPE: "Default,3" (a token class, then the count).
        let text = if t.name == "value" {
            t.text.rsplit(',').next().unwrap_or("").to_string()
        } else {
            t.text.clone()
        };
        let span = self.text_span(t);
        match parse_int(&text) {
            Ok(n) if n < lo => {
                self.error(Code::PnmlNumber, format!("{what} {n} is below {lo}"), span, "too small");
                self.help(&format!("{what} is a whole number from {lo} to {hi}"));
                None
            }
            Ok(n) if n > hi => {
                self.error(Code::PnmlNumber, format!("{what} {n} is above {hi}"), span, "too large");
                self.help(&format!("{what} is a whole number from {lo} to {hi}"));
                None
            }
            Ok(n) => Some(n),
            Err(why) => {
                self.error(Code::PnmlNumber, format!("{what} {why}"), span, "not a whole number");
                self.help(&format!("{what} is a whole number from {lo} to {hi}"));
                None
            }
        }
    }

    fn graphics(&mut self, g: &Elem) -> Graphics {
        let mut position = None;
        if let Some(p) = g.child("position") {
            let x = p.attr("x").and_then(|v| v.trim().parse::<f64>().ok());
            let y = p.attr("y").and_then(|v| v.trim().parse::<f64>().ok());
            match (x, y) {
                (Some(x), Some(y)) if x.is_finite() && y.is_finite() => position = Some(Point { x, y }),
                _ => {
                    let span = self.tag_span(p);
                    self.error(
                        Code::PnmlNumber,
                        "a <position> needs decimal `x` and `y`",
                        span,
                        "bad position",
                    );
                    self.help("write <position x=\"10.5\" y=\"20\"/>");
                }
            }
        }
        Graphics {
            position,
            raw: Some(self.raw(g)),
        }
    }

    /// A `<toolspecific>`: Alba's (returns it) or kept verbatim.
    fn toolspecific<'e>(&mut self, e: &'e Elem, extra: &mut Extra, alba: &mut Option<&'e Elem>) {
        if e.attr("tool") == Some(TOOL) && e.attr("version").is_none_or(|v| v.trim() == TOOL_VERSION) {
            if alba.is_some() {
                let span = self.tag_span(e);
                self.error(
                    Code::PnmlAlba,
                    "a second Alba <toolspecific> block on one element",
                    span,
                    "second block",
                );
                self.help("merge them into one");
                return;
            }
            *alba = Some(e);
        } else {
            if e.attr("tool") == Some(TOOL) {
                let span = self.attr_span(e, "version");
                self.error(
                    Code::PnmlIgnored,
                    format!(
                        "Alba <toolspecific> version `{}` is not version 1: kept unread",
                        e.attr("version").unwrap_or("")
                    ),
                    span,
                    "unknown version",
                );
            }
            extra.toolspecific.push(self.raw(e));
        }
    }

    /// Children of an Alba block, each name at most once except those in
    /// `many`; reports unknown ones.
    fn alba_children<'e>(&mut self, block: &'e Elem, known: &[&str], many: &[&str]) -> Vec<&'e Elem> {
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for c in &block.children {
            if !known.contains(&c.name.as_str()) {
                let span = self.tag_span(c);
                self.error(
                    Code::PnmlAlba,
                    format!("<{}> is not Alba data here", c.name),
                    span,
                    "unknown",
                );
                self.help(&format!("Alba's block here may hold: {}", known.join(", ")));
                continue;
            }
            if !many.contains(&c.name.as_str()) && !seen.insert(c.name.clone()) {
                let span = self.tag_span(c);
                self.error(Code::PnmlAlba, format!("a second <{}>", c.name), span, "second one");
                self.help("this entry appears at most once in Alba's block; remove one");
                continue;
            }
            out.push(c);
        }
        out
    }

    fn kind(&mut self, c: &Elem, ok: fn(ElementKind) -> bool, of: &str) -> Option<ElementKind> {
        match ElementKind::parse(&c.text).filter(|k| ok(*k)) {
            Some(k) => Some(k),
            None => {
                let span = self.text_span(c);
                let allowed: Vec<&str> = ElementKind::ALL
                    .iter()
                    .filter(|k| ok(**k))
                    .map(|k| k.as_str())
                    .collect();
                self.error(
                    Code::PnmlAlba,
                    format!("`{}` is not a kind of {of}", c.text.trim()),
                    span,
                    "unknown kind",
                );
                self.help(&format!("a {of} is one of: {}", allowed.join(", ")));
                None
            }
        }
    }

    fn prop(&mut self, c: &Elem, props: &mut BTreeMap<String, String>) {
        match c.attr("name") {
            Some(n) if !n.trim().is_empty() => {
                if props.insert(n.to_string(), c.text.clone()).is_some() {
                    let span = self.attr_span(c, "name");
                    self.error(
                        Code::PnmlAlba,
                        format!("the property `{n}` is given twice"),
                        span,
                        "second one",
                    );
                    self.help("each property name appears once; remove one");
                }
            }
            _ => {
                let span = self.tag_span(c);
                self.error(Code::PnmlAlba, "a <prop> needs a `name`", span, "no name");
                self.help("write <prop name=\"NAME\">value</prop>");
            }
        }
    }

    fn load_net(&mut self, e: &Elem) {
        self.net.span = self.tag_span(e);
        if let Some(id) = self.id(e) {
            self.net.id = id;
        }
        match e.attr("type") {
            Some(t) => {
                self.net.net_type = t.to_string();
                let lower = t.to_ascii_lowercase();
                if !(lower.contains("ptnet") || lower.contains("p/t") || lower.contains("pt net")) {
                    let span = self.attr_span(e, "type");
                    self.error(
                        Code::PnmlIgnored,
                        format!("net type `{t}` is not a place/transition net: read as one"),
                        span,
                        "not ptnet",
                    );
                }
            }
            None => {
                let span = self.tag_span(e);
                self.error(Code::PnmlStructure, "<net> has no `type`", span, "type missing");
                self.help(&format!("write type=\"{PTNET_TYPE}\""));
            }
        }
        let mut seen = HashSet::new();
        let mut alba = None;
        let mut extra = Extra::default();
        for c in &e.children {
            match c.name.as_str() {
                "name" => {
                    if self.once(&mut seen, "name", c)
                        && let Some(t) = self.label_text(c)
                    {
                        self.net.name = Some(t.text.clone());
                        self.keep_label_graphics(c, &mut extra);
                    }
                }
                "page" => self.page(c),
                "toolspecific" => self.toolspecific(c, &mut extra, &mut alba),
                "graphics" => extra.graphics = Some(self.graphics(c)),
                // Nodes straight under <net> (older PNML, PIPE 2/3).
                "place" | "transition" | "arc" | "referencePlace" | "referenceTransition" => self.node(c),
                _ => self.ignored(c, "net"),
            }
        }
        self.net.extra = extra;
        if let Some(block) = alba {
            for c in self.alba_children(block, &["mode", "widget"], &["widget"]) {
                match c.name.as_str() {
                    "mode" => match Mode::parse(&c.text) {
                        Some(m) => self.net.mode = m,
                        None => {
                            let span = self.text_span(c);
                            self.error(
                                Code::PnmlAlba,
                                format!("`{}` is not a mode", c.text.trim()),
                                span,
                                "unknown mode",
                            );
                            self.help("<mode> is petri or normal");
                        }
                    },
                    _ => self.widget(c),
                }
            }
        }
    }

    fn widget(&mut self, c: &Elem) {
        let Some(id) = self.id(c) else { return };
        let kind = match c
            .attr("kind")
            .and_then(ElementKind::parse)
            .filter(|k| k.is_widget_kind())
        {
            Some(k) => k,
            None => {
                let span = self.attr_span(c, "kind");
                self.error(
                    Code::PnmlAlba,
                    "a <widget> needs a `kind`: button, display, plot or label",
                    span,
                    "bad kind",
                );
                self.help("write <widget id=\"w1\" kind=\"button\" tag=\"Start\">caption</widget>");
                return;
            }
        };
        let position = match (c.attr("x"), c.attr("y")) {
            (None, None) => None,
            (x, y) => {
                let x = x.and_then(|v| v.trim().parse::<f64>().ok()).filter(|v| v.is_finite());
                let y = y.and_then(|v| v.trim().parse::<f64>().ok()).filter(|v| v.is_finite());
                match (x, y) {
                    (Some(x), Some(y)) => Some(Point { x, y }),
                    _ => {
                        let span = self.tag_span(c);
                        self.error(
                            Code::PnmlNumber,
                            "a <widget> needs decimal `x` and `y`",
                            span,
                            "bad position",
                        );
                        self.help("give both x and y as decimal numbers, or neither");
                        None
                    }
                }
            }
        };
        let style = c
            .attrs
            .iter()
            .filter(|(k, _)| !["id", "kind", "tag", "x", "y"].contains(&k.as_str()))
            .cloned()
            .collect();
        self.net.widgets.push(Widget {
            id,
            kind,
            tag: c.attr("tag").map(str::to_string),
            text: (!c.text.is_empty()).then(|| c.text.clone()),
            position,
            style,
        });
    }

    fn page(&mut self, e: &Elem) {
        let id = self.id(e);
        let first = self.first_page;
        if first {
            self.first_page = false;
            if let Some(id) = &id {
                self.net.page_id = id.clone();
            }
        }
        let mut extra = Extra::default();
        let mut seen = HashSet::new();
        for c in &e.children {
            match c.name.as_str() {
                "page" => self.page(c),
                "place" | "transition" | "arc" | "referencePlace" | "referenceTransition" => self.node(c),
                // The first page's name, graphics and other tools' blocks
                // are kept; nested pages are flattened into it, so theirs
                // are dropped with a warning (docs/nets.md).
                "name" | "graphics" | "toolspecific" if first => match c.name.as_str() {
                    "name" => {
                        if self.once(&mut seen, "name", c)
                            && let Some(t) = self.label_text(c)
                        {
                            self.net.page_name = Some(t.text.clone());
                            self.keep_label_graphics(c, &mut extra);
                        }
                    }
                    "graphics" => extra.graphics = Some(self.graphics(c)),
                    _ => extra.toolspecific.push(self.raw(c)),
                },
                "name" | "graphics" | "toolspecific" => {
                    if self.warned.insert(format!("nested page/{}", c.name)) {
                        let span = self.tag_span(c);
                        self.error(
                            Code::PnmlIgnored,
                            format!(
                                "the <{}> of a nested page is dropped: pages are flattened into the first",
                                c.name
                            ),
                            span,
                            "dropped",
                        );
                    }
                }
                _ => self.ignored(c, "page"),
            }
        }
        if first {
            self.net.page_extra = extra;
        }
    }

    fn node(&mut self, e: &Elem) {
        match e.name.as_str() {
            "place" => self.place(e),
            "transition" => self.transition(e),
            "arc" => self.arc(e),
            _ => {
                let Some(id) = self.id(e) else { return };
                match e.attr("ref") {
                    Some(r) => {
                        let span = self.attr_span(e, "ref");
                        self.refs.insert(id, (r.to_string(), span));
                    }
                    None => {
                        let span = self.tag_span(e);
                        self.error(
                            Code::PnmlStructure,
                            format!("<{}> has no `ref`", e.name),
                            span,
                            "ref missing",
                        );
                        self.help("a reference node names the node it stands for: ref=\"ID\"");
                    }
                }
            }
        }
    }

    fn place(&mut self, e: &Elem) {
        let id = self.id(e);
        let mut p = Place::new(id.clone().unwrap_or_default(), 0);
        p.span = self.tag_span(e);
        let mut seen = HashSet::new();
        let mut alba = None;
        let mut extra = Extra::default();
        for c in &e.children {
            match c.name.as_str() {
                "name" => {
                    if self.once(&mut seen, "name", c)
                        && let Some(t) = self.label_text(c)
                    {
                        p.name = Some(t.text.clone());
                        self.keep_label_graphics(c, &mut extra);
                    }
                }
                "initialMarking" => {
                    if self.once(&mut seen, "initialMarking", c)
                        && let Some(t) = self.label_text(c)
                    {
                        if let Some(n) = self.number(t, "an initial marking", 0, MAX_MARKING as i64) {
                            p.initial = n as u32;
                        }
                        self.keep_label_graphics(c, &mut extra);
                    }
                }
                "graphics" => extra.graphics = Some(self.graphics(c)),
                "toolspecific" => self.toolspecific(c, &mut extra, &mut alba),
                _ => self.ignored(c, "place"),
            }
        }
        p.extra = extra;
        if let Some(block) = alba {
            for c in self.alba_children(block, &["tag", "kind", "prop", "script"], &["prop"]) {
                match c.name.as_str() {
                    "tag" => {
                        let t = c.text.trim();
                        if t.is_empty() {
                            let span = self.tag_span(c);
                            self.error(Code::PnmlAlba, "an empty <tag>", span, "no tag name");
                            self.help("name a BOOL tag, or leave <tag> out");
                        } else {
                            p.tag = Some(t.to_string());
                        }
                    }
                    "kind" => {
                        if let Some(k) = self.kind(c, ElementKind::is_place_kind, "place") {
                            p.kind = k;
                        }
                    }
                    "script" => p.script = Some(c.text.clone()),
                    _ => self.prop(c, &mut p.props),
                }
            }
        }
        if id.is_some() {
            self.net.places.push(p);
        }
    }

    fn transition(&mut self, e: &Elem) {
        let id = self.id(e);
        let mut t = Transition::new(id.clone().unwrap_or_default());
        t.span = self.tag_span(e);
        let mut seen = HashSet::new();
        let mut alba = None;
        let mut extra = Extra::default();
        for c in &e.children {
            match c.name.as_str() {
                "name" => {
                    if self.once(&mut seen, "name", c)
                        && let Some(x) = self.label_text(c)
                    {
                        t.name = Some(x.text.clone());
                        self.keep_label_graphics(c, &mut extra);
                    }
                }
                "graphics" => extra.graphics = Some(self.graphics(c)),
                "toolspecific" => self.toolspecific(c, &mut extra, &mut alba),
                _ => self.ignored(c, "transition"),
            }
        }
        t.extra = extra;
        if let Some(block) = alba {
            for c in self.alba_children(block, &["guard", "priority", "kind", "prop"], &["prop"]) {
                match c.name.as_str() {
                    "guard" => {
                        if c.text.trim().is_empty() {
                            let span = self.tag_span(c);
                            self.error(Code::PnmlAlba, "an empty <guard>", span, "no expression");
                            self.help("leave the guard out for a transition that is always allowed to fire");
                        } else {
                            t.guard = Some(Guard {
                                text: c.text.clone(),
                                span: self.text_span(c),
                            });
                        }
                    }
                    "priority" => {
                        if let Some(n) = self.number(c, "a priority", i32::MIN as i64, i32::MAX as i64) {
                            t.priority = Some(n as i32);
                        }
                    }
                    "kind" => {
                        if let Some(k) = self.kind(c, ElementKind::is_transition_kind, "transition") {
                            t.kind = k;
                        }
                    }
                    _ => self.prop(c, &mut t.props),
                }
            }
        }
        if id.is_some() {
            self.net.transitions.push(t);
        }
    }

    fn arc(&mut self, e: &Elem) {
        let id = self.id(e);
        let (source, target) = (e.attr("source"), e.attr("target"));
        let (Some(source), Some(target)) = (source, target) else {
            let span = self.tag_span(e);
            self.error(
                Code::PnmlStructure,
                "an <arc> needs `source` and `target`",
                span,
                "source or target missing",
            );
            self.help("write <arc id=\"a1\" source=\"PLACE\" target=\"TRANSITION\">");
            return;
        };
        let mut a = Arc::new(id.clone().unwrap_or_default(), source, target, 1);
        a.span = self.tag_span(e);
        let mut seen = HashSet::new();
        let mut alba = None;
        let mut extra = Extra::default();
        for c in &e.children {
            match c.name.as_str() {
                "inscription" => {
                    if self.once(&mut seen, "inscription", c)
                        && let Some(t) = self.label_text(c)
                    {
                        if let Some(n) = self.number(t, "an arc weight", 1, MAX_WEIGHT as i64) {
                            a.weight = n as u32;
                        }
                        self.keep_label_graphics(c, &mut extra);
                    }
                }
                "graphics" => extra.graphics = Some(self.graphics(c)),
                "toolspecific" => self.toolspecific(c, &mut extra, &mut alba),
                // PIPE: <type value="inhibitor"/>.
                "type" if c.attr("value").is_some() => match c.attr("value").and_then(ArcKind::parse) {
                    Some(k) => a.kind = k,
                    None => {
                        let span = self.attr_span(c, "value");
                        self.error(
                            Code::PnmlAlba,
                            "an arc type is normal, inhibitor or read",
                            span,
                            "unknown",
                        );
                        self.help("write <type value=\"normal\"/> or <type value=\"inhibitor\"/>");
                    }
                },
                _ => self.ignored(c, "arc"),
            }
        }
        a.extra = extra;
        if let Some(block) = alba {
            for c in self.alba_children(block, &["kind"], &[]) {
                match ArcKind::parse(&c.text) {
                    Some(k) => a.kind = k,
                    None => {
                        let span = self.text_span(c);
                        self.error(
                            Code::PnmlAlba,
                            format!("`{}` is not an arc kind", c.text.trim()),
                            span,
                            "unknown",
                        );
                        self.help("an arc's <kind> is normal, inhibitor or read");
                    }
                }
            }
        }
        if id.is_some() {
            self.net.arcs.push(a);
        }
    }

    /// Follows reference nodes to the node they stand for.
    /// Follows reference nodes to the node they stand for (`None` for a
    /// cycle). Results are remembered for every node on the way, so a long
    /// chain named by many arcs costs its length once, not once per arc.
    fn resolve(&mut self, id: &str, span: Span) -> Option<String> {
        if !self.refs.contains_key(id) {
            return Some(id.to_string());
        }
        let result = match self.resolved.get(id) {
            Some(r) => r.clone(),
            None => {
                let mut path = Vec::new();
                let mut on_path = HashSet::new();
                let mut cur = id.to_string();
                let result = loop {
                    if let Some(r) = self.resolved.get(&cur) {
                        break r.clone();
                    }
                    let Some((next, _)) = self.refs.get(&cur) else {
                        break Some(cur);
                    };
                    if !on_path.insert(cur.clone()) {
                        break None;
                    }
                    let next = next.clone();
                    path.push(cur);
                    cur = next;
                };
                for p in path {
                    self.resolved.insert(p, result.clone());
                }
                result
            }
        };
        if result.is_none() {
            self.error(
                Code::PnmlArc,
                format!("the reference `{id}` refers to itself in a cycle"),
                span,
                "cyclic reference",
            );
            self.help("a chain of reference nodes must end at a place or transition");
        }
        result
    }

    fn check_arcs(&mut self) {
        let places: HashSet<String> = self.net.places.iter().map(|p| p.id.clone()).collect();
        let transitions: HashSet<String> = self.net.transitions.iter().map(|t| t.id.clone()).collect();
        let mut pairs: HashMap<(String, String), Span> = HashMap::new();
        let mut arcs = std::mem::take(&mut self.net.arcs);
        let mut ok = Vec::with_capacity(arcs.len());
        for mut a in arcs.drain(..) {
            let e_span = a.span;
            let s_span = self.attr_in(e_span, "source");
            let t_span = self.attr_in(e_span, "target");
            let (Some(s), Some(t)) = (self.resolve(&a.source, s_span), self.resolve(&a.target, t_span)) else {
                continue;
            };
            let node = |id: &str| {
                if places.contains(id) {
                    Some(true)
                } else if transitions.contains(id) {
                    Some(false)
                } else {
                    None
                }
            };
            let (sk, tk) = (node(&s), node(&t));
            let mut bad = false;
            for (id, k, sp, what) in [(&a.source, sk, s_span, "source"), (&a.target, tk, t_span, "target")] {
                if k.is_none() {
                    bad = true;
                    let d = Diagnostic::new(
                        Code::PnmlArc,
                        format!(
                            "arc `{}`: its {what} `{id}` is not a place or transition of the net",
                            a.id
                        ),
                        sp,
                        "unknown node",
                    )
                    .with_help("check the id; arcs name nodes by their `id`");
                    self.diags.push(d);
                }
            }
            if bad {
                continue;
            }
            if sk == tk {
                let both = if sk == Some(true) { "places" } else { "transitions" };
                let d = Diagnostic::new(
                    Code::PnmlArc,
                    format!("arc `{}` joins two {both} (`{}` → `{}`)", a.id, a.source, a.target),
                    e_span,
                    "not a place and a transition",
                )
                .with_help("an arc goes from a place to a transition or from a transition to a place");
                self.diags.push(d);
                continue;
            }
            if a.kind != ArcKind::Normal && sk != Some(true) {
                let d = Diagnostic::new(
                    Code::PnmlAlba,
                    format!(
                        "arc `{}`: {} arcs go from a place to a transition",
                        a.id,
                        a.kind.as_str()
                    ),
                    e_span,
                    "wrong direction",
                )
                .with_help("draw it from the place to the transition it tests, or make it a normal arc");
                self.diags.push(d);
                continue;
            }
            let key = (s.clone(), t.clone());
            if let Some(first) = pairs.get(&key).copied() {
                let d = Diagnostic::new(
                    Code::PnmlArc,
                    format!("a second arc from `{s}` to `{t}`"),
                    e_span,
                    "second arc",
                )
                .with_note(first, "first arc")
                .with_help("give one arc the summed weight");
                self.diags.push(d);
                continue;
            }
            pairs.insert(key, e_span);
            a.source = s;
            a.target = t;
            ok.push(a);
        }
        self.net.arcs = ok;
    }

    fn attr_in(&self, tag: Span, name: &str) -> Span {
        let e = Elem {
            name: String::new(),
            attrs: Vec::new(),
            children: Vec::new(),
            text: String::new(),
            text_range: None,
            start: tag.start as usize,
            start_end: tag.end as usize,
            end: tag.end as usize,
        };
        self.attr_span(&e, name)
    }
}

/// Loads a PNML document. Returns the net when there is no error (warnings,
/// see [`is_warning`], may come with it) and every diagnostic found.
pub fn load(file: FileId, text: &str) -> (Option<Net>, Vec<Diagnostic>) {
    let whole = Span::new(file, 0..0);
    if text.len() > MAX_FILE_BYTES {
        let d = Diagnostic::new(
            Code::PnmlLimit,
            format!(
                "the file has {} bytes; Alba reads PNML files up to {} MiB",
                text.len(),
                MAX_FILE_BYTES / (1024 * 1024)
            ),
            whole,
            "too large",
        )
        .with_help("split the model, or remove what it does not need (large graphics, other tools' data)");
        return (None, vec![d]);
    }
    let root = match xml::parse(text, &crate::XML_LIMITS) {
        Ok(r) => r,
        Err(err) => {
            let off = err.offset.min(text.len());
            let off = (0..=off).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
            let end = (off + 1..=text.len())
                .find(|&i| text.is_char_boundary(i))
                .unwrap_or(off);
            let code = if err.limit { Code::PnmlLimit } else { Code::PnmlSyntax };
            let d = Diagnostic::new(
                code,
                if err.limit {
                    format!("the file is too large to read: {}", err.message)
                } else {
                    format!("not well-formed XML: {}", err.message)
                },
                Span::new(file, off..end),
                "here",
            )
            .with_help(if err.limit {
                "split the model, or flatten what is nested so deep"
            } else {
                "PNML is XML: every tag closed in order, attribute values quoted, `&` and `<` in text written `&amp;` and `&lt;`"
            });
            return (None, vec![d]);
        }
    };
    let mut l = Loader {
        file,
        text,
        diags: Vec::new(),
        warned: HashSet::new(),
        ids: HashMap::new(),
        refs: HashMap::new(),
        resolved: HashMap::new(),
        net: Net::new(""),
        first_page: true,
    };
    if root.name != "pnml" {
        let span = l.tag_span(&root);
        l.error(
            Code::PnmlStructure,
            format!("the root element is <{}>, not <pnml>", root.name),
            span,
            "not PNML",
        );
        l.help("a PNML file is <pnml><net id=\"..\" type=\"..\">...</net></pnml>");
        return (None, l.diags);
    }
    let nets: Vec<&Elem> = root.children.iter().filter(|c| c.name == "net").collect();
    for c in root.children.iter().filter(|c| c.name != "net") {
        l.ignored(c, "pnml");
    }
    match nets.as_slice() {
        [] => {
            let span = l.tag_span(&root);
            l.error(Code::PnmlStructure, "the document has no <net>", span, "no net");
            l.help("a PNML file is <pnml><net id=\"..\" type=\"..\">...</net></pnml>");
            return (None, l.diags);
        }
        [net]
            if net
                .attr("type")
                .is_some_and(|t| t.to_ascii_lowercase().contains("symmetricnet")) =>
        {
            let span = l.attr_span(net, "type");
            l.error(
                Code::PnmlStructure,
                "a coloured net (symmetric net): the editor and the scan read place/transition nets",
                span,
                "coloured net",
            );
            l.help("`alba analyze` unfolds it to a place/transition net (docs/nets.md, \"Coloured nets\")");
            return (None, l.diags);
        }
        [net] => {
            for e in [&root, *net] {
                for (k, v) in &e.attrs {
                    if k.starts_with("xmlns:") && !l.net.namespaces.iter().any(|(n, _)| n == k) {
                        l.net.namespaces.push((k.clone(), v.clone()));
                    }
                }
            }
            l.load_net(net)
        }
        [_, second, ..] => {
            let span = l.tag_span(second);
            l.error(
                Code::PnmlStructure,
                "a second <net>: Alba reads one net per file",
                span,
                "second net",
            );
            l.help("put each net in its own .pnml file");
            return (None, l.diags);
        }
    }
    // Reference nodes must refer to a node.
    let refs: Vec<(String, String, Span)> = l.refs.iter().map(|(k, (v, s))| (k.clone(), v.clone(), *s)).collect();
    for (id, target, span) in refs {
        if !l.ids.contains_key(&target) {
            l.error(
                Code::PnmlArc,
                format!("the reference node `{id}` refers to `{target}`, which is not in the document"),
                span,
                "unknown node",
            );
            l.help("ref names the id of a place or transition of the net");
        }
    }
    l.check_arcs();
    let failed = l.diags.iter().any(|d| !is_warning(d));
    let Loader { net, mut diags, .. } = l;
    diags.sort_by_key(|d| d.primary.as_ref().map_or(0, |p| p.span.start));
    (if failed { None } else { Some(net) }, diags)
}

/// Escapes text and attribute values (`\r` as a reference so that it
/// survives XML's line-end normalisation).
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\r' => out.push_str("&#13;"),
            c => out.push(c),
        }
    }
    out
}

/// [`esc`] for attribute values, whose tabs and line ends XML would turn
/// into spaces.
fn esc_attr(s: &str) -> String {
    esc(s).replace('\t', "&#9;").replace('\n', "&#10;")
}

fn num(v: f64) -> String {
    format!("{v}")
}

struct W {
    out: String,
}

impl W {
    /// Closes an element opened by the line ending at `mark`: `<x .../>`
    /// when nothing was written inside, else `</x>` on its own line.
    fn close(&mut self, depth: usize, name: &str, mark: usize) {
        if self.out.len() == mark && self.out.ends_with(">\n") {
            self.out.truncate(mark - 2);
            self.out.push_str("/>\n");
        } else {
            self.line(depth, &format!("</{name}>"));
        }
    }

    fn line(&mut self, depth: usize, s: &str) {
        for _ in 0..depth {
            self.out.push_str("  ");
        }
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn label(&mut self, depth: usize, name: &str, text: &str, extra: &Extra) {
        match extra.label_graphics.get(name) {
            Some(g) => {
                self.line(depth, &format!("<{name}>"));
                self.line(depth + 1, &format!("<text>{}</text>", esc(text)));
                self.line(depth + 1, g);
                self.line(depth, &format!("</{name}>"));
            }
            None => self.line(depth, &format!("<{name}><text>{}</text></{name}>", esc(text))),
        }
    }

    fn extra(&mut self, depth: usize, extra: &Extra) {
        if let Some(g) = &extra.graphics {
            match (&g.raw, g.position) {
                (Some(raw), _) => self.line(depth, raw),
                (None, Some(p)) => self.line(
                    depth,
                    &format!("<graphics><position x=\"{}\" y=\"{}\"/></graphics>", num(p.x), num(p.y)),
                ),
                (None, None) => {}
            }
        }
        for t in &extra.toolspecific {
            self.line(depth, t);
        }
    }

    fn alba(&mut self, depth: usize, body: &[String]) {
        if body.is_empty() {
            return;
        }
        self.line(
            depth,
            &format!("<toolspecific tool=\"{TOOL}\" version=\"{TOOL_VERSION}\">"),
        );
        for b in body {
            self.line(depth + 1, b);
        }
        self.line(depth, "</toolspecific>");
    }
}

fn props(body: &mut Vec<String>, props: &BTreeMap<String, String>) {
    for (k, v) in props {
        body.push(format!("<prop name=\"{}\">{}</prop>", esc_attr(k), esc(v)));
    }
}

/// Writes a net as PNML (one page). `load(save(net))` gives `net` back
/// (spans aside; graphics written from `position` come back with `raw`).
pub fn save(net: &Net) -> String {
    let mut w = W { out: String::new() };
    w.line(0, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    let mut ns = String::new();
    for (k, v) in &net.namespaces {
        if k != "xmlns:" && k.len() > "xmlns:".len() {
            ns.push_str(&format!(" {}=\"{}\"", esc_attr(k), esc_attr(v)));
        }
    }
    w.line(
        0,
        &format!("<pnml xmlns=\"http://www.pnml.org/version-2009/grammar/pnml\"{ns}>"),
    );
    w.line(
        1,
        &format!(
            "<net id=\"{}\" type=\"{}\">",
            esc_attr(&net.id),
            esc_attr(&net.net_type)
        ),
    );
    if let Some(n) = &net.name {
        w.label(2, "name", n, &net.extra);
    }
    w.extra(2, &net.extra);
    let mut body = Vec::new();
    if net.mode != Mode::Petri {
        body.push(format!("<mode>{}</mode>", net.mode.as_str()));
    }
    for x in &net.widgets {
        let mut s = format!("<widget id=\"{}\" kind=\"{}\"", esc_attr(&x.id), x.kind.as_str());
        if let Some(t) = &x.tag {
            s.push_str(&format!(" tag=\"{}\"", esc_attr(t)));
        }
        if let Some(p) = x.position {
            s.push_str(&format!(" x=\"{}\" y=\"{}\"", num(p.x), num(p.y)));
        }
        for (k, v) in &x.style {
            s.push_str(&format!(" {k}=\"{}\"", esc_attr(v)));
        }
        s.push_str(&format!(">{}</widget>", esc(x.text.as_deref().unwrap_or(""))));
        body.push(s);
    }
    w.alba(2, &body);
    w.line(2, &format!("<page id=\"{}\">", esc_attr(&net.page_id)));
    if let Some(n) = &net.page_name {
        w.label(3, "name", n, &net.page_extra);
    }
    w.extra(3, &net.page_extra);
    for p in &net.places {
        w.line(3, &format!("<place id=\"{}\">", esc_attr(&p.id)));
        let mark = w.out.len();
        if let Some(n) = &p.name {
            w.label(4, "name", n, &p.extra);
        }
        if p.initial != 0 || p.extra.label_graphics.contains_key("initialMarking") {
            w.label(4, "initialMarking", &p.initial.to_string(), &p.extra);
        }
        w.extra(4, &p.extra);
        let mut body = Vec::new();
        if let Some(t) = &p.tag {
            body.push(format!("<tag>{}</tag>", esc(t)));
        }
        if p.kind != ElementKind::State {
            body.push(format!("<kind>{}</kind>", p.kind.as_str()));
        }
        props(&mut body, &p.props);
        if let Some(s) = &p.script {
            body.push(format!("<script>{}</script>", esc(s)));
        }
        w.alba(4, &body);
        w.close(3, "place", mark);
    }
    for t in &net.transitions {
        w.line(3, &format!("<transition id=\"{}\">", esc_attr(&t.id)));
        let mark = w.out.len();
        if let Some(n) = &t.name {
            w.label(4, "name", n, &t.extra);
        }
        w.extra(4, &t.extra);
        let mut body = Vec::new();
        if let Some(g) = &t.guard {
            body.push(format!("<guard>{}</guard>", esc(&g.text)));
        }
        if let Some(p) = t.priority {
            body.push(format!("<priority>{p}</priority>"));
        }
        if t.kind != ElementKind::Transition {
            body.push(format!("<kind>{}</kind>", t.kind.as_str()));
        }
        props(&mut body, &t.props);
        w.alba(4, &body);
        w.close(3, "transition", mark);
    }
    for a in &net.arcs {
        w.line(
            3,
            &format!(
                "<arc id=\"{}\" source=\"{}\" target=\"{}\">",
                esc_attr(&a.id),
                esc_attr(&a.source),
                esc_attr(&a.target)
            ),
        );
        let mark = w.out.len();
        if a.weight != 1 || a.extra.label_graphics.contains_key("inscription") {
            w.label(4, "inscription", &a.weight.to_string(), &a.extra);
        }
        w.extra(4, &a.extra);
        if a.kind != ArcKind::Normal {
            w.alba(4, &[format!("<kind>{}</kind>", a.kind.as_str())]);
        }
        w.close(3, "arc", mark);
    }
    w.line(2, "</page>");
    w.line(1, "</net>");
    w.line(0, "</pnml>");
    w.out
}
