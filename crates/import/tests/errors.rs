//! Malformed and hostile inputs: each gives one precise error naming
//! file:line:col, and nothing is written.

use alba_import::{Format, Options};
use std::fs;
use std::path::Path;

fn err(name: &str, format: Option<Format>, text: &str) -> String {
    let opts = Options {
        format,
        board: None,
        force: false,
    };
    match alba_import::convert(Path::new(name), text, &opts) {
        Ok((p, _)) => panic!(
            "{name} was accepted:\n{}",
            p.programs.first().map(|p| p.text.as_str()).unwrap_or("")
        ),
        Err(e) => e.to_string(),
    }
}

fn ld(body: &str) -> String {
    format!("LDmicro0.1\nCYCLE=10000\n\nIO LIST\n    Xa at 2\n    Yb at 3\nEND\n\nPROGRAM\n{body}")
}

const PLC_HEAD: &str = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201">
  <types><pous>
    <pou name="main" pouType="program">
      <interface><localVars><variable name="a"><type><BOOL/></type></variable></localVars></interface>
      <body><LD>
"#;
const PLC_TAIL: &str = "      </LD></body>\n    </pou>\n  </pous></types>\n</project>\n";

fn cases() -> Vec<(&'static str, Option<Format>, String)> {
    let deep: String = {
        let mut s = String::from("RUNG\n");
        for _ in 0..40 {
            s.push_str("PARALLEL\nSERIES\n");
        }
        s.push_str("CONTACTS Xa 0\n");
        for _ in 0..40 {
            s.push_str("END\nEND\n");
        }
        s.push_str("END\n");
        s
    };
    let deep_xml = format!("{}{}", "<a>".repeat(200), "</a>".repeat(200));
    let bomb = r#"<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
]>
<project xmlns="http://www.plcopen.org/xml/tc6_0201">&lol3;</project>
"#;
    vec![
        ("empty.ld", Some(Format::Ldmicro), String::new()),
        ("version.ld", None, "LDmicro0.9\nPROGRAM\n".into()),
        ("noprogram.ld", None, "LDmicro0.1\nCYCLE=10000\n\nIO LIST\nEND\n".into()),
        ("unended.ld", None, ld("RUNG\n    CONTACTS Xa 0\n    COIL Yb 0 0 0\n")),
        ("unknown.ld", None, ld("RUNG\n    CONTACTS Xa 0\n    FROB Yb\nEND\n")),
        ("flag.ld", None, ld("RUNG\n    CONTACTS Xa yes\n    COIL Yb 0 0 0\nEND\n")),
        ("coil.ld", None, ld("RUNG\n    CONTACTS Xa 0\n    COIL Yb 0\nEND\n")),
        ("iolist.ld", None, "LDmicro0.1\nIO LIST\n    Xa on 3\nEND\nPROGRAM\n".into()),
        ("deep.ld", None, ld(&deep)),
        ("conflict.ld", None, ld("RUNG\n    CONTACTS a 0\n    MOVE a 1\nEND\n")),
        ("operand.ld", None, ld("RUNG\n    CONTACTS Xa 0\n    MOVE v 1x2\nEND\n")),
        ("toplevel.ld", None, ld("CONTACTS Xa 0\n")),
        ("cycle.ld", None, "LDmicro0.1\nCYCLE=fast\nPROGRAM\n".into()),
        ("notxml.xml", Some(Format::Plcopen), "hello, world\n".into()),
        ("bomb.xml", None, bomb.into()),
        ("root.xml", Some(Format::Plcopen), "<?xml version=\"1.0\"?>\n<foo/>\n".into()),
        ("nons.xml", Some(Format::Plcopen), "<project>\n  <types/>\n</project>\n".into()),
        ("unclosed.xml", None, format!("{PLC_HEAD}        <contact localId=\"1\">\n{PLC_TAIL}")),
        (
            "dupid.xml",
            None,
            format!(
                "{PLC_HEAD}        <leftPowerRail localId=\"1\"/>\n        <contact localId=\"1\"><variable>a</variable></contact>\n{PLC_TAIL}"
            ),
        ),
        ("deep.xml", Some(Format::Plcopen), deep_xml),
        ("entity.L5X", None, "<RSLogix5000Content>\n  <Controller Name=\"&oops;\"/>\n</RSLogix5000Content>\n".into()),
        ("root.L5X", Some(Format::L5x), "<?xml version=\"1.0\"?>\n<Project/>\n".into()),
        ("nocontroller.L5X", None, "<RSLogix5000Content SchemaRevision=\"1.0\">\n</RSLogix5000Content>\n".into()),
        (
            "noprograms.L5X",
            None,
            "<RSLogix5000Content SchemaRevision=\"1.0\">\n  <Controller Name=\"C\">\n    <Tags/>\n  </Controller>\n</RSLogix5000Content>\n".into(),
        ),
        ("what.txt", None, "just some text\n".into()),
    ]
}

#[test]
fn malformed_inputs_give_located_errors() {
    let got: Vec<String> = cases().iter().map(|(n, f, t)| err(n, *f, t)).collect();
    let want = EXPECTED;
    if std::env::var_os("ALBA_BLESS").is_some() {
        for g in &got {
            println!("{g:?},");
        }
    }
    assert_eq!(got.len(), want.len(), "{got:#?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g, w);
    }
}

