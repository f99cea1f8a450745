// The Verify & Test page (issue 37; docs/verify.md "In the studio"): the
// project's properties and test tables with their last result, run on the
// saved project (POST /api/verify, POST /api/tests). A refuted property's
// counterexample (a reachable property's witness too) opens as a replay: a
// time slider over its scans, the tags' values at that scan, the ladder
// programs drawn with the power flow of that scan, and the nets and SFC
// charts drawn by their own views (net/view.ts, sfc/view.ts) with that
// scan's marking, fired transitions and active steps; the violating scan
// marked. The tables' coverage is overlaid on the same ladder: elements
// never powered by any table are marked. Running takes seconds of CPU: the
// server gives it to engineers, one run at a time.
import { api } from '../api';
import type { PropertyResult, Replay, TestsReply, VerifyReply } from '../api.gen';
import { gate } from '../auth';
import type { Ctx } from '../ctx';
import { clear, h } from '../dom';
import { tr } from '../i18n';
import { layoutRung } from '../ladder/layout';
import { attachIds } from '../ladder/locate';
import { parseProgram } from '../ladder/parse';
import { type RungView, renderRung } from '../ladder/render';
import { NetView } from '../net/view';
import { SfcView } from '../sfc/view';
import { changeScans, clampScan, coverageMarks, percentOf, powerAt, rowsAt, startScan, stepChange, valueOf, valuesAt } from './logic';

const resultName = (r: string): string =>
  ({ proved: tr('proved'), refuted: tr('refuted'), unknown: tr('unknown'), passed: tr('passed'), failed: tr('failed'), error: tr('error') })[r] ?? r;

/** A ladder program drawn for the replay and the coverage overlay. */
interface Drawn {
  name: string;
  rungs: RungView[];
  box: HTMLElement;
}

export class VerifyTab {
  readonly el: HTMLElement;
  private verified: VerifyReply | null = null;
  private tested: TestsReply | null = null;
  private replay: Replay | null = null;
  private replayOf = '';
  /** The open replay is a witness (the expression becomes true at its last scan), not a counterexample. */
  private witness = false;
  private scan = 0;
  private ladders: Drawn[] | null = null;
  /** The project's nets and SFC charts, drawn by their own views for the replay. */
  private charts: (NetView | SfcView)[] | null = null;
  private readonly runBtn = h('button', { class: 'primary', 'data-testid': 'verify-run' }, tr('Run properties'));
  private readonly testBtn = h('button', { 'data-testid': 'tests-run' }, tr('Run tests'));
  private readonly coverBox = h('input', { type: 'checkbox', 'data-testid': 'coverage-toggle' }) as HTMLInputElement;
  private readonly busy = h('span', { class: 'verify-busy', 'data-testid': 'verify-busy' });
  private readonly props = h('tbody', { 'data-testid': 'verify-properties' });
  private readonly tests = h('tbody', { 'data-testid': 'verify-tests' });
  private readonly coverLine = h('div', { class: 'verify-coverage', 'data-testid': 'verify-coverage' });
  private readonly replayBox = h('section', { class: 'verify-replay', 'data-testid': 'replay', hidden: true });
  private readonly slider = h('input', { type: 'range', min: '0', max: '0', step: '1', 'data-testid': 'replay-slider' }) as HTMLInputElement;
  private readonly scanLabel = h('span', { class: 'replay-scan', 'data-testid': 'replay-scan' });
  private readonly values = h('tbody', { 'data-testid': 'replay-values' });
  private readonly applied = h('div', { class: 'replay-rows', 'data-testid': 'replay-rows' });
  private readonly ladderBox = h('div', { class: 'verify-ladder', 'data-testid': 'verify-ladder' });
  private readonly chartBox = h('div', { class: 'verify-charts', 'data-testid': 'verify-charts' });

