//! `POST /api/nets/{name}/analysis`: the analysis of a net of the project
//! (docs/nets.md "Analysis"), streamed as JSON lines: progress while it runs,
//! then the same object as `alba analyze --json`. `{name}` is the program as
//! listed (`line.pnml`) or the net's name (`line`). One analysis at a time per
//! project (`429` while one runs), on a thread of its own at the least
//! priority (SCHED_BATCH, nice 19: the engine, the server and the drivers
//! come first), within [`ANALYSIS_MEMORY`] and
//! [`ANALYSIS_TIME`]; it stops when the client goes away. With `examination` (and
//! its `formulas`), the contest's examination instead, its result the object of
//! `alba analyze --examination E --json` (docs/api.md "Nets").
//!
//! `POST /api/nets/{name}/reset`: writes the net's initial marking at one
//! scan boundary (docs/nets.md "Live view").

use super::audit::Actor;
use crate::error::{ApiError, ApiResult};
use crate::reply::{MarkingValue, NetReset};
use crate::state::AppState;
use alba_compiler::diag::FileId;
use alba_compiler::net;
use alba_compiler::petri::net_name;
use alba_compiler::project::Language;
use axum::Json;
use axum::body::{Body, Bytes};
use axum::extract::{Path, State};
use axum::response::{IntoResponse, Response};
use net::PtNet;
use net::analysis::formula::{self, Property};
use net::analysis::stubborn::{self, CheckOptions};
use net::analysis::{Control, Invariants, Options, Progress, SymbolicMode, analyze, to_json};
use serde_json::{Value, json};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tokio::sync::{oneshot, watch};

/// States explored unless `max_states` says otherwise, and the most it may say.
pub const DEFAULT_MAX_STATES: usize = 1_000_000;
pub const MAX_STATES: usize = 10_000_000;
/// Memory the state space of one analysis may use.
pub const ANALYSIS_MEMORY: usize = 256 << 20;
/// How long one analysis may run.
pub const ANALYSIS_TIME: Duration = Duration::from_secs(120);
/// Least time between two progress lines.
const PROGRESS_EVERY: Duration = Duration::from_millis(250);

/// The request body (all optional; an empty body is `{}`).
#[derive(serde::Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
struct Request {
    max_states: Option<usize>,
    /// `"flows"` or `"minimal"` (default).
    invariants: Option<String>,
    /// Count the states with decision diagrams first (`alba analyze --symbolic`); by
    /// default they run only when the explicit state space does not fit in memory.
    symbolic: bool,
    /// Seconds the analysis may run, at most (and by default) [`ANALYSIS_TIME`].
    time_limit_s: Option<u64>,
    /// A contest examination instead of the analysis: `UpperBounds`,
    /// `ReachabilityCardinality`, `ReachabilityFireability` (with `formulas`) or
    /// `ReachabilityDeadlock`.
    examination: Option<String>,
    /// The examination's formula file (the contest's XML), as text.
    formulas: Option<String>,
}

/// The contest's examinations the analysis answers.
const EXAMINATIONS: [&str; 4] = [
    "UpperBounds",
    "ReachabilityCardinality",
    "ReachabilityFireability",
    "ReachabilityDeadlock",
];

/// Raises the cancellation flag when dropped: the client went away, or the
/// answer ended.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// The running analysis, as the answer's stream sees it.
struct Job {
    _cancel: CancelOnDrop,
    cancel: Arc<AtomicBool>,
    progress: watch::Receiver<Option<Value>>,
    progress_open: bool,
    result: oneshot::Receiver<Value>,
    deadline: tokio::time::Instant,
    timed_out: bool,
    done: bool,
}

/// The analysis thread's scheduling: SCHED_BATCH at nice 19, the least share of
/// the CPU that still makes progress on a busy machine (SCHED_IDLE could starve it
/// for ever, and a starved analysis cannot even see that it was cancelled).
pub(crate) fn lowest_priority() {
    use thread_priority::{
        NormalThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy, set_thread_priority_and_policy,
        thread_native_id,
    };
    let _ = set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Min,
        ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Batch),
    );
}

fn progress_json(p: &Progress) -> Value {
    json!({"part": p.part.name(), "states": p.states, "bytes": p.bytes})
}

