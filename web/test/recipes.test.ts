// The Recipes tab (issue 35, item 6): the tags a recipe's CSV names (what the
// confirmation lists and a capture reads), its CSV from the server's JSON,
// and the names the server takes.
import { describe, expect, it } from 'vitest';
import { ApiError } from '../src/api';
import { recipeCsv, recipeName, recipeTags, refusedNote } from '../src/ui/recipesView';

describe('recipes', () => {
  it('lists the tags of a CSV in order, without header, comments or blank lines', () => {
    expect(recipeTags('tag,value\nSetpoint,250\n\n# note\nMode,true\r\n"Name","a, b"\n')).toEqual(['Setpoint', 'Mode', 'Name']);
    expect(recipeTags('Speed,3\nTag,value\n'), 'a header only first').toEqual(['Speed', 'Tag']);
    expect(recipeTags('')).toEqual([]);
  });

  it('writes the entries as the file holds them, and reads them back', () => {
    const csv = recipeCsv({ Setpoint: 250, Ratio: 0.75, Mode: true, Name: 'say "hi", twice' });
    expect(csv).toBe('tag,value\nSetpoint,250\nRatio,0.75\nMode,true\nName,"say ""hi"", twice"\n');
    expect(recipeTags(csv)).toEqual(['Setpoint', 'Ratio', 'Mode', 'Name']);
  });

  it('takes the names the server takes', () => {
    expect(recipeName('batch-A_2')).toBe(true);
    for (const bad of ['', 'a b', '../x', 'x.csv', 'x'.repeat(65)]) expect(recipeName(bad)).toBe(false);
  });

  it('says a refused apply wrote nothing, and nothing of an apply whose outcome is unknown', () => {
    expect(refusedNote(new ApiError(422, 'row 2 (`Away.PRE`): …'))).toBe('Not applied: nothing written');
    expect(refusedNote(new ApiError(503, 'busy'))).toBe('');
    expect(refusedNote(new Error('network'))).toBe('');
  });
});
