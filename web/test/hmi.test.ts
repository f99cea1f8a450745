// Screens at run time (issue 17): every element type draws, and each
// animation changes what it should from a value.
import { describe, expect, it } from 'vitest';
import { domain } from '../src/domain';
import { type Element, animate, colorOf, drawElement, showAlarm, showLoop, showValue, tagsOf, tick } from '../src/hmi/render';
import type { Json } from '../src/types';

// the server's list (test/fixtures/domain.json, checked against GET /api/domain)
const TYPES = () => domain().screens.elements.map(([t]) => t);
const el = (type: string, extra: Partial<Element> = {}): Element => ({ id: type, type, x: 10, y: 20, w: 100, h: 200, ...extra });

describe('screen elements', () => {
  it('draws each of the 31 types at its place', () => {
    expect(TYPES().length).toBe(31);
    for (const t of TYPES()) {
      const g = drawElement(el(t, { props: { label: 'L' } }));
      expect(g.childElementCount, t).toBeGreaterThan(0);
      expect(g.getAttribute('transform'), t).toBe('translate(10,20) rotate(0 50 100)');
      expect(g.dataset.testid ?? g.getAttribute('data-testid')).toBe(`hmi-el-${t}`);
    }
  });

  it('fills a tank from a value between min and max, in each direction', () => {
    const e = el('tank');
    const g = drawElement(e);
    const level = g.querySelector('[data-part="level"]')!;
    animate(g, e, { kind: 'fill', tag: 'L', min: 0, max: 60, direction: 'up' }, 30);
    expect(Number(level.getAttribute('height'))).toBeCloseTo(98);
    expect(Number(level.getAttribute('y'))).toBeCloseTo(200 - 2 - 98);
    animate(g, e, { kind: 'fill', tag: 'L', min: 0, max: 60, direction: 'up' }, 90);
    expect(Number(level.getAttribute('height'))).toBeCloseTo(196, 0);
    animate(g, e, { kind: 'fill', tag: 'L', min: 0, max: 10, direction: 'right' }, 5);
    expect(Number(level.getAttribute('width'))).toBeCloseTo(48);
  });

  it('colours by on/off or by intervals, shows, hides, blinks, spins and moves', () => {
    expect(colorOf({ kind: 'color', tag: 'T', intervals: [{ from: 0, color: 'grey' }, { from: 55, color: 'red' }] }, 56)).toBe('red');
    expect(colorOf({ kind: 'color', tag: 'T', intervals: [{ from: 0, color: 'grey' }, { from: 55, color: 'red' }] }, 10)).toBe('grey');
    expect(colorOf({ kind: 'color', tag: 'B', on: 'green', off: 'white' }, false)).toBe('white');
    const e = el('pump');
    const g = drawElement(e);
    animate(g, e, { kind: 'color', tag: 'B', on: 'green' }, true);
    expect(g.querySelector('[data-part="fill"]')!.getAttribute('fill')).toBe('green');
    animate(g, e, { kind: 'rotate', tag: 'B', speed: 1 }, true);
    expect(g.querySelector('[data-part="rotor"]')!.classList.contains('hmi-spin')).toBe(true);
    animate(g, e, { kind: 'rotate', tag: 'B', speed: 1 }, false);
    expect(g.querySelector('[data-part="rotor"]')!.classList.contains('hmi-spin')).toBe(false);
    animate(g, e, { kind: 'visibility', tag: 'B' }, false);
    expect(g.style.display).toBe('none');
    animate(g, e, { kind: 'visibility', tag: 'B' }, true);
    expect(g.style.display).toBe('');
    animate(g, e, { kind: 'blink', tag: 'B' }, true);
    expect(g.classList.contains('hmi-blink')).toBe(true);
    animate(g, e, { kind: 'move', tag: 'X', min: 0, max: 10, dx: 100, dy: 0 }, 5);
    expect(g.getAttribute('transform')).toBe('translate(60,20) rotate(0 50 100)');
    const out = el('output');
    const og = drawElement(out);
    showValue(og, 36.129);
    expect(og.querySelector('[data-part="text"]')!.textContent).toBe('36.129');
  });

  it('subscribes to the tags the screen shows and writes, nothing else', () => {
    const screen = {
      schema: 1, width: 10, height: 10,
      elements: [el('tank', { animations: [{ kind: 'fill', tag: 'Level' }] }), el('output', { props: { tag: 'Flow' } }), el('switch', { action: { kind: 'toggle', tag: 'Run' } })],
    };
    expect(tagsOf(screen).sort()).toEqual(['Flow', 'Level', 'Run']);
  });
});

