//! PLCopen export: the examples made of contacts, coils, branches, timers,
//! compares and math, and a project of counters, one-shots and CPT, are
//! exported, imported again, and the round trip behaves like the original in
//! the simulator (random inputs, every BOOL and number compared on every
//! scan; a one-shot's storage bit, which becomes its R_TRIG/F_TRIG instance,
//! is the only tag left out).

use alba_import::Options;
use std::collections::HashMap;
use std::fs;
use std::path::Path;
use std::sync::Arc;

fn trace(dir: &Path, stimulus: &str, cols: &[String], until: u64) -> Vec<Vec<String>> {
    let c = alba_load::compile_dir(dir);
    let scan_ms = c.project.config.as_ref().map(|c| u64::from(c.scan_ms)).expect("config");
    let prog = c.program.expect("compiles");
    let mut files = alba_diag::Files::new();
    let fid = files.add("stimulus.csv", stimulus.to_string());
    let stim = alba_engine::sim::Stimulus::parse(stimulus, fid, &prog.layout).expect("stimulus");
    let columns = alba_engine::sim::columns(&cols.join(","), &prog.layout).expect("columns");
    let mut engine = alba_engine::Engine::new(Arc::new(prog)).expect("engine");
    let mut out = Vec::new();
    let opt = alba_engine::sim::SimOptions {
        scan_ms,
        until_ms: until,
        every_ms: scan_ms,
    };
    alba_engine::sim::run(&mut engine, &stim, &columns, opt, &mut out).expect("sim");
    String::from_utf8(out)
        .expect("utf8")
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

fn round_trip(example: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(example);
    round_trip_dir(example, &dir);
}

fn round_trip_dir(example: &str, dir: &Path) {
    let dir = dir.to_path_buf();
    let (xml, report) = alba_import::export_plcopen(&dir).expect("export");
    let refused: Vec<String> = report
        .entries
        .iter()
        .filter(|e| e.kind == alba_import::Kind::Refused)
        .map(|e| e.to_string())
        .collect();
    assert!(refused.is_empty(), "{example}: {refused:?}");
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join(format!("{example}.xml"));
    fs::write(&file, &xml).expect("write");
    let back = tmp.path().join("back");
    let r = alba_import::import(&file, &back, &Options::default()).expect("import");
    assert_eq!(r.count(alba_import::Kind::Refused), 0, "{example}: {}", r.render());
    // One-shot storage bits are R_TRIG/F_TRIG instances in the file.
    let instances: Vec<String> = xml
        .lines()
        .filter(|l| l.contains("<derived name=\"R_TRIG\"/>") || l.contains("<derived name=\"F_TRIG\"/>"))
        .filter_map(|l| {
            l.split("name=\"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .map(str::to_string)
        })
        .collect();
    // Inputs and compared columns from the original tag table.
    let tags = fs::read_to_string(dir.join("tags.csv")).expect("tags");
    let mut inputs = Vec::new();
    let mut cols = Vec::new();
    let mut analog = Vec::new();
    for row in tags.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        if f.len() < 3 || f[1] == "TIMER" || f[1] == "COUNTER" || instances.iter().any(|i| i == f[0]) {
            continue;
        }
        if f[2].starts_with("DI") {
            inputs.push(f[0].to_string());
        }
        if f[2].starts_with("AI") {
            analog.push(f[0].to_string());
        }
        cols.push(f[0].to_string());
    }
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut stim = String::from("time_ms,tag,value\n");
    let mut now: HashMap<String, u64> = HashMap::new();
    for k in 0..2000u64 {
        for a in &analog {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if k == 0 || x.is_multiple_of(25) {
                stim.push_str(&format!("{},{a},{}\n", k * 10, (x >> 8) % 1000));
            }
        }
        for i in &inputs {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if k == 0 || x.is_multiple_of(40) {
                let v = (x >> 8) % 2;
                if now.get(i) != Some(&v) {
                    now.insert(i.clone(), v);
                    stim.push_str(&format!("{},{i},{v}\n", k * 10));
                }
            }
        }
    }
    let a = trace(&dir, &stim, &cols, 60_000);
    let b = trace(&back, &stim, &cols, 60_000);
    assert_eq!(a.len(), b.len());
    let mut changed = 0;
    for (k, (ra, rb)) in a.iter().zip(&b).enumerate() {
        assert_eq!(ra, rb, "{example}: scan row {k} ({cols:?})");
        if k > 0 && ra != &a[k - 1] {
            changed += 1;
        }
    }
    assert!(changed > 5, "{example}: the trace hardly moves");
}

#[test]
fn compares_and_math_round_trip() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/compare-math");
    round_trip_dir("compare-math", &dir);
}