const EXPECTED: &[&str] = &[
    "empty.ld:1:1: the file is empty",
    "version.ld:1:1: `LDmicro0.9`: only LDmicro0.1 and LDmicro0.2 files are read",
    "noprogram.ld:6:1: no `PROGRAM` section",
    "unended.ld:13:1: the file ends inside the RUNG opened at line 10: `END` expected",
    "unknown.ld:12:5: unknown LDmicro element `FROB`",
    "flag.ld:11:17: `yes` is not 0 or 1",
    "coil.ld:12:5: `COIL` takes a name and the negated, set-only and reset-only flags; found 2 operand(s)",
    "iolist.ld:3:5: `Xa on 3` is not `NAME at PIN`",
    "deep.ld:75:1: circuits nested deeper than 64 levels",
    "conflict.ld:12:5: `a` is used as a bit and as a number",
    "operand.ld:12:12: `1x2` is neither a number nor a name",
    "toplevel.ld:10:1: `CONTACTS Xa 0`: a rung must start with `RUNG`",
    "cycle.ld:2:1: `CYCLE=fast`: the cycle time is not a number of µs",
    "notxml.xml:1:1: not well-formed XML: text outside the root element",
    "bomb.xml:2:1: refused: a document type declaration (<!DOCTYPE>), whose entities could expand without bound",
    "root.xml:2:1: not a PLCopen project: the root element is <foo>, not <project>",
    "nons.xml:1:1: not PLCopen TC6 XML: <project> lacks the namespace http://www.plcopen.org/xml/tc6_0201",
    "unclosed.xml:8:7: not well-formed XML: ill-formed document: expected `</contact>`, but `</LD>` was found",
    "dupid.xml:8:9: localId 1 is used twice in `main`",
    "deep.xml:1:385: refused: elements nested deeper than 128 levels",
    "entity.L5X:2:3: not well-formed XML: bad attribute value: at 1..5: unrecognized entity `oops`",
    "root.L5X:2:1: not an L5X export: the root element is <Project>, not <RSLogix5000Content>",
    "nocontroller.L5X:1:1: <RSLogix5000Content> has no <Controller>",
    "noprograms.L5X:2:3: nothing to import: the controller has no program with an RLL main routine",
    "what.txt:1:1: cannot tell the format: not LDmicro (`LDmicro0.1` first line), PLCopen XML (`<project>`), L5X (`<RSLogix5000Content>`) or an AuroraLD main.ara (`//PROJECT NAME`); give it with --format",
];

#[test]
fn a_real_file_with_nothing_importable_names_its_programs() {
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen-refused/beremiz-first-steps.xml");
    let text = fs::read_to_string(&f).expect("fixture");
    assert_eq!(
        err("beremiz-first-steps.xml", None, &text),
        "beremiz-first-steps.xml:2:1: nothing to import: Alba imports LD, SFC and ST bodies of programs, and its programs are `plc_prg` (FBD)"
    );
}

#[test]
fn unknown_board_is_refused() {
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/ldmicro/contacts.ld");
    let text = fs::read_to_string(&f).expect("fixture");
    let opts = Options {
        format: None,
        board: Some("due".into()),
        force: false,
    };
    let e = alba_import::convert(&f, &text, &opts).err().map(|e| e.to_string());
    assert_eq!(e.as_deref(), Some("unknown board `due`: uno, nano or mega"));
}

/// Every entry of `dir`, to show that an import left nothing behind.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn nothing_is_written_when_an_import_fails() {
    let tmp = tempfile::tempdir().expect("tmp");
    let input = tmp.path().join("bad.ld");
    fs::write(&input, ld("RUNG\n    FROB Xa\nEND\n")).expect("write");
    let out = tmp.path().join("project");
    let e = alba_import::import(&input, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(e.as_deref(), Some("bad.ld:11:5: unknown LDmicro element `FROB`"));
    assert_eq!(entries(tmp.path()), vec!["bad.ld".to_string()]);
}

#[test]
fn an_existing_project_is_kept_without_force() {
    let tmp = tempfile::tempdir().expect("tmp");
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/ldmicro/contacts.ld");
    let out = tmp.path().join("project");
    fs::create_dir(&out).expect("mkdir");
    fs::write(out.join("alba.toml"), "name = \"mine\"\n").expect("write");
    fs::write(out.join("notes.txt"), "keep me").expect("write");
    let e = alba_import::import(&input, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        e,
        Some(format!(
            "{} exists and is not empty; use --force to replace its project files",
            out.display()
        ))
    );
    assert_eq!(
        fs::read_to_string(out.join("alba.toml")).ok().as_deref(),
        Some("name = \"mine\"\n")
    );
    assert_eq!(entries(tmp.path()), vec!["project".to_string()]);
    // With --force the project files are replaced, other files stay.
    let opts = Options {
        force: true,
        ..Options::default()
    };
    let report = alba_import::import(&input, &out, &opts).expect("forced import");
    assert!(report.rungs > 0);
    assert!(
        fs::read_to_string(out.join("alba.toml"))
            .unwrap_or_default()
            .contains("name = \"contacts\"")
    );
    assert_eq!(
        fs::read_to_string(out.join("notes.txt")).ok().as_deref(),
        Some("keep me")
    );
    assert_eq!(entries(&out), vec!["alba.toml", "main.lad", "notes.txt", "tags.csv"]);
    assert_eq!(entries(tmp.path()), vec!["project".to_string()]);
}

#[test]
fn an_empty_folder_is_used() {
    let tmp = tempfile::tempdir().expect("tmp");
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/ldmicro/contacts.ld");
    let out = tmp.path().join("project");
    fs::create_dir(&out).expect("mkdir");
    alba_import::import(&input, &out, &Options::default()).expect("import");
    assert_eq!(entries(&out), vec!["alba.toml", "main.lad", "tags.csv"]);
}

#[test]
fn huge_files_are_refused_before_reading() {
    let tmp = tempfile::tempdir().expect("tmp");
    let input = tmp.path().join("huge.ld");
    let f = fs::File::create(&input).expect("create");
    f.set_len(alba_import::MAX_INPUT_BYTES + 1).expect("sparse file");
    let out = tmp.path().join("project");
    let e = alba_import::import(&input, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        e,
        Some(format!(
            "{} is 33554433 bytes; files above 32 MiB are refused",
            input.display()
        ))
    );
    assert!(!out.exists());
}

