// What every view shares: the live connection, the tag definitions, the
// instruction table, and notifications.
import { apiAddress } from './address';
import { api } from './api';
import type { LiveClient } from './live/client';
import type { Instruction, Json, TagInfo } from './types';

export interface TagRef {
  /** The canonical name to read, write, force or subscribe. */
  name: string;
  type: string;
  access: 'readwrite' | 'input' | 'readonly';
  /** The tag is on an I/O address (can be forced). */
  io: boolean;
  tag: TagInfo | null;
}

const MEMBERS: Record<string, Record<string, string>> = {
  TIMER: { PRE: 'DINT', ACC: 'DINT', EN: 'BOOL', TT: 'BOOL', DN: 'BOOL' },
  COUNTER: { PRE: 'DINT', ACC: 'DINT', CU: 'BOOL', CD: 'BOOL', DN: 'BOOL', OV: 'BOOL', UN: 'BOOL' },
};

export class TagCache {
  list: TagInfo[] = [];
  forced = new Map<string, Json>();
  private byName = new Map<string, TagInfo>();
  private byAddr = new Map<string, TagInfo>();
  private readonly listeners = new Set<() => void>();

  async refresh(): Promise<void> {
    const [tags, forces] = await Promise.all([api.tags(), api.forces().catch(() => [])]);
    this.list = tags;
    this.byName = new Map(tags.map((t) => [t.name.toUpperCase(), t]));
    this.byAddr = new Map(tags.filter((t) => t.address).map((t) => [t.address!.toUpperCase(), t]));
    this.forced = new Map(forces.map((f) => [f.name.toUpperCase(), f.value]));
    this.listeners.forEach((f) => f());
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
    const t = this.byName.get(op.toUpperCase()) ?? this.byAddr.get(apiAddress(op));
    if (t) return { name: t.name, type: t.type, access: t.access, io: !!t.address && t.access !== 'readonly', tag: t };
    const dot = op.lastIndexOf('.');
    if (dot > 0) {
      const base = this.byName.get(op.slice(0, dot).toUpperCase());
      const member = op.slice(dot + 1).toUpperCase();
      const ty = base && MEMBERS[base.type]?.[member];
      if (base && ty) {
        return { name: `${base.name}.${member}`, type: ty, access: ty === 'BOOL' ? 'readonly' : 'readwrite', io: false, tag: null };
      }
    }
    return null;
  }

  /** Names for the tag picker, for an argument kind of /api/instructions. */
  choices(kind: string): string[] {
    const out: string[] = [];
    const numeric = (ty: string) => ['SINT', 'INT', 'DINT', 'LINT', 'REAL', 'LREAL', 'TIME'].includes(ty);
    for (const t of this.list) {
      const writable = t.access === 'readwrite';
      const members = MEMBERS[t.type];
      switch (kind) {
        case 'bit_in':
          if (t.type === 'BOOL') out.push(t.name);
          if (members) for (const [m, ty] of Object.entries(members)) if (ty === 'BOOL') out.push(`${t.name}.${m}`);
          break;
        case 'bit_out':
          if (t.type === 'BOOL' && writable) out.push(t.name);
          break;
        case 'timer':
          if (t.type === 'TIMER') out.push(t.name);
          break;
        case 'counter':
          if (t.type === 'COUNTER') out.push(t.name);
          break;
        case 'timer_or_counter':
          if (members) out.push(t.name);
          break;
        case 'num_in':
        case 'preset':
          if (numeric(t.type)) out.push(t.name);
          if (members) out.push(`${t.name}.PRE`, `${t.name}.ACC`);
          break;
        case 'num_out':
          if (numeric(t.type) && writable) out.push(t.name);
          if (members) out.push(`${t.name}.PRE`, `${t.name}.ACC`);
          break;
        default:
          out.push(t.name);
      }
    }
    return out;
  }
}

export interface Ctx {
  live: LiveClient;
  tags: TagCache;
  instructions: Instruction[];
  notify(message: string, kind?: 'info' | 'error'): void;
}
