// The textual form of IEC 61131-3 SFC that the server reads (docs/nets.md
// "SFC"; crates/net/src/sfc.rs), parsed for the chart view, pure: steps with
// their action associations, transitions from steps to steps with their
// condition, and where each is in the text (to put the server's problems on
// the element they concern). The server's parser decides what is valid;
// this one is lenient and reads what it can.

export interface Action {
  name: string;
  qualifier: string;
  time: string | null;
  /** Offsets of the association `Name(Q[, t]);` in the text. */
  start?: number;
  end?: number;
}

export interface Step {
  name: string;
  initial: boolean;
  actions: Action[];
  /** 1-based lines of the text it spans. */
  line: number;
  endLine: number;
  /** Offset of its `END_STEP` (new actions go before it). */
  endStep: number;
  /** Offsets of the whole `STEP … END_STEP`. */
  span: [number, number];
}

export interface SfcTransition {
  /** Its name, or `t<k>` (k from 1, in document order) when it has none. */
  name: string;
  named: boolean;
  priority: number | null;
  from: string[];
  to: string[];
  condition: string;
  /** Offsets of the condition between `:=` and `;` / `END_TRANSITION`. */
  cond: [number, number];
  /** Offsets of the whole `TRANSITION … END_TRANSITION`, and of its `FROM` and `TO` lists. */
  span: [number, number];
  fromSpan: [number, number];
  toSpan: [number, number];
  line: number;
  endLine: number;
}

export interface Chart {
  steps: Step[];
  transitions: SfcTransition[];
}

/** Blanks comments (`(* … *)` and `// …`) keeping every offset and line end. */
function uncomment(text: string): string {
  return text.replace(/\(\*[\s\S]*?\*\)|\/\/[^\n]*/g, (c) => c.replace(/[^\n]/g, ' '));
}

const lineAt = (text: string, offset: number) => text.slice(0, offset).split('\n').length;

export function parseSfc(text: string): Chart {
  const src = uncomment(text);
  const steps: Step[] = [];
  const transitions: SfcTransition[] = [];
  const stepRe = /\b(INITIAL_STEP|STEP)\s+([A-Za-z_]\w*)\s*:([\s\S]*?)\bEND_STEP\b/dgi;
  for (const m of src.matchAll(stepRe)) {
    const actions: Action[] = [];
    const body = m.indices![3]![0];
    for (const a of m[3].matchAll(/([A-Za-z_][\w.]*)\s*\(\s*([A-Za-z][A-Za-z0-9]*)\s*(?:,\s*([^)]*?))?\s*\)\s*;?/g))
      actions.push({ name: a[1], qualifier: a[2].toUpperCase(), time: a[3]?.trim() || null, start: body + a.index!, end: body + a.index! + a[0].length });
    const end = m.index! + m[0].length;
    steps.push({ name: m[2], initial: m[1].toUpperCase() === 'INITIAL_STEP', actions, line: lineAt(src, m.index!), endLine: lineAt(src, end), endStep: end - 'END_STEP'.length, span: [m.index!, end] });
  }
  const list = (s: string) => s.replace(/[()]/g, '').split(',').map((x) => x.trim()).filter(Boolean);
  const trRe = /\bTRANSITION\b\s*(?:([A-Za-z_]\w*)\s*)?(?:\(\s*PRIORITY\s*:=\s*(-?\d+)\s*\)\s*)?FROM\s+(\([^)]*\)|[A-Za-z_]\w*)\s*TO\s+(\([^)]*\)|[A-Za-z_]\w*)\s*:=?([\s\S]*?);?\s*\bEND_TRANSITION\b/dgi;
  let k = 0;
  for (const m of src.matchAll(trRe)) {
    k++;
    // the condition as written (comments kept out)
    transitions.push({
      name: m[1] ?? `t${k}`, named: !!m[1], priority: m[2] === undefined ? null : Number(m[2]),
      from: list(m[3]), to: list(m[4]), condition: m[5].replace(/\s+/g, ' ').trim(), cond: m.indices![5] as [number, number],
      span: [m.index!, m.index! + m[0].length], fromSpan: m.indices![3] as [number, number], toSpan: m.indices![4] as [number, number],
      line: lineAt(src, m.index!), endLine: lineAt(src, m.index! + m[0].length),
    });
  }
  return { steps, transitions };
}

/** The element (step or transition name) whose text holds `line`. */
export function elementAtLine(chart: Chart, line: number): string | null {
  for (const s of chart.steps) if (s.line <= line && line <= s.endLine) return `step:${s.name}`;
  for (const t of chart.transitions) if (t.line <= line && line <= t.endLine) return `tr:${t.name}`;
  return null;
}

