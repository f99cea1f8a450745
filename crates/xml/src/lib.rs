//! A small element tree over quick-xml's reader, with byte positions, for
//! Alba's XML readers (PNML nets, PLCopen and L5X imports): their files are
//! small and the readers look around (ids, links after nodes), so a tree is
//! simpler than a streaming walk. Depth and element counts are capped
//! ([`Limits`]) so that a hostile file cannot exhaust the stack or memory;
//! only XML's five entities and character references are resolved, and a
//! document type declaration is skipped or, when asked, refused.

use quick_xml::events::Event;
use quick_xml::reader::Reader;
use std::collections::HashSet;

/// Most attributes on one element: the formats read here use a handful, and
/// a hostile file must not make one start tag cost what a document does.
pub const MAX_ATTRIBUTES: usize = 256;

/// What a document may hold.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Deepest element nesting accepted.
    pub max_depth: usize,
    /// Most elements in one document: with the tree in memory (a few
    /// hundred bytes per element at worst), this bounds what a hostile file
    /// of tiny elements costs.
    pub max_elements: usize,
    /// Refuse a `<!DOCTYPE>` (its internal subset could declare entities:
    /// the "billion laughs") instead of skipping it.
    pub refuse_doctype: bool,
}

#[derive(Debug, Clone)]
pub struct Elem {
    /// Local name (namespace prefix dropped).
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Elem>,
    /// Character data directly inside, entities resolved.
    pub text: String,
    /// Byte range of the character data (first to last piece).
    pub text_range: Option<(usize, usize)>,
    /// Start of `<`.
    pub start: usize,
    /// End of the start tag (`>`).
    pub start_end: usize,
    /// End of the end tag (or of the empty tag).
    pub end: usize,
}

impl Elem {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    pub fn child(&self, name: &str) -> Option<&Elem> {
        self.children.iter().find(|c| c.name == name)
    }
}

/// A well-formedness error at a byte offset.
#[derive(Debug)]
pub struct XmlError {
    pub offset: usize,
    pub message: String,
    /// A limit of Alba's ([`Limits`]), not bad XML.
    pub limit: bool,
}

fn local(name: &[u8]) -> String {
    let n = match name.iter().rposition(|&b| b == b':') {
        Some(i) => &name[i + 1..],
        None => name,
    };
    String::from_utf8_lossy(n).into_owned()
}

fn open(e: &quick_xml::events::BytesStart, start: usize, end: usize) -> Result<Elem, XmlError> {
    let mut attrs = Vec::new();
    // quick-xml's own duplicate check compares each attribute with every one
    // before it (quadratic: 9.5 CPU-minutes for 2.5 M attributes); this one
    // hashes the names, and the count is capped.
    let mut seen: HashSet<&[u8]> = HashSet::new();
    for a in e.attributes().with_checks(false) {
        let a = a.map_err(|err| XmlError {
            limit: false,
            offset: start,
            message: format!("bad attribute: {err}"),
        })?;
        if attrs.len() == MAX_ATTRIBUTES {
            return Err(XmlError {
                limit: true,
                offset: start,
                message: format!("more than {MAX_ATTRIBUTES} attributes on one element"),
            });
        }
        let full = a.key.into_inner();
        if !seen.insert(full) {
            return Err(XmlError {
                limit: false,
                offset: start,
                message: format!("bad attribute: duplicate attribute `{}`", String::from_utf8_lossy(full)),
            });
        }
        // Namespace declarations keep their prefix (`xmlns:pn`); other
        // attributes are known by their local name.
        let key = if full.starts_with(b"xmlns") {
            String::from_utf8_lossy(full).into_owned()
        } else {
            local(full)
        };
        let value = a.unescape_value().map_err(|err| XmlError {
            limit: false,
            offset: start,
            message: format!("bad attribute value: {err}"),
        })?;
        attrs.push((key, value.into_owned()));
    }
    Ok(Elem {
        name: local(e.name().as_ref()),
        attrs,
        children: Vec::new(),
        text: String::new(),
        text_range: None,
        start,
        start_end: end,
        end,
    })
}