  constructor(private readonly ctx: Ctx) {
    gate(this.runBtn, 'edit');
    gate(this.testBtn, 'edit');
    this.runBtn.addEventListener('click', () => void this.runProperties());
    this.testBtn.addEventListener('click', () => void this.runTests());
    this.coverBox.addEventListener('change', () => this.paint());
    this.slider.addEventListener('input', () => this.go(Number(this.slider.value)));
    const step = (label: string, testid: string, title: string, to: () => number) =>
      h('button', { 'data-testid': testid, title, onclick: () => this.go(to()) }, label);
    const changes = () => (this.replay ? changeScans(this.replay) : []);
    this.replayBox.append(
      h('h2', { 'data-testid': 'replay-title' }),
      h('div', { class: 'toolbar' },
        step('|◀', 'replay-first', tr('First scan'), () => 0),
        step('⇤', 'replay-prev-change', tr('Previous change'), () => stepChange(changes(), this.scan, -1)),
        step('◀', 'replay-prev', tr('Previous scan'), () => this.scan - 1),
        this.slider,
        step('▶', 'replay-next', tr('Next scan'), () => this.scan + 1),
        step('⇥', 'replay-next-change', tr('Next change'), () => stepChange(changes(), this.scan, 1)),
        step('▶|', 'replay-violation', tr('The violating scan'), () => (this.replay ? startScan(this.replay) : 0)),
        this.scanLabel),
      this.applied,
      h('table', { class: 'tags replay-values' }, h('thead', null, h('tr', null, h('th', null, tr('Tag')), h('th', null, tr('Value')))), this.values));
    this.el = h('section', { class: 'verify-view', 'data-testid': 'verify-view' },
      h('div', { class: 'toolbar' }, this.runBtn, this.testBtn, h('label', null, this.coverBox, ` ${tr('Coverage on the ladder')}`), this.busy),
      h('h2', null, tr('Properties')),
      h('table', { class: 'tags verify-table' },
        h('thead', null, h('tr', null, h('th', null, tr('Property')), h('th', null, tr('Result')), h('th', null, tr('Depth (scans)')), h('th', null, tr('States')), h('th', null, tr('Time (ms)')), h('th', null, tr('Method')), h('th', null, ''))),
        this.props),
      h('h2', null, tr('Tests')),
      h('table', { class: 'tags verify-table' },
        h('thead', null, h('tr', null, h('th', null, tr('Table')), h('th', null, tr('Result')), h('th', null, tr('Checks')), h('th', null, tr('Scans')), h('th', null, ''))),
        this.tests),
      this.coverLine,
      this.replayBox,
      this.chartBox,
      this.ladderBox);
    this.renderLists();
  }

  show(): void {}

  hide(): void {}

  private fail(e: unknown): void {
    this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
  }

  private async running<T>(what: string, f: () => Promise<T>): Promise<T | null> {
    this.busy.textContent = what;
    this.runBtn.disabled = this.testBtn.disabled = true;
    try {
      return await f();
    } catch (e) {
      this.fail(e);
      return null;
    } finally {
      this.busy.textContent = '';
      this.runBtn.disabled = this.testBtn.disabled = false;
      gate(this.runBtn, 'edit');
      gate(this.testBtn, 'edit');
    }
  }

  async runProperties(): Promise<void> {
    const r = await this.running(tr('Deciding the properties…'), () => api.verify());
    if (!r) return;
    this.verified = r;
    this.renderLists();
  }

  async runTests(): Promise<void> {
    const r = await this.running(tr('Running the test tables…'), () => api.runTests());
    if (!r) return;
    this.tested = r;
    this.coverBox.checked = true;
    this.renderLists();
    await this.drawLadders();
    this.paint();
  }

  private renderLists(): void {
    clear(this.props);
    const ps = this.verified?.properties ?? [];
    if (ps.length === 0) this.props.append(h('tr', null, h('td', { colspan: '6' }, tr('Not run yet: Run properties decides properties.toml on the saved project.'))));
    ps.forEach((p, i) => this.props.append(this.propertyRow(p, i)));
    clear(this.tests);
    const ts = this.tested?.tests ?? [];
    if (ts.length === 0) this.tests.append(h('tr', null, h('td', { colspan: '5' }, tr('Not run yet: Run tests runs tests/*.test.csv on the saved project.'))));
    for (const t of ts) {
      this.tests.append(h('tr', { 'data-testid': `test-${t.name}`, 'data-result': t.result },
        h('td', null, t.file),
        h('td', { class: `result ${t.result}` }, resultName(t.result)),
        h('td', null, String(t.checks)),
        h('td', null, String(t.scans)),
        h('td', null, t.message ?? '')));
    }
    const c = this.tested;
    this.coverLine.textContent = c
      ? tr('Coverage: {r} of {rn} rungs ({rp} %), {b} of {bn} branches, {s} of {sn} instructions switched', {
          r: c.rungs_powered, rn: c.rungs, rp: percentOf(c.rungs_powered, c.rungs), b: c.branches_powered, bn: c.branches, s: c.switched, sn: c.instructions,
        })
      : '';
  }

  private propertyRow(p: PropertyResult, i: number): HTMLElement {
    const run = p.counterexample ?? p.witness;
    const open = run
      ? h('button', { 'data-testid': `open-${i}`, onclick: () => void this.open(p) }, p.counterexample ? tr('Counterexample') : tr('Witness'))
      : '';
    return h('tr', { 'data-testid': `property-${i}`, 'data-result': p.result },
      h('td', null, p.name),
      h('td', { class: `result ${p.result}`, title: p.reason ?? '' }, resultName(p.result), p.reason ? ` — ${p.reason}` : ''),
      h('td', null, String(p.depth)),
      h('td', null, String(p.states)),
      h('td', null, String(p.millis)),
      h('td', { 'data-testid': `method-${i}` }, p.method === 'k-induction' ? tr('k-induction') : tr('explicit')),
      h('td', null, open));
  }

