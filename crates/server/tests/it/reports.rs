//! The shift report (docs/api.md, "Reports") over a known alarm history and
//! known samples: the workbook parsed back (calamine) and its numbers checked.

use crate::{Server, copy_example};
use alba_alarms::{Event, Hub, Log, State};
use alba_runtime::{Options, Runtime, SimIo};
use calamine::{Data, Reader, Xlsx};
use reqwest::StatusCode;
use std::sync::Arc;

const T0: i64 = 1_700_000_000_000;
const MIN: i64 = 60_000;

fn ev(t_ms: i64, id: &str, from: State, to: State, severity: u16) -> Event {
    Event {
        t_ms,
        id: id.into(),
        tag: "Nivel_L".into(),
        from,
        to,
        value: 1.0,
        user: None,
        comment: None,
        severity,
        message: format!("{id} message"),
    }
}

/// The tank with an alarm log and a historian holding a known shift.
async fn serve(test: &str) -> (Server, Runtime) {
    use State::*;
    let dir = copy_example("tank", test);
    let compiled = alba_server::project::load(&dir);
    let program = compiled.program.clone().expect("the example compiles");
    let mut ro = Options::new(compiled.project.scan_ms());
    ro.native = false;
    let runtime = Runtime::start(Arc::new(program), ro, Box::new(SimIo)).expect("runtime");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    let log = Log::open(&dir.join(".alba/alarms.db"), 30).expect("alarm log");
    let mut events = Vec::new();
    // HighLevel (low, 250): 12 annunciations 20 s apart in the first 10 minutes:
    // a flood, and chattering.
    for k in 0..12 {
        events.push(ev(T0 + k * 20_000, "HighLevel", Normal, ActiveUnacked, 250));
        events.push(ev(
            T0 + k * 20_000 + 5_000,
            "HighLevel",
            ActiveUnacked,
            ClearedUnacked,
            250,
        ));
    }
    // PumpFault (medium, 600) twice, 8 minutes apart; left normal.
    events.push(ev(T0 + 12 * MIN, "PumpFault", Normal, ActiveUnacked, 600));
    events.push(ev(T0 + 13 * MIN, "PumpFault", ActiveUnacked, ActiveAcked, 600));
    events.push(ev(T0 + 14 * MIN, "PumpFault", ActiveAcked, Normal, 600));
    events.push(ev(T0 + 20 * MIN, "PumpFault", Normal, ActiveUnacked, 600));
    events.push(ev(T0 + 21 * MIN, "PumpFault", ActiveUnacked, ActiveAcked, 600));
    events.push(ev(T0 + 22 * MIN, "PumpFault", ActiveAcked, Normal, 600));
    // EStop (critical) once, still active at the end: standing since minute 25.
    events.push(ev(T0 + 25 * MIN, "EStop", Normal, ActiveUnacked, 1000));
    // Outside the shift.
    events.push(ev(T0 + 90 * MIN, "Other", Normal, ActiveUnacked, 250));
    log.append(&events, &[]).expect("events logged");
    let history = alba_historian::Historian::open(dir.join(".alba/history.db"), Default::default()).expect("historian");
    let samples: Vec<alba_historian::Sample> = [(1, 2.0), (5, 4.0), (10, 9.0), (20, 1.0), (120, 100.0)]
        .into_iter()
        .map(|(m, v)| alba_historian::Sample {
            tag: "Nivel_L",
            t_ms: T0 + m * MIN,
            v,
        })
        .collect();
    history.record_batch(&samples).expect("samples");
    history.flush().expect("flush");
    let state = alba_server::AppState::new(
        runtime.handle(),
        compiled,
        "test",
        Some(Arc::new(history)),
        None,
        alba_server::auth::Auth::open(),
        &alba_settings::Http::default(),
    );
    assert!(state.control.set_alarms(Arc::new(Hub::new(Vec::new(), Some(log)))));
    (Server::serve_state(state, dir).await, runtime)
}

fn num(ws: &calamine::Range<Data>, row: u32, col: u32) -> f64 {
    match ws.get_value((row, col)) {
        Some(Data::Float(f)) => *f,
        Some(Data::Int(i)) => *i as f64,
        other => panic!("({row}, {col}) is not a number: {other:?}"),
    }
}

