//! The JSON of every API reply (docs/api.md), as serde types.
//!
//! The same types, rendered to TypeScript by `ts-rs`, are the studio's
//! `web/src/api.gen.ts`; a test (`tests/it/contract.rs`) fails when the
//! committed file and these types disagree (`UPDATE_BINDINGS=1 cargo test
//! -p alba-server` rewrites it). `Json` in TypeScript is any JSON value.

use alba_compiler::ladder::domain::{ArgInfo, Domain, GroupInfo, InstructionInfo, MemberInfo, OptionalInfo, TypeInfo};
use serde::Serialize;
use serde_json::Value as Json;
use ts_rs::TS;

/// Scan statistics since the last run (µs).
#[derive(Debug, Clone, Serialize, TS)]
pub struct Stats {
    pub last_us: u64,
    pub min_us: u64,
    pub max_us: u64,
    pub mean_us: u64,
    pub jitter_us: u64,
    pub overruns: u64,
}

/// The runtime's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
pub enum RunState {
    Running,
    Stopped,
    Faulted,
}

impl From<alba_control::runtime::RunState> for RunState {
    fn from(s: alba_control::runtime::RunState) -> RunState {
        match s {
            alba_control::runtime::RunState::Running => RunState::Running,
            alba_control::runtime::RunState::Stopped => RunState::Stopped,
            alba_control::runtime::RunState::Faulted => RunState::Faulted,
        }
    }
}

/// `GET /api/status`, `POST /api/run`, `POST /api/stop`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Status {
    pub project: String,
    pub state: RunState,
    pub fault: Option<String>,
    pub scan_ms: u32,
    pub scans: u64,
    pub time_ms: u64,
    pub stats: Stats,
    pub minor_faults: u64,
    pub io: String,
    pub programs: Vec<String>,
    pub clients: usize,
    /// Retain saves, the historian and disk space are all healthy
    /// (`S:STOREOK`).
    pub store_ok: bool,
    /// Retentive data was lost at start (`S:RETAINLOST`).
    pub retain_lost: bool,
    /// What is wrong with the runtime's stores now, oldest first
    /// (docs/reliability.md).
    pub problems: Vec<Problem>,
    /// The forces in effect (as `GET /api/forces`), for the studio's
    /// "forces active" banner.
    pub forces: Vec<Force>,
    /// The health of each client connection to a remote server
    /// (`[[opcua_server]]`, the MQTT broker); empty without any.
    pub connections: Vec<Connection>,
}

/// A client connection of `alba run` to a remote server (`[[opcua_server]]`,
/// `[mqtt]`'s broker).
#[derive(Debug, Clone, Serialize, TS)]
pub struct Connection {
    /// The server's `name` in alba.toml; `mqtt` for the broker.
    pub name: String,
    /// `opcua`, `mqtt` (JSON) or `sparkplug`.
    pub protocol: String,
    pub endpoint: String,
    /// Connected, with every binding accepted (Sparkplug with a primary
    /// host: born, the host online).
    pub ok: bool,
    /// A session is open (bindings may still be refused).
    pub connected: bool,
    /// Sessions opened since `alba run` started (reconnections: one less).
    pub connects: u64,
    /// Failed attempts and losses.
    pub errors: u64,
    /// Why it is down or unhealthy (`null` while ok).
    pub last_error: Option<String>,
    /// MQTT only: the outgoing queue's counters since `alba run` started.
    pub queue: Option<QueueCounters>,
}

/// What the MQTT client did with the changes it was given (docs/scale-out.md).
#[derive(Debug, Clone, Serialize, TS)]
pub struct QueueCounters {
    /// Messages handed to the connection (tag values, DDATA, replayed ones included).
    pub published: u64,
    /// Changes the full queue could not take: they went with a later
    /// snapshot, the intermediate values coalesced.
    pub coalesced: u64,
    /// Values lost: store-and-forward records past `buffer_max` (the
    /// oldest), unreadable, or of metrics the current birth does not have.
    pub dropped: u64,
    /// Sparkplug store and forward: records waiting on disk, and sent from it.
    pub buffered: u64,
    pub replayed: u64,
    /// The queue's bound (`[mqtt] queue`).
    pub capacity: u64,
}