  /** Opens a property's counterexample (or witness) on the violating scan. */
  async open(p: PropertyResult): Promise<void> {
    const r = p.counterexample ?? p.witness;
    if (!r) return;
    this.replay = r;
    this.replayOf = p.name;
    this.witness = !p.counterexample;
    const title = this.replayBox.querySelector('h2');
    if (title) title.textContent = p.counterexample ? tr('Counterexample of “{name}”', { name: p.name }) : tr('Witness of “{name}”', { name: p.name });
    this.slider.max = String(Math.max(0, r.scans.length - 1));
    await this.drawLadders();
    await this.drawCharts();
    this.go(startScan(r));
    // shown once it shows this replay's scan (not the previous one's, nor none)
    this.replayBox.hidden = false;
  }

  /** Shows scan `k` of the open replay. */
  go(k: number): void {
    const r = this.replay;
    if (!r) return;
    this.scan = clampScan(r, k);
    this.slider.value = String(this.scan);
    const t = r.scans[this.scan]?.time_ms ?? 0;
    const bad = this.scan === r.violating_scan;
    this.replayBox.classList.toggle('violation', bad && !this.witness);
    this.scanLabel.textContent =
      tr('scan {k} of {n}, {t} ms', { k: r.first_scan + this.scan + 1, n: r.first_scan + r.scans.length, t }) + (bad ? ` — ${this.witness ? tr('reached here') : tr('the property fails here')}` : '');
    this.scanLabel.dataset.violation = String(bad);
    clear(this.values);
    for (const v of valuesAt(r, this.scan)) {
      this.values.append(h('tr', { class: v.changed ? 'changed' : '', 'data-testid': `replay-value-${v.tag}` }, h('td', null, v.tag), h('td', null, v.value)));
    }
    const rows = rowsAt(r, this.scan);
    this.applied.textContent = rows.length ? `${tr('Set before this scan')}: ${rows.map((x) => `${x.tag} = ${x.value}`).join(', ')}` : '';
    this.paint();
  }

  /** Draws the project's ladder programs once (their saved text, with the compiled element ids). */
  private async drawLadders(): Promise<void> {
    if (this.ladders) return;
    try {
      const refs = (await api.programs()).filter((p) => p.language === 'ladder' && !p.plant);
      const out: Drawn[] = [];
      for (const ref of refs) {
        const prog = await api.program(ref.name);
        const doc = parseProgram(prog.text);
        attachIds(doc, prog.rungs ?? []);
        const box = h('div', { class: 'rungs', 'data-testid': `verify-ladder-${ref.name}` });
        const rungs: RungView[] = [];
        doc.rungs.forEach((rung, i) => {
          if (!rung.elements) return;
          const view = renderRung(layoutRung(rung.elements, rung.comment.length), { number: i, comment: rung.comment, problems: new Map(), selected: null, forced: new Set() }, null);
          rungs.push(view);
          box.append(h('div', { class: 'rung' }, view.svg));
        });
        out.push({ name: ref.name, rungs, box });
      }
      this.ladders = out;
      clear(this.ladderBox);
      for (const d of out) this.ladderBox.append(h('h3', null, d.name), d.box);
    } catch (e) {
      this.fail(e);
    }
  }

  /** Draws the project's nets and SFC charts once, with their own views (the saved text). */
  private async drawCharts(): Promise<void> {
    if (this.charts) return;
    try {
      const refs = (await api.programs()).filter((p) => (p.language === 'net' || p.language === 'sfc') && !p.plant);
      const out: (NetView | SfcView)[] = [];
      for (const ref of refs) {
        const view = ref.language === 'net' ? new NetView(this.ctx, ref.name) : new SfcView(this.ctx, ref.name);
        this.chartBox.append(h('h3', null, ref.name), h('div', { class: 'verify-chart', 'data-testid': `verify-chart-${ref.name}` }, view.el));
        await view.load();
        out.push(view);
      }
      this.charts = out;
    } catch (e) {
      this.fail(e);
    }
  }

  /** The power flow of the replay's scan and the coverage marks, on the drawn ladder; the scan's marking on the charts. */
  private paint(): void {
    if (this.replay) {
      const value = valueOf(this.replay, this.scan);
      const on = powerAt(this.replay, this.scan);
      for (const c of this.charts ?? []) {
        if (c instanceof NetView) c.showScan(value, on);
        else c.showScan((tag) => (tag.endsWith('.X') ? value(tag) === 1 : value(tag)));
      }
    }
    for (const d of this.ladders ?? []) {
      const on = this.replay ? powerAt(this.replay, this.scan) : new Set<number>();
      for (const v of d.rungs) v.setPower(on, this.replay !== null);
      const cov = this.coverBox.checked ? this.tested?.coverage.find((c) => c.program === d.name) : undefined;
      const marks = cov ? coverageMarks(cov) : null;
      d.box.querySelectorAll<SVGElement>('g.el[data-testid^="el-"]').forEach((g) => {
        const id = Number(g.dataset.testid?.slice(3));
        g.classList.toggle('never-powered', marks?.never.has(id) ?? false);
        g.classList.toggle('always-powered', marks?.always.has(id) ?? false);
      });
    }
    this.replayBox.dataset.property = this.replayOf;
  }
}
