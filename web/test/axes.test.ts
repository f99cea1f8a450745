import { describe, expect, it } from 'vitest';
import { axesInUse, clampToNow, fixedRange, fromLane, laneRange, lanesOf, scaleOf, toLane, type PenSpec } from '../src/trends/axes';

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
