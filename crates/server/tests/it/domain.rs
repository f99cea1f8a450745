//! `GET /api/domain`: the language as the studio takes it, from the Rust
//! definitions; the studio's unit tests use a copy of the reply
//! (web/test/fixtures/domain.json) that must stay equal to it
//! (`ALBA_BLESS=1` rewrites the copy).

use crate::Server;
use serde_json::{Value as Json, json};

fn fixture() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web/test/fixtures/domain.json")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn domain_has_structures_signatures_and_address_notations() {
    let s = Server::start("tank", "domain").await;
    let d = s.get("/api/domain").await;

    // Structures with their members, PID included.
    let ty = |name: &str| {
        d["types"]
            .as_array()
            .expect("types")
            .iter()
            .find(|t| t["name"] == name)
            .cloned()
            .unwrap_or_else(|| panic!("type {name}"))
    };
    assert_eq!(ty("TIMER")["kind"], "structure");
    assert_eq!(
        ty("TIMER")["members"][4],
        json!({"name": "DN", "type": "BOOL", "writable": false})
    );
    assert_eq!(
        ty("PID")["members"][0],
        json!({"name": "SP", "type": "REAL", "writable": true})
    );
    assert_eq!(ty("DINT")["kind"], "integer");
    assert_eq!(ty("DINT")["members"], json!([]));

    // Signatures: kinds, labels, titles; PID is in the palette.
    let instr = |m: &str| {
        d["instructions"]
            .as_array()
            .expect("instructions")
            .iter()
            .find(|i| i["mnemonic"] == m)
            .cloned()
            .unwrap_or_else(|| panic!("{m}"))
    };
    let pid = instr("PID");
    assert_eq!(pid["group"], "special");
    assert_eq!(pid["args"], json!(["pid", "num_in", "num_out"]));
    assert_eq!(pid["labels"], json!(["PID", "Process Var", "Control Var"]));
    assert_eq!(instr("TON")["title"], "Timer On Delay");
    assert_eq!(instr("XIC")["shape"], "contact");
    let groups: Vec<&str> = d["groups"]
        .as_array()
        .expect("groups")
        .iter()
        .map(|g| g["name"].as_str().expect("name"))
        .collect();
    assert_eq!(
        groups,
        [
            "bit", "timer", "counter", "compare", "math", "move", "trig", "flow", "special"
        ]
    );
    let pid_arg = d["args"]
        .as_array()
        .expect("args")
        .iter()
        .find(|a| a["name"] == "pid")
        .cloned();
    assert_eq!(pid_arg.expect("pid")["types"], json!(["PID"]));

    // /api/instructions is the same table.
    assert_eq!(s.get("/api/instructions").await, d["instructions"]);

    // Every notation of a tag's address comes with the tag.
    let tags = s.get("/api/tags").await;
    let stop = tags
        .as_array()
        .expect("tags")
        .iter()
        .find(|t| t["name"] == "STOP")
        .cloned()
        .expect("STOP");
    assert_eq!(stop["notations"], json!(["DI:1/0", "%IX0.0", "%I0.0", "I0.0", "I:0/0"]));
    s.stop().await;

    // The studio's unit tests run on a copy of this reply.
    let path = fixture();
    if std::env::var_os("ALBA_BLESS").is_some() {
        let text = serde_json::to_string_pretty(&d).expect("json") + "\n";
        std::fs::write(&path, text).expect("write the fixture");
    }
    let copy: Json =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read the fixture")).expect("fixture JSON");
    assert!(
        copy == d,
        "{} differs from GET /api/domain: run `ALBA_BLESS=1 cargo test -p alba-server domain` and commit it",
        path.display()
    );
}