/**
 * Where each step and transition goes, pure: steps in columns by their
 * distance from the initial step (down the page, as IEC charts read),
 * transitions between their steps; a transition back to an earlier step is
 * drawn as a jump.
 */
export function layoutSfc(chart: Chart): { at: Map<string, { x: number; y: number }>; jumps: Set<string> } {
  const byName = new Map(chart.steps.map((s) => [s.name.toUpperCase(), s]));
  const level = new Map<string, number>();
  const col = new Map<string, number>();
  const start = chart.steps.find((s) => s.initial) ?? chart.steps[0];
  const queue: string[] = [];
  if (start) {
    level.set(start.name, 0);
    col.set(start.name, 0);
    queue.push(start.name);
  }
  const jumps = new Set<string>();
  const place = new Map<string, { x: number; y: number }>();
  const used = new Map<number, number>();
  /** The columns of the transitions placed below each level. */
  const bars = new Map<number, Set<number>>();
  /** The first column from `c` with no transition below level `l`, taken. */
  const bar = (l: number, c: number) => {
    const taken = bars.get(l) ?? new Set<number>();
    while (taken.has(c)) c++;
    bars.set(l, taken.add(c));
    return c;
  };
  for (let k = 0; k < queue.length || level.size < chart.steps.length; k++) {
    if (k >= queue.length) {
      const s = chart.steps.find((x) => !level.has(x.name))!;
      level.set(s.name, 0);
      col.set(s.name, (used.get(0) ?? 0) + 1);
      queue.push(s.name);
    }
    const name = queue[k];
    const l = level.get(name)!;
    used.set(l, Math.max(used.get(l) ?? 0, col.get(name)!));
    const outs = chart.transitions.filter((t) => t.from.some((f) => f.toUpperCase() === name.toUpperCase()));
    for (const t of outs) {
      if (place.has(`tr:${t.name}`)) continue;
      const targets = t.to.map((x) => byName.get(x.toUpperCase())).filter((x): x is Step => !!x);
      const fresh = targets.filter((s) => !level.has(s.name));
      if (!fresh.length) {
        // a jump: under its step, or right of the step's other ways out
        jumps.add(t.name);
        place.set(`tr:${t.name}`, { x: bar(l, col.get(name)!), y: l + 0.5 });
        continue;
      }
      // a selective divergence (several transitions out of a step) spreads to the right
      const c0 = bar(l, outs.indexOf(t) === 0 ? col.get(name)! : Math.max(col.get(name)!, (used.get(l + 1) ?? -1) + 1));
      place.set(`tr:${t.name}`, { x: c0, y: l + 0.5 });
      fresh.forEach((s, i) => {
        level.set(s.name, l + 1);
        col.set(s.name, c0 + i);
        used.set(l + 1, Math.max(used.get(l + 1) ?? 0, c0 + i));
        queue.push(s.name);
      });
    }
  }
  for (const s of chart.steps) place.set(`step:${s.name}`, { x: col.get(s.name) ?? 0, y: level.get(s.name) ?? 0 });
  for (const t of chart.transitions) if (!place.has(`tr:${t.name}`)) {
    // a transition whose steps are not reached from the initial one: under its first source
    const f = place.get(`step:${t.from[0]}`) ?? { x: 0, y: 0 };
    place.set(`tr:${t.name}`, { x: f.x, y: f.y + 0.5 });
  }
  const at = new Map<string, { x: number; y: number }>();
  for (const [k, p] of place) at.set(k, { x: 80 + p.x * 260, y: 50 + p.y * 120 });
  return { at, jumps };
}

// ---- edits of the text (the chart's graphical edits), pure ----------------

/** A step name `S<n>` not used in the chart. */
export function freshStep(chart: Chart): string {
  const used = new Set(chart.steps.map((s) => s.name.toUpperCase()));
  let n = 1;
  while (used.has(`S${n}`)) n++;
  return `S${n}`;
}

/** Sets a transition's condition (the text between `:=` and `;`). */
export function setCondition(text: string, t: SfcTransition, condition: string): string {
  return `${text.slice(0, t.cond[0])} ${condition.trim()}${text.slice(t.cond[1])}`;
}

/** Adds an action association to a step, on a line of its own before END_STEP. */
export function addAction(text: string, step: Step, a: { name: string; qualifier: string; time: string | null }): string {
  const assoc = `${a.name}(${a.qualifier}${a.time ? `, ${a.time}` : ''});`;
  const before = text.slice(0, step.endStep);
  const sep = /\n\s*$/.test(before) ? '' : '\n';
  return `${before.replace(/[ \t]*$/, '')}${sep}    ${assoc}\n${text.slice(step.endStep)}`;
}