/// A child of a browsed OPC UA node.
#[derive(Debug, Clone, Serialize, TS)]
pub struct BrowseNode {
    /// Its node id as the server answers it (`ns=2;s=Tank.Level`, `i=2253`).
    pub node: String,
    /// The same with the namespace's URI (`nsu=urn:plant;s=Tank.Level`), what a
    /// binding should say; `null` in namespace 0.
    pub node_uri: Option<String>,
    pub browse_name: String,
    pub display_name: String,
    /// `Object`, `Variable`, `Method`, `ObjectType`, …
    pub class: String,
    /// A variable's data type (`Double`, `Int32`, `Boolean`, or a type's node id).
    pub data_type: Option<String>,
}

/// `GET /api/opcua/{server}/browse`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct OpcuaBrowse {
    pub server: String,
    /// The node browsed.
    pub node: String,
    pub children: Vec<BrowseNode>,
}

/// A current problem of the runtime's stores.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Problem {
    /// `retain` (restoring at start), `retain-save`, `history`,
    /// `history-damaged`, `history-disk`, `history-cap`.
    pub source: String,
    pub message: String,
    pub since_unix_ms: i64,
}

/// Who may write a tag.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
pub enum Access {
    Readwrite,
    Input,
    Readonly,
}

/// A tag of `tags.csv` (or a system tag) with its live value: `GET /api/tags`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct TagInfo {
    pub name: String,
    #[serde(rename = "type")]
    #[ts(rename = "type")]
    pub ty: String,
    pub address: Option<String>,
    /// Every notation of the address (AuroraLD, IEC, S7), upper case; empty without one.
    pub notations: Vec<String>,
    pub description: String,
    pub retain: bool,
    pub access: Access,
    /// A value, or an object of a structure's members.
    #[ts(type = "Json")]
    pub value: Json,
    /// The forced value, `null` if not forced.
    #[ts(type = "Json")]
    pub forced: Json,
}

/// A member or an address (not a tag of `tags.csv`) with its live value.
#[derive(Debug, Clone, Serialize, TS)]
pub struct TagValue {
    pub name: String,
    #[serde(rename = "type")]
    #[ts(rename = "type")]
    pub ty: String,
    pub access: Access,
    #[ts(type = "Json")]
    pub value: Json,
    #[ts(type = "Json")]
    pub forced: Json,
}

/// `GET /api/tags/{name}`: a tag, or a member or address.
#[derive(Debug, Clone, Serialize, TS)]
#[serde(untagged)]
pub enum TagReply {
    Tag(TagInfo),
    Other(TagValue),
}

/// A name and a value: a force (`GET /api/forces`, `PUT /api/forces/{name}`)
/// or a written tag (`PUT /api/tags/{name}`).
#[derive(Debug, Clone, Serialize, TS)]
pub struct Force {
    pub name: String,
    #[ts(type = "Json")]
    pub value: Json,
}

/// An alarm (`GET /api/alarms`, docs/alarms.md): `state` is `normal`,
/// `active_unacked`, `active_acked`, `cleared_unacked`, `shelved`,
/// `suppressed` or `out_of_service`; times are Unix ms.
#[derive(Debug, Clone, Serialize, TS)]
pub struct AlarmReply {
    pub id: String,
    pub tag: String,
    pub state: String,
    pub severity: u16,
    pub message: String,
    pub since_ms: i64,
    pub condition: String,
    /// The tag's value at the last evaluation.
    pub value: f64,
    /// The process is in alarm (the condition holds, after on-delay and deadband).
    pub active: bool,
    pub acked_by: Option<String>,
    pub ack_comment: Option<String>,
    pub acked_ms: Option<i64>,
    pub shelved_until_ms: Option<i64>,
    /// Why it is shelved or out of service, and by whom.
    pub reason: Option<String>,
    pub by: Option<String>,
}

/// The alarm system at a glance (`GET /api/alarms/stats`): counts by state,
/// new alarms in the last 10 minutes (a flood above 10, ISA-18.2), and the
/// most severe unacknowledged alarm for the banner.
#[derive(Debug, Clone, Serialize, TS)]
pub struct AlarmStats {
    pub alarms: usize,
    pub active: usize,
    pub unacked: usize,
    pub shelved: usize,
    pub suppressed: usize,
    pub out_of_service: usize,
    pub new_10min: usize,
    pub flood: bool,
    pub top_unacked: Option<String>,
    pub top_severity: Option<u16>,
}

