import { describe, expect, it } from 'vitest';
import { faceplateKey, faceplateParts, tankFill, trendKey, windowMs, withYLimit } from '../src/ui/fkeys';

describe('the function keys of the 004 PID monitor', () => {
  it('maps the faceplate keys as the seed lists them', () => {
    expect(['F1', 'F3', 'F5', 'F6', 'F8', 'F9', 'ArrowUp', 'ArrowDown'].map((key) => faceplateKey({ key }))).toEqual([
      'control', 'mode', 'tank', 'combined', 'alarms-on', 'alarms-off', 'up', 'down',
    ]);
    expect(faceplateKey({ key: 'F2' })).toBeNull();
    // Ctrl+F6 belongs to the trend, not to the faceplate's F6
    expect(faceplateKey({ key: 'F6', ctrlKey: true })).toBeNull();
    expect(faceplateKey({ key: 'F1', shiftKey: true })).toBeNull();
  });

  it('maps Ctrl+F6, Ctrl+F7 and Ctrl+F8 on the trends', () => {
    expect(trendKey({ key: 'F6', ctrlKey: true })).toBe('y-max');
    expect(trendKey({ key: 'F7', ctrlKey: true })).toBe('y-min');
    expect(trendKey({ key: 'F8', ctrlKey: true })).toBe('window');
    expect(trendKey({ key: 'F6' })).toBeNull();
    expect(trendKey({ key: 'F9', ctrlKey: true })).toBeNull();
    expect(trendKey({ key: 'F8', ctrlKey: true, shiftKey: true })).toBeNull();
  });

  it('shows the trend, the tank or both', () => {
    expect(faceplateParts('control')).toEqual({ trend: true, tank: false });
    expect(faceplateParts('tank')).toEqual({ trend: false, tank: true });
    expect(faceplateParts('combined')).toEqual({ trend: true, tank: true });
    expect(tankFill(50, 0, 100)).toBe(0.5);
    expect(tankFill(150, 0, 100)).toBe(1);
    expect(tankFill(-3, 0, 100)).toBe(0);
    expect(tankFill(5, 10, 10)).toBe(0);
  });

  it('sets one Y bound, keeping or fixing the other, and refuses an empty scale', () => {
    const pens = [{ tag: 'A', min: null, max: null }, { tag: 'B', min: 0, max: 50 }];
    expect(withYLimit(pens, 'max', 80, [-5, 120])).toEqual([{ tag: 'A', min: -5, max: 80 }, { tag: 'B', min: 0, max: 80 }]);
    expect(withYLimit(pens, 'min', 10, [-5, 120])).toEqual([{ tag: 'A', min: 10, max: 120 }, { tag: 'B', min: 10, max: 50 }]);
    expect(withYLimit(pens, 'min', 60, [-5, 120])).toBeNull();
    expect(withYLimit(pens, 'max', Number.NaN, [0, 1])).toBeNull();
  });

  it('reads the window in seconds', () => {
    expect(windowMs('30')).toBe(30000);
    expect(windowMs('2,5')).toBe(2500);
    expect(windowMs('0')).toBeNull();
    expect(windowMs('abc')).toBeNull();
  });
});
