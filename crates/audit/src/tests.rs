//! Unit tests of the audit log as a whole (the modules test their own helpers).

use std::path::Path;

use proptest::prelude::*;

use super::*;

fn temp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

fn open(dir: &Path) -> Audit {
    Audit::open(dir.join("audit.db"), Config::default()).expect("open audit log")
}

fn entry(t_ms: i64, action: Action, user: &str, target: &str) -> Entry {
    Entry {
        user: Some(user.into()),
        addr: Some("127.0.0.1:5000".into()),
        target: Some(target.into()),
        ..Entry::new(t_ms, action)
    }
}

#[test]
fn record_then_query_gives_the_row_back() {
    let dir = temp();
    let a = open(dir.path());
    let e = Entry {
        old: Some("false".into()),
        new: Some("true".into()),
        detail: Some("set by hand".into()),
        via: Some("modbus".into()),
        ..entry(1_000, Action::Write, "ana", "Llenar")
    };
    let id = a.begin(&e).expect("begin");
    assert_eq!(a.get(id).expect("get").expect("row").outcome, Outcome::Pending);
    a.finish(id, &Outcome::Ok).expect("finish");
    let page = a.query(&Filter::default(), None, 10).expect("query");
    assert_eq!(page.next, None);
    assert_eq!(
        page.rows,
        vec![Row {
            id,
            t_ms: 1_000,
            user: Some("ana".into()),
            addr: Some("127.0.0.1:5000".into()),
            action: "write".into(),
            target: Some("Llenar".into()),
            old: Some("false".into()),
            new: Some("true".into()),
            detail: Some("set by hand".into()),
            via: Some("modbus".into()),
            outcome: Outcome::Ok,
        }]
    );
}

#[test]
fn an_outcome_is_set_once_and_never_back_to_pending() {
    let dir = temp();
    let a = open(dir.path());
    let id = a.begin(&entry(1, Action::Stop, "bo", "PLC")).expect("begin");
    assert!(matches!(
        a.finish(id, &Outcome::Pending),
        Err(Error::InvalidArgument(_))
    ));
    a.finish(id, &Outcome::Failed("the PLC is attached".into()))
        .expect("finish");
    assert!(matches!(a.finish(id, &Outcome::Ok), Err(Error::InvalidArgument(_))));
    assert!(matches!(
        a.finish(id + 100, &Outcome::Ok),
        Err(Error::InvalidArgument(_))
    ));
    let row = a.get(id).expect("get").expect("row");
    assert_eq!(row.outcome, Outcome::Failed("the PLC is attached".into()));
    let done = a
        .record(&entry(2, Action::Login, "bo", "bo"), &Outcome::Ok)
        .expect("record");
    assert!(matches!(a.finish(done, &Outcome::Ok), Err(Error::InvalidArgument(_))));
}

/// The file itself refuses changes to a row, whoever opens it.
#[test]
fn the_file_refuses_edits_of_rows() {
    let dir = temp();
    let a = open(dir.path());
    let id = a
        .record(&entry(1, Action::Write, "ana", "X"), &Outcome::Ok)
        .expect("record");
    let pending = a.begin(&entry(2, Action::Write, "ana", "Y")).expect("begin");
    let c = Connection::open(a.path()).expect("open directly");
    for sql in [
        format!("UPDATE audit SET new_value = '666' WHERE id = {id}"),
        format!("UPDATE audit SET outcome = 'failed' WHERE id = {id}"),
        format!("UPDATE audit SET user_name = 'eve', outcome = 'ok' WHERE id = {pending}"),
    ] {
        let e = c.execute(&sql, []).expect_err(&sql);
        assert!(e.to_string().contains("append-only"), "{sql}: {e}");
    }
    c.execute(&format!("UPDATE audit SET outcome = 'ok' WHERE id = {pending}"), [])
        .expect("a pending outcome may be set");
}