/// A program's language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    Ladder,
    Il,
    Net,
    Sfc,
    St,
}

/// `GET /api/programs`: one program of the project.
#[derive(Debug, Clone, Serialize, TS)]
pub struct ProgramRef {
    pub name: String,
    pub language: Language,
    pub plant: bool,
}

/// A located diagnostic.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Diagnostic {
    pub code: String,
    pub severity: String,
    pub message: String,
    pub file: Option<String>,
    pub line: Option<usize>,
    pub col: Option<usize>,
    pub end_line: Option<usize>,
    pub end_col: Option<usize>,
    pub help: Option<String>,
}

/// A ladder instruction in a rung.
#[derive(Debug, Clone, Serialize, TS)]
pub struct InstrJson {
    /// The id of the compiled element (power flow), if compiled.
    pub id: Option<u32>,
    pub mnemonic: String,
    pub operands: Vec<String>,
    pub line: usize,
    pub col: usize,
}

/// A parallel branch in a rung.
#[derive(Debug, Clone, Serialize, TS)]
pub struct BranchJson {
    pub id: Option<u32>,
    pub line: usize,
    pub col: usize,
    pub legs: Vec<Vec<ElementJson>>,
}

/// An element of a rung.
#[derive(Debug, Clone, Serialize, TS)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ElementJson {
    Instr(InstrJson),
    Branch(BranchJson),
}

/// A rung of a ladder program.
#[derive(Debug, Clone, Serialize, TS)]
pub struct RungJson {
    pub number: usize,
    pub comment: Vec<String>,
    pub line: usize,
    pub elements: Vec<ElementJson>,
}

/// An instruction line of an IL program.
#[derive(Debug, Clone, Serialize, TS)]
pub struct IlLine {
    pub line: usize,
    pub id: Option<u32>,
}

/// A transition of a net program and its two monitored elements
/// (docs/nets.md, "Live view"): `enabled` is energised when the transition
/// may fire on the marking after the last scan (its arcs, and its guard as
/// evaluated in that scan); `fired` when it fired in the last scan.
#[derive(Debug, Clone, Serialize, TS)]
pub struct NetTransition {
    /// The transition's PNML id.
    pub id: String,
    pub enabled: Option<u32>,
    pub fired: Option<u32>,
}

/// A marking tag written by `POST /api/nets/{name}/reset`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct MarkingValue {
    pub tag: String,
    pub value: i32,
}

/// `POST /api/nets/{name}/reset`: the net and the marking written.
#[derive(Debug, Clone, Serialize, TS)]
pub struct NetReset {
    /// The net's program, as listed (`line.pnml`).
    pub program: String,
    pub marking: Vec<MarkingValue>,
}

/// `GET /api/programs/{name}`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Program {
    pub name: String,
    pub language: Language,
    pub plant: bool,
    pub text: String,
    pub diagnostics: Vec<Diagnostic>,
    /// Ladder programs.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub rungs: Option<Vec<RungJson>>,
    /// IL programs.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub lines: Option<Vec<IlLine>>,
    /// Net programs: each transition's monitored elements, in document order.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub transitions: Option<Vec<NetTransition>>,
}

/// `POST /api/check/{name}` of a program that compiles.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Checked {
    /// Always empty (a program that does not compile is an error reply).
    pub diagnostics: Vec<Diagnostic>,
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub rungs: Option<Vec<RungJson>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub lines: Option<Vec<IlLine>>,
}

/// `PUT /api/programs/{name}`, `PUT /api/tags.csv`: saved, and applied online or not.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Saved {
    pub diagnostics: Vec<Diagnostic>,
    pub applied: bool,
}

/// `GET /api/history/tags`: a recorded tag and the span of its samples.
#[derive(Debug, Clone, Serialize, TS)]
pub struct HistoryTag {
    pub name: String,
    pub first_ms: i64,
    pub last_ms: i64,
}

/// One history bucket: `[t_ms, min, max, first, last]` (`null` where a
/// value is not a number).
#[derive(Debug, Clone, Serialize, TS)]
pub struct Bucket(
    pub i64,
    #[ts(type = "number | null")] pub f64,
    #[ts(type = "number | null")] pub f64,
    #[ts(type = "number | null")] pub f64,
    #[ts(type = "number | null")] pub f64,
);

