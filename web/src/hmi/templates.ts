// Templates (issue 35, point 5): a user symbol (hmi/symbols/<name>.json) whose
// tags share a first name — `Pump1`, or `Pump1.Running`, `Pump1.Speed` — is a
// template; an instance is a group of copies of its elements with that prefix
// replaced by the instance's own (`Pump2.*`). Each copy carries
// `props.template` (the symbol), `props.prefix` (its prefix) and `props.part`
// (the template element it copies), so the screen stays a plain screen the
// server checks tag by tag, and the designer rebuilds an instance from its
// template when the template changes (on opening, and after Save as symbol),
// and Save as symbol rebuilds and saves the instances on the other saved
// screens too ([`rebuildAll`]).
import type { Json } from '../types';
import { freshId } from './edit';
import type { Element, Screen } from './render';

/** The tag names an element names: its shown tag, `*_tag` properties, its animations' and its action's tags. */
function tagRefs(e: Element): { get: () => string; set: (v: string) => void }[] {
  const out: { get: () => string; set: (v: string) => void }[] = [];
  const props = e.props ?? {};
  for (const k of Object.keys(props))
    if ((k === 'tag' || k.endsWith('_tag')) && typeof props[k] === 'string') out.push({ get: () => props[k] as string, set: (v) => (props[k] = v) });
  for (const a of e.animations ?? []) if (typeof a.tag === 'string' && a.tag) out.push({ get: () => a.tag, set: (v) => (a.tag = v) });
  const act = e.action;
  if (act && typeof act.tag === 'string' && act.tag) out.push({ get: () => act.tag as string, set: (v) => (act.tag = v) });
  return out;
}

/** Every tag the elements name. */
export function tagsOf(els: Element[]): string[] {
  return els.flatMap((e) => tagRefs(e).map((r) => r.get()));
}

/** The first name every tag of `els` shares (`Pump1` of `Pump1.Running`), or null when they have none or differ. */
export function prefixOf(els: Element[]): string | null {
  const firsts = new Set(tagsOf(els).map((t) => t.split('.')[0]));
  return firsts.size === 1 ? [...firsts][0] : null;
}

/** `name` with the prefix `from` replaced by `to` (the whole name, or its first part before a dot). */
export function retag(name: string, from: string, to: string): string {
  if (name === from) return to;
  return name.startsWith(`${from}.`) ? `${to}${name.slice(from.length)}` : name;
}

/** A prefix is a tag's name or a path of them: letters, digits, `_`, dots between. */
export const isPrefix = (p: string): boolean => /^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$/.test(p);

/**
 * The elements of an instance of `template` (named `name`) with `prefix`, its
 * box's top-left at (x, y), in the group `group`: fresh ids, or the ids of
 * `keep` (template part → id) for the parts an instance already had.
 */
export function instantiate(screen: Screen, template: Screen, name: string, prefix: string, x: number, y: number, group: string, keep: Map<string, string> = new Map()): Element[] {
  const from = prefixOf(template.elements);
  const taken = new Set(keep.values());
  return template.elements.map((t) => {
    const c = structuredClone(t);
    const kept = keep.get(t.id);
    c.id = kept ?? freshId(screen, t.type, taken);
    taken.add(c.id);
    c.x += x;
    c.y += y;
    c.group = group;
    if (from) for (const r of tagRefs(c)) r.set(retag(r.get(), from, prefix));
    c.props = { ...c.props, template: name, prefix, part: t.id } as Record<string, Json>;
    return c;
  });
}

/** An instance on a screen: its group, template, prefix, and top-left. */
export interface Instance {
  group: string;
  template: string;
  prefix: string;
  x: number;
  y: number;
}

/** The instances on `screen` (groups whose elements all name the same template and prefix). */
export function instancesOf(screen: Screen): Instance[] {
  const groups = new Map<string, Element[]>();
  for (const e of screen.elements) if (e.group && typeof e.props?.template === 'string') groups.set(e.group, [...(groups.get(e.group) ?? []), e]);
  const out: Instance[] = [];
  for (const [group, els] of groups) {
    const all = screen.elements.filter((e) => e.group === group);
    const { template, prefix } = els[0].props as { template: string; prefix: unknown };
    if (all.length !== els.length || typeof prefix !== 'string' || !els.every((e) => e.props?.template === template && e.props?.prefix === prefix)) continue;
    out.push({ group, template, prefix, x: Math.min(...els.map((e) => e.x)), y: Math.min(...els.map((e) => e.y)) });
  }
  return out;
}

/**
 * Rebuilds the instance `inst` from `template` with `prefix` (its own, or a
 * new one), in place in the drawing order; whether anything changed.
 */
export function rebuild(screen: Screen, inst: Instance, template: Screen, prefix = inst.prefix): boolean {
  const old = screen.elements.filter((e) => e.group === inst.group);
  const keep = new Map(old.filter((e) => typeof e.props?.part === 'string').map((e) => [e.props!.part as string, e.id]));
  const rest: Screen = { ...screen, elements: screen.elements.filter((e) => e.group !== inst.group) };
  const next = instantiate(rest, template, inst.template, prefix, inst.x, inst.y, inst.group, keep);
  if (JSON.stringify(next) === JSON.stringify(old)) return false;
  const at = screen.elements.findIndex((e) => e.group === inst.group);
  screen.elements = [...rest.elements.slice(0, at), ...next, ...rest.elements.slice(at)];
  return true;
}

/** Every instance of the template `name` on `screen` rebuilt from `template`; how many changed. */
export function rebuildAll(screen: Screen, name: string, template: Screen): number {
  return instancesOf(screen).filter((i) => i.template === name && rebuild(screen, i, template)).length;
}