pub async fn analysis(State(st): State<Arc<AppState>>, Path(name): Path<String>, body: Bytes) -> ApiResult<Response> {
    let req: Request = if body.iter().all(u8::is_ascii_whitespace) {
        Request::default()
    } else {
        serde_json::from_slice(&body).map_err(|e| ApiError::Malformed(format!("the analysis request: {e}")))?
    };
    let max_states = match req.max_states {
        None => DEFAULT_MAX_STATES,
        Some(n @ 1..=MAX_STATES) => n,
        Some(n) => {
            return Err(ApiError::Invalid(format!(
                "`max_states` is 1 to {MAX_STATES}, not `{n}`"
            )));
        }
    };
    let invariants = match req.invariants.as_deref() {
        None | Some("minimal") => Invariants::Minimal,
        Some("flows") => Invariants::Flows,
        Some(v) => {
            return Err(ApiError::Invalid(format!(
                "`invariants` is `flows` or `minimal`, not `{v}`"
            )));
        }
    };
    let limit = match req.time_limit_s {
        None => ANALYSIS_TIME,
        Some(n @ 1..) if n <= ANALYSIS_TIME.as_secs() => Duration::from_secs(n),
        Some(n) => {
            return Err(ApiError::Invalid(format!(
                "`time_limit_s` is 1 to {}, not `{n}`",
                ANALYSIS_TIME.as_secs()
            )));
        }
    };
    match (req.examination.as_deref(), &req.formulas) {
        (None, None) => {}
        (None, Some(_)) => return Err(ApiError::Invalid("`formulas` needs an `examination`".into())),
        (Some(e), _) if !EXAMINATIONS.contains(&e) => {
            return Err(ApiError::Invalid(format!(
                "`examination` is one of {}, not `{e}`",
                EXAMINATIONS.join(", ")
            )));
        }
        (Some("ReachabilityDeadlock"), Some(_)) => {
            return Err(ApiError::Invalid(
                "ReachabilityDeadlock has no formula file (it is EF deadlock)".into(),
            ));
        }
        (Some("ReachabilityDeadlock"), None) | (Some(_), Some(_)) => {}
        (Some(e), None) => {
            return Err(ApiError::Invalid(format!(
                "{e} needs its `formulas` (the XML file's text)"
            )));
        }
    }
    let examination = req.examination.clone();
    let formulas = req.formulas.clone();
    let (_, file, text) = find(&st, &name).await?;
    let permit = st.analysis.clone().try_acquire_owned().map_err(|_| {
        ApiError::Busy("an analysis of this project is running: wait for it to end, or cancel it".into())
    })?;
    // Loading (and the formulas) are checked first, so a net that does not load or a
    // formula file that does not read is a 422.
    let (pt, props) = tokio::task::spawn_blocking(move || -> Result<(PtNet, Option<Vec<Property>>), String> {
        let (net, diags, unfolding) = net::load_for_analysis(file, &text);
        let errors: Vec<_> = diags.iter().filter(|d| !net::is_warning(d)).collect();
        let pt = match net {
            Some(n) if errors.is_empty() => PtNet::from_net(&n),
            _ => {
                return Err(format!(
                    "the net does not load: {}",
                    errors
                        .first()
                        .map_or_else(|| "it does not load".to_string(), |d| d.message.clone())
                ));
            }
        };
        let props = match (examination.as_deref(), formulas) {
            (None, _) => None,
            (Some(_), Some(f)) => Some(
                formula::parse_for(&f, &pt, unfolding.as_ref())
                    .map_err(|e| format!("the formulas, line {}, column {}: {}", e.line, e.column, e.message))?,
            ),
            (Some(_), None) => Some(vec![formula::deadlock_property()]),
        };
        Ok((pt, props))
    })
    .await
    .map_err(|e| ApiError::Internal(e.to_string()))?
    .map_err(ApiError::Invalid)?;
    let cancel = Arc::new(AtomicBool::new(false));
    let (progress_tx, progress_rx) = watch::channel(None);
    let (result_tx, result_rx) = oneshot::channel();
    let options = Options {
        max_states,
        memory: ANALYSIS_MEMORY,
        invariants,
        symbolic: if req.symbolic {
            SymbolicMode::Always
        } else {
            SymbolicMode::Auto
        },
        ..Options::default()
    };
    let flag = cancel.clone();
    let lang = crate::lang::request_lang();
    std::thread::Builder::new()
        .name("net-analysis".into())
        .spawn(move || {
            lowest_priority();
            let last = std::sync::Mutex::new(Instant::now());
            let report = |p: &Progress| {
                if let Ok(mut t) = last.lock()
                    && t.elapsed() >= PROGRESS_EVERY
                {
                    *t = Instant::now();
                    progress_tx.send_replace(Some(progress_json(p)));
                }
            };
            let control = Control {
                cancel: &flag,
                progress: &report,
            };
            let json = match (&props, &req.examination) {
                (Some(props), Some(e)) => {
                    // The contest's examination: its exploration within the same
                    // limits, stopped past the memory budget like the analysis.
                    let over = |p: &Progress| {
                        report(p);
                        if p.bytes > ANALYSIS_MEMORY {
                            flag.store(true, Ordering::Relaxed);
                        }
                    };
                    let control = Control {
                        cancel: &flag,
                        progress: &over,
                    };
                    let check = CheckOptions {
                        max_states,
                        ..CheckOptions::default()
                    };
                    stubborn::answers_json(&pt, e, &stubborn::answer(&pt, props, &check, &control))
                }
                _ => {
                    let mut json = to_json(&pt, &analyze(&pt, &options, &control));
                    word_notes(lang, &mut json);
                    json
                }
            };
            // The next analysis may start once this one's result is out.
            drop(permit);
            let _ = result_tx.send(json);
        })
        .map_err(|e| ApiError::Internal(format!("cannot start the analysis: {e}")))?;
    let job = Job {
        _cancel: CancelOnDrop(cancel.clone()),
        cancel,
        progress: progress_rx,
        progress_open: true,
        result: result_rx,
        deadline: tokio::time::Instant::now() + limit,
        timed_out: false,
        done: false,
    };
    let lines = futures_util::stream::unfold(job, |mut job| async move {
        if job.done {
            return None;
        }
        loop {
            tokio::select! {
                r = &mut job.result => {
                    job.done = true;
                    let line = match r {
                        Ok(result) => json!({"result": result, "timed_out": job.timed_out}),
                        Err(_) => json!({"error": "the analysis ended without a result"}),
                    };
                    return Some((Ok::<_, std::io::Error>(Bytes::from(format!("{line}\n"))), job));
                }
                changed = job.progress.changed(), if job.progress_open => {
                    if changed.is_err() {
                        job.progress_open = false;
                        continue;
                    }
                    let p = job.progress.borrow_and_update().clone();
                    if let Some(p) = p {
                        return Some((Ok(Bytes::from(format!("{}\n", json!({"progress": p})))), job));
                    }
                }
                _ = tokio::time::sleep_until(job.deadline), if !job.timed_out => {
                    job.timed_out = true;
                    job.cancel.store(true, Ordering::Relaxed);
                }
            }
        }
    });
    Ok((
        [
            (axum::http::header::CONTENT_TYPE, "application/x-ndjson"),
            (axum::http::header::CACHE_CONTROL, "no-store"),
        ],
        Body::from_stream(lines),
    )
        .into_response())
}