/// `GET /api/history`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct History {
    /// The node whose tag it is (this runtime's unless the query named another).
    pub node: String,
    pub tag: String,
    pub from: i64,
    pub to: i64,
    pub buckets: Vec<Bucket>,
}

/// `GET /api/history/raw`: samples as `[t_ms, value]`, oldest first.
#[derive(Debug, Clone, Serialize, TS)]
pub struct HistoryRaw {
    pub node: String,
    pub tag: String,
    pub from: i64,
    pub to: i64,
    pub points: Vec<(i64, f64)>,
    /// More samples lie in the range than `limit` let through.
    pub more: bool,
}

/// `GET /api/history/nodes`: the nodes whose history this runtime can read.
#[derive(Debug, Clone, Serialize, TS)]
pub struct HistoryNodes {
    /// This runtime's node id (its project's name with the embedded store).
    pub node: String,
    /// The store is shared with other runtimes (`[history] backend = "postgres"`).
    pub shared: bool,
    /// Every node with history, this one included, by id.
    pub nodes: Vec<String>,
}

/// What came of an audited action: `pending` when the server ended before it knew.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
pub enum AuditOutcome {
    Pending,
    Ok,
    Failed,
}

/// One row of the audit trail (docs/audit.md).
#[derive(Debug, Clone, Serialize, TS)]
pub struct AuditRow {
    /// Increasing in the order rows were written; `before` of the next page.
    pub id: i64,
    /// Unix ms.
    pub time_ms: i64,
    /// `null` when no users are configured.
    pub user: Option<String>,
    /// The client's `ip:port`.
    pub addr: Option<String>,
    /// `write`, `force`, `unforce`, `save_program`, `online_edit`, `save_tags`, `run`,
    /// `stop`, `login`, `login_failed`, `logout`, `user_added`, `user_changed`,
    /// `user_removed`, `alarm_ack`.
    pub action: String,
    pub target: Option<String>,
    /// The value before and after (JSON; a string if the stored text is not JSON).
    #[ts(type = "Json")]
    pub old: Json,
    #[ts(type = "Json")]
    pub new: Json,
    /// A diff summary for saves.
    pub detail: Option<String>,
    pub outcome: AuditOutcome,
    /// Why it failed.
    pub error: Option<String>,
    /// The door it came through: `http`, `mqtt`, `opcua`, `modbus`
    /// (`null` in rows written before doors were recorded).
    pub via: Option<String>,
}

/// `GET /api/audit`: a page of rows, newest first; `next` is the `before` of
/// the following page (`null` on the last).
#[derive(Debug, Clone, Serialize, TS)]
pub struct AuditPage {
    pub rows: Vec<AuditRow>,
    pub next: Option<i64>,
}

/// Every error reply: a message, and the diagnostics of an edit that does
/// not compile.
#[derive(Debug, Clone, Serialize, TS)]
pub struct ErrorReply {
    pub error: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub diagnostics: Option<Vec<Diagnostic>>,
}

/// A serial port of the machine (`GET /api/hardware`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct SerialPortInfo {
    /// The device path (`/dev/ttyUSB0`, a pty of the emulated board).
    pub path: String,
    /// What is known of it: USB vendor:product, maker and product names,
    /// its `/dev/serial/by-id` name; `alba.toml [board] port` for the
    /// project's own port.
    pub description: String,
}

/// One pin of a board and what it can do.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct BoardPin {
    /// As the Arduino IDE names it (`D13`, `A6`).
    pub pin: String,
    /// `di`, `do`, `ai`, `ao` (PWM): the directions of `[board]` it may serve;
    /// `serial` for D0/D1 (the link to the PC).
    pub caps: Vec<String>,
}

/// A board Alba builds for, with its limits and pins.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct BoardModel {
    /// `uno`, `nano`, `mega`.
    pub name: String,
    /// `Arduino Nano`.
    pub title: String,
    pub flash_max: u32,
    pub ram_max: u32,
    pub pins: Vec<BoardPin>,
}

