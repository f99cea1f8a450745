//! The net model: what a `.pnml` file holds once loaded.
//!
//! One model for both execution modes. A Petri-mode net uses places,
//! transitions and arcs only; a normal-mode net (the source's state nets,
//! SPEC §5) gives each node an [`ElementKind`] and its parameters in
//! `props`, and keeps the operator elements (Button, Display, Plot, Label)
//! in [`Net::widgets`]. Everything Alba adds lives in
//! `<toolspecific tool="alba" version="1">` on the element it belongs to;
//! graphics and other tools' toolspecific blocks are kept verbatim for the
//! round trip.

use alba_diag::{FileId, Span};
use std::collections::BTreeMap;

/// How a net runs (docs/nets.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Standard place/transition semantics (SPEC §10.5). The default, and
    /// the mode of PNML written by other tools.
    #[default]
    Petri,
    /// The source's token flow (state nets).
    Normal,
}

impl Mode {
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Petri => "petri",
            Mode::Normal => "normal",
        }
    }

    pub fn parse(s: &str) -> Option<Mode> {
        match s.trim() {
            "petri" => Some(Mode::Petri),
            "normal" => Some(Mode::Normal),
            _ => None,
        }
    }
}

/// The element kinds of SPEC §5. Places carry a state-like kind
/// (`State`, `Counter`, `Expression`, `Variable`, `Input`, `Output`,
/// `Stop`, `End`), transitions a transition-like kind (`Transition`,
/// `Condition`, `Timer`); operator elements (`Button`, `Display`, `Plot`,
/// `Label`) are [`Widget`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ElementKind {
    State,
    Transition,
    Condition,
    Timer,
    Counter,
    Expression,
    Variable,
    Input,
    Output,
    Stop,
    End,
    Button,
    Display,
    Plot,
    Label,
}

impl ElementKind {
    pub const ALL: [ElementKind; 15] = [
        ElementKind::State,
        ElementKind::Transition,
        ElementKind::Condition,
        ElementKind::Timer,
        ElementKind::Counter,
        ElementKind::Expression,
        ElementKind::Variable,
        ElementKind::Input,
        ElementKind::Output,
        ElementKind::Stop,
        ElementKind::End,
        ElementKind::Button,
        ElementKind::Display,
        ElementKind::Plot,
        ElementKind::Label,
    ];

    /// The name in `<kind>` (lower case).
    pub fn as_str(self) -> &'static str {
        match self {
            ElementKind::State => "state",
            ElementKind::Transition => "transition",
            ElementKind::Condition => "condition",
            ElementKind::Timer => "timer",
            ElementKind::Counter => "counter",
            ElementKind::Expression => "expression",
            ElementKind::Variable => "variable",
            ElementKind::Input => "input",
            ElementKind::Output => "output",
            ElementKind::Stop => "stop",
            ElementKind::End => "end",
            ElementKind::Button => "button",
            ElementKind::Display => "display",
            ElementKind::Plot => "plot",
            ElementKind::Label => "label",
        }
    }

    pub fn parse(s: &str) -> Option<ElementKind> {
        let s = s.trim();
        ElementKind::ALL
            .into_iter()
            .find(|k| k.as_str().eq_ignore_ascii_case(s))
    }

    /// Kinds a PNML place may have.
    pub fn is_place_kind(self) -> bool {
        matches!(
            self,
            ElementKind::State
                | ElementKind::Counter
                | ElementKind::Expression
                | ElementKind::Variable
                | ElementKind::Input
                | ElementKind::Output
                | ElementKind::Stop
                | ElementKind::End
        )
    }

    /// Kinds a PNML transition may have.
    pub fn is_transition_kind(self) -> bool {
        matches!(
            self,
            ElementKind::Transition | ElementKind::Condition | ElementKind::Timer
        )
    }

    /// Operator elements (kept for the studio, no effect on execution).
    pub fn is_widget_kind(self) -> bool {
        matches!(
            self,
            ElementKind::Button | ElementKind::Display | ElementKind::Plot | ElementKind::Label
        )
    }
}

/// The kind of an arc.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ArcKind {
    /// Consumes (place → transition) or produces (transition → place).
    #[default]
    Normal,
    /// place → transition: the transition is enabled only while the place
    /// holds fewer than `weight` tokens; consumes nothing.
    Inhibitor,
    /// place → transition (test arc): needs `weight` tokens, consumes none.
    Read,
}