#[test]
fn filters_combine_and_pages_follow_each_other() {
    let dir = temp();
    let a = open(dir.path());
    let users = ["ana", "bo", "cy"];
    let actions = [Action::Write, Action::Force, Action::Run];
    let mut ids = Vec::new();
    for i in 0..60i64 {
        let e = entry(
            i * 10,
            actions[i as usize % 3],
            users[i as usize / 3 % 3],
            if i % 2 == 0 { "Pump" } else { "Valve" },
        );
        ids.push(a.record(&e, &Outcome::Ok).expect("record"));
    }
    // Filters: time range (both ends included), user, actions, target (case-insensitive).
    let f = Filter {
        from_ms: Some(100),
        to_ms: Some(400),
        user: Some("ana".into()),
        actions: vec![Action::Write, Action::Force],
        target: Some("PUMP".into()),
    };
    let want: Vec<i64> = (0..60i64)
        .filter(|i| (100..=400).contains(&(i * 10)) && i / 3 % 3 == 0 && i % 3 != 2 && i % 2 == 0)
        .map(|i| ids[i as usize])
        .rev()
        .collect();
    let got: Vec<i64> = a
        .query(&f, None, 100)
        .expect("query")
        .rows
        .iter()
        .map(|r| r.id)
        .collect();
    assert_eq!(got, want);
    // Paging: newest first, 7 at a time, no row lost or repeated, even with rows
    // appended between pages.
    let mut seen = Vec::new();
    let mut before = None;
    loop {
        let page = a.query(&Filter::default(), before, 7).expect("page");
        assert!(page.rows.len() <= 7);
        seen.extend(page.rows.iter().map(|r| r.id));
        a.record(&entry(9_999, Action::Stop, "late", "PLC"), &Outcome::Ok)
            .expect("append meanwhile");
        match page.next {
            Some(n) => before = Some(n),
            None => break,
        }
    }
    assert_eq!(seen, ids.iter().rev().copied().collect::<Vec<_>>());
    assert!(matches!(
        a.query(&Filter::default(), None, 0),
        Err(Error::InvalidArgument(_))
    ));
    assert_eq!(
        a.query(&Filter::default(), None, 1_000_000).expect("capped").rows.len(),
        60 + 9
    );
}

#[test]
fn retention_deletes_old_rows_only() {
    let dir = temp();
    let a = Audit::open(
        dir.path().join("audit.db"),
        Config {
            retention_days: Some(2),
        },
    )
    .expect("open");
    let day = 86_400_000;
    for t in [0, day, 2 * day, 3 * day, 4 * day] {
        a.record(&entry(t, Action::Write, "ana", "X"), &Outcome::Ok)
            .expect("record");
    }
    assert_eq!(a.retention_cutoff(4 * day), Some(2 * day));
    assert_eq!(a.apply_retention(4 * day).expect("retention"), 2);
    let times: Vec<i64> = a
        .query(&Filter::default(), None, 10)
        .expect("query")
        .rows
        .iter()
        .map(|r| r.t_ms)
        .collect();
    assert_eq!(times, vec![4 * day, 3 * day, 2 * day]);
    let keep = open(dir.path());
    assert_eq!(keep.retention_cutoff(100 * day), None);
    assert_eq!(keep.apply_retention(100 * day).expect("no retention"), 0);
    assert_eq!(keep.delete_before(i64::MAX).expect("delete all"), 3);
    // Ids are not reused after the newest rows were deleted.
    let id = keep
        .record(&entry(5 * day, Action::Run, "ana", "PLC"), &Outcome::Ok)
        .expect("record");
    assert_eq!(id, 6);
}

#[test]
fn bad_times_and_long_fields() {
    let dir = temp();
    let a = open(dir.path());
    assert!(matches!(
        a.record(&entry(MAX_TIME_MS + 1, Action::Run, "a", "b"), &Outcome::Ok),
        Err(Error::InvalidArgument(_))
    ));
    let long = "é".repeat(MAX_FIELD);
    let id = a
        .record(
            &Entry {
                detail: Some(long.clone()),
                ..entry(1, Action::OnlineEdit, "ana", "main.lad")
            },
            &Outcome::Ok,
        )
        .expect("record");
    let detail = a.get(id).expect("get").expect("row").detail.expect("detail");
    assert!(detail.len() <= MAX_FIELD && detail.ends_with('…'), "{}", detail.len());
    assert!(long.starts_with(detail.trim_end_matches('…')));
}

