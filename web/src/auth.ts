// Who is using the studio and what they may do. The server decides (every route
// checks the role, docs/api.md); this is the one place where the studio decides
// what to show enabled: views ask `can(action)` and, for a control the role may
// not use, `why(action)` gives the tooltip ("needs the engineer role").
//
// Roles, each including the one before: viewer < operator < engineer < admin.
// The session itself is the server's HttpOnly cookie: no token is kept here.

import type { Me, Role } from './api.gen';
import { domain } from './domain';
import { tr } from './i18n';

// The shapes of GET /api/me, generated from the server's reply types.
export type { Me, Role };
export const ROLES: readonly Role[] = ['viewer', 'operator', 'engineer', 'admin'];

/** A role's name as people read it (the API's names are the English ones). */
export function roleName(role: Role): string {
  return ({ viewer: tr('viewer'), operator: tr('operator'), engineer: tr('engineer'), admin: tr('admin') } as Record<Role, string>)[role] ?? role;
}

/**
 * What the studio can ask the server to do, by the role each needs (the route
 * table of docs/api.md):
 * - `write`: write a tag that is not an input (PUT /api/tags/{name}),
 * - `force`: force or unforce I/O (PUT/DELETE /api/forces…),
 * - `edit`: edit, check and save a program (POST /api/check, PUT /api/programs),
 * - `tags`: change the tag table (PUT /api/tags.csv),
 * - `runstop`: run or stop the PLC (POST /api/run, /api/stop),
 * - `audit`: read the audit trail (GET /api/audit),
 * - `ack`: acknowledge an alarm (POST /api/alarms/{id}/ack),
 * - `browse`: browse a remote OPC UA server (GET /api/opcua/{server}/browse),
 * - `hardware`: change the board, build firmware, download to a board (/api/hardware…),
 * - `recipe`: save or capture a recipe (PUT /api/recipes/{name}),
 * - `apply`: apply a recipe (POST /api/recipes/{name}/apply),
 * - `users`: manage users.
 */
export type Action = 'write' | 'force' | 'edit' | 'tags' | 'runstop' | 'audit' | 'ack' | 'browse' | 'hardware' | 'recipe' | 'apply' | 'users';

/** The route each action is (the server's role table decides its role). */
const ROUTE: Record<Action, [method: string, route: string]> = {
  write: ['PUT', '/api/tags/{name}'],
  force: ['PUT', '/api/forces/{name}'],
  edit: ['PUT', '/api/programs/{name}'],
  tags: ['PUT', '/api/tags.csv'],
  runstop: ['POST', '/api/stop'],
  audit: ['GET', '/api/audit'],
  ack: ['POST', '/api/alarms/{id}/ack'],
  browse: ['GET', '/api/opcua/{server}/browse'],
  hardware: ['POST', '/api/hardware/download'],
  recipe: ['PUT', '/api/recipes/{name}'],
  apply: ['POST', '/api/recipes/{name}/apply'],
  // No route of its own yet: user management is `alba user` on the controller.
  users: ['POST', '/api/users'],
};

/**
 * The role a route needs, from the server's table (GET /api/domain `routes`);
 * a route without a rule of its own needs viewer to read and admin to change
 * anything, as on the server.
 */
export function routeRole(method: string, route: string): Role {
  const r = domain().routes.find((x) => x.method === method && x.route === route);
  if (r) return r.role ?? 'viewer';
  return method === 'GET' || method === 'HEAD' ? 'viewer' : 'admin';
}

/** The strings of this module (one place; a Spanish catalogue comes later). */
export const authText = {
  needs: (role: Role) => tr('needs the {role} role', { role: roleName(role) }),
  noUsers: tr('local, no users'),
  who: (user: string, role: Role) => `${user} (${roleName(role)})`,
};

/** The rights before GET /api/me has answered: none beyond reading. */
const NOBODY: Me = { user: null, role: 'viewer', users: true };
let current: Me = NOBODY;

export function setMe(me: Me): void {
  current = me;
}

export function me(): Me {
  return current;
}

export function isRole(x: unknown): x is Role {
  return typeof x === 'string' && (ROLES as readonly string[]).includes(x);
}

/** The role `action` needs. */
export function needs(action: Action): Role {
  return routeRole(...ROUTE[action]);
}

/** `a` includes `b` (admin includes every role, viewer only itself). */
export function atLeast(a: Role, b: Role): boolean {
  return ROLES.indexOf(a) >= ROLES.indexOf(b);
}

/** May the user do `action`? */
export function can(action: Action, who: Me = current): boolean {
  return atLeast(who.role, needs(action));
}

/** Why the user may not do `action` (a tooltip), or undefined when they may. */
export function why(action: Action, who: Me = current): string | undefined {
  return can(action, who) ? undefined : authText.needs(needs(action));
}

/**
 * Disables `el` (with the reason as its title) when the user may not do
 * `action`; returns whether they may. The element's own title is kept for
 * when it is allowed.
 */
export function gate<E extends HTMLElement & { disabled: boolean }>(el: E, action: Action, who: Me = current): boolean {
  const reason = why(action, who);
  if (reason) {
    el.disabled = true;
    el.title = reason;
    el.dataset.needs = needs(action);
  }
  return reason === undefined;
}

/** The user and role as the status bar shows them. */
export function whoLabel(m: Me = current): string {
  return !m.users || m.user === null ? authText.noUsers : authText.who(m.user, m.role);
}

/** Reads a GET /api/me (or POST /api/login) reply; null when it is not one. */
export function parseMe(j: unknown): Me | null {
  if (!j || typeof j !== 'object') return null;
  const o = j as Record<string, unknown>;
  if (!isRole(o.role)) return null;
  if (o.users === false) return { user: null, role: o.role, users: false };
  if (typeof o.user !== 'string') return null;
  return { user: o.user, role: o.role, users: true };
}

/** Full rights with no users (an older server without GET /api/me acts so too). */
export const LOCAL: Me = { user: null, role: 'admin', users: false };
