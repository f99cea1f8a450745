// The JSON shapes of docs/api.md. The replies are generated from the
// server's types (crates/server/src/reply.rs → api.gen.ts, checked by
// `cargo test -p alba-server contract`); this file keeps the studio's names.

import type * as G from './api.gen';

export type Json = G.Json;
export type Stats = G.Stats;
export type Status = G.Status;
/** A client connection of `alba run` (`[[opcua_server]]`, the MQTT broker), in the status. */
export type Connection = G.Connection;
/** The MQTT client's queue counters of a connection. */
export type QueueCounters = G.QueueCounters;
/** `GET /api/opcua/{server}/browse` and its children. */
export type OpcuaBrowse = G.OpcuaBrowse;
export type BrowseNode = G.BrowseNode;
export type Access = G.Access;
export type TagInfo = G.TagInfo;
/** `GET /api/tags/{name}`: a tag of tags.csv, or a member or an address. */
export type TagReply = G.TagReply;
export type Force = G.Force;
export type ProgramRef = G.ProgramRef;
export type Diagnostic = G.Diagnostic;
export type ElementJson = G.ElementJson;
export type InstrJson = Extract<ElementJson, { kind: 'instr' }>;
export type BranchJson = Extract<ElementJson, { kind: 'branch' }>;
export type RungJson = G.RungJson;
export type Program = G.Program;
export type NetReset = G.NetReset;
export type Checked = G.Checked;
export type Saved = G.Saved;
/** One history bucket: [t_ms, min, max, first, last]. */
export type Bucket = G.Bucket;
export type History = G.History;
/** `GET /api/history/nodes`. */
export type HistoryNodes = G.HistoryNodes;
export type HistoryTag = G.HistoryTag;
/** `GET|PUT /api/trends`: the trend set saved in the project. */
export type TrendSet = G.TrendSet;
export type TrendPen = G.TrendPen;
/** `GET /api/tags/{name}/uses`. */
export type TagUse = G.TagUse;
/** Every error reply: `{error}`, with `diagnostics` for an edit that does not compile. */
export type ErrorReply = G.ErrorReply;

// WebSocket messages (server → client). `values` is written by hand on the
// server (crates/server/src/ws.rs, for speed): its shape is kept here.
export interface ValuesMsg {
  type: 'values';
  scan: number;
  t_ms: number;
  values: Record<string, Json>;
}
export type PowerMsg = G.PowerMsg;
export type StatusMsg = G.StatusMsg;
export type ErrorMsg = G.ErrorMsg;
export type AlarmsMsg = G.AlarmsMsg;
export type ServerMsg = ValuesMsg | PowerMsg | StatusMsg | ErrorMsg | AlarmsMsg;
/** An alarm (`GET /api/alarms`) and the summary (`GET /api/alarms/stats`, WebSocket `alarms`). */
export type Alarm = G.AlarmReply;
export type AlarmStats = G.AlarmStats;
