// The PID faceplate (issue 17, item 8; after 004_…'s ASC-PID screen): a
// loop's SP, PV and CV live with a trend of the last minute (SP and PV on the
// PV's scale above, CV in % below, each panel with its scale), auto/manual, the manual
// output moved by ↑/↓ (1 % a step: CV is in %, docs/pid.md), the setpoint (operators),
// the gains (engineers), its status bits, the alarms defined on its members
// (PV high/low in alarms.csv), and autotune: the relay experiment on a copy
// of the program and its plant models (POST /api/pid/{name}/autotune), whose
// rules' gains an engineer applies with one click. Opened from a PID tag's
// row or a faceplate element of a screen. Every change is a tag write
// through the API, like everywhere. The function keys of the source's PID
// monitor (fkeys.ts): F1 the control view, F3 auto/manual, ↑ ↓ the manual
// output, F5 the tank alone, F6 tank and trend, F8/F9 the loop's alarms in
// and out of service.
import { api } from '../api';
import { can, why } from '../auth';
import type { Ctx } from '../ctx';
import { fmt, h, s } from '../dom';
import { tr } from '../i18n';
import type { Json } from '../types';
import { type FaceplateAction, faceplateKey, faceplateParts, tankFill } from './fkeys';

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
  // two panels, never one scale for two units: SP and PV in the PV's units above, CV in % below
  const [W, LEFT, PV_H, CV_H, GAP] = [320, 40, 84, 40, 8];
  const PW = W - LEFT - 2;
  const lines = { SP: s('polyline', { fill: 'none', stroke: '#1f77b4', 'stroke-width': 1.5 }), PV: s('polyline', { fill: 'none', stroke: '#2ca02c', 'stroke-width': 1.5 }), CV: s('polyline', { fill: 'none', stroke: '#ff7f0e', 'stroke-width': 1.5 }) };
  const scaleText = (part: string, y: number) => s('text', { x: LEFT - 4, y, 'text-anchor': 'end', 'dominant-baseline': 'middle', 'font-size': 10, fill: '#5f6368', 'data-part': part });
  const scale = { pvHi: scaleText('pv-max', 2 + 5), pvLo: scaleText('pv-min', 2 + PV_H - 5), cvHi: scaleText('cv-max', 2 + PV_H + GAP + 5), cvLo: scaleText('cv-min', 2 + PV_H + GAP + CV_H - 5) };
  const panel = (y: number, hgt: number, testid: string, ...ls: SVGElement[]) =>
    s('g', { transform: `translate(${LEFT},${y})`, 'data-testid': testid }, s('rect', { width: PW, height: hgt, fill: '#fff', stroke: '#ccc' }), ...ls);
  const trend = s('svg', { width: W, height: PV_H + GAP + CV_H + 4, viewBox: `0 0 ${W} ${PV_H + GAP + CV_H + 4}`, class: 'faceplate-trend', 'data-testid': 'faceplate-trend' },
    panel(2, PV_H, 'faceplate-trend-pv', lines.SP, lines.PV),
    panel(2 + PV_H + GAP, CV_H, 'faceplate-trend-cv', lines.CV),
    Object.values(scale));
  // F5/F6: the PV as a tank's level on its scale (MINS–MAXS), beside or instead of the trend
  const [TW, TH] = [60, PV_H + GAP + CV_H];
  const water = s('rect', { x: 6, width: TW - 12, y: TH, height: 0, fill: '#5dade2', 'data-testid': 'faceplate-tank-level' });
  const tank = s('svg', { width: TW, height: TH + 4, viewBox: `0 0 ${TW} ${TH + 4}`, class: 'faceplate-tank', 'data-testid': 'faceplate-tank' },
    water, s('rect', { x: 6, y: 2, width: TW - 12, height: TH - 2, fill: 'none', stroke: '#5f6368', 'stroke-width': 2 }));
  const show = h('div', { class: 'fp-show', 'data-testid': 'faceplate-show' });
  const setView = (view: 'control' | 'tank' | 'combined') => {
    const parts = faceplateParts(view);
    show.dataset.view = view;
    show.replaceChildren(...(parts.tank ? [tank] : []), ...(parts.trend ? [trend] : []));
  };
  setView('control');
  const value = (m: string) => h('span', { class: 'fp-value', 'data-testid': `faceplate-${m}` }, '…');
  const values = { SP: value('SP'), PV: value('PV'), CV: value('CV') };
  const spIn = h('input', { type: 'number', step: 'any', 'data-testid': 'faceplate-sp-input', disabled: !can('write'), title: why('write') ?? tr('A new setpoint (Enter)') });
  spIn.addEventListener('keydown', (e) => e.key === 'Enter' && Number.isFinite(Number(spIn.value)) && void write('SP', Number(spIn.value)));
  // the setpoint box holds the setpoint, except while it is being typed in
  unwatch.push(store.watch(`${tag}.SP`, (v) => document.activeElement !== spIn && (spIn.value = typeof v === 'number' ? fmt(v) : '')));
  const manual = h('button', { 'data-testid': 'faceplate-mode', disabled: !can('write'), title: why('write') ?? '' });
  manual.onclick = () => void write('MAN', get('MAN') !== true);
  // CV is in % (MINO–MAXO, 0–100 by default); MINCV–MAXCV only scales the output tag
  const step = (dir: number) => () => void write('CV', Math.max(num('MINO'), Math.min(num('MAXO') || 100, num('CV') + dir)));
  const up = h('button', { 'data-testid': 'faceplate-up', title: tr('Manual output up by 1 %') }, '↑');
  const down = h('button', { 'data-testid': 'faceplate-down', title: tr('Manual output down by 1 %') }, '↓');
  up.onclick = step(1);
  down.onclick = step(-1);
  const gain = (m: string) => {
    const input = h('input', { type: 'number', step: 'any', size: 7, 'data-testid': `faceplate-gain-${m}`, disabled: !can('edit'), title: why('edit') ?? '' });
    input.addEventListener('change', () => Number.isFinite(Number(input.value)) && void write(m, Number(input.value)));
    unwatch.push(store.watch(`${tag}.${m}`, (v) => document.activeElement !== input && (input.value = fmt(v))));
    const unit = h('span', { class: 'hint', 'data-testid': `faceplate-unit-${m}` });
    return { label: h('label', null, m, ' ', input, ' ', unit), unit };
  };
  // The gains the loop uses: KC, TI, TD with DEP (TI and TD in minutes with
  // MINUTES, the SLC's units, else seconds), KP, KI, KD without.
  const gains = Object.fromEntries(['KP', 'KI', 'KD', 'KC', 'TI', 'TD'].map((m) => [m, gain(m)]));
  const gainRow = h('div', { class: 'fp-row', 'data-testid': 'faceplate-gains' });
  const showGains = () => {
    const t = get('MINUTES') === true ? 'min' : 's';
    const units: Record<string, string> = { KP: '', KI: '1/s', KD: 's', KC: '', TI: t, TD: t };
    const shown = get('DEP') === true ? ['KC', 'TI', 'TD'] : ['KP', 'KI', 'KD'];
    for (const m of shown) gains[m].unit.textContent = units[m];
    gainRow.replaceChildren(...shown.map((m) => gains[m].label));
  };
  for (const m of ['DEP', 'MINUTES']) unwatch.push(store.watch(`${tag}.${m}`, showGains));
  showGains();
  const bits = h('div', { class: 'fp-bits' }, BITS.map((b) => h('span', { class: 'fp-bit', 'data-testid': `faceplate-bit-${b}` }, b)));
  const alarms = h('div', { class: 'fp-alarms', 'data-testid': 'faceplate-alarms' });
  const myAlarms = async () => (await api.alarms().catch(() => [])).filter((a) => a.tag === tag || a.tag.startsWith(`${tag}.`));
  // F8/F9: every alarm of the loop back in service, or out of service (engineers)
  const alarmsInService = async (on: boolean) => {
    if (!can('edit')) return ctx.notify(why('edit') ?? tr('Not allowed'), 'error');
    for (const a of await myAlarms()) {
      await api.alarmOutOfService(a.id, !on, on ? tr('F8: alarms on (faceplate)') : tr('F9: alarms off (faceplate)')).catch((e) => ctx.notify(e instanceof Error ? e.message : String(e), 'error'));
    }
    void showAlarms();
  };
  const showAlarms = async () => {
    const mine = await myAlarms();
    alarms.replaceChildren(...mine.map((a) => h('span', { class: `fp-alarm ${a.state}`, 'data-testid': `faceplate-alarm-${a.id}`, title: a.message }, `${a.id}: ${a.state.replace('_', ' ')}`)));
  };
  void showAlarms();
  unwatch.push(ctx.live.onBatch((b) => b.alarms && void showAlarms()));
  const tune = autotune(ctx, tag, get, write);
  const close = h('button', { 'data-testid': 'faceplate-close' }, tr('Close'));
  const box = h('div', { class: 'modal', 'data-testid': 'faceplate' },
    h('div', { class: 'modal-box faceplate' },
      h('h2', null, tag),
      h('p', { class: 'hint fp-what', 'data-testid': 'faceplate-what' }, ctx.tags?.list.find((t) => t.name.toUpperCase() === tag.toUpperCase())?.description || tr('PID loop')),
      show,
      h('p', { class: 'hint fp-keys' }, tr('F1 control · F3 auto/manual · F5 tank · F6 tank and trend · F8/F9 alarms on/off')),
      h('div', { class: 'fp-values' },
        h('span', { class: 'fp-sp' }, 'SP ', values.SP), h('span', { class: 'fp-pv' }, 'PV ', values.PV), h('span', { class: 'fp-cv' }, 'CV ', values.CV)),
      h('div', { class: 'fp-row' }, h('label', null, tr('Setpoint'), ' ', spIn), manual, down, up),
      gainRow,
      h('div', { class: 'fp-row' }, gain('MINO').label, gain('MAXO').label),
      bits,
      alarms,
      tune,
      h('div', { class: 'modal-buttons' }, close)));
  // The values as they change; the trend samples all three twice a second
  // (a loop at rest still draws its lines).
  for (const m of ['SP', 'PV', 'CV'] as const) unwatch.push(store.watch(`${tag}.${m}`, (v) => (values[m].textContent = fmt(v))));
  const sample = () => {
    for (const k of ['SP', 'PV', 'CV'] as const) {
      hist[k].push(num(k));
      if (hist[k].length > POINTS) hist[k].shift();
    }
    // SP and PV on the PV's scale (MINS–MAXS), CV on its own (MINO–MAXO, %)
    const pv = [...hist.SP, ...hist.PV];
    const [lo, hi] = [Math.min(num('MINS'), ...pv), Math.max(num('MAXS'), ...pv)];
    for (const k of ['SP', 'PV'] as const) lines[k].setAttribute('points', polyline(hist[k], PW, PV_H, lo, hi));
    const [clo, chi] = [Math.min(num('MINO'), ...hist.CV), Math.max(num('MAXO') || 100, ...hist.CV)];
    lines.CV.setAttribute('points', polyline(hist.CV, PW, CV_H, clo, chi));
    const f = tankFill(num('PV'), lo, hi);
    water.setAttribute('y', String(TH - f * (TH - 2)));
    water.setAttribute('height', String(f * (TH - 2)));
    const label = (t: SVGElement, text: string) => t.textContent !== text && (t.textContent = text);
    label(scale.pvHi, fmt(hi));
    label(scale.pvLo, fmt(lo));
    label(scale.cvHi, `${fmt(chi)} %`);
    label(scale.cvLo, `${fmt(clo)} %`);
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
  const act: Record<FaceplateAction, () => void> = {
    control: () => setView('control'),
    tank: () => setView('tank'),
    combined: () => setView('combined'),
    mode: () => !manual.disabled && manual.click(),
    up: () => !up.disabled && up.click(),
    down: () => !down.disabled && down.click(),
    'alarms-on': () => void alarmsInService(true),
    'alarms-off': () => void alarmsInService(false),
  };
  const onKey = (e: KeyboardEvent) => {
    // a faceplate removed without Close (the page replaced) lets go of the keys
    if (!box.isConnected) return document.removeEventListener('keydown', onKey);
    const a = faceplateKey(e);
    // arrows in a number box keep their own meaning
    if (!a || ((a === 'up' || a === 'down') && e.target instanceof HTMLInputElement)) return;
    e.preventDefault();
    act[a]();
  };
  document.addEventListener('keydown', onKey);
  unwatch.push(() => document.removeEventListener('keydown', onKey));
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

/**
 * The autotune panel: the relay's settings, Run, and the rules' gains, each
 * with Apply (KC/TI/TD when the loop uses dependent gains, KP/KI/KD
 * otherwise). Engineers only: it sets gains.
 */
function autotune(ctx: Ctx, tag: string, get: (m: string) => Json | undefined, write: (m: string, v: Json) => Promise<unknown>): HTMLElement {
  const input = (name: string, value: number | null, title: string) =>
    h('label', { title }, name, ' ', h('input', { type: 'number', step: 'any', size: 5, value: value === null ? '' : String(value), placeholder: value === null ? tr('auto') : '', 'data-testid': `autotune-${name}` }));
  // An empty bias: the loop's own output once it holds PV at SP (docs/pid.md §6).
  const fields = [input('amplitude', 10, tr('Relay amplitude, % of CV')), input('bias', null, tr('Relay centre, % of CV (empty: the output of the loop once it holds PV at SP)')), input('hysteresis', 0, tr('Hysteresis, units of the PV'))];
  const sp = input('sp', 0, tr('Setpoint during the experiment'));
  const run = h('button', { 'data-testid': 'autotune-run', disabled: !can('edit'), title: why('edit') ?? tr('Runs the relay experiment on a copy of the program and its plant models; the running loop is not touched') }, tr('Autotune'));
  const result = h('div', { class: 'fp-tune-result', 'data-testid': 'autotune-result' });
  run.onclick = async () => {
    const req: Record<string, number> = {};
    for (const l of [...fields, sp]) {
      const i = l.querySelector('input')!;
      if (i.value.trim() !== '') req[i.dataset.testid!.replace('autotune-', '')] = Number(i.value);
    }
    run.disabled = true;
    result.replaceChildren(h('p', { class: 'hint' }, tr('Running the relay experiment…')));
    try {
      const r = await api.autotune(tag, req);
      const dep = get('DEP') === true;
      // the rules' TI and TD are seconds; a loop with MINUTES holds minutes
      const per = get('MINUTES') === true ? 60 : 1;
      const apply = (g: (typeof r.rules)[0]) => async () => {
        const gains: [string, number][] = dep ? [['KC', g.kc], ['TI', g.ti / per], ['TD', g.td / per]] : [['KP', g.kp], ['KI', g.ki], ['KD', g.kd]];
        for (const [m, v] of gains) await write(m, Number(v.toPrecision(6)));
        ctx.notify(tr('{rule} gains applied to {name}', { rule: g.rule, name: tag }));
      };
      result.replaceChildren(
        h('p', { 'data-testid': 'autotune-ku' }, `Ku = ${r.ku.toFixed(4)}, Pu = ${r.pu.toFixed(3)} s (${tr('{n} cycles', { n: r.cycles })})`),
        h('table', { class: 'tags' },
          h('thead', null, h('tr', null, [tr('Rule'), dep ? 'KC' : 'KP', dep ? `TI (${per === 60 ? 'min' : 's'})` : 'KI', dep ? `TD (${per === 60 ? 'min' : 's'})` : 'KD', ''].map((c) => h('th', null, c)))),
          h('tbody', null, r.rules.map((g, k) => {
            const b = h('button', { class: 'small', 'data-testid': `autotune-apply-${k}` }, tr('Apply'));
            b.onclick = apply(g);
            const [a, b2, c] = dep ? [g.kc, g.ti / per, g.td / per] : [g.kp, g.ki, g.kd];
            return h('tr', null, h('td', null, g.rule), h('td', null, a.toFixed(4)), h('td', null, b2.toFixed(4)), h('td', null, c.toFixed(4)), h('td', null, b));
          }))));
    } catch (e) {
      result.replaceChildren(h('p', { class: 'inline-error', 'data-testid': 'autotune-error' }, e instanceof Error ? e.message : String(e)));
    } finally {
      run.disabled = !can('edit');
    }
  };
  const spInput = sp.querySelector('input')!;
  spInput.value = fmt(get('SP') ?? 0);
  return h('details', { class: 'fp-tune', 'data-testid': 'faceplate-autotune' },
    h('summary', null, tr('Autotune (relay experiment)')),
    h('div', { class: 'fp-row' }, sp, ...fields, run),
    result);
}
