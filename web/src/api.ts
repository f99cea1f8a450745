// The HTTP API of docs/api.md. Every failure becomes an ApiError carrying the
// status and the server's `{"error", "diagnostics"?}` body.
import type { Domain } from './domain';
import type { Diagnostic, Force, History, Json, Program, ProgramRef, RungJson, Status, TagInfo } from './types';

export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    readonly diagnostics: Diagnostic[] = [],
  ) {
    super(message);
  }
}

async function request(method: string, path: string, body?: unknown, contentType = 'application/json'): Promise<Response> {
  const init: RequestInit = { method, headers: {} };
  if (body !== undefined) {
    init.body = typeof body === 'string' && contentType !== 'application/json' ? body : JSON.stringify(body);
  }
  // The server takes state-changing requests as JSON only, bodyless ones too (docs/security.md).
  if (body !== undefined || method !== 'GET') {
    (init.headers as Record<string, string>)['Content-Type'] = contentType;
  }
  let res: Response;
  try {
    res = await fetch(path, init);
  } catch (e) {
    throw new ApiError(0, `cannot reach the server: ${(e as Error).message}`);
  }
  if (!res.ok) {
    let msg = `${res.status} ${res.statusText}`;
    let diagnostics: Diagnostic[] = [];
    try {
      const j = await res.json();
      if (j && typeof j.error === 'string') msg = j.error;
      if (j && Array.isArray(j.diagnostics)) diagnostics = j.diagnostics;
    } catch {
      /* not JSON */
    }
    throw new ApiError(res.status, msg, diagnostics);
  }
  return res;
}

async function json<T>(method: string, path: string, body?: unknown): Promise<T> {
  const res = await request(method, path, body);
  if (res.status === 204) return undefined as T;
  return (await res.json()) as T;
}

const enc = encodeURIComponent;

export const api = {
  status: () => json<Status>('GET', '/api/status'),
  run: () => json<Status>('POST', '/api/run'),
  stop: () => json<Status>('POST', '/api/stop'),
  tags: () => json<TagInfo[]>('GET', '/api/tags'),
  writeTag: (name: string, value: Json) => json<{ name: string; value: Json }>('PUT', `/api/tags/${enc(name)}`, { value }),
  forces: () => json<Force[]>('GET', '/api/forces'),
  force: (name: string, value: Json) => json<Force>('PUT', `/api/forces/${enc(name)}`, { value }),
  unforce: (name: string) => json<void>('DELETE', `/api/forces/${enc(name)}`),
  programs: () => json<ProgramRef[]>('GET', '/api/programs'),
  program: (name: string) => json<Program>('GET', `/api/programs/${enc(name)}`),
  domain: () => json<Domain>('GET', '/api/domain'),
  check: (name: string, text: string) =>
    json<{ diagnostics: Diagnostic[]; rungs?: RungJson[] }>('POST', `/api/check/${enc(name)}`, { text }),
  saveProgram: (name: string, text: string, online = true) =>
    json<{ diagnostics: Diagnostic[]; applied: boolean }>('PUT', `/api/programs/${enc(name)}`, { text, online }),
  tagsCsv: async () => (await request('GET', '/api/tags.csv')).text(),
  saveTagsCsv: (text: string) => request('PUT', '/api/tags.csv', text, 'text/csv').then((r) => r.json()),
  historyTags: () => json<{ name: string; first_ms: number; last_ms: number }[]>('GET', '/api/history/tags'),
  history: (tag: string, from: number, to: number, points: number) =>
    json<History>(
      'GET',
      `/api/history?tag=${enc(tag)}&from=${Math.floor(from)}&to=${Math.ceil(to)}&points=${Math.max(1, Math.min(10000, Math.round(points)))}`,
    ),
  historyCsvUrl: (tags: string[], from: number, to: number, step: number) =>
    `/api/history.csv?tags=${tags.map(enc).join(',')}&from=${Math.floor(from)}&to=${Math.ceil(to)}&step=${Math.max(1, Math.round(step))}`,
};
