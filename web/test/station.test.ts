// The operator station (issue 35, point 8): which theme a browser starts in,
// when the studio starts in kiosk, which views a kiosk shows, and who may
// leave it (the server's answer about the session, read here).
import { describe, expect, it } from 'vitest';
import { kioskRoute, kioskWanted, mayLeaveKiosk, storedTheme } from '../src/ui/station';

describe('operator station', () => {
  it('starts in the remembered theme, else the system preference', () => {
    expect(storedTheme('dark', false)).toBe('dark');
    expect(storedTheme('light', true)).toBe('light');
    expect(storedTheme(null, true)).toBe('dark');
    expect(storedTheme('purple', false), 'an unknown value is not a theme').toBe('light');
  });

  it('starts in kiosk with ?kiosk=1 or when remembered', () => {
    expect(kioskWanted('?kiosk=1', null)).toBe(true);
    expect(kioskWanted('?x=2&kiosk=true', null)).toBe(true);
    expect(kioskWanted('', '1')).toBe(true);
    expect(kioskWanted('', null)).toBe(false);
    expect(kioskWanted('?kiosk=0', null)).toBe(false);
    // ?kiosk=0 does not leave a remembered kiosk: only an engineer does
    expect(kioskWanted('?kiosk=0', '1')).toBe(true);
  });

  it('keeps a kiosk on the screens and the alarms', () => {
    expect(kioskRoute('alarms')).toBe('alarms');
    expect(kioskRoute('screens')).toBe('screens');
    expect(kioskRoute('program/main')).toBe('screens');
    expect(kioskRoute('recipes')).toBe('screens');
    expect(kioskRoute('')).toBe('screens');
  });

  it('lets an engineer or an admin leave, or anyone in a studio without users', () => {
    expect(mayLeaveKiosk({ user: 'olga', role: 'operator', users: true })).toBe(false);
    expect(mayLeaveKiosk({ user: 'vic', role: 'viewer', users: true })).toBe(false);
    expect(mayLeaveKiosk({ user: 'eric', role: 'engineer', users: true })).toBe(true);
    expect(mayLeaveKiosk({ user: 'ada', role: 'admin', users: true })).toBe(true);
    expect(mayLeaveKiosk({ user: null, role: 'admin', users: false })).toBe(true);
  });
});
