import { afterEach, describe, expect, it, vi } from 'vitest';
import type { Ctx } from '../src/ctx';
import { ProgramEditor } from '../src/editor/program';

// A server answering GET /api/programs/main.lad, POST /api/check and PUT /api/programs.
function server(onSave: (text: string) => void) {
  let text = 'XIC(A)OTE(B);\n';
  const calls: string[] = [];
  const bad = { code: 'E301', severity: 'error', message: 'unknown tag `Q`', file: 'main.lad', line: 1, col: 5, end_line: 1, end_col: 6, help: null };
  vi.stubGlobal('fetch', async (path: string, init: RequestInit) => {
    calls.push(`${init.method} ${path}`);
    const body = init.body ? JSON.parse(init.body as string) : null;
    const json = (status: number, j: unknown) => new Response(JSON.stringify(j), { status, headers: { 'Content-Type': 'application/json' } });
    if (init.method === 'GET') return json(200, { name: 'main.lad', language: 'ladder', plant: false, text, diagnostics: [], rungs: [] });
    const ok = !body.text.includes('(Q)');
    if (!ok) return json(422, { error: '1 error', diagnostics: [bad] });
    if (init.method === 'PUT') {
      text = body.text;
      onSave(text);
      return json(200, { diagnostics: [], applied: true });
    }
    return json(200, { diagnostics: [], rungs: [] });
  });
  return calls;
}

function editor() {
  const notes: string[] = [];
  const ctx = { notify: (m: string) => notes.push(m) } as unknown as Ctx;
  const seen = { loaded: 0, text: 0, changed: 0 };
  const ed = new ProgramEditor(ctx, 'main.lad', {
    loaded: () => seen.loaded++,
    textChanged: () => seen.text++,
    changed: () => seen.changed++,
  });
  ed.section = document.createElement('section');
  return { ed, notes, seen };
}

afterEach(() => {
  vi.unstubAllGlobals();
  vi.useRealTimers();
});

describe('the program editor shared by the Ladder and IL tabs', () => {
  it('loads, checks an edit after a pause, lists its problems and does not save a bad text', async () => {
    const saved: string[] = [];
    const calls = server((t) => saved.push(t));
    const { ed, notes, seen } = editor();
    await ed.load();
    expect([ed.dirty, ed.textEl.value, seen.loaded, seen.text]).toEqual([false, 'XIC(A)OTE(B);\n', 1, 1]);
    vi.useFakeTimers();
    ed.setText('XIC(Q)OTE(B);\n');
    expect(ed.dirty).toBe(true);
    expect(calls.filter((c) => c.startsWith('POST'))).toEqual([]);
    await vi.advanceTimersByTimeAsync(400);
    expect(calls.filter((c) => c.startsWith('POST'))).toEqual(['POST /api/check/main.lad']);
    expect(ed.mine().map((d) => d.code)).toEqual(['E301']);
    ed.renderState();
    expect(ed.stateEl.textContent).toBe('edited — not saved (monitoring paused) · 1 problem');
    expect(ed.section!.dataset.dirty).toBe('true');
    const clicked: [number, number | null][] = [];
    ed.renderProblems([], (l, c) => clicked.push([l, c]));
    (ed.problemsEl.querySelector('[data-testid="diagnostic-0"]') as HTMLElement).click();
    expect(clicked).toEqual([[1, 5]]);
    expect(await ed.save()).toBe(false);
    expect(saved).toEqual([]);
    expect(notes).toEqual(['main.lad not saved: 1 error']);
    expect(seen.changed).toBeGreaterThan(0);
  });

  it('saves a good text online and reloads the running version', async () => {
    const saved: string[] = [];
    server((t) => saved.push(t));
    const { ed, notes } = editor();
    await ed.load();
    ed.setText('XIC(A)OTE(C);\n', false, false);
    expect(await ed.check()).toBe(true);
    expect(await ed.save()).toBe(true);
    expect(saved).toEqual(['XIC(A)OTE(C);\n']);
    expect(notes).toEqual(['main.lad saved and applied online']);
    expect([ed.dirty, ed.savedText]).toEqual([false, 'XIC(A)OTE(C);\n']);
    ed.renderProblems([{ code: 'syntax', line: 2, col: 1, text: 'expected `;`' }], () => undefined);
    expect(ed.problemsEl.textContent).toBe('syntax 2:1 expected `;`');
  });
});
