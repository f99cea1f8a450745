//! Scheduled shift reports (`[reports]`, docs/alarms.md "Scheduled
//! reports"): when a shift ends, `alba run` writes its report — the same
//! workbook and PDF as `GET /api/reports/shift.xlsx` and `.pdf`
//! (`alba_server::render_shift_report`) — into `[reports] folder`, each file
//! atomically (a temporary file, fsync, rename), and audits it (`report`).
//! A report that cannot be made or written is said on stderr and audited
//! `failed`; the service goes on.
//!
//! The time is a [`Clock`]'s (the system's in `alba run`, a virtual one in
//! the tests). The last shift that ended before the start is written then if
//! its files are missing (a restart across a shift change loses nothing);
//! after a jump of the clock the shifts passed are written, at most
//! [`MAX_CATCH_UP`] of them.

use crate::Service;
use alba_control::audit::{Action, Entry, Outcome};
use alba_server::AppState;
use alba_settings::Reports;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

const HOUR_MS: i64 = 3_600_000;
const DAY_MS: i64 = 86_400_000;
/// A shift's report is made this long after it ends (the historian's
/// recorder and the alarm evaluator have written its last moments).
pub const GRACE_MS: i64 = 10_000;
/// The most shifts written at once after the clock jumped (a week of three).
pub const MAX_CATCH_UP: usize = 21;
/// How often `alba run` looks at the clock (a report is at most this late).
const POLL: Duration = Duration::from_secs(15);

/// Wall-clock time, Unix ms.
pub trait Clock: Send + Sync {
    fn now_ms(&self) -> i64;
}

/// The system's clock.
pub struct SystemClock;

impl Clock for SystemClock {
    fn now_ms(&self) -> i64 {
        alba_server::now_ms()
    }
}

/// When the shifts change (Unix ms), from `[reports]`.
#[derive(Debug, Clone)]
struct Schedule {
    hours: Vec<u8>,
    offset_ms: i64,
}

impl Schedule {
    fn of(cfg: &Reports) -> Schedule {
        Schedule {
            hours: cfg.shift_hours.clone(),
            offset_ms: i64::from(cfg.utc_offset_minutes) * 60_000,
        }
    }

    /// The shift changes of local days `days`, ascending.
    fn changes(&self, days: std::ops::RangeInclusive<i64>) -> impl Iterator<Item = i64> + '_ {
        days.flat_map(move |d| {
            self.hours
                .iter()
                .map(move |&h| d * DAY_MS + i64::from(h) * HOUR_MS - self.offset_ms)
        })
    }

    /// The latest shift change at or before `t`.
    fn last_at_or_before(&self, t: i64) -> i64 {
        let day = (t + self.offset_ms).div_euclid(DAY_MS);
        self.changes(day - 1..=day).filter(|&c| c <= t).max().unwrap_or(t)
    }

    /// The shift that ends at the change `end`: its start.
    fn start_of(&self, end: i64) -> i64 {
        self.last_at_or_before(end - 1)
    }

    /// The first shift change after `t`.
    fn next_after(&self, t: i64) -> i64 {
        let day = (t + self.offset_ms).div_euclid(DAY_MS);
        self.changes(day..=day + 1).find(|&c| c > t).unwrap_or(t + DAY_MS)
    }
}

/// Writes the reports of the shifts that end while it runs.
struct Scheduler {
    state: Arc<AppState>,
    cfg: Reports,
    schedule: Schedule,
    folder: PathBuf,
    /// The end of the last shift written (or skipped).
    done: i64,
}

impl Scheduler {
    fn new(dir: &Path, cfg: &Reports, state: Arc<AppState>, now: i64) -> Scheduler {
        let schedule = Schedule::of(cfg);
        let last = schedule.last_at_or_before(now - GRACE_MS);
        let folder = dir.join(&cfg.folder);
        let mut s = Scheduler {
            state,
            cfg: cfg.clone(),
            schedule,
            folder,
            done: last,
        };
        // The last shift before the start, if its files are missing.
        let start = s.schedule.start_of(last);
        if s.files(start).iter().any(|(_, p)| !p.exists()) {
            s.done = start;
        }
        s
    }

    /// The files of the shift starting at `start` (local time in the name).
    fn files(&self, start: i64) -> Vec<(alba_settings::ReportFormat, PathBuf)> {
        let stamp = alba_control::audit::format_utc(start + self.schedule.offset_ms);
        // `2026-12-07T06:00:00.000Z` → `2026-12-07-0600`
        let name = format!("shift-{}-{}{}", &stamp[..10], &stamp[11..13], &stamp[14..16]);
        self.cfg
            .formats
            .iter()
            .map(|f| (*f, self.folder.join(format!("{name}.{}", f.ext()))))
            .collect()
    }

