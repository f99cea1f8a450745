//! What a conversion reports: its entries (converted, approximated,
//! refused), each at its [`Location`] in the source, and the [`Error`] that
//! stops it.

use crate::Format;
use std::fmt;

/// A place in an input file (line and column from 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub file: String,
    pub line: u32,
    pub col: u32,
}

impl Location {
    pub fn new(file: &str, line: u32, col: u32) -> Location {
        Location {
            file: file.to_string(),
            line,
            col,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.col)
    }
}

/// How a construct of the source came across.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Converted with the same behaviour.
    Converted,
    /// Converted, but the behaviour differs in a documented way.
    Approximated,
    /// Not converted (the message says what was left out).
    Refused,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Converted => "converted",
            Kind::Approximated => "approximated",
            Kind::Refused => "refused",
        }
    }
}

/// One line of the report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Entry {
    pub kind: Kind,
    pub location: Location,
    pub message: String,
}

impl fmt::Display for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}: {}", self.location, self.kind.name(), self.message)
    }
}

/// What was converted, approximated and refused, in source order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    pub entries: Vec<Entry>,
    /// The format that was read.
    pub format: Option<Format>,
    /// Rungs written into the Alba programs.
    pub rungs: usize,
    /// Tags written into tags.csv.
    pub tags: usize,
}

impl Report {
    pub(crate) fn push(&mut self, kind: Kind, location: Location, message: impl Into<String>) {
        self.entries.push(Entry {
            kind,
            location,
            message: message.into(),
        });
    }

    pub fn count(&self, kind: Kind) -> usize {
        self.entries.iter().filter(|e| e.kind == kind).count()
    }

    /// The report as text, one entry a line.
    pub fn render(&self) -> String {
        let mut s = String::new();
        for e in &self.entries {
            s.push_str(&e.to_string());
            s.push('\n');
        }
        s
    }
}

/// Why an import failed. Nothing was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    /// The place in the input, when the input is at fault.
    pub location: Option<Location>,
    pub message: String,
}

impl Error {
    pub(crate) fn at(location: Location, message: impl Into<String>) -> Error {
        Error {
            location: Some(location),
            message: message.into(),
        }
    }

    pub(crate) fn plain(message: impl Into<String>) -> Error {
        Error {
            location: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(l) => write!(f, "{l}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for Error {}
