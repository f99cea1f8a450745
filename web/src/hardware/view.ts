// The Hardware tab (issue 33; docs/arduino.md "From the studio"): the board
// and its pin map (a drawing of the board's pins, the map as a table with
// each pin's capabilities and problems, saved into alba.toml), the
// machine's serial ports (refreshed, or a path typed by hand; Identify asks
// what answers), Build (flash and RAM against the board's limits) and
// Download of the byte code as a job with its progress, kept after a reload;
// Attach uses the board as the running PLC's I/O (controller firmware) or
// watches the sketch it runs (monitor), and Detach puts the project's own
// I/O back, without restarting `alba run`.
// A viewer sees it all; changes need the engineer role (the server decides).
import { ApiError, api } from '../api';
import type { BoardIdentity, BuildSizes, HardwareJob, HardwareView, PinRow } from '../api.gen';
import { gate } from '../auth';
import type { Ctx } from '../ctx';
import { clear, h, s } from '../dom';
import { tr, when } from '../i18n';
import { boardOf, capsOf, changed, follow, jobToShow, mapOf, percent, placeProblems, rememberJob } from './logic';

const capName = (c: string): string =>
  ({ di: tr('digital in'), do: tr('digital out'), ai: tr('analog in'), ao: tr('PWM out'), serial: tr('serial (PC link)') })[c] ?? c;

const dirName = (d: string): string => ({ di: tr('Digital inputs'), do: tr('Digital outputs'), ai: tr('Analog inputs'), ao: tr('Analog outputs') })[d] ?? d;

export class HardwareTab {
  readonly el: HTMLElement;
  private view: HardwareView | null = null;
  private edits = new Map<string, string>();
  private problems = new Map<string | null, import('../api.gen').Diagnostic[]>();
  private readonly boardSel = h('select', { 'data-testid': 'hw-board' });
  private readonly presetSel = h('select', { 'data-testid': 'hw-pinmap' });
  private readonly saveBtn = h('button', { class: 'primary', 'data-testid': 'hw-save' }, tr('Save board'));
  private readonly undoBtn = h('button', { 'data-testid': 'hw-undo', title: tr('Put [board] back as it was before the last save') }, tr('Undo'));
  private readonly drawing = h('div', { class: 'hw-drawing', 'data-testid': 'hw-drawing' });
  private readonly table = h('tbody', { 'data-testid': 'hw-pins' });
  private readonly tableProblems = h('div', { class: 'hw-problems', 'data-testid': 'hw-problems' });
  private readonly portSel = h('select', { 'data-testid': 'hw-ports' });
  private readonly portTyped = h('input', { type: 'text', 'data-testid': 'hw-port-typed', placeholder: tr('or type a path, as /dev/ttyUSB0') });
  private readonly portInfo = h('div', { class: 'hw-port-info', 'data-testid': 'hw-port-info' });
  private readonly kindSel = h('select', { 'data-testid': 'hw-kind' },
    h('option', { value: 'sketch' }, tr('stand-alone sketch')),
    h('option', { value: 'interpreter' }, tr('byte-code interpreter')),
    h('option', { value: 'controller' }, tr('controller firmware (remote I/O)')));
  private readonly buildBtn = h('button', { 'data-testid': 'hw-build' }, tr('Build'));
  private readonly uploadBtn = h('button', { 'data-testid': 'hw-upload', title: tr('Build the firmware and upload it to the board with avrdude') }, tr('Upload'));
  private readonly sizes = h('div', { class: 'hw-sizes', 'data-testid': 'hw-sizes' });
  private readonly downloadBtn = h('button', { class: 'primary', 'data-testid': 'hw-download' }, tr('Download'));
  private readonly identifyBtn = h('button', { 'data-testid': 'hw-identify' }, tr('Identify'));
  private readonly verifyBtn = h('button', { 'data-testid': 'hw-verify', title: tr('Read the board\'s program back and compare it with the project\'s') }, tr('Verify'));
  private readonly verifyLine = h('div', { class: 'hw-verify', 'data-testid': 'hw-verify-result' });
  private readonly bar = h('progress', { max: '100', value: '0', 'data-testid': 'hw-progress' });
  private readonly jobLine = h('div', { class: 'hw-job', 'data-testid': 'hw-job' });
  private readonly cancelBtn = h('button', { 'data-testid': 'hw-cancel', title: tr('Stop the download: the board keeps its program') }, tr('Cancel'));
  private readonly attachMode = h('select', { 'data-testid': 'hw-attach-mode' },
    h('option', { value: 'controller', title: tr('The board runs the controller firmware (alba firmware): its pins are the PLC\'s inputs and outputs') }, tr('as the PLC\'s I/O (controller firmware)')),
    h('option', { value: 'monitor', title: tr('The board runs the project\'s sketch (alba export arduino): watch it live') }, tr('watch the sketch it runs (monitor)')));
  private readonly attachBtn = h('button', { class: 'primary', 'data-testid': 'hw-attach' }, tr('Attach'));
  private readonly detachBtn = h('button', { 'data-testid': 'hw-detach', title: tr('The project\'s own I/O back; the board\'s outputs go off') }, tr('Detach'));
  private readonly attachedLine = h('div', { class: 'hw-attached', 'data-testid': 'hw-attached' });
  private shownJob = '';
  /** The live values watched for the drawing (unwatch on hide or redraw). */
  private unwatch: (() => void)[] = [];
  private shown = false;
  private following = '';

