// The status bar says when the runtime's stores are in trouble (issue 15).
import { describe, expect, it } from 'vitest';
import { StatusBar } from '../src/ui/statusbar';
import type { Connection, Status } from '../src/types';

const status = (over: Partial<Status>): Status => ({
  project: 'tank', state: 'running', fault: null, scan_ms: 10, scans: 5, time_ms: 50,
  stats: { last_us: 1, min_us: 1, max_us: 9, mean_us: 2, jitter_us: 0, overruns: 0 },
  minor_faults: 0, io: 'sim', programs: ['main.lad'], clients: 1, store_ok: true, retain_lost: false, problems: [], forces: [], connections: [],
  ...over,
});

describe('store problems in the status bar', () => {
  it('is hidden while all is well, and names the count, the loss and each message', () => {
    const bar = new StatusBar();
    const store = bar.el.querySelector('[data-testid="status-store"]') as HTMLElement;
    bar.status(status({}));
    expect(store.hidden).toBe(true);
    bar.status(status({
      store_ok: false,
      retain_lost: true,
      problems: [
        { source: 'retain', message: 'retentive data lost: retain.json is not a retain file', since_unix_ms: 1 },
        { source: 'history', message: 'history not recorded: the disk is full', since_unix_ms: 2 },
      ],
    }));
    expect(store.hidden).toBe(false);
    expect(store.textContent).toBe('2 storage problems · retentive data lost');
    expect(store.title).toContain('the disk is full');
    expect(store.getAttribute('role')).toBe('alert');
    bar.status(status({}));
    expect(store.hidden).toBe(true);
  });

  it('says "not live" instead of a frozen run state while stale', () => {
    const bar = new StatusBar();
    const state = bar.el.querySelector('[data-testid="status-state"]') as HTMLElement;
    bar.status(status({}));
    bar.stale(true);
    expect([state.textContent, state.dataset.state]).toEqual(['not live', 'stale']);
    bar.status(status({ state: 'stopped' }));
    expect(state.textContent).toBe('not live');
    bar.stale(false);
    expect([state.textContent, state.dataset.state]).toEqual(['stopped', 'stopped']);
  });
});

describe('client connections in the status bar ([[opcua_server]])', () => {
  const conn = (over: Partial<Connection>): Connection => ({
    name: 'plant', protocol: 'opcua', endpoint: 'opc.tcp://10.0.0.5:4840/', ok: true, connected: true, connects: 1, errors: 0, last_error: null, queue: null, ...over,
  });

  it('shows each connection green when ok, red with the reason when down, amber when bindings are refused', () => {
    const bar = new StatusBar();
    const conns = bar.el.querySelector('[data-testid="status-connections"]') as HTMLElement;
    bar.status(status({}));
    expect(conns.hidden).toBe(true);
    bar.status(status({ connections: [conn({}), conn({ name: 'line2', ok: false, connected: false, last_error: 'cannot connect: BadNotConnected' })] }));
    expect(conns.hidden).toBe(false);
    const plant = bar.el.querySelector('[data-testid="status-remote-plant"]') as HTMLElement;
    const line2 = bar.el.querySelector('[data-testid="status-remote-line2"]') as HTMLElement;
    expect([plant.textContent, plant.dataset.health]).toEqual(['plant', 'ok']);
    expect(plant.title).toBe('plant: connected to opc.tcp://10.0.0.5:4840/');
    expect(line2.dataset.health).toBe('down');
    expect(line2.title).toContain('cannot connect: BadNotConnected');
    bar.status(status({ connections: [conn({ ok: false, last_error: 'input Level (ns=2;s=x): BadNodeIdUnknown' })] }));
    const again = bar.el.querySelector('[data-testid="status-remote-plant"]') as HTMLElement;
    expect(again.dataset.health).toBe('refused');
    expect(again.title).toContain('BadNodeIdUnknown');
    expect(bar.el.querySelector('[data-testid="status-remote-line2"]')).toBeNull();
  });

  it('shows the MQTT broker with its queue counters, amber while Sparkplug holds data for its primary host', () => {
    const bar = new StatusBar();
    const queue = { published: 1200, coalesced: 3, dropped: 0, buffered: 0, replayed: 0, capacity: 10000 };
    bar.status(status({ connections: [conn({ name: 'mqtt', protocol: 'mqtt', endpoint: '10.0.0.5:1883', queue })] }));
    const mqtt = bar.el.querySelector('[data-testid="status-remote-mqtt"]') as HTMLElement;
    expect([mqtt.textContent, mqtt.dataset.health]).toEqual(['mqtt', 'ok']);
    expect(mqtt.title).toBe('mqtt: connected to 10.0.0.5:1883\n1200 published, 3 coalesced, 0 dropped');
    bar.status(status({
      connections: [conn({
        name: 'mqtt', protocol: 'sparkplug', endpoint: '10.0.0.5:1883', ok: false,
        last_error: 'the primary host scada is offline: buffering', queue: { ...queue, buffered: 40, dropped: 2 },
      })],
    }));
    const held = bar.el.querySelector('[data-testid="status-remote-mqtt"]') as HTMLElement;
    expect(held.dataset.health).toBe('refused');
    expect(held.title).toContain('the primary host scada is offline');
    expect(held.title).toContain('1200 published, 3 coalesced, 2 dropped\n40 buffered, 0 replayed');
  });
});

describe('tooltips of the status bar (issue 30, item 23)', () => {
  it('says what each field counts', () => {
    const bar = new StatusBar();
    const tip = (id: string) => (bar.el.querySelector(`[data-testid="status-${id}"]`)!.parentElement as HTMLElement).title;
    expect(tip('scan-last')).toBe('How long the last scan took');
    expect(tip('scan-max')).toBe('The longest scan since the start');
    expect(tip('overruns')).toBe('Scans that took longer than the scan period');
    expect(tip('scans')).toBe('Scans since the start');
    expect(tip('state')).toBe('The state of the PLC (not live: the runtime does not answer)');
    expect(tip('conn')).toBe('The studio’s connection to the runtime');
    expect(tip('user')).toBe('Who uses the studio, and their role');
  });
});
