// Generated from crates/server/src/reply.rs by `UPDATE_BINDINGS=1 cargo test -p alba-server`: do not edit.

/** Any JSON value. */
export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };

export type Stats = { last_us: number, min_us: number, max_us: number, mean_us: number, jitter_us: number, overruns: number, };

export type RunState = "running" | "stopped" | "faulted";

export type Problem = { 
/**
 * `retain` (restoring at start), `retain-save`, `history`,
 * `history-damaged`, `history-disk`, `history-cap`.
 */
source: string, message: string, since_unix_ms: number, };

export type Status = { project: string, state: RunState, fault: string | null, scan_ms: number, scans: number, time_ms: number, stats: Stats, minor_faults: number, io: string, programs: Array<string>, clients: number, 
/**
 * Retain saves, the historian and disk space are all healthy
 * (`S:STOREOK`).
 */
store_ok: boolean, 
/**
 * Retentive data was lost at start (`S:RETAINLOST`).
 */
retain_lost: boolean, 
/**
 * What is wrong with the runtime's stores now, oldest first
 * (docs/reliability.md).
 */
problems: Array<Problem>, 
/**
 * The forces in effect (as `GET /api/forces`), for the studio's
 * "forces active" banner.
 */
forces: Array<Force>, 
/**
 * The health of each client connection to a remote server
 * (`[[opcua_server]]`, the MQTT broker); empty without any.
 */
connections: Array<Connection>, };

export type Connection = { 
/**
 * The server's `name` in alba.toml; `mqtt` for the broker.
 */
name: string, 
/**
 * `opcua`, `mqtt` (JSON) or `sparkplug`.
 */
protocol: string, endpoint: string, 
/**
 * Connected, with every binding accepted (Sparkplug with a primary
 * host: born, the host online).
 */
ok: boolean, 
/**
 * A session is open (bindings may still be refused).
 */
connected: boolean, 
/**
 * Sessions opened since `alba run` started (reconnections: one less).
 */
connects: number, 
/**
 * Failed attempts and losses.
 */
errors: number, 
/**
 * Why it is down or unhealthy (`null` while ok).
 */
last_error: string | null, 
/**
 * MQTT only: the outgoing queue's counters since `alba run` started.
 */
queue: QueueCounters | null, };

export type QueueCounters = { 
/**
 * Messages handed to the connection (tag values, DDATA, replayed ones included).
 */
published: number, 
/**
 * Changes the full queue could not take: they went with a later
 * snapshot, the intermediate values coalesced.
 */
coalesced: number, 
/**
 * Values lost: store-and-forward records past `buffer_max` (the
 * oldest), unreadable, or of metrics the current birth does not have.
 */
dropped: number, 
/**
 * Sparkplug store and forward: records waiting on disk, and sent from it.
 */
buffered: number, replayed: number, 
/**
 * The queue's bound (`[mqtt] queue`).
 */
capacity: number, };

export type BrowseNode = { 
/**
 * Its node id as the server answers it (`ns=2;s=Tank.Level`, `i=2253`).
 */
node: string, 
/**
 * The same with the namespace's URI (`nsu=urn:plant;s=Tank.Level`), what a
 * binding should say; `null` in namespace 0.
 */
node_uri: string | null, browse_name: string, display_name: string, 
/**
 * `Object`, `Variable`, `Method`, `ObjectType`, …
 */
class: string, 
/**
 * A variable's data type (`Double`, `Int32`, `Boolean`, or a type's node id).
 */
data_type: string | null, };

export type OpcuaBrowse = { server: string, 
/**
 * The node browsed.
 */
node: string, children: Array<BrowseNode>, };

export type TrendSet = { 
/**
 * Format version: 1.
 */
version: number, 
/**
 * The live window, 1 s to 7 days.
 */
window_ms: number, 
/**
 * The pens, in legend order (at most 32).
 */
pens: Array<TrendPen>, };