  constructor(private readonly ctx: Ctx) {
    const refresh = h('button', { 'data-testid': 'hw-refresh', title: tr('List the serial ports again') }, tr('Refresh'));
    refresh.onclick = () => void this.load();
    this.saveBtn.onclick = () => void this.save();
    this.undoBtn.onclick = () => void this.undo();
    this.buildBtn.onclick = () => void this.build();
    this.uploadBtn.onclick = () => void this.upload();
    this.downloadBtn.onclick = () => void this.download();
    this.identifyBtn.onclick = () => void this.identify();
    this.verifyBtn.onclick = () => void this.verify();
    this.cancelBtn.onclick = () => void api.hardwareCancel(this.shownJob).catch((e) => this.fail(e));
    this.cancelBtn.hidden = true;
    this.attachBtn.onclick = () => void this.attach();
    this.detachBtn.onclick = () => void this.detach();
    this.boardSel.onchange = () => this.render();
    this.presetSel.onchange = () => {
      // another preset: the table shows it once saved
      this.edits.clear();
    };
    for (const b of [this.saveBtn, this.buildBtn, this.downloadBtn, this.identifyBtn, this.verifyBtn, this.cancelBtn, this.attachBtn, this.detachBtn, this.uploadBtn]) gate(b, 'hardware');
    this.jobLine.hidden = true;
    this.bar.hidden = true;
    this.el = h('section', { class: 'hardware-view', 'data-testid': 'hardware-view' },
      h('div', { class: 'hw-board-part' },
        h('h2', null, tr('Board')),
        h('div', { class: 'toolbar' },
          h('label', null, tr('Board'), ' ', this.boardSel),
          h('label', null, tr('Pin map'), ' ', this.presetSel),
          this.saveBtn,
          this.undoBtn),
        this.drawing,
        this.tableProblems,
        h('table', { class: 'tags hw-table' },
          h('thead', null, h('tr', null, [tr('Channel'), tr('Pin'), tr('Can be'), tr('Tags'), tr('Problem')].map((c) => h('th', null, c)))),
          this.table)),
      h('div', { class: 'hw-actions' },
        h('h2', null, tr('Serial port')),
        this.portSel,
        h('div', { class: 'toolbar' }, this.portTyped, refresh, this.identifyBtn),
        this.portInfo,
        h('h2', null, tr('Firmware')),
        h('div', { class: 'toolbar' }, this.kindSel, this.buildBtn, this.uploadBtn),
        this.sizes,
        h('h2', null, tr('Program')),
        h('div', { class: 'toolbar' }, this.downloadBtn, this.verifyBtn, this.bar, this.cancelBtn),
        this.jobLine,
        this.verifyLine,
        h('h2', null, tr('Live board')),
        h('div', { class: 'toolbar' }, this.attachMode, this.attachBtn, this.detachBtn),
        this.attachedLine));
  }

  show(): void {
    this.shown = true;
    void this.load();
  }

  hide(): void {
    this.shown = false;
    this.stopWatching();
  }

  private stopWatching(): void {
    for (const u of this.unwatch) u();
    this.unwatch = [];
    this.ctx.live.subscribe('hardware', null);
  }

  /** Lights each wired pin of the drawing while its channel's tag is on (a value not 0). */
  private watchPins(rows: PinRow[]): void {
    this.stopWatching();
    if (!this.shown) return;
    const names: string[] = [];
    for (const r of rows) {
      if (!r.pin || r.tags.length === 0) continue;
      const tag = r.tags[0];
      names.push(tag);
      const pin = this.drawing.querySelector(`[data-testid="hw-board-pin-${r.pin}"]`);
      if (!pin) continue;
      this.unwatch.push(
        this.ctx.live.store.watch(tag, (v) => {
          pin.setAttribute('data-live', v === true || (typeof v === 'number' && v !== 0) ? 'on' : 'off');
        }),
      );
    }
    if (names.length > 0) this.ctx.live.subscribe('hardware', names);
  }

