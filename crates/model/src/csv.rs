//! A small RFC 4180 CSV reader that keeps the byte span of every field, so
//! diagnostics can point at the exact column. (The `csv` crate reports
//! record positions only, not where a quoted field sits in the source.)

use std::ops::Range;

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// The field's value, quotes removed and doubled quotes collapsed.
    pub text: String,
    /// Byte span of the field in the source, quotes included.
    pub span: Range<usize>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Record {
    pub fields: Vec<Field>,
    /// Byte span of the whole record (without the line ending).
    pub span: Range<usize>,
}

impl Record {
    /// Span just after the last field, for "missing field" messages.
    pub fn end(&self) -> Range<usize> {
        self.span.end..self.span.end
    }
}

/// A syntax error: where and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CsvError {
    pub span: Range<usize>,
    pub message: String,
}

/// Reads all records; blank lines are skipped. A malformed record is
/// reported and reading goes on with the next line, so every error of a file
/// is found in one pass.
pub fn read(text: &str) -> (Vec<Record>, Vec<CsvError>) {
    let bytes = text.as_bytes();
    let mut pos = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut records = Vec::new();
    let mut errors = Vec::new();
    while pos < bytes.len() {
        let line_end = find_line_end(bytes, pos);
        if text[pos..line_end].trim().is_empty() {
            pos = skip_newline(bytes, line_end);
            continue;
        }
        match read_record(text, pos) {
            Ok((rec, next)) => {
                records.push(rec);
                pos = next;
            }
            Err(e) => {
                // Resume after the line where the error was found.
                let resume = find_line_end(bytes, e.span.start.max(pos));
                errors.push(e);
                pos = skip_newline(bytes, resume);
            }
        }
    }
    (records, errors)
}

fn find_line_end(bytes: &[u8], from: usize) -> usize {
    let mut i = from;
    while i < bytes.len() && bytes[i] != b'\n' && bytes[i] != b'\r' {
        i += 1;
    }
    i
}

fn skip_newline(bytes: &[u8], mut i: usize) -> usize {
    if i < bytes.len() && bytes[i] == b'\r' {
        i += 1;
    }
    if i < bytes.len() && bytes[i] == b'\n' {
        i += 1;
    }
    i
}

/// Reads one record starting at `start`; returns it and the offset of the
/// next line.
fn read_record(text: &str, start: usize) -> Result<(Record, usize), CsvError> {
    let bytes = text.as_bytes();
    let mut fields = Vec::new();
    let mut pos = start;
    loop {
        let field_start = pos;
        let mut value = String::new();
        if pos < bytes.len() && bytes[pos] == b'"' {
            pos += 1;
            loop {
                match bytes.get(pos) {
                    None => {
                        return Err(CsvError {
                            span: field_start..field_start + 1,
                            message: "this quote is never closed".into(),
                        });
                    }
                    Some(b'"') if bytes.get(pos + 1) == Some(&b'"') => {
                        value.push('"');
                        pos += 2;
                    }
                    Some(b'"') => {
                        pos += 1;
                        break;
                    }
                    Some(_) => {
                        let ch_len = text[pos..].chars().next().map_or(1, char::len_utf8);
                        value.push_str(&text[pos..pos + ch_len]);
                        pos += ch_len;
                    }
                }
            }
            // Only spaces may follow a closing quote before the separator.
            while pos < bytes.len() && (bytes[pos] == b' ' || bytes[pos] == b'\t') {
                pos += 1;
            }
            if pos < bytes.len() && !matches!(bytes[pos], b',' | b'\n' | b'\r') {
                let ch_len = text[pos..].chars().next().map_or(1, char::len_utf8);
                return Err(CsvError {
                    span: pos..pos + ch_len,
                    message: "unexpected text after a closing quote; quote the whole field".into(),
                });
            }
        } else {
            while pos < bytes.len() && !matches!(bytes[pos], b',' | b'\n' | b'\r') {
                if bytes[pos] == b'"' {
                    return Err(CsvError {
                        span: pos..pos + 1,
                        message: "a quote inside an unquoted field; quote the whole field and double the quote".into(),
                    });
                }
                pos += 1;
            }
            value.push_str(&text[field_start..pos]);
        }
        fields.push(Field {
            text: value,
            span: field_start..pos,
        });
        if pos < bytes.len() && bytes[pos] == b',' {
            pos += 1;
            continue;
        }
        let record = Record {
            fields,
            span: start..pos,
        };
        return Ok((record, skip_newline(bytes, pos)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_keep_their_spans() {
        let text = "a,\"b,c\",d\r\n\n x ,\"say \"\"hi\"\"\"\n";
        let (recs, errs) = read(text);
        assert!(errs.is_empty());
        assert_eq!(recs.len(), 2);
        let f: Vec<_> = recs[0].fields.iter().map(|f| f.text.as_str()).collect();
        assert_eq!(f, ["a", "b,c", "d"]);
        assert_eq!(&text[recs[0].fields[1].span.clone()], "\"b,c\"");
        assert_eq!(recs[1].fields[0].text, " x ");
        assert_eq!(recs[1].fields[1].text, "say \"hi\"");
    }

    #[test]
    fn trailing_comma_gives_an_empty_field_and_bom_is_skipped() {
        let (recs, _) = read("\u{feff}a,b,\n");
        assert_eq!(recs[0].fields.len(), 3);
        assert_eq!(recs[0].fields[0].span, 3..4);
    }

    #[test]
    fn errors_are_located_and_reading_goes_on() {
        let text = "a,\"op\"x\nb,c\"d\ne,f\n\"never";
        let (recs, errs) = read(text);
        let starts: Vec<_> = errs.iter().map(|e| e.span.start).collect();
        assert_eq!(starts, [6, 11, 18], "{errs:?}");
        assert_eq!(recs.len(), 1);
        assert_eq!(recs[0].fields[0].text, "e");
    }
}
