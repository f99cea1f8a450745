//! The fallback journal (issue 31): `audit.journal` beside `audit.db`, a
//! file of [`JOURNAL_BYTES`] zeros written when the log is opened, so that
//! its blocks are the file's before the disk can fill. When `audit.db`
//! cannot be written (a full disk), the safety actions — stop, removing
//! forces — are recorded here instead ([`crate::Audit::begin_safety`]) and
//! still performed; the next time the log is written or opened, the
//! journal's rows are moved into it ([`crate::Audit::replay_journal`]).
//!
//! A row is one line of tab-separated fields (`\`, tab and newline escaped)
//! written over the zeros at the end of what is used, then `fdatasync`: no
//! block is allocated and the file's size never changes.

use std::fs::{File, OpenOptions};
use std::io::{self, Read};
use std::os::unix::fs::FileExt;
use std::path::Path;

/// The journal's size: a few thousand stops and unforces.
pub const JOURNAL_BYTES: u64 = 256 * 1024;

pub(crate) struct Journal {
    file: File,
    /// Bytes used (the first zero byte).
    used: u64,
}

fn escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('\t', "\\t").replace('\n', "\\n")
}

fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('t') => out.push('\t'),
            Some('n') => out.push('\n'),
            Some(o) => out.push(o),
            None => {}
        }
    }
    out
}

/// One line: its fields (`None` is an empty field marked `\0`-less: `-`
/// alone; a real `-` is written `\-`).
pub(crate) fn line(fields: &[Option<&str>]) -> String {
    let mut s = fields
        .iter()
        .map(|f| match f {
            None => "-".to_string(),
            Some(v) if v.starts_with('-') => format!("\\{}", escape(v)),
            Some(v) => escape(v),
        })
        .collect::<Vec<_>>()
        .join("\t");
    s.push('\n');
    s
}

/// The fields of a line written by [`line`].
pub(crate) fn fields(line: &str) -> Vec<Option<String>> {
    line.split('\t')
        .map(|f| if f == "-" { None } else { Some(unescape(f)) })
        .collect()
}

impl Journal {
    /// Opens (or makes, filled with zeros and synced) the journal at `path`.
    pub fn open(path: &Path) -> io::Result<Journal> {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)?;
        let len = file.metadata()?.len();
        if len < JOURNAL_BYTES {
            // Written, not `set_len`: a sparse file has no blocks to write into on a full disk.
            let zeros = vec![0u8; (JOURNAL_BYTES - len) as usize];
            file.write_all_at(&zeros, len)?;
            file.sync_all()?;
        }
        let mut text = Vec::new();
        (&mut file).take(JOURNAL_BYTES).read_to_end(&mut text)?;
        let used = text.iter().position(|&b| b == 0).unwrap_or(text.len()) as u64;
        Ok(Journal { file, used })
    }

    /// Bytes used: where the next line goes.
    pub fn used(&self) -> u64 {
        self.used
    }

    pub fn is_empty(&self) -> bool {
        self.used == 0
    }

    /// Writes `line` durably; an error when it does not fit.
    pub fn append(&mut self, line: &str) -> io::Result<()> {
        let bytes = line.as_bytes();
        if self.used + bytes.len() as u64 > JOURNAL_BYTES || bytes.contains(&0) {
            return Err(io::Error::new(io::ErrorKind::StorageFull, "the audit journal is full"));
        }
        self.file.write_all_at(bytes, self.used)?;
        self.file.sync_data()?;
        self.used += bytes.len() as u64;
        Ok(())
    }

    /// The lines written, oldest first.
    pub fn lines(&self) -> io::Result<Vec<String>> {
        let mut bytes = vec![0u8; self.used as usize];
        self.file.read_exact_at(&mut bytes, 0)?;
        Ok(String::from_utf8_lossy(&bytes).lines().map(str::to_string).collect())
    }

    /// Empties the journal (its rows are in the log now).
    pub fn clear(&mut self) -> io::Result<()> {
        self.file.write_all_at(&vec![0u8; self.used as usize], 0)?;
        self.file.sync_data()?;
        self.used = 0;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_round_trip_and_the_file_never_grows() {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("audit.journal");
        let mut j = Journal::open(&path).expect("open");
        assert!(j.is_empty());
        let weird = "a\tb\\c\nd";
        let l = line(&[Some("1"), None, Some(weird), Some("-x"), Some("-")]);
        j.append(&l).expect("append");
        drop(j);
        let mut j = Journal::open(&path).expect("reopen");
        assert_eq!(std::fs::metadata(&path).expect("meta").len(), JOURNAL_BYTES);
        let lines = j.lines().expect("lines");
        assert_eq!(lines.len(), 1);
        assert_eq!(
            fields(&lines[0]),
            vec![
                Some("1".to_string()),
                None,
                Some(weird.to_string()),
                Some("-x".to_string()),
                Some("-".to_string())
            ]
        );
        let big = "x".repeat(JOURNAL_BYTES as usize);
        assert!(j.append(&big).is_err(), "what does not fit is refused");
        j.clear().expect("clear");
        assert!(j.is_empty() && j.lines().expect("lines").is_empty());
    }
}
