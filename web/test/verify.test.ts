// The Verify & Test page's logic (issue 37): the replay under the slider and the coverage marks.
import { describe, expect, it } from 'vitest';
import type { ProgramCoverage, Replay } from '../src/api.gen';
import { changeScans, clampScan, coverageMarks, percentOf, powerAt, rowsAt, startScan, stepChange, valueOf, valuesAt } from '../src/verify/logic';

// The lamp of examples/start-stop lit 30 ms after Start (3 scans of 10 ms), as the server replays it.
const replay: Replay = {
  rows: [
    { time_ms: 0, tag: 'Start', value: '1' },
    { time_ms: 10, tag: 'Start', value: '0' },
  ],
  violating_scan: 3,
  first_scan: 0,
  tags: ['Start', 'Motor', 'Lamp'],
  scans: [
    { time_ms: 0, values: ['1', '1', '0'], on: [0, 1, 2] },
    { time_ms: 10, values: ['0', '1', '0'], on: [1, 2] },
    { time_ms: 20, values: ['0', '1', '0'], on: [1, 2] },
    { time_ms: 30, values: ['0', '1', '1'], on: [1, 2, 3, 4] },
  ],
};

describe('the counterexample replay', () => {
  it('opens on the violating scan and clamps the slider', () => {
    expect(startScan(replay)).toBe(3);
    expect(clampScan(replay, -4)).toBe(0);
    expect(clampScan(replay, 99)).toBe(3);
    expect(clampScan(replay, Number.NaN)).toBe(0);
    expect(startScan({ ...replay, violating_scan: 40 })).toBe(3);
  });

  it('shows each scan’s values, marking what changed', () => {
    expect(valuesAt(replay, 0).map((v) => v.changed)).toEqual([false, false, false]);
    expect(valuesAt(replay, 1)).toEqual([
      { tag: 'Start', value: '0', changed: true },
      { tag: 'Motor', value: '1', changed: false },
      { tag: 'Lamp', value: '0', changed: false },
    ]);
    expect(valuesAt(replay, 3).find((v) => v.tag === 'Lamp')).toEqual({ tag: 'Lamp', value: '1', changed: true });
  });

  it('gives the stimulus rows applied at a scan and its power flow', () => {
    expect(rowsAt(replay, 0)).toEqual([replay.rows[0]]);
    expect(rowsAt(replay, 1)).toEqual([replay.rows[1]]);
    expect(rowsAt(replay, 2)).toEqual([]);
    expect([...powerAt(replay, 3)]).toEqual([1, 2, 3, 4]);
  });

  it('gives a scan’s values by tag name, as the net and SFC views read them', () => {
    const v = valueOf(replay, 3);
    expect(v('Lamp')).toBe(1);
    expect(v('lamp')).toBe(1);
    expect(valueOf(replay, 1)('Start')).toBe(0);
    expect(v('batch.idle')).toBeUndefined();
    const text = valueOf({ ...replay, tags: ['Name'], scans: [{ time_ms: 0, values: ['abc'], on: [] }] }, 0);
    expect(text('Name')).toBe('abc');
  });

  it('steps from change to change', () => {
    const c = changeScans(replay);
    expect(c).toEqual([0, 1, 3]);
    expect(stepChange(c, 1, 1)).toBe(3);
    expect(stepChange(c, 3, 1)).toBe(3);
    expect(stepChange(c, 3, -1)).toBe(1);
    expect(stepChange(c, 0, -1)).toBe(0);
  });
});

describe('the coverage overlay', () => {
  it('marks the elements never powered and those always powered', () => {
    const c: ProgramCoverage = { program: 'main.lad', elements: [0, 1, 2, 3, 4], powered: [0, 1, 2], always: [1] };
    const m = coverageMarks(c);
    expect([...m.never]).toEqual([3, 4]);
    expect([...m.always]).toEqual([1]);
    expect(percentOf(3, 5)).toBe(60);
    expect(percentOf(0, 0)).toBe(0);
  });
});
