import { afterEach, describe, expect, it } from 'vitest';
import { useBrowserLanguage, useLanguage } from '../src/i18n';
import { LANE_SHARE, aboveLanes, axesInUse, clampToNow, fixedRange, fromLane, laneRange, lanesOf, lanesTop, scaleOf, timeLabels, timeSpace, toLane, type PenSpec } from '../src/trends/axes';

const pen = (tag: string, axis: number, digital = false, min: number | null = null, max: number | null = null): PenSpec => ({ tag, axis, digital, min, max });

describe('trend axes and lanes', () => {
  it('puts analog pens on their axis and BOOLs on lanes of their own', () => {
    const pens = [pen('Level', 1), pen('Pump', 1, true), pen('Speed', 2), pen('Valve', 3, true)];
    expect(pens.map(scaleOf)).toEqual(['y1', 'lanes', 'y2', 'lanes']);
    expect(lanesOf(pens)).toEqual([-1, 0, -1, 1]);
    expect(axesInUse(pens)).toEqual(['y1', 'y2']);
    expect(scaleOf(pen('x', 9))).toBe('y4');
  });
  it('draws 0/1 as steps inside the lane and reads them back', () => {
    const drawn = [toLane(0, 0), toLane(0, 1), toLane(2, 1)] as number[];
    [0.15, 0.85, 2.85].forEach((want, k) => expect(drawn[k]).toBeCloseTo(want));
    expect(toLane(1, null)).toBeNull();
    expect([fromLane(0.15), fromLane(0.85), fromLane(2.85), fromLane(null)]).toEqual([0, 1, 1, null]);
    // Lanes alone fill the plot; beside analog pens, the bottom third or so.
    expect(laneRange(2, false)).toEqual([0, 2]);
    expect(laneRange(2, true)[1]).toBeCloseTo(2 / 0.35);
  });
  it('fixes an axis when a pen on it says so, else scales it automatically', () => {
    const pens = [pen('A', 1), pen('B', 1, false, 0, 60), pen('C', 2, false, 5, 1)];
    expect(fixedRange(pens, 'y1')).toEqual([0, 60]);
    expect(fixedRange(pens, 'y2')).toBeNull();
  });
  it('keeps a zoomed-out range out of the future', () => {
    expect(clampToNow(0, 200, 150)).toEqual([-50, 150]);
    expect(clampToNow(0, 100, 150)).toEqual([0, 100]);
  });
});

describe('trend axes beside lanes, and time labels (issue 30, items 12 and 16)', () => {
  afterEach(() => {
    useLanguage('en');
    useBrowserLanguage('en-US');
  });

  it('keeps the analog pens above the lanes: their range reaches down over the lanes, unlabelled', () => {
    // a level of 10 to 60 L beside a BOOL: 10 L is where the lanes end, not inside them
    const [lo, hi] = aboveLanes(10, 60, true);
    expect(hi).toBe(60);
    expect(lanesTop(lo, hi)).toBeCloseTo(10);
    expect((10 - lo) / (hi - lo)).toBeCloseTo(LANE_SHARE);
    expect(aboveLanes(10, 60, false)).toEqual([10, 60]);
  });

  it('labels time ticks in the language, the date below the first and where the day changes', () => {
    useBrowserLanguage('en-GB');
    const t = (d: number, h: number, m: number, s = 0) => new Date(2026, 5, d, h, m, s).getTime();
    expect(timeLabels([t(12, 16, 54), t(12, 16, 55), t(12, 16, 56)], 60e3)).toEqual(['16:54\n12/06/2026', '16:55', '16:56']);
    expect(timeLabels([t(12, 16, 54, 10), t(12, 16, 54, 20)], 10e3)).toEqual(['16:54:10\n12/06/2026', '16:54:20']);
    expect(timeLabels([t(12, 23, 0), t(13, 0, 0), t(13, 1, 0)], 3600e3)).toEqual(['23:00\n12/06/2026', '00:00\n13/06/2026', '01:00']);
    expect(timeLabels([t(12, 0, 0), t(13, 0, 0)], 86400e3)).toEqual(['12/06/2026', '13/06/2026']);
    useLanguage('es');
    expect(timeLabels([t(12, 16, 54)], 60e3)).toEqual(['16:54\n12/06/2026']);
    useLanguage('en');
    useBrowserLanguage('en-US');
    expect(timeLabels([t(12, 16, 54)], 60e3)).toEqual(['4:54 PM\n06/12/2026']);
  });

  it('spaces time ticks wider than their widest label', () => {
    useBrowserLanguage('en-US');
    // "10:58:58 PM" is 11 characters: at 7 px each, ticks at least 77 px apart and a gap
    expect(timeSpace()).toBeGreaterThan(11 * 7);
    useBrowserLanguage('en-GB');
    expect(timeSpace()).toBeGreaterThan(10 * 7); // 28/12/2000
  });
});
