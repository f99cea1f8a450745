//! The shift report (issue 35, docs/api.md "Reports"):
//! `GET /api/reports/shift.xlsx?from=MS&to=MS` and `.pdf`: the alarm KPIs
//! of the range after EEMUA 191 / ISA-18.2 (`alba_alarms::kpi`, from the
//! alarm log) and the min/max/mean of each historised tag (the historian).
//! The numbers are computed once ([`gather`]); this file only lays them out,
//! as a workbook (rust_xlsxwriter) or a PDF (pdf-writer, the standard
//! Helvetica font: no font embedded).

use crate::error::{ApiError, ApiResult};
use crate::state::AppState;
use alba_control::alarms::kpi::{self, Kpis};
use alba_control::audit::format_utc;
use alba_settings::ReportFormat;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use std::collections::HashMap;
use std::sync::Arc;

/// The longest range one report covers (31 days).
pub const MAX_RANGE_MS: i64 = 31 * 86_400_000;
/// The most alarm events one report reads (more: `422`, a shorter range).
pub const MAX_EVENTS: u64 = 500_000;
/// The most samples of one tag one report reads (more: `422`, a shorter range).
pub const MAX_SAMPLES: usize = 2_000_000;

/// A historised tag's statistics over the range (its samples).
#[derive(Debug, Clone, PartialEq)]
pub struct TrendStat {
    pub tag: String,
    pub samples: u64,
    pub min: f64,
    pub max: f64,
    /// The mean of the samples (not weighted by time).
    pub mean: f64,
}

/// Everything a shift report shows.
#[derive(Debug, Clone)]
pub struct Report {
    pub project: String,
    pub kpis: Kpis,
    pub trends: Vec<TrendStat>,
}

/// `from` and `to` (Unix ms, both required, `from <= to`, at most 31 days).
fn range(q: &HashMap<String, String>) -> ApiResult<(i64, i64)> {
    let int = |name: &str| -> ApiResult<i64> {
        let text = q
            .get(name)
            .ok_or_else(|| ApiError::Malformed(format!("the query needs `{name}` (Unix time in ms)")))?;
        text.trim()
            .parse::<i64>()
            .map_err(|_| ApiError::Malformed(format!("`{name}={text}` is not a time in Unix ms")))
    };
    let (from, to) = (int("from")?, int("to")?);
    if from > to {
        return Err(ApiError::Malformed(format!("`from` ({from}) is after `to` ({to})")));
    }
    if to.checked_sub(from).is_none_or(|d| d > MAX_RANGE_MS) {
        return Err(ApiError::Malformed("a report covers at most 31 days".into()));
    }
    Ok((from, to))
}