#[test]
fn reopening_keeps_rows_and_refuses_foreign_files() {
    let dir = temp();
    let path = dir.path().join("audit.db");
    {
        let a = open(dir.path());
        a.record(&entry(1, Action::Login, "ana", "ana"), &Outcome::Ok)
            .expect("record");
    }
    let a = open(dir.path());
    assert_eq!(a.query(&Filter::default(), None, 10).expect("query").rows.len(), 1);
    let mode: String = Connection::open(&path)
        .expect("inspect")
        .query_row("PRAGMA journal_mode", [], |r| r.get(0))
        .expect("journal mode");
    assert_eq!(mode, "wal");

    let junk = dir.path().join("junk.db");
    std::fs::write(&junk, b"this is not a database, not at all, no no no no no no no no no no no no no no no no no no no no no no no no no no no no no").expect("write");
    assert!(matches!(
        Audit::open(&junk, Config::default()),
        Err(Error::NotAudit { .. })
    ));
    let other = dir.path().join("other.db");
    Connection::open(&other)
        .expect("other")
        .execute_batch("CREATE TABLE t(x); PRAGMA application_id = 7;")
        .expect("other schema");
    assert!(matches!(
        Audit::open(&other, Config::default()),
        Err(Error::NotAudit { .. })
    ));
    let newer = dir.path().join("newer.db");
    drop(Audit::open(&newer, Config::default()).expect("create"));
    Connection::open(&newer)
        .expect("newer")
        .execute_batch("PRAGMA user_version = 99;")
        .expect("bump version");
    let e = Audit::open(&newer, Config::default()).expect_err("newer schema");
    assert!(e.to_string().contains("newer"), "{e}");
    assert!(matches!(
        Audit::open(dir.path().join("missing/audit.db"), Config::default()),
        Err(Error::Open { .. })
    ));
    // A project's log: `.alba/audit.db`, its folder created; not where a file is.
    let project = dir.path().join("project");
    std::fs::create_dir(&project).expect("project dir");
    let p = Audit::open_project(&project, Config::default()).expect("open in project");
    assert_eq!(p.path(), project.join(".alba/audit.db"));
    assert_eq!(project_path(&project), project.join(".alba").join("audit.db"));
    std::fs::write(dir.path().join("file"), "x").expect("a file");
    assert!(matches!(
        Audit::open_project(&dir.path().join("file"), Config::default()),
        Err(Error::CreateDir { .. })
    ));
}

/// Parses RFC 4180 text into records of fields (the test's own reader).
fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = text.chars().peekable();
    let mut quoted = false;
    let mut at_start = true;
    while let Some(c) = chars.next() {
        if quoted {
            if c == '"' {
                if chars.peek() == Some(&'"') {
                    chars.next();
                    field.push('"');
                } else {
                    quoted = false;
                }
            } else {
                field.push(c);
            }
            continue;
        }
        match c {
            '"' if at_start => {
                quoted = true;
                at_start = false;
            }
            ',' => {
                record.push(std::mem::take(&mut field));
                at_start = true;
            }
            '\r' if chars.peek() == Some(&'\n') => {
                chars.next();
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
                at_start = true;
            }
            c => {
                field.push(c);
                at_start = false;
            }
        }
    }
    assert!(field.is_empty() && record.is_empty(), "text ends inside a record");
    records
}

/// A field read back as it was stored: one leading `'` removed when the export added it.
fn unescape(f: &str) -> String {
    f.strip_prefix('\'').unwrap_or(f).to_string()
}

fn text() -> impl Strategy<Value = Option<String>> {
    prop_oneof![
        Just(None),
        "[a-z=+@'\\-\t\r\n,\" é€]{0,12}".prop_map(Some),
        any::<String>().prop_map(Some),
        (-1000.0f64..1000.0).prop_map(|v| Some(v.to_string())),
    ]
}

