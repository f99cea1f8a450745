// The ladder tab in happy-dom (issue 30, items 1 and 10): a click, an edit and
// a change of forces draw again only the rungs whose picture changed, and the
// keyboard moves the selection and opens the force menu.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { type Ctx, TagCache } from '../src/ctx';
import { LadderView } from '../src/ladder/view';
import { type NavItem, navigate } from '../src/ladder/nav';
import { LiveClient } from '../src/live/client';
import { closeMenu } from '../src/ui/menu';
import type { TagInfo } from '../src/types';
import { FIXTURES } from './fixtures';

const TANK = FIXTURES.find((f) => f.example === 'tank')!;

const tag = (name: string, type: string, address: string | null = null): TagInfo =>
  ({ name, type, address, notations: [], description: '', retain: false, access: address?.startsWith('DI') ? 'input' : 'readwrite', value: null, forced: null }) as TagInfo;

const TAGS = [
  tag('STOP', 'BOOL', 'DI:1/0'), tag('FILL', 'BOOL', 'DI:1/1'), tag('S_REC', 'BOOL', 'DI:1/2'), tag('S_CAP', 'BOOL', 'DI:1/3'),
  tag('S_ULT', 'INT', 'AI:3/0'), tag('Nivel_m', 'REAL'), tag('Nivel_L', 'REAL'), tag('STOP_ONS', 'BOOL'), tag('CT_STP', 'COUNTER'),
  tag('L_STP', 'BOOL', 'DO:2/3'), tag('L_RUN', 'BOOL', 'DO:2/4'), tag('Llenar', 'BOOL'), tag('Bomba1', 'BOOL', 'DO:2/0'),
  tag('Bomba2', 'BOOL', 'DO:2/1'), tag('L_FILL', 'BOOL', 'DO:2/5'), tag('L_REFILL', 'BOOL', 'DO:2/6'), tag('Descargar', 'BOOL'),
];

function server() {
  vi.stubGlobal('fetch', async (path: string, init: RequestInit = {}) => {
    const json = (j: unknown) => new Response(JSON.stringify(j), { status: 200, headers: { 'Content-Type': 'application/json' } });
    if (path.startsWith('/api/programs/') && (init.method ?? 'GET') === 'GET') return json({ name: 'main.lad', language: 'ladder', plant: false, text: TANK.text, diagnostics: [], rungs: TANK.rungs });
    if (path.startsWith('/api/check/')) return json({ diagnostics: [], rungs: [] });
    return json({});
  });
}

async function view() {
  server();
  const tags = new TagCache();
  tags.set(TAGS);
  const live = new LiveClient('ws://127.0.0.1:1/none');
  const ctx = { live, tags, notify: () => undefined } as unknown as Ctx;
  const v = new LadderView(ctx, 'main.lad');
  document.body.append(v.el);
  await v.load();
  v.show();
  return { v, tags };
}

const rungsEl = (v: LadderView) => v.el.querySelector<HTMLElement>('[data-testid="rungs"]')!;
const svgs = (v: LadderView) => [...v.el.querySelectorAll('svg.rung-svg')];
const press = (v: LadderView, key: string, opts: KeyboardEventInit = {}) =>
  rungsEl(v).dispatchEvent(new KeyboardEvent('keydown', { key, bubbles: true, cancelable: true, ...opts }));
const selected = (v: LadderView) => {
  const el = v.el.querySelector('.rung.selected, g.el.selected');
  return el ? `${el.closest('[data-rung]')!.getAttribute('data-rung')}:${el.getAttribute('data-path') ?? ''}` : null;
};
/** Clicks the element of rung `rung` at `path`. */
const click = (v: LadderView, rung: number, path: string) =>
  v.el.querySelector(`[data-rung="${rung}"] [data-path="${path}"] rect.hit`)!.dispatchEvent(new MouseEvent('click', { bubbles: true }));

afterEach(() => {
  closeMenu();
  vi.unstubAllGlobals();
  document.body.replaceChildren();
  localStorage.clear();
});

describe('the ladder tab draws again only what changed', () => {
  it('a click keeps every other rung on screen as it was', async () => {
    const { v } = await view();
    const before = svgs(v);
    expect(before.length).toBe(11);
    click(v, 8, '0'); // XIC(FILL), rung 9
    expect(selected(v)).toBe('8:0');
    const after = svgs(v);
    expect(after.filter((s, k) => s === before[k]).length).toBe(10);
    expect(after[8]).not.toBe(before[8]);
    // another element of the same rung, then one of rung 2: only the rungs involved
    click(v, 8, '2');
    const third = svgs(v);
    expect(third.filter((s, k) => s !== after[k]).length).toBe(1);
    click(v, 1, '0');
    const fourth = svgs(v);
    expect(fourth.map((s, k) => s !== third[k]).flatMap((changed, k) => (changed ? [k] : []))).toEqual([1, 8]);
  });

  it('an operand edit draws its rung only; a force draws only the rungs that use the tag', async () => {
    const { v, tags } = await view();
    click(v, 8, '0');
    const before = svgs(v);
    const input = v.el.querySelector<HTMLInputElement>('[data-testid="operand-0"]')!;
    input.value = 'STOP';
    input.dispatchEvent(new Event('change'));
    const after = svgs(v);
    expect(after.map((s, k) => s !== before[k]).flatMap((changed, k) => (changed ? [k] : []))).toEqual([8]);
    expect(v.el.querySelector('[data-rung="8"] text.operand')!.textContent).toBe('STOP');
    expect(selected(v)).toBe('8:0');
    // STOP is used by rung 2 and now by rung 9: a force on it redraws those two (their F badge)
    tags.set(TAGS, [{ name: 'STOP', value: true }]);
    const forced = svgs(v);
    expect(forced.map((s, k) => s !== after[k]).flatMap((changed, k) => (changed ? [k] : []))).toEqual([1, 8]);
    expect(v.el.querySelectorAll('text.forced-badge').length).toBe(2);
  });
});

