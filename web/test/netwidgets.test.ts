// The net's operator elements as OPCSM defines them (issue 34, point 10; the 003_… seed
// §2.2.3.13–16): a Display's modes and number formats, a Plot's autoscale or fixed range,
// a Label's look, a Button that latches on a double-click; their properties round-trip
// through the PNML's <widget> attributes.
import { describe, expect, it } from 'vitest';
import { loadPnml, savePnml } from '../src/net/pnml';
import { ButtonLatch, displayText, formatNumber, labelLook, plotRange } from '../src/net/widgets';

describe('a Display', () => {
  it('shows binary as ON/OFF, multivalue as the text of the value, numerical with its unit', () => {
    expect(displayText(true, { mode: 'binary' })).toBe('ON');
    expect(displayText(0, { mode: 'binary' })).toBe('OFF');
    expect(displayText(2, { mode: 'multivalue', states: '0:Stopped;1:Running;2:Fault' })).toBe('Fault');
    expect(displayText(7, { mode: 'multivalue', states: '0:Stopped' })).toBe('7');
    expect(displayText(120, { unit: 'Kg' })).toBe('120 Kg');
    expect(displayText(12.5)).toBe('12.5');
    expect(displayText(12.3456, { decimals: '2', unit: 'bar' })).toBe('12.35 bar');
    expect(displayText(undefined, { mode: 'binary' })).toBe('');
  });

  it('formats numbers as decimal, integer, engineering, binary 8…256, hex, time and string', () => {
    expect(formatNumber(12.6, 'integer')).toBe('13');
    expect(formatNumber(12345.678, 'engineering')).toBe('12.346e3');
    expect(formatNumber(0.00047, 'engineering')).toBe('470.000e-6');
    expect(formatNumber(999.9996, 'engineering')).toBe('1.000e3');
    expect(formatNumber(5, 'binary8')).toBe('0000 0101');
    expect(formatNumber(-1, 'binary16')).toBe('1111 1111 1111 1111');
    expect(formatNumber(1, 'binary32').replace(/ /g, '')).toHaveLength(32);
    expect(formatNumber(1, 'binary64').replace(/ /g, '')).toHaveLength(64);
    expect(formatNumber(1, 'binary128').replace(/ /g, '')).toHaveLength(128);
    expect(formatNumber(-1, 'binary256').replace(/ /g, '')).toBe('1'.repeat(256));
    expect(formatNumber(255, 'hex')).toBe('16#FF');
    expect(formatNumber(-1, 'hex')).toBe('16#FFFFFFFF');
    expect(formatNumber(3_723_456, 'time')).toBe('1:02:03.456');
    expect(formatNumber(61_500, 'time')).toBe('1:01.500');
    expect(formatNumber(-250, 'time')).toBe('-0:00.250');
    expect(formatNumber('abc', 'string')).toBe('abc');
    expect(formatNumber(true, 'decimal')).toBe('1');
    expect(displayText(4096, { format: 'hex', unit: 'counts' })).toBe('16#1000 counts');
  });
});

describe('a Plot', () => {
  it('autoscales by default, else draws between min and max', () => {
    expect(plotRange([20, 80, 35])).toEqual({ lo: 20, hi: 80 });
    expect(plotRange([20, 80, 35], { autoscale: 'false', min: '0', max: '100' })).toEqual({ lo: 0, hi: 100 });
    expect(plotRange([20, 80, 35], { autoscale: 'true', min: '0', max: '100' })).toEqual({ lo: 20, hi: 80 });
    expect(plotRange([20, 80], { autoscale: 'false', min: '50' })).toEqual({ lo: 50, hi: 80 });
    expect(plotRange([5, 5])).toEqual({ lo: 5, hi: 6 });
    expect(plotRange([], { autoscale: 'false', min: '10', max: '0' })).toEqual({ lo: 0, hi: 10 });
  });
});

describe('a Label', () => {
  it('has colours, a background that can be hidden, a border, a font and an alignment', () => {
    expect(labelLook({ color: '#c00', background: 'yellow', border: 'false', font: 'serif', font_size: '14', align: 'center' })).toEqual({
      color: '#c00', background: 'yellow', border: false, font: 'serif', fontSize: 14, align: 'center',
    });
    expect(labelLook({ background: 'yellow', show_background: 'false' }).background).toBeNull();
    expect(labelLook({ color: 'red;fill:blue', align: 'diagonal', font_size: '400' })).toMatchObject({ color: null, align: 'left', fontSize: null, border: true });
  });
});

describe('a Button', () => {
  it('is 1 while pressed, latches at 1 on a double-click, and a press releases the latch', () => {
    const b = new ButtonLatch();
    expect([b.press(), b.release()]).toEqual([true, false]);
    // a double-click: two presses and releases, then the double-click
    expect([b.press(), b.release(), b.press(), b.release(), b.double()]).toEqual([true, false, true, false, true]);
    expect(b.latched).toBe(true);
    // latched: the next press releases it (0), its release writes nothing
    expect([b.press(), b.release()]).toEqual([false, null]);
    expect(b.latched).toBe(false);
    expect([b.press(), b.release()]).toEqual([true, false]);
  });
});

describe('the properties in the PNML', () => {
  it('are attributes of <widget>, kept through a load and a save', () => {
    const text = `<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <toolspecific tool="alba" version="1">
      <widget id="d" kind="display" tag="Level" x="0" y="0" mode="numerical" format="hex" unit="kg" font_size="14">Level</widget>
      <widget id="p" kind="plot" tag="Level" x="0" y="60" autoscale="false" min="0" max="100" title="Tank" unit="%">Level</widget>
      <widget id="l" kind="label" x="0" y="120" color="#fff" background="navy" align="right">Note</widget>
    </toolspecific>
    <page id="pg"><place id="a"><name><text>a</text></name></place></page>
  </net>
</pnml>
`;
    const net = loadPnml(text).net!;
    expect(net.widgets.map((w) => w.style)).toEqual([
      { mode: 'numerical', format: 'hex', unit: 'kg', font_size: '14' },
      { autoscale: 'false', min: '0', max: '100', title: 'Tank', unit: '%' },
      { color: '#fff', background: 'navy', align: 'right' },
    ]);
    const again = loadPnml(savePnml(net)).net!;
    expect(again.widgets.map((w) => w.style)).toEqual(net.widgets.map((w) => w.style));
    expect(savePnml(net)).toContain('<widget id="p" kind="plot" tag="Level" x="0" y="60" autoscale="false" max="100" min="0" title="Tank" unit="%">Level</widget>');
  });
});
