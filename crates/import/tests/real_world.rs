//! Bugs that files written by the real tools revealed (the fixtures of
//! tests/fixtures/*/README.md), each pinned by the smallest input that shows it.

use alba_import::{Format, Options};
use std::path::Path;

/// Converts `text` as `format`: the programs' text and the rendered report.
fn convert(name: &str, format: Format, text: &str) -> (String, String) {
    let opts = Options {
        format: Some(format),
        board: None,
        force: false,
    };
    let (project, report) =
        alba_import::convert(Path::new(name), text, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    let programs: String = project.programs.iter().map(|p| p.text.clone()).collect();
    (programs, report.render())
}

/// An OpenPLC-style LD body: `vars` declared in the program, `body` inside <LD>.
fn plcopen(product: &str, vars: &str, body: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201">
  <fileHeader companyName="x" productName="{product}" productVersion="1" creationDateTime="2024-01-01T00:00:00"/>
  <types><pous>
    <pou name="main" pouType="program">
      <interface><localVars>
{vars}
      </localVars></interface>
      <body><LD>
        <leftPowerRail localId="1"><position x="0" y="0"/><connectionPointOut formalParameter=""/></leftPowerRail>
{body}
      </LD></body>
    </pou>
  </pous></types>
</project>
"#
    )
}

fn var(name: &str, ty: &str) -> String {
    let t = match ty {
        "TON" | "TOF" | "CTU" => format!("<derived name=\"{ty}\"/>"),
        _ => format!("<{ty}/>"),
    };
    format!("        <variable name=\"{name}\"><type>{t}</type></variable>\n")
}

/// A block `ty` at (x, y) whose inputs are (formal, source localId, source formal).
fn block(id: u32, ty: &str, inst: Option<&str>, y: u32, ins: &[(&str, &str, &str)]) -> String {
    let mut s = format!("<block localId=\"{id}\" typeName=\"{ty}\"");
    if let Some(i) = inst {
        s.push_str(&format!(" instanceName=\"{i}\""));
    }
    s.push_str(&format!("><position x=\"100\" y=\"{y}\"/><inputVariables>"));
    for (formal, from, fp) in ins {
        let fp = if fp.is_empty() {
            String::new()
        } else {
            format!(" formalParameter=\"{fp}\"")
        };
        s.push_str(&format!(
            "<variable formalParameter=\"{formal}\"><connectionPointIn><connection refLocalId=\"{from}\"{fp}/></connectionPointIn></variable>"
        ));
    }
    s.push_str("</inputVariables><outputVariables/></block>\n");
    s
}

fn in_var(id: u32, expr: &str) -> String {
    format!("<inVariable localId=\"{id}\"><position x=\"0\" y=\"0\"/><expression>{expr}</expression></inVariable>\n")
}

fn out_var(id: u32, y: u32, from: u32, fp: &str, expr: &str) -> String {
    format!(
        "<outVariable localId=\"{id}\"><position x=\"300\" y=\"{y}\"/><connectionPointIn><connection refLocalId=\"{from}\" formalParameter=\"{fp}\"/></connectionPointIn><expression>{expr}</expression></outVariable>\n"
    )
}

fn coil(id: u32, y: u32, from: u32, fp: &str, v: &str) -> String {
    format!(
        "<coil localId=\"{id}\"><position x=\"300\" y=\"{y}\"/><connectionPointIn><connection refLocalId=\"{from}\" formalParameter=\"{fp}\"/></connectionPointIn><variable>{v}</variable></coil>\n"
    )
}