/** Replaces (or with null removes) a step's k-th action association. */
export function setAction(text: string, step: Step, k: number, a: { name: string; qualifier: string; time: string | null } | null): string {
  const x = step.actions[k];
  if (x?.start === undefined || x.end === undefined) return text;
  const assoc = a ? `${a.name}(${a.qualifier}${a.time ? `, ${a.time}` : ''});` : '';
  return `${text.slice(0, x.start)}${assoc}${text.slice(x.end)}`;
}

/** `text` with `lines` appended, each on a line of its own. */
function append(text: string, ...lines: string[]): string {
  const tail = text.endsWith('\n') || text === '' ? '' : '\n';
  return `${text}${tail}${lines.map((l) => `${l}\n`).join('')}`;
}

/** `text` with each [start, end) replaced, the edits not overlapping (applied from the end). */
function splice(text: string, edits: [number, number, string][]): string {
  return [...edits].sort((a, b) => b[0] - a[0]).reduce((t, [from, to, by]) => `${t.slice(0, from)}${by}${t.slice(to)}`, text);
}

/** A `FROM`/`TO` list as written: one name, or several in parentheses. */
const ends = (names: string[]) => (names.length === 1 ? names[0] : `(${names.join(', ')})`);

const transition = (from: string[], to: string[]) => `TRANSITION FROM ${ends(from)} TO ${ends(to)} := FALSE; END_TRANSITION`;

/** A new step after `from`: the step and a transition to it (condition FALSE until set), at the end of the text. */
export function addStepAfter(text: string, chart: Chart, from: string): { text: string; step: string } {
  const step = freshStep(chart);
  return { text: append(text, `STEP ${step}: END_STEP`, transition([from], [step])), step };
}

/** A simultaneous divergence: a new step added to what transition `t` activates. */
export function addParallel(text: string, chart: Chart, t: SfcTransition): { text: string; step: string } {
  const step = freshStep(chart);
  return { text: append(splice(text, [[...t.toSpan, ends([...t.to, step])]]), `STEP ${step}: END_STEP`), step };
}

/**
 * A new transition from step `from` to step `to` (condition FALSE until set): a jump when
 * `to` comes earlier, a selective divergence when `from` already has a way out, a selective
 * convergence when `to` already has a way in.
 */
export function addLink(text: string, from: string, to: string): string {
  return append(text, transition([from], [to]));
}

/** A simultaneous convergence: step `step` added to what transition `t` waits for. */
export function addJoin(text: string, t: SfcTransition, step: string): string {
  if (t.from.some((f) => f.toUpperCase() === step.toUpperCase())) return text;
  return splice(text, [[...t.fromSpan, ends([...t.from, step])]]);
}

/** [start, end) widened to whole lines when nothing else is on them. */
function wholeLines(text: string, [from, to]: [number, number]): [number, number] {
  const lineStart = text.lastIndexOf('\n', from - 1) + 1;
  let lineEnd = text.indexOf('\n', to);
  if (lineEnd < 0) lineEnd = text.length;
  if (text.slice(lineStart, from).trim() || text.slice(to, lineEnd).trim()) return [from, to];
  return [lineStart, Math.min(text.length, lineEnd + 1)];
}

/**
 * Deletes a step (`step:<name>`) or transition (`tr:<name>`). A deleted step leaves the
 * `FROM`/`TO` lists it was in; a transition left with no step on one side goes too.
 */
export function removeElement(text: string, chart: Chart, id: string): string {
  const t = chart.transitions.find((x) => `tr:${x.name}` === id);
  if (t) return splice(text, [[...wholeLines(text, t.span), '']]);
  const st = chart.steps.find((x) => `step:${x.name}` === id);
  if (!st) return text;
  const other = (n: string) => n.toUpperCase() !== st.name.toUpperCase();
  const edits: [number, number, string][] = [[...wholeLines(text, st.span), '']];
  for (const x of chart.transitions) {
    const from = x.from.filter(other);
    const to = x.to.filter(other);
    if (!from.length || !to.length) edits.push([...wholeLines(text, x.span), '']);
    else {
      if (from.length !== x.from.length) edits.push([...x.fromSpan, ends(from)]);
      if (to.length !== x.to.length) edits.push([...x.toSpan, ends(to)]);
    }
  }
  return splice(text, edits);
}