  private fail(e: unknown): void {
    this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
  }

  async load(): Promise<void> {
    try {
      this.view = await api.hardware();
    } catch (e) {
      this.fail(e);
      return;
    }
    this.edits.clear();
    this.problems.clear();
    this.render();
    const job = jobToShow(this.view.jobs);
    if (job) {
      this.showJob(job);
      if (job.state === 'running') void this.follow(job.id);
    }
  }

  /** The port to use: the one typed by hand, else the one chosen. */
  port(): string {
    return this.portTyped.value.trim() || this.portSel.value;
  }

  private render(): void {
    const v = this.view;
    if (!v) return;
    const chosen = this.boardSel.value || v.board || 'uno';
    clear(this.boardSel);
    for (const b of v.boards) this.boardSel.append(h('option', { value: b.name, selected: b.name === chosen }, b.title));
    const preset = this.presetSel.value || v.pinmap;
    clear(this.presetSel);
    for (const p of v.presets) this.presetSel.append(h('option', { value: p, selected: p === preset }, p));
    const board = boardOf(v, chosen);
    // ports: the chosen one kept across a refresh
    const was = this.portSel.value || v.port || '';
    clear(this.portSel);
    if (v.ports.length === 0) this.portSel.append(h('option', { value: '' }, tr('no serial port found')));
    for (const p of v.ports) this.portSel.append(h('option', { value: p.path, selected: p.path === was, title: p.description }, `${p.path} — ${p.description}`));
    // the table
    clear(this.table);
    for (const r of v.pins) this.table.append(this.row(r, board));
    clear(this.tableProblems);
    const general = [...(this.problems.get(null) ?? []), ...v.diagnostics.filter((d) => d.file === 'alba.toml')];
    for (const d of general) this.tableProblems.append(h('div', { class: 'problem' }, `${d.code}: ${d.message}`));
    this.drawBoard(board, v.pins);
    this.watchPins(v.pins);
    this.showAttached(v);
    this.undoBtn.disabled = v.undo === 0;
    if (v.undo > 0) gate(this.undoBtn, 'hardware');
  }

  private async undo(): Promise<void> {
    try {
      this.view = await api.hardwareUndoBoard();
      this.edits.clear();
      this.problems.clear();
      this.boardSel.value = this.view.board ?? '';
      this.presetSel.value = this.view.pinmap;
      this.ctx.notify(tr('Board save undone'));
      this.render();
    } catch (e) {
      this.fail(e);
    }
  }

  private showAttached(v: HardwareView): void {
    const a = v.attached;
    clear(this.attachedLine);
    this.attachedLine.dataset.attached = String(a !== null);
    if (a) {
      this.attachedLine.append(h('strong', null, tr('Attached')), ` — ${when(a.since_ms)}: ${a.message}`);
      this.attachMode.value = a.mode;
    } else {
      this.attachedLine.append(tr('Not attached: the PLC uses its own I/O ({io})', { io: v.io }));
    }
    this.attachBtn.hidden = a !== null;
    this.detachBtn.hidden = a === null;
  }

  private async attach(): Promise<void> {
    const port = this.port();
    if (!port) return this.ctx.notify(tr('Choose a serial port first'), 'error');
    try {
      this.view = await api.hardwareAttach(port, this.attachMode.value);
      this.render();
      this.ctx.notify(tr('Attached to {port}', { port }));
    } catch (e) {
      this.fail(e);
    }
  }

  private async detach(): Promise<void> {
    try {
      this.view = await api.hardwareDetach();
      this.render();
      this.ctx.notify(tr('Detached: the PLC uses its own I/O'));
    } catch (e) {
      this.fail(e);
    }
  }

