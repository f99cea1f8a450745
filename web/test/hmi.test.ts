// Screens at run time (issue 17): every element type draws, and each
// animation changes what it should from a value.
import { describe, expect, it } from 'vitest';
import { domain } from '../src/domain';
import { type Element, active, animate, blinkTimes, colorOf, drawElement, showAlarm, showLoop, showValue, tagsOf, tick } from '../src/hmi/render';
import type { Json } from '../src/types';
import { PEN_COLORS, ScreenTrend, trendPens, trendPoints, trendScale, windowMs } from '../src/hmi/trend';
import { clockTime } from '../src/i18n';
import { parsePens } from '../src/hmi/animform';

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
    expect(g.classList.contains('hmi-blinking')).toBe(true);
    animate(g, e, { kind: 'move', tag: 'X', min: 0, max: 10, dx: 100, dy: 0 }, 5);
    expect(g.getAttribute('transform')).toBe('translate(60,20) rotate(0 50 100)');
    const out = el('output');
    const og = drawElement(out);
    showValue(og, 36.129);
    expect(og.querySelector('[data-part="text"]')!.textContent).toBe('36.129');
  });

  it('blinks with its own shown and hidden times, on a digital or an analog condition', () => {
    const e = el('pump');
    const g = drawElement(e);
    const blinker = () => g.querySelector(':scope > animate[data-part="blink"]');
    animate(g, e, { kind: 'blink', tag: 'B', on_ms: 300, off_ms: 700 }, true);
    expect([blinker()!.getAttribute('dur'), blinker()!.getAttribute('keyTimes'), blinker()!.getAttribute('values')]).toEqual(['1000ms', '0;0.3', '1;0.15']);
    animate(g, e, { kind: 'blink', tag: 'B', on_ms: 300, off_ms: 700 }, false);
    expect([blinker(), g.classList.contains('hmi-blinking')]).toEqual([null, false]);
    // the older period_ms: shown and hidden for half each
    animate(g, e, { kind: 'blink', tag: 'B', period_ms: 400 }, true);
    expect(blinker()!.getAttribute('dur')).toBe('400ms');
    expect(blinkTimes({ kind: 'blink', tag: 'B' })).toEqual([500, 500]);
    // analog: inside min–max; when false: outside
    const range = { kind: 'blink', tag: 'L', min: 50, max: 60 };
    expect([active(range, 49.9), active(range, 50), active(range, 60), active(range, 61)]).toEqual([false, true, true, false]);
    expect([active({ ...range, when: false }, 55), active({ ...range, when: false }, 70)]).toEqual([false, true]);
    expect([active({ kind: 'visibility', tag: 'L', min: 5 }, 1e9), active({ kind: 'visibility', tag: 'B', when: false }, true)]).toEqual([true, false]);
    animate(g, e, { kind: 'visibility', tag: 'L', min: 5, max: 10 }, 11);
    expect(g.style.display).toBe('none');
  });

  it('rotates about an anchor point, from one angle to another, and spins at its speed', () => {
    const e = el('pump');
    const g = drawElement(e);
    // an anchor turns the whole element about it, after its placement
    animate(g, e, { kind: 'rotate', tag: 'X', min: 0, max: 100, from: -90, degrees: 90, cx: 0, cy: 10 }, 75);
    expect(g.getAttribute('transform')).toBe('translate(10,20) rotate(0 50 100) rotate(45 0 10)');
    animate(g, e, { kind: 'move', tag: 'M', min: 0, max: 1, dx: 5, dy: 0, when: false }, false);
    expect(g.getAttribute('transform')).toBe('translate(15,20) rotate(0 50 100) rotate(45 0 10)');
    // without one a pump's rotor turns about its hub
    animate(g, e, { kind: 'rotate', tag: 'X', min: 0, max: 100, degrees: 180 }, 50);
    expect(g.querySelector('[data-part="rotor"]')!.getAttribute('transform')).toBe('rotate(90)');
    // a spin: the rotor, 2 turns a second anticlockwise, while the tag is off (when: false)
    const spin = () => g.querySelector('[data-part="rotor"] > animateTransform[data-part="spin"]');
    animate(g, e, { kind: 'rotate', tag: 'B', speed: -2, when: false }, false);
    expect([spin()!.getAttribute('dur'), spin()!.getAttribute('to'), spin()!.getAttribute('additive')]).toEqual(['0.5s', '-360 0 0', 'sum']);
    animate(g, e, { kind: 'rotate', tag: 'B', speed: -2, when: false }, true);
    expect(spin()).toBeNull();
    // a whole element spins about its anchor
    const t = el('rectangle');
    const tg = drawElement(t);
    animate(tg, t, { kind: 'rotate', tag: 'B', speed: 0.5, cx: 5, cy: 6 }, true);
    const whole = tg.querySelector(':scope > animateTransform[data-part="spin"]')!;
    expect([whole.getAttribute('from'), whole.getAttribute('to'), whole.getAttribute('dur')]).toEqual(['0 5 6', '360 5 6', '2s']);
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

  it('draws a trend of its time window on its scale, with axis labels (issue 30, item 4)', () => {
    const e = el('trend', { w: 220, h: 130, props: { tag: 'L', min: 0, max: 10, window_s: 60 } });
    const g = drawElement(e);
    const t = new ScreenTrend(g, e.props);
    expect(t.windowMs).toBe(60_000);
    const now = new Date(2026, 5, 12, 16, 54, 0).getTime();
    // from the historian: 0 held since before the window, 5 at its middle
    t.seed([[now - 90_000, 0], [now - 30_000, 5]]);
    t.push(now - 10_000, 10);
    t.draw(now);
    const [x0, y0, x1, y1] = g.querySelector('[data-part="line"]')!.getAttribute('data-box')!.split(',').map(Number);
    const pts = g.querySelector('[data-part="line"]')!.getAttribute('points')!.split(' ').map((p) => p.split(',').map(Number));
    const at = (f: number) => Number((x0 + (x1 - x0) * f).toFixed(1));
    const y = (v: number) => Number((y1 - (v / 10) * (y1 - y0)).toFixed(1));
    expect(pts).toEqual([[at(0), y(0)], [at(0.5), y(0)], [at(0.5), y(5)], [at(5 / 6), y(5)], [at(5 / 6), y(10)], [at(1), y(10)]]);
    const text = (part: string) => g.querySelector(`[data-part="${part}"]`)!.textContent;
    expect([text('y-min'), text('y-max')]).toEqual(['0', '10']);
    expect([text('x-from'), text('x-to')]).toEqual([clockTime(now - 60_000), clockTime(now)]);
  });

  it('draws a steady value as a steady line across the window, on a scale around it', () => {
    const e = el('trend', { w: 220, h: 130, props: { tag: 'L' } });
    const g = drawElement(e);
    const t = new ScreenTrend(g, e.props);
    expect(t.windowMs).toBe(120_000); // the default: 2 minutes
    const now = 1_000_000_000;
    t.push(now - 500_000, 42); // one value, long before the window, never changed since
    t.draw(now);
    const pts = g.querySelector('[data-part="line"]')!.getAttribute('points')!.split(' ').map((p) => p.split(',').map(Number));
    const [x0, y0, x1, y1] = g.querySelector('[data-part="line"]')!.getAttribute('data-box')!.split(',').map(Number);
    expect(pts.map(([x]) => x)).toEqual([x0, x1]);
    expect(pts[0][1]).toBe(pts[1][1]);
    expect(pts[0][1]).toBeCloseTo((y0 + y1) / 2, 0);
    expect(g.querySelector('[data-part="y-min"]')!.textContent).toBe('37.8');
    expect(g.querySelector('[data-part="y-max"]')!.textContent).toBe('46.2');
    // later: still a line to now
    t.draw(now + 60_000);
    expect(g.querySelector('[data-part="line"]')!.getAttribute('points')!.split(' ').length).toBe(2);
  });

  it('draws up to three pens on one scale, each in its colour, with a legend (issue 35, point 1)', async () => {
    const props: Record<string, Json> = {
      label: 'Level, pump, speed',
      window_s: 60,
      pens: [{ tag: 'L', color: '#c62828' }, { tag: 'P' }, { tag: 'S', color: 'purple' }, { tag: 'X' }],
    };
    expect(trendPens(props)).toEqual([
      { tag: 'L', color: '#c62828' },
      { tag: 'P', color: PEN_COLORS[1] },
      { tag: 'S', color: 'purple' },
    ]);
    expect(trendPens({ tag: 'L' }), 'the one pen of its tag').toEqual([{ tag: 'L', color: PEN_COLORS[0] }]);
    expect(trendPens({ pens: [{ color: 'red' }, 'L'] }), 'a pen without a tag is none').toEqual([]);
    const e = el('trend', { w: 220, h: 130, props });
    expect(tagsOf({ schema: 1, width: 300, height: 200, elements: [e] }).sort()).toEqual(['L', 'P', 'S']);
    const g = drawElement(e);
    await expect(g.outerHTML).toMatchFileSnapshot('./__snapshots__/symbols/trend-pens.svg');
    const stroke = (part: string) => g.querySelector(`[data-part="${part}"]`)!.getAttribute('stroke');
    expect([stroke('line'), stroke('line-2'), stroke('line-3')]).toEqual(['#c62828', PEN_COLORS[1], 'purple']);
    expect(g.querySelector('[data-part="line-4"]')).toBeNull();
    expect([1, 2, 3].map((k) => g.querySelector(`[data-part="pen-${k}"]`)!.textContent)).toEqual(['L', 'P', 'S']);
    const t = new ScreenTrend(g, e.props, 3);
    const now = 1_000_000_000;
    t.push(now - 30_000, 0, 0);
    t.push(now - 30_000, 100, 1);
    t.push(now - 30_000, 50, 2);
    t.draw(now);
    // one scale for all: 0…100 widened by 5 %
    expect([g.querySelector('[data-part="y-min"]')!.textContent, g.querySelector('[data-part="y-max"]')!.textContent]).toEqual(['-5', '105']);
    const ys = ['line', 'line-2', 'line-3'].map((part) => Number(g.querySelector(`[data-part="${part}"]`)!.getAttribute('points')!.split(' ')[0].split(',')[1]));
    const [, y0, , y1] = g.querySelector('[data-part="line"]')!.getAttribute('data-box')!.split(',').map(Number);
    const y = (v: number) => Number((y1 - ((v + 5) / 110) * (y1 - y0)).toFixed(1));
    expect(ys).toEqual([y(0), y(100), y(50)]);
  });

  it('reads the pens form: "tag colour" lines, at most three', () => {
    expect(parsePens('Level #c62828\n\n  Pump  \nSpeed purple\n', 3)).toEqual([{ tag: 'Level', color: '#c62828' }, { tag: 'Pump' }, { tag: 'Speed', color: 'purple' }]);
    expect(parsePens('A\nB\nC\nD', 3)).toBeNull();
    expect(parsePens('', 3)).toEqual([]);
  });

  it('takes a window of 1 s to a day, else 2 minutes', () => {
    expect([windowMs({ window_s: 1 }), windowMs({ window_s: 86_400 }), windowMs({ window_s: 0 }), windowMs({ window_s: '60' }), windowMs(undefined)]).toEqual([1000, 86_400_000, 120_000, 120_000, 120_000]);
    expect(trendScale([], { min: 5 })).toEqual([0, 1]);
    expect(trendScale([1, 3], {})).toEqual([0.9, 3.1]);
    expect(trendPoints([], 0, 10, [0, 0, 10, 10], [0, 1])).toBe('');
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