    /// Writes every shift that ended by `now` (less the grace) and is not
    /// written yet; the time to wait for the next one.
    async fn tick(&mut self, now: i64) -> Duration {
        let last = self.schedule.last_at_or_before(now - GRACE_MS);
        let mut ends = Vec::new();
        let mut end = last;
        while end > self.done {
            ends.push(end);
            end = self.schedule.start_of(end);
        }
        if ends.len() > MAX_CATCH_UP {
            eprintln!(
                "reports: the clock moved {} shifts ahead: the last {MAX_CATCH_UP} are written",
                ends.len()
            );
            ends.truncate(MAX_CATCH_UP);
        }
        for &end in ends.iter().rev() {
            self.write(self.schedule.start_of(end), end).await;
        }
        self.done = self.done.max(last);
        let next = self.schedule.next_after(now - GRACE_MS) + GRACE_MS;
        Duration::from_millis(u64::try_from(next - now).unwrap_or(0))
    }

    /// The shift `[from, to]`'s files.
    async fn write(&self, from: i64, to: i64) {
        let shift = format!(
            "{} to {}",
            alba_control::audit::format_utc(from),
            alba_control::audit::format_utc(to)
        );
        for (format, path) in self.files(from) {
            let outcome = match alba_server::render_shift_report(&self.state, from, to, format).await {
                Err(e) => Err(format!("the report cannot be made: {e}")),
                Ok(bytes) => {
                    let (p, folder) = (path.clone(), self.folder.clone());
                    tokio::task::spawn_blocking(move || -> Result<(), String> {
                        std::fs::create_dir_all(&folder)
                            .map_err(|e| format!("{} cannot be made: {e}", folder.display()))?;
                        alba_model::fsutil::write_atomic(&p, |w| std::io::Write::write_all(w, &bytes))
                            .map_err(|e| format!("{} cannot be written: {e}", p.display()))
                    })
                    .await
                    .unwrap_or_else(|e| Err(format!("the writer ended: {e}")))
                }
            };
            if let Err(e) = &outcome {
                eprintln!("reports: shift {shift}: {e}");
            }
            if let Some(audit) = self.state.control.audit().cloned() {
                let mut entry = Entry::new(alba_server::now_ms(), Action::Report);
                entry.target = Some(path.display().to_string());
                entry.detail = Some(format!("shift {shift}"));
                let outcome = match outcome {
                    Ok(()) => Outcome::Ok,
                    Err(e) => Outcome::Failed(e),
                };
                match tokio::task::spawn_blocking(move || audit.record(&entry, &outcome)).await {
                    Ok(Ok(_)) => {}
                    Ok(Err(e)) => eprintln!("reports: the audit trail cannot be written ({e})"),
                    Err(e) => eprintln!("reports: the audit trail cannot be written ({e})"),
                }
            }
        }
    }
}

/// Starts the scheduled reports of `[reports]` (none without it).
pub(crate) fn start(s: &Service<'_>) {
    if let Some(cfg) = s.config.and_then(|c| c.reports.as_ref()) {
        spawn(s.dir, cfg, s.state.clone(), Arc::new(SystemClock), POLL);
    }
}