fn text(ws: &calamine::Range<Data>, row: u32, col: u32) -> String {
    match ws.get_value((row, col)) {
        Some(Data::String(s)) => s.clone(),
        other => panic!("({row}, {col}) is not text: {other:?}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_shift_workbook_holds_the_kpis_of_a_known_history() {
    let (s, runtime) = serve("report-xlsx").await;
    let (from, to) = (T0, T0 + 30 * MIN);
    let res = s
        .http
        .get(s.url(&format!("/api/reports/shift.xlsx?from={from}&to={to}")))
        .send()
        .await
        .expect("report");
    assert_eq!(res.status(), StatusCode::OK);
    assert_eq!(
        res.headers()["content-type"],
        "application/vnd.openxmlformats-officedocument.spreadsheetml.sheet"
    );
    let bytes = res.bytes().await.expect("body").to_vec();
    let mut wb: Xlsx<_> = Xlsx::new(std::io::Cursor::new(bytes)).expect("an XLSX workbook");
    let sum = wb.worksheet_range("Summary").expect("Summary");
    let label = |r: u32| text(&sum, r, 0);
    assert_eq!(label(5), "Alarms (annunciations)");
    assert_eq!(num(&sum, 3, 1), from as f64);
    assert_eq!(num(&sum, 5, 1), 15.0, "12 + 2 + 1 annunciations");
    assert!(
        (num(&sum, 6, 1) - 15.0 / 4.0).abs() < 1e-9,
        "four windows (the last one starts at `to`)"
    );
    assert_eq!(num(&sum, 7, 1), 12.0);
    assert_eq!(num(&sum, 8, 1), 1.0, "one flood period");
    assert_eq!(num(&sum, 10, 1), 1.0, "one standing alarm");
    assert_eq!(num(&sum, 11, 1), 1.0, "one chattering alarm");

    let per = wb.worksheet_range("Per 10 min").expect("Per 10 min");
    let counts: Vec<f64> = (1..=4).map(|r| num(&per, r, 2)).collect();
    // PumpFault at minutes 12 and 20, EStop at 25.
    assert_eq!(counts, vec![12.0, 1.0, 2.0, 0.0]);
    assert_eq!(per.get_value((1, 3)), Some(&Data::Bool(true)));

    let top = wb.worksheet_range("Top 10").expect("Top 10");
    assert_eq!(
        (1..=3).map(|r| (text(&top, r, 1), num(&top, r, 2))).collect::<Vec<_>>(),
        vec![
            ("HighLevel".to_string(), 12.0),
            ("PumpFault".to_string(), 2.0),
            ("EStop".to_string(), 1.0)
        ]
    );
    let standing = wb.worksheet_range("Standing").expect("Standing");
    assert_eq!(text(&standing, 1, 0), "EStop");
    assert_eq!(num(&standing, 1, 3), 5.0, "minutes active at the end");
    let chatter = wb.worksheet_range("Chattering").expect("Chattering");
    assert_eq!(
        (text(&chatter, 1, 0), num(&chatter, 1, 1)),
        ("HighLevel".to_string(), 3.0)
    );
    let prio = wb.worksheet_range("Priorities").expect("Priorities");
    assert_eq!(
        (1..=3)
            .map(|r| (text(&prio, r, 0), num(&prio, r, 1)))
            .collect::<Vec<_>>(),
        vec![
            ("low".to_string(), 12.0),
            ("medium".to_string(), 2.0),
            ("high".to_string(), 1.0)
        ]
    );
    assert!((num(&prio, 1, 2) - 80.0).abs() < 1e-9);
    let trends = wb.worksheet_range("Trends").expect("Trends");
    assert_eq!(text(&trends, 1, 0), "Nivel_L");
    assert_eq!(
        (2..=4).map(|c| num(&trends, 1, c)).collect::<Vec<_>>(),
        vec![1.0, 9.0, 4.0],
        "min, max, mean of the four samples in the shift"
    );
    assert_eq!(num(&trends, 1, 1), 4.0);
    s.stop().await;
    drop(runtime);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_shift_pdf_is_a_pdf_and_bad_ranges_are_400() {
    let (s, runtime) = serve("report-pdf").await;
    let res = s
        .http
        .get(s.url(&format!("/api/reports/shift.pdf?from={T0}&to={}", T0 + 30 * MIN)))
        .send()
        .await
        .expect("report");
    assert_eq!(res.status(), StatusCode::OK);
    assert_eq!(res.headers()["content-type"], "application/pdf");
    let bytes = res.bytes().await.expect("body");
    assert!(bytes.starts_with(b"%PDF-"));
    let body = String::from_utf8_lossy(&bytes);
    assert!(body.contains("HighLevel: 12"), "the top ten in the text");
    for q in [
        "",
        "?from=1",
        "?from=a&to=2",
        "?from=10&to=5",
        "?from=0&to=9999999999999",
    ] {
        for ext in ["xlsx", "pdf"] {
            let (code, j) = s
                .call(reqwest::Method::GET, &format!("/api/reports/shift.{ext}{q}"), None)
                .await;
            assert_eq!(code, StatusCode::BAD_REQUEST, "{ext}{q}: {j}");
            assert!(j["error"].is_string());
        }
    }
    s.stop().await;
    drop(runtime);
}
