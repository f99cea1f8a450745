// The net editor's pure operations (issue 20): edits, geometry and routing,
// markings, enabling and the replay of a firing sequence.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import { addPlace, addTransition, arcProblem, connect, copy, moveNodes, paste, position, remove, rename, setPosition } from '../src/net/edit';
import { placeBox, positions, route, routes, segmentHitsBox, transitionBox } from '../src/net/geom';
import { emptyNet, loadPnml, noExtra, savePnml } from '../src/net/pnml';
import { enabled, fire, initialMarking, markingTag, netName, replay } from '../src/net/sim';

const REPO = join(__dirname, '../..');
const cell = () => loadPnml(readFileSync(join(REPO, 'examples/petri-resource/cell.pnml'), 'utf8')).net!;

describe('net edits', () => {
  it('adds states and transitions with fresh ids on the grid, and arcs only between a place and a transition', () => {
    const net = emptyNet('n', 'normal');
    const s0 = addPlace(net, 41, 58);
    const s1 = addPlace(net, 200, 60);
    const t = addTransition(net, 120, 63);
    const c = addTransition(net, 300, 60, 'condition');
    const e = addPlace(net, 0, 0, 'expression');
    expect([s0.id, s1.id, t.id, c.id, e.id]).toEqual(['S0', 'S1', 'T1', 'C1', 'E1']);
    expect(position(s0.extra)).toEqual({ x: 40, y: 60 });
    expect(position(t.extra)).toEqual({ x: 120, y: 60 });
    expect(e.script).toBe('');
    expect(arcProblem(net, 'S0', 'S1')).toBe('same');
    expect(connect(net, 'S0', 'S1')).toBeNull();
    expect(connect(net, 'S0', 'T1')!.id).toBe('a1');
    expect(connect(net, 'S0', 'T1')).toBeNull();
    expect(arcProblem(net, 'T1', 'S1', 'inhibitor')).toBe('direction');
    expect(connect(net, 'T1', 'S1', 2)!.weight).toBe(2);
    // saved and read back: the same model
    expect(loadPnml(savePnml(net)).net).toEqual(net);
  });

  it('moves a node inside its own graphics, keeping the rest of them', () => {
    const extra = noExtra();
    extra.graphics = { x: 1, y: 2, raw: '<graphics><position x="1" y="2"/><dimension x="40" y="40"/></graphics>' };
    setPosition(extra, 30, 40);
    expect(extra.graphics!.raw).toBe('<graphics><position x="30" y="40"/><dimension x="40" y="40"/></graphics>');
    extra.graphics = { x: null, y: null, raw: '<pn:graphics><pn:fill color="red"/></pn:graphics>' };
    setPosition(extra, 5, 6);
    expect(extra.graphics!.raw).toBe('<pn:graphics><pn:position x="5" y="6"/><pn:fill color="red"/></pn:graphics>');
    const net = cell();
    const at = positions(net);
    moveNodes(net, ['robot', 'grab1'], 10, -10, (id) => at.get(id)!);
    const again = loadPnml(savePnml(net)).net!;
    expect(position(again.places.find((p) => p.id === 'robot')!.extra)).toEqual({ x: at.get('robot')!.x + 10, y: at.get('robot')!.y - 10 });
  });

  it('deletes nodes with their arcs; copies and pastes with fresh ids and the arcs between the copies', () => {
    const net = cell();
    const before = net.arcs.length;
    const clip = copy(net, new Set(['idle1', 'arrive1', 'wait1']));
    expect(clip.arcs.map((a) => a.id)).toEqual(['a1', 'a2']);
    const at = positions(net);
    const ids = paste(net, clip, 20, 20, (id) => at.get(id)!);
    expect(ids).toEqual(['idle3', 'wait3', 'arrive3']);
    expect(net.arcs.slice(-2).map((a) => [a.id, a.source, a.target])).toEqual([['a12', 'idle3', 'arrive3'], ['a13', 'arrive3', 'wait3']]);
    remove(net, new Set(['robot']));
    expect(net.places.some((p) => p.id === 'robot')).toBe(false);
    expect(net.arcs.length).toBe(before + 2 - 4);
    expect(net.arcs.some((a) => a.source === 'robot' || a.target === 'robot')).toBe(false);
  });

  it('renames a node and its arcs follow; refuses a taken id or one that is not an identifier', () => {
    const net = cell();
    expect(rename(net, 'robot', 'idle1')).toBe('taken');
    expect(rename(net, 'robot', 'two words')).toBe('ident');
    expect(rename(net, 'robot', 'arm')).toBeNull();
    expect(net.arcs.filter((a) => a.source === 'arm' || a.target === 'arm').length).toBe(4);
  });
});

