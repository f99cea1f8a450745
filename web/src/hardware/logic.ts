// The Hardware tab's logic (issue 33), apart from the page so that Vitest
// checks it: sizes against the board's limits, the pin table's edits and
// problems, the job a reloaded page shows again. The domain (boards, pins,
// capabilities, presets, problems and their codes) comes from the server
// (GET /api/hardware), never re-typed here.
import type { BoardModel, Diagnostic, HardwareJob, HardwareView, PinRow } from '../api.gen';

export const DIRS = ['di', 'do', 'ai', 'ao'] as const;
export type Dir = (typeof DIRS)[number];

/** `used` of `max` in whole percent (at least 1 when anything is used, at most 100 for the bar). */
export function percent(used: number, max: number): number {
  if (max <= 0) return 0;
  const p = Math.round((100 * used) / max);
  return used > 0 ? Math.max(1, p) : 0;
}

/** The board called `name`, if the server knows it. */
export function boardOf(view: HardwareView, name: string | null): BoardModel | undefined {
  return view.boards.find((b) => b.name === name);
}

/** What a pin can do on a board (`di do ao`; `serial` for D0/D1), from the server's table. */
export function capsOf(board: BoardModel | undefined, pin: string | null): string[] {
  if (!board || !pin) return [];
  return board.pins.find((p) => p.pin === pin.trim().toUpperCase())?.caps ?? [];
}

/** The pins of each direction as the table lists them (channel order), with the edits of `edits` (address → pin). */
export function mapOf(rows: PinRow[], edits: Map<string, string>): Record<Dir, string[]> {
  const out: Record<Dir, string[]> = { di: [], do: [], ai: [], ao: [] };
  for (const d of DIRS) {
    const list = rows.filter((r) => r.dir === d && r.pin !== null).sort((a, b) => a.channel - b.channel);
    out[d] = list.map((r) => (edits.get(r.address) ?? r.pin ?? '').trim().toUpperCase());
  }
  return out;
}

/** Whether the edits change anything. */
export function changed(rows: PinRow[], edits: Map<string, string>): boolean {
  return rows.some((r) => r.pin !== null && edits.has(r.address) && edits.get(r.address)!.trim().toUpperCase() !== r.pin);
}

/**
 * The problems of a refused save (422: alba.toml's diagnostics, as `alba
 * check` gives them) placed on the table's rows: a diagnostic belongs to
 * every row whose pin it names (`pin D2 is wired twice`); the others are
 * the table's as a whole (`null`).
 */
export function placeProblems(rows: PinRow[], edits: Map<string, string>, diags: Diagnostic[]): Map<string | null, Diagnostic[]> {
  const out = new Map<string | null, Diagnostic[]>();
  const put = (k: string | null, d: Diagnostic) => out.set(k, [...(out.get(k) ?? []), d]);
  for (const d of diags) {
    const named = new Set([...d.message.matchAll(/\b([DA]\d{1,2})\b/g)].map((m) => m[1]));
    const hit = rows.filter((r) => {
      const pin = (edits.get(r.address) ?? r.pin ?? '').trim().toUpperCase();
      return pin !== '' && named.has(pin);
    });
    if (hit.length === 0) put(null, d);
    for (const r of hit) put(r.address, d);
  }
  return out;
}

const JOB_KEY = 'alba.hardware.job';

/** Remembers the job the page started, for a reload. */
export function rememberJob(id: string, store: Pick<Storage, 'setItem'> = localStorage): void {
  try {
    store.setItem(JOB_KEY, id);
  } catch {
    /* private mode: the server's list still has it */
  }
}

/** The job to show on a (re)loaded page: the one this browser started if the server still has it, else the newest. */
export function jobToShow(jobs: HardwareJob[], store: Pick<Storage, 'getItem'> = localStorage): HardwareJob | null {
  let mine: string | null = null;
  try {
    mine = store.getItem(JOB_KEY);
  } catch {
    mine = null;
  }
  return jobs.find((j) => j.id === mine) ?? jobs[0] ?? null;
}

/** Polls a job until it ends, calling `seen` with each state; resolves with the last. */
export async function follow(
  get: (id: string) => Promise<HardwareJob>,
  id: string,
  seen: (j: HardwareJob) => void,
  wait: (ms: number) => Promise<void> = (ms) => new Promise((r) => setTimeout(r, ms)),
): Promise<HardwareJob> {
  for (;;) {
    const j = await get(id);
    seen(j);
    if (j.state !== 'running') return j;
    await wait(200);
  }
}