/// Reads the alarm log and the historian for `[from, to]` and computes the report.
pub async fn gather(st: &AppState, from: i64, to: i64) -> ApiResult<Report> {
    let log = st.control.alarms().and_then(|h| h.log().cloned());
    let history = st.history.clone();
    let (events, trends) = tokio::task::spawn_blocking(move || -> ApiResult<_> {
        let events = match log {
            Some(log) => log
                .events(from, to, MAX_EVENTS + 1)
                .map_err(|e| ApiError::Internal(format!("the alarm log cannot be read: {e}")))?,
            None => Vec::new(),
        };
        if events.len() as u64 > MAX_EVENTS {
            return Err(ApiError::Invalid(format!(
                "more than {MAX_EVENTS} alarm events in the range: ask for a shorter one"
            )));
        }
        let mut trends = Vec::new();
        if let Some(h) = history {
            for t in h.tags(None)? {
                if t.last_ms < from || t.first_ms > to {
                    continue;
                }
                let points = h.raw(None, &t.name, from, to, MAX_SAMPLES + 1)?;
                if points.is_empty() {
                    continue;
                }
                if points.len() > MAX_SAMPLES {
                    return Err(ApiError::Invalid(format!(
                        "more than {MAX_SAMPLES} samples of `{}` in the range: ask for a shorter one",
                        t.name
                    )));
                }
                let (mut min, mut max, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
                for p in &points {
                    min = min.min(p.v);
                    max = max.max(p.v);
                    sum += p.v;
                }
                trends.push(TrendStat {
                    tag: t.name,
                    samples: points.len() as u64,
                    min,
                    max,
                    mean: sum / points.len() as f64,
                });
            }
        }
        Ok((events, trends))
    })
    .await
    .map_err(|e| ApiError::Internal(format!("the report task ended: {e}")))??;
    Ok(Report {
        project: st.name.clone(),
        kpis: kpi::kpis(&events, from, to),
        trends,
    })
}

type Params = Query<HashMap<String, String>>;

/// The shift report of `[from, to]` (Unix ms) as a file of `format`: what
/// the routes below send, and what `alba run` writes to `[reports] folder`
/// when a shift ends (alba-app's `reports.rs`).
pub async fn render(st: &AppState, from: i64, to: i64, format: ReportFormat) -> ApiResult<Vec<u8>> {
    let report = gather(st, from, to).await?;
    match format {
        ReportFormat::Xlsx => {
            workbook(&report).map_err(|e| ApiError::Internal(format!("the workbook cannot be written: {e}")))
        }
        ReportFormat::Pdf => Ok(document(&report)),
    }
}

/// The report as an Excel workbook.
pub async fn xlsx(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Response> {
    let (from, to) = range(&q)?;
    let bytes = render(&st, from, to, ReportFormat::Xlsx).await?;
    Ok(download(
        bytes,
        "application/vnd.openxmlformats-officedocument.spreadsheetml.sheet",
        "xlsx",
    ))
}

/// The report as a PDF.
pub async fn pdf(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Response> {
    let (from, to) = range(&q)?;
    let bytes = render(&st, from, to, ReportFormat::Pdf).await?;
    Ok(download(bytes, "application/pdf", "pdf"))
}

fn download(bytes: Vec<u8>, ctype: &'static str, ext: &str) -> Response {
    let disposition = format!("attachment; filename=\"shift-report.{ext}\"");
    (
        [
            (header::CONTENT_TYPE, ctype.to_string()),
            (header::CONTENT_DISPOSITION, disposition),
        ],
        bytes,
    )
        .into_response()
}

/// The summary lines: label and value (both sheets and the PDF).
fn summary(r: &Report) -> Vec<(&'static str, f64)> {
    let k = &r.kpis;
    vec![
        ("From (Unix ms)", k.from_ms as f64),
        ("To (Unix ms)", k.to_ms as f64),
        ("Alarms (annunciations)", k.annunciations as f64),
        ("Mean alarms per 10 min", k.mean_per_10min),
        ("Most alarms in 10 min", k.max_per_10min as f64),
        ("Flood periods (> 10 per 10 min)", k.floods.len() as f64),
        ("Time in flood (%)", k.flood_percent),
        ("Standing alarms", k.standing.len() as f64),
        ("Chattering alarms (3 in 60 s)", k.chattering.len() as f64),
    ]
}

/// The workbook: a sheet per KPI, numbers as numbers.
pub fn workbook(r: &Report) -> Result<Vec<u8>, rust_xlsxwriter::XlsxError> {
    use rust_xlsxwriter::{Format, Workbook};
    let bold = Format::new().set_bold();
    let mut wb = Workbook::new();
    let k = &r.kpis;
    {
        let ws = wb.add_worksheet();
        ws.set_name("Summary")?;
        ws.write_string_with_format(0, 0, format!("Shift report: {}", r.project), &bold)?;
        ws.write_string(1, 0, "From (UTC)")?;
        ws.write_string(1, 1, format_utc(k.from_ms))?;
        ws.write_string(2, 0, "To (UTC)")?;
        ws.write_string(2, 1, format_utc(k.to_ms))?;
        for (i, (label, v)) in summary(r).into_iter().enumerate() {
            let row = 3 + i as u32;
            ws.write_string(row, 0, label)?;
            ws.write_number(row, 1, v)?;
        }
        ws.set_column_width(0, 34)?;
        ws.set_column_width(1, 26)?;
    }
    let sheet = |wb: &mut Workbook, name: &str, header: &[&str]| -> Result<(), rust_xlsxwriter::XlsxError> {
        let ws = wb.add_worksheet();
        ws.set_name(name)?;
        for (c, h) in header.iter().enumerate() {
            ws.write_string_with_format(0, c as u16, *h, &bold)?;
            ws.set_column_width(c as u16, 22)?;
        }
        Ok(())
    };
    sheet(
        &mut wb,
        "Per 10 min",
        &["Window start (UTC)", "Window start (ms)", "Alarms", "Flood"],
    )?;
    {
        let ws = wb.worksheet_from_name("Per 10 min")?;
        for (i, &(start, n)) in k.windows.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, format_utc(start))?;
            ws.write_number(row, 1, start as f64)?;
            ws.write_number(row, 2, n as f64)?;
            ws.write_boolean(row, 3, n > kpi::FLOOD_ABOVE)?;
        }
    }
    sheet(&mut wb, "Floods", &["Start (UTC)", "End (UTC)", "Alarms"])?;
    {
        let ws = wb.worksheet_from_name("Floods")?;
        for (i, f) in k.floods.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, format_utc(f.start_ms))?;
            ws.write_string(row, 1, format_utc(f.end_ms))?;
            ws.write_number(row, 2, f.alarms as f64)?;
        }
    }
    sheet(&mut wb, "Top 10", &["Rank", "Alarm", "Alarms"])?;
    {
        let ws = wb.worksheet_from_name("Top 10")?;
        for (i, (id, n)) in k.top.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_number(row, 0, (i + 1) as f64)?;
            ws.write_string(row, 1, id)?;
            ws.write_number(row, 2, *n as f64)?;
        }
    }
    sheet(
        &mut wb,
        "Standing",
        &["Alarm", "State", "Active since (UTC)", "Minutes active"],
    )?;
    {
        let ws = wb.worksheet_from_name("Standing")?;
        for (i, s) in k.standing.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, &s.id)?;
            ws.write_string(row, 1, s.state.name())?;
            ws.write_string(row, 2, format_utc(s.since_ms))?;
            ws.write_number(row, 3, (k.to_ms - s.since_ms) as f64 / 60_000.0)?;
        }
    }
    sheet(&mut wb, "Chattering", &["Alarm", "Most in 60 s"])?;
    {
        let ws = wb.worksheet_from_name("Chattering")?;
        for (i, (id, n)) in k.chattering.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, id)?;
            ws.write_number(row, 1, *n as f64)?;
        }
    }
    sheet(&mut wb, "Priorities", &["Band", "Alarms", "Share (%)", "Target (%)"])?;
    {
        let ws = wb.worksheet_from_name("Priorities")?;
        for (i, b) in k.priorities.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, b.name)?;
            ws.write_number(row, 1, b.count as f64)?;
            ws.write_number(row, 2, b.percent)?;
            ws.write_number(row, 3, b.target)?;
        }
    }
    sheet(&mut wb, "Trends", &["Tag", "Samples", "Min", "Max", "Mean"])?;
    {
        let ws = wb.worksheet_from_name("Trends")?;
        for (i, t) in r.trends.iter().enumerate() {
            let row = 1 + i as u32;
            ws.write_string(row, 0, &t.tag)?;
            ws.write_number(row, 1, t.samples as f64)?;
            ws.write_number(row, 2, t.min)?;
            ws.write_number(row, 3, t.max)?;
            ws.write_number(row, 4, t.mean)?;
        }
    }
    wb.save_to_buffer()
}

