//! `POST /api/pid/{name}/autotune` (engineer): the relay-feedback experiment
//! of `alba tune` (docs/pid.md §6) for the faceplate — on a copy of the
//! running program and its plant models, in virtual time from the initial
//! state, off the async executor; the running PLC is not touched. The reply
//! is Ku, Pu and the rules' gains; applying them is an ordinary tag write.

use crate::error::{ApiError, ApiResult};
use crate::state::AppState;
use alba_control::autotune::{RelayOptions, rules, tune};
use alba_ir::Target;
use axum::Json;
use axum::extract::{Path, State};
use serde::Deserialize;
use serde_json::{Value as JsonValue, json};
use std::sync::Arc;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Request {
    /// The setpoint during the experiment (the loop's initial one if absent).
    #[serde(default)]
    sp: Option<f64>,
    /// Relay amplitude d, % of CV.
    #[serde(default = "d_amplitude")]
    amplitude: f64,
    /// Relay centre, % of CV (if absent: the loop's output once it holds the
    /// plant at SP, alba_control::autotune).
    #[serde(default)]
    bias: Option<f64>,
    /// Hysteresis h, engineering units of the PV.
    #[serde(default)]
    hysteresis: f64,
    /// Give up after this long of virtual time, s.
    #[serde(default = "d_until")]
    until_s: u64,
}

fn d_amplitude() -> f64 {
    10.0
}
fn d_until() -> u64 {
    600
}

pub async fn autotune(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    body: Result<Json<Request>, axum::extract::rejection::JsonRejection>,
) -> ApiResult<Json<JsonValue>> {
    let Json(r) = body.map_err(|e| ApiError::Malformed(e.body_text()))?;
    let ok = |v: f64, lo: f64, hi: f64| v.is_finite() && (lo..=hi).contains(&v);
    if !ok(r.amplitude, 0.1, 100.0) || !r.bias.is_none_or(|b| ok(b, 0.0, 100.0)) || !ok(r.hysteresis, 0.0, 1e9) {
        return Err(ApiError::Invalid(
            "amplitude is 0.1 to 100 %, bias 0 to 100 %, hysteresis 0 or more".into(),
        ));
    }
    if !(10..=86_400).contains(&r.until_s) || r.sp.is_some_and(|v| !v.is_finite()) {
        return Err(ApiError::Invalid("until_s is 10 to 86 400 s; sp a number".into()));
    }
    let program = st.runtime.snapshot().program.clone();
    match program.layout.resolve(&name) {
        Ok(Target::Pid(_)) => {}
        Ok(_) => return Err(ApiError::Invalid(format!("`{name}` is not a PID loop"))),
        Err(e) => return Err(ApiError::NotFound(e.to_string())),
    }
    if program.plants.is_empty() {
        return Err(ApiError::Invalid(
            "the project has no [[plant_model]] to tune against (docs/pid.md §3)".into(),
        ));
    }
    let scan_ms = u64::from(st.scan_ms);
    let result = tokio::task::spawn_blocking(move || {
        let opt = RelayOptions {
            scan_ms,
            amplitude: r.amplitude,
            bias: r.bias,
            hysteresis: r.hysteresis,
            until_ms: r.until_s * 1000,
            cycles: 4,
        };
        tune(program, &name, r.sp, opt)
    })
    .await
    .map_err(|e| ApiError::Internal(e.to_string()))?
    .map_err(|e| ApiError::Invalid(format!("relay experiment: {e}")))?;
    let gains: Vec<JsonValue> = rules(result.ku, result.pu)
        .iter()
        .map(|g| {
            let (kp, ki, kd) = g.independent();
            json!({"rule": g.rule, "kc": g.kc, "ti": g.ti, "td": g.td, "kp": kp, "ki": ki, "kd": kd})
        })
        .collect();
    Ok(Json(json!({
        "ku": result.ku, "pu": result.pu, "a": result.a, "cycles": result.cycles, "bias": result.bias, "rules": gains,
    })))
}
