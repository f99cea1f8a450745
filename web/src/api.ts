// The HTTP API of docs/api.md. Every failure becomes an ApiError carrying the
// status and the server's `{"error", "diagnostics"?}` body.
import type { BoardIdentity, BuildSizes, HardwareJob, HardwareView, JobStarted, TestsReply, Verified, VerifyReply } from './api.gen';
import type { Domain } from './domain';
import { language } from './i18n';
import type { Alarm, AlarmStats, Diagnostic, Force, History, HistoryNodes, Json, NetReset, OpcuaBrowse, Program, ProgramRef, RungJson, Status, TagInfo, TagUse, TrendSet } from './types';

export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    readonly diagnostics: Diagnostic[] = [],
    /** Seconds to wait before trying again (429: `Retry-After`, or the body's `retry_after_s`). */
    readonly retryAfter: number | null = null,
  ) {
    super(message);
  }
}

/**
 * Called when the server answers 401 to anything but a login (the session
 * expired or was ended): main.ts shows the login page.
 */
let unauthorized: ((message: string) => void) | null = null;

export function onUnauthorized(f: ((message: string) => void) | null): void {
  unauthorized = f;
}

const SAFE = new Set(['GET', 'HEAD']);

/** A JSON body already written (kept as it is: pretty, so that the server's line:column point into a readable text). */
class RawJson {
  constructor(readonly text: string) {}
}

async function request(method: string, path: string, body?: unknown, contentType = 'application/json', signal?: AbortSignal): Promise<Response> {
  // The session is the cookie (same origin only). Every state-changing request
  // has a JSON body (an empty object when there is nothing to say), since the
  // server refuses any other (a cross-site form or text/plain post) — except
  // tags.csv, whose text/csv also needs a preflight the server never grants.
  // The studio's language, not the browser's: the server words diagnostics in it (docs/i18n.md).
  const headers: Record<string, string> = { 'Accept-Language': language() };
  const init: RequestInit = { method, headers, credentials: 'same-origin', signal };
  if (body === undefined && !SAFE.has(method)) body = {};
  if (body !== undefined) {
    init.body = body instanceof RawJson ? body.text : body instanceof Blob ? body : typeof body === 'string' && contentType !== 'application/json' ? body : JSON.stringify(body);
    headers['Content-Type'] = contentType;
  }
  let res: Response;
  try {
    res = await fetch(path, init);
  } catch (e) {
    if (signal?.aborted) throw e;
    throw new ApiError(0, `cannot reach the server: ${(e as Error).message}`);
  }
  if (!res.ok) {
    let msg = `${res.status} ${res.statusText}`;
    let diagnostics: Diagnostic[] = [];
    let retryAfter: number | null = null;
    const header = Number(res.headers.get('Retry-After'));
    if (res.headers.get('Retry-After') !== null && Number.isFinite(header)) retryAfter = header;
    try {
      const j = await res.json();
      if (j && typeof j.error === 'string') msg = j.error;
      if (j && Array.isArray(j.diagnostics)) diagnostics = j.diagnostics;
      for (const k of ['retry_after_s', 'retry_after']) if (retryAfter === null && j && typeof j[k] === 'number') retryAfter = j[k];
    } catch {
      /* not JSON */
    }
    if (res.status === 401 && path !== '/api/login') unauthorized?.(msg);
    throw new ApiError(res.status, msg, diagnostics, retryAfter);
  }
  return res;
}

async function json<T>(method: string, path: string, body?: unknown): Promise<T> {
  const res = await request(method, path, body);
  if (res.status === 204) return undefined as T;
  return (await res.json()) as T;
}

const enc = encodeURIComponent;

/** A progress line of `POST /api/nets/{name}/analysis` (docs/api.md "Nets"). */
export interface AnalysisProgress {
  part: 'state_space' | 'components' | 'flows' | 'invariants';
  states: number;
  bytes: number;
}

/**
 * POST /api/nets/{name}/analysis (`symbolic`: decision diagrams first): reads the answer's JSON lines, calling
 * `onProgress` for each progress line, and resolves with the last one's
 * result. Aborting `signal` closes the connection, which stops the analysis
 * on the server; the promise then rejects with the abort.
 */
async function netAnalysis<T>(name: string, symbolic: boolean, onProgress: (p: AnalysisProgress) => void, signal?: AbortSignal): Promise<{ result: T; timed_out: boolean }> {
  const res = await request('POST', `/api/nets/${enc(name)}/analysis`, symbolic ? { symbolic } : {}, 'application/json', signal);
  if (!res.body) throw new ApiError(0, 'the analysis answered nothing');
  const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
  let buf = '';
  for (;;) {
    const { value, done } = await reader.read();
    if (value) buf += value;
    let nl: number;
    while ((nl = buf.indexOf('\n')) >= 0) {
      const line = buf.slice(0, nl);
      buf = buf.slice(nl + 1);
      if (line.trim() === '') continue;
      const j = JSON.parse(line);
      if (j.progress) onProgress(j.progress as AnalysisProgress);
      else if (j.error) throw new ApiError(500, String(j.error));
      else if (j.result) return { result: j.result as T, timed_out: j.timed_out === true };
    }
    if (done) throw new ApiError(0, 'the analysis ended without a result');
  }
}