export type TrendPen = { 
/**
 * A tag or member holding a BOOL or a number.
 */
tag: string, 
/**
 * Another node of a shared historian whose recorded tag this is
 * (drawn from its history, not live); none: this runtime's.
 */
node?: string, 
/**
 * The y axis (1 to 4) it shares with the other pens of that number;
 * BOOL pens are drawn as steps on lanes of their own whatever it says.
 */
axis: number, 
/**
 * A fixed scale (both or neither); none: automatic.
 */
min: number | null, max: number | null, };

export type ScreenDomain = { 
/**
 * `[type, what it is]`, AuroraLD's 30.
 */
elements: Array<[string, string]>, 
/**
 * Each element type's own properties (besides `label`, `tag`, `alarm`).
 */
properties: Array<ParamTable>, 
/**
 * The animations and their parameters besides `tag`.
 */
animations: Array<ParamTable>, actions: Array<string>, };

export type ParamTable = { kind: string, params: Array<ParamInfo>, };

export type ParamInfo = { name: string, 
/**
 * `number` (from `min` to `max`, in `unit`), `bool`, `color`, `choice`
 * (one of `choices`), `intervals` (up to 4 `{from, color}`), `text` (at
 * most `max` characters), `tag`, `points` (at most `max` `[x, y]`) or
 * `pens` (at most `max` `{tag, color}`, a trend's).
 */
kind: 'number' | 'bool' | 'color' | 'choice' | 'intervals' | 'text' | 'tag' | 'points' | 'pens', min: number | null, max: number | null, unit: string, choices: Array<string>, help: string, 
/**
 * Still read, no longer offered by the form.
 */
legacy: boolean, };

export type TagUse = { 
/**
 * The program, as listed in alba.toml.
 */
program: string, line: number, col: number, 
/**
 * The rung (from 0), for a ladder program.
 */
rung: number | null, 
/**
 * The compiled element's id (the ids of `GET /api/programs/{name}`).
 */
id: number | null, 
/**
 * The instruction as written: `XIC(FILL)`, `LD I0.0`.
 */
instruction: string, 
/**
 * The instruction writes the tag there (an output operand of a ladder
 * instruction); IL uses are all marked as reads.
 */
write: boolean, };

export type Access = "readwrite" | "input" | "readonly";

export type TagInfo = { name: string, type: string, address: string | null, 
/**
 * Every notation of the address (AuroraLD, IEC, S7), upper case; empty without one.
 */
notations: Array<string>, description: string, retain: boolean, access: Access, 
/**
 * A value, or an object of a structure's members.
 */
value: Json, 
/**
 * The forced value, `null` if not forced.
 */
forced: Json, };

export type TagValue = { name: string, type: string, access: Access, value: Json, forced: Json, };

export type TagReply = TagInfo | TagValue;

export type Force = { name: string, value: Json, };

export type Language = "ladder" | "il" | "net" | "sfc" | "st";

export type ProgramRef = { name: string, language: Language, plant: boolean, };

export type Diagnostic = { code: string, severity: string, message: string, file: string | null, line: number | null, col: number | null, end_line: number | null, end_col: number | null, help: string | null, };

export type InstrJson = { 
/**
 * The id of the compiled element (power flow), if compiled.
 */
id: number | null, mnemonic: string, operands: Array<string>, line: number, col: number, };

export type BranchJson = { id: number | null, line: number, col: number, legs: Array<Array<ElementJson>>, };

export type ElementJson = { "kind": "instr" } & InstrJson | { "kind": "branch" } & BranchJson;

export type RungJson = { number: number, comment: Array<string>, line: number, elements: Array<ElementJson>, };

export type IlLine = { line: number, id: number | null, };

export type NetTransition = { 
/**
 * The transition's PNML id.
 */
id: string, enabled: number | null, fired: number | null, };

export type MarkingValue = { tag: string, value: number, };

export type NetReset = { 
/**
 * The net's program, as listed (`line.pnml`).
 */
program: string, marking: Array<MarkingValue>, };