/// A problem of the pin map, with the code `alba check` gives it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct PinProblem {
    /// `E102` (alba.toml `[board]`), `E501` (the program uses a channel the board cannot serve).
    pub code: String,
    pub message: String,
}

/// One channel of the pin map (a row of the studio's pin table).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct PinRow {
    /// `di`, `do`, `ai` or `ao`.
    pub dir: String,
    pub channel: u32,
    /// `DI:1/0`.
    pub address: String,
    /// `D2`; `null` for a channel the program uses and the map does not wire.
    pub pin: Option<String>,
    /// Tags of tags.csv at this address.
    pub tags: Vec<String>,
    pub problem: Option<PinProblem>,
}

/// A long hardware action's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    Running,
    Done,
    Failed,
}

/// A hardware job (`GET /api/hardware/jobs/{id}`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct HardwareJob {
    pub id: String,
    /// `download` or `upload`.
    pub kind: String,
    pub port: String,
    pub state: JobState,
    /// 0 to 100.
    pub progress: u8,
    /// What it is doing, what it did, or why it failed, in words.
    pub message: String,
    /// When it started (ms since the epoch).
    pub started_ms: i64,
}

/// `GET /api/hardware`: the project's board and pin map, the machine's ports.
#[derive(Debug, Clone, Serialize, TS)]
pub struct HardwareView {
    /// `[board] model` of alba.toml (`uno`, `nano`, `mega`); `null` without `[board]`.
    pub board: Option<String>,
    /// `[board] pinmap`: the preset the map starts from (`aurora`, `s7`, `openplc`).
    pub pinmap: String,
    /// Outputs on when the pin is low.
    pub active_low: bool,
    /// `[board] port`: the project's serial port, if set.
    pub port: Option<String>,
    pub ports: Vec<SerialPortInfo>,
    /// Every board with its limits and pins.
    pub boards: Vec<BoardModel>,
    pub presets: Vec<String>,
    /// The pin map as a table, with each channel's problem.
    pub pins: Vec<PinRow>,
    /// The project's `[board]` problems (and any other that stops the build), as `alba check` gives them.
    pub diagnostics: Vec<Diagnostic>,
    /// Recent jobs, newest first (kept while `alba run` runs).
    pub jobs: Vec<HardwareJob>,
    /// The board used as the running PLC's I/O now (`POST /api/hardware/attach`);
    /// `null`: the project's own I/O (`io`).
    pub attached: Option<Attachment>,
    /// The I/O driver `alba run` was started with (`--io`: `sim`, `arduino:…`),
    /// back after a detach.
    pub io: String,
    /// Board saves of this run that Undo can take back (`POST /api/hardware/board/undo`).
    pub undo: u32,
}

/// A board attached as the running PLC's I/O.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct Attachment {
    pub port: String,
    /// `controller` (the board's pins are the program's I/O) or `monitor`
    /// (the board runs the sketch; its memory is watched).
    pub mode: String,
    /// The I/O driver now (`arduino:/dev/ttyUSB0`, `board:/dev/ttyUSB0`).
    pub io: String,
    /// When it was attached (ms since the epoch).
    pub since_ms: i64,
    /// In words.
    pub message: String,
}

/// `POST /api/hardware/build`: what a firmware uses of its board.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct BuildSizes {
    pub board: String,
    /// `sketch`, `interpreter` or `controller`.
    pub kind: String,
    pub flash_bytes: u32,
    pub ram_bytes: u32,
    pub flash_max: u32,
    pub ram_max: u32,
    /// The toolchain's report (`nano: flash … of … bytes …`).
    pub report: String,
}

/// `POST /api/hardware/download`: the job started.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct JobStarted {
    pub job: String,
}

/// `POST /api/hardware/verify`: the board's running program read back and
/// compared with the project's byte code.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct Verified {
    pub port: String,
    /// The board holds exactly the project's byte code.
    pub same: bool,
    /// Bytes of the project's byte code.
    pub bytes: u32,
    /// In words (where it differs, the program ids).
    pub message: String,
}

