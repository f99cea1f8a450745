// The net tab (issue 20) in happy-dom: drawn from the PNML, edited with the
// source's keys, undone, a refused guard drawn on its transition, live
// tokens from the WebSocket's values, and a deadlock's firing sequence
// replayed from the analysis.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { afterEach, describe, expect, it, vi } from 'vitest';
import { setMe } from '../src/auth';
import { type Ctx, TagCache } from '../src/ctx';
import { LiveClient } from '../src/live/client';
import { emptyBatch } from '../src/live/coalesce';
import { findNode, position } from '../src/net/edit';
import { NetView } from '../src/net/view';
import { lineCol } from '../src/net/xml';

const REPO = join(__dirname, '../..');
const BATCH = readFileSync(join(REPO, 'examples/state-net-batch/batch.pnml'), 'utf8');
const CELL = readFileSync(join(REPO, 'examples/petri-resource/cell.pnml'), 'utf8');
const TOUR = readFileSync(join(REPO, 'examples/opcsm-tour/tour.pnml'), 'utf8');

/** The monitored elements of batch.pnml's transitions, as GET /api/programs gives them. */
const BATCH_ELEMENTS = ['start', 'filled', 'mixed', 'again', 'enough'].map((id, k) => ({ id, enabled: 40 + k, fired: 30 + k }));

function server(files: Record<string, string>, analysis: unknown = null, transitions: unknown = undefined) {
  const calls: string[] = [];
  vi.stubGlobal('fetch', async (path: string, init: RequestInit) => {
    calls.push(`${init.method} ${path}`);
    const json = (status: number, j: unknown) => new Response(JSON.stringify(j), { status, headers: { 'Content-Type': 'application/json' } });
    const name = decodeURIComponent(path.split('/').pop()!);
    if (path.includes('/analysis')) {
      // POST /api/nets/{name}/analysis: JSON lines, a progress line then the result.
      const lines = [{ progress: { part: 'state_space', states: 1, bytes: 0 } }, { result: analysis, timed_out: false }];
      return new Response(lines.map((l) => JSON.stringify(l) + '\n').join(''), { status: 200, headers: { 'Content-Type': 'application/x-ndjson' } });
    }
    if (path === '/api/step') return json(200, { state: 'stopped' });
    if (path.endsWith('/reset')) return json(200, { program: 'batch.pnml', marking: [] });
    if (path.startsWith('/api/tags/')) {
      calls.push(`${name}=${JSON.parse(init.body as string).value}`);
      return json(200, { name, value: JSON.parse(init.body as string).value });
    }
    if (init.method === 'GET') return json(200, { name, language: 'net', plant: false, text: files[name], diagnostics: [], transitions });
    const body = JSON.parse(init.body as string);
    const at = body.text.indexOf('Strat');
    if (at >= 0) {
      const [line, col] = lineCol(body.text, at);
      return json(422, { error: '1 error', diagnostics: [{ code: 'E621', severity: 'error', message: 'unknown tag `Strat`', file: name, line, col, end_line: line, end_col: col + 5, help: 'did you mean `Start`?' }] });
    }
    if (init.method === 'PUT') files[name] = body.text;
    return json(200, { diagnostics: [], applied: true });
  });
  return calls;
}

function view(program: string) {
  const notes: string[] = [];
  const tags = new TagCache();
  tags.set([
    { name: 'Start', type: 'BOOL', address: 'DI:1/0', description: '', retain: false, access: 'input', value: false, forced: null, notations: [] },
    { name: 'Lamp', type: 'BOOL', address: null, description: '', retain: false, access: 'readwrite', value: false, forced: null, notations: [] },
  ] as never);
  const live = new LiveClient('ws://127.0.0.1:1/none');
  const ctx = { live, tags, notify: (m: string) => notes.push(m) } as unknown as Ctx;
  const v = new NetView(ctx, program);
  document.body.append(v.el);
  return { v, ctx, live, notes };
}

const node = (v: NetView, id: string) => v.el.querySelector<SVGGElement>(`[data-testid="net-node-${id}"]`);
const key = (v: NetView, k: string, opts: KeyboardEventInit = {}) =>
  v.el.querySelector('[data-testid="net-canvas"]')!.dispatchEvent(new KeyboardEvent('keydown', { key: k, bubbles: true, ...opts }));

afterEach(() => {
  vi.unstubAllGlobals();
  vi.useRealTimers();
  document.body.replaceChildren();
});