export type Program = { name: string, language: Language, plant: boolean, text: string, diagnostics: Array<Diagnostic>, 
/**
 * Ladder programs.
 */
rungs?: Array<RungJson>, 
/**
 * IL programs.
 */
lines?: Array<IlLine>, 
/**
 * Net programs: each transition's monitored elements, in document order.
 */
transitions?: Array<NetTransition>, };

export type Checked = { 
/**
 * Always empty (a program that does not compile is an error reply).
 */
diagnostics: Array<Diagnostic>, rungs?: Array<RungJson>, lines?: Array<IlLine>, };

export type Saved = { diagnostics: Array<Diagnostic>, applied: boolean, };

export type Domain = { 
/**
 * Every data type a tag may have, elementary ones first.
 */
types: Array<TypeInfo>, 
/**
 * Palette groups in palette order.
 */
groups: Array<GroupInfo>, 
/**
 * Kinds of operands (the `args` of instructions).
 */
args: Array<ArgInfo>, 
/**
 * Every ladder instruction, grouped in palette order.
 */
instructions: Array<InstructionInfo>, };

export type DomainReply = { 
/**
 * The routes with their own rule; any other route needs `viewer` for
 * GET and `admin` for anything else.
 */
routes: Array<RouteRole>, 
/**
 * What a SCADA screen may hold (hmi/*.json): for the designer.
 */
screens: ScreenDomain, 
/**
 * Every data type a tag may have, elementary ones first.
 */
types: Array<TypeInfo>, 
/**
 * Palette groups in palette order.
 */
groups: Array<GroupInfo>, 
/**
 * Kinds of operands (the `args` of instructions).
 */
args: Array<ArgInfo>, 
/**
 * Every ladder instruction, grouped in palette order.
 */
instructions: Array<InstructionInfo>, };

export type RouteRole = { method: string, route: string, role: Role | null, };

export type TypeInfo = { name: string, 
/**
 * `bool`, `integer`, `real` or `structure`.
 */
kind: 'bool' | 'integer' | 'real' | 'structure', 
/**
 * Members of a structure, in order (empty for elementary types).
 */
members: Array<MemberInfo>, };

export type MemberInfo = { name: string, type: string, 
/**
 * Programs and the API may write it (else the instruction sets it).
 */
writable: boolean, };

export type GroupInfo = { name: string, title: string, };

export type ArgInfo = { name: string, 
/**
 * What the checker expects there.
 */
doc: string, 
/**
 * Types of the tags (and members) that fit; empty when only literals or
 * labels do.
 */
types: Array<string>, 
/**
 * Only writable tags and members fit.
 */
writable: boolean, 
/**
 * Members of structures of those types fit too (`T1.DN`, `T1.PRE`).
 */
members: boolean, 
/**
 * The operand names one tag, member or address whose value can be shown
 * (false for labels, expressions and literal-only places).
 */
tag: boolean, };

export type InstructionInfo = { mnemonic: string, group: string, 
/**
 * Output instructions may end a rung; inputs are conditions.
 */
output: boolean, 
/**
 * How the ladder diagram draws it: `contact`, `coil` or `box`.
 */
shape: 'contact' | 'coil' | 'box', 
/**
 * One argument kind per operand (names of `args`).
 */
args: Array<string>, 
/**
 * One label per operand.
 */
labels: Array<string>, title: string, doc: string, 
/**
 * Status bits of the structure in the first operand, shown in the box header.
 */
bits: Array<string>, 
/**
 * Per operand, the live value shown beside it: `null` none, `""` the
 * operand's own value, else that member of the first operand (a
 * timer's literal preset row shows `PRE`).
 */
shows: Array<string | null>, 
/**
 * Operands that may follow the ones of `args`, in order, each with
 * its default when left out (a TON's time base: `TON(T,5,0,s)`).
 */
optional: Array<OptionalInfo>, };

