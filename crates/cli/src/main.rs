//! `alba`: the command-line front of Alba.

mod analyze;
mod audit;
mod bench;
mod bench_all;
mod bench_modbus;
mod bench_mqtt;
mod bench_realtime;
mod bench_st;
mod copy;
mod demo;
mod export;
mod firmware;
mod historian;
mod import;
mod new;
mod run;
mod tune;
mod user;
mod verify;

use alba_diag::{Code, Diagnostic, Files, render_all};
use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_engine::{Engine, sim::SimError};
use alba_model::fsutil;
use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Parser)]
#[command(name = "alba", version, about = "Alba: an open PLC and SCADA studio", long_about = None)]
struct Cli {
    /// The language of messages: en or es (default: LC_ALL, LC_MESSAGES or
    /// LANG, else English).
    #[arg(long, global = true, value_name = "LANG")]
    lang: Option<String>,
    #[command(subcommand)]
    command: Command,
}

/// The language asked for by `--lang X` or `--lang=X` among `args`, if any.
fn lang_arg(args: &[String]) -> Option<&str> {
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--" {
            break;
        }
        if a == "--lang" {
            return it.next().map(String::as_str);
        }
        if let Some(v) = a.strip_prefix("--lang=") {
            return Some(v);
        }
    }
    None
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
        /// Run the generated Arduino firmware on an emulated MCU (simavr) instead of the
        /// engine: same stimulus, same trace form (I/O read on the pins, the rest in memory).
        #[arg(long)]
        firmware: bool,
        /// With --firmware: run the byte-code interpreter firmware with the project's byte
        /// code in its EEPROM (docs/bytecode.md) instead of the compiled sketch.
        #[arg(long, requires = "firmware")]
        bytecode: bool,
        #[command(flatten)]
        board: export::BoardArgs,
        /// Step-response figures of traced signals: SIGNAL or SIGNAL:REFERENCE, comma-separated
        /// (overshoot, rise time, 98 % settling time, IAE); printed after the run.
        #[arg(long, value_name = "LIST")]
        summary: Option<String>,
        /// Evaluate the project's alarms.csv on every scan and write each change of state
        /// here as CSV (`time_ms,alarm,tag,from,to,value,severity,message`; docs/alarms.md).
        #[arg(long, value_name = "CSV", conflicts_with = "firmware")]
        alarms: Option<PathBuf>,
    },
    /// Download the project's byte code to a board running Alba's byte-code interpreter
    /// (`alba export interpreter`), over its serial port (docs/bytecode.md, "Download").
    /// The board: --board, else `[board]` of alba.toml, else the one the interpreter says it is.
    Download {
        /// The project whose byte code to send (not with --read).
        #[arg(required_unless_present = "read")]
        project: Option<PathBuf>,
        /// The board's serial port.
        #[arg(long, value_name = "PORT")]
        port: String,
        #[command(flatten)]
        board: export::BoardArgs,
        /// Read the program back afterwards and compare.
        #[arg(long, conflicts_with = "read")]
        verify: bool,
        /// Download nothing: read the board's running program into FILE (raw bytes;
        /// Intel HEX when FILE ends in `.hex`, and on standard output for `-`).
        #[arg(long, value_name = "FILE", conflicts_with = "project")]
        read: Option<PathBuf>,
    },
    /// Convert a program written with another tool — LDmicro `.ld`, PLCopen TC6 XML,
    /// Studio 5000 `.L5X`, an AuroraLD Studio project folder — into a new Alba project,
    /// with a report of what was converted, approximated or refused (docs/interchange.md).
    Import {
        /// The file to import, or an AuroraLD project folder (or its main.ara).
        file: PathBuf,
        /// The project folder to write (new or empty, unless --force).
        #[arg(short, long, value_name = "DIR")]
        out: PathBuf,
        /// The input's format (default: detected from its content, then its extension).
        #[arg(long, value_name = "FORMAT", value_parser = ["ldmicro", "plcopen", "l5x", "aurora"])]
        format: Option<String>,
        /// Wire the I/O to this Arduino board's pins (uno, nano or mega; LDmicro and AuroraLD).
        #[arg(long, value_name = "BOARD", value_parser = ["uno", "nano", "mega"])]
        board: Option<String>,
        /// Replace the project files of an existing, non-empty folder.
        #[arg(long)]
        force: bool,
    },
    /// Export the project to another form.
    Export {
        #[command(subcommand)]
        to: Export,
    },
    /// Create a runnable start/stop project in a new folder.
    New {
        dir: PathBuf,
        /// Start from a state net (normal mode, with a ladder program) instead of ladder alone.
        #[arg(long)]
        net: bool,
    },
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
        /// Benchmark nets instead: a net's scan against the same Ladder, and the analysis (states/s, Kanban 5).
        #[arg(long, conflicts_with = "modbus")]
        nets: bool,
        /// Benchmark MQTT publishing instead: tag changes per second through a broker, latency, scan jitter
        /// (JSON and Sparkplug B; see docs/performance.md).
        #[arg(long, conflicts_with_all = ["modbus", "nets"])]
        mqtt: bool,
        /// With --mqtt: tag counts to run, every tag changing every 10 ms scan (default 100,1000).
        #[arg(long, value_delimiter = ',', value_name = "N,...")]
        tags: Option<Vec<usize>>,
        /// With --mqtt: the broker (HOST:PORT); default: a Mosquitto started for the bench on loopback.
        #[arg(long, value_name = "HOST:PORT")]
        broker: Option<String>,
        /// Measure the scan start lateness of `alba run` instead (cyclictest-like; 1 ms and 10 ms, idle and
        /// under Modbus/HTTP/WebSocket/OPC UA/historian load, normal and SCHED_FIFO; see docs/performance.md).
        #[arg(long, conflicts_with_all = ["modbus", "nets", "mqtt"])]
        realtime: bool,
        /// Benchmark the historian instead: ingest (every tag of a 10 000-tag project) and 1 000-point
        /// queries over 10 M samples (1 M with --quick).
        #[arg(long, conflicts_with_all = ["modbus", "nets", "realtime", "mqtt"])]
        historian: bool,
        /// Run every benchmark in turn: the engine, nets, the historian, Modbus, real time, MQTT (--quick: shorter).
        /// The studio's DOM latency needs a browser: web/bench/studios.mjs (docs/performance.md).
        #[arg(long, conflicts_with_all = ["modbus", "nets", "realtime", "historian", "mqtt"])]
        all: bool,
        /// With --realtime: the SCHED_FIFO priority to try (1 to 99).
        #[arg(long, value_name = "P", default_value = "80")]
        priority: u8,
        /// With --realtime: pin the engine thread to this CPU (`[runtime] cpu`).
        #[arg(long, value_name = "N")]
        cpu: Option<usize>,
        /// With --modbus: client counts to run (default 1,4,16).
        #[arg(long, value_delimiter = ',', value_name = "N,...")]
        clients: Option<Vec<usize>>,
        /// With --modbus and --realtime: seconds per row (a client count for --modbus); with --mqtt: per row.
        #[arg(long, value_name = "S", default_value = "5")]
        seconds: f64,
        /// With --modbus: load this server (HOST:PORT) instead of starting Alba's own.
        #[arg(long, value_name = "ADDR:PORT")]
        target: Option<std::net::SocketAddr>,
        /// With --modbus: the first holding register read (default 8192 on Alba's own, 0 on --target).
        #[arg(long, value_name = "N")]
        start: Option<u16>,
        /// Measure the gap an online edit leaves between two scans instead (before and after it was
        /// prepared off the engine thread), on --sizes rungs (default 10000,50000).
        #[arg(long, conflicts_with_all = ["modbus", "nets", "realtime", "historian", "mqtt", "all"])]
        swap: bool,
        /// Run only the Structured Text contender of the scan benchmark (the benchmark rung in ST, and
        /// programs of 1 000 and 10 000 lines; see docs/performance.md).
        #[arg(long, conflicts_with_all = ["modbus", "nets", "realtime", "historian", "mqtt", "all", "swap"])]
        st: bool,
        /// Print the Cranelift IR and machine code native code runs for the benchmark rung instead.
        #[arg(long, conflicts_with_all = ["modbus", "nets", "realtime"])]
        listing: bool,
        /// Run one contender only, untimed, for a profiler (valgrind --tool=callgrind; see
        /// docs/performance.md): --scans scans of the first of --sizes.
        #[arg(long, value_enum, value_name = "CONTENDER", conflicts_with_all = ["modbus", "nets", "realtime", "listing"])]
        profile: Option<bench::Contender>,
        /// With --profile: scans to run.
        #[arg(long, value_name = "K", default_value = "300")]
        scans: u64,
    },
    /// Explain a diagnostic code (E301, ...).
    Explain { code: String },
    /// Analyse a net (PNML): reachability/coverability, bounds, deadlocks, liveness, invariants.
    Analyze {
        /// The .pnml file.
        net: PathBuf,
        /// Print one JSON object (SPEC §10.5).
        #[arg(long)]
        json: bool,
        /// Stop after this many states (or coverability nodes).
        #[arg(long, value_name = "N")]
        max_states: Option<usize>,
        /// Memory the state space may use: bytes, or with K, M, G (default: 3/4 of the
        /// memory available).
        #[arg(long, value_name = "SIZE", value_parser = analyze::parse_size)]
        memory: Option<usize>,
        /// Invariants: `flows` (a basis of the P- and T-flows only) or `minimal` (also the
        /// minimal semi-positive invariants, within --invariant-budget).
        #[arg(long, value_enum, default_value = "minimal")]
        invariants: analyze::InvariantsArg,
        /// Work units the minimal invariants may take, each of P and T (about 10^8 a second).
        #[arg(long, value_name = "N")]
        invariant_budget: Option<u64>,
        /// Also count the states with the symbolic engine (decision diagrams), exactly and
        /// of any number; the explicit exploration is skipped when the count shows it
        /// cannot fit. Without it the symbolic engine runs only when the explicit
        /// exploration stops at its memory budget.
        #[arg(long)]
        symbolic: bool,
        /// Threads of the explicit exploration and of the liveness/reversibility pass
        /// (default: the available parallelism, at most 2; the results do not depend on it).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
        threads: Option<u16>,
        /// Answer a Model Checking Contest examination instead (one `FORMULA` line per
        /// formula; docs/nets.md, "Contest examinations").
        #[arg(long, value_enum, value_name = "EXAMINATION")]
        examination: Option<analyze::Examination>,
        /// The examination's formula file (default: `<EXAMINATION>.xml` beside the model).
        #[arg(long, value_name = "FILE.xml", requires = "examination")]
        formulas: Option<PathBuf>,
        /// Print each witness or counterexample firing sequence after its `FORMULA` line.
        #[arg(long, requires = "examination")]
        trace: bool,
    },
    /// Autotune a PID loop by relay feedback against the project's plant models (docs/pid.md).
    Tune {
        project: PathBuf,
        /// The PID tag to tune.
        #[arg(long = "loop", value_name = "TAG")]
        pid: String,
        /// Setpoint for the experiment (default: the loop's SP).
        #[arg(long, value_name = "SP")]
        sp: Option<f64>,
        /// Relay amplitude, % of CV.
        #[arg(long, default_value_t = 20.0)]
        amplitude: f64,
        /// Relay centre, % of CV (default: the loop's own output once it holds PV at SP in auto).
        #[arg(long)]
        bias: Option<f64>,
        /// Relay hysteresis, engineering units of the error (use it against noise).
        #[arg(long, default_value_t = 0.0)]
        hysteresis: f64,
        /// Give up after this long in virtual time, ms.
        #[arg(long, value_name = "MS", default_value_t = 600_000)]
        until: u64,
        /// Whole cycles to average after two cycles of transient.
        #[arg(long, default_value_t = 4)]
        cycles: usize,
    },
    /// Run a project in real time and serve the studio and the API.
    Run {
        project: PathBuf,
        /// Address to serve on (loopback by default).
        #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8080")]
        http: std::net::SocketAddr,
        /// I/O driver: `sim` (plant models of the project, forces and writes) or
        /// `arduino:PORT[,link=modbus|aurora,reset_ms=N,timeout_ms=N,retries=N,slave=N]`
        /// (a board running `alba firmware`), or `board:PORT[,options]` (attach to a board
        /// running the project's exported sketch; see docs/arduino.md), or `modbus` (poll the
        /// `[[modbus_device]]` slaves of alba.toml; see docs/protocols.md).
        #[arg(long, default_value = "sim")]
        io: String,
        /// Interpret instead of compiling the program to native code.
        #[arg(long)]
        no_native: bool,
        /// Serve Modbus TCP (OpenPLC v3's address map) on this address (default: `[modbus] listen` of alba.toml, else off).
        #[arg(long, value_name = "ADDR:PORT")]
        modbus: Option<std::net::SocketAddr>,
        /// Serve OPC UA on this address, e.g. 127.0.0.1:4840 (security None only on loopback; elsewhere Basic256Sha256 with `[opcua.users]`).
        #[arg(long, value_name = "ADDR:PORT")]
        opcua: Option<std::net::SocketAddr>,
        /// Publish every tag to this MQTT broker and take writes from it (default: `[mqtt] broker` of alba.toml, else off; see docs/scale-out.md).
        #[arg(long, value_name = "HOST:PORT")]
        mqtt: Option<String>,
        /// Serve the studio over HTTPS even on loopback (beyond loopback it always is, unless
        /// `--insecure-http`); the certificate: `[http] cert`/`key`, else self-signed in `.alba/tls/`.
        #[arg(long, conflicts_with = "insecure_http")]
        https: bool,
        /// Serve plain HTTP beyond loopback (anyone on the path reads and alters the traffic).
        #[arg(long)]
        insecure_http: bool,
        /// Run a copy of the project, made in DIR (default `./alba-<folder name>`) unless DIR
        /// holds one already: the studio's saves go there and the original stays as it is
        /// (run the repository's examples this way).
        #[arg(long, value_name = "DIR", num_args = 0..=1, default_missing_value = "")]
        copy: Option<PathBuf>,
    },
    /// Generate the remote-I/O firmware of an Arduino for controller mode
    /// (`alba run PROJECT --io arduino:PORT`).
    Firmware {
        /// A project whose `[board]` gives the board and its pin map.
        project: Option<PathBuf>,
        /// The board: uno, nano or mega (overrides the project's).
        #[arg(long)]
        board: Option<String>,
        /// Preset pin map: aurora, s7 or openplc (overrides the project's; default aurora).
        #[arg(long)]
        pinmap: Option<String>,
        /// Serial protocol: modbus (Modbus RTU slave) or aurora (AuroraLD text link).
        #[arg(long, default_value = "modbus")]
        link: String,
        /// Modbus slave id.
        #[arg(long, default_value_t = 1)]
        slave: u8,
        /// Outputs go off when no valid request came for this long.
        #[arg(long, value_name = "MS", default_value_t = alba_io::firmware::WATCHDOG_MS)]
        watchdog_ms: u32,
        /// Digital outputs are on when the pin is low (relay boards).
        #[arg(long)]
        active_low: bool,
        /// Digital inputs use the pin's pull-up and are on when the pin is low
        /// (a button or contact to GND).
        #[arg(long)]
        input_pullup: bool,
        /// Folder to write the sketch into (as FOLDER/FOLDER.ino, as the Arduino IDE wants).
        #[arg(short, long, value_name = "DIR")]
        out: PathBuf,
        /// Build with avr-gcc and report flash and RAM against the board.
        #[arg(long)]
        build: bool,
        /// Build, then upload with avrdude to this serial port.
        #[arg(long, value_name = "PORT")]
        upload: Option<String>,
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
    /// Decide the properties of properties.toml over every input sequence: proved,
    /// refuted (with a counterexample stimulus `alba sim` replays) or unknown
    /// (docs/verify.md). Exit 0 all proved, 1 any refuted, 2 otherwise.
    Verify {
        project: PathBuf,
        /// One JSON object on standard output: `{"properties": [{"name", "result",
        /// "counterexample", "depth", …}]}`.
        #[arg(long)]
        json: bool,
        /// Write counterexamples here (default: PROJECT/counterexamples).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Decide only the property with this name.
        #[arg(long, value_name = "NAME")]
        property: Option<String>,
        /// Give up (unknown) after storing this many states.
        #[arg(long, value_name = "N", default_value_t = 2_000_000)]
        max_states: usize,
        /// Give up (unknown) after this many seconds per property.
        #[arg(long, value_name = "S", default_value_t = 60)]
        timeout: u64,
        /// Give up (unknown) when the stored states would take more than this many MB.
        #[arg(long, value_name = "MB", default_value_t = 1024)]
        max_mb: usize,
    },
    /// Run the test tables tests/*.test.csv (exit 1 when any fails) and print the
    /// rung and instruction coverage of the tables (docs/verify.md).
    Test {
        project: PathBuf,
        /// Also write JUnit XML here (one testcase per table).
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
    },
    /// Print the argon2 hash of a password read from stdin (for tools; `alba user` manages users).
    HashPassword,
    /// Manage the project's users and roles (users.toml).
    #[command(subcommand)]
    User(user::UserCmd),
    /// The shared historian: `migrate` creates its PostgreSQL schema; `--mqtt HOST:PORT`
    /// consumes the runtimes' MQTT messages (JSON, Sparkplug B) into it.
    Historian(historian::HistorianArgs),
}

