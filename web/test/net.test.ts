// The net editor's model (issue 20): PNML read and written as the server
// does, round trips of every example and fixture.
import { readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import { loadPnml, savePnml } from '../src/net/pnml';
import { lineCol, offsetOf, parseXml } from '../src/net/xml';

const REPO = join(__dirname, '../..');
const examples = readdirSync(join(REPO, 'examples')).flatMap((d) => {
  try {
    return readdirSync(join(REPO, 'examples', d)).filter((f) => f.endsWith('.pnml')).map((f) => join(REPO, 'examples', d, f));
  } catch {
    return [];
  }
});
const FIXTURES = join(REPO, 'crates/net/tests/fixtures');
const SAVED = join(REPO, 'crates/net/tests/saved');
const fixtures = readdirSync(FIXTURES).filter((f) => f.endsWith('.pnml'));

describe('PNML', () => {
  it('finds the examples', () => {
    expect(examples.length).toBeGreaterThanOrEqual(2);
    expect(fixtures.length).toBeGreaterThanOrEqual(4);
  });

  for (const f of [...examples, ...fixtures.map((x) => join(FIXTURES, x))]) {
    it(`round-trips ${f.slice(REPO.length + 1)}: parse → save → parse gives the same model, and saving again the same text`, () => {
      const a = loadPnml(readFileSync(f, 'utf8'));
      expect(a.error).toBeNull();
      const text = savePnml(a.net!);
      const b = loadPnml(text);
      expect(b.error).toBeNull();
      expect(b.net).toEqual(a.net);
      expect(savePnml(b.net!)).toBe(text);
    });
  }

  for (const f of fixtures) {
    it(`writes ${f} as the server does (crates/net/tests/saved)`, () => {
      const a = loadPnml(readFileSync(join(FIXTURES, f), 'utf8'));
      expect(savePnml(a.net!)).toBe(readFileSync(join(SAVED, f), 'utf8'));
    });
  }

  it('reads Alba’s block: mode, kinds, guards, props, scripts, arc kinds', () => {
    const { net } = loadPnml(readFileSync(join(REPO, 'examples/state-net-batch/batch.pnml'), 'utf8'));
    expect(net!.mode).toBe('normal');
    const start = net!.transitions.find((t) => t.id === 'start')!;
    expect(start.kind).toBe('condition');
    expect(start.guard).toBe('Start AND batch.batches.count < 3');
    expect(net!.places.find((p) => p.id === 'batches')!.props).toEqual({ load: '0', direction: 'up' });
    expect(net!.places[0].extra.graphics).toMatchObject({ x: 40, y: 40 });
    expect(net!.places.find((p) => p.id === 'done')!.tag).toBe('AllDone');
  });

  it('keeps what it does not know, and reports bad XML with its place', () => {
    const text = `<pnml><net id="n" type="x"><page id="p"><place id="a"><toolspecific tool="other"><z q="1"/></toolspecific>
      <toolspecific tool="alba" version="1"><kind>Counter</kind><bogus>1</bogus></toolspecific></place></page></net></pnml>`;
    const { net } = loadPnml(text);
    expect(net!.places[0].kind).toBe('counter');
    expect(net!.places[0].extra.toolspecific).toEqual(['<toolspecific tool="other"><z q="1"/></toolspecific>']);
    expect(net!.places[0].albaExtra).toEqual(['<bogus>1</bogus>']);
    expect(savePnml(net!)).toContain('<bogus>1</bogus>');
    const bad = loadPnml('<pnml><net id="n" type="x">\n<place id="a"></net></pnml>');
    expect(bad.net).toBeNull();
    expect(bad.error!.message).toMatch(/closes <place>/);
    expect(lineCol('<pnml><net id="n" type="x">\n<place id="a"></net></pnml>', bad.error!.offset)).toEqual([2, 15]);
  });

  it('resolves entities, CDATA and character references', () => {
    const e = parseXml('<a x="1 &amp; 2">t &lt; <![CDATA[<b>]]>&#65;&#x42;</a>');
    expect(e.attrs).toEqual([['x', '1 & 2']]);
    expect(e.text).toBe('t < <b>AB');
    expect(() => parseXml('<a>&nbsp;</a>')).toThrow(/unknown entity/);
  });

  it('converts line:column and offsets both ways (columns in characters)', () => {
    const t = 'ab\nc😀d\ne';
    expect(offsetOf(t, 2, 3)).toBe(6);
    expect(lineCol(t, 6)).toEqual([2, 3]);
    expect(offsetOf(t, 3, 1)).toBe(t.indexOf('e'));
  });
});