impl ArcKind {
    pub fn as_str(self) -> &'static str {
        match self {
            ArcKind::Normal => "normal",
            ArcKind::Inhibitor => "inhibitor",
            ArcKind::Read => "read",
        }
    }

    pub fn parse(s: &str) -> Option<ArcKind> {
        match s.trim() {
            "normal" => Some(ArcKind::Normal),
            "inhibitor" => Some(ArcKind::Inhibitor),
            "read" | "test" => Some(ArcKind::Read),
            _ => None,
        }
    }
}

/// A point of `<graphics><position x y/>` (PNML: decimals).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Point {
    pub x: f64,
    pub y: f64,
}

/// The `<graphics>` of an element. `raw` is the element as it was read
/// (written back unchanged, so offsets, dimensions, fills and arc bend points
/// survive); `position` is the node's position parsed from it. An editor
/// that moves a node sets `position` and clears `raw` (see
/// [`Graphics::at`]); `save` writes `raw` when present, else `position`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Graphics {
    pub position: Option<Point>,
    pub raw: Option<String>,
}

impl Graphics {
    pub fn at(x: f64, y: f64) -> Graphics {
        Graphics {
            position: Some(Point { x, y }),
            raw: None,
        }
    }
}

/// What every element keeps for the round trip besides its own data.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Extra {
    pub graphics: Option<Graphics>,
    /// `<toolspecific>` blocks of other tools (or of unknown Alba versions),
    /// verbatim, in document order.
    pub toolspecific: Vec<String>,
    /// `<graphics>` of the element's labels (`name`, `initialMarking`,
    /// `inscription`: label offsets), verbatim, by label.
    pub label_graphics: BTreeMap<String, String>,
}

/// A guard: an expression in Alba's expression language, with its place in
/// the file (the `petri` part parses it).
#[derive(Debug, Clone, PartialEq)]
pub struct Guard {
    pub text: String,
    pub span: Span,
}

/// A place (a state of a state net).
#[derive(Debug, Clone, PartialEq)]
pub struct Place {
    pub id: String,
    pub name: Option<String>,
    /// `<initialMarking>`; 0 when absent.
    pub initial: u32,
    /// `<tag>NAME</tag>`: BOOL tag driven true while marked.
    pub tag: Option<String>,
    /// `State` unless Alba's block says otherwise.
    pub kind: ElementKind,
    /// Kind parameters (`<prop name="...">value</prop>`), e.g. a counter's
    /// preset, an input's source.
    pub props: BTreeMap<String, String>,
    /// An Expression element's script (`<script>`), verbatim.
    pub script: Option<String>,
    pub extra: Extra,
    /// The `<place>` start tag.
    pub span: Span,
}

/// A transition.
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    pub id: String,
    pub name: Option<String>,
    pub guard: Option<Guard>,
    /// Lower fires earlier; transitions without one come after all with
    /// one, in document order (see [`Net::firing_order`]).
    pub priority: Option<i32>,
    /// `Transition` unless Alba's block says otherwise.
    pub kind: ElementKind,
    pub props: BTreeMap<String, String>,
    pub extra: Extra,
    pub span: Span,
}

/// An arc between a place and a transition (either way).
#[derive(Debug, Clone, PartialEq)]
pub struct Arc {
    pub id: String,
    pub source: String,
    pub target: String,
    /// `<inscription>`; 1 when absent.
    pub weight: u32,
    pub kind: ArcKind,
    pub extra: Extra,
    pub span: Span,
}

/// An operator element (Button, Display, Plot, Label) of the net's live
/// view, stored in the net's Alba block as `<widget>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Widget {
    pub id: String,
    pub kind: ElementKind,
    /// The tag it shows or sets (none for a Label).
    pub tag: Option<String>,
    /// Its caption.
    pub text: Option<String>,
    pub position: Option<Point>,
    /// The source's properties of the element (OPCSM, `003_…` §2.2.3.13–16: a
    /// Display's `mode`, `format`, `unit`; a Plot's `autoscale`, `title`, `min`,
    /// `max`; a Label's colours, border, font, alignment): every other
    /// attribute of `<widget>`, kept and written back by name. The studio
    /// reads them (`web/src/net/widgets.ts`); the engine does not.
    pub style: BTreeMap<String, String>,
}