/// The report's lines of text (the PDF).
fn lines(r: &Report) -> Vec<String> {
    let k = &r.kpis;
    let mut out = vec![
        format!("Shift report: {}", r.project),
        format!("{} to {} (UTC)", format_utc(k.from_ms), format_utc(k.to_ms)),
        String::new(),
        "Alarm KPIs (EEMUA 191 / ISA-18.2, one operator)".to_string(),
    ];
    for (label, v) in summary(r).into_iter().skip(2) {
        out.push(format!("  {label}: {}", number(v)));
    }
    out.push(String::new());
    out.push("Flood periods".into());
    for f in &k.floods {
        out.push(format!(
            "  {} to {}: {} alarms",
            format_utc(f.start_ms),
            format_utc(f.end_ms),
            f.alarms
        ));
    }
    out.push(String::new());
    out.push("Top ten most frequent alarms".into());
    for (i, (id, n)) in k.top.iter().enumerate() {
        out.push(format!("  {}. {id}: {n}", i + 1));
    }
    out.push(String::new());
    out.push("Standing alarms".into());
    for s in &k.standing {
        out.push(format!(
            "  {} ({}) since {}",
            s.id,
            s.state.name(),
            format_utc(s.since_ms)
        ));
    }
    out.push(String::new());
    out.push("Chattering alarms (3 or more in 60 s)".into());
    for (id, n) in &k.chattering {
        out.push(format!("  {id}: {n} in 60 s"));
    }
    out.push(String::new());
    out.push("Priority distribution (target 80 / 15 / 5 %)".into());
    for b in &k.priorities {
        out.push(format!(
            "  {}: {} ({}%, target {}%)",
            b.name,
            b.count,
            number(b.percent),
            number(b.target)
        ));
    }
    out.push(String::new());
    out.push("Trends (min / max / mean of the samples)".into());
    for t in &r.trends {
        out.push(format!(
            "  {}: {} / {} / {} ({} samples)",
            t.tag,
            number(t.min),
            number(t.max),
            number(t.mean),
            t.samples
        ));
    }
    out
}

fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

/// The report as a PDF of A4 pages, Helvetica 10 pt (text outside
/// WinAnsi's ASCII part is written as `?`).
pub fn document(r: &Report) -> Vec<u8> {
    use pdf_writer::{Content, Finish, Name, Pdf, Rect, Ref, Str};
    const PER_PAGE: usize = 60;
    let text = lines(r);
    let pages: Vec<&[String]> = text.chunks(PER_PAGE).collect();
    let catalog = Ref::new(1);
    let tree = Ref::new(2);
    let font = Ref::new(3);
    let mut next = 4;
    let mut ids = Vec::new();
    for _ in &pages {
        ids.push((Ref::new(next), Ref::new(next + 1)));
        next += 2;
    }
    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree)
        .kids(ids.iter().map(|(p, _)| *p))
        .count(ids.len() as i32);
    for (lines, &(page_id, content_id)) in pages.iter().zip(&ids) {
        let mut page = pdf.page(page_id);
        page.media_box(Rect::new(0.0, 0.0, 595.0, 842.0));
        page.parent(tree);
        page.contents(content_id);
        page.resources().fonts().pair(Name(b"F1"), font);
        page.finish();
        let mut c = Content::new();
        for (i, line) in lines.iter().enumerate() {
            let ascii: String = line
                .chars()
                .map(|ch| {
                    if ch.is_ascii() && !ch.is_ascii_control() {
                        ch
                    } else {
                        '?'
                    }
                })
                .collect();
            c.begin_text();
            c.set_font(Name(b"F1"), 10.0);
            c.next_line(50.0, 800.0 - 12.5 * i as f32);
            c.show(Str(ascii.as_bytes()));
            c.end_text();
        }
        pdf.stream(content_id, &c.finish());
    }
    pdf.type1_font(font).base_font(Name(b"Helvetica"));
    pdf.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_checked() {
        let q = |pairs: &[(&str, &str)]| -> HashMap<String, String> {
            pairs.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect()
        };
        assert_eq!(range(&q(&[("from", "0"), ("to", "600000")])).expect("ok"), (0, 600_000));
        for bad in [
            q(&[("from", "0")]),
            q(&[("to", "0")]),
            q(&[("from", "x"), ("to", "1")]),
            q(&[("from", "5"), ("to", "1")]),
            q(&[("from", "0"), ("to", &(MAX_RANGE_MS + 1).to_string())]),
            q(&[("from", &i64::MIN.to_string()), ("to", &i64::MAX.to_string())]),
        ] {
            assert!(matches!(range(&bad), Err(ApiError::Malformed(_))), "{bad:?}");
        }
    }

    #[test]
    fn the_pdf_holds_the_numbers() {
        let r = Report {
            project: "p".into(),
            kpis: kpi::kpis(&[], 0, 600_000),
            trends: vec![TrendStat {
                tag: "Level".into(),
                samples: 3,
                min: 1.0,
                max: 3.0,
                mean: 2.0,
            }],
        };
        let bytes = document(&r);
        assert!(bytes.starts_with(b"%PDF-"));
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("Level: 1 / 3 / 2 (3 samples)"), "{text}");
        assert!(text.contains("/Helvetica"));
    }
}
