// The symbols of screen elements (issue 17, item 3): each of the 30 types
// draws as its golden SVG (test/__snapshots__/symbols/<type>.svg; `vitest -u`
// rewrites them after a deliberate change, to be looked at before commit),
// carries the parts animations reach, and each animation kind changes the
// drawing as its golden file shows.
import { afterAll, beforeAll, describe, expect, it, vi } from 'vitest';
import { domain } from '../src/domain';
import { type Animation, type Element, animate, drawElement } from '../src/hmi/render';
import type { Json } from '../src/types';

// the server's list (test/fixtures/domain.json, checked against GET /api/domain)
const TYPES = () => domain().screens.elements.map(([t]) => t);
const el = (type: string, props: Element['props'] = {}): Element => ({ id: 'x', type, x: 0, y: 0, w: 100, h: 100, props: { label: 'L', ...props } });
const golden = (name: string) => `./__snapshots__/symbols/${name}.svg`;

// the clock draws the time it is drawn at
beforeAll(() => {
  vi.useFakeTimers({ toFake: ['Date'] });
  vi.setSystemTime(new Date(2026, 0, 1, 10, 10, 30));
});
afterAll(() => vi.useRealTimers());

describe('element symbols', () => {
  it('knows the 30 types and the faceplate', () => {
    expect(TYPES().length).toBe(31);
  });

  for (const type of domain().screens.elements.map(([t]) => t)) {
    it(`draws ${type} as its golden SVG`, async () => {
      await expect(drawElement(el(type)).outerHTML).toMatchFileSnapshot(golden(type));
    });
  }

  it('draws the circular meter and the silo variants', async () => {
    await expect(drawElement(el('meter', { style: 'circular' })).outerHTML).toMatchFileSnapshot(golden('meter-circular'));
    await expect(drawElement(el('tank', { style: 'silo' })).outerHTML).toMatchFileSnapshot(golden('tank-silo'));
  });

  // Every choice of every element property the domain lists, and the other variants (issue 35, point 1).
  const variants: [string, Record<string, Json>][] = [
    ['polygon', { points: [[0, 0], [100, 20], [80, 100], [10, 70]], color: '#ff8800', stroke: '#333333', stroke_width: 3 }],
    ['line', { points: [[0, 0], [50, 80], [100, 20]], stroke: '#1565c0', stroke_width: 4 }],
    ['arc', { start: 0, end: 270 }],
    ['arc', { start: -45, end: 45, close: 'chord', color: '#ffe082' }],
    ['arc', { start: 90, end: 180, close: 'centre' }],
    ['rectangle', { color: '#b3e5fc', stroke: '#0277bd', stroke_width: 2 }],
    ['text', { text: 'Hello', size: 20, color: '#c62828' }],
    ['led', { color: '#ffd54f' }],
    ['pump', { color: '#81c784' }],
    ['image', { src: 'assets/logo.png', scale: 50 }],
    ['wind_turbine', { tower: false }],
    ['fan', { casing: false }],
  ];
  for (const table of domain().screens.properties) {
    for (const param of table.params.filter((p) => p.kind === 'choice')) {
      for (const choice of param.choices) variants.push([table.kind, { [param.name]: choice }]);
    }
  }
  for (const [type, props] of variants) {
    const name = `${type}-${Object.entries(props).map(([k, v]) => `${k}-${Array.isArray(v) ? v.length : v}`).join('-')}`.replace(/[^\w-]/g, '');
    it(`draws the variant ${name}`, async () => {
      const g = drawElement(el(type, props));
      expect(g.querySelector('[data-part]'), name).not.toBeNull();
      await expect(g.outerHTML).toMatchFileSnapshot(golden(`variant-${name}`));
    });
  }

  it('marks the parts animations reach, on every type', () => {
    for (const type of TYPES()) {
      const g = drawElement(el(type));
      expect(g.querySelector('[data-part]'), type).not.toBeNull();
    }
    for (const type of ['wind_turbine', 'fan', 'motor', 'pump']) {
      const g = drawElement(el(type));
      expect(g.querySelector('[data-part="rotor"]'), type).not.toBeNull();
      expect(g.querySelector('[data-part="fill"]'), type).not.toBeNull();
      // the rotor turns about its axis: its parent group is translated there
      expect(g.querySelector('[data-part="rotor"]')!.parentElement!.getAttribute('transform'), type).toMatch(/^translate\(/);
    }
    for (const type of ['tank', 'bottle', 'meter']) {
      const level = drawElement(el(type)).querySelector('[data-part="level"]')!;
      expect([level.getAttribute('x'), level.getAttribute('y'), level.getAttribute('width'), level.getAttribute('height')], type).toEqual(['2', '98', '96', '0']);
    }
    const valve = drawElement(el('valve'));
    expect(valve.querySelector('[data-part="fill"]')).not.toBeNull();
    expect(valve.querySelector('[data-part="fill2"]')).not.toBeNull();
    const gauge = drawElement(el('meter', { style: 'circular' }));
    expect(gauge.querySelector('[data-part="needle"]')).not.toBeNull();
    expect(gauge.querySelector('[data-part="text"]')).not.toBeNull();
    const clock = drawElement(el('clock'));
    expect(clock.querySelector('[data-part="hour"]')!.getAttribute('transform')).toBe('rotate(305)');
    expect(clock.querySelector('[data-part="minute"]')!.getAttribute('transform')).toBe('rotate(63)');
    expect(clock.querySelector('[data-part="text"]')!.textContent).toBe('10:10:30');
    expect(drawElement(el('trend')).querySelector('polyline[data-part="line"]')!.getAttribute('points')).toBe('');
  });
});

describe('animations on symbols', () => {
  const cases: [string, string, Animation, Json][] = [
    ['visibility', 'pump', { kind: 'visibility', tag: 'B' }, false],
    ['blink', 'pump', { kind: 'blink', tag: 'B' }, true],
    ['move', 'pump', { kind: 'move', tag: 'X', min: 0, max: 10, dx: 100, dy: 40 }, 5],
    ['rotate-degrees', 'pump', { kind: 'rotate', tag: 'X', min: 0, max: 100, degrees: 180 }, 50],
    ['rotate-speed', 'pump', { kind: 'rotate', tag: 'B', speed: 1 }, true],
    ['rotate-speed-anticlockwise-when-off', 'fan', { kind: 'rotate', tag: 'B', speed: -0.5, when: false }, false],
    ['rotate-from-to', 'pump', { kind: 'rotate', tag: 'X', min: 0, max: 100, from: -90, degrees: 90 }, 25],
    ['rotate-anchor', 'rectangle', { kind: 'rotate', tag: 'X', min: 0, max: 10, degrees: 90, cx: 0, cy: 0 }, 5],
    ['rotate-anchor-spin', 'valve', { kind: 'rotate', tag: 'B', speed: 2, cx: 50, cy: 100 }, true],
    ['blink-times', 'led', { kind: 'blink', tag: 'B', on_ms: 250, off_ms: 750 }, true],
    ['blink-range', 'tank', { kind: 'blink', tag: 'L', min: 80, max: 100 }, 90],
    ['blink-range-outside', 'tank', { kind: 'blink', tag: 'L', min: 80, max: 100 }, 50],
    ['visibility-range', 'led', { kind: 'visibility', tag: 'L', min: 0, max: 10, when: false }, 5],
    ['move-when-off', 'pump', { kind: 'move', tag: 'B', dx: 30, dy: 0, when: false }, false],
    ['color-on', 'pump', { kind: 'color', tag: 'B', on: '#2e7d32', off: '#9ea3a8' }, true],
    ['color-off', 'pump', { kind: 'color', tag: 'B', on: '#2e7d32', off: '#9ea3a8' }, false],
    ['color-intervals', 'pump', { kind: 'color', tag: 'T', intervals: [{ from: 0, color: '#9ea3a8' }, { from: 55, color: '#c62828' }] }, 60],
    ['fill-up', 'tank', { kind: 'fill', tag: 'L', min: 0, max: 100, direction: 'up' }, 50],
    ['fill-down', 'tank', { kind: 'fill', tag: 'L', min: 0, max: 100, direction: 'down' }, 50],
    ['fill-left', 'tank', { kind: 'fill', tag: 'L', min: 0, max: 100, direction: 'left' }, 25],
    ['fill-right', 'tank', { kind: 'fill', tag: 'L', min: 0, max: 100, direction: 'right', color: '#c62828' }, 75],
  ];
  for (const [name, type, a, v] of cases) {
    it(`${name} on a ${type}`, async () => {
      const e = el(type);
      const g = drawElement(e);
      animate(g, e, a, v);
      await expect(g.outerHTML).toMatchFileSnapshot(golden(`anim-${name}`));
    });
  }
});