/// A PLCopen LD body that is one chain of `n` contacts into a coil.
fn chain(n: usize) -> String {
    let mut s = String::from(PLC_HEAD);
    s.push_str("        <leftPowerRail localId=\"1\"/>\n");
    for i in 0..n {
        s.push_str(&format!(
            "        <contact localId=\"{}\"><connectionPointIn><connection refLocalId=\"{}\"/></connectionPointIn><variable>a</variable></contact>\n",
            i + 2,
            i + 1
        ));
    }
    s.push_str(&format!(
        "        <coil localId=\"{}\"><connectionPointIn><connection refLocalId=\"{}\"/></connectionPointIn><variable>a</variable></coil>\n",
        n + 2,
        n + 1
    ));
    s.push_str(PLC_TAIL);
    s
}

#[test]
fn long_connection_chains_convert_or_are_refused_without_overflow() {
    let ok = alba_import::convert(Path::new("chain.xml"), &chain(1990), &Options::default());
    let (p, _) = ok.expect("a chain of 1990 contacts converts");
    assert!(p.programs[0].text.contains("XIC(a)XIC(a)"));
    let (p, report) =
        alba_import::convert(Path::new("chain.xml"), &chain(5000), &Options::default()).expect("converts");
    assert!(p.programs[0].text.contains("REFUSED"));
    let refused: Vec<String> = report.entries.iter().map(|e| e.to_string()).collect();
    assert!(
        refused
            .iter()
            .any(|e| e.contains("refused: <coil> `a`: connections chained deeper than 2000 elements")),
        "{refused:?}"
    );
}

#[test]
fn deeply_shared_branches_stay_small() {
    // 60 diamonds in a row: each level's condition appears twice in the
    // next, so written out inline it would double 60 times.
    let mut s = String::from(PLC_HEAD);
    s.push_str("        <leftPowerRail localId=\"1\"/>\n");
    let mut prev = 1;
    let contact = |id: usize, from: &[usize], neg: bool| {
        let c: String = from
            .iter()
            .map(|f| format!("<connection refLocalId=\"{f}\"/>"))
            .collect();
        format!(
            "        <contact localId=\"{id}\" negated=\"{neg}\"><connectionPointIn>{c}</connectionPointIn><variable>a</variable></contact>\n"
        )
    };
    for i in 0..60 {
        let (a, b, c) = (3 * i + 2, 3 * i + 3, 3 * i + 4);
        s.push_str(&contact(a, &[prev], false));
        s.push_str(&contact(b, &[prev], true));
        s.push_str(&contact(c, &[a, b], false));
        prev = c;
    }
    s.push_str(&format!(
        "        <coil localId=\"999\"><connectionPointIn><connection refLocalId=\"{prev}\"/></connectionPointIn><variable>a</variable></coil>\n"
    ));
    s.push_str(PLC_TAIL);
    let (p, _) = alba_import::convert(Path::new("diamonds.xml"), &s, &Options::default()).expect("converts");
    assert!(p.programs[0].text.len() < 200_000, "{} bytes", p.programs[0].text.len());
    assert!(p.tags.iter().any(|t| t.description == "alba import: a long condition"));
}

#[test]
fn hostile_l5x_rungs_are_refused_not_crashed() {
    let rung = |text: &str| {
        format!(
            "<RSLogix5000Content SchemaRevision=\"1.0\"><Controller Name=\"C\"><Tags>\
             <Tag Name=\"a\" TagType=\"Base\" DataType=\"BOOL\"/><Tag Name=\"x\" TagType=\"Base\" DataType=\"DINT\"/></Tags>\
             <Programs><Program Name=\"P\" MainRoutineName=\"R\"><Routines><Routine Name=\"R\" Type=\"RLL\"><RLLContent>\
             <Rung Number=\"0\" Type=\"N\"><Text><![CDATA[{text}]]></Text></Rung>\
             <Rung Number=\"1\" Type=\"N\"><Text><![CDATA[XIC(a)OTE(a);]]></Text></Rung>\
             </RLLContent></Routine></Routines></Program></Programs></Controller></RSLogix5000Content>"
        )
    };
    let deep_branch = format!("{}XIC(a){}OTE(a);", "[".repeat(20_000), "]".repeat(20_000));
    let deep_cpt = format!("CPT(x,{}1{});", "(".repeat(20_000), ")".repeat(20_000));
    let long = format!("{}OTE(a);", "XIC(a)".repeat(100_000));
    for (what, text) in [("branches", deep_branch), ("cpt", deep_cpt), ("long", long)] {
        let (p, report) = alba_import::convert(Path::new("h.L5X"), &rung(&text), &Options::default())
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let prog = &p.programs[0].text;
        assert!(prog.ends_with("XIC(a)OTE(a);\n"), "{what}: the good rung is kept");
        if what != "long" {
            assert!(prog.starts_with("// REFUSED"), "{what}");
            assert_eq!(report.count(alba_import::Kind::Refused), 1, "{what}");
        }
    }
}

#[test]
fn an_l5x_routine_export_imports_its_routine() {
    let text = r#"<?xml version="1.0" encoding="UTF-8" standalone="yes"?>
<RSLogix5000Content SchemaRevision="1.0" SoftwareRevision="33.00" TargetName="Seal" TargetType="Routine" TargetSubType="RLL" ContainsContext="true">
<Controller Use="Context" Name="C">
<Tags Use="Context">
<Tag Name="Start" TagType="Base" DataType="BOOL"/>
<Tag Name="Motor" TagType="Base" DataType="BOOL"/>
</Tags>
<Programs Use="Context">
<Program Use="Context" Name="MainProgram">
<Routines Use="Context">
<Routine Use="Target" Name="Seal" Type="RLL">
<RLLContent>
<Rung Number="0" Type="N">
<Text><![CDATA[[XIC(Start),XIC(Motor)]OTE(Motor);]]></Text>
</Rung>
</RLLContent>
</Routine>
</Routines>
</Program>
</Programs>
</Controller>
</RSLogix5000Content>
"#;
    let (p, report) = alba_import::convert(Path::new("Seal.L5X"), text, &Options::default()).expect("converts");
    assert_eq!(p.programs[0].text, "[XIC(Start),XIC(Motor)]OTE(Motor);\n");
    assert_eq!(report.count(alba_import::Kind::Refused), 0, "{}", report.render());
}