prop_compose! {
    fn arb_entry()(
        t_ms in -MAX_TIME_MS..=MAX_TIME_MS,
        user in text(), addr in text(), action in 0..Action::ALL.len(),
        target in text(), old in text(), new in text(), detail in text(), via in text(),
        outcome in prop_oneof![Just(Outcome::Ok), Just(Outcome::Pending), any::<String>().prop_map(Outcome::Failed)],
    ) -> (Entry, Outcome) {
        (Entry { t_ms, user, addr, action: Action::ALL[action], target, old, new, detail, via }, outcome)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Whatever the fields hold, the export parses back (RFC 4180) to exactly the stored
    /// rows, oldest first, one record per row, and no field starts a formula.
    #[test]
    fn csv_export_round_trips(entries in proptest::collection::vec(arb_entry(), 0..12), limit in 0u64..16) {
        let dir = temp();
        let a = open(dir.path());
        for (e, o) in &entries {
            a.record(e, o).expect("record");
        }
        let mut out = Vec::new();
        let n = a.export_csv(&Filter::default(), limit, &mut out).expect("export");
        let text = String::from_utf8(out).expect("UTF-8");
        prop_assert!(text.starts_with(CSV_HEADER));
        let records = parse_csv(&text);
        let want: Vec<Row> = a.query(&Filter::default(), None, MAX_PAGE).expect("query").rows.into_iter().rev().take(limit as usize).collect();
        prop_assert_eq!(n as usize, want.len());
        prop_assert_eq!(records.len(), want.len() + 1);
        prop_assert_eq!(records[0].join(","), CSV_HEADER.trim_end());
        for (rec, row) in records[1..].iter().zip(&want) {
            for f in rec {
                prop_assert!(!f.starts_with(['=', '+', '@', '\t', '\r']), "formula start: {:?}", f);
                prop_assert!(!f.starts_with('-') || f.parse::<f64>().is_ok(), "formula start: {:?}", f);
            }
            let opt = |s: &str| { let s = unescape(s); if s.is_empty() { None } else { Some(s) } };
            prop_assert_eq!(rec.len(), 13);
            prop_assert_eq!(rec[0].parse::<i64>().ok(), Some(row.id));
            prop_assert_eq!(rec[1].parse::<i64>().ok(), Some(row.t_ms));
            prop_assert_eq!(unescape(&rec[2]), format_utc(row.t_ms));
            prop_assert_eq!(opt(&rec[3]), row.user.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(opt(&rec[4]), row.addr.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(&rec[5], &row.action);
            prop_assert_eq!(opt(&rec[6]), row.target.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(opt(&rec[7]), row.old.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(opt(&rec[8]), row.new.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(opt(&rec[9]), row.detail.clone().filter(|s| !s.is_empty()));
            prop_assert_eq!(&rec[10], row.outcome.name());
            let err = match &row.outcome { Outcome::Failed(e) => e.clone(), _ => String::new() };
            prop_assert_eq!(unescape(&rec[11]), err);
            prop_assert_eq!(opt(&rec[12]), row.via.clone().filter(|s| !s.is_empty()));
        }
    }
}

/// A log of schema version 1 (no `via`) opens: the column is added, its
/// rows keep `via` empty, new rows say it, and the append-only trigger
/// covers it.
#[test]
fn a_version_1_log_gains_via() {
    let dir = temp();
    let path = dir.path().join("audit.db");
    {
        let c = rusqlite::Connection::open(&path).expect("open");
        c.execute_batch(
            "PRAGMA journal_mode = WAL;
             CREATE TABLE audit(id INTEGER PRIMARY KEY AUTOINCREMENT, t INTEGER NOT NULL, user_name TEXT,
               addr TEXT, action TEXT NOT NULL, target TEXT, old_value TEXT, new_value TEXT, detail TEXT,
               outcome TEXT NOT NULL CHECK (outcome IN ('pending', 'ok', 'failed')), error TEXT);
             CREATE TRIGGER audit_append_only BEFORE UPDATE ON audit WHEN OLD.outcome <> 'pending'
             BEGIN SELECT RAISE(ABORT, 'append-only'); END;
             INSERT INTO audit(t, action, outcome) VALUES (5, 'run', 'ok');
             PRAGMA application_id = 1097622081; PRAGMA user_version = 1;",
        )
        .expect("a version 1 log");
    }
    let a = Audit::open(&path, Config::default()).expect("a version 1 log opens");
    let id = a
        .begin(&Entry {
            via: Some("mqtt".into()),
            ..entry(6, Action::Write, "mqtt", "Level")
        })
        .expect("begin");
    let rows = a.query(&Filter::default(), None, 10).expect("query").rows;
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].via.as_deref(), Some("mqtt"));
    assert_eq!(rows[1].via, None);
    let c = rusqlite::Connection::open(&path).expect("open");
    let changed = c.execute("UPDATE audit SET via = 'http' WHERE id = ?1", [id]);
    assert!(changed.is_err(), "via of a row changed: {changed:?}");
}