export type OptionalInfo = { 
/**
 * Its kind (`time_base`).
 */
name: string, label: string, 
/**
 * What fits there, in words.
 */
doc: string, 
/**
 * The values to offer (the checker also takes other spellings, such
 * as a time base in seconds, `0.01`).
 */
choices: Array<string>, 
/**
 * What applies when the operand is left out.
 */
default: string, };

export type HistoryTag = { name: string, first_ms: number, last_ms: number, };

export type Bucket = [number, number | null, number | null, number | null, number | null];

export type History = { 
/**
 * The node whose tag it is (this runtime's unless the query named another).
 */
node: string, tag: string, from: number, to: number, buckets: Array<Bucket>, };

export type HistoryRaw = { node: string, tag: string, from: number, to: number, points: Array<[number, number]>, 
/**
 * More samples lie in the range than `limit` let through.
 */
more: boolean, };

export type HistoryNodes = { 
/**
 * This runtime's node id (its project's name with the embedded store).
 */
node: string, 
/**
 * The store is shared with other runtimes (`[history] backend = "postgres"`).
 */
shared: boolean, 
/**
 * Every node with history, this one included, by id.
 */
nodes: Array<string>, };

export type AlarmReply = { id: string, tag: string, state: string, severity: number, message: string, since_ms: number, condition: string, 
/**
 * The tag's value at the last evaluation.
 */
value: number, 
/**
 * The process is in alarm (the condition holds, after on-delay and deadband).
 */
active: boolean, acked_by: string | null, ack_comment: string | null, acked_ms: number | null, shelved_until_ms: number | null, 
/**
 * Why it is shelved or out of service, and by whom.
 */
reason: string | null, by: string | null, };

export type AlarmStats = { alarms: number, active: number, unacked: number, shelved: number, suppressed: number, out_of_service: number, new_10min: number, flood: boolean, top_unacked: string | null, top_severity: number | null, };

export type AuditOutcome = "pending" | "ok" | "failed";

export type AuditRow = { 
/**
 * Increasing in the order rows were written; `before` of the next page.
 */
id: number, 
/**
 * Unix ms.
 */
time_ms: number, 
/**
 * `null` when no users are configured.
 */
user: string | null, 
/**
 * The client's `ip:port`.
 */
addr: string | null, 
/**
 * `write`, `force`, `unforce`, `save_program`, `online_edit`, `save_tags`, `run`,
 * `stop`, `login`, `login_failed`, `logout`, `user_added`, `user_changed`,
 * `user_removed`, `alarm_ack`.
 */
action: string, target: string | null, 
/**
 * The value before and after (JSON; a string if the stored text is not JSON).
 */
old: Json, new: Json, 
/**
 * A diff summary for saves.
 */
detail: string | null, outcome: AuditOutcome, 
/**
 * Why it failed.
 */
error: string | null, 
/**
 * The door it came through: `http`, `mqtt`, `opcua`, `modbus`
 * (`null` in rows written before doors were recorded).
 */
via: string | null, };

export type AuditPage = { rows: Array<AuditRow>, next: number | null, };

export type ErrorReply = { error: string, diagnostics?: Array<Diagnostic>, };

export type Role = "viewer" | "operator" | "engineer" | "admin";

export type Login = { token: string, user: string, role: Role, };

export type Me = { user: string | null, role: Role, users: boolean, };

export type PowerMsg = { type: 'power', scan: number, program: string, on: Array<number>, };

export type ErrorMsg = { type: 'error', error: string, };

export type StatusMsg = { type: 'status', project: string, state: RunState, fault: string | null, scan_ms: number, scans: number, time_ms: number, stats: Stats, minor_faults: number, io: string, programs: Array<string>, clients: number, 
/**
 * Retain saves, the historian and disk space are all healthy
 * (`S:STOREOK`).
 */
store_ok: boolean, 
/**
 * Retentive data was lost at start (`S:RETAINLOST`).
 */
retain_lost: boolean, 
/**
 * What is wrong with the runtime's stores now, oldest first
 * (docs/reliability.md).
 */
problems: Array<Problem>, 
/**
 * The forces in effect (as `GET /api/forces`), for the studio's
 * "forces active" banner.
 */
forces: Array<Force>, 
/**
 * The health of each client connection to a remote server
 * (`[[opcua_server]]`, the MQTT broker); empty without any.
 */
connections: Array<Connection>, };