/// `POST /api/hardware/identify`: what answers on a port.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct BoardIdentity {
    pub port: String,
    /// `false`: something answered that is not Alba's interpreter, or nothing did ("unknown device").
    pub known: bool,
    /// `nano` (the interpreter's own word).
    pub board: Option<String>,
    /// Byte-code format of the interpreter.
    pub format: Option<u8>,
    /// Board id (board, pin map, polarity) in hex.
    pub board_id: Option<String>,
    /// `running`, `no_program`, `faulted`.
    pub state: Option<String>,
    /// The running program's id in hex, when a program checks.
    pub program: Option<String>,
    /// In words.
    pub message: String,
}

/// A user's role (docs/security.md, "Sessions and roles"); each includes
/// the ones before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, TS)]
#[serde(rename_all = "lowercase")]
#[ts(rename = "Role")]
pub enum RoleName {
    Viewer,
    Operator,
    Engineer,
    Admin,
}

impl From<alba_auth::Role> for RoleName {
    fn from(r: alba_auth::Role) -> RoleName {
        match r {
            alba_auth::Role::Viewer => RoleName::Viewer,
            alba_auth::Role::Operator => RoleName::Operator,
            alba_auth::Role::Engineer => RoleName::Engineer,
            alba_auth::Role::Admin => RoleName::Admin,
        }
    }
}

/// `POST /api/login`: the session's bearer token (also set as the
/// `alba_session` cookie), the user and their role.
#[derive(Debug, Clone, Serialize, TS)]
pub struct Login {
    pub token: String,
    pub user: String,
    pub role: RoleName,
}

/// `GET /api/me`: who the request acts as. `users` is false when the
/// project has no users (every loopback request then acts as `admin`,
/// `user` null).
#[derive(Debug, Clone, Serialize, TS)]
pub struct Me {
    pub user: Option<String>,
    pub role: RoleName,
    pub users: bool,
}

/// `GET /api/domain`: the language (from `alba_ladder::domain`) and the role
/// each route needs (`ROUTE_ROLES`), so the studio knows what a user may do
/// without a table of its own.
#[derive(Debug, Clone, Serialize, TS)]
pub struct DomainReply {
    #[serde(flatten)]
    #[ts(flatten)]
    pub language: Domain,
    /// The routes with their own rule; any other route needs `viewer` for
    /// GET and `admin` for anything else.
    pub routes: Vec<RouteRole>,
    /// What a SCADA screen may hold (hmi/*.json): for the designer.
    pub screens: ScreenDomain,
}

/// The element types, animations (with their parameters) and widget
/// actions of screens (`alba_project::hmi`).
#[derive(Debug, Clone, Serialize, TS)]
pub struct ScreenDomain {
    /// `[type, what it is]`, AuroraLD's 30.
    pub elements: Vec<(String, String)>,
    /// Each element type's own properties (besides `label`, `tag`, `alarm`).
    pub properties: Vec<ParamTable>,
    /// The animations and their parameters besides `tag`.
    pub animations: Vec<ParamTable>,
    pub actions: Vec<String>,
}

/// An element type's properties or an animation's parameters, as the
/// designer's form asks for them (`kind`: the element type or animation).
#[derive(Debug, Clone, Serialize, TS)]
pub struct ParamTable {
    pub kind: String,
    pub params: Vec<ParamInfo>,
}

/// A parameter of an animation (`alba_project::hmi::Param`).
#[derive(Debug, Clone, Serialize, TS)]
pub struct ParamInfo {
    pub name: String,
    /// `number` (from `min` to `max`, in `unit`), `bool`, `color`, `choice`
    /// (one of `choices`), `intervals` (up to 4 `{from, color}`), `text` (at
    /// most `max` characters), `tag`, `points` (at most `max` `[x, y]`) or
    /// `pens` (at most `max` `{tag, color}`, a trend's).
    #[ts(type = "'number' | 'bool' | 'color' | 'choice' | 'intervals' | 'text' | 'tag' | 'points' | 'pens'")]
    pub kind: &'static str,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub unit: String,
    pub choices: Vec<String>,
    pub help: String,
    /// Still read, no longer offered by the form.
    pub legacy: bool,
}

/// A route of `ROUTE_ROLES` and the role it needs (`null`: anybody).
#[derive(Debug, Clone, Serialize, TS)]
pub struct RouteRole {
    pub method: String,
    pub route: String,
    pub role: Option<RoleName>,
}

