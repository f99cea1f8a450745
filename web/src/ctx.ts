// What every view shares: the live connection, the tag definitions and
// notifications. (The language itself — types, members, instructions — is
// in domain.ts.)
import { api } from './api';
import { argInfo, membersOf } from './domain';
import type { LiveClient } from './live/client';
import type { Force, Json, TagInfo } from './types';

export interface TagRef {
  /** The canonical name to read, write, force or subscribe. */
  name: string;
  type: string;
  access: 'readwrite' | 'input' | 'readonly';
  /** The tag is on an I/O address (can be forced). */
  io: boolean;
  tag: TagInfo | null;
}

/** An address as the index of notations keys it: upper case, numbers without leading zeros. */
export function addressKey(text: string): string {
  return text.trim().toUpperCase().replace(/\d+/g, (d) => String(Number(d)));
}

export class TagCache {
  list: TagInfo[] = [];
  forced = new Map<string, Json>();
  private byName = new Map<string, TagInfo>();
  private byAddr = new Map<string, TagInfo>();
  private readonly listeners = new Set<() => void>();

  async refresh(): Promise<void> {
    const [tags, forces] = await Promise.all([api.tags(), api.forces().catch(() => [])]);
    this.set(tags, forces);
  }

  /** The last list's tags and forces without their values: a refresh that changes nothing else redraws nothing. */
  private shape = '';

  /**
   * Uses these tags and forces (as GET /api/tags and /api/forces answer). The
   * listeners hear of it only when more than the values changed: the live
   * values come over the WebSocket, and a view redrawn for nothing loses the
   * row under the user's finger (a long press) or the cell being watched.
   */
  set(tags: TagInfo[], forces: Force[] = []): void {
    const shape = JSON.stringify([tags.map(({ value: _v, ...rest }) => rest), forces]);
    const changed = shape !== this.shape;
    this.shape = shape;
    this.list = tags;
    this.byName = new Map(tags.map((t) => [t.name.toUpperCase(), t]));
    // every notation of each tag's address (DI:1/5, %IX0.5, I0.5 …), as the server lists them
    this.byAddr = new Map(tags.flatMap((t) => [t.address ?? '', ...(t.notations ?? [])].filter(Boolean).map((a) => [addressKey(a), t])));
    this.forced = new Map(forces.map((f) => [f.name.toUpperCase(), f.value]));
    if (changed) this.listeners.forEach((f) => f());
  }

  async refreshForces(): Promise<void> {
    const forces = await api.forces();
    this.forced = new Map(forces.map((f) => [f.name.toUpperCase(), f.value]));
    this.listeners.forEach((f) => f());
  }

  onChange(f: () => void): () => void {
    this.listeners.add(f);
    return () => this.listeners.delete(f);
  }

  get(name: string): TagInfo | undefined {
    return this.byName.get(name.toUpperCase());
  }

  /** What an operand names: a tag, a member of one, or the tag on an address. */
  resolve(operand: string): TagRef | null {
    const op = operand.trim();
    const t = this.byName.get(op.toUpperCase()) ?? this.byAddr.get(addressKey(op));
    if (t) return { name: t.name, type: t.type, access: t.access, io: !!t.address && t.access !== 'readonly', tag: t };
    const dot = op.lastIndexOf('.');
    if (dot > 0) {
      const base = this.byName.get(op.slice(0, dot).toUpperCase());
      const member = op.slice(dot + 1).toUpperCase();
      const m = base && membersOf(base.type).find((x) => x.name === member);
      if (base && m) {
        return { name: `${base.name}.${m.name}`, type: m.type, access: m.writable ? 'readwrite' : 'readonly', io: false, tag: null };
      }
    }
    return null;
  }

  /** Names for the tag picker, for an argument kind of the domain (every tag for an unknown kind). */
  choices(kind: string): string[] {
    const arg = argInfo(kind);
    if (!arg) return this.list.map((t) => t.name);
    const fits = (type: string, writable: boolean) => arg.types.includes(type) && (writable || !arg.writable);
    const out: string[] = [];
    for (const t of this.list) {
      if (fits(t.type, t.access === 'readwrite')) out.push(t.name);
      if (arg.members) for (const m of membersOf(t.type)) if (fits(m.type, m.writable)) out.push(`${t.name}.${m.name}`);
    }
    return out;
  }
}

export interface Ctx {
  live: LiveClient;
  tags: TagCache;
  /** A toast; one with the `key` of an earlier one replaces it. */
  notify(message: string, kind?: 'info' | 'error', key?: string): void;
}