/// A net: one `<net>` of a PNML file, its pages flattened.
#[derive(Debug, Clone, PartialEq)]
pub struct Net {
    pub id: String,
    pub name: Option<String>,
    /// The `type` attribute as read (the ptnet URI when written by Alba).
    pub net_type: String,
    pub mode: Mode,
    /// Places, transitions and arcs in document order across pages.
    pub places: Vec<Place>,
    pub transitions: Vec<Transition>,
    pub arcs: Vec<Arc>,
    pub widgets: Vec<Widget>,
    /// The id of the (first) page; Alba writes one page.
    pub page_id: String,
    /// The first page's name, graphics and other tools' blocks (those of
    /// nested pages are dropped when flattening, with a warning).
    pub page_name: Option<String>,
    pub page_extra: Extra,
    /// The net's own graphics/unknown toolspecific blocks.
    pub extra: Extra,
    /// Prefixed namespace declarations (`xmlns:pn`, value) of `<pnml>` and
    /// `<net>`, written back on `<pnml>` so that kept blocks that use a
    /// prefix stay well-formed.
    pub namespaces: Vec<(String, String)>,
    /// The `<net>` start tag.
    pub span: Span,
}

/// The ptnet type URI of the 2009 grammar.
pub const PTNET_TYPE: &str = "http://www.pnml.org/version-2009/grammar/ptnet";

impl Net {
    /// An empty Petri-mode net.
    pub fn new(id: impl Into<String>) -> Net {
        Net {
            id: id.into(),
            name: None,
            net_type: PTNET_TYPE.to_string(),
            mode: Mode::Petri,
            places: Vec::new(),
            transitions: Vec::new(),
            arcs: Vec::new(),
            widgets: Vec::new(),
            page_id: "page0".to_string(),
            page_name: None,
            page_extra: Extra::default(),
            extra: Extra::default(),
            namespaces: Vec::new(),
            span: no_span(),
        }
    }

    pub fn place(&self, id: &str) -> Option<&Place> {
        self.places.iter().find(|p| p.id == id)
    }

    pub fn transition(&self, id: &str) -> Option<&Transition> {
        self.transitions.iter().find(|t| t.id == id)
    }

    /// Indices into `transitions` in the order Petri mode tries them:
    /// transitions with a priority first, lower number first; then those
    /// without, in document order (a stable sort, so equal priorities keep
    /// document order).
    pub fn firing_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.transitions.len()).collect();
        order.sort_by_key(|&i| match self.transitions[i].priority {
            Some(p) => (0, p),
            None => (1, 0),
        });
        order
    }

    /// Sets every span to an empty one (to compare two loads of one net).
    pub fn clear_spans(&mut self) {
        self.span = no_span();
        for p in &mut self.places {
            p.span = no_span();
        }
        for t in &mut self.transitions {
            t.span = no_span();
            if let Some(g) = &mut t.guard {
                g.span = no_span();
            }
        }
        for a in &mut self.arcs {
            a.span = no_span();
        }
    }
}

/// The span used for elements built in code.
pub fn no_span() -> Span {
    Span::new(FileId(0), 0..0)
}

impl Place {
    pub fn new(id: impl Into<String>, initial: u32) -> Place {
        Place {
            id: id.into(),
            name: None,
            initial,
            tag: None,
            kind: ElementKind::State,
            props: BTreeMap::new(),
            script: None,
            extra: Extra::default(),
            span: no_span(),
        }
    }
}

impl Transition {
    pub fn new(id: impl Into<String>) -> Transition {
        Transition {
            id: id.into(),
            name: None,
            guard: None,
            priority: None,
            kind: ElementKind::Transition,
            props: BTreeMap::new(),
            extra: Extra::default(),
            span: no_span(),
        }
    }
}

impl Arc {
    pub fn new(id: impl Into<String>, source: impl Into<String>, target: impl Into<String>, weight: u32) -> Arc {
        Arc {
            id: id.into(),
            source: source.into(),
            target: target.into(),
            weight,
            kind: ArcKind::Normal,
            extra: Extra::default(),
            span: no_span(),
        }
    }
}