#[derive(Subcommand)]
enum Export {
    /// An Arduino sketch of the control program (plant models left out).
    Arduino {
        project: PathBuf,
        #[command(flatten)]
        board: export::BoardArgs,
        /// Folder to write the sketch folder `<name>/` into.
        #[arg(short, long, value_name = "DIR", default_value = ".")]
        out: PathBuf,
        /// Build with avr-gcc and report flash and RAM against the board.
        #[arg(long)]
        build: bool,
        /// Build, then upload with avrdude to this serial port.
        #[arg(long, value_name = "PORT")]
        upload: Option<String>,
    },
    /// The byte-code interpreter firmware for a board (an Arduino sketch folder
    /// `alba_interp/`); `alba download` then sends it programs.
    Interpreter {
        /// A project whose `[board]` (model, pin map, active_low) the interpreter is for;
        /// without one, --board and --pinmap (default aurora), outputs active high.
        project: Option<PathBuf>,
        #[command(flatten)]
        board: export::BoardArgs,
        /// Folder to write the sketch folder into.
        #[arg(short, long, value_name = "DIR", default_value = ".")]
        out: PathBuf,
        /// Build with avr-gcc and report flash and RAM against the board.
        #[arg(long)]
        build: bool,
        /// Build, then upload with avrdude to this serial port.
        #[arg(long, value_name = "PORT")]
        upload: Option<String>,
    },
    /// The project's Ladder programs as PLCopen TC6 XML v2.01 LD bodies, with layout
    /// positions (for the OpenPLC editor, Beremiz, CODESYS; docs/interchange.md).
    Plcopen {
        project: PathBuf,
        /// The file to write.
        #[arg(short, long, value_name = "FILE")]
        out: PathBuf,
    },
    /// The control program as byte code for the board's interpreter (docs/bytecode.md):
    /// Intel HEX when the file name ends in `.hex`, raw bytes otherwise.
    Bytecode {
        project: PathBuf,
        #[command(flatten)]
        board: export::BoardArgs,
        /// The file to write.
        #[arg(short, long, value_name = "FILE")]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    // The language first, so that even a refused command line is reported in it.
    let args: Vec<String> = std::env::args().collect();
    let lang = match lang_arg(&args) {
        Some(l) => match alba_diag::Lang::parse(l) {
            Some(l) => l,
            None => {
                eprintln!(
                    "error[{}]: unknown language `{l}` for --lang: choose en or es",
                    Code::BadArgument
                );
                return ExitCode::FAILURE;
            }
        },
        None => alba_diag::Lang::from_env(),
    };
    alba_diag::set_language(lang);
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
            if lang == alba_diag::Lang::Es {
                eprint!("error[{}]: {}: {text}", Code::BadArgument, es_title(Code::BadArgument));
            } else {
                eprint!("error[{}]: {text}", Code::BadArgument);
            }
            return ExitCode::FAILURE;
        }
    };
    match cli.command {
        Command::Check { project, short, ir } => check(&project, short, ir),
        Command::Verify {
            project,
            json,
            out,
            property,
            max_states,
            timeout,
            max_mb,
        } => verify::verify(
            &project,
            verify::VerifyArgs {
                json,
                options: alba_verify::project::Options {
                    out,
                    only: property,
                    budget: alba_verify::explore::Budget {
                        max_states,
                        max_seconds: timeout,
                        max_bytes: max_mb.saturating_mul(1 << 20),
                        ..Default::default()
                    },
                },
            },
        ),
        Command::Test { project, junit } => verify::test(&project, junit.as_deref()),
        Command::Sim {
            project,
            until,
            stimulus,
            trace,
            tags,
            every,
            firmware,
            bytecode,
            board,
            summary,
            alarms,
        } => simulate(
            &project,
            SimArgs {
                alarms: alarms.as_deref(),
                until,
                stimulus: stimulus.as_deref(),
                trace: trace.as_deref(),
                tags: tags.as_deref(),
                every,
                firmware: firmware.then_some(&board),
                bytecode,
                summary: summary.as_deref(),
            },
        ),
        Command::Export {
            to:
                Export::Arduino {
                    project,
                    board,
                    out,
                    build,
                    upload,
                },
        } => export::export(&project, &board, &out, build, upload.as_deref()),
        Command::Export {
            to: Export::Bytecode { project, board, out },
        } => export::bytecode(&project, &board, &out),
        Command::Export {
            to: Export::Plcopen { project, out },
        } => import::export_plcopen(&project, &out),
        Command::Import {
            file,
            out,
            format,
            board,
            force,
        } => import::run(&file, &out, format.as_deref(), board, force),
        Command::Export {
            to:
                Export::Interpreter {
                    project,
                    board,
                    out,
                    build,
                    upload,
                },
        } => export::interpreter(project.as_deref(), &board, &out, build, upload.as_deref()),
        Command::Download {
            project,
            port,
            board,
            verify,
            read,
        } => match (read, project) {
            (Some(out), _) => export::read_back(&port, &out),
            (None, Some(project)) => export::download(&project, &board, &port, verify),
            (None, None) => fail("give the project to download, or --read FILE"),
        },
        Command::New { dir, net } => new::run(&dir, net),
        Command::Bench {
            modbus: true,
            clients,
            seconds,
            target,
            start,
            ..
        } => bench_modbus::run(clients.as_deref().unwrap_or(&[1, 4, 16]), seconds, target, start),
        Command::Bench { nets: true, quick, .. } => bench::nets(quick),
        Command::Bench {
            historian: true, quick, ..
        } => bench::historian(quick),
        Command::Bench {
            all: true,
            quick,
            priority,
            cpu,
            seconds,
            ..
        } => bench_all::all(quick, if quick { 1.0 } else { seconds }, priority, cpu),
        Command::Bench {
            mqtt: true,
            tags,
            seconds,
            broker,
            ..
        } => bench_mqtt::run(tags.as_deref().unwrap_or(&[100, 1_000]), seconds, broker),
        Command::Bench {
            realtime: true,
            seconds,
            priority,
            cpu,
            ..
        } => bench_realtime::run(seconds, priority, cpu),
        Command::Bench { listing: true, .. } => bench::listing(),
        Command::Bench { swap: true, sizes, .. } => bench::swap(sizes.as_deref().unwrap_or(&[10_000, 50_000])),
        Command::Bench {
            profile: Some(contender),
            sizes,
            scans,
            ..
        } => bench::profile(
            contender,
            sizes.and_then(|s| s.first().copied()).unwrap_or(1_000),
            scans,
        ),
        Command::Bench { sizes, quick, st, .. } => {
            let sizes = sizes.as_deref().unwrap_or(&[100, 1_000, 10_000]);
            if st {
                bench_st::run(sizes, quick)
            } else {
                match bench::run(sizes, quick) {
                    ExitCode::SUCCESS => bench_st::run(sizes, quick),
                    failed => failed,
                }
            }
        }
        Command::Explain { code } => explain(&code),
        Command::Analyze {
            net,
            json,
            max_states,
            memory,
            invariants,
            invariant_budget,
            symbolic,
            threads,
            examination,
            formulas,
            trace,
        } => analyze::run(
            &net,
            json,
            analyze::Limits {
                max_states,
                memory,
                invariants,
                invariant_budget,
                symbolic,
                threads: threads.map(usize::from),
            },
            examination.map(|examination| analyze::Contest {
                examination,
                formulas,
                trace,
            }),
        ),
        Command::Tune {
            project,
            pid,
            sp,
            amplitude,
            bias,
            hysteresis,
            until,
            cycles,
        } => tune::run(tune::TuneArgs {
            dir: &project,
            pid: &pid,
            sp,
            amplitude,
            bias,
            hysteresis,
            until,
            cycles,
        }),
        Command::Run {
            project,
            http,
            io,
            no_native,
            modbus,
            opcua,
            mqtt,
            https,
            insecure_http,
            copy,
        } => {
            let project = match copy {
                None => project,
                Some(dest) => {
                    let dest = if dest.as_os_str().is_empty() {
                        copy::default_dest(&project)
                    } else {
                        dest
                    };
                    match copy::prepare(&project, &dest) {
                        Ok(fresh) => {
                            eprintln!(
                                "Running {} {} (the studio saves there; {} is not changed).",
                                if fresh {
                                    "a new copy of the project in"
                                } else {
                                    "the copy in"
                                },
                                dest.display(),
                                project.display()
                            );
                            dest
                        }
                        Err(e) => {
                            eprintln!("error: {e}");
                            return ExitCode::FAILURE;
                        }
                    }
                }
            };
            let tls = match (https, insecure_http) {
                (true, _) => alba_app::tls::Tls::Always,
                (_, true) => alba_app::tls::Tls::Never,
                _ => alba_app::tls::Tls::Auto,
            };
            let opts = alba_app::Options {
                addr: http,
                io,
                native: !no_native,
                modbus,
                opcua,
                mqtt,
                tls,
                scan_log: None,
                quiet: false,
            };
            run::run(&project, opts, None)
        }
        Command::Demo { dir, http } => demo::run(&dir, http, true),
        Command::HashPassword => hash_password(),
        Command::User(cmd) => user::run(cmd),
        Command::Historian(cmd) => historian::run(cmd),
        Command::Firmware {
            project,
            board,
            pinmap,
            link,
            slave,
            watchdog_ms,
            active_low,
            input_pullup,
            out,
            build,
            upload,
        } => firmware::run(firmware::Args {
            project: project.as_deref(),
            board: board.as_deref(),
            pinmap: pinmap.as_deref(),
            link: &link,
            slave,
            watchdog_ms,
            active_low,
            pullup: input_pullup,
            out: &out,
            build: build || upload.is_some(),
            upload: upload.as_deref(),
        }),
    }
}

