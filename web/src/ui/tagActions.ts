// Writing, toggling and forcing a tag from a menu (ladder elements).
import { ApiError, api } from '../api';
import { can, why } from '../auth';
import type { Ctx } from '../ctx';
import type { Json } from '../types';
import type { MenuItem } from './menu';
import { tr } from '../i18n';

async function act(ctx: Ctx, what: Promise<unknown>, forces: boolean): Promise<void> {
  try {
    await what;
    if (forces) await ctx.tags.refreshForces();
  } catch (e) {
    ctx.notify(e instanceof ApiError ? e.message : String(e), 'error');
  }
}

/** Parses what a user typed for a tag of `type` (numbers as numbers, BOOL as true/false). */
export function parseValue(type: string, text: string): Json {
  const t = text.trim();
  if (type === 'BOOL') {
    if (/^(1|true|on)$/i.test(t)) return true;
    if (/^(0|false|off)$/i.test(t)) return false;
  }
  if (t !== '' && !Number.isNaN(Number(t))) return Number(t);
  return t;
}

/** Menu items for one operand; `suffix` (e.g. "-Start") tells apart several operands of one box. */
export function tagMenuItems(ctx: Ctx, operand: string, suffix = ''): MenuItem[] {
  const ref = ctx.tags.resolve(operand);
  if (!ref) return [];
  const items: MenuItem[] = [];
  const name = ref.name;
  const label = suffix ? ` ${name}` : '';
  const isForced = ctx.tags.forced.has(name.toUpperCase());
  // what the role may not do is listed disabled, saying why
  const force = { disabled: !can('force'), title: why('force') };
  const write = { disabled: !can('write'), title: why('write') };
  if (ref.io) {
    if (ref.type === 'BOOL') {
      items.push({ label: tr('Force ON') + label, testid: `menu-force-on${suffix}`, ...force, action: () => void act(ctx, api.force(name, true), true) });
      items.push({ label: tr('Force OFF') + label, testid: `menu-force-off${suffix}`, ...force, action: () => void act(ctx, api.force(name, false), true) });
    } else {
      items.push({
        label: tr('Force value…') + label,
        testid: `menu-force-value${suffix}`,
        ...force,
        action: () => {
          const v = prompt(tr('Force {name} ({type}) to:', { name, type: ref.type }));
          if (v !== null) void act(ctx, api.force(name, parseValue(ref.type, v)), true);
        },
      });
    }
    items.push({ label: tr('Unforce') + label, testid: `menu-unforce${suffix}`, disabled: !isForced || force.disabled, title: force.title, action: () => void act(ctx, api.unforce(name), true) });
  }
  if (ref.access === 'readwrite' && ref.type === 'BOOL' && !ref.io) {
    items.push({
      label: tr('Toggle') + label,
      testid: `menu-toggle${suffix}`,
      ...write,
      action: () => void act(ctx, api.writeTag(name, !(ctx.live.store.get(name) === true)), false),
    });
  }
  if (ref.access === 'readwrite' && ref.type !== 'BOOL') {
    items.push({
      label: tr('Set value…') + label,
      testid: `menu-set-value${suffix}`,
      ...write,
      action: () => {
        const v = prompt(tr('New value of {name} ({type}):', { name, type: ref.type }), String(ctx.live.store.get(name) ?? ''));
        if (v !== null) void act(ctx, api.writeTag(name, parseValue(ref.type, v)), false);
      },
    });
  }
  return items;
}
