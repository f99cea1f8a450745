// The WebSocket connection: reconnects with back-off, re-sends the union of
// what every view wants, and dispatches coalesced batches.
import type { Json, ServerMsg, Status } from '../types';
import { Coalescer, backoffDelay, unionSubscription, type Batch } from './coalesce';

export type ConnState = 'connecting' | 'connected' | 'reconnecting';

export class ValueStore {
  private readonly values = new Map<string, Json>();
  private readonly watchers = new Map<string, Set<(v: Json) => void>>();

  static key(name: string): string {
    return name.toUpperCase();
  }

  get(name: string): Json | undefined {
    return this.values.get(ValueStore.key(name));
  }

  /** Calls `cb` with the value now (if known) and on every change; returns the unwatch. */
  watch(name: string, cb: (v: Json) => void): () => void {
    const k = ValueStore.key(name);
    let set = this.watchers.get(k);
    if (!set) this.watchers.set(k, (set = new Set()));
    set.add(cb);
    if (this.values.has(k)) cb(this.values.get(k) as Json);
    return () => {
      set.delete(cb);
      if (set.size === 0) this.watchers.delete(k);
    };
  }

  apply(values: Map<string, Json>): void {
    for (const [name, v] of values) {
      const k = ValueStore.key(name);
      this.values.set(k, v);
      this.watchers.get(k)?.forEach((cb) => cb(v));
    }
  }
}

export class LiveClient {
  readonly store = new ValueStore();
  state: ConnState = 'connecting';
  status: Status | null = null;
  /** When the last message came (ms since the epoch; 0: none yet). */
  lastMessageMs = 0;
  private ws: WebSocket | null = null;
  private attempt = 0;
  private readonly subs = new Map<string, string[] | '*'>();
  private readonly monitors = new Map<string, string[]>();
  private sentSub = '';
  private sentMon = '';
  private readonly coalescer = new Coalescer((b) => this.deliver(b));
  private readonly batchListeners = new Set<(b: Batch) => void>();
  private readonly rawListeners = new Set<(m: ServerMsg) => void>();
  private readonly stateListeners = new Set<(s: ConnState) => void>();
  private closed = false;

  constructor(private readonly url: string = LiveClient.defaultUrl()) {}

  static defaultUrl(): string {
    const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
    return `${proto}//${location.host}/api/ws`;
  }

  connect(): void {
    this.closed = false;
    const ws = new WebSocket(this.url);
    this.ws = ws;
    ws.onopen = () => {
      this.attempt = 0;
      this.sentSub = '';
      this.sentMon = '';
      this.setState('connected');
      this.sync();
    };
    ws.onmessage = (ev) => {
      this.lastMessageMs = Date.now();
      let msg: ServerMsg;
      try {
        msg = JSON.parse(String(ev.data));
      } catch {
        return;
      }
      this.rawListeners.forEach((f) => f(msg));
      this.coalescer.push(msg);
    };
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      if (this.closed) return;
      this.setState('reconnecting');
      setTimeout(() => this.connect(), backoffDelay(this.attempt++));
    };
    ws.onerror = () => ws.close();
  }

  close(): void {
    this.closed = true;
    this.ws?.close();
  }

  /** Declares what the view `key` wants to receive (replacing its previous wish). */
  subscribe(key: string, names: string[] | '*' | null): void {
    if (names === null) this.subs.delete(key);
    else this.subs.set(key, names);
    this.sync();
  }

  monitor(key: string, programs: string[] | null): void {
    if (programs === null) this.monitors.delete(key);
    else this.monitors.set(key, programs);
    this.sync();
  }

  /** Listens to the coalesced batches (after the value store is updated). */
  onBatch(f: (b: Batch) => void): () => void {
    this.batchListeners.add(f);
    return () => this.batchListeners.delete(f);
  }

  /** Applies a batch: the value store first, then the listeners. */
  deliver(b: Batch): void {
    this.store.apply(b.values);
    if (b.status) this.status = b.status;
    this.batchListeners.forEach((f) => f(b));
  }

  onRaw(f: (m: ServerMsg) => void): () => void {
    this.rawListeners.add(f);
    return () => this.rawListeners.delete(f);
  }

  onState(f: (s: ConnState) => void): () => void {
    this.stateListeners.add(f);
    f(this.state);
    return () => this.stateListeners.delete(f);
  }

  private setState(s: ConnState): void {
    this.state = s;
    this.stateListeners.forEach((f) => f(s));
  }

  private sync(): void {
    const ws = this.ws;
    if (!ws || ws.readyState !== WebSocket.OPEN) return;
    const sub = JSON.stringify({ subscribe: unionSubscription(this.subs.values()) });
    if (sub !== this.sentSub) {
      ws.send(sub);
      this.sentSub = sub;
    }
    const programs = [...new Set([...this.monitors.values()].flat())].sort();
    const mon = JSON.stringify({ monitor: programs });
    if (mon !== this.sentMon) {
      ws.send(mon);
      this.sentMon = mon;
    }
  }
}
