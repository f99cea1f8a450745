// Is what the studio shows live? One answer for every view (issue 16): the
// page's `data-live` attribute, which the style sheet turns into grey, hatched
// live elements and a banner saying since when — so a view added later
// cannot forget to look stale.
import type { Status } from '../types';
import type { ConnState } from './client';

export type Freshness = 'live' | 'stale' | 'stopped' | 'faulted';

/** A running runtime sends its status at least every 0.5 s; this much silence is stale. */
export const SILENCE_MS = 3000;

/**
 * What the screen shows, from the connection, the last status and the time
 * of the last message: `stale` when the connection is down or silent,
 * else the runtime's state (`stopped` and `faulted` values do not move).
 */
export function freshness(conn: ConnState, status: Status | null, lastMessageMs: number, nowMs: number): Freshness {
  if (conn !== 'connected') return 'stale';
  if (status?.state === 'stopped') return 'stopped';
  if (status?.state === 'faulted') return 'faulted';
  if (nowMs - lastMessageMs > SILENCE_MS) return 'stale';
  return 'live';
}
