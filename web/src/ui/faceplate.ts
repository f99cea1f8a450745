// The PID faceplate (issue 17, item 8; after 004_…'s ASC-PID screen): a
// loop's SP, PV and CV live with a trend of the last minute (SP and PV on the
// PV's scale, CV on its own), auto/manual, the manual
// output moved by ↑/↓ (1 % of the CV range a step), the setpoint (operators),
// the gains (engineers), and its status bits. Opened from a PID tag's row.
// Every change is a tag write through the API, like everywhere.
import { api } from '../api';
import { can, why } from '../auth';
import type { Ctx } from '../ctx';
import { fmt, h, s } from '../dom';
import { tr } from '../i18n';
import type { Json } from '../types';

const POINTS = 120;
const BITS = ['MAN', 'UL', 'LL', 'SPOR', 'PVOR', 'INDB'];

/** A polyline of `values` (oldest first) in a w × h box scaled to [lo, hi]. */
export function polyline(values: number[], w: number, h: number, lo: number, hi: number): string {
  const span = hi - lo || 1;
  return values.map((v, k) => `${((k / Math.max(1, POINTS - 1)) * w).toFixed(1)},${(h - ((v - lo) / span) * h).toFixed(1)}`).join(' ');
}

export function openFaceplate(ctx: Ctx, tag: string): HTMLElement {
  const store = ctx.live.store;
  const get = (m: string) => store.get(`${tag}.${m}`);
  const num = (m: string) => (typeof get(m) === 'number' ? (get(m) as number) : 0);
  const write = (m: string, v: Json) => api.writeTag(`${tag}.${m}`, v).catch((e) => ctx.notify(e instanceof Error ? e.message : String(e), 'error'));
  const unwatch: (() => void)[] = [];
  const hist: Record<'SP' | 'PV' | 'CV', number[]> = { SP: [], PV: [], CV: [] };
  const W = 320;
  const H = 120;
  const lines = { SP: s('polyline', { fill: 'none', stroke: '#1f77b4', 'stroke-width': 1.5 }), PV: s('polyline', { fill: 'none', stroke: '#2ca02c', 'stroke-width': 1.5 }), CV: s('polyline', { fill: 'none', stroke: '#ff7f0e', 'stroke-width': 1.5 }) };
  const trend = s('svg', { width: W, height: H, viewBox: `0 0 ${W} ${H}`, class: 'faceplate-trend', 'data-testid': 'faceplate-trend' }, s('rect', { width: W, height: H, fill: '#fff', stroke: '#ccc' }), lines.SP, lines.PV, lines.CV);
  const value = (m: string) => h('span', { class: 'fp-value', 'data-testid': `faceplate-${m}` }, '…');
  const values = { SP: value('SP'), PV: value('PV'), CV: value('CV') };
  const spIn = h('input', { type: 'number', step: 'any', 'data-testid': 'faceplate-sp-input', disabled: !can('write'), title: why('write') ?? tr('A new setpoint (Enter)') });
  spIn.addEventListener('keydown', (e) => e.key === 'Enter' && Number.isFinite(Number(spIn.value)) && void write('SP', Number(spIn.value)));
  const manual = h('button', { 'data-testid': 'faceplate-mode', disabled: !can('write'), title: why('write') ?? '' });
  manual.onclick = () => void write('MAN', get('MAN') !== true);
  const step = (dir: number) => () => void write('CV', num('CV') + dir * Math.max(1e-6, (num('MAXCV') - num('MINCV')) / 100 || 1));
  const up = h('button', { 'data-testid': 'faceplate-up', title: tr('Manual output up by 1 %') }, '↑');
  const down = h('button', { 'data-testid': 'faceplate-down', title: tr('Manual output down by 1 %') }, '↓');
  up.onclick = step(1);
  down.onclick = step(-1);
  const gain = (m: string) => {
    const input = h('input', { type: 'number', step: 'any', size: 7, 'data-testid': `faceplate-gain-${m}`, disabled: !can('edit'), title: why('edit') ?? '' });
    input.addEventListener('change', () => Number.isFinite(Number(input.value)) && void write(m, Number(input.value)));
    unwatch.push(store.watch(`${tag}.${m}`, (v) => document.activeElement !== input && (input.value = fmt(v))));
    return h('label', null, m, ' ', input);
  };
  const bits = h('div', { class: 'fp-bits' }, BITS.map((b) => h('span', { class: 'fp-bit', 'data-testid': `faceplate-bit-${b}` }, b)));
  const close = h('button', { 'data-testid': 'faceplate-close' }, tr('Close'));
  const box = h('div', { class: 'modal', 'data-testid': 'faceplate' },
    h('div', { class: 'modal-box faceplate' },
      h('h2', null, tr('PID loop {name}', { name: tag })),
      trend,
      h('div', { class: 'fp-values' },
        h('span', { class: 'fp-sp' }, 'SP ', values.SP), h('span', { class: 'fp-pv' }, 'PV ', values.PV), h('span', { class: 'fp-cv' }, 'CV ', values.CV)),
      h('div', { class: 'fp-row' }, h('label', null, tr('Setpoint'), ' ', spIn), manual, down, up),
      h('div', { class: 'fp-row' }, gain('KP'), gain('KI'), gain('KD')),
      bits,
      h('div', { class: 'modal-buttons' }, close)));
  // The values as they change; the trend samples all three twice a second
  // (a loop at rest still draws its lines).
  for (const m of ['SP', 'PV', 'CV'] as const) unwatch.push(store.watch(`${tag}.${m}`, (v) => (values[m].textContent = fmt(v))));
  const sample = () => {
    for (const k of ['SP', 'PV', 'CV'] as const) {
      hist[k].push(num(k));
      if (hist[k].length > POINTS) hist[k].shift();
    }
    // SP and PV on the PV's scale (MINS–MAXS), CV on its own (MINCV–MAXCV)
    const pv = [...hist.SP, ...hist.PV];
    const [lo, hi] = [Math.min(num('MINS'), ...pv), Math.max(num('MAXS'), ...pv)];
    for (const k of ['SP', 'PV'] as const) lines[k].setAttribute('points', polyline(hist[k], W, H, lo, hi));
    lines.CV.setAttribute('points', polyline(hist.CV, W, H, Math.min(num('MINCV'), ...hist.CV), Math.max(num('MAXCV'), ...hist.CV)));
  };
  const timer = setInterval(sample, 500);
  unwatch.push(() => clearInterval(timer));
  const showMode = () => {
    const man = get('MAN') === true;
    manual.textContent = man ? tr('Manual → Auto') : tr('Auto → Manual');
    manual.dataset.mode = man ? 'manual' : 'auto';
    up.disabled = down.disabled = !man || !can('write');
  };
  unwatch.push(store.watch(`${tag}.MAN`, showMode));
  showMode();
  for (const b of BITS) unwatch.push(store.watch(`${tag}.${b}`, (v) => box.querySelector(`[data-testid="faceplate-bit-${b}"]`)?.classList.toggle('on', v === true)));
  // what the faceplate shows, subscribed while it is open
  ctx.live.subscribe('faceplate', [tag]);
  close.onclick = () => {
    unwatch.forEach((f) => f());
    ctx.live.subscribe('faceplate', null);
    box.remove();
  };
  document.body.append(box);
  return box;
}