/// WebSocket: power flow of a monitored program.
#[derive(Debug, Clone, Serialize, TS)]
pub struct PowerMsg {
    #[ts(type = "'power'")]
    #[serde(rename = "type")]
    pub kind: &'static str,
    pub scan: u64,
    pub program: String,
    pub on: Vec<u32>,
}

/// WebSocket: an error answering a command.
#[derive(Debug, Clone, Serialize, TS)]
pub struct ErrorMsg {
    #[ts(type = "'error'")]
    #[serde(rename = "type")]
    pub kind: &'static str,
    pub error: String,
}

/// WebSocket: the alarm summary, at start and after every change of an
/// alarm's state (then `GET /api/alarms` has the list).
#[derive(Debug, Clone, Serialize, TS)]
pub struct AlarmsMsg {
    #[ts(type = "'alarms'")]
    #[serde(rename = "type")]
    pub kind: &'static str,
    #[serde(flatten)]
    #[ts(flatten)]
    pub stats: AlarmStats,
}

/// WebSocket: the status, every 500 ms and at each change of state.
#[derive(Debug, Clone, Serialize, TS)]
pub struct StatusMsg {
    #[ts(type = "'status'")]
    #[serde(rename = "type")]
    pub kind: &'static str,
    #[serde(flatten)]
    #[ts(flatten)]
    pub status: Status,
}

/// A place where a program names a tag: `GET /api/tags/{name}/uses`.
#[derive(Debug, Clone, Serialize, TS)]
pub struct TagUse {
    /// The program, as listed in alba.toml.
    pub program: String,
    pub line: usize,
    pub col: usize,
    /// The rung (from 0), for a ladder program.
    pub rung: Option<usize>,
    /// The compiled element's id (the ids of `GET /api/programs/{name}`).
    pub id: Option<u32>,
    /// The instruction as written: `XIC(FILL)`, `LD I0.0`.
    pub instruction: String,
    /// The instruction writes the tag there (an output operand of a ladder
    /// instruction); IL uses are all marked as reads.
    pub write: bool,
}

/// The studio's trend set, kept in the project as `trends.json`
/// (`GET|PUT /api/trends`, docs/file-formats.md).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize, TS)]
#[serde(deny_unknown_fields)]
pub struct TrendSet {
    /// Format version: 1.
    pub version: u32,
    /// The live window, 1 s to 7 days.
    pub window_ms: u64,
    /// The pens, in legend order (at most 32).
    pub pens: Vec<TrendPen>,
}

/// One pen of a trend set.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize, TS)]
#[serde(deny_unknown_fields)]
pub struct TrendPen {
    /// A tag or member holding a BOOL or a number.
    pub tag: String,
    /// Another node of a shared historian whose recorded tag this is
    /// (drawn from its history, not live); none: this runtime's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[ts(optional)]
    pub node: Option<String>,
    /// The y axis (1 to 4) it shares with the other pens of that number;
    /// BOOL pens are drawn as steps on lanes of their own whatever it says.
    pub axis: u8,
    /// A fixed scale (both or neither); none: automatic.
    pub min: Option<f64>,
    pub max: Option<f64>,
}

// The Verify & Test page (`POST /api/verify`, `POST /api/tests`; crate::verify).

/// One row of a counterexample or witness stimulus (`time_ms,tag,value`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct StimulusRow {
    pub time_ms: u64,
    pub tag: String,
    pub value: String,
}

/// One scan of a replay.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct ReplayScan {
    pub time_ms: u64,
    /// Parallel to [`Replay::tags`].
    pub values: Vec<String>,
    /// Program elements (the power-flow ids of `/api/ws`) energised at the end of the scan.
    pub on: Vec<u32>,
}

/// A counterexample (or witness) replayed through the engine as `alba sim` replays it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct Replay {
    /// The stimulus file's rows.
    pub rows: Vec<StimulusRow>,
    /// The scan (0-based, in `scans`) where the property fails (a witness: holds).
    pub violating_scan: u32,
    /// The number (0-based) of `scans[0]` in the whole run: a long one keeps only its
    /// last 2 000 scans.
    pub first_scan: u32,
    pub tags: Vec<String>,
    pub scans: Vec<ReplayScan>,
}