#[test]
fn cyclic_l5x_aliases_are_refused() {
    let text = r#"<RSLogix5000Content SchemaRevision="1.0"><Controller Name="C"><Tags>
<Tag Name="A" TagType="Alias" AliasFor="B"/>
<Tag Name="B" TagType="Alias" AliasFor="A"/>
<Tag Name="Q" TagType="Base" DataType="BOOL"/>
</Tags><Programs><Program Name="P" MainRoutineName="R"><Routines><Routine Name="R" Type="RLL"><RLLContent>
<Rung Number="0" Type="N"><Text><![CDATA[XIC(A)OTE(Q);]]></Text></Rung>
</RLLContent></Routine></Routines></Program></Programs></Controller></RSLogix5000Content>"#;
    let (p, report) = alba_import::convert(Path::new("c.L5X"), text, &Options::default()).expect("converts");
    assert!(p.programs[0].text.starts_with("// REFUSED"));
    assert!(
        report
            .render()
            .contains("c.L5X:6:27: refused: rung 0 of `P`/`R`: `B`: aliases chained more than 16 deep (or in a cycle)"),
        "{}",
        report.render()
    );
}

/// A small AuroraLD folder: `XIC(a)OTE(b)` on tags a (DI:1/0) and b (DO:2/0).
fn aurora() -> alba_import::aurora::Folder {
    let mut counters = vec!["0"; 40];
    counters[0] = "1";
    counters[1] = "1";
    counters[4] = "1";
    let mut instr: Vec<&str> = counters;
    instr.extend(["0", "210.0"]);
    instr.extend([
        "a", "XIC", "0", "255", "210.0", "0", "false", "0", "0", "70", "true", "false",
    ]);
    instr.extend([
        "b", "OTE", "0", "1025", "210.0", "0", "false", "0", "1", "70", "true", "false",
    ]);
    alba_import::aurora::Folder {
        main: Some("//PROJECT NAME\nsmall\n//TIME AND DATE\n9:5:1\n1/2/2022\n//RAIL\n1237.0\n".into()),
        tags: Some("1\na\nBool\nDI:1/0\n0\n\nb\nBool\nDO:2/0\n0\n\n".into()),
        instructions: Some(instr.join("\n") + "\n"),
        trends: None,
        screens: Vec::new(),
    }
}

/// `aurora()` with line `line` (from 1) of `file` replaced by `text`.
fn aurora_with(file: &str, line: usize, text: &str) -> alba_import::aurora::Folder {
    let mut f = aurora();
    let slot = match file {
        "main.ara" => &mut f.main,
        "tags.pl" => &mut f.tags,
        _ => &mut f.instructions,
    };
    let mut lines: Vec<String> = slot.as_deref().unwrap_or("").lines().map(str::to_string).collect();
    lines[line - 1] = text.to_string();
    *slot = Some(lines.join("\n") + "\n");
    f
}

fn aurora_err(f: &alba_import::aurora::Folder) -> String {
    match alba_import::convert_folder("small", f, &Options::default()) {
        Ok((p, _)) => panic!("accepted:\n{}", p.programs[0].text),
        Err(e) => e.to_string(),
    }
}

