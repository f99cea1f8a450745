import { describe, expect, it } from 'vitest';
import type { Element } from '../src/hmi/render';
import { MAX_POINTS, dedupe, fromPoints, insertVertex, nearestEdge, pointsOf, removeVertex, setPoints, type Pt } from '../src/hmi/vertices';
import { commonParams, commonValues, setAll } from '../src/hmi/multi';
import type { ParamInfo } from '../src/api.gen';

const el = (type: string, props: Record<string, unknown> = {}, rotation = 0): Element =>
  ({ id: 'p1', type, x: 100, y: 50, w: 40, h: 20, rotation, props, animations: [] }) as Element;

describe('vertices of a polygon or a line', () => {
  it('reads props.points, or the shape drawn without them', () => {
    expect(pointsOf(el('polygon', { points: [[0, 0], [10, 0], [5, 8]] }))).toEqual([[0, 0], [10, 0], [5, 8]]);
    expect(pointsOf(el('polygon'))).toEqual([[20, 0], [40, 20], [0, 20]]);
    expect(pointsOf(el('line'))).toEqual([[0, 10], [40, 10]]);
    expect(pointsOf(el('line', { points: [[0, 0], 'x'] }))).toEqual([[0, 10], [40, 10]]);
  });

  it('inserts after an edge, within 200', () => {
    const pts: Pt[] = [[0, 0], [10, 0], [10, 10]];
    expect(insertVertex(pts, 1, [12, 5])).toEqual([[0, 0], [10, 0], [12, 5], [10, 10]]);
    expect(insertVertex(pts, 2, [5, 5])).toEqual([[0, 0], [10, 0], [10, 10], [5, 5]]);
    const full = Array.from({ length: MAX_POINTS }, (_, k): Pt => [k, 0]);
    expect(insertVertex(full, 0, [0, 1])).toBeNull();
  });

  it('removes down to 3 for a polygon and 2 for a line', () => {
    const tri: Pt[] = [[0, 0], [10, 0], [10, 10]];
    expect(removeVertex(tri, 0, 'polygon')).toBeNull();
    expect(removeVertex(tri, 0, 'line')).toEqual([[10, 0], [10, 10]]);
    expect(removeVertex([[0, 0], [1, 1]], 1, 'line')).toBeNull();
  });

  it('finds the nearest edge, the closing one of a polygon too', () => {
    const sq: Pt[] = [[0, 0], [10, 0], [10, 10], [0, 10]];
    expect(nearestEdge(sq, [5, -1], true)).toBe(0);
    expect(nearestEdge(sq, [11, 5], true)).toBe(1);
    expect(nearestEdge(sq, [-1, 5], true)).toBe(3);
    expect(nearestEdge(sq, [-1, 5], false)).toBe(0);
  });

  it('fits the box to the points, so a vertex dragged outside grows it', () => {
    const e = el('polygon', { points: [[0, 0], [40, 0], [20, 20]], fill: 'red' });
    setPoints(e, [[-10, 0], [40, 0], [20, 30]]);
    expect([e.x, e.y, e.w, e.h]).toEqual([90, 50, 50, 30]);
    expect(e.props).toEqual({ points: [[0, 0], [50, 0], [30, 30]], fill: 'red' });
  });

  it('keeps a turned element\'s box and holds its vertices inside', () => {
    const e = el('polygon', {}, 45);
    setPoints(e, [[-10, 0], [40, 0], [20, 30]]);
    expect([e.x, e.y, e.w, e.h]).toEqual([100, 50, 40, 20]);
    expect(e.props?.points).toEqual([[0, 0], [40, 0], [20, 20]]);
  });

  it('makes an element of drawn points, a double-click\'s repeats dropped', () => {
    expect(dedupe([[0, 0], [10, 0], [10, 0], [0, 0]], true)).toEqual([[0, 0], [10, 0]]);
    const e = fromPoints('polygon2', 'polygon', [[100, 100], [200, 100], [150, 180], [150, 180]]);
    expect(e).toMatchObject({ id: 'polygon2', type: 'polygon', x: 100, y: 100, w: 100, h: 80, props: { points: [[0, 0], [100, 0], [50, 80]] } });
    expect(fromPoints('p', 'polygon', [[0, 0], [10, 10], [10, 10]])).toBeNull();
    expect(fromPoints('l', 'line', [[0, 0], [50, 0]])).toMatchObject({ w: 50, h: 1 });
  });
});

describe('several elements edited together', () => {
  const p = (name: string, kind: ParamInfo['kind'], help = ''): ParamInfo => ({ name, kind, min: null, max: null, unit: '', choices: [], help, legacy: false });
  it('offers the properties every type has with the same kind, no vertices', () => {
    const rect = [p('fill', 'color', 'a'), p('stroke', 'color'), p('radius', 'number')];
    const poly = [p('points', 'points'), p('fill', 'color', 'b'), p('stroke', 'text')];
    expect(commonParams([rect, poly]).map((x) => x.name)).toEqual(['fill']);
    expect(commonParams([poly]).map((x) => x.name)).toEqual(['fill', 'stroke']);
    expect(commonParams([])).toEqual([]);
  });

  it('shows the values they agree on, and sets one on all', () => {
    const els = [el('rectangle', { fill: 'red', stroke: 'blue' }), el('rectangle', { fill: 'red' }), el('rectangle', { fill: 'red', stroke: 'blue' })];
    const params = [p('fill', 'color'), p('stroke', 'color'), p('radius', 'number')];
    expect(commonValues(els, params)).toEqual({ fill: 'red' });
    setAll(els, 'stroke', '#00ff00');
    expect(els.map((e) => e.props?.stroke)).toEqual(['#00ff00', '#00ff00', '#00ff00']);
    setAll(els, 'fill', undefined);
    expect(els.every((e) => !('fill' in (e.props ?? {})))).toBe(true);
  });
});

describe('rulers and guides', () => {
  it('ticks every 10, longer every 50, labelled every 100', async () => {
    const { ticks } = await import('../src/hmi/guides');
    const t = ticks(120);
    expect(t.map((x) => x.at)).toEqual([0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120]);
    expect(t.filter((x) => x.size === 'big').map((x) => x.at)).toEqual([0, 100]);
    expect(t.filter((x) => x.size === 'mid').map((x) => x.at)).toEqual([50]);
  });

  it('snaps the nearest edge or centre onto a guide within the tolerance', async () => {
    const { snapToGuides, snapAxis } = await import('../src/hmi/guides');
    expect(snapAxis(100, 160, [163], 6)).toBe(3);
    expect(snapAxis(100, 160, [127], 6)).toBe(-3);
    expect(snapAxis(100, 160, [97, 131], 6)).toBe(1); // the nearest: the centre 130 to 131
    expect(snapAxis(100, 160, [170], 6)).toBe(0);
    expect(snapToGuides({ x: 100, y: 440, w: 60, h: 60 }, { v: [], h: [503] }, 6)).toEqual([0, 3]);
    const { snapPoint } = await import('../src/hmi/guides');
    expect(snapPoint(200, 500, { v: [204], h: [520] }, 6)).toEqual([204, 500]);
  });

  it('keeps guides per screen in the browser', async () => {
    const { loadGuides, saveGuides } = await import('../src/hmi/guides');
    saveGuides('s1', { v: [100], h: [40, 503] });
    expect(loadGuides('s1')).toEqual({ v: [100], h: [40, 503] });
    expect(loadGuides('other')).toEqual({ v: [], h: [] });
    localStorage.setItem('alba.hmi.guides.bad', '{"v": ["x", 3]');
    expect(loadGuides('bad')).toEqual({ v: [], h: [] });
  });
});
