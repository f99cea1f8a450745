// The function keys of the SLC 500 thesis's PID monitor (source 004, §5.3: its
// Turbo Vision menu and status line), on the faceplate and the trends:
//   F1  the PID control view (trend of SP, PV and CV)     F3  auto ⇄ manual (↑ ↓ move CV in manual)
//   F5  the tank alone                                     F6  the tank and the time response together
//   F8  the loop's alarms in service                       F9  the loop's alarms out of service
//   Ctrl+F6  the trend's Y maximum   Ctrl+F7  its Y minimum   Ctrl+F8  the time shown
// Pure functions (tested in test/fkeys.test.ts); the views act on what they return.

export type FaceplateAction = 'control' | 'mode' | 'tank' | 'combined' | 'alarms-on' | 'alarms-off' | 'up' | 'down';
export type TrendAction = 'y-max' | 'y-min' | 'window';

interface KeyLike {
  key: string;
  ctrlKey?: boolean;
  altKey?: boolean;
  metaKey?: boolean;
  shiftKey?: boolean;
}

const plain = (e: KeyLike) => !e.ctrlKey && !e.altKey && !e.metaKey && !e.shiftKey;

/** The faceplate's action for a key, or null (the key is not the faceplate's). */
export function faceplateKey(e: KeyLike): FaceplateAction | null {
  if (!plain(e)) return null;
  switch (e.key) {
    case 'F1':
      return 'control';
    case 'F3':
      return 'mode';
    case 'F5':
      return 'tank';
    case 'F6':
      return 'combined';
    case 'F8':
      return 'alarms-on';
    case 'F9':
      return 'alarms-off';
    case 'ArrowUp':
      return 'up';
    case 'ArrowDown':
      return 'down';
    default:
      return null;
  }
}

/** The trends' action for a key (Ctrl+F6, Ctrl+F7, Ctrl+F8), or null. */
export function trendKey(e: KeyLike): TrendAction | null {
  if (!e.ctrlKey || e.altKey || e.metaKey || e.shiftKey) return null;
  return e.key === 'F6' ? 'y-max' : e.key === 'F7' ? 'y-min' : e.key === 'F8' ? 'window' : null;
}

/** What the faceplate shows for a view key: the trend, the tank, or both. */
export function faceplateParts(view: 'control' | 'tank' | 'combined'): { trend: boolean; tank: boolean } {
  return { trend: view !== 'tank', tank: view !== 'control' };
}

/** The tank's fill (0–1) for PV on the scale lo–hi, clamped. */
export function tankFill(pv: number, lo: number, hi: number): number {
  if (!(hi > lo) || !Number.isFinite(pv)) return 0;
  return Math.max(0, Math.min(1, (pv - lo) / (hi - lo)));
}

/**
 * A new Y limit for the pens of the trend: `which` bound set to `value`, the other kept
 * (or taken from `shown`, the scale drawn now, when the pen's scale is automatic). Null
 * when the result would not be a scale (min not below max, not a number).
 */
export function withYLimit<P extends { min: number | null; max: number | null }>(
  pens: P[],
  which: 'min' | 'max',
  value: number,
  shown: [number, number],
): P[] | null {
  if (!Number.isFinite(value)) return null;
  const out = pens.map((p) => {
    const lo = which === 'min' ? value : (p.min ?? shown[0]);
    const hi = which === 'max' ? value : (p.max ?? shown[1]);
    return { ...p, min: lo, max: hi };
  });
  return out.every((p) => (p.min as number) < (p.max as number)) ? out : null;
}

/** Seconds typed for Ctrl+F8 as a window in ms (1 s to 7 days), or null. */
export function windowMs(text: string): number | null {
  const s = Number(text.trim().replace(',', '.'));
  if (!Number.isFinite(s) || s < 1 || s > 7 * 86400) return null;
  return Math.round(s * 1000);
}