/// The report of an AuroraLD folder that converts.
fn aurora_report(f: &alba_import::aurora::Folder) -> (String, String) {
    let (p, r) = alba_import::convert_folder("small", f, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    (p.programs[0].text.clone(), r.render())
}

#[test]
fn the_small_aurora_folder_converts() {
    let (text, report) = aurora_report(&aurora());
    assert_eq!(text, "XIC(a)OTE(b);\n", "{report}");
}

#[test]
fn malformed_aurora_folders_give_located_errors() {
    let mut no_tags = aurora();
    no_tags.tags = None;
    let mut empty_instr = aurora();
    empty_instr.instructions = Some(String::new());
    let mut garbage = aurora();
    garbage.main = Some("\u{0}\u{1}PK\u{3}\u{4}binary".into());
    let mut short = aurora();
    short.instructions = Some(
        short
            .instructions
            .unwrap_or_default()
            .replace("1025\n210.0\n0\nfalse\n0\n1\n70\ntrue\nfalse\n", ""),
    );
    let mut extra = aurora();
    extra.instructions = Some(extra.instructions.unwrap_or_default() + "stray\n");
    let mut truncated_tags = aurora();
    truncated_tags.tags = Some("1\na\nBool\nDI:1/0\n0\n\nb\nBool\n".into());
    let cases = [
        aurora_with("main.ara", 1, "PROJECT"),
        garbage,
        aurora_with("main.ara", 3, "//DATE"),
        no_tags,
        aurora_with("tags.pl", 1, "two"),
        aurora_with("tags.pl", 1, "150"),
        truncated_tags,
        empty_instr,
        aurora_with("instructions.pl", 2, "500"),
        aurora_with("instructions.pl", 2, "-1"),
        aurora_with("instructions.pl", 44, "XIO"),
        aurora_with("instructions.pl", 45, "zero"),
        aurora_with("instructions.pl", 42, "NaN"),
        aurora_with("instructions.pl", 49, "maybe"),
        short,
        extra,
    ];
    let got: Vec<String> = cases.iter().map(aurora_err).collect();
    if std::env::var_os("ALBA_BLESS").is_some() {
        for g in &got {
            println!("{g:?},");
        }
    }
    let want = [
        "main.ara:1:1: not an AuroraLD main.ara: the first line is `PROJECT`, not `//PROJECT NAME`",
        "main.ara:1:1: not an AuroraLD main.ara: the first line is `\u{0}\u{1}PK\u{3}\u{4}binary`, not `//PROJECT NAME`",
        "main.ara:3:1: `//DATE` where main.ara has `//TIME AND DATE`",
        "small: tags.pl is missing (every AuroraLD project has one, §3.14)",
        "tags.pl:1:1: `two` is not an integer: it should be `ptag_counter`, the row of the last tag (−1 for none)",
        "tags.pl:1:1: 151 tags: AuroraLD's table holds at most 100 (rows 0 to 99)",
        "tags.pl:8:1: tags.pl ends here: the `address` of tag row 1 is missing",
        "instructions.pl:1:1: instructions.pl ends here: the number of rung instructions (`rung_counter`) is missing",
        "instructions.pl:2:1: 500 XIC: AuroraLD holds 0 to 200 of each instruction (its arrays of 200, Fig. 67)",
        "instructions.pl:2:1: -1 XIC: AuroraLD holds 0 to 200 of each instruction (its arrays of 200, Fig. 67)",
        "instructions.pl:44:1: `XIO` where the `type` of XIC 0 should be `XIC`: the counters at the top of instructions.pl do not match the attributes that follow",
        "instructions.pl:45:1: `zero` is not an integer: it should be the `num` of XIC 0",
        "instructions.pl:42:1: `NaN` is not a number: it should be the `y` of RUNG 0",
        "instructions.pl:49:1: `maybe` is not `true` or `false`: it should be the `state` of XIC 0",
        "instructions.pl:57:1: instructions.pl ends here: the `x` of OTE 0 is missing",
        "instructions.pl:67:1: `stray` follows the attributes of the last instruction: instructions.pl has more lines than its counters announce",
    ];
    assert_eq!(got.len(), want.len(), "{got:#?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g, w);
    }
}

#[test]
fn hostile_aurora_rungs_are_refused_with_their_place() {
    // A second branch nested in the first: the rung is refused.
    let mut f = aurora();
    let mut instr: Vec<String> = f.instructions.unwrap_or_default().lines().map(str::to_string).collect();
    instr[3] = "2".into(); // two BSTs
    let bst = |x: &str, ax: &str| ["BST", "0", x, "210.0", ax, "50", "0"].map(String::from);
    // BSTs come after XIO's (none) and before OTE's attributes: after XIC's 12 lines.
    let at = 40 + 2 + 12;
    for (k, b) in [bst("255", "280"), bst("325", "70")].into_iter().enumerate() {
        for (j, v) in b.into_iter().enumerate() {
            instr.insert(at + 7 * k + j, v);
        }
    }
    f.instructions = Some(instr.join("\n") + "\n");
    let (text, report) = aurora_report(&f);
    assert!(
        text.starts_with("// REFUSED by alba import: rung 0: branches overlap or nest"),
        "{text}"
    );
    assert!(
        report.contains("instructions.pl:41:1: refused: rung 0: branches overlap or nest (x 255–535 and 325–395)"),
        "{report}"
    );

    // An output among the conditions, an unknown tag, an instruction of no rung.
    for (line, value, want) in [
        (
            58,
            "300",
            "instructions.pl:55:1: refused: rung 0: OTE 0 at x = 300 stands among the conditions (Saving) (Fig. 60); left out",
        ),
        (
            43,
            "ghost",
            "instructions.pl:43:1: refused: rung 0: XIC 0: `ghost` is not a tag of tags.pl; left out",
        ),
        (
            50,
            "3",
            "instructions.pl:43:1: refused: XIC 0: it belongs to rung 3, and there are 1 rungs; left out",
        ),
    ] {
        let (_, report) = aurora_report(&aurora_with("instructions.pl", line, value));
        assert!(report.contains(want), "{want}\n{report}");
    }

    // A screen that does not parse is left out; the ladder is imported.
    let mut f = aurora();
    f.screens.push(("bad.pcs".into(), "1\n2\nthree\n".into()));
    let (text, report) = aurora_report(&f);
    assert_eq!(text, "XIC(a)OTE(b);\n");
    assert!(
        report.contains("bad.pcs:3:1: refused: screen bad.pcs not imported: `three` is not an integer: it should be the number of HMI_OUT elements"),
        "{report}"
    );
}

#[test]
fn aurora_folders_read_from_disk_keep_the_limits() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("proj");
    fs::create_dir(&dir).expect("mkdir");
    let out = tmp.path().join("out");
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        e,
        Some(format!(
            "{} is not an AuroraLD project folder: it has no main.ara",
            dir.display()
        ))
    );
    let f = aurora();
    fs::write(dir.join("main.ara"), f.main.unwrap_or_default()).expect("write");
    fs::write(dir.join("tags.pl"), f.tags.unwrap_or_default()).expect("write");
    let big = fs::File::create(dir.join("instructions.pl")).expect("create");
    big.set_len(alba_import::MAX_INPUT_BYTES + 1).expect("sparse");
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        e,
        Some(format!(
            "{} is 33554433 bytes; files above 32 MiB are refused",
            dir.join("instructions.pl").display()
        ))
    );
    // A folder is only read as AuroraLD.
    let opts = Options {
        format: Some(Format::L5x),
        ..Options::default()
    };
    let e = alba_import::import(&dir, &out, &opts).err().map(|e| e.to_string());
    assert_eq!(
        e,
        Some(format!(
            "{} is a folder: only AuroraLD projects (--format aurora) are folders, not l5x",
            dir.display()
        ))
    );
    // Bad tags: nothing is written.
    fs::write(dir.join("instructions.pl"), f.instructions.unwrap_or_default()).expect("write");
    fs::write(dir.join("tags.pl"), "1\na\n").expect("write");
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert_eq!(
        e.as_deref(),
        Some("tags.pl:2:1: tags.pl ends here: the `variable` of tag row 0 is missing")
    );
    assert_eq!(entries(tmp.path()), vec!["proj".to_string()]);
    // The folder, or its main.ara, imports.
    fs::write(dir.join("tags.pl"), aurora().tags.unwrap_or_default()).expect("write");
    alba_import::import(&dir.join("main.ara"), &out, &Options::default()).expect("import");
    assert_eq!(entries(&out), vec!["alba.toml", "main.lad", "tags.csv"]);
}