/// OpenPLC's Blink: the TOF's EN is the TON's ENO, the TON's EN the rail.
/// ENO of a timer was refused ("ENO outputs are not converted"), which left
/// the TOF out while its Q still drove the light.
#[test]
fn eno_of_a_function_block_is_its_en() {
    let vars = [var("x", "BOOL"), var("T1", "TON"), var("T2", "TOF"), var("y", "BOOL")].concat();
    let body = [
        in_var(10, "T#500ms"),
        block(
            3,
            "TON",
            Some("T1"),
            10,
            &[("EN", "1", ""), ("IN", "1", ""), ("PT", "10", "")],
        ),
        block(
            4,
            "TOF",
            Some("T2"),
            20,
            &[("EN", "3", "ENO"), ("IN", "3", "Q"), ("PT", "10", "")],
        ),
        coil(5, 30, 4, "Q", "y"),
    ]
    .concat();
    let (text, report) = convert("eno.xml", Format::Plcopen, &plcopen("Unnamed", &vars, &body));
    assert_eq!(text, "TON(T1,500,0);\nXIC(T1.DN)TOF(T2,500,0);\nXIC(T2.DN)OTE(y);\n");
    // EN wired to the rail is always true: nothing is approximated.
    assert!(!report.contains("approximated"), "{report}");
    assert!(!report.contains("refused"), "{report}");
}

/// A block refused for any reason refuses the elements that read its
/// outputs; they were converted as if the block had run.
#[test]
fn a_refused_block_refuses_its_readers() {
    let vars = [var("n", "INT"), var("T1", "TON"), var("y", "BOOL")].concat();
    // IN of the TON is an INT: refused.
    let body = [
        in_var(10, "n"),
        in_var(11, "T#1s"),
        block(3, "TON", Some("T1"), 10, &[("IN", "10", ""), ("PT", "11", "")]),
        coil(5, 30, 3, "Q", "y"),
    ]
    .concat();
    let (text, report) = convert("refused.xml", Format::Plcopen, &plcopen("Unnamed", &vars, &body));
    assert!(!text.contains("OTE(y)"), "{text}");
    assert!(
        report.contains(
            "refused: <coil> `y`: it reads block TON `T1`, which was refused (`n`, a number, wired into a power input)"
        ),
        "{report}"
    );
}

/// OpenPLC's Arduino_Cloud example converts an INT with INT_TO_DINT and a
/// timer's ET with TIME_TO_REAL: in seconds for the matiec tools (OpenPLC,
/// Beremiz), in milliseconds for CODESYS.
#[test]
fn type_conversions_convert() {
    let vars = [
        var("i", "INT"),
        var("d", "DINT"),
        var("r", "REAL"),
        var("s", "SINT"),
        var("T1", "TON"),
    ]
    .concat();
    let body = [
        in_var(10, "i"),
        in_var(11, "T#2s"),
        block(3, "TON", Some("T1"), 5, &[("IN", "1", ""), ("PT", "11", "")]),
        block(20, "INT_TO_DINT", None, 10, &[("IN", "10", "")]),
        out_var(21, 10, 20, "OUT", "d"),
        block(22, "TIME_TO_REAL", None, 20, &[("IN", "3", "ET")]),
        out_var(23, 20, 22, "OUT", "r"),
        block(24, "DINT_TO_SINT", None, 30, &[("IN", "20", "OUT")]),
        out_var(25, 30, 24, "OUT", "s"),
        block(26, "INT_TO_TIME", None, 40, &[("IN", "10", "")]),
    ]
    .concat();
    let (text, report) = convert("conv.xml", Format::Plcopen, &plcopen("Unnamed", &vars, &body));
    assert_eq!(
        text,
        "TON(T1,2000,0);\nMOV(i,int_to_dint_out1);\nMOV(int_to_dint_out1,d);\nCPT(r,T1.ACC/1000.0);\nMOV(int_to_dint_out1,s);\n// REFUSED by alba import: block INT_TO_TIME (INT_TO_TIME: conversions to TIME are not converted)\n"
    );
    assert!(
        report.contains("approximated: TIME_TO_REAL: TIME in seconds"),
        "{report}"
    );
    assert!(
        report.contains("approximated: DINT_TO_SINT: out of range, Alba keeps the low bits"),
        "{report}"
    );
    assert!(!report.contains("approximated: INT_TO_DINT"), "{report}");
    let (text, report) = convert("conv.xml", Format::Plcopen, &plcopen("CODESYS", &vars, &body));
    assert!(text.contains("MOV(T1.ACC,r);"), "{text}");
    assert!(
        report.contains("TIME in milliseconds, as CODESYS converts it"),
        "{report}"
    );
}
