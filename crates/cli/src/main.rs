//! `alba`: the command-line front of Alba.

mod bench;
mod bench_modbus;
mod demo;
mod new;
mod run;

use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_engine::{Engine, sim::SimError};
use alba_model::{Code, Diagnostic, Files, diag::render_all, fsutil};
use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Parser)]
#[command(name = "alba", version, about = "Alba: an open PLC and SCADA studio", long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Compile a project and report every problem (exit 1 on errors).
    Check {
        /// The project folder (with alba.toml).
        project: PathBuf,
        /// One line per problem (`file:line:col: error[CODE]: message`).
        #[arg(long)]
        short: bool,
        /// Print the compiled IR.
        #[arg(long)]
        ir: bool,
    },
    /// Run a project in virtual time and write a trace (SPEC §10.2).
    Sim {
        project: PathBuf,
        /// Simulate scans at t = k·scan_ms while t <= UNTIL (milliseconds).
        #[arg(long, value_name = "MS")]
        until: u64,
        /// CSV `time_ms,tag,value` setting inputs before the first scan with t >= time_ms.
        #[arg(long, value_name = "CSV")]
        stimulus: Option<PathBuf>,
        /// Write the trace here instead of standard output.
        #[arg(long, value_name = "CSV")]
        trace: Option<PathBuf>,
        /// Comma-separated names to trace (tags, members, addresses, S:FS); default: every tag.
        #[arg(long, value_name = "LIST")]
        tags: Option<String>,
        /// Record every MS milliseconds (a multiple of the scan period; default: every scan).
        #[arg(long, value_name = "MS")]
        every: Option<u64>,
    },
    /// Create a runnable start/stop project in a new folder.
    New { dir: PathBuf },
    /// Benchmark the engine against native Rust on generated ladder programs.
    Bench {
        /// Rung counts to run (default 100,1000,10000).
        #[arg(long, value_delimiter = ',', value_name = "N,...")]
        sizes: Option<Vec<usize>>,
        /// Fewer repetitions, for a quick look.
        #[arg(long)]
        quick: bool,
        /// Benchmark the Modbus TCP server instead (FC3 x 10 registers; see docs/performance.md).
        #[arg(long)]
        modbus: bool,
        /// With --modbus: client counts to run (default 1,4,16).
        #[arg(long, value_delimiter = ',', value_name = "N,...")]
        clients: Option<Vec<usize>>,
        /// With --modbus: seconds per client count.
        #[arg(long, value_name = "S", default_value = "5")]
        seconds: f64,
        /// With --modbus: load this server (HOST:PORT) instead of starting Alba's own.
        #[arg(long, value_name = "ADDR:PORT")]
        target: Option<std::net::SocketAddr>,
        /// With --modbus: the first holding register read (default 8192 on Alba's own, 0 on --target).
        #[arg(long, value_name = "N")]
        start: Option<u16>,
    },
    /// Explain a diagnostic code (E301, ...).
    Explain { code: String },
    /// Run a project in real time and serve the studio and the API.
    Run {
        project: PathBuf,
        /// Address to serve on (loopback by default).
        #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8080")]
        http: std::net::SocketAddr,
        /// I/O driver: `sim` (plant models of the project, forces and writes).
        #[arg(long, default_value = "sim")]
        io: String,
        /// Interpret instead of compiling the program to native code.
        #[arg(long)]
        no_native: bool,
        /// Serve Modbus TCP (OpenPLC v3's address map) on this address (default: `[modbus] listen` of alba.toml, else off).
        #[arg(long, value_name = "ADDR:PORT")]
        modbus: Option<std::net::SocketAddr>,
        /// Serve OPC UA on this address (security None, anonymous: use loopback), e.g. 127.0.0.1:4840.
        #[arg(long, value_name = "ADDR:PORT")]
        opcua: Option<std::net::SocketAddr>,
    },
    /// Start the studio on the tank example with its simulated plant.
    Demo {
        /// Project folder: written on the first run, reused after (your edits are kept).
        #[arg(long, default_value = "alba-demo")]
        dir: PathBuf,
        /// Address to serve on (loopback by default).
        #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8080")]
        http: std::net::SocketAddr,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // Bad command-line input is an input error like any other.
            let text = e.render().to_string();
            let text = text.strip_prefix("error: ").unwrap_or(&text);
            eprint!("error[{}]: {text}", Code::BadArgument);
            return ExitCode::FAILURE;
        }
    };
    match cli.command {
        Command::Check { project, short, ir } => check(&project, short, ir),
        Command::Sim {
            project,
            until,
            stimulus,
            trace,
            tags,
            every,
        } => simulate(
            &project,
            until,
            stimulus.as_deref(),
            trace.as_deref(),
            tags.as_deref(),
            every,
        ),
        Command::New { dir } => new::run(&dir),
        Command::Bench {
            modbus: true,
            clients,
            seconds,
            target,
            start,
            ..
        } => bench_modbus::run(clients.as_deref().unwrap_or(&[1, 4, 16]), seconds, target, start),
        Command::Bench { sizes, quick, .. } => bench::run(sizes.as_deref().unwrap_or(&[100, 1_000, 10_000]), quick),
        Command::Explain { code } => explain(&code),
        Command::Run {
            project,
            http,
            io,
            no_native,
            modbus,
            opcua,
        } => run::run(&project, http, &io, !no_native, modbus, opcua, None),
        Command::Demo { dir, http } => demo::run(&dir, http, true),
    }
}