export type AlarmsMsg = { type: 'alarms', alarms: number, active: number, unacked: number, shelved: number, suppressed: number, out_of_service: number, new_10min: number, flood: boolean, top_unacked: string | null, top_severity: number | null, };

export type SerialPortInfo = { 
/**
 * The device path (`/dev/ttyUSB0`, a pty of the emulated board).
 */
path: string, 
/**
 * What is known of it: USB vendor:product, maker and product names,
 * its `/dev/serial/by-id` name; `alba.toml [board] port` for the
 * project's own port.
 */
description: string, };

export type BoardPin = { 
/**
 * As the Arduino IDE names it (`D13`, `A6`).
 */
pin: string, 
/**
 * `di`, `do`, `ai`, `ao` (PWM): the directions of `[board]` it may serve;
 * `serial` for D0/D1 (the link to the PC).
 */
caps: Array<string>, };

export type BoardModel = { 
/**
 * `uno`, `nano`, `mega`.
 */
name: string, 
/**
 * `Arduino Nano`.
 */
title: string, flash_max: number, ram_max: number, pins: Array<BoardPin>, };

export type PinProblem = { 
/**
 * `E102` (alba.toml `[board]`), `E501` (the program uses a channel the board cannot serve).
 */
code: string, message: string, };

export type PinRow = { 
/**
 * `di`, `do`, `ai` or `ao`.
 */
dir: string, channel: number, 
/**
 * `DI:1/0`.
 */
address: string, 
/**
 * `D2`; `null` for a channel the program uses and the map does not wire.
 */
pin: string | null, 
/**
 * Tags of tags.csv at this address.
 */
tags: Array<string>, problem: PinProblem | null, };

export type JobState = "running" | "done" | "failed";

export type HardwareJob = { id: string, 
/**
 * `download` or `upload`.
 */
kind: string, port: string, state: JobState, 
/**
 * 0 to 100.
 */
progress: number, 
/**
 * What it is doing, what it did, or why it failed, in words.
 */
message: string, 
/**
 * When it started (ms since the epoch).
 */
started_ms: number, };

export type HardwareView = { 
/**
 * `[board] model` of alba.toml (`uno`, `nano`, `mega`); `null` without `[board]`.
 */
board: string | null, 
/**
 * `[board] pinmap`: the preset the map starts from (`aurora`, `s7`, `openplc`).
 */
pinmap: string, 
/**
 * Outputs on when the pin is low.
 */
active_low: boolean, 
/**
 * `[board] port`: the project's serial port, if set.
 */
port: string | null, ports: Array<SerialPortInfo>, 
/**
 * Every board with its limits and pins.
 */
boards: Array<BoardModel>, presets: Array<string>, 
/**
 * The pin map as a table, with each channel's problem.
 */
pins: Array<PinRow>, 
/**
 * The project's `[board]` problems (and any other that stops the build), as `alba check` gives them.
 */
diagnostics: Array<Diagnostic>, 
/**
 * Recent jobs, newest first (kept while `alba run` runs).
 */
jobs: Array<HardwareJob>, 
/**
 * The board used as the running PLC's I/O now (`POST /api/hardware/attach`);
 * `null`: the project's own I/O (`io`).
 */
attached: Attachment | null, 
/**
 * The I/O driver `alba run` was started with (`--io`: `sim`, `arduino:…`),
 * back after a detach.
 */
io: string, 
/**
 * Board saves of this run that Undo can take back (`POST /api/hardware/board/undo`).
 */
undo: number, };