#[test]
fn counters_one_shots_and_cpt_round_trip() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/counters-edges");
    round_trip_dir("counters-edges", &dir);
    let (xml, report) = alba_import::export_plcopen(&dir).expect("export");
    for want in [
        "typeName=\"CTU\" instanceName=\"Parts\"",
        "typeName=\"CTD\" instanceName=\"Stock\"",
        "typeName=\"R_TRIG\" instanceName=\"P1\"",
        "typeName=\"F_TRIG\" instanceName=\"P3\"",
        "<variable>Parts.Q</variable>",
        "<expression>(Level * 2.5 + Parts.CV) / (1 + ABS(Stock.CV))</expression>",
        "<expression>Level MOD 7 + 2 ** 3 - (-Edges) + (Level &gt; 500) * (Edges / 3)</expression>",
    ] {
        assert!(xml.contains(want), "{want}\n{xml}");
    }
    assert!(
        report.render().contains(
            "main.lad:13:1: approximated: OSF(P3,…) is F_TRIG `P3`: IEC's F_TRIG gives a pulse on the first scan"
        ),
        "{}",
        report.render()
    );
}

#[test]
fn start_stop_round_trip() {
    round_trip("start-stop");
}

#[test]
fn traffic_light_round_trip() {
    round_trip("traffic-light");
}

#[test]
fn star_delta_round_trip() {
    round_trip("star-delta");
}

#[test]
fn unsupported_instructions_are_refused_with_their_rung() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tank");
    let (xml, report) = alba_import::export_plcopen(&dir).expect("export");
    assert!(xml.contains("<project xmlns=\"http://www.plcopen.org/xml/tc6_0201\""));
    let refused: Vec<String> = report
        .entries
        .iter()
        .filter(|e| e.kind == alba_import::Kind::Refused)
        .map(|e| e.to_string())
        .collect();
    assert!(!refused.is_empty());
    assert!(
        refused
            .iter()
            .all(|e| (e.starts_with("main.lad:") && e.contains("rung not exported")) || e.starts_with("tags.csv:")),
        "{refused:?}"
    );
    assert!(
        refused
            .iter()
            .any(|e| e == "main.lad:2:1: refused: rung not exported: SCP is not exported to PLCopen (yet)")
    );
}

fn export_golden(example: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(example);
    let (xml, _) = alba_import::export_plcopen(&dir).expect("export");
    let golden = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden/export")
        .join(format!("{example}.xml"));
    if std::env::var_os("ALBA_BLESS").is_some() {
        fs::create_dir_all(golden.parent().expect("dir")).expect("mkdir");
        fs::write(&golden, &xml).expect("bless");
        return;
    }
    let want = fs::read_to_string(&golden).expect("golden; run with ALBA_BLESS=1");
    assert_eq!(xml, want);
}

#[test]
fn start_stop_export_golden() {
    export_golden("start-stop");
}

#[test]
fn st_motor_export_golden() {
    export_golden("st-motor");
}

