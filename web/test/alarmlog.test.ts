// The alarm log page (issue 17, item 7): the server's CSV parsed and filtered.
import { describe, expect, it } from 'vitest';
import { logRows, parseCsv, reportUrl } from '../src/ui/alarmLog';

const CSV =
  'id,time_ms,time_utc,alarm,tag,from,to,value,severity,user,comment,message\r\n' +
  '1,1000,1970-01-01T00:00:01Z,level_hi,Nivel_L,normal,active_unacked,56.2,700,,,"Tank above 55 L, check"\r\n' +
  '2,2000,1970-01-01T00:00:02Z,level_hi,Nivel_L,active_unacked,active_acked,56.4,700,ana,"said ""ok""",Tank above 55 L\r\n' +
  '3,3000,1970-01-01T00:00:03Z,estop,STOP,normal,active_unacked,1,1000,,,"two\nlines"\r\n';

describe('the alarm log', () => {
  it('parses quoted fields, doubled quotes, commas and line breaks inside quotes', () => {
    const rows = parseCsv(CSV);
    expect(rows.length).toBe(4);
    expect(rows[1][11]).toBe('Tank above 55 L, check');
    expect(rows[2][10]).toBe('said "ok"');
    expect(rows[3][11]).toBe('two\nlines');
    expect(parseCsv('a,b\nc,')).toEqual([['a', 'b'], ['c', '']]);
  });

  it('filters by alarm, tag, state, user and comment', () => {
    expect(logRows(CSV, '').map((r) => r.id)).toEqual(['1', '2', '3']);
    expect(logRows(CSV, 'ANA').map((r) => r.id)).toEqual(['2']);
    expect(logRows(CSV, 'stop').map((r) => r.id)).toEqual(['3']);
    expect(logRows(CSV, 'active_acked').map((r) => [r.id, r.user, r.comment])).toEqual([['2', 'ana', 'said "ok"']]);
    expect(logRows('', 'x')).toEqual([]);
  });

  it('links the shift report of the range, or nothing for a range that is not one', () => {
    expect(reportUrl('xlsx', 1000.4, 2000.2)).toBe('/api/reports/shift.xlsx?from=1000&to=2001');
    expect(reportUrl('pdf', 5, 5)).toBe('/api/reports/shift.pdf?from=5&to=5');
    expect(reportUrl('xlsx', NaN, 5)).toBeNull();
    expect(reportUrl('xlsx', 10, 5)).toBeNull();
  });
});
