// One rule for whether the screen is live (issue 16).
import { describe, expect, it } from 'vitest';
import { SILENCE_MS, freshness } from '../src/live/freshness';
import type { Status } from '../src/types';

const st = (state: Status['state']) => ({ state }) as Status;

describe('freshness', () => {
  it('is stale while disconnected, whatever the last status said', () => {
    expect(freshness('reconnecting', st('running'), 1000, 1001)).toBe('stale');
    expect(freshness('connecting', null, 0, 0)).toBe('stale');
  });
  it('follows the runtime while connected', () => {
    expect(freshness('connected', st('running'), 1000, 1500)).toBe('live');
    expect(freshness('connected', st('stopped'), 1000, 1500)).toBe('stopped');
    expect(freshness('connected', st('faulted'), 1000, 1500)).toBe('faulted');
  });
  it('is stale when a running runtime goes silent', () => {
    expect(freshness('connected', st('running'), 1000, 1000 + SILENCE_MS)).toBe('live');
    expect(freshness('connected', st('running'), 1000, 1001 + SILENCE_MS)).toBe('stale');
    // A stopped runtime sends nothing new: that is not staleness.
    expect(freshness('connected', st('stopped'), 1000, 100_000)).toBe('stopped');
  });
});