#[test]
fn what_has_no_iec_form_is_refused_with_its_rung() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    fs::write(
        dir.join("alba.toml"),
        "name = \"x\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write");
    fs::write(
        dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nA,BOOL,DI:1/0,,,\nB,BOOL,,,,\nS,BOOL,,,,\nT,TIMER,,,,\nC,COUNTER,,,,\nU,COUNTER,,,,\n",
    )
    .expect("write");
    fs::write(
        dir.join("main.lad"),
        "XIC(A)RTO(T,100,0);\nXIC(B)RES(T);\nXIC(A)CTU(C,3,0);\nXIC(B)CTD(C,3,0);\nXIC(A)ONS(S)OTE(B);\nXIC(S)OTE(B);\nXIC(A)CTU(U,2,1);\n",
    )
    .expect("write");
    let (_, report) = alba_import::export_plcopen(dir).expect("export");
    let refused: Vec<String> = report
        .entries
        .iter()
        .filter(|e| e.kind == alba_import::Kind::Refused)
        .map(|e| e.to_string())
        .collect();
    let want = [
        "main.lad:1:1: refused: rung not exported: RTO has no IEC 61131-3 equivalent: the standard timers are TON, TOF and TP (a retentive timer is a vendor's library block)",
        "main.lad:2:1: refused: rung not exported: RES has no IEC 61131-3 equivalent: an IEC counter is reset by R of its own call, a timer by its IN",
        "main.lad:3:1: refused: rung not exported: `C` is counted up and down: IEC's CTUD evaluates both inputs in one call, Alba's CTU and CTD each at its own rung",
        "main.lad:5:1: refused: rung not exported: `S` is a one-shot's storage bit and is also used elsewhere (or has an address); it cannot become an R_TRIG/F_TRIG instance",
        "main.lad:7:1: refused: rung not exported: CTU: an initial count `1` has no IEC equivalent",
    ];
    for w in want {
        assert!(refused.iter().any(|r| r == w), "{w}\n{refused:#?}");
    }
}

#[test]
fn st_motor_round_trip() {
    round_trip("st-motor");
}

#[test]
fn plcopen_st_import_export_import_keeps_the_program() {
    // st-motor.xml imported, exported and imported again: the same .st
    // program and tags, and the same trace.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen/st-motor.xml");
    let tmp = tempfile::tempdir().expect("tmp");
    let first = tmp.path().join("first");
    alba_import::import(&src, &first, &Options::default()).expect("import");
    let (xml, report) = alba_import::export_plcopen(&first).expect("export");
    assert_eq!(report.count(alba_import::Kind::Refused), 0, "{}", report.render());
    assert!(
        xml.contains("<ST>") && xml.contains("history[starts MOD 4] := starts;"),
        "{xml}"
    );
    let file = tmp.path().join("again.xml");
    fs::write(&file, &xml).expect("write");
    let second = tmp.path().join("second");
    let r = alba_import::import(&file, &second, &Options::default()).expect("import again");
    assert_eq!(r.count(alba_import::Kind::Refused), 0, "{}", r.render());
    let a = fs::read_to_string(first.join("main.st")).expect("st");
    let b = fs::read_to_string(second.join("main.st")).expect("st");
    assert_eq!(a, b);
    let stim = "time_ms,tag,value\n0,start,1\n20,start,0\n200,stop,1\n220,stop,0\n300,start,1\n320,start,0\n";
    let cols: Vec<String> = ["motor", "lamp", "main.starts", "main.history[1]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let ta = trace(&first, stim, &cols, 1000);
    // Columns after the time: motor, lamp, starts, history[1].
    assert!(
        ta.iter().any(|r| r[3] == "2") && ta.iter().all(|r| r[4] == "1"),
        "{ta:?}"
    );
    assert_eq!(ta, trace(&second, stim, &cols, 1000));
}

#[test]
fn st_functions_function_blocks_and_types_are_exported_and_come_back() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    fs::write(
        d.join("alba.toml"),
        "name = \"t\"\nscan_ms = 10\nprograms = [\"lib.st\", \"main.st\"]\n",
    )
    .expect("w");
    fs::write(
        d.join("tags.csv"),
        "name,type,address,initial,retain,description\nx,INT,,,,\ny,INT,,,,\n",
    )
    .expect("w");
    fs::write(
        d.join("lib.st"),
        "TYPE Pair : STRUCT a : INT; b : INT := 7; END_STRUCT; Color : (Red, Green := 5); END_TYPE\n\
         FUNCTION Twice : INT\nVAR_INPUT a : INT; END_VAR\nTwice := a * 2;\nEND_FUNCTION\n\
         FUNCTION_BLOCK Acc\nVAR_INPUT v : INT; END_VAR\nVAR_OUTPUT p : Pair; END_VAR\np.a := p.a + v;\nEND_FUNCTION_BLOCK\n",
    )
    .expect("w");
    fs::write(
        d.join("main.st"),
        "PROGRAM Main\nVAR acc : Acc; c : Color := Green; END_VAR\nacc(v := Twice(1));\nx := acc.p.a + acc.p.b; (* ]]> in a comment *)\n\
         y := TO_INT(c);\nEND_PROGRAM\n\
         PROGRAM Other\nVAR h : ARRAY[0..1] OF INT := [3, 4]; END_VAR\nh[0] := h[1];\nEND_PROGRAM\n",
    )
    .expect("w");
    let (xml, report) = alba_import::export_plcopen(d).expect("export");
    let text = report.render();
    assert!(
        xml.contains("<pou name=\"Twice\" pouType=\"function\">")
            && xml.contains("<returnType><INT/></returnType>")
            && xml.contains("<pou name=\"Acc\" pouType=\"functionBlock\">")
            && xml.contains("<dataType name=\"Pair\"><baseType><struct>")
            && xml.contains("<value name=\"Green\" value=\"5\"/>"),
        "{xml}"
    );
    // Only programs are task instances.
    assert!(
        xml.contains("typeName=\"Main\"") && !xml.contains("typeName=\"Acc\""),
        "{xml}"
    );
    // What PLCopen cannot say is refused at its place.
    assert!(
        text.contains("main.st:8:5: refused: an array or structure initialiser is not exported")
            && text.contains("main.st:7:9: refused: PROGRAM `Other` not exported"),
        "{text}"
    );
    // Imported back: the same values, and `]]>` survives the CDATA section.
    let back = d.join("back");
    let file = d.join("t.xml");
    fs::write(&file, &xml).expect("write");
    let r = alba_import::import(&file, &back, &Options::default()).expect("import");
    assert_eq!(r.count(alba_import::Kind::Refused), 0, "{}", r.render());
    let st = fs::read_to_string(back.join("Main.st")).expect("st");
    assert!(st.contains("(* ]]> in a comment *)"), "{st}");
    let cols: Vec<String> = ["x", "y", "Main.acc.p.a"].iter().map(|s| s.to_string()).collect();
    let stim = "time_ms,tag,value\n";
    let ta = trace(d, stim, &cols, 50);
    // x = p.a + b (7), y = Green (5), p.a + 2 a scan.
    assert!(
        ta.len() > 3
            && ta
                .iter()
                .all(|r| r[1].parse::<i64>().ok() == r[3].parse::<i64>().ok().map(|a| a + 7) && r[2] == "5")
            && ta.last().is_some_and(|r| r[3] != "0"),
        "{ta:?}"
    );
    assert_eq!(ta, trace(&back, stim, &cols, 50));
}

