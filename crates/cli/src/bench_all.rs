//! `alba bench --all`: every benchmark in turn (each of its own module:
//! `bench` for the engine, nets, historian and online edits; `bench_modbus`,
//! `bench_realtime`, `bench_mqtt`). Numbers printed, never asserted.

use crate::{bench, bench_modbus, bench_mqtt, bench_realtime, bench_st};
use std::process::ExitCode;

/// `alba bench --all`: every benchmark in turn, each with its defaults
/// (`secs` per row of the Modbus and real-time ones); fails if one does.
pub fn all(quick: bool, secs: f64, priority: u8, cpu: Option<usize>) -> ExitCode {
    let mut failed = Vec::new();
    let mut part = |name: &'static str, f: &dyn Fn() -> ExitCode| {
        println!("\n== alba bench: {name} ==\n");
        if f() != ExitCode::SUCCESS {
            failed.push(name);
        }
    };
    part("engine", &|| bench::run(&[100, 1_000, 10_000], quick));
    part("structured text", &|| bench_st::run(&[100, 1_000, 10_000], quick));
    part("nets", &|| bench::nets(quick));
    part("historian", &|| bench::historian(quick));
    part("modbus", &|| bench_modbus::run(&[1, 4, 16], secs, None, None));
    part("realtime", &|| bench_realtime::run(secs, priority, cpu));
    part("mqtt", &|| bench_mqtt::run(&[100, 1_000], secs, None));
    part("online edit", &|| {
        bench::swap(if quick { &[10_000] } else { &[10_000, 50_000] })
    });
    println!(
        "\nNot run here (it needs a browser): engine → browser DOM latency with 1, 10 and 50 studios,\n\
         `cd web && ALBA_BIN=../target/release/alba node bench/studios.mjs` (docs/performance.md)."
    );
    if failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        eprintln!("error: failed: {}", failed.join(", "));
        ExitCode::FAILURE
    }
}