describe('the net tab', () => {
  it('cuts a guard short where it would run into a neighbour, keeping it whole in its tooltip (issue 30, item 23)', async () => {
    server({ 'batch.pnml': BATCH });
    const { v } = view('batch.pnml');
    await v.load();
    v.show();
    const { TEXT, textBox, overlaps, transitionBox } = await import('../src/net/geom');
    const guard = (id: string) => v.el.querySelector<SVGTextElement>(`[data-testid="net-node-${id}"] .net-guard`)!;
    const at = (id: string) => {
      const [x, y] = v.el.querySelector(`[data-testid="net-node-${id}"]`)!.getAttribute('transform')!.match(/-?[\d.]+/g)!.map(Number);
      return { x, y };
    };
    const box = (id: string) => {
      const g = guard(id);
      const c = at(id);
      return textBox(c.x + Number(g.getAttribute('x')), c.y + Number(g.getAttribute('y')), g.firstChild!.textContent!.length, TEXT.mono);
    };
    // `again` and `enough` stand side by side: again's guard stops before enough's bar
    expect(overlaps(box('again'), box('enough'))).toBe(false);
    expect(overlaps(box('again'), transitionBox(at('enough')))).toBe(false);
    expect(guard('again').firstChild!.textContent!.endsWith('…')).toBe(true);
    expect(guard('again').querySelector('title')!.textContent).toBe('batch.batches.count < 3');
  });

  it('has the top bar\'s Run and Stop: the same words, tooltips and state (issue 30, item 23)', async () => {
    server({ 'batch.pnml': BATCH });
    const run = Object.assign(document.createElement('button'), { textContent: '▶ Run', title: 'Start scanning', disabled: true });
    const stop = Object.assign(document.createElement('button'), { textContent: '■ Stop', title: 'Stop scanning (outputs off)' });
    run.dataset.testid = 'btn-run';
    stop.dataset.testid = 'btn-stop';
    document.body.append(run, stop);
    const { v } = view('batch.pnml');
    await v.load();
    v.show();
    const mine = (w: string) => v.el.querySelector<HTMLButtonElement>(`[data-testid="net-${w}"]`)!;
    expect([mine('run').textContent, mine('run').title, mine('run').disabled]).toEqual(['▶ Run', 'Start scanning (F5)', true]);
    expect([mine('stop').textContent, mine('stop').title, mine('stop').disabled]).toEqual(['■ Stop', 'Stop scanning (outputs off) (Shift+F5)', false]);
    // the top bar changes (the PLC stopped): the net's pair follows
    run.disabled = false;
    stop.disabled = true;
    await vi.waitFor(() => expect([mine('run').disabled, mine('stop').disabled]).toEqual([false, true]));
    v.hide();
  });

  it('draws the net with its initial marking, adds elements with S, T, Shift+E and Shift+C, and undoes them', async () => {
    server({ 'batch.pnml': BATCH });
    const { v } = view('batch.pnml');
    await v.load();
    v.show();
    expect(v.el.querySelectorAll('.net-place').length).toBe(5);
    expect(v.el.querySelectorAll('.net-transition').length).toBe(5);
    expect(v.el.querySelectorAll('.net-arc').length).toBe(10);
    expect(node(v, 'idle')!.dataset.tokens).toBe('1');
    expect(node(v, 'filled')!.dataset.kind).toBe('timer');
    vi.useFakeTimers(); // the checks after each edit stay queued
    key(v, 's');
    key(v, 't');
    key(v, 'E', { shiftKey: true });
    key(v, 'C', { shiftKey: true });
    expect(node(v, 'S0')).not.toBeNull();
    expect(node(v, 'T1')).not.toBeNull();
    expect(node(v, 'E1')!.dataset.kind).toBe('expression');
    expect(node(v, 'C1')!.dataset.kind).toBe('condition');
    expect(v.dirty).toBe(true);
    expect(v.current!.places.map((p) => p.id)).toContain('S0');
    key(v, 'z', { ctrlKey: true });
    expect(node(v, 'C1')).toBeNull();
    key(v, 'y', { ctrlKey: true });
    expect(node(v, 'C1')).not.toBeNull();
    for (let k = 0; k < 4; k++) key(v, 'z', { ctrlKey: true });
    expect(v.dirty).toBe(false);
  });

  it('edits the PNML as text; a text that is not PNML is listed with its place and not drawn', async () => {
    server({ 'batch.pnml': BATCH });
    const { v } = view('batch.pnml');
    await v.load();
    v.show();
    vi.useFakeTimers();
    v.el.querySelector<HTMLElement>('[data-testid="view-text"]')!.click();
    const text = v.el.querySelector<HTMLTextAreaElement>('[data-testid="editor-text"]')!;
    expect(text.value).toBe(BATCH);
    text.value = BATCH.replace('<place id="fill">', '<place id="fill"><bad>');
    text.dispatchEvent(new Event('input'));
    expect(v.el.querySelector('[data-testid="diagnostic-0"]')!.textContent).toMatch(/closes <bad>/);
    v.el.querySelector<HTMLElement>('[data-testid="view-graphic"]')!.click();
    expect(v.el.querySelector('[data-testid="net-unreadable"]')).not.toBeNull();
    v.el.querySelector<HTMLElement>('[data-testid="view-text"]')!.click();
    text.value = BATCH.replace('<place id="fill">', '<place id="filling">').replace(/"fill"/g, '"filling"');
    text.dispatchEvent(new Event('input'));
    v.el.querySelector<HTMLElement>('[data-testid="view-graphic"]')!.click();
    expect(node(v, 'filling')).not.toBeNull();
  });

  it('puts a refused guard on its transition and in the properties, and saves nothing', async () => {
    const calls = server({ 'batch.pnml': BATCH });
    const { v } = view('batch.pnml');
    await v.load();
    v.show();
    vi.useFakeTimers();
    node(v, 'start')!.dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
    window.dispatchEvent(new PointerEvent('pointerup', { bubbles: true }));
    const guard = v.el.querySelector<HTMLInputElement>('[data-testid="net-prop-guard"]')!;
    expect(guard.value).toBe('Start AND batch.batches.count < 3');
    guard.value = 'Strat AND batch.batches.count < 3';
    guard.dispatchEvent(new Event('change'));
    expect(v.current!.transitions.find((t) => t.id === 'start')!.guard).toBe('Strat AND batch.batches.count < 3');
    await vi.advanceTimersByTimeAsync(450);
    expect(calls).toContain('POST /api/check/batch.pnml');
    expect(v.el.querySelector('[data-testid="net-error-start"]')).not.toBeNull();
    expect(v.el.querySelector('[data-testid="net-prop-error"]')!.textContent).toContain('unknown tag `Strat`');
    expect(v.el.querySelector('[data-testid="diagnostic-0"]')!.textContent).toContain('E621');
    // the highlighted guard marks the name that is not a tag
    expect(v.el.querySelector('[data-testid="net-prop-guard-hl"] .hl-name')!.textContent).toBe('Strat');
    expect(await v.save()).toBe(false);
    expect(calls.filter((c) => c.startsWith('PUT'))).toEqual(['PUT /api/programs/batch.pnml']);
  });

  it('shows the running net’s tokens, the transitions the runtime says are enabled or fired, and a history of firings', async () => {
    const calls = server({ 'batch.pnml': BATCH }, null, BATCH_ELEMENTS);
    const { v, live } = view('batch.pnml');
    await v.load();
    v.show();
    live.state = 'connected';
    live.status = { state: 'running' } as never;
    const raw = (m: unknown) => (live as unknown as { rawListeners: Set<(m: unknown) => void> }).rawListeners.forEach((f) => f(m));
    const values = (scan: number, vals: Record<string, number>) => {
      raw({ type: 'values', scan, t_ms: 1_700_000_000_000, values: vals });
      live.deliver({ ...emptyBatch(), values: new Map(Object.entries(vals)) });
    };
    const power = (scan: number, on: number[]) => {
      raw({ type: 'power', scan, program: 'batch.pnml', on });
      live.deliver({ ...emptyBatch(), power: new Map([['batch.pnml', on]]) });
    };
    const enabled = () => ['start', 'filled', 'mixed', 'again', 'enough'].filter((id) => node(v, id)!.dataset.enabled === 'true');
    values(1, { 'batch.idle': 1, 'batch.start': 0, 'batch.fill': 0 });
    values(2, { 'batch.idle': 0, 'batch.start': 1 });
    expect(node(v, 'idle')!.dataset.tokens).toBe('0');
    // the token at `start` alone does not make it enabled: the runtime's element says so (its guard)
    expect(enabled()).toEqual([]);
    expect(node(v, 'start')!.dataset.tokens).toBe('1');
    expect(node(v, 'start')!.querySelectorAll('.net-token').length).toBe(1);
    power(2, [40]);
    expect(enabled()).toEqual(['start']);
    values(3, { 'batch.start': 0, 'batch.fill': 1 });
    power(3, [30]);
    expect(enabled()).toEqual([]);
    expect(node(v, 'start')!.classList.contains('fired')).toBe(true);
    expect(node(v, 'fill')!.dataset.tokens).toBe('1');
    expect(node(v, 'fill')!.querySelectorAll('.net-token').length).toBe(1);
    expect(v.el.querySelector('[data-testid="net-live-state"]')!.textContent).toBe('live');
    const history = (k: number) => v.el.querySelector(`[data-testid="net-history-${k}"]`)!.textContent;
    expect(history(0)).toContain('#3');
    expect(history(0)).toContain('fired start — fill +1');
    // a firing that changes no marking is listed too (the server sends a net's power flow every scan it fires)
    power(4, [31]);
    expect(history(0)).toContain('#4');
    expect(history(0)).toContain('fired filled');
    expect(history(1)).toContain('#3');
    // stopped: still live (single steps), F6 steps, Reset marking is one request
    live.status = { state: 'stopped' } as never;
    power(4, []);
    expect(v.el.querySelector('[data-testid="net-live-state"]')!.textContent).toBe('stopped: F6 runs one scan');
    expect(node(v, 'fill')!.dataset.tokens).toBe('1');
    v.el.querySelector('[data-testid="net-canvas"]')!.dispatchEvent(new KeyboardEvent('keydown', { key: 'F6', bubbles: true }));
    v.el.querySelector<HTMLButtonElement>('[data-testid="net-step"]')!.click();
    v.el.querySelector<HTMLButtonElement>('[data-testid="net-reset"]')!.click();
    await vi.waitFor(() => expect(calls.filter((c) => c.startsWith('POST'))).toEqual(['POST /api/step', 'POST /api/step', 'POST /api/nets/batch.pnml/reset']));
    expect(calls.filter((c) => c.startsWith('PUT'))).toEqual([]);
  });

  it('shows a replayed scan (the Verify & Test page’s counterexample): its marking, enabled and fired transitions, not the live ones', async () => {
    server({ 'batch.pnml': BATCH }, null, BATCH_ELEMENTS);
    const { v } = view('batch.pnml');
    await v.load();
    // not connected: the initial marking, until a scan is shown
    expect(node(v, 'idle')!.dataset.tokens).toBe('1');
    const scan = (vals: Record<string, number>, on: number[]) => v.showScan((tag) => vals[tag], new Set(on));
    // the scan where `start` fires: its "fired" element (30) energised, the token now in `fill`
    scan({ 'batch.idle': 0, 'batch.start': 0, 'batch.fill': 1 }, [30, 41]);
    expect(node(v, 'idle')!.dataset.tokens).toBe('0');
    expect(node(v, 'fill')!.dataset.tokens).toBe('1');
    expect(node(v, 'start')!.classList.contains('fired')).toBe(true);
    expect(node(v, 'filled')!.dataset.enabled).toBe('true');
    expect(node(v, 'mixed')!.classList.contains('fired')).toBe(false);
    expect(v.el.querySelector('[data-testid="net-live-state"]')!.textContent).toBe('replay');
    // the scan before: nothing fired
    scan({ 'batch.idle': 0, 'batch.start': 1, 'batch.fill': 0 }, [40]);
    expect(node(v, 'start')!.dataset.tokens).toBe('1');
    expect(node(v, 'start')!.classList.contains('fired')).toBe(false);
    expect(node(v, 'start')!.dataset.enabled).toBe('true');
  });

  it('shows the operator elements live: a Display’s value, a Plot’s last values, a Label’s caption; a Button writes while pressed', async () => {
    const calls = server({ 'tour.pnml': TOUR });
    const { v, live } = view('tour.pnml');
    await v.load();
    v.show();
    const widget = (id: string) => v.el.querySelector(`[data-testid="net-widget-${id}"]`)!;
    const shown = (id: string) => widget(id).querySelector('.net-widget-value')!.textContent;
    // not live: no values
    expect([shown('w_doubled'), shown('w_level'), shown('w_start')]).toEqual(['', '', '']);
    live.state = 'connected';
    live.status = { state: 'running' } as never;
    const values = (vals: Record<string, unknown>) => live.deliver({ ...emptyBatch(), values: new Map(Object.entries(vals)) as never });
    values({ Doubled: 12.5, Level: 20, Start: false });
    expect([shown('w_doubled'), shown('w_level'), shown('w_start'), shown('w_note')]).toEqual(['12.5', '20', '0', '']);
    for (const x of [80, 35]) values({ Level: x });
    const ys = widget('w_level').querySelector('.net-plot-line')!.getAttribute('points')!.split(' ').map((p) => Number(p.split(',')[1]));
    // 20, 80, 35 scaled between the lowest and the highest: 80 at the top (y 24), 20 at the bottom (y 44)
    expect(ys).toEqual([44, 24, 44 - (15 / 60) * 20]);
    expect(widget('w_note').querySelector('.net-widget-caption')!.textContent).toBe('The elements of OPCSM, one of each kind');
    // a label is as wide as its caption
    expect(Number(widget('w_note').querySelector('rect')!.getAttribute('width'))).toBeGreaterThan(200);
    widget('w_start').dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
    await vi.waitFor(() => expect(calls).toContain('Start=true'));
    window.dispatchEvent(new PointerEvent('pointerup', { bubbles: true }));
    await vi.waitFor(() => expect(calls).toContain('Start=false'));
    expect(calls.filter((c) => c.startsWith('PUT'))).toEqual(['PUT /api/tags/Start', 'PUT /api/tags/Start']);
    // pressing it neither selected nor moved it; not live, a press selects it (to edit it)
    expect(widget('w_start').classList.contains('selected')).toBe(false);
    live.state = 'reconnecting';
    widget('w_start').dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
    window.dispatchEvent(new PointerEvent('pointerup', { bubbles: true }));
    expect(widget('w_start').classList.contains('selected')).toBe(true);
    expect(calls.filter((c) => c.startsWith('PUT'))).toHaveLength(2);
  });

  it('shows a Display in its format and unit, a Plot in its fixed range with its title, a Label in its colours; a Button latches on a double-click', async () => {
    const styled = TOUR.replace('kind="display" tag="Doubled" x="200" y="260"', 'kind="display" tag="Doubled" x="200" y="260" format="hex" unit="kg" font_size="16"')
      .replace('kind="plot" tag="Level" x="340" y="260"', 'kind="plot" tag="Level" x="340" y="260" autoscale="false" min="0" max="100" title="Tank" unit="%"')
      .replace('kind="label" x="60" y="330"', 'kind="label" x="60" y="330" color="#fff" background="navy" align="center" border="false"');
    expect(styled).not.toBe(TOUR);
    const calls = server({ 'tour.pnml': styled });
    const { v, live } = view('tour.pnml');
    await v.load();
    v.show();
    const widget = (id: string) => v.el.querySelector(`[data-testid="net-widget-${id}"]`)!;
    const shown = (id: string) => widget(id).querySelector('.net-widget-value')!.textContent;
    live.state = 'connected';
    live.status = { state: 'running' } as never;
    const values = (vals: Record<string, unknown>) => live.deliver({ ...emptyBatch(), values: new Map(Object.entries(vals)) as never });
    values({ Doubled: 255, Level: 20, Start: false });
    expect(shown('w_doubled')).toBe('16#FF kg');
    expect(widget('w_doubled').querySelector('.net-widget-value')!.getAttribute('style')).toBe('font-size:16px');
    for (const x of [80, 35]) values({ Level: x });
    // 0…100: 20 at y 40, 80 at 28, 35 at 37 (not the points' own range)
    const ys = widget('w_level').querySelector('.net-plot-line')!.getAttribute('points')!.split(' ').map((p) => Number(p.split(',')[1]));
    expect(ys).toEqual([40, 28, 37]);
    expect(shown('w_level')).toBe('35 %');
    expect(widget('w_level').querySelector('.net-widget-caption')!.textContent).toBe('Tank');
    expect(widget('w_level').querySelector('.net-plot-scale')!.textContent).toBe('0…100 %');
    const note = widget('w_note');
    expect(note.querySelector('rect')!.getAttribute('style')).toBe('fill:navy');
    expect(note.querySelector('.net-widget-caption')!.getAttribute('style')).toBe('fill:#fff');
    expect(note.querySelector('.net-widget-caption')!.getAttribute('text-anchor')).toBe('middle');
    expect(note.classList.contains('no-border')).toBe(true);
    // a double-click latches Start at true; the next press releases it
    const click = () => {
      widget('w_start').dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
      window.dispatchEvent(new PointerEvent('pointerup', { bubbles: true }));
    };
    click();
    click();
    widget('w_start').dispatchEvent(new MouseEvent('dblclick', { bubbles: true }));
    await vi.waitFor(() => expect(calls.filter((c) => c.startsWith('Start='))).toEqual(['Start=true', 'Start=false', 'Start=true', 'Start=false', 'Start=true']));
    expect(widget('w_start').classList.contains('latched')).toBe(true);
    click();
    await vi.waitFor(() => expect(calls.filter((c) => c.startsWith('Start='))).toHaveLength(6));
    expect(calls.filter((c) => c.startsWith('Start=')).at(-1)).toBe('Start=false');
    expect(widget('w_start').classList.contains('latched')).toBe(false);
  });

  it('edits an arc’s weight and kind, and copies and pastes the whole net with fresh ids', async () => {
    server({ 'cell.pnml': CELL });
    const { v } = view('cell.pnml');
    await v.load();
    v.show();
    vi.useFakeTimers();
    v.el.querySelector('[data-testid="net-arc-a4"]')!.dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
    const weight = v.el.querySelector<HTMLInputElement>('[data-testid="net-prop-weight"]')!;
    weight.value = '2';
    weight.dispatchEvent(new Event('change'));
    expect(v.current!.arcs.find((a) => a.id === 'a4')!.weight).toBe(2);
    expect(v.el.querySelector('[data-testid="net-arc-a4"] .net-weight')!.textContent).toBe('2');
    const kind = v.el.querySelector<HTMLSelectElement>('[data-testid="net-prop-arc-kind"]')!;
    kind.value = 'read';
    kind.dispatchEvent(new Event('change'));
    expect(v.el.querySelector('[data-testid="net-arc-a4"]')!.classList.contains('kind-read')).toBe(true);
    const places = v.current!.places.length;
    const arcs = v.current!.arcs.length;
    key(v, 'a', { ctrlKey: true });
    key(v, 'c', { ctrlKey: true });
    key(v, 'v', { ctrlKey: true });
    expect(v.current!.places.length).toBe(2 * places);
    expect(v.current!.arcs.length).toBe(2 * arcs);
    expect(new Set(v.current!.places.map((p) => p.id)).size).toBe(2 * places);
    key(v, 'Delete');
    expect(v.current!.places.length).toBe(places);
  });

  it('lets a viewer look but not edit', async () => {
    server({ 'cell.pnml': CELL });
    setMe({ user: 'ann', role: 'viewer', users: true });
    const { v } = view('cell.pnml');
    await v.load();
    v.show();
    expect(v.el.querySelector<HTMLButtonElement>('[data-testid="net-add-state"]')!.disabled).toBe(true);
    expect(v.el.querySelector<HTMLButtonElement>('[data-testid="net-run"]')!.disabled).toBe(true);
    key(v, 's');
    expect(v.dirty).toBe(false);
    node(v, 'robot')!.dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true }));
    expect(v.el.querySelector<HTMLInputElement>('[data-testid="net-prop-initial"]')!.disabled).toBe(true);
  });

  it('offers only states and transitions to a Petri-mode net', async () => {
    server({ 'cell.pnml': CELL });
    const { v, notes } = view('cell.pnml');
    await v.load();
    v.show();
    const btn = (k: string) => v.el.querySelector<HTMLButtonElement>(`[data-testid="net-add-${k}"]`)!;
    expect([btn('state').disabled, btn('transition').disabled, btn('counter').disabled, btn('timer').disabled]).toEqual([false, false, true, true]);
    key(v, 'E', { shiftKey: true });
    expect(v.dirty).toBe(false);
    expect(notes[0]).toMatch(/normal mode only/);
    vi.useFakeTimers();
    key(v, 't');
    expect(v.current!.transitions.map((t) => t.id)).toContain('T1');
  });

  it('shows the analysis, marks dead transitions and replays the deadlock step by step', async () => {
    const cellWithDead = CELL.replace('<transition id="grab2"/>', '<transition id="grab2"/><transition id="never"/>').replace('<arc id="b1"', '<place id="nothing"/><arc id="z1" source="nothing" target="never"/><arc id="b1"');
    const calls = server({ 'cell.pnml': cellWithDead }, {
      places: 11, transitions: 9, bounded: true, safe: false, place_bounds: { robot: 1 }, states: 20, edges: 30, deadlocks: 1,
      dead_transitions: ['never'], live: false, reversible: false, p_invariants: [{ robot: 1, load1: 1, load2: 1 }], t_invariants: [],
      deadlock_trace: ['arrive1', 'grab1'], state_space: 'reachability', stopped: null, notes: [],
      status: { state_space: 'complete', components: 'complete', p_flows: 'complete', t_flows: 'complete', p_invariants: 'complete', t_invariants: 'skipped: budget' },
    });
    const { v } = view('cell.pnml');
    await v.load();
    v.show();
    await v.analyse();
    expect(calls).toContain('POST /api/nets/cell.pnml/analysis');
    expect(v.el.querySelector('[data-testid="net-an-status-t_invariants"]')!.textContent).toBe('skipped: budget');
    expect(v.el.querySelector('[data-testid="net-an-bounded"]')!.textContent).toBe('yes');
    expect(v.el.querySelector('[data-testid="net-an-deadlocks"]')!.textContent).toBe('1');
    expect(node(v, 'never')!.classList.contains('dead')).toBe(true);
    v.el.querySelector<HTMLElement>('[data-testid="net-an-pinv-0"]')!.dispatchEvent(new MouseEvent('mouseenter'));
    expect(node(v, 'load2')!.classList.contains('lit')).toBe(true);
    expect(node(v, 'idle1')!.classList.contains('lit')).toBe(false);
    v.el.querySelector<HTMLElement>('[data-testid="net-replay"]')!.click();
    expect(node(v, 'idle1')!.dataset.tokens).toBe('1');
    v.el.querySelector<HTMLElement>('[data-testid="net-replay-next"]')!.click();
    expect(node(v, 'idle1')!.dataset.tokens).toBe('0');
    expect(node(v, 'wait1')!.dataset.tokens).toBe('1');
    expect(node(v, 'arrive1')!.classList.contains('fired')).toBe(true);
    v.el.querySelector<HTMLElement>('[data-testid="net-replay-next"]')!.click();
    expect(node(v, 'load1')!.dataset.tokens).toBe('1');
    expect(node(v, 'robot')!.dataset.tokens).toBe('0');
    expect(v.el.querySelector('[data-testid="net-replay-step"]')!.textContent).toBe('step 2 of 2');
    expect(v.el.querySelector('[data-testid="net-replay-dead"]')).not.toBeNull();
    v.el.querySelector<HTMLElement>('[data-testid="net-replay-back"]')!.click();
    expect(node(v, 'load1')!.dataset.tokens).toBe('0');
  });
});