/// Issue 31: every screen was read (64 × 32 MiB: 2 GB) before main.ara was
/// looked at. main.ara is now checked first, and screens and the folder are
/// bounded on their sizes before anything else is read (the big files are
/// sparse: they cost no disk, and reading one would be seen in the error).
#[test]
fn an_aurora_folder_is_checked_before_its_screens_are_read() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("proj");
    fs::create_dir(&dir).expect("mkdir");
    let out = tmp.path().join("out");
    let sparse = |name: &str, len: u64| {
        fs::File::create(dir.join(name))
            .expect("create")
            .set_len(len)
            .expect("sparse");
    };
    fs::write(dir.join("main.ara"), "not a main.ara\n").expect("write");
    for i in 0..64 {
        sparse(&format!("s{i:02}.pcs"), alba_import::MAX_INPUT_BYTES + 1);
    }
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert!(
        e.as_deref().is_some_and(|e| e.contains("not an AuroraLD main.ara")),
        "{e:?}"
    );
    // A good main.ara: a screen past its bound is refused by its size.
    let f = aurora();
    fs::write(dir.join("main.ara"), f.main.clone().unwrap_or_default()).expect("write");
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert!(
        e.as_deref()
            .is_some_and(|e| e.contains("screens above 1024 KiB are refused")),
        "{e:?}"
    );
    // Screens each within their bound, the folder past its own.
    for i in 0..64 {
        sparse(&format!("s{i:02}.pcs"), alba_import::aurora::MAX_SCREEN_BYTES);
    }
    sparse("tags.pl", alba_import::MAX_INPUT_BYTES);
    sparse("instructions.pl", alba_import::MAX_INPUT_BYTES);
    let e = alba_import::import(&dir, &out, &Options::default())
        .err()
        .map(|e| e.to_string());
    assert!(
        e.as_deref().is_some_and(|e| e.contains("at most 64 MiB are read")),
        "{e:?}"
    );
    assert!(!out.exists());
}

/// A PLCopen program `seq` with the SFC body `body` and BOOL variables a, b, q.
fn sfc_project(body: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types><pous>
    <pou name="seq" pouType="program">
      <interface><localVars><variable name="a"><type><BOOL/></type></variable><variable name="b"><type><BOOL/></type></variable><variable name="q"><type><BOOL/></type></variable><variable name="n"><type><INT/></type></variable></localVars></interface>
      <actions><action name="Act"><body><IL><xhtml:p>LD TRUE
ST q</xhtml:p></IL></body></action></actions>
      <body><SFC>
{body}
      </SFC></body>
    </pou>
  </pous></types>
</project>
"#
    )
}

fn st(cond: &str) -> String {
    format!("<condition><inline name=\"\"><ST><xhtml:p><![CDATA[{cond}]]></xhtml:p></ST></inline></condition>")
}

#[test]
fn hostile_plcopen_sfc_bodies_are_refused_with_their_place() {
    let step = |id: u32, name: &str, from: &str, initial: bool| {
        format!(
            "<step localId=\"{id}\" name=\"{name}\" initialStep=\"{initial}\"><connectionPointIn>{from}</connectionPointIn></step>"
        )
    };
    let conn = |id: u32| format!("<connection refLocalId=\"{id}\"/>");
    let tr = |id: u32, from: &str, cond: &str| {
        format!("<transition localId=\"{id}\"><connectionPointIn>{from}</connectionPointIn>{cond}</transition>")
    };
    let good = format!(
        "{}\n{}\n{}\n{}",
        step(1, "S0", &conn(4), true),
        tr(2, &conn(1), &st("a")),
        step(3, "S1", &conn(2), false),
        tr(4, &conn(3), &st("NOT a"))
    );
    let (p, _) =
        alba_import::convert(Path::new("seq.xml"), &sfc_project(&good), &Options::default()).expect("converts");
    assert_eq!(
        p.programs[0].text,
        "(* seq: imported from PLCopen TC6 XML by alba import *)\nINITIAL_STEP S0: END_STEP\nSTEP S1: END_STEP\n\
         TRANSITION FROM S0 TO S1 := a; END_TRANSITION\nTRANSITION FROM S1 TO S0 := NOT a; END_TRANSITION\n"
    );
    let cases: Vec<(String, &str)> = vec![
        // A function in a condition, a transition into a transition, a jump
        // to no step, a connector that loops on itself, an action with a body,
        // a timed qualifier without its time, a condition drawn in LD.
        (
            // A function of a step's time: neither the nets' language nor
            // ST (which has no `S0.T`) can say it.
            good.replace("NOT a", "ABS(S0.T) > 2"),
            "`ABS(…)`: functions are not available in Alba's conditions",
        ),
        (
            format!("{good}\n{}", tr(9, &conn(2), &st("b"))),
            "transition 2 of `seq`: it leads to another transition, not to a step",
        ),
        (
            format!(
                "{good}\n{}\n<jumpStep localId=\"8\" targetName=\"Nowhere\"><connectionPointIn>{}</connectionPointIn></jumpStep>",
                tr(7, &conn(3), &st("b")),
                conn(7)
            ),
            "transition 7 of `seq`: it jumps to `Nowhere`, which is not a step of the chart",
        ),
        (
            format!(
                "{good}\n<selectionDivergence localId=\"5\"><connectionPointIn>{}</connectionPointIn></selectionDivergence>\n{}",
                conn(5),
                tr(6, &conn(5), &st("b"))
            ),
            "transition 6 of `seq`: connectors chained deeper than 1000",
        ),
        (
            format!(
                "{good}\n<actionBlock localId=\"5\"><connectionPointIn>{}</connectionPointIn><action localId=\"0\" qualifier=\"N\"><reference name=\"Act\"/></action><action localId=\"0\" qualifier=\"L\"><reference name=\"q\"/></action></actionBlock>",
                conn(3)
            ),
            "an action of step `S1`: `Act` is an action whose body is not ST",
        ),
        (
            format!(
                "{good}\n<actionBlock localId=\"5\"><connectionPointIn>{}</connectionPointIn><action localId=\"0\" qualifier=\"L\"><reference name=\"q\"/></action></actionBlock>",
                conn(3)
            ),
            "an action of step `S1`: the qualifier L needs a duration; left out",
        ),
        (
            good.replace(
                &st("NOT a"),
                &format!(
                    "<condition><connectionPointIn>{}</connectionPointIn></condition>",
                    conn(1)
                ),
            ),
            "its condition is drawn in LD/FBD; only a variable or an ST expression is converted",
        ),
    ];
    for (body, want) in &cases {
        let (_, report) =
            alba_import::convert(Path::new("seq.xml"), &sfc_project(body), &Options::default()).expect("converts");
        let text = report.render();
        assert!(text.contains(want), "{want}\n{text}");
    }
    // A function of variables only is kept in ST: `: … END_TRANSITION`.
    let (project, _) = alba_import::convert(
        Path::new("seq.xml"),
        &sfc_project(&good.replace("NOT a", "ABS(n) > 2")),
        &Options::default(),
    )
    .expect("converts");
    assert!(
        project.programs[0]
            .text
            .contains("FROM S1 TO S0 : ABS(n) > 2 END_TRANSITION"),
        "{}",
        project.programs[0].text
    );
    // Two initial steps: the chart is refused, and with it the only program.
    let two = good.replace("initialStep=\"false\"", "initialStep=\"true\"");
    assert_eq!(
        err("seq.xml", None, &sfc_project(&two)),
        "seq.xml:2:1: nothing to import: Alba imports LD, SFC and ST bodies of programs, and its programs are `seq` (SFC)"
    );
}