  private row(r: PinRow, board: ReturnType<typeof boardOf>): HTMLElement {
    const pin = this.edits.get(r.address) ?? r.pin ?? '';
    const input = h('input', { type: 'text', value: pin, size: '4', 'data-testid': `hw-pin-${r.address}`, disabled: r.pin === null });
    gate(input, 'hardware');
    if (r.pin === null) input.disabled = true;
    input.oninput = () => {
      this.edits.set(r.address, input.value);
      caps.textContent = capsOf(board, input.value).map(capName).join(', ');
    };
    const caps = h('td', null, capsOf(board, pin).map(capName).join(', '));
    const placed = this.problems.get(r.address) ?? [];
    const problem = placed[0] ? { code: placed[0].code, message: placed[0].message } : r.problem;
    return h('tr', { class: problem ? 'hw-conflict' : '', 'data-testid': `hw-row-${r.address}`, title: dirName(r.dir) },
      h('td', null, r.address),
      h('td', null, input),
      caps,
      h('td', null, r.tags.join(', ')),
      h('td', { class: 'problem', 'data-testid': `hw-problem-${r.address}` }, problem ? `${problem.code}: ${problem.message}` : ''));
  }

  /** The board's pins in two rows (digital, analog), lit where the map wires a channel. */
  private drawBoard(board: ReturnType<typeof boardOf>, rows: PinRow[]): void {
    clear(this.drawing);
    if (!board) return;
    const used = new Map(rows.filter((r) => r.pin).map((r) => [r.pin!, r]));
    const digital = board.pins.filter((p) => p.pin.startsWith('D'));
    const analog = board.pins.filter((p) => p.pin.startsWith('A'));
    const W = 22;
    const width = Math.max(digital.length, analog.length) * W + 20;
    const svg = s('svg', { viewBox: `0 0 ${width} 110`, width: String(width), height: '110', role: 'img', 'aria-label': board.title });
    svg.append(s('rect', { x: '2', y: '2', width: String(width - 4), height: '106', rx: '6', class: 'hw-pcb' }));
    svg.append(s('text', { x: '10', y: '60', class: 'hw-title' }, board.title));
    const pinAt = (p: { pin: string; caps: string[] }, i: number, y: number) => {
      const r = used.get(p.pin);
      const g = s('g', { 'data-testid': `hw-board-pin-${p.pin}`, class: `hw-pin ${r ? `hw-${r.dir}` : ''} ${p.caps.includes('serial') ? 'hw-serial' : ''}` },
        s('title', null, [`${p.pin}:`, p.caps.map(capName).join(', '), r ? [r.address, ...r.tags].join(' ') : ''].filter(Boolean).join(' ')),
        s('rect', { x: String(10 + i * W), y: String(y), width: '16', height: '16', rx: '3' }),
        s('text', { x: String(18 + i * W), y: String(y + (y < 50 ? -3 : 28)), 'text-anchor': 'middle' }, p.pin));
      svg.append(g);
    };
    digital.forEach((p, i) => pinAt(p, i, 16));
    analog.forEach((p, i) => pinAt(p, i, 74));
    this.drawing.append(svg);
  }

  private async save(): Promise<void> {
    const v = this.view;
    if (!v) return;
    const board = this.boardSel.value;
    const pinmap = this.presetSel.value;
    const body: Record<string, unknown> = { board, pinmap };
    if (pinmap === v.pinmap && changed(v.pins, this.edits)) Object.assign(body, mapOf(v.pins, this.edits));
    // the port typed by hand becomes the project's (alba.toml [board] port)
    const port = this.portTyped.value.trim() || v.port;
    if (port) body.port = port;
    try {
      this.view = await api.saveBoard(body);
      this.edits.clear();
      this.problems.clear();
      this.ctx.notify(tr('Board saved into alba.toml'));
      this.render();
    } catch (e) {
      if (e instanceof ApiError && e.diagnostics.length > 0) {
        this.problems = placeProblems(v.pins, this.edits, e.diagnostics);
        this.render();
        this.ctx.notify(tr('Not saved: {m}', { m: e.diagnostics[0].message }), 'error');
      } else this.fail(e);
    }
  }

  private async build(): Promise<void> {
    this.buildBtn.disabled = true;
    clear(this.sizes);
    this.sizes.append(tr('Building with avr-gcc…'));
    try {
      const b = await api.hardwareBuild(this.boardSel.value, this.kindSel.value);
      this.showSizes(b);
    } catch (e) {
      clear(this.sizes);
      if (e instanceof ApiError && e.diagnostics.length > 0) {
        for (const d of e.diagnostics) this.sizes.append(h('div', { class: 'problem' }, `${d.code} ${d.file ?? ''}${d.line ? `:${d.line}` : ''}: ${d.message}`));
      } else this.sizes.append(h('div', { class: 'problem' }, e instanceof Error ? e.message : String(e)));
    } finally {
      this.buildBtn.disabled = false;
      gate(this.buildBtn, 'hardware');
    }
  }

