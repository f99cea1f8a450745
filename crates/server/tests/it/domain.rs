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

/// The texts a person reads (titles, docs, operand labels, the designer's help), each
/// with where it was found, from a reply of `GET /api/domain`.
fn texts(v: &Json, key: &str, out: &mut Vec<(String, String)>) {
    match v {
        Json::String(t) if ["title", "doc", "labels", "label", "help", "elements"].contains(&key) => {
            out.push((key.to_string(), t.clone()))
        }
        Json::Array(a) if key == "elements" => {
            // `[type, what it is]`: the type is a name, not a text
            a.iter().for_each(|e| texts(&e[1], key, out))
        }
        Json::Array(a) => a.iter().for_each(|e| texts(e, key, out)),
        Json::Object(o) => o.iter().for_each(|(k, e)| texts(e, k, out)),
        _ => {}
    }
}

/// A Spanish studio gets the domain's texts in Spanish (issue 34's leftover): every text
/// of the English reply has its entry in `es::DOMAIN` (or `es::VALUES`, for the operand
/// kinds), the Spanish reply carries it, and every entry of `es::DOMAIN` is a text of the
/// reply (no stale entries).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_domain_speaks_spanish() {
    use alba_compiler::diag::es;
    let s = Server::start("tank", "domain-es").await;
    let en = s.get("/api/domain").await;
    let get_es = |path: &str| {
        s.http
            .get(s.url(path))
            .header("accept-language", "es-ES,es;q=0.9")
            .send()
    };
    let es_reply: Json = get_es("/api/domain")
        .await
        .expect("request")
        .json()
        .await
        .expect("JSON");
    let (mut en_texts, mut es_texts) = (Vec::new(), Vec::new());
    texts(&en, "", &mut en_texts);
    texts(&es_reply, "", &mut es_texts);
    assert_eq!(en_texts.len(), es_texts.len());
    assert!(en_texts.len() > 300, "{} texts", en_texts.len());
    let missing: Vec<&String> = en_texts
        .iter()
        .filter(|(_, t)| es::domain_text(t).is_none())
        .map(|(_, t)| t)
        .collect();
    assert!(missing.is_empty(), "texts without Spanish in es::DOMAIN: {missing:#?}");
    for ((_, en), (_, es)) in en_texts.iter().zip(&es_texts) {
        assert_eq!(Some(es.as_str()), es::domain_text(en), "{en}");
    }
    let stale: Vec<&str> = es::DOMAIN
        .iter()
        .map(|(en, _)| *en)
        .filter(|en| !en_texts.iter().any(|(_, t)| t == en))
        .collect();
    assert!(stale.is_empty(), "entries of es::DOMAIN that no text uses: {stale:?}");
    // The palette's table too, and the rest of the reply (names, types, routes) as it was.
    let palette: Json = get_es("/api/instructions")
        .await
        .expect("request")
        .json()
        .await
        .expect("JSON");
    assert_eq!(palette, es_reply["instructions"]);
    assert_eq!(es_reply["instructions"][0]["title"], "Examinar si cerrado");
    assert_eq!(es_reply["types"], en["types"]);
    assert_eq!(es_reply["routes"], en["routes"]);
    s.stop().await;
}