#[test]
fn plcopen_st_refusals_are_located_in_the_xml() {
    let xml = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types><pous>
    <pou name="bad" pouType="program">
<interface><localVars><variable name="s"><type><derived name="PID"/></type></variable><variable name="n"><type><INT/></type></variable></localVars></interface>
      <body><ST><xhtml:p><![CDATA[n := n + 1;
n := * 2;
]]></xhtml:p></ST></body>
    </pou>
    <pou name="good" pouType="program">
      <interface><localVars><variable name="m"><type><INT/></type></variable></localVars></interface>
      <body><ST><xhtml:p><![CDATA[m := m + 1;]]></xhtml:p></ST></body>
    </pou>
    <pou name="fb" pouType="functionBlock">
      <body><ST><xhtml:p><![CDATA[;]]></xhtml:p></ST></body>
    </pou>
  </pous></types>
</project>
"#;
    let (project, report) = alba_import::convert(Path::new("st.xml"), xml, &Options::default()).expect("converts");
    let text = report.render();
    // The variable of OpenPLC's PID at its <variable>, the syntax error at the `*`.
    assert!(
        text.contains("5:23: refused: variable `s` of `bad`: its type `PID` does not run"),
        "{text}"
    );
    assert!(text.contains("7:6: refused: ST of `bad`: E220"), "{text}");
    assert!(text.contains("converted: ST body of function block `fb`"), "{text}");
    // `bad` is not written; `good` is, after the function block.
    let files: Vec<&str> = project.programs.iter().map(|p| p.file.as_str()).collect();
    assert_eq!(files, ["fb.st", "good.st"]);
    assert!(project.programs[1].text.contains("m := m + 1;"));
    // Only refused ST programs: nothing to import, and why.
    let only_bad = xml.replace(
        "pouType=\"program\">\n      <interface><localVars><variable name=\"m\"",
        "pouType=\"functionBlock\">\n      <interface><localVars><variable name=\"m\"",
    );
    assert_eq!(
        err("st.xml", None, &only_bad),
        "st.xml:2:1: nothing to import: Alba imports LD, SFC and ST bodies of programs, and its programs are `bad` (ST, refused at 5:23: variable `s` of `bad`: its type `PID` does not run in Alba's ST yet (docs/st.md))"
    );
}

#[test]
fn plcopen_st_program_that_does_not_check_is_left_out_with_its_line() {
    let xml = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types><pous>
    <pou name="bad" pouType="program">
      <interface><localVars><variable name="n"><type><INT/></type></variable></localVars></interface>
      <body><ST><xhtml:p><![CDATA[n := n + 1;
IF n > 3 THEN
  n := TRUE;
END_IF;]]></xhtml:p></ST></body>
    </pou>
    <pou name="good" pouType="program">
      <interface><localVars><variable name="m"><type><INT/></type></variable></localVars></interface>
      <body><ST><xhtml:p><![CDATA[m := m + 1;]]></xhtml:p></ST></body>
    </pou>
  </pous></types>
</project>
"#;
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join("st.xml");
    std::fs::write(&file, xml).expect("write");
    let out = tmp.path().join("p");
    let report = alba_import::import(&file, &out, &Options::default()).expect("imports");
    let text = report.render();
    // The type error at its line in the XML (line 8: `n := TRUE;`), and the
    // whole program left out rather than that line alone.
    assert!(text.contains("8:1: refused: `bad.st`: error[E221]"), "{text}");
    assert!(
        text.contains("refused: `bad.st` does not check in Alba; left out"),
        "{text}"
    );
    assert!(!out.join("bad.st").exists());
    assert!(out.join("good.st").exists());
}