/// `POST /api/verify`: one property's answer.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct PropertyResult {
    pub name: String,
    /// `proved`, `refuted` or `unknown`.
    pub result: String,
    /// Scans of the counterexample or witness, else the depth searched.
    pub depth: u32,
    pub states: u64,
    pub millis: u64,
    /// Why `unknown`.
    pub reason: Option<String>,
    /// How it was decided: `explicit` (the search on the engine) or `k-induction` (SAT).
    pub method: String,
    /// A refuted property's counterexample.
    pub counterexample: Option<Replay>,
    /// A `reachable` property's witness.
    pub witness: Option<Replay>,
}

/// `POST /api/verify`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct VerifyReply {
    pub scan_ms: u32,
    pub properties: Vec<PropertyResult>,
}

/// `POST /api/tests`: one table's result.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct TestCaseResult {
    pub name: String,
    /// `tests/<name>.test.csv`.
    pub file: String,
    /// `passed`, `failed` or `error`.
    pub result: String,
    /// Cells checked (passed tables).
    pub checks: u64,
    /// The first wrong cell (failed) or the error, in words.
    pub message: Option<String>,
    /// The failing cell's line in the table.
    pub line: Option<u64>,
    pub scans: u64,
    pub millis: u64,
}

/// Coverage of one program by all the tables together.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct ProgramCoverage {
    pub program: String,
    /// Its elements (power-flow ids), and those that ever carried power.
    pub elements: Vec<u32>,
    pub powered: Vec<u32>,
    /// Elements that always had power (never switched off).
    pub always: Vec<u32>,
}

/// `POST /api/tests`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct TestsReply {
    pub tests: Vec<TestCaseResult>,
    pub passed: u64,
    pub failed: u64,
    pub rungs: u64,
    pub rungs_powered: u64,
    pub branches: u64,
    pub branches_powered: u64,
    pub instructions: u64,
    pub switched: u64,
    /// Rungs never powered and instructions never switched, as `alba test` prints them.
    pub rungs_never: Vec<String>,
    pub never_switched: Vec<String>,
    pub coverage: Vec<ProgramCoverage>,
}

/// The TypeScript of every reply type, as `web/src/api.gen.ts` holds it.
pub fn typescript() -> String {
    let cfg = ts_rs::Config::new().with_large_int("number");
    let mut out = String::from(
        "// Generated from crates/server/src/reply.rs by `UPDATE_BINDINGS=1 cargo test -p alba-server`: do not edit.\n\n\
         /** Any JSON value. */\n\
         export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };\n",
    );
    macro_rules! decl {
        ($($t:ty),* $(,)?) => {
            $(
                out.push('\n');
                out.push_str("export ");
                out.push_str(&<$t as TS>::decl(&cfg));
                out.push('\n');
            )*
        };
    }
    decl!(
        Stats,
        RunState,
        Problem,
        Status,
        Connection,
        QueueCounters,
        BrowseNode,
        OpcuaBrowse,
        TrendSet,
        TrendPen,
        ScreenDomain,
        ParamTable,
        ParamInfo,
        TagUse,
        Access,
        TagInfo,
        TagValue,
        TagReply,
        Force,
        Language,
        ProgramRef,
        Diagnostic,
        InstrJson,
        BranchJson,
        ElementJson,
        RungJson,
        IlLine,
        NetTransition,
        MarkingValue,
        NetReset,
        Program,
        Checked,
        Saved,
        Domain,
        DomainReply,
        RouteRole,
        TypeInfo,
        MemberInfo,
        GroupInfo,
        ArgInfo,
        InstructionInfo,
        OptionalInfo,
        HistoryTag,
        Bucket,
        History,
        HistoryRaw,
        HistoryNodes,
        AlarmReply,
        AlarmStats,
        AuditOutcome,
        AuditRow,
        AuditPage,
        ErrorReply,
        RoleName,
        Login,
        Me,
        PowerMsg,
        ErrorMsg,
        StatusMsg,
        AlarmsMsg,
        SerialPortInfo,
        BoardPin,
        BoardModel,
        PinProblem,
        PinRow,
        JobState,
        HardwareJob,
        HardwareView,
        Attachment,
        BuildSizes,
        JobStarted,
        Verified,
        BoardIdentity,
        StimulusRow,
        ReplayScan,
        Replay,
        PropertyResult,
        VerifyReply,
        TestCaseResult,
        ProgramCoverage,
        TestsReply,
    );
    out
}
