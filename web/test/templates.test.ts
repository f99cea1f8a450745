import { describe, expect, it } from 'vitest';
import type { Element, Screen } from '../src/hmi/render';
import { symbolOf, ungroup } from '../src/hmi/edit';
import { instancesOf, instantiate, isPrefix, prefixOf, rebuild, rebuildAll, retag, tagsOf } from '../src/hmi/templates';

const el = (id: string, type: string, more: Partial<Element> = {}): Element => ({ id, type, x: 0, y: 0, w: 40, h: 40, props: {}, animations: [], ...more });

const faceplate = (): Screen => ({
  schema: 1, title: '', width: 100, height: 60,
  elements: [
    el('pump1', 'pump', { animations: [{ kind: 'rotate', tag: 'Pump1.Running' }] }),
    el('out1', 'output', { x: 50, props: { tag: 'Pump1.Speed' } }),
    el('btn1', 'button', { y: 40, action: { kind: 'toggle', tag: 'Pump1.Start' } }),
  ],
});

describe('templates and their instances', () => {
  it('a template is a symbol whose tags share a first name', () => {
    expect(tagsOf(faceplate().elements)).toEqual(['Pump1.Running', 'Pump1.Speed', 'Pump1.Start']);
    expect(prefixOf(faceplate().elements)).toBe('Pump1');
    expect(prefixOf([el('a', 'led', { props: { tag: 'Bomba1' } })])).toBe('Bomba1');
    expect(prefixOf([el('a', 'led', { props: { tag: 'A.x' } }), el('b', 'led', { props: { cap_tag: 'B.y' } })])).toBeNull();
    expect(prefixOf([el('a', 'rectangle')])).toBeNull();
  });

  it('retags the prefix only, the whole name or its first part', () => {
    expect(retag('Pump1.Running', 'Pump1', 'Pump2')).toBe('Pump2.Running');
    expect(retag('Pump1', 'Pump1', 'Pump2')).toBe('Pump2');
    expect(retag('Pump10.Running', 'Pump1', 'Pump2')).toBe('Pump10.Running');
    expect(isPrefix('Pump2')).toBe(true);
    expect(isPrefix('Area1.Pump2')).toBe(true);
    expect(isPrefix('2pump')).toBe(false);
    expect(isPrefix('Pump 2')).toBe(false);
  });

  it('an instance: copies with the instance\'s prefix, placed, grouped, marked', () => {
    const screen: Screen = { schema: 1, title: '', width: 800, height: 600, elements: [el('pump1', 'pump')] };
    const els = instantiate(screen, faceplate(), 'pumpface', 'Pump2', 200, 100, 'g1');
    expect(els.map((e) => e.id)).toEqual(['pump2', 'output1', 'button1']);
    expect(tagsOf(els)).toEqual(['Pump2.Running', 'Pump2.Speed', 'Pump2.Start']);
    expect(els.map((e) => [e.x, e.y])).toEqual([[200, 100], [250, 100], [200, 140]]);
    expect(els.every((e) => e.group === 'g1' && e.props?.template === 'pumpface' && e.props?.prefix === 'Pump2')).toBe(true);
    expect(els.map((e) => e.props?.part)).toEqual(['pump1', 'out1', 'btn1']);
  });

  it('two instances are found, and rebuilt when the template changes (ids and place kept)', () => {
    const screen: Screen = { schema: 1, title: '', width: 800, height: 600, elements: [] };
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump1', 0, 0, 'g1'));
    screen.elements.push(el('title', 'text'));
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump2', 300, 0, 'g2'));
    const insts = instancesOf(screen);
    expect(insts).toEqual([
      { group: 'g1', template: 'pumpface', prefix: 'Pump1', x: 0, y: 0 },
      { group: 'g2', template: 'pumpface', prefix: 'Pump2', x: 300, y: 0 },
    ]);
    const ids = screen.elements.map((e) => e.id);
    // unchanged template: nothing to do
    expect(rebuild(screen, insts[1], faceplate())).toBe(false);
    // the template gets a fourth element and a new colour
    const t2 = faceplate();
    t2.elements[0].props = { color: '#2e7d32' };
    t2.elements.push(el('led1', 'led', { x: 80, props: { tag: 'Pump1.Fault' } }));
    expect(rebuild(screen, insts[1], t2)).toBe(true);
    expect(screen.elements.map((e) => e.id)).toEqual([...ids, 'led1']);
    const g2 = screen.elements.filter((e) => e.group === 'g2');
    expect(tagsOf(g2)).toEqual(['Pump2.Running', 'Pump2.Speed', 'Pump2.Start', 'Pump2.Fault']);
    expect(g2[0].props?.color).toBe('#2e7d32');
    expect(g2[3].x).toBe(380);
    // a new prefix for the first, in its place before the text
    expect(rebuild(screen, insts[0], t2, 'Pump7')).toBe(true);
    expect(screen.elements[4].id).toBe('title');
    expect(tagsOf(screen.elements.filter((e) => e.group === 'g1'))).toEqual(['Pump7.Running', 'Pump7.Speed', 'Pump7.Start', 'Pump7.Fault']);
  });

  it('rebuilds every instance of one template on a screen, and only those', () => {
    const screen: Screen = { schema: 1, title: '', width: 800, height: 600, elements: [] };
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump1', 0, 0, 'g1'));
    screen.elements.push(...instantiate(screen, faceplate(), 'other', 'Pump3', 0, 200, 'g3'));
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump2', 300, 0, 'g2'));
    expect(rebuildAll(screen, 'pumpface', faceplate()), 'unchanged').toBe(0);
    const t2 = faceplate();
    t2.elements[0].props = { color: '#2e7d32' };
    expect(rebuildAll(screen, 'pumpface', t2)).toBe(2);
    const colour = (g: string) => screen.elements.find((e) => e.group === g)?.props?.color;
    expect([colour('g1'), colour('g2'), colour('g3')]).toEqual(['#2e7d32', '#2e7d32', undefined]);
    expect(tagsOf(screen.elements.filter((e) => e.group === 'g2'))).toEqual(['Pump2.Running', 'Pump2.Speed', 'Pump2.Start']);
  });

  it('a group whose elements disagree is not an instance', () => {
    const screen: Screen = { schema: 1, title: '', width: 800, height: 600, elements: [] };
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump1', 0, 0, 'g1'));
    screen.elements[1].props = { ...screen.elements[1].props, prefix: 'Other' };
    expect(instancesOf(screen)).toEqual([]);
  });
});

describe('an instance made plain', () => {
  it('ungrouped, or saved as a symbol, it loses its marks', () => {
    const screen: Screen = { schema: 1, title: '', width: 800, height: 600, elements: [] };
    screen.elements.push(...instantiate(screen, faceplate(), 'pumpface', 'Pump2', 10, 10, 'g1'));
    const sym = symbolOf(screen.elements);
    expect(sym.elements.some((e) => 'template' in (e.props ?? {}) || 'part' in (e.props ?? {}))).toBe(false);
    expect(prefixOf(sym.elements)).toBe('Pump2');
    ungroup(screen, new Set(screen.elements.map((e) => e.id)));
    expect(instancesOf(screen)).toEqual([]);
    expect(screen.elements.every((e) => !e.group && !('prefix' in (e.props ?? {})))).toBe(true);
  });
});
