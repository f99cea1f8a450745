import { describe, expect, it } from 'vitest';
import { ilOperands, parseIl, powerByLine, stripComments } from '../src/il/parse';

describe('IL operands', () => {
  it('takes the places after the mnemonic, not constants or comments', () => {
    expect(ilOperands(stripComments('LD    I0.1        // platform at position 1').code)).toEqual({ mnemonic: 'LD', operands: ['I0.1'] });
    expect(ilOperands('S     Q0.0, 1').operands).toEqual(['Q0.0']);
    expect(ilOperands('MOVW  AIW0, VW100').operands).toEqual(['AIW0', 'VW100']);
    expect(ilOperands('AW<   195, MW3').operands).toEqual(['MW3']);
    expect(ilOperands('TON   T37, T#5s').operands).toEqual(['T37']);
    expect(ilOperands('ALD').operands).toEqual([]);
    expect(ilOperands('NETWORK 2').mnemonic).toBeNull();
  });
  it('keeps quoted symbols whole, even with // inside', () => {
    expect(ilOperands(stripComments('LDN "Stop Button" // stop').code)).toEqual({ mnemonic: 'LDN', operands: ['Stop Button'] });
    expect(stripComments('= "a//b" // c').code.trim()).toBe('= "a//b"');
  });
  it('follows /* */ comments across lines', () => {
    const lines = parseIl('LD I0.0 /* x\nA I0.1\n*/ = Q0.0\n');
    expect(lines.map((l) => [l.mnemonic, l.operands])).toEqual([['LD', ['I0.0']], [null, []], ['=', ['Q0.0']], [null, []]]);
  });
});

describe('IL power', () => {
  it('lights the lines whose id is on', () => {
    const m = powerByLine([{ line: 3, id: 7 }, { line: 4, id: 8 }, { line: 5, id: null }], [8]);
    expect([...m]).toEqual([[3, false], [4, true], [5, false]]);
  });
});