/// The analysis's `notes` and `stopped`, which alba-net writes in English as the
/// command line prints them, in the language of the request (the phrase book of
/// `alba_diag::es`; a text it lacks stays English).
fn word_notes(lang: alba_compiler::diag::Lang, json: &mut serde_json::Value) {
    let word = |t: &mut serde_json::Value| {
        if let Some(s) = t.as_str() {
            *t = crate::lang::phrased(lang, s).into();
        }
    };
    if let Some(notes) = json.get_mut("notes").and_then(serde_json::Value::as_array_mut) {
        notes.iter_mut().for_each(word);
    }
    if let Some(stopped) = json.get_mut("stopped") {
        word(stopped);
    }
}

/// The net program `name` names (as listed, or the net's name): its listed
/// name, file and saved text.
async fn find(st: &AppState, name: &str) -> ApiResult<(String, FileId, String)> {
    let p = st.project.lock().await;
    let src = p
        .project
        .programs
        .iter()
        .filter(|s| s.language == Language::Net)
        .find(|s| s.name.eq_ignore_ascii_case(name) || net_name(&s.name).eq_ignore_ascii_case(name))
        .ok_or_else(|| ApiError::NotFound(format!("no net `{name}` in the project")))?;
    Ok((src.name.clone(), src.file, p.project.files.text(src.file).to_string()))
}

/// The initial marking of a net: (marking tag, value) for each place, and in
/// normal mode each transition (0), as the net's first scan loads it.
fn initial_marking(program: &str, net: &net::Net) -> Vec<(String, i32)> {
    let name = net_name(program);
    let tag = |id: &str| alba_compiler::petri::marking_tag(&name, id);
    let normal = net.mode == net::Mode::Normal;
    let mut out: Vec<(String, i32)> = net
        .places
        .iter()
        .map(|p| {
            let m = i32::try_from(p.initial).unwrap_or(i32::MAX);
            (tag(&p.id), if normal { m.min(1) } else { m })
        })
        .collect();
    if normal {
        out.extend(net.transitions.iter().map(|t| (tag(&t.id), 0)));
    }
    out
}

/// Audited (`reset_marking`, target the program, new the marking): every
/// marking tag of the saved net gets its initial value, all at one scan
/// boundary. `422` when the net does not load or the running program has not
/// got its marking tags (the net saved but not applied).
pub async fn reset(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    actor: Actor,
) -> ApiResult<Json<NetReset>> {
    let (program, file, text) = find(&st, &name).await?;
    let (net, diags) = net::load(file, &text);
    let Some(net) = net.filter(|_| diags.iter().all(net::is_warning)) else {
        let first = diags
            .iter()
            .find(|d| !net::is_warning(d))
            .map_or_else(|| "it does not load".to_string(), |d| d.message.clone());
        return Err(ApiError::Invalid(format!("the net does not load: {first}")));
    };
    let marking = initial_marking(&program, &net);
    st.control.reset_marking(&actor.control(), &program, &marking).await?;
    let reply = NetReset {
        program,
        marking: marking
            .into_iter()
            .map(|(tag, value)| MarkingValue { tag, value })
            .collect(),
    };
    Ok(Json(reply))
}
