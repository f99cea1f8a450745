//! Diagnostics: every problem Alba reports has a code, a message, a place and
//! (often) a hint on how to fix it.
//!
//! A [`Diagnostic`] points into a [`Files`] database by byte spans; rendering
//! (terminal text, one-line form, JSON for the web editor) is separate from
//! the diagnostic itself. The catalogue of codes lives in [`codes`].
//!
//! This crate stands apart from the data model (`alba-model`) and from the
//! project settings (`alba-project`): every stage reports through it, and it
//! depends on nothing of Alba.

pub mod codes;
pub mod es;
pub mod lang;

pub use codes::Code;
use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::SimpleFiles;
use codespan_reporting::term;
pub use lang::{Lang, language, set_language};
use std::fmt;
use std::ops::Range;

/// Index of a file in a [`Files`] database.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(pub u32);

/// A byte range in one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, range: Range<usize>) -> Span {
        Span {
            file,
            start: range.start as u32,
            end: range.end as u32,
        }
    }

    pub fn range(&self) -> Range<usize> {
        self.start as usize..self.end as usize
    }

    /// A span covering both `self` and `other` (same file assumed).
    pub fn to(&self, other: Span) -> Span {
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// The source texts diagnostics point into.
#[derive(Debug, Clone, Default)]
pub struct Files {
    files: Vec<(String, String)>,
    /// The byte offset of each line's start, per file: `line_col` is a
    /// binary search, so locating every element of a program is linear in
    /// its size (issue 15: a 40 k-rung program view was quadratic).
    lines: Vec<Vec<usize>>,
    /// Bytes `line_col` has examined (shared by clones): its cost, which
    /// tests hold linear in the number of lookups.
    scanned: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0)
        .chain(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .collect()
}

impl Files {
    pub fn new() -> Files {
        Files::default()
    }

    /// Adds a file; `name` is what diagnostics print (usually a path).
    pub fn add(&mut self, name: impl Into<String>, text: impl Into<String>) -> FileId {
        let text = text.into();
        self.lines.push(line_starts(&text));
        self.files.push((name.into(), text));
        FileId(self.files.len() as u32 - 1)
    }

    pub fn name(&self, id: FileId) -> &str {
        &self.files[id.0 as usize].0
    }

    /// Replaces the text of a file (an edited program checked in place).
    pub fn replace(&mut self, id: FileId, text: impl Into<String>) {
        if let Some(f) = self.files.get_mut(id.0 as usize) {
            f.1 = text.into();
            self.lines[id.0 as usize] = line_starts(&f.1);
        }
    }

    pub fn text(&self, id: FileId) -> &str {
        &self.files[id.0 as usize].1
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, id: FileId, offset: usize) -> (usize, usize) {
        let text = self.text(id);
        let offset = floor_char_boundary(text, offset.min(text.len()));
        let starts = &self.lines[id.0 as usize];
        // The last line starting at or before `offset`.
        let line = starts.partition_point(|&s| s <= offset).max(1);
        let in_line = &text[starts[line - 1]..offset];
        self.scanned
            .fetch_add(in_line.len() as u64, std::sync::atomic::Ordering::Relaxed);
        (line, in_line.chars().count() + 1)
    }

    /// The bytes [`line_col`](Self::line_col) has examined since these files
    /// were made (clones share the count): for tests that hold the cost of
    /// locating things linear.
    pub fn bytes_scanned(&self) -> u64 {
        self.scanned.load(std::sync::atomic::Ordering::Relaxed)
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// A labelled place in a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

/// One problem found in the user's input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    pub code: Code,
    pub message: String,
    /// Where the problem is; `None` for problems that are not in a file
    /// (a missing project folder, say), whose message then names the path.
    pub primary: Option<Label>,
    pub secondary: Vec<Label>,
    pub help: Option<String>,
}

impl Diagnostic {
    /// The only constructor: a code, a message and the place it is about.
    pub fn new(code: Code, message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Diagnostic {
            code,
            message: message.into(),
            primary: Some(Label {
                span,
                message: label.into(),
            }),
            secondary: Vec::new(),
            help: None,
        }
    }

    /// A diagnostic with no place in a file.
    pub fn unplaced(code: Code, message: impl Into<String>) -> Self {
        Diagnostic {
            code,
            message: message.into(),
            primary: None,
            secondary: Vec::new(),
            help: None,
        }
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn with_note(mut self, span: Span, message: impl Into<String>) -> Self {
        self.secondary.push(Label {
            span,
            message: message.into(),
        });
        self
    }

    /// This diagnostic in `lang`: in Spanish, the message by the code's
    /// template in [`es::MESSAGES`], else `título: English message`; labels
    /// and help by [`es::PHRASES`], else as they are. English is as built.
    pub fn localized(&self, lang: Lang) -> Diagnostic {
        match lang {
            Lang::En => self.clone(),
            Lang::Es => {
                let phrase = |t: &str| es::phrase(t).unwrap_or_else(|| t.to_string());
                let message = es::message(self.code, &self.message).unwrap_or_else(|| match es::title(self.code) {
                    Some(t) => format!("{t}: {}", self.message),
                    None => self.message.clone(),
                });
                let label = |l: &Label| Label {
                    span: l.span,
                    message: phrase(&l.message),
                };
                Diagnostic {
                    code: self.code,
                    message,
                    primary: self.primary.as_ref().map(label),
                    secondary: self.secondary.iter().map(label).collect(),
                    help: self.help.as_deref().map(phrase),
                }
            }
        }
    }

    /// `file:line:col: error[CODE]: message` (no source excerpt), in the
    /// process's [`language`].
    pub fn short(&self, files: &Files) -> String {
        self.short_in(files, language())
    }

    /// [`Diagnostic::short`] in `lang`.
    pub fn short_in(&self, files: &Files, lang: Lang) -> String {
        match lang {
            Lang::En => self.short_as_built(files),
            _ => self.localized(lang).short_as_built(files),
        }
    }

    fn short_as_built(&self, files: &Files) -> String {
        match &self.primary {
            Some(l) => {
                let (line, col) = files.line_col(l.span.file, l.span.start as usize);
                format!(
                    "{}:{}:{}: error[{}]: {}",
                    files.name(l.span.file),
                    line,
                    col,
                    self.code,
                    self.message
                )
            }
            None => format!("error[{}]: {}", self.code, self.message),
        }
    }

    /// The full form with a source excerpt, for terminals and logs.
    pub fn render(&self, files: &Files) -> String {
        self.render_in(files, language())
    }

    /// [`Diagnostic::render`] in `lang`.
    pub fn render_in(&self, files: &Files, lang: Lang) -> String {
        self.render_as(files, cs::Severity::Error, lang)
    }

    /// [`Diagnostic::render`] headed `warning[CODE]`: for the few problems
    /// that do not stop a project (a deprecated setting).
    pub fn render_warning(&self, files: &Files) -> String {
        self.render_as(files, cs::Severity::Warning, language())
    }

    fn render_as(&self, files: &Files, severity: cs::Severity, lang: Lang) -> String {
        match lang {
            Lang::En => self.render_as_built(files, severity, "help"),
            Lang::Es => self.localized(lang).render_as_built(files, severity, "ayuda"),
        }
    }

    fn render_as_built(&self, files: &Files, severity: cs::Severity, help_word: &str) -> String {
        let mut db = SimpleFiles::new();
        for (name, text) in &files.files {
            db.add(name.as_str(), text.as_str());
        }
        let mut labels = Vec::new();
        if let Some(l) = &self.primary {
            labels.push(cs::Label::primary(l.span.file.0 as usize, l.span.range()).with_message(&l.message));
        }
        for l in &self.secondary {
            labels.push(cs::Label::secondary(l.span.file.0 as usize, l.span.range()).with_message(&l.message));
        }
        let mut d = cs::Diagnostic::new(severity)
            .with_code(self.code.to_string())
            .with_message(&self.message)
            .with_labels(labels);
        if let Some(h) = &self.help {
            d = d.with_notes(vec![format!("{help_word}: {h}")]);
        }
        let config = term::Config::default();
        match term::emit_into_string(&config, &db, &d) {
            Ok(s) => s,
            // A span outside its file is a bug of ours; still say what we know.
            Err(_) => format!("{}\n", self.short_as_built(files)),
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if language() != Lang::En {
            let d = self.localized(language());
            return write!(f, "error[{}]: {}", d.code, d.message);
        }
        write!(f, "error[{}]: {}", self.code, self.message)
    }
}

/// Renders a list of diagnostics followed by a count line.
pub fn render_all(diags: &[Diagnostic], files: &Files) -> String {
    let mut out = String::new();
    for d in diags {
        out.push_str(&d.render(files));
    }
    if !diags.is_empty() {
        out.push_str(&error_count(diags.len()));
        out.push('\n');
    }
    out
}

/// `1 error`, `2 errors` (`2 errores` in Spanish), in the process's
/// [`language`].
pub fn error_count(n: usize) -> String {
    match (language(), n) {
        (_, 1) => "1 error".to_string(),
        (Lang::Es, n) => format!("{n} errores"),
        (Lang::En, n) => format!("{n} errors"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_characters_from_one() {
        let mut files = Files::new();
        let f = files.add("a", "ab\nñx\n");
        assert_eq!(files.line_col(f, 0), (1, 1));
        assert_eq!(files.line_col(f, 3), (2, 1));
        // 'x' follows the two-byte 'ñ': column 2.
        assert_eq!(files.line_col(f, 5), (2, 2));
    }

    #[test]
    fn line_col_agrees_with_counting_and_costs_one_line() {
        let text = "XIC(a)\r\nñandú OTE(b)\n\n\n€€ x\nlast";
        let mut files = Files::new();
        let f = files.add("a", "");
        files.replace(f, text);
        for offset in 0..=text.len() + 3 {
            let o = floor_char_boundary(text, offset.min(text.len()));
            let before = &text[..o];
            let line = before.matches('\n').count() + 1;
            let start = before.rfind('\n').map_or(0, |i| i + 1);
            assert_eq!(
                files.line_col(f, offset),
                (line, before[start..].chars().count() + 1),
                "{offset}"
            );
        }
        // Each lookup examines its own line only.
        let longest = text.split('\n').map(str::len).max().unwrap_or(0) as u64;
        assert!(files.bytes_scanned() <= (text.len() as u64 + 4) * longest);
        let before = files.bytes_scanned();
        files.line_col(f, text.len());
        assert_eq!(files.bytes_scanned() - before, 4, "only `last` is examined");
    }

    #[test]
    fn short_form_names_file_line_and_column() {
        let mut files = Files::new();
        let f = files.add("main.lad", "XIC(a)\nOTE(Strat);\n");
        let d = Diagnostic::new(Code::UnknownTag, "unknown tag `Strat`", Span::new(f, 11..16), "here");
        assert_eq!(d.short(&files), "main.lad:2:5: error[E301]: unknown tag `Strat`");
        let full = d.render(&files);
        assert!(full.contains("main.lad:2:5"), "{full}");
        assert!(full.contains("^^^^^ here"), "{full}");
    }

    #[test]
    fn spanish_rendering_translates_message_label_and_help() {
        let mut files = Files::new();
        let f = files.add("main.lad", "XIC(a)\nOTE(Strat);\n");
        let d = Diagnostic::new(Code::UnknownTag, "unknown tag `Strat`", Span::new(f, 11..16), "here")
            .with_help("did you mean `Start`?");
        assert_eq!(
            d.short_in(&files, Lang::Es),
            "main.lad:2:5: error[E301]: variable desconocida `Strat`"
        );
        let full = d.render_in(&files, Lang::Es);
        assert!(full.contains("^^^^^ aquí"), "{full}");
        assert!(full.contains("= ayuda: ¿quiso decir `Start`?"), "{full}");
        // English stays as built.
        assert_eq!(d.localized(Lang::En), d);
        assert!(d.render_in(&files, Lang::En).contains("help: did you mean `Start`?"));
    }

    #[test]
    fn a_message_without_template_keeps_its_english_behind_the_spanish_title() {
        let d = Diagnostic::unplaced(Code::Toolchain, "avr-gcc exited with status 1");
        assert_eq!(
            d.localized(Lang::Es).message,
            "no se pudo compilar o cargar el firmware: avr-gcc exited with status 1"
        );
    }
}
