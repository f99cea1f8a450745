//! Bugs that files written by the real tools revealed (the fixtures of
//! tests/fixtures/*/README.md), each pinned by the smallest input that shows it.

use alba_import::{Format, Options};
use std::path::Path;

/// Converts `text` as `format`: the project and the rendered report.
fn project(name: &str, format: Format, text: &str) -> (alba_import::Project, String) {
    let opts = Options {
        format: Some(format),
        board: None,
        force: false,
    };
    let (project, report) =
        alba_import::convert(Path::new(name), text, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    (project, report.render())
}

/// [`project`]: the programs' text and the report.
fn convert(name: &str, format: Format, text: &str) -> (String, String) {
    let (project, report) = project(name, format, text);
    (project.programs.iter().map(|p| p.text.clone()).collect(), report)
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

/// An L5X controller with `datatypes`, controller `tags` and one RLL routine
/// of `rungs`.
fn l5x(datatypes: &str, tags: &str, rungs: &[&str]) -> String {
    let rungs: String = rungs
        .iter()
        .enumerate()
        .map(|(n, r)| format!("<Rung Number=\"{n}\" Type=\"N\"><Text><![CDATA[{r}]]></Text></Rung>\n"))
        .collect();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8" standalone="yes"?>
<RSLogix5000Content SchemaRevision="1.0" SoftwareRevision="20.01" TargetName="C" TargetType="Controller">
<Controller Name="C">
<DataTypes>
{datatypes}
</DataTypes>
<Tags>
{tags}
</Tags>
<Programs><Program Name="P" MainRoutineName="R"><Routines><Routine Name="R" Type="RLL"><RLLContent>
{rungs}</RLLContent></Routine></Routines></Program></Programs>
</Controller>
</RSLogix5000Content>
"#
    )
}

fn tag(name: &str, ty: &str, radix: &str, value: &str) -> String {
    format!(
        "<Tag Name=\"{name}\" TagType=\"Base\" DataType=\"{ty}\" Radix=\"{radix}\"><Data Format=\"Decorated\"><DataValue DataType=\"{ty}\" Radix=\"{radix}\" Value=\"{value}\"/></Data></Tag>"
    )
}

/// Exports without L5K data (l5x2c's, `ExportOptions="References
/// DecoratedData …"`) hold values only in the tag's radix: they were read
/// as decimal, and a value in another radix was dropped without a word.
#[test]
fn decorated_values_are_read_in_their_radix() {
    let tags = [
        tag("h", "SINT", "Hex", "16#ff"),
        tag("o", "INT", "Octal", "8#000_017"),
        tag("b", "DINT", "Binary", "2#0000_0000_0000_0000_0000_0000_0000_0101"),
        tag("n", "DINT", "Hex", "16#ffff_fffe"),
        tag("a", "DINT", "ASCII", "'AB$0A'"),
        tag("l", "INT", "ASCII", "'$l$$'"),
        tag("w", "INT", "ASCII", "'$+1'"),
        tag("x", "REAL", "Exponential", "1.50000000e+002"),
        tag("q", "REAL", "Float", "1.$QNAN"),
        tag("z", "LINT", "Hex", "16#8000_0000_0000_0000"),
    ]
    .concat();
    let (project, report) = project("radix.L5X", Format::L5x, &l5x("", &tags, &["NOP();"]));
    let initial: Vec<(String, String)> = project
        .tags
        .iter()
        .map(|t| (t.name.clone(), t.initial.clone()))
        .collect();
    let want = [
        ("h", "-1"),
        ("o", "15"),
        ("b", "5"),
        ("n", "-2"),
        ("a", "4276746"),
        ("l", "2596"),
        ("w", ""),
        ("x", "150.0"),
        ("q", ""),
        ("z", "-9223372036854775808"),
    ];
    assert_eq!(initial, want.map(|(a, b)| (a.to_string(), b.to_string())), "{report}");
    assert!(
        report.contains("approximated: tag `q`: its value `1.$QNAN` is not a REAL; it starts at 0"),
        "{report}"
    );
}

/// A rung export (Studio 5000's "Export Rung…", L5Sharp's
/// `Rung0_from_Main.L5X`): the rungs are the `Use="Target"` ones of a
/// context routine that has no `Type`; the import said there was nothing.
#[test]
fn an_l5x_rung_export_imports_its_rungs() {
    let text = r#"<RSLogix5000Content SchemaRevision="1.0" TargetType="Rung" TargetCount="1" ContainsContext="true">
<Controller Use="Context" Name="C"><Programs Use="Context"><Program Use="Context" Name="P">
<Tags Use="Context"><Tag Name="a" TagType="Base" DataType="BOOL"/><Tag Name="n" TagType="Base" DataType="DINT"/></Tags>
<Routines Use="Context"><Routine Use="Context" Name="Main"><RLLContent Use="Context">
<Rung Use="Target" Number="4" Type="N"><Text><![CDATA[XIC(a)MOV(7,n);]]></Text></Rung>
</RLLContent></Routine></Routines></Program></Programs></Controller></RSLogix5000Content>"#;
    let (text, report) = convert("rung.L5X", Format::L5x, text);
    assert_eq!(text, "XIC(a)MOV(7,n);\n", "{report}");
}

/// `OTE(SimpleDint.[Tag.Member])` (L5Sharp's Test.L5X): an indirect bit
/// address passed the renaming and failed Alba's check with a garbled name
/// (`unknown tag SimpleDint.[TestSimpleTag`).
#[test]
fn an_indirect_address_is_refused_by_name() {
    let tags = [tag("d", "DINT", "Decimal", "0"), tag("i", "DINT", "Decimal", "3")].concat();
    let (_, report) = convert("ind.L5X", Format::L5x, &l5x("", &tags, &["OTE(d.[i]);"]));
    assert!(
        report
            .contains("refused: rung 0 of `P`/`R`: `d.[i]`: an indirect address or an array member (Alba has neither)"),
        "{report}"
    );
}

/// l5x2c's `ex1.L5X` has `XIC(A)[,XIO(C)]OTE(D)` and `XIC(A)[,]OTE(D)`:
/// Studio 5000 draws an empty leg as a wire, Alba's ladder has no empty leg.
#[test]
fn empty_branch_legs_are_wires() {
    let tags: String = ["a", "b", "c", "d", "f"]
        .iter()
        .map(|n| format!("<Tag Name=\"{n}\" TagType=\"Base\" DataType=\"BOOL\"/>"))
        .collect();
    let rungs = [
        "XIC(a)[,XIO(b)]OTE(c);",
        "XIC(a)[ , ]OTE(c);",
        "XIC(a)[[,XIC(b)],XIC(d)]OTE(c);",
        "XIC(a)[,OTE(b)];",
        "XIC(a)[,OTE(b),XIC(d)OTE(f)];",
        "XIC(a)[,OTE(b)]OTE(c);",
        "XIC(a)[XIO(b),XIC(d)]OTE(c);",
        // A wire beside outputs inside a leg whose value is read after the
        // outer branch, and one whose value nothing reads.
        "XIC(a)[[,XIC(b)OTE(c)],XIC(d)]OTE(f);",
        "XIC(a)[OTE(b),[,XIC(d)OTE(c)]];",
    ];
    let (text, report) = convert("legs.L5X", Format::L5x, &l5x("", &tags, &rungs));
    assert_eq!(
        text,
        "XIC(a)OTE(c);\nXIC(a)OTE(c);\nXIC(a)OTE(c);\nXIC(a)OTE(b);\nXIC(a)[OTE(b),XIC(d)OTE(f)];\n\
         // REFUSED by alba import: rung 5: XIC(a)[,OTE(b)]OTE(c); (an empty branch leg (a wire) beside outputs, with more instructions after the branch: Alba's ladder has no always-true instruction to stand for it)\n\
         XIC(a)[XIO(b),XIC(d)]OTE(c);\n\
         // REFUSED by alba import: rung 7: XIC(a)[[,XIC(b)OTE(c)],XIC(d)]OTE(f); (an empty branch leg (a wire) beside outputs, with more instructions after the branch: Alba's ladder has no always-true instruction to stand for it)\n\
         XIC(a)[OTE(b),XIC(d)OTE(c)];\n",
        "{report}"
    );
}

/// l5x2c's belt conveyor keeps its failures in the BIT members of a UDT,
/// over a SINT that `MOV(-1, …)` sets at once: the UDT tag was refused, and
/// with it seven of the ten rungs.
#[test]
fn udt_members_become_tags() {
    let types = r#"<DataType Name="Inner" Family="NoFamily" Class="User"><Members>
<Member Name="Delay" DataType="TIMER" Dimension="0" Hidden="false"/>
<Member Name="Count" DataType="DINT" Dimension="0" Radix="Decimal" Hidden="false"/>
</Members></DataType>
<DataType Name="Outer" Family="NoFamily" Class="User"><Members>
<Member Name="ZZZZZZZZZZOuter0" DataType="SINT" Dimension="0" Radix="Decimal" Hidden="true"/>
<Member Name="Run" DataType="BIT" Dimension="0" Radix="Decimal" Hidden="false" Target="ZZZZZZZZZZOuter0" BitNumber="0"/>
<Member Name="Fault" DataType="BIT" Dimension="0" Radix="Decimal" Hidden="false" Target="ZZZZZZZZZZOuter0" BitNumber="7"/>
<Member Name="In" DataType="Inner" Dimension="0" Hidden="false"/>
<Member Name="Log" DataType="DINT" Dimension="4" Radix="Decimal" Hidden="false"/>
<Member Name="Name" DataType="STRING" Dimension="0" Hidden="false"/>
</Members></DataType>"#;
    let tags = r#"<Tag Name="M" TagType="Base" DataType="Outer"><Data Format="Decorated"><Structure DataType="Outer">
<DataValueMember Name="Run" DataType="BOOL" Value="1"/>
<DataValueMember Name="Fault" DataType="BOOL" Value="0"/>
<StructureMember Name="In" DataType="Inner">
<StructureMember Name="Delay" DataType="TIMER"><DataValueMember Name="PRE" DataType="DINT" Radix="Decimal" Value="1500"/><DataValueMember Name="ACC" DataType="DINT" Radix="Decimal" Value="0"/></StructureMember>
<DataValueMember Name="Count" DataType="DINT" Radix="Hex" Value="16#0000_0010"/>
</StructureMember>
</Structure></Data></Tag>
<Tag Name="RunAlias" TagType="Alias" AliasFor="M.Run"/>"#;
    let rungs = [
        "XIC(RunAlias)TON(M.In.Delay,?,?);",
        "XIC(M.In.Delay.DN)MOV(-1,M.ZZZZZZZZZZOuter0);",
        "XIC(M.Fault)ADD(M.In.Count,1,M.In.Count);",
        "XIC(M.Nope)OTE(M.Run);",
        "MOV(0,M.Log[1]);",
        "COP(M,M,1);",
    ];
    let (project, report) = project("udt.L5X", Format::L5x, &l5x(types, tags, &rungs));
    let text = &project.programs[0].text;
    assert_eq!(
        text.lines().take(3).collect::<Vec<_>>(),
        [
            "XIC(M_Run)TON(M_In_Delay,1500,0);",
            "XIC(M_In_Delay.DN)MOV(-1,%MB0);",
            "XIC(M_Fault)ADD(M_In_Count,1,M_In_Count);"
        ],
        "{report}"
    );
    for want in [
        "refused: member `M.Log`: an array (Alba has no arrays)",
        "refused: member `M.Name`: data type `STRING` is not one Alba has",
        "converted: tag `M` of the user-defined type `Outer`: a tag for each member (`M.Member` is `M_Member`); `M.ZZZZZZZZZZOuter0` is the marker byte %MB0, its BIT members its bits",
        "refused: rung 3 of `P`/`R`: `M.Nope`: `Nope` is not a member",
        "refused: rung 4 of `P`/`R`: `M.Log[1]`: an indirect address or an array member (Alba has neither)",
        "refused: rung 5 of `P`/`R`: `COP` is not an Alba instruction",
    ] {
        assert!(report.contains(want), "{want}\n{report}");
    }
    let rows: Vec<String> = project
        .tags
        .iter()
        .map(|t| format!("{},{},{},{}", t.name, t.ty, t.address, t.initial))
        .collect();
    assert_eq!(
        rows,
        [
            "M_Run,BOOL,%MX0.0,1",
            "M_Fault,BOOL,%MX0.7,",
            "M_In_Delay,TIMER,,",
            "M_In_Count,DINT,,16"
        ]
    );
}