/// Prints diagnostics to stderr.
fn report(diags: &[Diagnostic], files: &Files, short: bool) {
    let text = if short {
        let mut s: String = diags.iter().map(|d| d.short(files) + "\n").collect();
        s.push_str(&alba_diag::error_count(diags.len()));
        s.push('\n');
        s
    } else {
        render_all(diags, files)
    };
    eprint!("{text}");
}

fn check(dir: &Path, short: bool, ir: bool) -> ExitCode {
    let c = alba_load::compile_dir(dir);
    for w in &c.project.warnings {
        if short {
            eprintln!("{}", w.short(c.files()).replacen(": error[", ": warning[", 1));
        } else {
            eprint!("{}", w.render_warning(c.files()));
        }
    }
    let Some(program) = &c.program else {
        report(&c.diagnostics, c.files(), short);
        return ExitCode::FAILURE;
    };
    let mut files = c.project.files.clone();
    let alarm_ids: Vec<String> = match alba_alarms::def::load(dir, &mut files, &program.layout) {
        Ok(a) => a.into_iter().map(|d| d.id).collect(),
        Err(d) => {
            report(&d, &files, short);
            return ExitCode::FAILURE;
        }
    };
    let alarms = alarm_ids.len();
    let (screens, bad) = alba_compiler::screens::check_dir(dir, &mut files, &program.layout, &alarm_ids);
    if !bad.is_empty() {
        report(&bad, &files, short);
        return ExitCode::FAILURE;
    }
    if ir {
        print!("{}", program.dump());
    }
    let rungs = program.rungs.len();
    let tags = program.layout.tags.len();
    // (English, Spanish singular, Spanish plural)
    let es = alba_diag::language() == alba_diag::Lang::Es;
    let n = |k: usize, what: (&str, &str, &str)| match (es, k) {
        (false, 1) => format!("1 {}", what.0),
        (false, k) => format!("{k} {}s", what.0),
        (true, 1) => format!("1 {}", what.1),
        (true, k) => format!("{k} {}", what.2),
    };
    let alarms = if alarms > 0 {
        format!(", {}", n(alarms, ("alarm", "alarma", "alarmas")))
    } else {
        String::new()
    };
    let screens = if screens > 0 {
        format!(", {}", n(screens, ("screen", "pantalla", "pantallas")))
    } else {
        String::new()
    };
    eprintln!(
        "{}: ok ({}, {}, {}, {}{alarms}{screens})",
        dir.display(),
        n(program.units.len(), ("program", "programa", "programas")),
        n(rungs, ("rung", "peldaño", "peldaños")),
        n(tags, ("tag", "variable", "variables")),
        n(program.ops.len(), ("op", "operación", "operaciones"))
    );
    ExitCode::SUCCESS
}