/** What `POST /api/pid/{name}/autotune` answers (docs/api.md "PID"). */
export interface Autotune {
  ku: number;
  pu: number;
  a: number;
  cycles: number;
  rules: { rule: string; kc: number; ti: number; td: number; kp: number; ki: number; kd: number }[];
}

export const api = {
  me: () => json<unknown>('GET', '/api/me'),
  login: (user: string, password: string) => json<unknown>('POST', '/api/login', { user, password }),
  logout: () => json<void>('POST', '/api/logout'),
  status: () => json<Status>('GET', '/api/status'),
  run: () => json<Status>('POST', '/api/run'),
  stop: () => json<Status>('POST', '/api/stop'),
  /** One scan of the stopped PLC (409 while it runs). */
  step: () => json<Status>('POST', '/api/step'),
  tags: () => json<TagInfo[]>('GET', '/api/tags'),
  writeTag: (name: string, value: Json) => json<{ name: string; value: Json }>('PUT', `/api/tags/${enc(name)}`, { value }),
  forces: () => json<Force[]>('GET', '/api/forces'),
  alarms: () => json<Alarm[]>('GET', '/api/alarms'),
  alarmStats: () => json<AlarmStats>('GET', '/api/alarms/stats'),
  ackAlarm: (id: string, comment: string) => json<Alarm>('POST', `/api/alarms/${enc(id)}/ack`, { comment }),
  shelveAlarm: (id: string, minutes: number, reason: string) => json<Alarm>('POST', `/api/alarms/${enc(id)}/shelve`, { minutes, reason }),
  unshelveAlarm: (id: string) => json<Alarm>('POST', `/api/alarms/${enc(id)}/unshelve`),
  alarmOutOfService: (id: string, on: boolean, reason: string) => json<Alarm>('POST', `/api/alarms/${enc(id)}/out_of_service`, { on, reason }),
  force: (name: string, value: Json) => json<Force>('PUT', `/api/forces/${enc(name)}`, { value }),
  unforce: (name: string) => json<void>('DELETE', `/api/forces/${enc(name)}`),
  unforceAll: () => json<void>('DELETE', '/api/forces'),
  programs: () => json<ProgramRef[]>('GET', '/api/programs'),
  program: (name: string) => json<Program>('GET', `/api/programs/${enc(name)}`),
  domain: () => json<Domain>('GET', '/api/domain'),
  check: (name: string, text: string) =>
    json<{ diagnostics: Diagnostic[]; rungs?: RungJson[] }>('POST', `/api/check/${enc(name)}`, { text }),
  saveProgram: (name: string, text: string, online = true) =>
    json<{ diagnostics: Diagnostic[]; applied: boolean }>('PUT', `/api/programs/${enc(name)}`, { text, online }),
  /** A GET answered with text (a CSV export). */
  text: async (path: string) => (await request('GET', path)).text(),
  tagsCsv: async () => (await request('GET', '/api/tags.csv')).text(),
  saveTagsCsv: (text: string) => request('PUT', '/api/tags.csv', text, 'text/csv').then((r) => r.json()),
  trends: () => json<TrendSet>('GET', '/api/trends'),
  recipes: () => json<string[]>('GET', '/api/recipes'),
  /** A recipe's entries `{tag: value}`, in the file's order. */
  recipe: (name: string) => json<Record<string, Json>>('GET', `/api/recipes/${enc(name)}`),
  saveRecipe: (name: string, csv: string) => request('PUT', `/api/recipes/${enc(name)}`, csv, 'text/csv').then((r) => r.json()),
  captureRecipe: (name: string, tags: string[]) => json<{ values: Record<string, Json> }>('POST', `/api/recipes/${enc(name)}/capture`, { tags }),
  applyRecipe: (name: string) => json<{ name: string; written: number }>('POST', `/api/recipes/${enc(name)}/apply`),
  screens: () => json<string[]>('GET', '/api/screens'),
  screen: (name: string) => json<unknown>('GET', `/api/screens/${enc(name)}`),
  // pretty, so that a refusal's line and column point into a readable file
  saveScreen: (name: string, screen: unknown) => json<unknown>('PUT', `/api/screens/${enc(name)}`, new RawJson(JSON.stringify(screen, null, 2))),
  checkScreen: (name: string, screen: unknown) => json<unknown>('POST', `/api/screens/${enc(name)}/check`, new RawJson(JSON.stringify(screen))),
  /** POST /api/nets/{name}/analysis: the analysis of a net of the project, with progress (docs/nets.md "Analysis"). */
  netAnalysis,
  /** POST /api/nets/{name}/reset: the net's initial marking, written at one scan boundary. */
  resetNet: (name: string) => json<NetReset>('POST', `/api/nets/${enc(name)}/reset`),
  /** GET /api/opcua/{server}/browse: the children of a node of a remote OPC UA server (the Objects folder by default). */
  opcuaBrowse: (server: string, node?: string) =>
    json<OpcuaBrowse>('GET', `/api/opcua/${enc(server)}/browse${node ? `?node=${enc(node)}` : ''}`),
  autotune: (loop: string, req: Record<string, number>) => json<Autotune>('POST', `/api/pid/${enc(loop)}/autotune`, req),
  symbols: () => json<string[]>('GET', '/api/symbols'),
  symbol: (name: string) => json<unknown>('GET', `/api/symbols/${enc(name)}`),
  /** The project's images (hmi/assets/), by name. */
  assets: () => json<string[]>('GET', '/api/assets'),
  /** Uploads an image into the project's hmi/assets/ (PNG, JPEG, GIF; an SVG only if nothing in it can run or load). */
  putAsset: (name: string, image: Blob) => request('PUT', `/api/assets/${enc(name)}`, image, image.type || 'application/octet-stream').then(() => undefined),
  saveSymbol: (name: string, symbol: unknown) => json<unknown>('PUT', `/api/symbols/${enc(name)}`, new RawJson(JSON.stringify(symbol, null, 2))),
  saveTrends: (s: TrendSet) => json<TrendSet>('PUT', '/api/trends', s),
  uses: (name: string) => json<TagUse[]>('GET', `/api/tags/${enc(name)}/uses`),
  /** The nodes whose history this runtime reads (others only with a shared historian). */
  historyNodes: () => json<HistoryNodes>('GET', '/api/history/nodes'),
  /** The recorded tags of this runtime, or of another node of a shared historian. */
  historyTags: (node?: string) =>
    json<{ name: string; first_ms: number; last_ms: number }[]>('GET', `/api/history/tags${node ? `?node=${enc(node)}` : ''}`),
  history: (tag: string, from: number, to: number, points: number, node?: string) =>
    json<History>(
      'GET',
      `/api/history?tag=${enc(tag)}&from=${Math.floor(from)}&to=${Math.ceil(to)}&points=${Math.max(1, Math.min(10000, Math.round(points)))}${node ? `&node=${enc(node)}` : ''}`,
    ),
  /** GET /api/hardware: the board, its pin map, the machine's serial ports, recent jobs (docs/api.md "Hardware"). */
  hardware: () => json<HardwareView>('GET', '/api/hardware'),
  /** POST /api/verify: the saved project's properties decided, counterexamples replayed (docs/verify.md "In the studio"). */
  verify: (property?: string) => json<VerifyReply>('POST', '/api/verify', property ? { property } : {}),
  /** POST /api/tests: the test tables run, with coverage. */
  runTests: () => json<TestsReply>('POST', '/api/tests', {}),
  /** PUT /api/hardware/board: `[board]` saved into alba.toml (422 with the diagnostics when it does not check). */
  saveBoard: (body: Record<string, unknown>) => json<HardwareView>('PUT', '/api/hardware/board', body),
  /** POST /api/hardware/board/undo: `[board]` as it was before the last save (409: nothing to undo). */
  hardwareUndoBoard: () => json<HardwareView>('POST', '/api/hardware/board/undo'),
  hardwareBuild: (board: string, kind: string) => json<BuildSizes>('POST', '/api/hardware/build', { board, kind }),
  hardwareDownload: (port: string) => json<JobStarted>('POST', '/api/hardware/download', { port }),
  /** POST /api/hardware/upload: a job that builds the firmware and uploads it with avrdude. */
  hardwareUpload: (port: string, board: string, kind: string) => json<JobStarted>('POST', '/api/hardware/upload', { port, board, kind }),
  hardwareJob: (id: string) => json<HardwareJob>('GET', `/api/hardware/jobs/${enc(id)}`),
  /** POST /api/hardware/jobs/{id}/cancel: the board drops the records it had and runs its program on. */
  hardwareCancel: (id: string) => json<HardwareJob>('POST', `/api/hardware/jobs/${enc(id)}/cancel`),
  hardwareIdentify: (port: string) => json<BoardIdentity>('POST', '/api/hardware/identify', { port }),
  /** POST /api/hardware/verify: the board's running program read back against the project's byte code. */
  hardwareVerify: (port: string) => json<Verified>('POST', '/api/hardware/verify', { port }),
  /** POST /api/hardware/attach: the board as the running PLC's I/O (`controller`) or watched (`monitor`), without restarting it. */
  hardwareAttach: (port: string, mode: string) => json<HardwareView>('POST', '/api/hardware/attach', { port, mode }),
  /** POST /api/hardware/detach: the project's own I/O back (the board's outputs off). */
  hardwareDetach: () => json<HardwareView>('POST', '/api/hardware/detach'),
  /** `tags`: `Tag` of this runtime, `Tag@node` of another node. */
  historyCsvUrl: (tags: string[], from: number, to: number, step: number) =>
    `/api/history.csv?tags=${tags.map(enc).join(',')}&from=${Math.floor(from)}&to=${Math.ceil(to)}&step=${Math.max(1, Math.round(step))}`,
};