#[test]
fn plcopen_functions_and_function_blocks_import_export_import_keep_the_program() {
    // st-pous-types.xml (data types, a function, a function block, two
    // programs in two tasks) imported, exported and imported again: the
    // same .st files and the same trace.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen/st-pous-types.xml");
    let tmp = tempfile::tempdir().expect("tmp");
    let first = tmp.path().join("first");
    alba_import::import(&src, &first, &Options::default()).expect("import");
    let (xml, report) = alba_import::export_plcopen(&first).expect("export");
    assert_eq!(report.count(alba_import::Kind::Refused), 0, "{}", report.render());
    let file = tmp.path().join("again.xml");
    fs::write(&file, &xml).expect("write");
    let second = tmp.path().join("second");
    let r = alba_import::import(&file, &second, &Options::default()).expect("import again");
    assert_eq!(r.count(alba_import::Kind::Refused), 0, "{}", r.render());
    for f in ["types.st", "Clamp.st", "Filler.st", "Main.st", "Logger.st"] {
        let a = fs::read_to_string(first.join(f)).unwrap_or_else(|_| panic!("{f}"));
        let b = fs::read_to_string(second.join(f)).unwrap_or_else(|_| panic!("{f}"));
        assert_eq!(a, b, "{f}");
    }
    let stim = "time_ms,tag,value\n20,start,1\n40,start,0\n";
    let cols: Vec<String> = ["full", "cycles", "Main.plant.level", "Logger.log[1]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let ta = trace(&first, stim, &cols, 200);
    assert!(
        ta.iter().any(|r| r[1] == "1") && ta.last().is_some_and(|r| r[4] == "1"),
        "{ta:?}"
    );
    assert_eq!(ta, trace(&second, stim, &cols, 200));
}