  private showSizes(b: BuildSizes): void {
    clear(this.sizes);
    const meter = (label: string, used: number, max: number, id: string) =>
      h('div', { class: 'hw-meter', 'data-testid': id },
        h('span', { class: 'hw-meter-label' }, label),
        h('meter', { min: '0', max: String(max), value: String(used), high: String(max * 0.9) }),
        tr('{used} of {max} bytes ({p} %)', { used, max, p: percent(used, max) }));
    this.sizes.append(meter(tr('Flash'), b.flash_bytes, b.flash_max, 'hw-flash'), meter(tr('RAM'), b.ram_bytes, b.ram_max, 'hw-ram'));
  }

  private async identify(): Promise<void> {
    const port = this.port();
    if (!port) return this.ctx.notify(tr('Choose a serial port first'), 'error');
    clear(this.portInfo);
    this.portInfo.append(tr('Asking {port}…', { port }));
    try {
      const id: BoardIdentity = await api.hardwareIdentify(port);
      clear(this.portInfo);
      this.portInfo.append(id.known ? id.message : tr('Unknown device: {m}', { m: id.message.replace(/^unknown device: /, '') }));
    } catch (e) {
      clear(this.portInfo);
      this.portInfo.append(h('span', { class: 'problem' }, e instanceof Error ? e.message : String(e)));
    }
  }

  private async verify(): Promise<void> {
    const port = this.port();
    if (!port) return this.ctx.notify(tr('Choose a serial port first'), 'error');
    clear(this.verifyLine);
    this.verifyLine.append(tr('Reading the program back from {port}…', { port }));
    try {
      const v = await api.hardwareVerify(port);
      clear(this.verifyLine);
      this.verifyLine.dataset.same = String(v.same);
      this.verifyLine.append(h('span', { class: v.same ? '' : 'problem' }, v.message));
    } catch (e) {
      clear(this.verifyLine);
      this.verifyLine.append(h('span', { class: 'problem' }, e instanceof Error ? e.message : String(e)));
    }
  }

  private async upload(): Promise<void> {
    const port = this.port();
    if (!port) return this.ctx.notify(tr('Choose a serial port first'), 'error');
    this.starting();
    try {
      const { job } = await api.hardwareUpload(port, this.boardSel.value, this.kindSel.value);
      rememberJob(job);
      await this.follow(job);
    } catch (e) {
      this.notStarted(e);
    }
  }

  private async download(): Promise<void> {
    const port = this.port();
    if (!port) return this.ctx.notify(tr('Choose a serial port first'), 'error');
    this.starting();
    try {
      const { job } = await api.hardwareDownload(port);
      rememberJob(job);
      await this.follow(job);
    } catch (e) {
      this.notStarted(e);
    }
  }

  private async follow(id: string): Promise<void> {
    if (this.following === id) return;
    this.following = id;
    try {
      const end = await follow(api.hardwareJob, id, (j) => this.showJob(j));
      const upload = end.kind === 'upload';
      if (end.state === 'done') this.ctx.notify(upload ? tr('Uploaded to {port}', { port: end.port }) : tr('Downloaded to {port}', { port: end.port }));
      else this.ctx.notify(upload ? tr('Upload failed: {m}', { m: end.message }) : tr('Download failed: {m}', { m: end.message }), 'error');
    } catch (e) {
      this.fail(e);
    } finally {
      this.following = '';
    }
  }

  /** A new job asked for: the last one's result is not shown as this one's. */
  private starting(): void {
    this.jobLine.dataset.state = 'starting';
    this.bar.value = 0;
    clear(this.jobLine);
    this.jobLine.append(tr('Starting…'));
  }

  private notStarted(e: unknown): void {
    this.jobLine.dataset.state = 'refused';
    clear(this.jobLine);
    this.jobLine.append(h('span', { class: 'problem' }, e instanceof Error ? e.message : String(e)));
    this.fail(e);
  }

  private showJob(j: HardwareJob): void {
    this.shownJob = j.id;
    this.cancelBtn.hidden = j.state !== 'running';
    this.bar.hidden = false;
    this.bar.value = j.progress;
    this.jobLine.hidden = false;
    this.jobLine.dataset.state = j.state;
    const state = { running: tr('running'), done: tr('done'), failed: tr('failed') }[j.state];
    clear(this.jobLine);
    this.jobLine.append(h('strong', null, `${state} · ${j.progress} %`), ` — ${j.port}, ${when(j.started_ms)}: `, h('span', { 'data-testid': 'hw-job-message' }, j.message));
  }
}
