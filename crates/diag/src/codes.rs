//! The catalogue of diagnostic codes, with the explanation `alba explain CODE`
//! prints. Ranges by stage: E1xx project files, E2xx ladder syntax,
//! E3xx program checks, E4xx simulation inputs, E5xx firmware, E6xx nets.

use std::fmt;

macro_rules! codes {
    ($($name:ident = $num:literal, $title:literal, $explain:literal;)*) => {
        /// A diagnostic code.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Code { $($name,)* }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$name,)*];

            pub fn number(self) -> u16 {
                match self { $(Code::$name => $num,)* }
            }

            /// A one-line title.
            pub fn title(self) -> &'static str {
                match self { $(Code::$name => $title,)* }
            }

            /// What the code means and how to fix it.
            pub fn explanation(self) -> &'static str {
                match self { $(Code::$name => $explain,)* }
            }
        }
    };
}

codes! {
    Io = 100, "a file could not be read or written",
        "Alba could not open, read or write a file of the project. The message names the file and the operating system's reason.";
    TomlSyntax = 101, "alba.toml is not valid TOML",
        "alba.toml must be a TOML document (https://toml.io). Check quotes, brackets and `key = value` pairs near the place shown.";
    ConfigField = 102, "a setting in alba.toml is missing, unknown or has a bad value",
        "alba.toml needs `name` (a string) and `programs` (a list of program files); `scan_ms` (1..=60000, default 10), `retain_ms` (10..=3600000, default 1000), `description`, a `[history]` table (`enabled`, `retention_days` 0..=36500, `sample_ms`, `deadband` ≥ 0), a `[modbus]` table (`listen` = \"IP:PORT\", `max_connections` 1..=4096, `idle_timeout_s` 0..=86400, `unit_id` 0..=255, `allow` and `read_only` (see E108), and `[modbus.tags]` with addresses like \"hr 8192\"), an `[opcua]` table (`listen` = \"IP:PORT\", needing users (users.toml) beyond loopback; the deprecated `[opcua.users]` with `name = \"<argon2 hash from alba hash-password>\"`, never a plain-text password; `read_only` lists some of them) and a `[board]` table (`model` = uno, nano or mega; `pinmap` = aurora, s7 or openplc) are optional. Unknown keys are refused so that typos do not pass silently.";
    ProgramFile = 103, "a program listed in alba.toml cannot be used",
        "Each entry of `programs` must name an existing file in the project folder, once, with a known extension (`.lad` for ladder).";
    BoardPin = 104, "an I/O address has no pin on the board",
        "With a `[board]` in alba.toml, every I/O channel a tag uses must be wired by the pin map to a pin the board has and that can serve it: a digital pin for DI/DO (not D0/D1, the serial link), an analog pin for AI, a PWM pin for AO. Use another channel, another pin map or board, or list the pins in `[board]` (`di`, `do`, `ai`, `ao`).";
    PlantModel = 105, "a plant model in alba.toml is invalid",
        "Each `[[plant_model]]` table of alba.toml simulates a process on the I/O: `kind` is first_order (gain, tau), second_order (gain, den = [a2, a1, a0]), tank (area, inflow, outflow, sensor, max_level) or motor (r, l, kt, ke, j, b, sensor); `input` and `output` name the actuator signal it reads and the measurement it writes (a tag, member or address; the output must be an input or an internal tag). Optional: input_scale and output_scale = [raw_lo, raw_hi, lo, hi], saturation = [lo, hi] (actuator limits), dead_time (0 to 600 s), noise (standard deviation) with seed, initial (the measurement at the start). Times and coefficients must be positive numbers; parameters of another kind are refused. See docs/pid.md.";
    ModbusTag = 106, "a [modbus.tags] entry cannot be used",
        "Each entry of `[modbus.tags]` in alba.toml gives a tag (or `Tag.MEMBER`, or a system tag like `S:SCANMAX`) an explicit Modbus address after OpenPLC's map: `Name = \"hr 8192\"`. The name must exist; BOOL goes on a coil or discrete input (`coil`, `di`), numbers on registers (`hr`, `ir`: 1 register for SINT/INT, 2 for DINT/REAL/TIME, 4 for LINT/LREAL, high word first); coils and holding registers are written by clients, so inputs and read-only tags go on `di` or `ir`; two entries may not share a bit or register. See docs/protocols.md.";
    UsersFile = 107, "a problem in users.toml",
        "Each user of `users.toml` (beside alba.toml) is a table `[users.NAME]` with `role` (viewer, operator, engineer or admin) and `password`, the argon2 hash of the password as a PHC string (`$argon2id$...`), never the password itself. Names have 1 to 64 letters, digits and `_ . - @`. Unknown keys are refused. `alba user add|passwd|remove|role` writes the file; see docs/file-formats.md and docs/security.md. A users.toml that other users of the machine may read or write (Unix mode beyond 0600) is reported as a warning, not an error: `chmod 600 users.toml` (every `alba user` command saves it 0600).";
    ModbusClients = 108, "the Modbus server's client rules cannot be used",
        "Modbus TCP has no authentication, so the server of `alba run` decides by the client's address. `[modbus] allow` lists the clients served: IPv4 or IPv6 addresses (\"192.168.1.20\", \"::1\") and CIDR ranges (\"10.0.0.0/24\", \"fd00::/8\", host bits clear); the list may not be empty. A `listen` address beyond loopback (like 0.0.0.0) needs `allow`; on loopback every local client is served unless `allow` says otherwise. `read_only = true` refuses every write. See docs/security.md.";
    OpcuaUsersDeprecated = 109, "[opcua.users] is deprecated (a warning)",
        "Users in `[opcua.users]` of alba.toml still work (read_only ones as viewers, the others as operators), but users now live in `users.toml`, one store for every interface. This is a warning: the project loads and runs. Move each user with `alba user add <project> <name> --role operator` (typing the password again), or `alba user migrate <project>`, which copies the hashes into users.toml; then delete `[opcua.users]` and `read_only` from alba.toml. A name in both files takes its users.toml entry.";
    CsvSyntax = 110, "a CSV file is malformed",
        "CSV files use commas between fields, double quotes around fields that contain commas or quotes (a quote inside is written twice), and one record per line; every record has as many fields as the header.";
    CsvHeader = 111, "a CSV header is wrong",
        "tags.csv starts with the header `name,type,address,initial,retain,description` (columns other than name and type may be left out). A stimulus file starts with `time_ms,tag,value`.";
    BadTagName = 112, "a tag name is not valid",
        "Tag names use letters, digits and `_`, do not start with a digit, and must not read as an address (like `MW2` or `I0.0`) or a reserved word.";
    UnknownType = 113, "unknown data type",
        "Types are BOOL, SINT, INT, DINT, LINT, REAL, LREAL, TIME, TIMER, COUNTER and PID (case-insensitive).";
    DuplicateTag = 114, "a tag is declared twice",
        "Tag names are case-insensitive, as IEC 61131-3 requires: `Motor` and `MOTOR` are the same tag. Rename or remove one of them.";
    BadAddress = 115, "an address is not valid",
        "Addresses name the I/O image: DI:1/n DO:2/n AI:3/n AO:4/n (AuroraLD), %IXb.i %QXb.i %IWn %QWn %MXb.i %MBn %MWn %MDn (IEC 61131-3), Ib.i Qb.i AIWn AQWn Ainn Mb.i MBn MWn MDn (S7-200), I:e/b O:e/b B3:e/b N7:e F8:e N9:e N10:e (SLC 500 files, elements 0 to 255, word bits 0 to 15). Bit numbers go from 0 to 7; S7 analog word addresses are even.";
    AddressUsedTwice = 116, "two tags use the same address",
        "Each I/O channel or marker byte belongs to one tag. Two notations of one channel (DI:1/9 and %IX1.1) are the same address; overlapping marker words (MW0 and MD0) are too.";
    TypeAddressMismatch = 117, "the tag's type does not fit its address",
        "Digital I/O and marker bits hold BOOL; analog I/O holds INT or DINT; MB holds SINT, MW holds INT, MD holds DINT, REAL or TIME. Structures (TIMER, COUNTER, PID) cannot have an address.";
    BadInitialValue = 118, "an initial value does not fit the tag's type",
        "BOOL takes 0, 1, true or false; integers take decimal (or 16#, 8#, 2# based) numbers within the type's range; REAL takes a number; TIME takes milliseconds or a T#1m30s literal. Structures take no initial value in tags.csv: their PRE and ACC come from the instruction (TON(t,5000,0)).";
    BadRetain = 119, "the retain column is not a boolean",
        "`retain` is empty (not retained), 0/1, true/false or yes/no.";
    ReservedType = 120, "a reserved type is not available yet",
        "No type is reserved at present (PID, once reserved, is available). The code is kept so that old reports keep their meaning.";
    PidParameter = 121, "a PID parameter in tags.csv is invalid",
        "The `initial` field of a PID tag is a list of `MEMBER=value` pairs separated by `;` (for example `KP=5;KI=0.8;UPD=640;MAXS=10`). Each member must exist and be writable, each value must be a number, and together with the defaults they must make a valid loop: UPD > 0 ms, gains and times (KP KI KD KC TI TD) not negative, MINS <= MAXS, 0 <= DB <= MAXS-MINS, 0 <= MINO <= MAXO <= 100 (%), DFN >= 0, FORM 0 to 4, 11 or 12 (3 and 4 as the 004 programs run them; FORM 3 and 11 with UPD >= 10 ms), no NaN or infinity. The SLC 500 reports the same conditions at run time as PID errors 11H 12H 13H 14H 23H 41H 51H 52H; Alba reports them when the project is checked, and at run time (ERRC, a minor fault) when a program writes such a value.";
    AlarmFile = 140, "alarms.csv is not valid",
        "alarms.csv has the header `id,tag,condition,severity,delay_ms,deadband,message` (an eighth column `suppressed_by` may follow) and one alarm per row: a unique id (letters, digits, `_`, `-`, `.`), a tag, member or address of the program, a condition (on, off, rising, falling, or > >= < <= == != and a number; comparisons only for numbers), a severity (1 to 1000, or low, medium, high, critical), an on-delay in ms (0 to 86400000; none for rising/falling), a deadband ≥ 0 (for comparisons), a message, and optionally a BOOL tag that suppresses the alarm while true. See docs/alarms.md.";
    ScreenFile = 141, "a screen file (hmi/*.json) is not valid",
        "A screen of the studio (hmi/<screen>.json) is not valid: not JSON, a schema this version does not read, an unknown element type or animation, an element without an id or a size, a tag the program does not have, a structure where a value is needed, a widget writing an input or a read-only tag, or a range whose max is not above its min. The message says which, at its place in the file; docs/file-formats.md has the format.";
    Syntax = 200, "ladder syntax error",
        "A rung is a sequence of instructions `NAME(operand,...)` and branches `[leg,leg,...]`, ended by `;`. A `//` comment line directly above a rung is its comment.";
    UnknownInstruction = 201, "unknown instruction",
        "The instruction name is not in Alba's ladder instruction set. `alba explain E201` lists the groups: bit (XIC XIO OTE OTL OTU ONS OSR OSF), timers (TON TOF RTO TP), counters (CTU CTD RES), compare (LIM EQU NEQ LES GRT LEQ GEQ MEQ), math (ADD SUB MUL DIV MOD SQR NEG ABS XPY LN LOG CPT SCP), move/logic (MOV CLR AND OR XOR NOT), trigonometry (SIN COS TAN ASN ACS ATN DEG RAD), program flow (JMP LBL AFI NOP).";
    Unbalanced = 202, "brackets or parentheses do not match",
        "Every `[` of a branch needs its `]`, every `(` its `)`, before the `;` that ends the rung.";
    EmptyLeg = 203, "a branch has an empty leg",
        "Each leg of a branch `[a,b]` holds at least one instruction.";
    UnterminatedRung = 204, "a rung does not end with `;`",
        "Every rung, the last one too, ends with `;`.";
    IlSyntax = 210, "Instruction List syntax error",
        "An AWL line holds one instruction: a mnemonic and its operands separated by commas (`LD I0.0`, `MOVW +5, MW2`). `NETWORK n` and `TITLE =` lines, `//` and `/* */` comments and the ORGANIZATION_BLOCK frame of STEP 7-Micro/WIN exports are accepted.";
    UnknownMnemonic = 211, "unknown AWL instruction",
        "The mnemonic is not in Alba's S7-200 instruction set. Bit logic: LD LDN A AN O ON NOT = S R EU ED; stack: ALD OLD LPS LRD LPP LDS; compares: LDW= AW= OW= (and <> < > <= >=), LDD…/AD…/OD… for double words, LDR…/AR…/OR… for reals; math: +I -I *I /I, +D -D *D /D, +R -R *R /R, INCW DECW INCD DECD; moves: MOVB MOVW MOVD MOVR; timers: TON TONR TOF (TOFF); counters: CTU CTD CTUD; flow: FOR NEXT JMP LBL NOP.";
    LogicStack = 212, "the logic stack does not hold what the instruction needs",
        "S7-200 logic works on a stack: LD, LDN, compares and LDS push a value; A, O, =, boxes and timers use the top; ALD, OLD, LPP combine or pop two levels; counters take their inputs from two or three levels. A network (and the code after a label) starts with an empty stack: begin it with a load instruction. The stack has 9 levels: a tenth load drops the oldest value, which no instruction may then reach.";
    S7Timer = 213, "a timer or counter number does not fit the instruction",
        "S7-200 timer numbers fix the kind and resolution: TONR uses T0–T31 and T64–T95, TON and TOF use T32–T63 and T96–T255, and one number serves one kind of timer. Counters are C0–C255, one counter per number.";
    LoopStructure = 214, "FOR and NEXT do not match",
        "Every FOR has its NEXT later in the same program, and loops nest at most 8 deep.";
    IlNotSupported = 215, "an S7-200 feature Alba does not have yet",
        "Subroutines and interrupt routines, local variables, and the byte forms INCB, DECB and LDB= … are not available yet; use M markers, words and one main program.";
    StSyntax = 220, "Structured Text syntax error",
        "A Structured Text file (`.st`) holds IEC 61131-3 POUs: `PROGRAM name … END_PROGRAM`, `FUNCTION`, `FUNCTION_BLOCK`, `TYPE … END_TYPE` and `VAR_GLOBAL` blocks. Statements end with `;`: assignments `x := e;`, calls `t1(IN := x, PT := T#5s);`, IF/ELSIF/ELSE/END_IF, CASE … OF … END_CASE, FOR/WHILE/REPEAT loops, EXIT and RETURN. Comments are `(* *)`, `/* */` and `//`. The message says what was expected at the place shown; see docs/st.md.";
    StType = 221, "a Structured Text type error",
        "Structured Text is strictly typed: both sides of an operator, and the value and target of an assignment, have one type, except that a value widens implicitly to a larger type of its family (SINT → INT → DINT → LINT, USINT → UINT → UDINT → ULINT, BYTE → WORD → DWORD → LWORD, REAL → LREAL, an integer to a REAL wide enough). Conditions are BOOL. The message names both types; convert with a `*_TO_*` function (`INT_TO_REAL(x)`).";
    StName = 222, "an unknown name in Structured Text",
        "A name in ST is a variable of the POU, a tag of tags.csv (every tag is a global variable of every POU), a standard function or function block, or a member of a structure or function block instance (`t1.Q`). The message suggests the closest known name.";
    StNotSupported = 223, "a Structured Text feature the engine does not have yet",
        "Alba lowers ST to its one IR; a few parts of the language have no form there yet (STRING, LTIME, DATE and TIME_OF_DAY, arrays of structures or of function blocks, pointers, recursive calls: user FUNCTIONs and FUNCTION_BLOCKs are inlined where they are called). They are refused at their place rather than compiled to something that behaves differently; docs/st.md lists them.";
    StDeclaration = 224, "a Structured Text declaration cannot be used",
        "A variable is declared once per POU; an ARRAY has constant bounds with the low bound not above the high one and at most 10 000 elements; an initial value fits the variable's type; a `VAR CONSTANT` is not written; EXIT is inside a loop; the loop variable of a FOR is an integer variable of the POU.";
    UnknownTag = 301, "unknown tag",
        "Operands name tags of tags.csv (case-insensitive), their members (`Delay.DN`), addresses, system tags (`S:FS`) or literals.";
    OperandCount = 302, "wrong number of operands",
        "Each instruction takes a fixed number of operands; the message says which.";
    OperandType = 303, "an operand has the wrong type",
        "The instruction needs another kind of operand here: a BOOL for contacts and coils, a number for compares and math, a TIMER or COUNTER tag for timer and counter instructions.";
    NotWritable = 304, "an operand cannot be written",
        "Inputs (DI, AI and tags on them), literals, system tags and the status bits of timers and counters (EN TT DN CU CD OV UN) are read-only for programs; RES clears a timer or counter.";
    UnknownMember = 305, "a structure has no such member",
        "TIMER has PRE ACC EN TT DN; COUNTER has PRE ACC CU CD DN OV UN.";
    MissingLabel = 306, "JMP to a label that does not exist",
        "A JMP names a label set by LBL(label) at the start of a rung of the same program.";
    DuplicateLabel = 307, "a label is set twice",
        "Each LBL name appears once per program.";
    NoOutput = 308, "a rung has no output instruction",
        "Every rung needs an output instruction (OTE, OTL, a timer, a counter, a math or move instruction, JMP, NOP...), and a rung or a final branch leg must end with one.";
    LabelNotFirst = 309, "LBL is not the first instruction of its rung",
        "A label marks the start of a rung: write LBL(name) as the rung's first instruction.";
    BadLiteral = 310, "a literal is malformed or out of range",
        "Integer literals are decimal or based (16#FF), reals use a dot (1.5, 2.0e3), times are T#5s or T#1m30s; the value must fit where it goes. A timer's time base is ms, cs, ds, s or min (or 0.001, 0.01, 0.1, 1.0, 60 seconds).";
    ConflictingPreset = 311, "one timer or counter is given two different presets",
        "The literal PRE and ACC of TON(t,pre,acc) are the structure's initial values, so every instruction on one tag must give the same ones (or `?`); likewise every TON, TOF and RTO on one timer counts in one time base (TON(t,pre,acc,s); none is ms), and TP only on a timer in ms.";
    Expression = 312, "a CPT expression is malformed",
        "CPT accepts + - * / MOD ** ^, parentheses, comparisons (= <> < > <= >=), AND OR XOR NOT, the functions SQR SQRT ABS SIN COS TAN ASN ACS ATN ATAN2 LN LOG DEG RAD TRN FRD TOD ROUND, AuroraLD's log10 logE log(a,b) Int signum cosh sinh tanh rnd(a,b) radians degrees, and PI and E.";
    NotYetSupported = 313, "a reserved instruction is not available yet",
        "No instruction is reserved at present (PID, once reserved, is available; see ladder.md and pid.md). The code is kept so that old reports keep their meaning.";
    StimulusSyntax = 401, "a stimulus row is malformed",
        "Stimulus files have the header `time_ms,tag,value`; time_ms is a non-negative integer; values are 0/1, true/false, integers or reals.";
    StimulusTarget = 402, "a stimulus row names something that cannot be set",
        "A stimulus sets inputs and internal tags by name, member or address; outputs driven by the program, status bits and system tags cannot be set.";
    TraceName = 403, "a traced name is not valid",
        "--tags takes tag names, members (Delay.ACC), addresses (DO:2/0, %QX0.1) and system tags (S:FS), separated by commas; a whole TIMER or COUNTER is not a value: name a member.";
    BadArgument = 404, "a command-line value is not valid",
        "See `alba help <command>` for the accepted values.";
    NotOnBoard = 501, "the program cannot run on the board",
        "Firmware for an Arduino runs the control program with 32-bit REALs and no 64-bit floating point: LREAL tags and LREAL arithmetic are refused, with the instruction responsible. Use REAL, or run the program on the PC with the board as remote I/O (controller mode).";
    DoesNotFit = 502, "the firmware does not fit the board",
        "The built firmware needs more flash or RAM than the board has (the report gives both against the board's limits). Shorten the program, use fewer tags, or choose a board with more memory (the Mega has 8 KiB of RAM and 248 KiB of flash).";
    Toolchain = 503, "the firmware could not be built or uploaded",
        "Building needs Debian's gcc-avr, avr-libc and arduino-core-avr (./test.sh installs them); uploading needs avrdude and the board on the named serial port. The message gives the tool's own error.";
    PnmlSyntax = 601, "a PNML file is not well-formed XML",
        "A .pnml file is an XML document (ISO/IEC 15909-2). The message gives the XML error at the place shown: an unclosed or mismatched tag, a bad attribute, an unknown entity (only XML's five predefined entities and character references are accepted), text outside the root element. Files over 16 MiB and elements nested deeper than 64 levels are refused with E606.";
    PnmlStructure = 602, "a PNML document does not have the structure of a net",
        "Alba reads one `<net id=\"..\" type=\"..\">` inside `<pnml>`, with pages holding `<place id>`, `<transition id>` and `<arc id source target>`; every node and arc needs a non-empty `id`, and each label (`name`, `initialMarking`, `inscription`) appears at most once on an element. See docs/nets.md, section pnml.";
    PnmlDuplicateId = 603, "two PNML elements have the same id",
        "PNML ids are unique in the whole document: places, transitions, arcs and pages share one space of names. Rename one of them (and the arcs that use it).";
    PnmlArc = 604, "a PNML arc does not join a place and a transition",
        "An arc goes from a place to a transition or from a transition to a place, and its `source` and `target` name nodes of the net (a reference node stands for the node it refers to). Two places or two transitions cannot be joined, and two arcs may not join the same pair in the same direction (give the one arc a weight instead).";
    PnmlNumber = 605, "a PNML number is out of range",
        "`<initialMarking><text>` is a whole number from 0 to 1000000, `<inscription><text>` (an arc's weight) a whole number from 1 to 1000000, Alba's `<priority>` an integer (32 bits), positions decimal numbers. Negative, fractional and larger values are refused rather than rounded.";
    PnmlLimit = 606, "a PNML file is too large",
        "Alba reads PNML files up to 16 MiB, with at most 1000000 elements nested at most 64 levels deep, so that a broken or hostile file cannot exhaust memory or the stack. Split the model, or remove what it does not need (large graphics, other tools' data).";
    PnmlAlba = 607, "Alba's data in a PNML file is not valid",
        "Alba keeps its own data in `<toolspecific tool=\"alba\" version=\"1\">` on the element it belongs to: on the net `<mode>petri</mode>` or `<mode>normal</mode>` and `<widget id kind [tag] [x y]>caption</widget>` (kind button, display, plot or label); on a place `<tag>NAME</tag>`, `<kind>` (state, counter, expression, variable, input, output, stop, end), `<prop name=\"..\">value</prop>` and `<script>`; on a transition `<guard>EXPR</guard>`, `<priority>N</priority>`, `<kind>` (transition, condition, timer) and `<prop>`; on an arc `<kind>normal|inhibitor|read</kind>` (inhibitor and read arcs go from a place to a transition). Each appears at most once. See docs/nets.md.";
    PnmlIgnored = 608, "part of a PNML file was ignored (a warning)",
        "An element Alba does not know (another tool's extension outside `<toolspecific>`, a label of another net type) is skipped with this warning, once per element name; the net loads. Other tools' `<toolspecific>` blocks are not ignored: they are kept and written back unchanged.";
    NetMode = 620, "a net element cannot run in this mode (yet)",
        "Petri mode has plain places and transitions (with guards and `<tag>`); the state-net kinds (Timer, Condition, Counter, Expression, Variable, Input, Output, Stop, End) run in normal mode (`<mode>normal</mode>`, docs/nets.md).";
    NetGuard = 621, "a transition guard is not valid",
        "A `<guard>` is a BOOL expression of Alba's expression language for nets: tag names and members, literals, `NOT`, `AND` (`&`), `OR` (`|`), `XOR`, parentheses, comparisons (= == <> != < > <= >=), arithmetic (+ - * / : MOD % ** ^, with the state-net source's precedence) and its functions (cos, sqrt, rem, log...). Every name must be a tag, member, address or system tag; a number alone is not a guard: compare it.";
    NetPlaceTag = 622, "a place's `<tag>` cannot be driven",
        "A place's `<tag>NAME</tag>` makes the net write the tag NAME: a BOOL, true while the place is marked, or, when the place has a `value` (a number), a numeric tag that holds that constant while the place is marked and 0 after. NAME must be a tag or member of that kind the program may write: not an input, a status bit, a system tag or a marking.";
    NetTagClash = 623, "a place's marking tag clashes with a tag",
        "The marking of place P of net N (file N.pnml) is the DINT tag `N.P`; no tag of tags.csv, no place of another net, and no member of a TIMER, COUNTER or PID tag named N (`N.DN`) may have that name.";
    NetRange = 624, "a marking or weight does not fit a DINT",
        "Markings are DINT tags: an initial marking or an arc weight (the arcs between one place and one transition added up) must be at most 2147483647.";
    NetArc = 625, "an arc cannot be used by a Petri-mode net",
        "Inhibitor and read (test) arcs go from a place to a transition; from a transition to a place only normal arcs produce tokens.";
    NetElement = 630, "a normal-mode element is not valid",
        "In a normal-mode net (docs/nets.md \"Normal mode\") every element holds at most one token and passes it on: arcs are plain (no inhibitor or read arcs) and weigh 1; a Condition needs a `<guard>`; a Timer needs `<prop name=\"delay\">` (milliseconds or T#5s); a Counter takes `load` (a DINT) and `direction` (up or down); an Input `source`; an Output `target` and `source`; a Variable `mode` (Assignment, Variable, WriteToMyVariable, WriteToTarget, DefineTarget, ResetTargetValue), `source`, `target`, `value` and `initial` as its mode needs; other kinds take no properties.";
    NetScript = 631, "an Expression element's script is not valid",
        "An Expression element (normal mode) runs its `<script>` each scan it holds the token: sections `define{a, b}` (names of tags it uses), `constant{k = 2.5}` (or `const{}`) and `function{...}` with statements separated by `;` or line ends, each `target = expression` or a bare expression whose value goes to the element's own variable `<net>.<id>.value` (REAL); `//` starts a comment. Expressions are Alba's expression language for nets (numbers and tags, + - * / : MOD % ** ^ with the source's precedence, parentheses, and the source's functions cos, cosh, arcos, sin, sinh, arcsin, tan, tanh, arctan, sqrt, rem, root, pow, exp, abs, log, round, truncate, floor, ceiling, sign); targets are numeric tags a program may write.";
    SfcSyntax = 650, "an SFC file does not follow the textual SFC syntax",
        "An .sfc file is IEC 61131-3's textual SFC: `INITIAL_STEP name: actions END_STEP`, `STEP name: actions END_STEP` where an action is `Tag(Q)` or `Tag(Q, T#5s)` ended by `;` (Q one of N S R L D P P1 P0 SD DS SL), and `TRANSITION [name] [(PRIORITY := n)] FROM step TO step := condition; END_TRANSITION` (lists of steps in parentheses for simultaneous divergence and convergence). Comments are `(* ... *)` and `//`. See docs/nets.md, SFC.";
    SfcStructure = 651, "an SFC chart is not well formed",
        "An SFC has exactly one INITIAL_STEP, unique step names, transitions between declared steps, a time on the timed qualifiers (L D SD DS SL) and none on the others.";
    SfcAction = 652, "an SFC action cannot be driven",
        "An action is a BOOL tag (or member) a program may write: not an input, a status bit or a system tag.";
    ImportFailed = 701, "a program from another tool cannot be imported",
        "`alba import` reads LDmicro `.ld` files, PLCopen TC6 XML v2.01 and Studio 5000 `.L5X` exports (the content decides the format, else the extension; `--format ldmicro|plcopen|l5x` overrides). The message names the place in the input (`file:line:col`) that is malformed or that Alba cannot convert at all; constructs it can leave out are listed as refused in the report instead, and the rest is imported. The output folder must be new or empty unless `--force` is given. Nothing is written when an import fails. See docs/interchange.md.";
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "E{}", self.number())
    }
}

impl std::str::FromStr for Code {
    type Err = ();
    fn from_str(s: &str) -> Result<Code, ()> {
        let digits = s.trim().trim_start_matches(['E', 'e']);
        let n: u16 = digits.parse().map_err(|_| ())?;
        Code::ALL.iter().copied().find(|c| c.number() == n).ok_or(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn codes_are_unique_and_parse_back() {
        let mut seen = HashSet::new();
        for c in Code::ALL {
            assert!(seen.insert(c.number()), "duplicate number {}", c.number());
            assert_eq!(c.to_string().parse::<Code>(), Ok(*c));
            assert!(!c.explanation().is_empty());
        }
    }
}
