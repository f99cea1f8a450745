//! CSV export with sample-and-hold, over any store that can count, look up and stream a
//! column's samples (the SQLite file, the PostgreSQL table).

use std::collections::VecDeque;
use std::io::Write;

use crate::MAX_CSV_ROWS;
use crate::error::{Error, Result};

/// What the export reads of each column (`c`: its index), all in one snapshot.
pub(crate) trait Source {
    /// The number of samples in `[from, to]`.
    fn count(&mut self, c: usize, from: i64, to: i64) -> Result<u64>;
    /// For each of `times` (ascending), the value of the last sample at or before it.
    fn values_at(&mut self, c: usize, times: &[i64]) -> Result<Vec<Option<f64>>>;
    /// At most `limit` samples in `(after, to]`, oldest first.
    fn after(&mut self, c: usize, after: i64, to: i64, limit: i64) -> Result<Vec<(i64, f64)>>;
}

/// How one exported column follows its tag.
enum Track {
    /// Looked up at each row time: for tags with many samples per row.
    Lookup,
    /// A read-ahead window over the samples after the last one read.
    Stream {
        buf: VecDeque<(i64, f64)>,
        /// The time of the last sample fetched into `buf`.
        after: i64,
        exhausted: bool,
        /// The value held at the last row written.
        value: Option<f64>,
    },
}

const STREAM_CHUNK: i64 = 4096;
/// Rows written per round of look-ups.
const BLOCK: i64 = 1024;
/// A lookup costs about as much as streaming this many samples (measured on SQLite: ~9 µs
/// per lookup, ~0.17 µs per streamed sample): columns with more samples per row look up.
const LOOKUP_RATIO: u64 = 50;

fn field(name: &str) -> String {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_owned()
    }
}

/// Checks the step and the number of rows: the rows of an export of `[from, to]`.
pub(crate) fn rows(from: i64, to: i64, step: i64) -> Result<i64> {
    let Some(rows) = crate::csv_rows(from, to, step) else {
        return Err(Error::InvalidArgument(format!(
            "CSV step must be at least 1 ms, not {step}"
        )));
    };
    if rows > MAX_CSV_ROWS {
        return Err(Error::InvalidArgument(format!(
            "CSV export of {rows} rows: at most {MAX_CSV_ROWS}, use a larger step"
        )));
    }
    Ok(rows as i64)
}

/// Writes the export (see `Historian::export_csv`) of the columns `headers` names, whose
/// samples `src` reads. Returns the number of data rows.
pub(crate) fn write(
    src: &mut dyn Source,
    headers: &[String],
    from: i64,
    to: i64,
    step: i64,
    out: &mut dyn Write,
) -> Result<u64> {
    let rows = rows(from, to, step)?;
    let mut tracks = Vec::with_capacity(headers.len());
    for c in 0..headers.len() {
        let samples = if rows == 0 {
            0
        } else {
            src.count(c, from.saturating_add(1), to)?
        };
        tracks.push(if samples > LOOKUP_RATIO * rows as u64 {
            Track::Lookup
        } else {
            let value = if rows == 0 { None } else { src.values_at(c, &[from])?[0] };
            Track::Stream {
                buf: VecDeque::new(),
                after: from,
                exhausted: false,
                value,
            }
        });
    }
    let mut line = String::from("Time (ms)");
    for h in headers {
        line.push(',');
        line.push_str(&field(h));
    }
    line.push('\n');
    out.write_all(line.as_bytes())?;
    let mut columns: Vec<Vec<Option<f64>>> = vec![Vec::new(); headers.len()];
    let mut first = 0;
    while first < rows {
        let times: Vec<i64> = (first..rows.min(first + BLOCK)).map(|r| from + r * step).collect();
        for (c, (track, values)) in tracks.iter_mut().zip(columns.iter_mut()).enumerate() {
            match track {
                Track::Lookup => *values = src.values_at(c, &times)?,
                Track::Stream {
                    buf,
                    after,
                    exhausted,
                    value,
                } => {
                    values.clear();
                    for &t in &times {
                        loop {
                            while let Some(&(st, sv)) = buf.front() {
                                if st > t {
                                    break;
                                }
                                *value = Some(sv);
                                buf.pop_front();
                            }
                            if !buf.is_empty() || *exhausted {
                                break;
                            }
                            let got = src.after(c, *after, to, STREAM_CHUNK)?;
                            *exhausted = (got.len() as i64) < STREAM_CHUNK;
                            if let Some(&(st, _)) = got.last() {
                                *after = st;
                            }
                            buf.extend(got);
                        }
                        values.push(*value);
                    }
                }
            }
        }
        for (k, t) in times.iter().enumerate() {
            line.clear();
            line.push_str(&(t - from).to_string());
            for values in &columns {
                line.push(',');
                if let Some(v) = values[k] {
                    line.push_str(&v.to_string());
                }
            }
            line.push('\n');
            out.write_all(line.as_bytes())?;
        }
        first += BLOCK;
    }
    out.flush()?;
    Ok(rows as u64)
}