/// The alarm events of `alba sim --alarms`, as CSV, atomically.
fn write_alarm_events(path: &Path, events: &[alba_alarms::Event]) -> Result<(), String> {
    fsutil::write_atomic(path, |w| alba_alarms::log::write_events_csv(events, w))
        .map_err(|e| format!("cannot write the alarm events to {}: {e}", path.display()))
}

fn fail(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::FAILURE
}

/// The options of `alba sim`.
struct SimArgs<'a> {
    until: u64,
    stimulus: Option<&'a Path>,
    trace: Option<&'a Path>,
    tags: Option<&'a str>,
    every: Option<u64>,
    /// Run the exported firmware in simavr instead of the engine.
    firmware: Option<&'a export::BoardArgs>,
    /// With `firmware`: the byte-code interpreter instead of the sketch.
    bytecode: bool,
    summary: Option<&'a str>,
    /// Write the alarms' changes of state here.
    alarms: Option<&'a Path>,
}

fn simulate(dir: &Path, a: SimArgs) -> ExitCode {
    let SimArgs {
        until,
        stimulus,
        trace,
        tags,
        every,
        firmware,
        bytecode,
        summary,
        alarms,
    } = a;
    let c = alba_load::compile_dir(dir);
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
            let text = match alba_project::read_text(path) {
                Ok(t) => t,
                Err(msg) => {
                    report(&[Diagnostic::unplaced(Code::Io, msg.to_string())], &files, false);
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
    if let Some(board) = firmware {
        let timing = alba_arduino::simavr::Timing {
            scan_ms,
            until_ms: until,
            every_ms: every,
            from_first_scan: bytecode,
        };
        let text = match export::simulate(dir, board, &stim, &cols, timing, bytecode) {
            Ok(t) => t,
            Err(code) => return code,
        };
        let written = match trace {
            Some(path) => fsutil::write_atomic(path, |w| w.write_all(text.as_bytes())),
            None => std::io::stdout().write_all(text.as_bytes()),
        };
        return match (written, summary) {
            (Err(e), _) => fail(format!("cannot write the trace: {e}")),
            (Ok(()), Some(list)) => print_summary(&text, list, trace.is_some()),
            (Ok(()), None) => ExitCode::SUCCESS,
        };
    }
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
    // `--alarms`: the project's alarms evaluated after every scan, at virtual time.
    let mut alarm_state = match alarms {
        None => None,
        Some(_) => {
            let mut files = c.project.files.clone();
            match alba_alarms::def::load(dir, &mut files, &engine.program().layout) {
                Ok(defs) => Some(alba_alarms::Alarms::new(defs)),
                Err(d) => {
                    report(&d, &files, false);
                    return ExitCode::FAILURE;
                }
            }
        }
    };
    let mut events = Vec::new();
    let mut observe = |t: u64, e: &Engine| {
        if let Some(a) = alarm_state.as_mut() {
            events.extend(a.update(t as i64, e.memory()));
        }
    };
    if let Some(list) = summary {
        // The trace is kept in memory, written as usual, then summarised.
        let mut buf = Vec::new();
        let result = sim::run_observed(&mut engine, &stim, &cols, opt, &mut buf, &mut observe);
        if let Err(e) = result {
            return match e {
                SimError::Io(e) => fail(format!("cannot write the trace: {e}")),
                SimError::Major(m) => fail(format!("major fault: {}", m.message)),
            };
        }
        let written = match trace {
            Some(path) => fsutil::write_atomic(path, |w| w.write_all(&buf)),
            None => std::io::stdout().lock().write_all(&buf),
        };
        if let Err(e) = written
            && e.kind() != std::io::ErrorKind::BrokenPipe
        {
            return fail(format!("cannot write the trace: {e}"));
        }
        if let Some(path) = alarms
            && let Err(e) = write_alarm_events(path, &events)
        {
            return fail(e);
        }
        if let Some(f) = engine.faults().first {
            eprintln!(
                "warning: {} minor fault(s); first: {}",
                engine.faults().count,
                engine.describe_fault(&f)
            );
        }
        return print_summary(&String::from_utf8_lossy(&buf), list, trace.is_some());
    }
    let result = match trace {
        Some(path) => {
            let mut outcome = Ok(());
            let io = fsutil::write_atomic(path, |w| {
                outcome = sim::run_observed(&mut engine, &stim, &cols, opt, w, &mut observe);
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
            sim::run_observed(&mut engine, &stim, &cols, opt, &mut w, &mut observe)
                .and_then(|()| w.flush().map_err(SimError::Io))
        }
    };
    if let Some(path) = alarms
        && let Err(e) = write_alarm_events(path, &events)
    {
        return fail(e);
    }
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

/// `--summary A,B:REF`: the step-response figures of each signal, on
/// standard output when the trace went to a file, else on standard error.
fn print_summary(trace: &str, list: &str, to_stdout: bool) -> ExitCode {
    for item in list.split(',').map(str::trim) {
        let (sig, reference) = match item.split_once(':') {
            // `S:FS`-like names contain a colon: a reference follows only the last one
            // that leaves a traced name on both sides; try the whole item first.
            Some((a, b)) if alba_engine::analysis::columns(trace, &[item]).is_err() => (a, Some(b)),
            _ => (item, None),
        };
        let names: Vec<&str> = std::iter::once(sig).chain(reference).collect();
        let (t, cols) = match alba_engine::analysis::columns(trace, &names) {
            Ok(v) => v,
            Err(e) => {
                let d = Diagnostic::unplaced(Code::BadArgument, format!("--summary: {e}"));
                report(&[d], &Files::new(), false);
                return ExitCode::FAILURE;
            }
        };
        let line = match alba_engine::analysis::step_info(&t, &cols[0], cols.get(1).map(Vec::as_slice)) {
            Some(s) => format!("{item}: {s}"),
            None => format!("{item}: no step (the signal ends where it starts)"),
        };
        if to_stdout {
            println!("{line}");
        } else {
            eprintln!("{line}");
        }
    }
    ExitCode::SUCCESS
}

/// The Spanish title of `c` (the English one should the catalogue lack it,
/// which alba-diag's tests forbid).
fn es_title(c: Code) -> &'static str {
    alba_diag::es::title(c).unwrap_or(c.title())
}

fn explain(code: &str) -> ExitCode {
    match code.parse::<Code>() {
        Ok(c) if alba_diag::language() == alba_diag::Lang::Es => {
            // Every code has its Spanish explanation (alba-diag's tests see to it).
            let e = alba_diag::es::explanation(c).unwrap_or(c.explanation());
            println!("{c}: {}\n\n{e}", es_title(c));
            ExitCode::SUCCESS
        }
        Ok(c) => {
            println!("{c}: {}\n\n{}", c.title(), c.explanation());
            ExitCode::SUCCESS
        }
        Err(()) => {
            let es = alba_diag::language() == alba_diag::Lang::Es;
            if es {
                eprintln!("error: código desconocido `{code}`; los códigos son:");
            } else {
                eprintln!("error: unknown code `{code}`; codes are:");
            }
            for c in Code::ALL {
                eprintln!("  {c}  {}", if es { es_title(*c) } else { c.title() });
            }
            ExitCode::FAILURE
        }
    }
}

/// `alba hash-password`: reads one line (the password) from stdin and
/// prints its argon2id hash for `[opcua.users]`.
fn hash_password() -> ExitCode {
    let mut line = String::new();
    if let Err(e) = std::io::stdin().read_line(&mut line) {
        eprintln!("error: cannot read the password from stdin: {e}");
        return ExitCode::FAILURE;
    }
    let pw = line.strip_suffix('\n').unwrap_or(&line);
    let pw = pw.strip_suffix('\r').unwrap_or(pw);
    if pw.is_empty() {
        eprintln!("error: the password is empty (give it on stdin, e.g. `printf %s 'secret' | alba hash-password`)");
        return ExitCode::FAILURE;
    }
    match alba_auth::hash_password(pw) {
        Ok(h) => {
            println!("{h}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