describe('net geometry', () => {
  it('lays out nodes without a position by layers from the marked places', () => {
    const at = positions(cell());
    expect(at.size).toBe(18);
    expect(at.get('robot')!.x).toBe(at.get('idle1')!.x);
    expect(at.get('arrive1')!.x).toBeGreaterThan(at.get('idle1')!.x);
    const seen = new Set([...at.values()].map((p) => `${p.x},${p.y}`));
    expect(seen.size).toBe(18);
  });

  it('routes straight when nothing is in the way, around a node that is, and clips to the outlines', () => {
    const p = { x: 0, y: 0 };
    const t = { x: 200, y: 0 };
    expect(route(p, 'place', t, 'transition', [])).toEqual([{ x: 20, y: 0 }, { x: 194, y: 0 }]);
    const block = placeBox({ x: 100, y: 0 });
    const r = route(p, 'place', t, 'transition', [block]);
    expect(r.length).toBeGreaterThan(2);
    for (let k = 1; k < r.length; k++) expect(segmentHitsBox(r[k - 1], r[k], block)).toBe(false);
    expect(segmentHitsBox({ x: 0, y: 0 }, { x: 200, y: 0 }, transitionBox({ x: 100, y: 0 }))).toBe(true);
    expect(segmentHitsBox({ x: 0, y: 50 }, { x: 200, y: 50 }, transitionBox({ x: 100, y: 0 }))).toBe(false);
  });

  it('draws two arcs between the same nodes, one each way, side by side', () => {
    const net = emptyNet('n', 'petri');
    addPlace(net, 0, 0);
    addTransition(net, 100, 0);
    connect(net, 'P1', 'T1');
    connect(net, 'T1', 'P1');
    const r = routes(net, positions(net));
    expect(r.get('a1')![0].y).not.toBe(r.get('a2')![0].y);
  });
});

describe('markings', () => {
  it('names marking tags after the file', () => {
    expect(netName('nets/line.pnml')).toBe('line');
    expect(markingTag('cell.pnml', 'robot')).toBe('cell.robot');
  });

  it('finds the transitions a marking enables, with weights, inhibitor and read arcs', () => {
    const net = emptyNet('n', 'petri');
    addPlace(net, 0, 0).initial = 2;
    addPlace(net, 0, 100);
    addTransition(net, 100, 0);
    addTransition(net, 100, 100);
    connect(net, 'P1', 'T1', 2);
    connect(net, 'P2', 'T1', 1, 'inhibitor');
    connect(net, 'P1', 'T2', 3, 'read');
    connect(net, 'T1', 'P2');
    const m0 = initialMarking(net);
    expect([...enabled(net, m0)]).toEqual(['T1']);
    const m1 = fire(net, m0, 'T1');
    expect(Object.fromEntries(m1)).toEqual({ P1: 0, P2: 1 });
    expect(enabled(net, m1).size).toBe(0);
  });

  it('replays a firing sequence to a deadlock, stopping at a transition that is not enabled', () => {
    const net = cell();
    const { markings, fired } = replay(net, ['arrive1', 'arrive2', 'grab1', 'grab2']);
    expect(fired).toEqual(['arrive1', 'arrive2', 'grab1']);
    expect(markings.length).toBe(4);
    expect(markings[3].get('load1')).toBe(1);
    expect(markings[3].get('robot')).toBe(0);
  });
});

describe('guard and script highlighting', () => {
  it('tells keywords, numbers, tags and names that are not tags apart, and keeps the text', async () => {
    const { highlight } = await import('../src/net/code');
    const text = 'Start AND NOT Strat OR line.buffer >= 2.5 // go\nT1.DN';
    const toks = highlight(text, (n) => ['START', 'LINE.BUFFER', 'T1.DN'].includes(n.toUpperCase()));
    expect(toks.map((t) => t.text).join('')).toBe(text);
    const kinds = Object.fromEntries(toks.filter((t) => t.kind !== 'space' && t.kind !== 'op').map((t) => [t.text, t.kind]));
    expect(kinds).toEqual({ Start: 'tag', AND: 'keyword', NOT: 'keyword', Strat: 'name', OR: 'keyword', 'line.buffer': 'tag', '2.5': 'number', '// go': 'comment', 'T1.DN': 'tag' });
  });

  it("shows the source's functions as functions, only where they are called", async () => {
    const { highlight } = await import('../src/net/code');
    const text = 'v2 = cos (v1) * total & sqrt(v3) > 2 | cosine(v1) + rem';
    const toks = highlight(text, (n) => ['V1', 'V2', 'V3', 'TOTAL'].includes(n.toUpperCase()));
    expect(toks.map((t) => t.text).join('')).toBe(text);
    const kinds = Object.fromEntries(toks.filter((t) => t.kind !== 'space' && t.kind !== 'op').map((t) => [t.text, t.kind]));
    expect(kinds).toEqual({ v2: 'tag', cos: 'function', v1: 'tag', total: 'tag', sqrt: 'function', v3: 'tag', '2': 'number', cosine: 'name', rem: 'name' });
  });
});

describe('routing a large net', () => {
  // (How fast is for a benchmark to say, not a test: tests assert no wall-clock times.)
  it('routes 400 arcs among 200 nodes', () => {
    const net = emptyNet('big', 'petri');
    for (let k = 0; k < 100; k++) addPlace(net, (k % 10) * 80, Math.floor(k / 10) * 80);
    for (let k = 0; k < 100; k++) addTransition(net, (k % 10) * 80 + 40, Math.floor(k / 10) * 80 + 40);
    for (let k = 0; k < 100; k++) {
      connect(net, `P${k + 1}`, `T${k + 1}`);
      connect(net, `T${k + 1}`, `P${((k + 11) % 100) + 1}`);
      connect(net, `P${((k + 37) % 100) + 1}`, `T${k + 1}`);
      connect(net, `T${k + 1}`, `P${((k + 3) % 100) + 1}`);
    }
    const r = routes(net, positions(net));
    expect(r.size).toBe(net.arcs.length);
  });
});
