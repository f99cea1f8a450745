// The trend's CSV export (issue 30, item 17): the absolute time, no rows
// before the first sample, REAL values without float noise.
import { describe, expect, it } from 'vitest';
import { localStamp, shortestF32, trendCsv, utcOffset } from '../src/trends/csv';

describe('the trend CSV', () => {
  it('writes a REAL in the fewest digits that read back as the same f32', () => {
    const v = Math.fround(49.79472);
    expect(String(v)).toBe('49.79471969604492');
    expect(shortestF32(v)).toBe('49.79472');
    expect(Math.fround(Number(shortestF32(v)))).toBe(v);
    expect(shortestF32(Math.fround(0.1))).toBe('0.1');
    expect(shortestF32(3)).toBe('3');
    expect(shortestF32(-Math.fround(1e-7))).toBe('-1e-7');
    // not an f32: left as it is
    expect(shortestF32(0.1)).toBe('0.1');
    expect(shortestF32(1 / 3)).toBe(String(1 / 3));
    // every f32 of a sweep reads back
    for (let k = 0; k < 2000; k++) {
      const f = Math.fround((k - 1000) * 0.0137 + k * 1e-5);
      expect(Math.fround(Number(shortestF32(f)))).toBe(f);
    }
  });

  it('adds the local time, drops the rows before the first sample, rounds REAL noise only', () => {
    const from = new Date(2026, 5, 12, 16, 54, 0).getTime();
    const noisy = Math.fround(49.79472);
    const server = [
      'Time (ms),Nivel_L,Bomba1,"Count, total"',
      '0,,,',
      '250,,,',
      `500,${noisy},,`,
      `750,${noisy},1,3`,
      `1000,0.30000001192092896,0,4`,
      '',
    ].join('\n');
    const out = trendCsv(server, from, [true, false, false]).trim().split('\n');
    expect(out[0]).toBe(`Time (${utcOffset(from)}),Time (ms),Nivel_L,Bomba1,"Count, total"`);
    expect(out.slice(1)).toEqual([
      `${localStamp(from + 500)},0,49.79472,,`,
      `${localStamp(from + 750)},250,49.79472,1,3`,
      `${localStamp(from + 1000)},500,0.3,0,4`,
    ]);
    expect(localStamp(from + 750)).toBe('2026-06-12 16:54:00.750');
    expect(utcOffset(from)).toMatch(/^UTC[+-]\d\d:\d\d$/);
  });

  it('keeps the header alone when nothing was recorded in the range', () => {
    const from = new Date(2026, 5, 12, 16, 54, 0).getTime();
    expect(trendCsv('Time (ms),A\n0,\n250,\n', from, [true]).trim().split('\n')).toEqual([`Time (${utcOffset(from)}),Time (ms),A`]);
  });
});