fn add_text(stack: &mut [Elem], s: &str, from: usize, to: usize) {
    if let Some(top) = stack.last_mut() {
        top.text.push_str(s);
        top.text_range = Some(match top.text_range {
            Some((a, _)) => (a, to),
            None => (from, to),
        });
    }
}

/// Parses a whole document into its root element.
pub fn parse(text: &str, limits: &Limits) -> Result<Elem, XmlError> {
    let mut reader = Reader::from_str(text);
    let config = reader.config_mut();
    config.check_end_names = true;
    config.trim_text(false);
    let mut stack: Vec<Elem> = Vec::new();
    let mut root: Option<Elem> = None;
    let mut count = 0usize;
    loop {
        let before = reader.buffer_position() as usize;
        let ev = reader.read_event().map_err(|err| XmlError {
            limit: false,
            offset: reader.error_position() as usize,
            message: err.to_string(),
        })?;
        let after = reader.buffer_position() as usize;
        if matches!(ev, Event::Start(_) | Event::Empty(_)) {
            count += 1;
            if count > limits.max_elements {
                return Err(XmlError {
                    limit: true,
                    offset: before,
                    message: format!("more than {} elements", limits.max_elements),
                });
            }
        }
        match ev {
            Event::Start(e) => {
                if root.is_some() && stack.is_empty() {
                    return Err(XmlError {
                        limit: false,
                        offset: before,
                        message: "a second root element: a document has one".into(),
                    });
                }
                if stack.len() >= limits.max_depth {
                    return Err(XmlError {
                        limit: true,
                        offset: before,
                        message: format!("elements nested deeper than {} levels", limits.max_depth),
                    });
                }
                stack.push(open(&e, before, after)?);
            }
            Event::Empty(e) => {
                if root.is_some() && stack.is_empty() {
                    return Err(XmlError {
                        limit: false,
                        offset: before,
                        message: "a second root element: a document has one".into(),
                    });
                }
                let el = open(&e, before, after)?;
                match stack.last_mut() {
                    Some(top) => top.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::End(_) => {
                let Some(mut el) = stack.pop() else {
                    return Err(XmlError {
                        limit: false,
                        offset: before,
                        message: "an end tag without a start tag".into(),
                    });
                };
                el.end = after;
                match stack.last_mut() {
                    Some(top) => top.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::Text(t) => {
                let s = t.decode().map_err(|err| XmlError {
                    limit: false,
                    offset: before,
                    message: err.to_string(),
                })?;
                if stack.is_empty() {
                    if !s.trim().is_empty() {
                        return Err(XmlError {
                            limit: false,
                            offset: before,
                            message: "text outside the root element".into(),
                        });
                    }
                } else {
                    add_text(&mut stack, &s, before, after);
                }
            }
            Event::CData(t) => {
                let s = t.decode().map_err(|err| XmlError {
                    limit: false,
                    offset: before,
                    message: err.to_string(),
                })?;
                if stack.is_empty() {
                    return Err(XmlError {
                        limit: false,
                        offset: before,
                        message: "CDATA outside the root element".into(),
                    });
                }
                add_text(&mut stack, &s, before, after);
            }
            Event::GeneralRef(r) => {
                let resolved: String = if r.is_char_ref() {
                    match r.resolve_char_ref() {
                        Ok(Some(c)) => c.to_string(),
                        _ => {
                            return Err(XmlError {
                                limit: false,
                                offset: before,
                                message: "a character reference that is not a character".into(),
                            });
                        }
                    }
                } else {
                    let name = r.decode().map_err(|err| XmlError {
                        limit: false,
                        offset: before,
                        message: err.to_string(),
                    })?;
                    match quick_xml::escape::resolve_predefined_entity(&name) {
                        Some(s) => s.to_string(),
                        None => {
                            return Err(XmlError {
                                limit: false,
                                offset: before,
                                message: format!("unknown entity `&{name};` (only XML's five are defined)"),
                            });
                        }
                    }
                };
                if stack.is_empty() {
                    return Err(XmlError {
                        limit: false,
                        offset: before,
                        message: "a reference outside the root element".into(),
                    });
                }
                add_text(&mut stack, &resolved, before, after);
            }
            Event::DocType(_) if limits.refuse_doctype => {
                return Err(XmlError {
                    limit: true,
                    offset: before,
                    message: "a document type declaration (<!DOCTYPE>), whose entities could expand without bound"
                        .into(),
                });
            }
            Event::DocType(_) => {
                // Internal subsets could define entities; Alba resolves none
                // (see GeneralRef), so the doctype is only skipped.
            }
            Event::Decl(_) | Event::PI(_) | Event::Comment(_) => {}
            Event::Eof => break,
        }
    }
    if let Some(open) = stack.last() {
        return Err(XmlError {
            limit: false,
            offset: open.start,
            message: format!("<{}> is never closed", open.name),
        });
    }
    root.ok_or(XmlError {
        limit: false,
        offset: 0,
        message: "no root element: the file is empty".into(),
    })
}

impl Elem {
    /// Children with this local name.
    pub fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Elem> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// Every descendant with this local name, depth first.
    pub fn descendants<'a>(&'a self, name: &str, out: &mut Vec<&'a Elem>) {
        for c in &self.children {
            if c.name == name {
                out.push(c);
            }
            c.descendants(name, out);
        }
    }
}

/// Line and column (from 1, in characters) of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (u32, u32) {
    let offset = offset.min(text.len());
    let mut start = offset;
    while start > 0 && !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    let col = before[line_start..].chars().count() + 1;
    (
        u32::try_from(line).unwrap_or(u32::MAX),
        u32::try_from(col).unwrap_or(u32::MAX),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: Limits = Limits {
        max_depth: 64,
        max_elements: 1_000_000,
        refuse_doctype: true,
    };

    fn element(attrs: impl Iterator<Item = String>) -> String {
        let mut s = String::from("<net");
        for a in attrs {
            s.push(' ');
            s.push_str(&a);
        }
        s.push_str("/>");
        s
    }

    /// Issue 31: 2.5 M attributes took 9.5 CPU-minutes in quick-xml's
    /// quadratic duplicate check; now one element holds at most
    /// `MAX_ATTRIBUTES` and the file is refused at the first one past it.
    #[test]
    fn attributes_beyond_the_cap_are_refused_as_a_limit() {
        let ok = element((0..MAX_ATTRIBUTES).map(|i| format!("a{i}=\"{i}\"")));
        assert_eq!(parse(&ok, &LIMITS).expect("at the cap").attrs.len(), MAX_ATTRIBUTES);
        let text = element((0..2_500_000).map(|i| format!("a{i}=\"\"")));
        let e = parse(&text, &LIMITS).expect_err("past the cap");
        assert!(e.limit, "{}", e.message);
        assert!(e.message.contains("more than 256 attributes"), "{}", e.message);
    }

    #[test]
    fn a_duplicate_attribute_is_an_error_wherever_it_is() {
        for dup in [1, 100, MAX_ATTRIBUTES - 1] {
            let text = element((0..dup).map(|i| format!("a{i}=\"x\"")).chain(["a0=\"y\"".to_string()]));
            let e = parse(&text, &LIMITS).expect_err("a duplicate");
            assert!(!e.limit);
            assert!(e.message.contains("duplicate attribute `a0`"), "{}", e.message);
        }
        // The same local name under two prefixes is not a duplicate in XML.
        let text = "<a x:id=\"1\" y:id=\"2\" xmlns:x=\"u\" xmlns:y=\"v\"/>";
        assert_eq!(parse(text, &LIMITS).expect("distinct names").attrs.len(), 4);
    }
}
