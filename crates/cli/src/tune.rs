//! `alba tune`: relay-feedback autotuning of a PID loop against the
//! project's plant models, in virtual time (docs/pid.md §6).

use alba_diag::{Code, Diagnostic};
use alba_engine::autotune::{RelayOptions, rules, tune};
use alba_ir::Target;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

pub struct TuneArgs<'a> {
    pub dir: &'a Path,
    pub pid: &'a str,
    pub sp: Option<f64>,
    pub amplitude: f64,
    pub bias: Option<f64>,
    pub hysteresis: f64,
    pub until: u64,
    pub cycles: usize,
}

pub fn run(a: TuneArgs) -> ExitCode {
    let c = alba_load::compile_dir(a.dir);
    let Some(program) = c.program else {
        super::report(&c.diagnostics, &c.project.files, false);
        return ExitCode::FAILURE;
    };
    let bad = |msg: String| {
        super::report(&[Diagnostic::unplaced(Code::BadArgument, msg)], &c.project.files, false);
        ExitCode::FAILURE
    };
    match program.layout.resolve(a.pid) {
        Ok(Target::Pid(_)) => {}
        Ok(_) => return bad(format!("--loop: `{}` is not a PID tag", a.pid)),
        Err(e) => return bad(format!("--loop: {e}")),
    }
    if program.plants.is_empty() {
        return bad("the project has no [[plant_model]] to tune against (docs/pid.md §3)".into());
    }
    if a.cycles < 2 {
        return bad("--cycles must be 2 or more".into());
    }
    let scan_ms = u64::from(c.project.scan_ms());
    let opt = RelayOptions {
        scan_ms,
        amplitude: a.amplitude,
        bias: a.bias,
        hysteresis: a.hysteresis,
        until_ms: a.until,
        cycles: a.cycles,
    };
    let r = match tune(Arc::new(program), a.pid, a.sp, opt) {
        Ok(r) => r,
        Err(e) => return super::fail(format!("relay experiment: {e}")),
    };
    println!(
        "relay ±{} % around {} %, hysteresis {}: {} cycles, PV fundamental ±{:.4} (peaks ±{:.4})",
        a.amplitude, r.bias, a.hysteresis, r.cycles, r.a, r.a_peak
    );
    println!("Ku = {:.4} (%CV per % of the PV span), Pu = {:.3} s\n", r.ku, r.pu);
    println!("| rule | KC | TI (s) | TD (s) | KP | KI (1/s) | KD (s) |");
    println!("|---|---|---|---|---|---|---|");
    for g in rules(r.ku, r.pu) {
        let (kp, ki, kd) = g.independent();
        println!(
            "| {} | {:.4} | {:.3} | {:.3} | {:.4} | {:.5} | {:.4} |",
            g.rule, g.kc, g.ti, g.td, kp, ki, kd
        );
    }
    let (kp, ki, _) = rules(r.ku, r.pu)[3].independent();
    println!("\nIn tags.csv (Tyreus-Luyben PI, independent gains): \"KP={kp:.4};KI={ki:.5}\"");
    ExitCode::SUCCESS
}