describe('the keyboard in the ladder', () => {
  it('arrows move the selection through elements, legs and rungs', async () => {
    const { v } = await view();
    press(v, 'ArrowDown');
    expect(selected(v)).toBe('0:');
    press(v, 'ArrowRight');
    expect(selected(v)).toBe('0:0');
    press(v, 'ArrowRight');
    expect(selected(v)).toBe('0:1');
    press(v, 'ArrowRight'); // the last element stays
    expect(selected(v)).toBe('0:1');
    press(v, 'ArrowLeft');
    press(v, 'ArrowLeft');
    expect(selected(v)).toBe('0:');
    // rung 8: XIC(Llenar)XIO(L_STP)[OTE(Bomba1),OTE(L_FILL)] — down from one leg to the other
    click(v, 7, '2.0.0');
    expect(selected(v)).toBe('7:2.0.0');
    press(v, 'ArrowDown');
    expect(selected(v)).toBe('7:2.1.0');
    press(v, 'ArrowUp');
    expect(selected(v)).toBe('7:2.0.0');
    press(v, 'Home');
    expect(selected(v)).toBe('7:0');
    press(v, 'ArrowDown'); // the element of rung 9 under XIC(Llenar): XIC(FILL)
    expect(selected(v)).toBe('8:0');
    press(v, 'End');
    expect(selected(v)).toBe('8:6');
  });

  it('Shift+F10 and the menu key open the selected element’s force menu, with the focus on its first item', async () => {
    const { v } = await view();
    click(v, 8, '0'); // XIC(FILL): an input
    rungsEl(v).focus();
    press(v, 'F10', { shiftKey: true });
    const menu = document.querySelector('[data-testid="context-menu"]')!;
    expect(menu.querySelector('.menu-title')!.textContent).toBe('XIC(FILL)');
    expect((document.activeElement as HTMLElement).dataset.testid).toBe('menu-force-on');
    menu.dispatchEvent(new KeyboardEvent('keydown', { key: 'ArrowDown', bubbles: true }));
    expect((document.activeElement as HTMLElement).dataset.testid).toBe('menu-force-off');
    closeMenu();
    expect(document.activeElement).toBe(rungsEl(v));
    expect(document.querySelector('[data-testid="context-menu"]')).toBeNull();
    press(v, 'ContextMenu');
    expect(document.querySelector('[data-testid="context-menu"] .menu-title')!.textContent).toBe('XIC(FILL)');
  });
});

describe('navigate (pure)', () => {
  const item = (path: string, x: number, y: number, w = 80, h = 50): NavItem => ({ path, x, y, w, h });
  // rung 0: A [B, C] D — a branch at 100 with legs at y 0 and y 60; rung 1: E F
  const rungs = [[item('0', 0, 0), item('1', 100, 0, 100, 110), item('1.0.0', 110, 0), item('1.1.0', 110, 60), item('2', 220, 0)], [item('0', 0, 0), item('1', 100, 0)], null];

  it('walks program order, goes across legs, and to the nearest element of the next rung', () => {
    expect(navigate(rungs, null, 'ArrowRight')).toEqual({ rung: 0, path: null });
    expect(navigate(rungs, { rung: 0, path: '0' }, 'ArrowRight')).toEqual({ rung: 0, path: '1' });
    expect(navigate(rungs, { rung: 0, path: '1' }, 'ArrowRight')).toEqual({ rung: 0, path: '1.0.0' });
    expect(navigate(rungs, { rung: 0, path: '1.0.0' }, 'ArrowDown')).toEqual({ rung: 0, path: '1.1.0' });
    expect(navigate(rungs, { rung: 0, path: '1.1.0' }, 'ArrowDown')).toEqual({ rung: 1, path: '1' });
    expect(navigate(rungs, { rung: 0, path: '2' }, 'ArrowDown')).toEqual({ rung: 1, path: '1' });
    expect(navigate(rungs, { rung: 1, path: '0' }, 'ArrowUp')).toEqual({ rung: 0, path: '0' });
    expect(navigate(rungs, { rung: 1, path: '1' }, 'ArrowDown')).toEqual({ rung: 2, path: null });
    expect(navigate(rungs, { rung: 2, path: null }, 'ArrowDown')).toEqual({ rung: 2, path: null });
    expect(navigate(rungs, { rung: 2, path: null }, 'ArrowRight')).toEqual({ rung: 2, path: null });
    expect(navigate([], null, 'ArrowDown')).toBeNull();
  });
});