/// The task: looks at `clock` every `poll` at most (sooner when a shift
/// ends sooner) until the server closes.
fn spawn(dir: &Path, cfg: &Reports, state: Arc<AppState>, clock: Arc<dyn Clock>, poll: Duration) {
    let mut closing = state.closing();
    let mut scheduler = Scheduler::new(dir, cfg, state, clock.now_ms());
    tokio::spawn(async move {
        loop {
            let wait = scheduler.tick(clock.now_ms()).await.min(poll);
            tokio::select! {
                _ = tokio::time::sleep(wait) => {}
                _ = closing.changed() => return,
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_settings::ReportFormat;
    use std::sync::atomic::{AtomicI64, Ordering};

    /// A clock that moves only when told to.
    struct VirtualClock(AtomicI64);

    impl Clock for VirtualClock {
        fn now_ms(&self) -> i64 {
            self.0.load(Ordering::SeqCst)
        }
    }

    /// 2023-11-14T22:13:20Z.
    const T0: i64 = 1_700_000_000_000;

    fn cfg(hours: &[u8], offset_minutes: i32) -> Reports {
        Reports {
            folder: "reports".into(),
            shift_hours: hours.to_vec(),
            utc_offset_minutes: offset_minutes,
            formats: vec![ReportFormat::Xlsx, ReportFormat::Pdf],
        }
    }

    #[test]
    fn shift_changes_in_utc_and_local_time() {
        let s = Schedule::of(&cfg(&[6, 14, 22], 0));
        let day = T0.div_euclid(DAY_MS) * DAY_MS;
        assert_eq!(s.last_at_or_before(T0), day + 22 * HOUR_MS);
        assert_eq!(s.next_after(T0), day + DAY_MS + 6 * HOUR_MS);
        assert_eq!(s.start_of(day + 22 * HOUR_MS), day + 14 * HOUR_MS);
        assert_eq!(
            s.start_of(day + 6 * HOUR_MS),
            day - 2 * HOUR_MS,
            "the night shift began the day before"
        );
        assert_eq!(s.last_at_or_before(day + 6 * HOUR_MS), day + 6 * HOUR_MS);
        // UTC+1: the 06:00 change is at 05:00 UTC.
        let s = Schedule::of(&cfg(&[6, 14, 22], 60));
        assert_eq!(s.last_at_or_before(T0), day + 21 * HOUR_MS);
        assert_eq!(s.next_after(day + 21 * HOUR_MS), day + DAY_MS + 5 * HOUR_MS);
        // UTC-5 and a single daily change.
        let s = Schedule::of(&cfg(&[0], -300));
        assert_eq!(s.last_at_or_before(T0), day + 5 * HOUR_MS);
        assert_eq!(s.start_of(day + 5 * HOUR_MS), day + 5 * HOUR_MS - DAY_MS);
    }

    /// The tank with an alarm log holding alarms of a known shift, its
    /// state and its scratch folder.
    fn tank(test: &str) -> (Arc<AppState>, alba_runtime::Runtime, PathBuf) {
        use alba_alarms::{Event, Hub, Log, State};
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tank");
        let dir = std::env::temp_dir().join(format!("alba-app-reports-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join(".alba")).expect("scratch dir");
        for e in std::fs::read_dir(&src).expect("example").flatten() {
            if e.path().is_file() {
                std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy");
            }
        }
        let compiled = alba_server::project::load(&dir);
        let program = compiled.program.clone().expect("the tank compiles");
        let mut ro = alba_runtime::Options::new(compiled.project.scan_ms());
        ro.native = false;
        let runtime =
            alba_runtime::Runtime::start(Arc::new(program), ro, Box::new(alba_runtime::SimIo)).expect("runtime");
        let log = Log::open(&dir.join(".alba/alarms.db"), 30).expect("alarm log");
        let day = T0.div_euclid(DAY_MS) * DAY_MS;
        let ev = |t_ms: i64, from: State, to: State| Event {
            t_ms,
            id: "HighLevel".into(),
            tag: "Nivel_L".into(),
            from,
            to,
            value: 1.0,
            user: None,
            comment: None,
            severity: 250,
            message: "high level".into(),
        };
        // Three alarms in the night shift of the next day (22:00 → 06:00).
        let mut events = Vec::new();
        for k in 0..3 {
            let t = day + DAY_MS + 2 * HOUR_MS + k * 600_000;
            events.push(ev(t, State::Normal, State::ActiveUnacked));
            events.push(ev(t + 5_000, State::ActiveUnacked, State::ClearedUnacked));
        }
        log.append(&events, &[]).expect("events");
        let audit = alba_audit::Audit::open_project(&dir, alba_audit::Config::default()).expect("audit");
        let state = AppState::new(
            runtime.handle(),
            compiled,
            "sim",
            None,
            Some(audit),
            alba_server::auth::Auth::open(),
            &alba_settings::Http::default(),
        );
        assert!(state.control.set_alarms(Arc::new(Hub::new(Vec::new(), Some(log)))));
        (state, runtime, dir)
    }

    async fn wait_for(path: &Path) {
        for _ in 0..500 {
            if path.exists() {
                return;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        panic!("{} was not written", path.display());
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn the_report_of_a_finished_shift_is_written_to_the_folder() {
        use calamine::{Data, Reader, Xlsx};
        let (state, runtime, dir) = tank("scheduled");
        let day = T0.div_euclid(DAY_MS) * DAY_MS;
        let reports = dir.join("reports");
        // The night shift 22:00 → 06:00 is under way; the previous ones' files
        // are there already (the start writes only a missing one).
        let clock = Arc::new(VirtualClock(AtomicI64::new(day + DAY_MS + HOUR_MS)));
        std::fs::create_dir_all(&reports).expect("folder");
        for ext in ["xlsx", "pdf"] {
            let name = format!("shift-{}-1400.{ext}", &alba_control::audit::format_utc(day)[..10]);
            std::fs::write(reports.join(name), "earlier").expect("earlier report");
        }
        spawn(
            &dir,
            &cfg(&[6, 14, 22], 0),
            state.clone(),
            clock.clone(),
            Duration::from_millis(20),
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
        let stamp = |t: i64| alba_control::audit::format_utc(t)[..10].to_string();
        let night = reports.join(format!("shift-{}-2200.xlsx", stamp(day)));
        assert!(!night.exists(), "the shift has not ended");
        // 06:00 and the grace pass on the virtual clock.
        clock
            .0
            .store(day + DAY_MS + 6 * HOUR_MS + GRACE_MS + 1, Ordering::SeqCst);
        wait_for(&night).await;
        let pdf = night.with_extension("pdf");
        wait_for(&pdf).await;
        let bytes = std::fs::read(&night).expect("the workbook");
        let mut wb: Xlsx<_> = Xlsx::new(std::io::Cursor::new(bytes)).expect("an XLSX workbook");
        let sum = wb.worksheet_range("Summary").expect("Summary");
        let num = |r: u32| match sum.get_value((r, 1)) {
            Some(Data::Float(f)) => *f,
            other => panic!("row {r}: {other:?}"),
        };
        assert_eq!(num(3), (day + 22 * HOUR_MS) as f64, "from: 22:00");
        assert_eq!(num(4), (day + DAY_MS + 6 * HOUR_MS) as f64, "to: 06:00");
        assert_eq!(num(5), 3.0, "the night's three alarms");
        assert!(std::fs::read(&pdf).expect("pdf").starts_with(b"%PDF-"));
        // No temporary file left, the earlier files untouched.
        let names: Vec<String> = std::fs::read_dir(&reports)
            .expect("folder")
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 4, "{names:?}");
        assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
        // Audited, nobody's (each row once its file is written).
        let audit = state.control.audit().expect("audit");
        let filter = alba_control::audit::Filter {
            actions: vec![Action::Report],
            ..Default::default()
        };
        let mut rows = Vec::new();
        for _ in 0..500 {
            rows = audit.query(&filter, None, 10).expect("query").rows;
            if rows.len() >= 2 {
                break;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        assert_eq!(rows.len(), 2, "{rows:?}");
        assert!(
            rows.iter().all(|r| r.user.is_none() && r.outcome == Outcome::Ok),
            "{rows:?}"
        );
        assert!(
            rows.iter()
                .any(|r| r.target.as_deref() == Some(night.display().to_string().as_str())),
            "{rows:?}"
        );
        state.closing.send_replace(true);
        drop(runtime);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn a_folder_that_cannot_be_written_is_audited_failed_and_the_task_goes_on() {
        let (state, runtime, dir) = tank("unwritable");
        let day = T0.div_euclid(DAY_MS) * DAY_MS;
        // A file where the folder should be.
        std::fs::write(dir.join("reports"), "not a folder").expect("file");
        let mut s = Scheduler::new(&dir, &cfg(&[6, 14, 22], 0), state.clone(), day + 23 * HOUR_MS);
        s.done = day + 22 * HOUR_MS;
        s.tick(day + DAY_MS + 6 * HOUR_MS + GRACE_MS).await;
        let audit = state.control.audit().expect("audit");
        let rows = audit
            .query(&alba_control::audit::Filter::default(), None, 10)
            .expect("query")
            .rows;
        assert_eq!(rows.len(), 2, "{rows:?}");
        assert!(
            rows.iter().all(|r| matches!(r.outcome, Outcome::Failed(_))
                && r.detail.as_deref().is_some_and(|d| d.starts_with("shift "))),
            "{rows:?}"
        );
        // Moves on: the next shift is tried again.
        std::fs::remove_file(dir.join("reports")).expect("rm");
        s.tick(day + DAY_MS + 14 * HOUR_MS + GRACE_MS).await;
        assert!(
            dir.join("reports")
                .join(format!(
                    "shift-{}-0600.xlsx",
                    &alba_control::audit::format_utc(day + DAY_MS)[..10]
                ))
                .exists()
        );
        drop(runtime);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