#[test]
fn ironplc_st_program_whose_fb_call_does_not_check_leaves_nothing_to_import() {
    // IronPLC's test project (it imports: tests/scenarios.rs) with Main's
    // variable made an INT: the program converts, but calling an INT does
    // not check, so it is left out; the function block left alone runs
    // nothing, so the import is refused, naming the place (line 45, the
    // column after `<xhtml …>`).
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen/ironplc-simple.xml");
    let text = fs::read_to_string(&f).expect("fixture");
    let t = text.replace("<derived name=\"Counter\"/>", "<INT/>");
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join("simple.xml");
    fs::write(&file, &t).expect("write");
    let out = tmp.path().join("p");
    let e = alba_import::import(&file, &out, &Options::default())
        .expect_err("nothing left")
        .to_string();
    assert!(
        e.starts_with("simple.xml:45:57:")
            && e.contains("nothing left to import: `Main.st` does not check in Alba (error[E2"),
        "{e}"
    );
    assert!(!out.exists());
}

#[test]
fn plcopen_sfc_st_action_with_a_syntax_error_is_refused_at_its_line() {
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen/sfc-st-actions.xml");
    let good = fs::read_to_string(&f).expect("fixture");
    // The second line of action Fill (line 21 of the file) loses its `:=`.
    let bad = good.replace("level := level + 1;]]>", "level level + 1;]]>");
    assert_ne!(bad, good);
    let (project, report) = alba_import::convert(Path::new("sfc.xml"), &bad, &Options::default()).expect("converts");
    let r = report.render();
    assert!(r.contains("21:1: refused: ST actions of `tank`: E220"), "{r}");
    assert!(r.contains("refused: the ST actions of `tank` are not converted"), "{r}");
    let files: Vec<&str> = project.programs.iter().map(|p| p.file.as_str()).collect();
    assert_eq!(files, ["tank.sfc"]);
}

#[test]
fn openplc_pragmas_are_refused_each_at_its_place() {
    // The OpenPLC Editor's example Random_Generator_Pragma: its ST function
    // block calls C through three pragmas (`{SetFbVar(OUT,rand())}` …); each
    // is one refusal at its line and column, not a cascade of syntax errors.
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plcopen/openplc-random-pragma.xml");
    let text = fs::read_to_string(&f).expect("fixture");
    let (_, report) = alba_import::convert(Path::new("random.xml"), &text, &Options::default()).expect("converts");
    let r = report.render();
    let pragma = "refused: ST of `rand_generator`: E223: a pragma `{…}` is not run: OpenPLC and Beremiz paste its text into their generated C code, and Alba runs no C code";
    for at in ["288:1", "295:3", "304:3"] {
        assert!(r.contains(&format!("random.xml:{at}: {pragma}")), "{at} in\n{r}");
    }
    assert!(!r.contains("E220"), "{r}");
}

#[test]
fn an_st_program_that_does_not_parse_is_named_with_its_first_error() {
    // As a public OpenPLC project has it: a variable table pasted as the
    // program's ST body. Nothing is left to import, and the error says
    // where the body went wrong rather than only that it is ST.
    let text = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types>
    <pous>
      <pou name="main" pouType="program">
        <interface><localVars><variable name="Temperature"><type><INT/></type></variable></localVars></interface>
        <body>
          <ST>
            <xhtml:p><![CDATA[Temperature VAR INT %MW0 22]]></xhtml:p>
          </ST>
        </body>
      </pou>
    </pous>
  </types>
</project>
"#;
    let e = alba_import::convert(Path::new("pasted.xml"), text, &Options::default())
        .expect_err("nothing to import")
        .to_string();
    assert!(e.contains("its programs are `main` (ST, refused at 9:"), "{e}");
    assert!(e.contains("E220"), "{e}");
}

#[test]
fn an_external_variable_the_configuration_lacks_is_one_tag_for_every_program() {
    // As a public OpenPLC project has it: two programs name `shared` in
    // their externalVars, which the configuration does not declare. It is
    // one tag (not one per program, refused as declared twice).
    let program = |name: &str, body: &str| {
        format!(
            r#"<pou name="{name}" pouType="program">
        <interface><externalVars><variable name="shared"><type><INT/></type></variable></externalVars></interface>
        <body><ST><xhtml:p><![CDATA[{body}]]></xhtml:p></ST></body>
      </pou>"#
        )
    };
    let text = format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types>
    <pous>
      {}
      {}
    </pous>
  </types>
</project>
"#,
        program("writer", "shared := 5;"),
        program("reader", "shared := shared + 1;")
    );
    let (p, report) = alba_import::convert(Path::new("ext.xml"), &text, &Options::default()).expect("converts");
    let r = report.render();
    assert!(!r.contains("declared twice") && !r.contains("refused"), "{r}");
    let shared: Vec<&str> = p
        .tags
        .iter()
        .map(|t| t.name.as_str())
        .filter(|n| n.eq_ignore_ascii_case("shared"))
        .collect();
    assert_eq!(shared, ["shared"], "{r}");
    let files: Vec<&str> = p.programs.iter().map(|p| p.file.as_str()).collect();
    assert_eq!(files, ["writer.st", "reader.st"]);
}

#[test]
fn sfc_steps_without_a_local_id_keep_their_names() {
    // As IronPLC's grammar test file writes them (`<step name="Init"
    // initialStep="true">`, no localId): the steps are named, not empty.
    let text = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0200">
  <types><pous>
    <pou name="Chart" pouType="program">
      <body><SFC>
        <step name="Init" initialStep="true"><connectionPointOut/></step>
        <step name="Step1" initialStep="false"><connectionPointIn/></step>
      </SFC></body>
    </pou>
  </pous></types>
</project>
"#;
    let (p, report) = alba_import::convert(Path::new("sfc.xml"), text, &Options::default()).expect("converts");
    let sfc = &p.programs[0].text;
    assert!(
        sfc.contains("INITIAL_STEP Init: END_STEP") && sfc.contains("STEP Step1: END_STEP"),
        "{sfc}\n{}",
        report.render()
    );
}