/// Prints diagnostics to stderr.
fn report(diags: &[Diagnostic], files: &Files, short: bool) {
    let text = if short {
        let mut s: String = diags.iter().map(|d| d.short(files) + "\n").collect();
        s.push_str(&format!(
            "{} error{}\n",
            diags.len(),
            if diags.len() == 1 { "" } else { "s" }
        ));
        s
    } else {
        render_all(diags, files)
    };
    eprint!("{text}");
}

fn check(dir: &Path, short: bool, ir: bool) -> ExitCode {
    let c = alba_compiler::compile_dir(dir);
    let Some(program) = &c.program else {
        report(&c.diagnostics, c.files(), short);
        return ExitCode::FAILURE;
    };
    if ir {
        print!("{}", program.dump());
    }
    let rungs = program.rungs.len();
    let tags = program.layout.tags.len();
    let n = |k: usize, what: &str| format!("{k} {what}{}", if k == 1 { "" } else { "s" });
    eprintln!(
        "{}: ok ({}, {}, {}, {})",
        dir.display(),
        n(program.units.len(), "program"),
        n(rungs, "rung"),
        n(tags, "tag"),
        n(program.ops.len(), "op")
    );
    ExitCode::SUCCESS
}

fn fail(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::FAILURE
}

fn simulate(
    dir: &Path,
    until: u64,
    stimulus: Option<&Path>,
    trace: Option<&Path>,
    tags: Option<&str>,
    every: Option<u64>,
) -> ExitCode {
    let c = alba_compiler::compile_dir(dir);
    let Some(program) = c.program else {
        report(&c.diagnostics, &c.project.files, false);
        return ExitCode::FAILURE;
    };
    let scan_ms = c.project.scan_ms() as u64;
    let every = every.unwrap_or(scan_ms);
    if every == 0 || !every.is_multiple_of(scan_ms) {
        let d = Diagnostic::unplaced(
            Code::BadArgument,
            format!("--every {every} is not a positive multiple of the scan period ({scan_ms} ms)"),
        );
        report(&[d], &c.project.files, false);
        return ExitCode::FAILURE;
    }
    let layout = &program.layout;
    let mut files = Files::new();
    let stim = match stimulus {
        None => Stimulus::default(),
        Some(path) => {
            let text = match alba_model::project::read_text(path) {
                Ok(t) => t,
                Err(msg) => {
                    report(&[Diagnostic::unplaced(Code::Io, msg)], &files, false);
                    return ExitCode::FAILURE;
                }
            };
            let f = files.add(path.display().to_string(), text);
            match Stimulus::parse(files.text(f), f, layout) {
                Ok(s) => s,
                Err(d) => {
                    report(&d, &files, false);
                    return ExitCode::FAILURE;
                }
            }
        }
    };
    let cols = match tags {
        Some(list) => match sim::columns(list, layout) {
            Ok(c) => c,
            Err(d) => {
                report(&d, &files, false);
                return ExitCode::FAILURE;
            }
        },
        None => sim::all_columns(layout),
    };
    let mut engine = match Engine::new(Arc::new(program)) {
        Ok(e) => e,
        Err(e) => {
            return fail(format!("internal error: the compiled program does not verify: {e}"));
        }
    };
    let opt = SimOptions {
        scan_ms,
        until_ms: until,
        every_ms: every,
    };
    let result = match trace {
        Some(path) => {
            let mut outcome = Ok(());
            let io = fsutil::write_atomic(path, |w| {
                outcome = sim::run(&mut engine, &stim, &cols, opt, w);
                match &outcome {
                    Err(SimError::Io(e)) => Err(std::io::Error::new(e.kind(), e.to_string())),
                    Err(SimError::Major(m)) => Err(std::io::Error::other(m.message.clone())),
                    Ok(()) => Ok(()),
                }
            });
            match (outcome, io) {
                (Err(e), _) => Err(e),
                (Ok(()), Err(e)) => Err(SimError::Io(e)),
                (Ok(()), Ok(())) => Ok(()),
            }
        }
        None => {
            let stdout = std::io::stdout();
            let mut w = std::io::BufWriter::new(stdout.lock());
            sim::run(&mut engine, &stim, &cols, opt, &mut w).and_then(|()| w.flush().map_err(SimError::Io))
        }
    };
    if let Some(f) = engine.faults().first {
        eprintln!(
            "warning: {} minor fault(s); first: {}",
            engine.faults().count,
            engine.describe_fault(&f)
        );
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(SimError::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(SimError::Io(e)) => fail(format!("cannot write the trace: {e}")),
        Err(SimError::Major(m)) => fail(format!("major fault: {}", m.message)),
    }
}

fn explain(code: &str) -> ExitCode {
    match code.parse::<Code>() {
        Ok(c) => {
            println!("{c}: {}\n\n{}", c.title(), c.explanation());
            ExitCode::SUCCESS
        }
        Err(()) => {
            eprintln!("error: unknown code `{code}`; codes are:");
            for c in Code::ALL {
                eprintln!("  {c}  {}", c.title());
            }
            ExitCode::FAILURE
        }
    }
}