export type Attachment = { port: string, 
/**
 * `controller` (the board's pins are the program's I/O) or `monitor`
 * (the board runs the sketch; its memory is watched).
 */
mode: string, 
/**
 * The I/O driver now (`arduino:/dev/ttyUSB0`, `board:/dev/ttyUSB0`).
 */
io: string, 
/**
 * When it was attached (ms since the epoch).
 */
since_ms: number, 
/**
 * In words.
 */
message: string, };

export type BuildSizes = { board: string, 
/**
 * `sketch`, `interpreter` or `controller`.
 */
kind: string, flash_bytes: number, ram_bytes: number, flash_max: number, ram_max: number, 
/**
 * The toolchain's report (`nano: flash … of … bytes …`).
 */
report: string, };

export type JobStarted = { job: string, };

export type Verified = { port: string, 
/**
 * The board holds exactly the project's byte code.
 */
same: boolean, 
/**
 * Bytes of the project's byte code.
 */
bytes: number, 
/**
 * In words (where it differs, the program ids).
 */
message: string, };

export type BoardIdentity = { port: string, 
/**
 * `false`: something answered that is not Alba's interpreter, or nothing did ("unknown device").
 */
known: boolean, 
/**
 * `nano` (the interpreter's own word).
 */
board: string | null, 
/**
 * Byte-code format of the interpreter.
 */
format: number | null, 
/**
 * Board id (board, pin map, polarity) in hex.
 */
board_id: string | null, 
/**
 * `running`, `no_program`, `faulted`.
 */
state: string | null, 
/**
 * The running program's id in hex, when a program checks.
 */
program: string | null, 
/**
 * In words.
 */
message: string, };

export type StimulusRow = { time_ms: number, tag: string, value: string, };

export type ReplayScan = { time_ms: number, 
/**
 * Parallel to [`Replay::tags`].
 */
values: Array<string>, 
/**
 * Program elements (the power-flow ids of `/api/ws`) energised at the end of the scan.
 */
on: Array<number>, };

export type Replay = { 
/**
 * The stimulus file's rows.
 */
rows: Array<StimulusRow>, 
/**
 * The scan (0-based, in `scans`) where the property fails (a witness: holds).
 */
violating_scan: number, 
/**
 * The number (0-based) of `scans[0]` in the whole run: a long one keeps only its
 * last 2 000 scans.
 */
first_scan: number, tags: Array<string>, scans: Array<ReplayScan>, };

export type PropertyResult = { name: string, 
/**
 * `proved`, `refuted` or `unknown`.
 */
result: string, 
/**
 * Scans of the counterexample or witness, else the depth searched.
 */
depth: number, states: number, millis: number, 
/**
 * Why `unknown`.
 */
reason: string | null, 
/**
 * How it was decided: `explicit` (the search on the engine) or `k-induction` (SAT).
 */
method: string, 
/**
 * A refuted property's counterexample.
 */
counterexample: Replay | null, 
/**
 * A `reachable` property's witness.
 */
witness: Replay | null, };

export type VerifyReply = { scan_ms: number, properties: Array<PropertyResult>, };

export type TestCaseResult = { name: string, 
/**
 * `tests/<name>.test.csv`.
 */
file: string, 
/**
 * `passed`, `failed` or `error`.
 */
result: string, 
/**
 * Cells checked (passed tables).
 */
checks: number, 
/**
 * The first wrong cell (failed) or the error, in words.
 */
message: string | null, 
/**
 * The failing cell's line in the table.
 */
line: number | null, scans: number, millis: number, };

export type ProgramCoverage = { program: string, 
/**
 * Its elements (power-flow ids), and those that ever carried power.
 */
elements: Array<number>, powered: Array<number>, 
/**
 * Elements that always had power (never switched off).
 */
always: Array<number>, };

export type TestsReply = { tests: Array<TestCaseResult>, passed: number, failed: number, rungs: number, rungs_powered: number, branches: number, branches_powered: number, instructions: number, switched: number, 
/**
 * Rungs never powered and instructions never switched, as `alba test` prints them.
 */
rungs_never: Array<string>, never_switched: Array<string>, coverage: Array<ProgramCoverage>, };
