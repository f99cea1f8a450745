// The optional 4th operand of TON, TOF and RTO (issue 34, point 3): the time
// base of `TON(Delay,5,0,s)`. The domain describes it (label, choices,
// default); the editor labels it "Time base", offers its choices and never
// takes it for a tag.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { type Ctx, TagCache } from '../src/ctx';
import { instruction } from '../src/domain';
import { operandLabels, operandTags, optionalAt } from '../src/ladder/ast';
import { LadderView } from '../src/ladder/view';
import { LiveClient } from '../src/live/client';
import type { TagInfo } from '../src/types';

const TEXT = '// a delay in seconds\nXIC(Run)TON(Delay,5,0,s);\n// another in milliseconds\nXIC(Run)TOF(Hold,500,0);\n';

const tag = (name: string, type: string): TagInfo =>
  ({ name, type, address: null, notations: [], description: '', retain: false, access: 'readwrite', value: null, forced: null }) as TagInfo;

async function view(program = TEXT) {
  vi.stubGlobal('fetch', async (path: string, init: RequestInit = {}) => {
    const json = (j: unknown) => new Response(JSON.stringify(j), { status: 200, headers: { 'Content-Type': 'application/json' } });
    if (path.startsWith('/api/programs/') && (init.method ?? 'GET') === 'GET') return json({ name: 'main.lad', language: 'ladder', plant: false, text: program, diagnostics: [], rungs: [] });
    if (path.startsWith('/api/check/')) return json({ diagnostics: [], rungs: [] });
    return json({});
  });
  const tags = new TagCache();
  // a tag named like a time base: the operand `s` must still not be taken for it
  tags.set([tag('Run', 'BOOL'), tag('Delay', 'TIMER'), tag('Hold', 'TIMER'), tag('s', 'BOOL')]);
  const ctx = { live: new LiveClient('ws://127.0.0.1:1/none'), tags, notify: () => undefined } as unknown as Ctx;
  const v = new LadderView(ctx, 'main.lad');
  document.body.append(v.el);
  await v.load();
  v.show();
  return v;
}

const click = (v: LadderView, rung: number, path: string) =>
  v.el.querySelector(`[data-rung="${rung}"] [data-path="${path}"] rect.hit`)!.dispatchEvent(new MouseEvent('click', { bubbles: true }));
const field = (v: LadderView, k: number) => v.el.querySelector<HTMLSelectElement | HTMLInputElement>(`[data-testid="operand-${k}"]`);
const text = (v: LadderView) => {
  v.el.querySelector<HTMLButtonElement>('[data-testid="view-text"]')!.click();
  return v.el.querySelector<HTMLTextAreaElement>('[data-testid="editor-text"]')!.value;
};

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.replaceChildren();
  localStorage.clear();
});

describe('the time base of TON, TOF and RTO', () => {
  it('is described by the domain as an optional operand with its choices', () => {
    for (const m of ['TON', 'TOF', 'RTO']) {
      expect(instruction(m)!.optional).toEqual([
        { name: 'time_base', label: 'Time base', doc: expect.stringContaining('ms, cs, ds, s or min'), choices: ['ms', 'cs', 'ds', 's', 'min'], default: 'ms' },
      ]);
      expect(optionalAt(m, 3)?.name).toBe('time_base');
      expect(optionalAt(m, 2)).toBeUndefined();
    }
    expect(instruction('TP')!.optional).toEqual([]);
    expect(instruction('CTU')!.optional).toEqual([]);
  });

  it('is labelled "Time base", not "Operand 4"', () => {
    expect(operandLabels('TON', 4)).toEqual(['Timer', 'Preset', 'Accum', 'Time base']);
    expect(operandLabels('RTO', 4)[3]).toBe('Time base');
    expect(operandLabels('TP', 4)[3]).toBe('Operand 4');
  });

  it('is never a tag', () => {
    const i = (mnemonic: string, operands: string[]) => ({ kind: 'instr' as const, mnemonic, operands });
    expect(operandTags(i('TON', ['Delay', '5', '0', 's']))).toEqual(['Delay']);
    expect(operandTags(i('TOF', ['Delay', 'Pre', '0', 'min']))).toEqual(['Delay', 'Pre']);
    expect(operandTags(i('RTO', ['Delay', '5', '0', '0.01']))).toEqual(['Delay']);
  });

  it('is drawn in the box and chosen in the properties panel', async () => {
    const v = await view();
    const box = v.el.querySelector('[data-rung="0"]')!;
    expect([...box.querySelectorAll('text.label')].map((t) => t.textContent)).toEqual(['Timer', 'Preset', 'Accum', 'Time base']);
    click(v, 0, '1');
    const base = field(v, 3)!;
    expect(base.tagName).toBe('SELECT');
    expect(base.value).toBe('s');
    expect([...(base as HTMLSelectElement).options].map((o) => o.value)).toEqual(['', 'ms', 'cs', 'ds', 's', 'min']);
    expect(base.closest('label')!.textContent).toContain('Time base');
    // no "Where used" for `s`, though a tag has that name
    expect(v.el.querySelector('[data-testid="uses-s"]')).toBeNull();
    expect(v.el.querySelector('[data-testid="uses-Delay"]')).not.toBeNull();
    base.value = 'min';
    base.dispatchEvent(new Event('change'));
    expect(text(v)).toContain('TON(Delay,5,0,min)');
  });

  it('is offered at its default when left out, and left out again when set back', async () => {
    const v = await view();
    click(v, 1, '1');
    const base = field(v, 3)! as HTMLSelectElement;
    expect(base.tagName).toBe('SELECT');
    expect(base.value).toBe('');
    expect(base.options[0].textContent).toBe('ms (default)');
    base.value = 'cs';
    base.dispatchEvent(new Event('change'));
    const select = field(v, 3)! as HTMLSelectElement;
    expect(select.value).toBe('cs');
    select.value = '';
    select.dispatchEvent(new Event('change'));
    expect(text(v)).toContain('TOF(Hold,500,0);');
  });

  it('keeps a time base written in seconds (`0.01`) as a choice', async () => {
    const v = await view('XIC(Run)RTO(Delay,5,0,0.01);\n');
    click(v, 0, '1');
    const base = field(v, 3)! as HTMLSelectElement;
    expect(base.value).toBe('0.01');
    expect([...base.options].map((o) => o.value)).toEqual(['', 'ms', 'cs', 'ds', 's', 'min', '0.01']);
    base.value = 'ds';
    base.dispatchEvent(new Event('change'));
    expect(text(v)).toContain('RTO(Delay,5,0,ds)');
  });
});