describe('the net editor’s keys and gestures', () => {
  const pos = (v: NetView, id: string) => position(findNode(v.current!, id)!.extra);
  const down = (el: Element, x: number, y: number, opts: PointerEventInit = {}) =>
    el.dispatchEvent(new PointerEvent('pointerdown', { button: 0, bubbles: true, clientX: x, clientY: y, ...opts }));
  const move = (x: number, y: number, opts: PointerEventInit = {}) => window.dispatchEvent(new PointerEvent('pointermove', { bubbles: true, clientX: x, clientY: y, ...opts }));
  const up = () => window.dispatchEvent(new PointerEvent('pointerup', { bubbles: true }));
  /** Time passes: two presses on a node within 400 ms are a double click (an arc starts). */
  const later = () => vi.setSystemTime(Date.now() + 1000);
  const click = (v: NetView, id: string) => {
    later();
    down(node(v, id)!, 0, 0);
    up();
  };
  const canvas = (v: NetView) => v.el.querySelector<HTMLElement>('[data-testid="net-canvas"]')!;
  const zoom = (v: NetView) => v.el.querySelector('[data-testid="net-zoom"]')!.textContent;
  async function open(text = BATCH, program = 'batch.pnml') {
    server({ [program]: text });
    const r = view(program);
    await r.v.load();
    r.v.show();
    vi.useFakeTimers(); // the checks after each edit stay queued
    return r;
  }

  it('F4 goes to the first property, F8 to the guard or the script', async () => {
    const { v } = await open();
    click(v, 'fill');
    key(v, 'F4');
    expect((document.activeElement as HTMLElement).dataset.testid).toBe('net-prop-id');
    click(v, 'start');
    key(v, 'F8');
    expect((document.activeElement as HTMLElement).dataset.testid).toBe('net-prop-guard');
    key(v, 'E', { shiftKey: true });
    key(v, 'F8');
    expect((document.activeElement as HTMLElement).dataset.testid).toBe('net-prop-script');
    // in the text view F4 and F8 leave the focus alone
    v.el.querySelector<HTMLElement>('[data-testid="view-text"]')!.click();
    const text = v.el.querySelector<HTMLTextAreaElement>('[data-testid="editor-text"]')!;
    text.focus();
    text.dispatchEvent(new KeyboardEvent('keydown', { key: 'F4', bubbles: true }));
    expect(document.activeElement).toBe(text);
  });

  it('F5 runs and Shift+F5 stops the PLC through the top bar’s buttons (a disabled one is not pressed)', async () => {
    const { v } = await open();
    const pressed: string[] = [];
    const bar = ['run', 'stop'].map((w) => {
      const b = document.createElement('button');
      b.dataset.testid = `btn-${w}`;
      b.onclick = () => pressed.push(w);
      document.body.append(b);
      return b;
    });
    key(v, 'F5');
    key(v, 'F5', { shiftKey: true });
    expect(pressed).toEqual(['run', 'stop']);
    bar[0].disabled = true;
    key(v, 'F5');
    expect(pressed).toEqual(['run', 'stop']);
  });

  it('arrows move the selection by the grid, Shift+arrows by one unit, in one undoable step each', async () => {
    const { v } = await open();
    click(v, 'fill');
    click(v, 'mix');
    // Shift+click adds to the selection
    down(node(v, 'fill')!, 0, 0, { shiftKey: true });
    up();
    expect([pos(v, 'fill'), pos(v, 'mix')]).toEqual([{ x: 240, y: 40 }, { x: 440, y: 40 }]);
    key(v, 'ArrowRight');
    key(v, 'ArrowDown');
    expect([pos(v, 'fill'), pos(v, 'mix')]).toEqual([{ x: 250, y: 50 }, { x: 450, y: 50 }]);
    key(v, 'ArrowLeft', { shiftKey: true });
    key(v, 'ArrowUp', { shiftKey: true });
    expect(pos(v, 'mix')).toEqual({ x: 449, y: 49 });
    expect(pos(v, 'idle')).toEqual({ x: 40, y: 40 });
    key(v, 'z', { ctrlKey: true });
    expect(pos(v, 'mix')).toEqual({ x: 449, y: 50 });
    // nothing selected: arrows do nothing
    key(v, 'Escape');
    key(v, 'ArrowRight');
    expect(pos(v, 'mix')).toEqual({ x: 449, y: 50 });
  });

  it('+, − and 0 zoom in, out and fit; Ctrl+wheel zooms, a plain wheel scrolls', async () => {
    const { v } = await open();
    expect(zoom(v)).toBe('100 %');
    key(v, '+');
    expect(zoom(v)).toBe('125 %');
    key(v, '=');
    expect(zoom(v)).toBe('150 %');
    key(v, '-');
    key(v, '-');
    key(v, '-');
    expect(zoom(v)).toBe('90 %');
    const svg = v.el.querySelector('[data-testid="net-svg"]')!;
    // the drawing is at least 1200 × 700 units
    // the drawing: the nodes with a margin, at least 1200 × 700 units (batch.pnml: 1240 × 740 from −40, −40)
    expect([svg.getAttribute('width'), svg.getAttribute('height')]).toEqual(['1116', '666']);
    Object.defineProperty(canvas(v), 'clientWidth', { value: 620 });
    Object.defineProperty(canvas(v), 'clientHeight', { value: 720 });
    key(v, '0');
    expect(zoom(v)).toBe('48 %');
    // from a zoom between two steps, in goes to the next step up, out to the next one down
    const wheel = (deltaY: number, ctrlKey: boolean) => {
      const e = new WheelEvent('wheel', { deltaY, bubbles: true, cancelable: true });
      Object.defineProperty(e, 'ctrlKey', { value: ctrlKey }); // happy-dom's WheelEvent drops it
      canvas(v).dispatchEvent(e);
      return e.defaultPrevented;
    };
    expect(wheel(-100, true)).toBe(true);
    expect(zoom(v)).toBe('50 %');
    key(v, '0');
    expect(wheel(100, true)).toBe(true);
    expect(zoom(v)).toBe('33 %');
    expect(wheel(-100, false)).toBe(false);
    expect(zoom(v)).toBe('33 %');
    // the smallest and largest zooms hold
    for (let k = 0; k < 12; k++) key(v, '-');
    expect(zoom(v)).toBe('25 %');
    for (let k = 0; k < 12; k++) key(v, '+');
    expect(zoom(v)).toBe('300 %');
    expect(v.dirty).toBe(false);
  });

  it('Ctrl+X cuts (the node and its arcs), Ctrl+V pastes it back; Ctrl+D duplicates 30 units down and right', async () => {
    const { v } = await open();
    click(v, 'fill');
    key(v, 'x', { ctrlKey: true });
    expect(node(v, 'fill')).toBeNull();
    expect(v.current!.arcs.map((a) => a.id)).not.toContain('a2');
    expect(v.current!.arcs.length).toBe(8);
    key(v, 'v', { ctrlKey: true });
    expect(v.current!.places.length).toBe(5);
    const pasted = [...v.current!.places].pop()!;
    expect(pos(v, pasted.id)).toEqual({ x: 270, y: 70 });
    // a single node's arcs went with it: the pasted copy has none
    expect(v.current!.arcs.length).toBe(8);
    click(v, 'mixed');
    down(node(v, 'mix')!, 0, 0, { shiftKey: true });
    up();
    key(v, 'd', { ctrlKey: true });
    const ids = v.current!.transitions.map((t) => t.id);
    expect(ids.length).toBe(6);
    const dup = ids[5];
    expect(pos(v, dup)).toEqual({ x: 570, y: 70 });
    // the arc between the two duplicated nodes is duplicated too, and the copies are selected
    expect(v.current!.arcs.length).toBe(9);
    expect(node(v, dup)!.classList.contains('selected')).toBe(true);
    expect(node(v, 'mixed')!.classList.contains('selected')).toBe(false);
    // nothing selected: Ctrl+X and Ctrl+D do nothing
    key(v, 'Escape');
    key(v, 'x', { ctrlKey: true });
    key(v, 'd', { ctrlKey: true });
    expect(v.current!.transitions.length).toBe(6);
  });

  it('dragging a node moves it snapped to the grid (Alt: free, Grid off: free), one undoable step', async () => {
    const { v } = await open();
    down(node(v, 'fill')!, 100, 100);
    move(123, 104);
    move(127, 96);
    // while dragging the node is drawn where it goes; the text changes on release
    expect(node(v, 'fill')!.getAttribute('transform')).toBe('translate(270,40)');
    expect(v.dirty).toBe(false);
    up();
    expect(pos(v, 'fill')).toEqual({ x: 270, y: 40 });
    later();
    down(node(v, 'fill')!, 100, 100);
    move(103, 107, { altKey: true });
    up();
    expect(pos(v, 'fill')).toEqual({ x: 273, y: 47 });
    key(v, 'z', { ctrlKey: true });
    expect(pos(v, 'fill')).toEqual({ x: 270, y: 40 });
    const grid = v.el.querySelector<HTMLInputElement>('[data-testid="net-snap"]')!;
    grid.checked = false;
    grid.dispatchEvent(new Event('change'));
    later();
    down(node(v, 'fill')!, 100, 100);
    move(101, 102);
    up();
    expect(pos(v, 'fill')).toEqual({ x: 271, y: 42 });
    // a click without a move changes nothing
    const text = v.current;
    later();
    down(node(v, 'fill')!, 100, 100);
    up();
    expect(v.current).toEqual(text);
  });

  it('a rubber band selects the nodes it touches and the arcs between them; Shift adds; a click on the background clears', async () => {
    const { v } = await open();
    const bg = () => v.el.querySelector('[data-testid="net-background"]')!;
    const selected = () => [...v.el.querySelectorAll('.selected')].map((g) => g.getAttribute('data-testid')!.replace(/^net-(node|arc)-/, '')).sort();
    down(bg(), 200, 0);
    expect(v.el.querySelector('[data-testid="net-band"]')).not.toBeNull();
    move(460, 80);
    expect(v.el.querySelector('[data-testid="net-band"]')!.getAttribute('width')).toBe('260');
    up();
    expect(selected()).toEqual(['a3', 'a4', 'fill', 'filled', 'mix']);
    down(bg(), 20, 20, { shiftKey: true });
    move(60, 60);
    up();
    expect(selected()).toEqual(['a3', 'a4', 'fill', 'filled', 'idle', 'mix']);
    expect(v.el.querySelector('[data-testid="net-props"] h3')!.textContent).toBe('6 elements selected');
    // the band's selection moves together
    key(v, 'ArrowDown');
    expect([pos(v, 'idle'), pos(v, 'mix'), pos(v, 'start')]).toEqual([{ x: 40, y: 50 }, { x: 440, y: 50 }, { x: 140, y: 40 }]);
    down(bg(), 900, 600);
    up();
    expect(selected()).toEqual([]);
  });

  it('the middle button, or the left one with Space held, pans the canvas instead of selecting or moving', async () => {
    const { v } = await open();
    const c = canvas(v);
    c.scrollLeft = 100;
    c.scrollTop = 50;
    down(node(v, 'fill')!, 300, 300, { button: 1 });
    move(260, 280, { button: 1 });
    up();
    expect([c.scrollLeft, c.scrollTop]).toEqual([140, 70]);
    expect(v.current!.places.find((p) => p.id === 'fill')).toBeDefined();
    expect(pos(v, 'fill')).toEqual({ x: 240, y: 40 });
    key(v, ' ');
    down(node(v, 'fill')!, 300, 300);
    move(310, 300);
    up();
    expect(c.scrollLeft).toBe(130);
    expect(pos(v, 'fill')).toEqual({ x: 240, y: 40 });
    expect(node(v, 'fill')!.classList.contains('selected')).toBe(false);
    c.dispatchEvent(new KeyboardEvent('keyup', { key: ' ', bubbles: true }));
    down(node(v, 'fill')!, 300, 300);
    up();
    expect(node(v, 'fill')!.classList.contains('selected')).toBe(true);
  });
});