describe('gauges, trends and clocks', () => {
  it('turns a circular meter needle over 270° from min to max', () => {
    const e = el('meter', { props: { style: 'circular' } });
    const g = drawElement(e);
    animate(g, e, { kind: 'rotate', tag: 'L', min: 0, max: 60 }, 30);
    expect(g.querySelector('[data-part="needle"]')!.getAttribute('transform')).toBe('rotate(135)');
  });

  it('draws a trend of the last values on its scale', () => {
    const e = el('trend', { props: { tag: 'L', min: 0, max: 10 } });
    const g = drawElement(e);
    for (const v of [0, 5, 10, 20]) showValue(g, v, e.props);
    const pts = g.querySelector('[data-part="line"]')!.getAttribute('points')!.split(' ').map((p) => p.split(',').map(Number));
    expect(pts.length).toBe(4);
    const [, y0, , y1] = g.querySelector('[data-part="line"]')!.getAttribute('data-box')!.split(',').map(Number);
    expect(pts.map(([, y]) => y)).toEqual([y1, (y0 + y1) / 2, y0, y0].map((y) => Number(y.toFixed(1))));
  });

  it('sets a clock to the time', () => {
    const g = drawElement(el('clock'));
    tick(g, new Date(2026, 0, 1, 3, 30, 0));
    expect(g.querySelector('[data-part="hour"]')!.getAttribute('transform')).toBe('rotate(105)');
    expect(g.querySelector('[data-part="minute"]')!.getAttribute('transform')).toBe('rotate(180)');
    expect(g.querySelector('[data-part="text"]')!.textContent).toBe('03:30:00');
  });
});

describe('the faceplate element', () => {
  it('shows SP, PV and CV as bars and figures on their scales, and the mode', () => {
    const g = drawElement(el('faceplate', { props: { tag: 'Loop' } }));
    const m: Record<string, Json> = { SP: 5, PV: 2.5, CV: 75, MINS: 0, MAXS: 10, MINO: 0, MAXO: 100, MINCV: 0, MAXCV: 10000, MAN: false };
    showLoop(g, (k) => m[k]);
    const width = (k: string) => {
      const bar = g.querySelector(`[data-part="bar-${k}"]`)!;
      return Number(bar.getAttribute('width')) / Number(bar.getAttribute('data-width'));
    };
    expect([width('SP'), width('PV'), width('CV')].map((x) => Number(x.toFixed(2)))).toEqual([0.5, 0.25, 0.75]);
    expect(g.querySelector('[data-part="val-PV"]')!.textContent).toBe('2.50');
    expect(g.querySelector('[data-part="mode"]')!.textContent).toBe('AUTO');
  });
});

describe('the alarm indicator', () => {
  it('shows its alarm state: unacknowledged blinks, acknowledged is steady, normal is grey', () => {
    const g = drawElement(el('alarm', { props: { alarm: 'level_hi' } }));
    const fill = () => g.querySelector('[data-part="fill"]')!.getAttribute('fill');
    showAlarm(g, 'active_unacked');
    expect([fill(), g.classList.contains('hmi-blink')]).toEqual(['#c62828', true]);
    showAlarm(g, 'active_acked');
    expect([fill(), g.classList.contains('hmi-blink')]).toEqual(['#c62828', false]);
    showAlarm(g, 'cleared_unacked');
    expect([fill(), g.classList.contains('hmi-blink')]).toEqual(['#f9a825', true]);
    showAlarm(g, 'normal');
    expect([fill(), g.classList.contains('hmi-blink'), g.dataset.state]).toEqual(['#9ea3a8', false, 'normal']);
  });
});
