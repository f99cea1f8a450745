//! `/api/hardware` (issue 33; SPEC §10.6) through `alba run`: the board and
//! pin map of alba.toml, saved atomically and audited; firmware built by
//! avr-gcc with its sizes; the byte code downloaded as a job to the
//! interpreter firmware on an emulated Nano (`alba-board`: simavr paced to
//! real time, its UART on a pty, as crates/cli/tests/it/download.rs runs it);
//! each route refused to a viewer; the controller (remote-I/O) firmware on
//! an emulated Nano attached as the running PLC's I/O and detached, without
//! restarting `alba run`.

use super::{add_role_users, options, serve};
use alba_arduino::{interp, simavr};
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

const TOML: &str = "# The start/stop circuit on a Nano.\nname = \"hw\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n\n\
# Wired as the course's board.\n[board]\nmodel = \"nano\"\npinmap = \"aurora\"\n";

/// examples/start-stop with `[board]` for the Nano, and a user per role.
fn project(test: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/start-stop");
    let dir = std::env::temp_dir().join(format!("alba-app-hw-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    for f in ["tags.csv", "main.lad"] {
        std::fs::copy(src.join(f), dir.join(f)).expect("copy");
    }
    std::fs::write(dir.join("alba.toml"), TOML).expect("alba.toml");
    add_role_users(&dir);
    dir
}

struct Studio {
    http: std::net::SocketAddr,
    client: reqwest::Client,
    engineer: String,
    viewer: String,
    stop: Option<(tokio::sync::oneshot::Sender<()>, tokio::task::JoinHandle<()>)>,
    dir: PathBuf,
}

impl Studio {
    async fn start(test: &str) -> Studio {
        let dir = project(test);
        let mut o = options("sim");
        o.quiet = true;
        let (http, stop, task) = serve(&dir, o).await;
        let client = reqwest::Client::new();
        let mut s = Studio {
            http,
            client,
            engineer: String::new(),
            viewer: String::new(),
            stop: Some((stop, task)),
            dir,
        };
        s.engineer = s.login("engineer").await;
        s.viewer = s.login("viewer").await;
        s
    }

    async fn login(&self, user: &str) -> String {
        crate::login(&self.client, self.http, user).await
    }

    /// `method path` with `body` as `token`: the status and the JSON reply.
    async fn call(&self, method: Method, path: &str, token: &str, body: Option<Json>) -> (StatusCode, Json) {
        let mut r = self
            .client
            .request(method, format!("http://{}{path}", self.http))
            .bearer_auth(token);
        if let Some(b) = body {
            r = r.json(&b);
        }
        let resp = r.send().await.expect("request");
        let status = resp.status();
        (status, resp.json().await.unwrap_or(Json::Null))
    }

    async fn audit(&self, action: &str) -> Vec<Json> {
        let (s, j) = self
            .call(
                Method::GET,
                &format!("/api/audit?action={action}"),
                &self.engineer,
                None,
            )
            .await;
        assert_eq!(s, StatusCode::OK, "{j}");
        j["rows"].as_array().unwrap_or_else(|| panic!("{j}")).clone()
    }

    /// `POST /api/hardware/{action}` `{"port"}` as the engineer.
    async fn on_port(&self, action: &str, port: &str) -> (StatusCode, Json) {
        self.call(
            Method::POST,
            &format!("/api/hardware/{action}"),
            &self.engineer,
            Some(json!({ "port": port })),
        )
        .await
    }

    /// Polls a job until it ends; every progress seen on the way.
    async fn finish(&self, job: &str) -> (Json, Vec<u64>) {
        let mut seen = Vec::new();
        for _ in 0..600 {
            let (s, j) = self
                .call(Method::GET, &format!("/api/hardware/jobs/{job}"), &self.viewer, None)
                .await;
            assert_eq!(s, StatusCode::OK, "{j}");
            seen.push(j["progress"].as_u64().expect("progress"));
            if j["state"] != "running" {
                return (j, seen);
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        panic!("job {job} did not end in 60 s");
    }

    async fn stop(mut self) {
        if let Some((stop, task)) = self.stop.take() {
            let _ = stop.send(());
            tokio::time::timeout(Duration::from_secs(20), task)
                .await
                .expect("stops")
                .expect("task");
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_board_and_pin_map_are_shown_saved_atomically_audited_and_refused_to_a_viewer() {
    let s = Studio::start("board").await;
    let (st, j) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!(
        (j["board"].as_str(), j["pinmap"].as_str()),
        (Some("nano"), Some("aurora"))
    );
    assert!(j["ports"].is_array(), "{j}");
    // The table: Start on DI:1/0 is D2 (aurora), the Nano's A7 an analog input only.
    let rows = j["pins"].as_array().expect("pins");
    let start = rows.iter().find(|r| r["address"] == "DI:1/0").expect("DI:1/0");
    assert_eq!(
        (start["pin"].as_str(), start["tags"][0].as_str()),
        (Some("D2"), Some("Start"))
    );
    let nano = j["boards"]
        .as_array()
        .expect("boards")
        .iter()
        .find(|b| b["name"] == "nano")
        .expect("nano");
    let a7 = nano["pins"]
        .as_array()
        .expect("pins")
        .iter()
        .find(|p| p["pin"] == "A7")
        .expect("A7");
    assert_eq!(a7["caps"], json!(["ai"]));

    // A viewer sees, and changes nothing.
    let before = std::fs::read_to_string(s.dir.join("alba.toml")).expect("alba.toml");
    for (m, path, body) in [
        (Method::PUT, "/api/hardware/board", json!({"board": "uno"})),
        (
            Method::POST,
            "/api/hardware/build",
            json!({"board": "nano", "kind": "sketch"}),
        ),
        (Method::POST, "/api/hardware/download", json!({"port": "/dev/null"})),
        (Method::POST, "/api/hardware/identify", json!({"port": "/dev/null"})),
        (Method::POST, "/api/hardware/verify", json!({"port": "/dev/null"})),
        (Method::POST, "/api/hardware/jobs/1/cancel", json!({})),
    ] {
        let (st, j) = s.call(m, path, &s.viewer, Some(body)).await;
        assert_eq!(st, StatusCode::FORBIDDEN, "{path}: {j}");
    }

    // A conflict (D2 an input and an output) is refused with its code; nothing saved.
    let (st, j) = s
        .call(
            Method::PUT,
            "/api/hardware/board",
            &s.engineer,
            Some(json!({"board": "nano", "pinmap": "aurora", "do": ["D12", "D2"]})),
        )
        .await;
    assert_eq!(st, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert_eq!(d["code"], "E102", "{j}");
    assert!(d["message"].as_str().expect("message").contains("D2"), "{j}");
    assert_eq!(std::fs::read_to_string(s.dir.join("alba.toml")).expect("toml"), before);
    // Unknown board or preset: 400.
    for body in [json!({"board": "due"}), json!({"board": "uno", "pinmap": "x"})] {
        let (st, j) = s
            .call(Method::PUT, "/api/hardware/board", &s.engineer, Some(body))
            .await;
        assert_eq!(st, StatusCode::BAD_REQUEST, "{j}");
    }

    // The Uno with the s7 map and a port: saved, the comments kept.
    let (st, j) = s
        .call(
            Method::PUT,
            "/api/hardware/board",
            &s.engineer,
            Some(json!({"board": "uno", "pinmap": "s7", "port": "/dev/ttyUSB7"})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!((j["board"].as_str(), j["pinmap"].as_str()), (Some("uno"), Some("s7")));
    assert_eq!(j["ports"][0]["path"], "/dev/ttyUSB7", "{j}");
    let saved = std::fs::read_to_string(s.dir.join("alba.toml")).expect("toml");
    assert!(
        saved.contains("# Wired as the course's board.") && saved.contains("model = \"uno\""),
        "{saved}"
    );
    let (c, d) = alba_load::load(&s.dir);
    assert!(d.is_empty(), "{d:?}");
    let b = c.config.and_then(|c| c.board).expect("[board]");
    assert_eq!(
        (b.model.name(), b.pinmap.as_str(), b.port.as_deref()),
        ("uno", "s7", Some("/dev/ttyUSB7"))
    );
    let (_, j) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    let q0 = j["pins"]
        .as_array()
        .expect("pins")
        .iter()
        .find(|r| r["address"] == "DO:2/0")
        .expect("DO:2/0");
    assert_eq!(
        (q0["pin"].as_str(), q0["tags"][0].as_str()),
        (Some("D8"), Some("Motor"))
    );

    // Undo: `[board]` as it was before the save (the Nano, aurora, no port), the rest kept.
    let (st, j) = s
        .call(Method::POST, "/api/hardware/board/undo", &s.viewer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::FORBIDDEN, "{j}");
    assert_eq!(j.get("undo"), None);
    let (_, v) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    assert_eq!(v["undo"], 1, "{v}");
    let (st, j) = s
        .call(Method::POST, "/api/hardware/board/undo", &s.engineer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!(
        (j["board"].as_str(), j["pinmap"].as_str(), &j["port"], &j["undo"]),
        (Some("nano"), Some("aurora"), &Json::Null, &json!(0)),
        "{j}"
    );
    assert_eq!(std::fs::read_to_string(s.dir.join("alba.toml")).expect("toml"), before);
    let (st, j) = s
        .call(Method::POST, "/api/hardware/board/undo", &s.engineer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::CONFLICT, "{j}");
    assert!(
        j["error"].as_str().expect("error").contains("no board save to undo"),
        "{j}"
    );

    let rows = s.audit("save_board").await;
    // The save and its undo; the three refusals (the conflict, the unknown board
    // and preset) and the undo with nothing to undo.
    let ok: Vec<_> = rows.iter().filter(|r| r["outcome"] == "ok").collect();
    assert_eq!((ok.len(), rows.len()), (2, 6), "{rows:?}");
    assert!(ok.iter().all(|r| r["user"] == "engineer"), "{rows:?}");
    assert!(
        ok.iter()
            .any(|r| r["detail"].as_str().expect("detail").contains("model = uno")),
        "{rows:?}"
    );
    assert!(
        ok.iter()
            .any(|r| r["detail"].as_str().expect("detail").starts_with("undo")),
        "{rows:?}"
    );

    let (st, _) = s.call(Method::GET, "/api/hardware/jobs/nope", &s.viewer, None).await;
    assert_eq!(st, StatusCode::NOT_FOUND);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn builds_answer_avr_gcc_s_sizes_and_a_project_that_does_not_build_its_diagnostics() {
    let s = Studio::start("build").await;
    for (body, want) in [
        (json!({"board": "due", "kind": "sketch"}), StatusCode::BAD_REQUEST),
        (json!({"board": "nano", "kind": "bootloader"}), StatusCode::BAD_REQUEST),
        (json!({"board": "nano"}), StatusCode::BAD_REQUEST),
    ] {
        let (st, j) = s
            .call(Method::POST, "/api/hardware/build", &s.engineer, Some(body))
            .await;
        assert_eq!(st, want, "{j}");
        assert!(j["error"].is_string(), "{j}");
    }
    // The interpreter: the sizes of the firmware `alba export interpreter --build` makes.
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/build",
            &s.engineer,
            Some(json!({"board": "nano", "kind": "interpreter"})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let c = alba_load::compile_dir(&s.dir);
    let t = alba_app::hardware::target(&c, Some("nano"), None, true).expect("target");
    let (built, _) = interp::firmware(&t).expect("interpreter");
    assert_eq!(j["flash_bytes"], built.flash, "{j}");
    assert_eq!(j["ram_bytes"], built.ram, "{j}");
    assert_eq!(
        (j["flash_max"].as_u64(), j["ram_max"].as_u64()),
        (Some(32_256), Some(2_048))
    );
    // The stand-alone sketch for the Mega: smaller than its flash, the Mega's limits.
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/build",
            &s.engineer,
            Some(json!({"board": "mega", "kind": "sketch"})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let flash = j["flash_bytes"].as_u64().expect("flash");
    assert!(flash > 1000 && flash < 253_952, "{j}");
    assert_eq!(j["ram_max"], 8_192, "{j}");
    assert!(j["report"].as_str().expect("report").starts_with("mega: flash"), "{j}");

    // A program that does not compile: 422 and where.
    std::fs::write(s.dir.join("main.lad"), "XIC(Nobody)OTE(Motor);\n").expect("main.lad");
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/build",
            &s.engineer,
            Some(json!({"board": "nano", "kind": "sketch"})),
        )
        .await;
    assert_eq!(st, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert!(d["message"].as_str().expect("message").contains("Nobody"), "{j}");
    assert_eq!(
        (d["file"].as_str(), d["line"].as_u64()),
        (Some("main.lad"), Some(1)),
        "{j}"
    );
    s.stop().await;
}

/// The interpreter for the project's board on an emulated Nano, its UART on `dir/link`.
struct Board {
    child: Child,
    /// The board's answers to `cmd`.
    out: BufReader<std::process::ChildStdout>,
    link: String,
}

impl Board {
    /// The interpreter for the project's board (the Nano when it has none).
    fn start(dir: &Path) -> Board {
        let c = alba_load::compile_dir(dir);
        let t = alba_app::hardware::target(&c, Some("nano"), None, true).expect("target");
        let (built, _) = interp::firmware(&t).expect("interpreter firmware");
        let bin = simavr::board().expect("alba-board");
        let link = dir.join("link");
        let mut child = Command::new(bin)
            .arg(&built.elf)
            .args(["-m", "atmega328p", "--tty"])
            .arg(&link)
            .args(["--pins", "D12,D13", "--eeprom"])
            .arg(dir.join("eeprom.bin"))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("alba-board");
        let mut ready = String::new();
        let mut out = BufReader::new(child.stdout.take().expect("stdout"));
        out.read_line(&mut ready).expect("ready");
        assert!(ready.starts_with("ready "), "{ready}");
        Board {
            child,
            out,
            link: link.to_string_lossy().into_owned(),
        }
    }

    /// The controller (remote-I/O) firmware for the Nano (aurora map, Modbus
    /// RTU: `alba firmware`) on an emulated Nano, its UART on `dir/ctl-link`.
    fn controller(dir: &Path) -> Board {
        let map = alba_model::board::PinMap::preset("aurora").expect("aurora");
        let spec = alba_io::firmware::Spec::new(
            alba_model::board::Model::Nano,
            "aurora",
            map,
            alba_io::firmware::Link::Modbus,
        );
        let sketch = alba_io::firmware::write(&spec, &dir.join("ctl")).expect("firmware");
        let built = alba_arduino::toolchain::build(&sketch, alba_model::board::Model::Nano, &dir.join("ctl/build"))
            .expect("avr-gcc");
        Board::run(&built.elf, &dir.join("ctl-link"))
    }

    /// The project's stand-alone sketch with its monitoring link (`alba export
    /// arduino`) on an emulated Nano, its UART on `dir/sketch-link`.
    fn sketch(dir: &Path) -> Board {
        let c = alba_load::compile_dir(dir);
        let t = alba_app::hardware::target(&c, Some("nano"), None, true).expect("target");
        let prog = alba_arduino::sketch::control_program(c.program.as_ref().expect("program"));
        let s = alba_arduino::sketch::generate(&prog, "hw", &t).expect("sketch");
        let folder = dir.join("sketch").join(&s.name);
        std::fs::create_dir_all(&folder).expect("mkdir");
        for (name, text) in &s.files {
            std::fs::write(folder.join(name), text).expect("sketch file");
        }
        let built = alba_arduino::toolchain::build(
            &folder.join(&s.files[0].0),
            alba_model::board::Model::Nano,
            &folder.join("build"),
        )
        .expect("avr-gcc");
        Board::run(&built.elf, &dir.join("sketch-link"))
    }

    /// `elf` on an emulated Nano sampling D12 and D13, its UART on `link`.
    fn run(elf: &Path, link: &Path) -> Board {
        let bin = simavr::board().expect("alba-board");
        let mut child = Command::new(bin)
            .arg(elf)
            .args(["-m", "atmega328p", "--tty"])
            .arg(link)
            .args(["--pins", "D12,D13"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("alba-board");
        let mut ready = String::new();
        let mut out = BufReader::new(child.stdout.take().expect("stdout"));
        out.read_line(&mut ready).expect("ready");
        assert!(ready.starts_with("ready "), "{ready}");
        Board {
            child,
            out,
            link: link.to_string_lossy().into_owned(),
        }
    }

    /// A command of the emulated board (`stuck 5`, `stuck off`) and its answer.
    fn cmd(&mut self, c: &str) -> String {
        let stdin = self.child.stdin.as_mut().expect("stdin");
        writeln!(stdin, "{c}").expect("command");
        let mut a = String::new();
        self.out.read_line(&mut a).expect("answer");
        a.trim().to_string()
    }
}

impl Drop for Board {
    fn drop(&mut self) {
        if let Some(mut i) = self.child.stdin.take() {
            let _ = writeln!(i, "quit");
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_byte_code_goes_to_the_emulated_nano_as_a_job_and_failures_say_why_in_words() {
    let s = Studio::start("download").await;
    let mut board = Board::start(&s.dir);

    // Who is there, before anything is sent: the interpreter, no program yet.
    let (st, j) = s.on_port("identify", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!(
        (j["known"].as_bool(), j["board"].as_str()),
        (Some(true), Some("nano")),
        "{j}"
    );
    assert_eq!(j["state"], "no_program", "{j}");

    let (st, j) = s.on_port("download", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let job = j["job"].as_str().expect("job").to_string();
    let (end, seen) = s.finish(&job).await;
    assert_eq!(end["state"], "done", "{end}");
    assert_eq!(end["progress"], 100, "{end}");
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "progress only grows: {seen:?}");
    let msg = end["message"].as_str().expect("message");
    assert!(
        msg.contains("verified") && msg.contains("runs the new program"),
        "{msg}"
    );
    // The board says so itself: running, with the program the project encodes.
    let (_, j) = s.on_port("identify", &board.link).await;
    assert_eq!(j["state"], "running", "{j}");
    let c = alba_load::compile_dir(&s.dir);
    let t = alba_app::hardware::target(&c, None, None, true).expect("target");
    let prog = alba_arduino::sketch::control_program(c.program.as_ref().expect("program"));
    let bc = alba_arduino::bytecode::encode(&prog, "hw", &t).expect("byte code");
    assert_eq!(j["program"], format!("{:08x}", bc.program_id), "{j}");
    // Verify: the board's program read back is the project's.
    let (st, j) = s.on_port("verify", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!(
        (j["same"].as_bool(), j["bytes"].as_u64()),
        (Some(true), Some(bc.bytes.len() as u64)),
        "{j}"
    );
    // The view keeps the job (a reloaded page finds it), and the port typed by hand.
    let (_, v) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    assert_eq!(v["jobs"][0]["id"], job.as_str(), "{v}");
    assert!(
        v["ports"]
            .as_array()
            .expect("ports")
            .iter()
            .any(|p| p["path"] == board.link.as_str()),
        "{v}"
    );

    // A port that is not there: the job fails in words, nothing sent.
    let gone = s.dir.join("no-such-port").to_string_lossy().into_owned();
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/download",
            &s.engineer,
            Some(json!({"port": gone})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let (end, _) = s.finish(j["job"].as_str().expect("job")).await;
    assert_eq!(end["state"], "failed", "{end}");
    let msg = end["message"].as_str().expect("message");
    assert!(
        msg.contains("cannot open") && msg.contains("is the board plugged in?") && msg.contains("nothing was sent"),
        "{msg}"
    );
    // The board was not touched: it runs the program downloaded before.
    let (_, j) = s.on_port("identify", &board.link).await;
    assert_eq!(j["state"], "running", "{j}");

    // A record the board's memory does not keep (an EEPROM cell stuck): flag 20 in
    // words, and the board runs the program it had, not the changed one.
    let running = j["program"].clone();
    std::fs::write(
        s.dir.join("main.lad"),
        "[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)OTE(Lamp);\n",
    )
    .expect("main.lad");
    assert_eq!(board.cmd("stuck 5"), "ok");
    let (st, j) = s.on_port("download", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let (end, _) = s.finish(j["job"].as_str().expect("job")).await;
    assert_eq!(end["state"], "failed", "{end}");
    assert_eq!(
        end["message"],
        "record 1 was refused 3 times: the memory did not keep what was written (20): the board still runs the previous program",
        "{end}"
    );
    assert_eq!(board.cmd("stuck off"), "ok");
    let (_, j) = s.on_port("identify", &board.link).await;
    assert_eq!((&j["state"], &j["program"]), (&json!("running"), &running), "{j}");
    // …which is not the project's any more: Verify says so, and where.
    let (st, j) = s.on_port("verify", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!(j["same"], false, "{j}");
    let msg = j["message"].as_str().expect("message");
    assert!(
        msg.contains("differs from the project's at byte") && msg.contains(running.as_str().expect("id")),
        "{msg}"
    );

    // Each download audited with its outcome.
    let mut rows = Vec::new();
    for _ in 0..50 {
        rows = s.audit("download").await;
        if rows.iter().all(|r| r["outcome"] != "pending") {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    assert_eq!(rows.len(), 3, "{rows:?}");
    assert!(
        rows.iter()
            .any(|r| r["outcome"] == "ok" && r["target"] == board.link.as_str()),
        "{rows:?}"
    );
    assert!(
        rows.iter()
            .any(|r| r["target"] == board.link.as_str() && r["error"].as_str().is_some_and(|e| e.contains("(20)"))),
        "{rows:?}"
    );
    assert!(
        rows.iter()
            .any(|r| r["outcome"] != "ok" && r["target"] == gone.as_str()),
        "{rows:?}"
    );
    drop(board);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_a_board_in_alba_toml_the_download_takes_the_board_the_interpreter_says_it_is() {
    let s = Studio::start("noboard").await;
    std::fs::write(
        s.dir.join("alba.toml"),
        "name = \"hw\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("alba.toml");
    let board = Board::start(&s.dir);
    let (_, v) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    assert_eq!(v["board"], Json::Null, "{v}");
    let (st, j) = s.on_port("download", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let (end, _) = s.finish(j["job"].as_str().expect("job")).await;
    assert_eq!(
        (&end["state"], &end["progress"]),
        (&json!("done"), &json!(100)),
        "{end}"
    );
    let (_, j) = s.on_port("verify", &board.link).await;
    assert_eq!(j["same"], true, "{j}");
    let (_, j) = s.on_port("identify", &board.link).await;
    let running = j["program"].clone();

    // Cancelled after the second record (the shared download, as a job's cancel
    // does it): the board drops what it had and runs its program on.
    std::fs::write(
        s.dir.join("main.lad"),
        "[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)OTE(Lamp);\n",
    )
    .expect("main.lad");
    let (dir, port) = (s.dir.clone(), board.link.clone());
    let r = tokio::task::spawn_blocking(move || {
        let c = alba_load::compile_dir(&dir);
        alba_app::hardware::download(&c, None, None, &port, true, |done, _| done < 2).map(|d| d.bytes)
    })
    .await
    .expect("download");
    match r {
        Err(alba_app::hardware::DownloadFailure::Link(e)) => {
            assert!(e.to_string().starts_with("cancelled after record 2 of "), "{e}")
        }
        other => panic!("expected a cancelled download: {other:?}"),
    }
    let (_, j) = s.on_port("identify", &board.link).await;
    assert_eq!((&j["state"], &j["program"]), (&json!("running"), &running), "{j}");
    // A job cancelled through the API ends, whether the board had it all or not.
    let (_, j) = s.on_port("download", &board.link).await;
    let job = j["job"].as_str().expect("job").to_string();
    let (st, j) = s
        .call(
            Method::POST,
            &format!("/api/hardware/jobs/{job}/cancel"),
            &s.engineer,
            Some(json!({})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let (end, _) = s.finish(&job).await;
    let msg = end["message"].as_str().expect("message");
    assert!(
        (end["state"] == "failed"
            && msg.contains("cancelled after record")
            && msg.contains("still runs the previous program"))
            || end["state"] == "done",
        "{end}"
    );
    let (st, _) = s
        .call(
            Method::POST,
            "/api/hardware/jobs/nope/cancel",
            &s.engineer,
            Some(json!({})),
        )
        .await;
    assert_eq!(st, StatusCode::NOT_FOUND);
    drop(board);
    s.stop().await;
}

/// Waits (30 s at most) until the emulated board's output pins are `pins`.
async fn board_says(board: &mut Board, pins: &str, what: &str) {
    let t0 = std::time::Instant::now();
    while board.cmd("get") != pins {
        assert!(t0.elapsed() < Duration::from_secs(30), "timed out waiting for {what}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_board_is_attached_as_the_plc_s_io_and_detached_without_restarting_audited() {
    let s = Studio::start("attach").await;
    let mut board = Board::controller(&s.dir);
    let attach = |port: &str, mode: &str| json!({ "port": port, "mode": mode });

    // A viewer changes nothing.
    for (path, body) in [
        ("/api/hardware/attach", attach(&board.link, "controller")),
        ("/api/hardware/detach", json!({})),
    ] {
        let (st, j) = s.call(Method::POST, path, &s.viewer, Some(body)).await;
        assert_eq!(st, StatusCode::FORBIDDEN, "{path}: {j}");
    }
    // Not a mode; not a port; nothing to detach.
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/attach",
            &s.engineer,
            Some(attach(&board.link, "remote")),
        )
        .await;
    assert_eq!(st, StatusCode::BAD_REQUEST, "{j}");
    let gone = s.dir.join("no-such-port").to_string_lossy().into_owned();
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/attach",
            &s.engineer,
            Some(attach(&gone, "controller")),
        )
        .await;
    assert_eq!(st, StatusCode::BAD_GATEWAY, "{j}");
    assert!(
        j["error"].as_str().expect("error").contains("no such serial port"),
        "{j}"
    );
    let (st, j) = s
        .call(Method::POST, "/api/hardware/detach", &s.engineer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::CONFLICT, "{j}");

    // Attached: the board's pins are the program's I/O, the PLC never stopped.
    let scans = |j: &Json| j["scans"].as_u64().unwrap_or(0);
    let (_, before) = s.call(Method::GET, "/api/status", &s.viewer, None).await;
    let (st, v) = s
        .call(
            Method::POST,
            "/api/hardware/attach",
            &s.engineer,
            Some(attach(&board.link, "controller")),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{v}");
    assert_eq!(v["attached"]["port"], board.link.as_str(), "{v}");
    assert_eq!(
        (v["attached"]["mode"].as_str(), v["io"].as_str()),
        (Some("controller"), Some("sim")),
        "{v}"
    );
    assert_eq!(v["attached"]["io"], format!("arduino:{}", board.link), "{v}");
    let (_, v) = s.call(Method::GET, "/api/hardware", &s.viewer, None).await;
    assert_eq!(v["attached"]["port"], board.link.as_str(), "{v}");
    let tag = |name: &'static str| {
        let s = &s;
        async move {
            s.call(Method::GET, &format!("/api/tags/{name}"), &s.viewer, None)
                .await
                .1["value"]
                .clone()
        }
    };
    // Start pressed on the board (D2): the program sees it, Motor seals in on D12.
    assert_eq!(board.cmd("set D2 1"), "ok");
    let t0 = std::time::Instant::now();
    while tag("Start").await != json!(true) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "Start never came from the board's pin"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(board.cmd("set D2 0"), "ok");
    board_says(&mut board, "pins 1 0", "Motor on the board's D12").await;
    let t0 = std::time::Instant::now();
    while tag("Start").await != json!(false) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "Start never released from the board's pin"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(tag("Motor").await, json!(true));
    let (_, after) = s.call(Method::GET, "/api/status", &s.viewer, None).await;
    assert_eq!(after["state"], "running", "{after}");
    assert!(scans(&after) > scans(&before), "{before} {after}");

    // One user of a port at a time.
    let (st, j) = s
        .call(
            Method::POST,
            "/api/hardware/attach",
            &s.engineer,
            Some(attach(&board.link, "monitor")),
        )
        .await;
    assert_eq!(st, StatusCode::CONFLICT, "{j}");
    let (st, j) = s.on_port("download", &board.link).await;
    assert_eq!(st, StatusCode::TOO_MANY_REQUESTS, "{j}");
    assert!(j["error"].as_str().expect("error").contains("detach it first"), "{j}");

    // Detached: the board's outputs off, the simulated I/O back, still running.
    let (st, v) = s
        .call(Method::POST, "/api/hardware/detach", &s.engineer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::OK, "{v}");
    assert_eq!(v["attached"], Json::Null, "{v}");
    board_says(&mut board, "pins 0 0", "the board's outputs off").await;
    assert_eq!(board.cmd("set D2 1"), "ok");
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(tag("Start").await, json!(false), "the board's pin is not read any more");
    let (_, status) = s.call(Method::GET, "/api/status", &s.viewer, None).await;
    assert_eq!(status["state"], "running", "{status}");

    // Audited: the refused attach to a missing port, the attach, the detach.
    let rows = s.audit("attach").await;
    assert_eq!(rows.len(), 2, "{rows:?}");
    let ok = rows.iter().find(|r| r["outcome"] == "ok").expect("the attach");
    assert_eq!(
        (ok["user"].as_str(), ok["target"].as_str(), ok["detail"].as_str()),
        (Some("engineer"), Some(board.link.as_str()), Some("controller")),
        "{rows:?}"
    );
    assert_eq!(
        (ok["old"].as_str(), ok["new"].clone()),
        (Some("sim"), json!(format!("arduino:{}", board.link))),
        "{rows:?}"
    );
    assert!(
        rows.iter()
            .any(|r| r["target"] == gone.as_str() && r["outcome"] != "ok"),
        "{rows:?}"
    );
    let rows = s.audit("detach").await;
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(
        (rows[0]["outcome"].as_str(), rows[0]["user"].as_str()),
        (Some("ok"), Some("engineer")),
        "{rows:?}"
    );
    drop(board);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cable_pulled_mid_download_ends_the_job_in_words_and_the_board_keeps_its_program() {
    let s = Studio::start("cable").await;
    let mut board = Board::start(&s.dir);
    let (_, j) = s.on_port("download", &board.link).await;
    let (end, _) = s.finish(j["job"].as_str().expect("job")).await;
    assert_eq!(end["state"], "done", "{end}");
    let (_, j) = s.on_port("identify", &board.link).await;
    let running = j["program"].clone();
    assert!(running.is_string(), "{j}");

    // Another program; the cable pulled (the pty closed) while its records go.
    std::fs::write(
        s.dir.join("main.lad"),
        "[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)OTE(Lamp);\n",
    )
    .expect("main.lad");
    let (st, j) = s.on_port("download", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    let job = j["job"].as_str().expect("job").to_string();
    let mut at = None;
    for _ in 0..3000 {
        let (_, j) = s
            .call(Method::GET, &format!("/api/hardware/jobs/{job}"), &s.viewer, None)
            .await;
        if j["state"] != "running" {
            panic!("the download ended before the cable was pulled: {j}");
        }
        if j["progress"].as_u64().is_some_and(|p| p > 0) {
            assert_eq!(board.cmd("unplug"), "ok");
            at = j["progress"].as_u64();
            break;
        }
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    let at = at.expect("the records never started");
    let (end, _) = s.finish(&job).await;
    assert_eq!(end["state"], "failed", "{end}");
    assert!(
        (end["progress"].as_u64().expect("progress")) < 100,
        "pulled at {at} %: {end}"
    );
    let msg = end["message"].as_str().expect("message");
    assert!(
        msg.starts_with("the link to the board was lost at record ")
            && msg.contains("(cable pulled or board reset?)")
            && msg.ends_with(": the board still runs the previous program"),
        "{msg}"
    );
    // Plugged in again: the board runs the program it had.
    assert!(board.cmd("plug").starts_with("ok "));
    let (st, j) = s.on_port("identify", &board.link).await;
    assert_eq!(st, StatusCode::OK, "{j}");
    assert_eq!((&j["state"], &j["program"]), (&json!("running"), &running), "{j}");
    let (_, j) = s.on_port("verify", &board.link).await;
    assert_eq!(j["same"], false, "{j}");
    drop(board);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_board_running_the_sketch_is_watched_live_and_let_go_without_restarting() {
    let s = Studio::start("monitor").await;
    let mut board = Board::sketch(&s.dir);
    let (st, v) = s
        .call(
            Method::POST,
            "/api/hardware/attach",
            &s.engineer,
            Some(json!({"port": board.link, "mode": "monitor"})),
        )
        .await;
    assert_eq!(st, StatusCode::OK, "{v}");
    assert_eq!(
        (v["attached"]["mode"].as_str(), v["attached"]["io"].clone()),
        (Some("monitor"), json!(format!("board:{}", board.link))),
        "{v}"
    );
    let tag = |name: &'static str| {
        let s = &s;
        async move {
            s.call(Method::GET, &format!("/api/tags/{name}"), &s.viewer, None)
                .await
                .1["value"]
                .clone()
        }
    };
    // The board runs the program: Start pressed on it seals Motor in, on the board
    // and in the runtime's mirror of its memory.
    assert_eq!(board.cmd("set D2 1"), "ok");
    board_says(&mut board, "pins 1 0", "Motor on the board's D12").await;
    assert_eq!(board.cmd("set D2 0"), "ok");
    let t0 = std::time::Instant::now();
    while tag("Motor").await != json!(true) || tag("Start").await != json!(false) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "the board's memory never mirrored"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    // Stop is the board's own business while it is watched.
    let (st, j) = s.call(Method::POST, "/api/stop", &s.engineer, Some(json!({}))).await;
    assert_eq!(st, StatusCode::CONFLICT, "{j}");
    // Let go: the runtime scans the project's program again, from the board's memory.
    let (st, v) = s
        .call(Method::POST, "/api/hardware/detach", &s.engineer, Some(json!({})))
        .await;
    assert_eq!(st, StatusCode::OK, "{v}");
    assert_eq!(v["attached"], Json::Null, "{v}");
    let (_, status) = s.call(Method::GET, "/api/status", &s.viewer, None).await;
    assert_eq!(status["state"], "running", "{status}");
    assert_eq!(tag("Motor").await, json!(true), "sealed in, as the board had it");
    // The board is left running its program (watching it changed nothing there).
    assert_eq!(board.cmd("get"), "pins 1 0");
    let (st, _) = s.call(Method::POST, "/api/stop", &s.engineer, Some(json!({}))).await;
    assert_eq!(st, StatusCode::OK);
    drop(board);
    s.stop().await;
}
