import { describe, expect, it } from 'vitest';
import { liveTags, newPen, parsePen, penId, penKey, remotePens } from '../src/trends/pens';

describe('pens of other nodes', () => {
  it('names a pen Tag, or Tag@node for another node', () => {
    expect(penId({ tag: 'Level' })).toBe('Level');
    expect(penId({ tag: 'Level', node: 'line-2' })).toBe('Level@line-2');
  });

  it('keys live buffers by tag case-insensitively, by node exactly', () => {
    expect(penKey({ tag: 'level' })).toBe(penKey({ tag: 'LEVEL' }));
    expect(penKey({ tag: 'level', node: 'L2' })).toBe('LEVEL@L2');
    expect(penKey({ tag: 'level', node: 'L2' })).not.toBe(penKey({ tag: 'level', node: 'l2' }));
    expect(penKey({ tag: 'level', node: 'L2' })).not.toBe(penKey({ tag: 'level' }));
  });

  it('reads what the user asked for: Tag@node, the picked node, or this runtime', () => {
    expect(parsePen(' Level ', '', 'line-1')).toEqual({ tag: 'Level' });
    expect(parsePen('Level', 'line-2', 'line-1')).toEqual({ tag: 'Level', node: 'line-2' });
    expect(parsePen('Flow@line-3', 'line-2', 'line-1')).toEqual({ tag: 'Flow', node: 'line-3' });
    // this runtime's own node id is no other node
    expect(parsePen('Flow@line-1', '', 'line-1')).toEqual({ tag: 'Flow' });
    expect(parsePen('Flow', 'line-1', 'line-1')).toEqual({ tag: 'Flow' });
    // a node id may hold an @: the last one separates
    expect(parsePen('S:FAULT@cell@7', '', 'x')).toEqual({ tag: 'S:FAULT@cell', node: '7' });
    expect(parsePen('@line-2', '', 'x')).toEqual({ tag: '@line-2' });
  });

  it('subscribes live only to this runtime\'s tags', () => {
    const pens = [newPen({ tag: 'A' }), newPen({ tag: 'B', node: 'n2' }), newPen({ tag: 'C' })];
    expect(liveTags(pens)).toEqual(['A', 'C']);
    expect(remotePens(pens).map(penId)).toEqual(['B@n2']);
    expect(pens[1]).toEqual({ tag: 'B', node: 'n2', axis: 1, min: null, max: null });
    expect('node' in pens[0]).toBe(false);
  });
});
