// The Hardware tab's logic (src/hardware/logic.ts): sizes against limits,
// the pin table's edits and where a refused save's problems go, the job a
// reloaded page shows.
import { describe, expect, it } from 'vitest';
import type { Diagnostic, HardwareJob, HardwareView, PinRow } from '../src/api.gen';
import { boardOf, capsOf, changed, follow, jobToShow, mapOf, percent, placeProblems, rememberJob } from '../src/hardware/logic';

const row = (dir: string, channel: number, pin: string | null, tags: string[] = []): PinRow => ({
  dir,
  channel,
  address: `${{ di: 'DI:1', do: 'DO:2', ai: 'AI:3', ao: 'AO:4' }[dir]}/${channel}`,
  pin,
  tags,
  problem: null,
});

const rows: PinRow[] = [row('di', 0, 'D2', ['Start']), row('di', 1, 'D3', ['Stop']), row('do', 0, 'D12', ['Motor']), row('do', 1, 'D13'), row('ai', 0, 'A4')];

const diag = (message: string): Diagnostic => ({
  code: 'E102',
  severity: 'error',
  message,
  file: 'alba.toml',
  line: 9,
  col: 1,
  end_line: 9,
  end_col: 5,
  help: null,
});

const job = (id: string, state: HardwareJob['state'], progress = 0): HardwareJob => ({
  id,
  kind: 'download',
  port: '/dev/ttyUSB0',
  state,
  progress,
  message: '',
  started_ms: 0,
});

describe('the Hardware tab', () => {
  it('gives sizes as whole percents of the board, never 0 % for something used', () => {
    expect(percent(2474, 32256)).toBe(8);
    expect(percent(1, 32256)).toBe(1);
    expect(percent(0, 2048)).toBe(0);
    expect(percent(2048, 2048)).toBe(100);
    expect(percent(5, 0)).toBe(0);
  });

  it('reads capabilities from the server\'s board table', () => {
    const view = { boards: [{ name: 'nano', title: 'Arduino Nano', flash_max: 32256, ram_max: 2048, pins: [{ pin: 'A7', caps: ['ai'] }, { pin: 'D1', caps: ['serial'] }] }] } as unknown as HardwareView;
    const nano = boardOf(view, 'nano');
    expect(capsOf(nano, ' a7 ')).toEqual(['ai']);
    expect(capsOf(nano, 'D1')).toEqual(['serial']);
    expect(capsOf(nano, 'D99')).toEqual([]);
    expect(boardOf(view, 'due')).toBeUndefined();
  });

  it('turns the table and its edits into the map to save', () => {
    const edits = new Map([['DO:2/1', ' a0 ']]);
    expect(mapOf(rows, edits)).toEqual({ di: ['D2', 'D3'], do: ['D12', 'A0'], ai: ['A4'], ao: [] });
    expect(changed(rows, edits)).toBe(true);
    expect(changed(rows, new Map([['DO:2/1', 'd13']]))).toBe(false);
    // a channel the map does not wire (pin null) is not saved
    expect(mapOf([...rows, row('di', 7, null, ['Extra'])], new Map()).di).toEqual(['D2', 'D3']);
  });

  it('puts a refused save\'s problems on the rows whose pins they name', () => {
    const edits = new Map([['DO:2/1', 'D2']]);
    const placed = placeProblems(rows, edits, [diag('pin D2 is wired twice'), diag('unknown pin map `x`')]);
    expect([...placed.keys()].sort()).toEqual(['DI:1/0', 'DO:2/1', null].sort());
    expect(placed.get('DO:2/1')?.[0].message).toBe('pin D2 is wired twice');
    expect(placed.get(null)?.[0].message).toBe('unknown pin map `x`');
  });

  it('shows again after a reload the job this browser started, else the newest', () => {
    const store = new Map<string, string>();
    const s = { getItem: (k: string) => store.get(k) ?? null, setItem: (k: string, v: string) => void store.set(k, v) };
    const jobs = [job('3', 'done', 100), job('2', 'failed', 40)];
    expect(jobToShow(jobs, s)?.id).toBe('3');
    rememberJob('2', s);
    expect(jobToShow(jobs, s)?.id).toBe('2');
    expect(jobToShow([], s)).toBeNull();
  });

  it('follows a job until it ends', async () => {
    const states = [job('1', 'running', 0), job('1', 'running', 50), job('1', 'done', 100)];
    const seen: number[] = [];
    const end = await follow(async () => states.shift()!, '1', (j) => seen.push(j.progress), async () => undefined);
    expect(end.state).toBe('done');
    expect(seen).toEqual([0, 50, 100]);
  });
});
