import { afterEach, describe, expect, it, vi } from 'vitest';
import { ApiError, api, onUnauthorized } from '../src/api';
import { type Action, LOCAL, type Me, type Role, ROLES, can, gate, me, needs, parseMe, setMe, whoLabel, why } from '../src/auth';
import { type Ctx, TagCache } from '../src/ctx';
import { domain, setDomain } from '../src/domain';
import { ProgramEditor } from '../src/editor/program';
import { LiveClient } from '../src/live/client';
import { TagsView } from '../src/tags/view';
import type { TagInfo } from '../src/types';
import { tagMenuItems } from '../src/ui/tagActions';
import { StatusBar } from '../src/ui/statusbar';

const user = (role: Role, name = 'ann'): Me => ({ user: name, role, users: true });

afterEach(() => {
  vi.unstubAllGlobals();
  onUnauthorized(null);
});

describe('roles and what they may do (the route table of docs/api.md)', () => {
  // action → the roles that may do it
  const table: Record<Action, Role[]> = {
    write: ['operator', 'engineer', 'admin'],
    force: ['engineer', 'admin'],
    edit: ['engineer', 'admin'],
    tags: ['engineer', 'admin'],
    runstop: ['engineer', 'admin'],
    audit: ['engineer', 'admin'],
    ack: ['operator', 'engineer', 'admin'],
    browse: ['engineer', 'admin'],
    hardware: ['engineer', 'admin'],
    recipe: ['engineer', 'admin'],
    apply: ['operator', 'engineer', 'admin'],
    users: ['admin'],
  };
  for (const [action, allowed] of Object.entries(table) as [Action, Role[]][]) {
    it(`${action}: ${allowed.join(', ')}`, () => {
      for (const role of ROLES) expect([role, can(action, user(role))]).toEqual([role, allowed.includes(role)]);
      expect(needs(action)).toBe(allowed[0]);
    });
  }

  it("takes each action's role from the server's route table (GET /api/domain routes)", () => {
    const saved = domain();
    try {
      const routes = saved.routes.map((r) => (r.route === '/api/tags/{name}' ? { ...r, role: 'engineer' as Role } : r));
      setDomain({ ...saved, routes });
      expect(needs('write')).toBe('engineer');
      expect(can('write', user('operator'))).toBe(false);
      // A change without a rule of its own needs admin, a read viewer, as on the server.
      setDomain({ ...saved, routes: [] });
      expect([needs('write'), needs('audit')]).toEqual(['admin', 'viewer']);
    } finally {
      setDomain(saved);
    }
  });

  it('a viewer may do nothing that changes anything', () => {
    const v = user('viewer');
    expect(Object.keys(table).filter((a) => can(a as Action, v))).toEqual([]);
  });

  it('says why an action is not allowed, and nothing when it is', () => {
    expect(why('force', user('operator'))).toBe('needs the engineer role');
    expect(why('write', user('viewer'))).toBe('needs the operator role');
    expect(why('users', user('engineer'))).toBe('needs the admin role');
    expect(why('force', user('engineer'))).toBeUndefined();
  });

  it('without users, the studio has every right', () => {
    for (const a of Object.keys(table)) expect(can(a as Action, LOCAL)).toBe(true);
  });

  it('uses the current user (set after GET /api/me)', () => {
    setMe(user('operator'));
    expect(me().role).toBe('operator');
    expect(can('write')).toBe(true);
    expect(can('runstop')).toBe(false);
  });

  it('gate() disables a control with the reason as its tooltip, and leaves an allowed one alone', () => {
    const b = document.createElement('button');
    b.title = 'Stop scanning';
    expect(gate(b, 'runstop', user('operator'))).toBe(false);
    expect(b.disabled).toBe(true);
    expect(b.title).toBe('needs the engineer role');
    expect(b.dataset.needs).toBe('engineer');
    const c = document.createElement('button');
    c.title = 'Stop scanning';
    expect(gate(c, 'runstop', user('engineer'))).toBe(true);
    expect(c.disabled).toBe(false);
    expect(c.title).toBe('Stop scanning');
  });

  it('reads GET /api/me and POST /api/login replies (and refuses other shapes)', () => {
    expect(parseMe({ user: 'ann', role: 'operator' })).toEqual(user('operator'));
    expect(parseMe({ token: 'secret', user: 'bob', role: 'engineer' })).toEqual(user('engineer', 'bob'));
    expect(parseMe({ user: null, role: 'admin', users: false })).toEqual(LOCAL);
    expect(parseMe({ user: 'ann', role: 'root' })).toBeNull();
    expect(parseMe({ user: null, role: 'viewer' })).toBeNull();
    expect(parseMe('ann')).toBeNull();
    expect(parseMe(null)).toBeNull();
  });

  it('labels the user for the status bar', () => {
    expect(whoLabel(user('operator'))).toBe('ann (operator)');
    expect(whoLabel(LOCAL)).toBe('local, no users');
    const bar = new StatusBar();
    bar.user(user('engineer'));
    const field = bar.el.querySelector('[data-testid="status-user"]') as HTMLElement;
    const logout = bar.el.querySelector('[data-testid="btn-logout"]') as HTMLButtonElement;
    expect(field.textContent).toBe('ann (engineer)');
    expect(field.dataset.role).toBe('engineer');
    expect(logout.hidden).toBe(false);
    bar.user(LOCAL);
    expect(field.textContent).toBe('local, no users');
    expect(logout.hidden).toBe(true);
  });
});

/** A fetch that records each request and answers with `reply(method, path)`. */
function recordFetch(reply: (method: string, path: string) => Response = () => new Response(null, { status: 204 })) {
  const calls: { method: string; path: string; init: RequestInit }[] = [];
  vi.stubGlobal('fetch', async (path: string, init: RequestInit) => {
    calls.push({ method: init.method ?? 'GET', path, init });
    return reply(init.method ?? 'GET', path);
  });
  return calls;
}

const jsonReply = (status: number, j: unknown, headers: Record<string, string> = {}) =>
  new Response(JSON.stringify(j), { status, headers: { 'Content-Type': 'application/json', ...headers } });

describe('requests', () => {
  it('every state-changing request has a JSON body and the same-origin credentials', async () => {
    const calls = recordFetch();
    await api.run();
    await api.stop();
    await api.unforce('S_REC');
    await api.logout();
    await api.writeTag('Vol_L', 3);
    await api.login('ann', 'pw');
    for (const c of calls) {
      expect([c.method, c.path, (c.init.headers as Record<string, string>)['Content-Type']]).toEqual([c.method, c.path, 'application/json']);
      expect(c.init.credentials).toBe('same-origin');
      expect(() => JSON.parse(c.init.body as string)).not.toThrow();
    }
    expect(calls.map((c) => `${c.method} ${c.path} ${c.init.body}`)).toEqual([
      'POST /api/run {}',
      'POST /api/stop {}',
      'DELETE /api/forces/S_REC {}',
      'POST /api/logout {}',
      'PUT /api/tags/Vol_L {"value":3}',
      'POST /api/login {"user":"ann","password":"pw"}',
    ]);
  });

  it('reads have no body', async () => {
    const calls = recordFetch(() => jsonReply(200, []));
    await api.tags();
    expect(calls[0].init.body).toBeUndefined();
    expect(calls[0].init.credentials).toBe('same-origin');
  });

  it('a 401 tells main.ts that the session ended, except for a failed login', async () => {
    recordFetch((_, path) => jsonReply(401, { error: path === '/api/login' ? 'wrong user or password' : 'session expired' }));
    const ended: string[] = [];
    onUnauthorized((m) => ended.push(m));
    await expect(api.tags()).rejects.toMatchObject({ status: 401, message: 'session expired' });
    await expect(api.login('ann', 'bad')).rejects.toMatchObject({ status: 401 });
    expect(ended).toEqual(['session expired']);
  });

  it('a 429 carries the wait, from Retry-After or the body', async () => {
    recordFetch(() => jsonReply(429, { error: 'too many attempts' }, { 'Retry-After': '7' }));
    await expect(api.login('ann', 'x')).rejects.toMatchObject({ status: 429, retryAfter: 7 });
    recordFetch(() => jsonReply(429, { error: 'too many attempts', retry_after_s: 12 }));
    await expect(api.login('ann', 'x')).rejects.toMatchObject({ status: 429, retryAfter: 12 });
    recordFetch(() => jsonReply(403, { error: 'needs the engineer role' }));
    const e = await api.stop().catch((x) => x);
    expect(e).toBeInstanceOf(ApiError);
    expect(e).toMatchObject({ status: 403, message: 'needs the engineer role', retryAfter: null });
  });
});

const tag = (name: string, type: string, access: TagInfo['access'], address: string | null = null): TagInfo => ({
  name, type, address, notations: [], description: '', retain: false, access, value: type === 'BOOL' ? false : 0, forced: null,
});

const TAGS = [tag('Pump', 'BOOL', 'readwrite'), tag('Level', 'REAL', 'readwrite'), tag('S_REC', 'BOOL', 'input', 'DI:1/0'), tag('T1', 'TIMER', 'readwrite')];

function ctx(): Ctx {
  const tags = new TagCache();
  tags.set(TAGS);
  return { live: new LiveClient('ws://127.0.0.1:1/api/ws'), tags, notify: () => undefined };
}

/** The tag table as `who` sees it. */
function tagsView(who: Me) {
  setMe(who);
  recordFetch((_, path) => jsonReply(200, path === '/api/forces' ? [] : TAGS));
  const v = new TagsView(ctx());
  v.show();
  const q = (id: string) => v.el.querySelector(`[data-testid="${id}"]`) as HTMLButtonElement | HTMLInputElement;
  return { v, q };
}

describe('views ask auth.ts', () => {
  it('the tag table of a viewer: nothing to press', () => {
    const { q } = tagsView(user('viewer'));
    for (const id of ['tag-toggle-Pump', 'tag-edit-value-Level', 'tag-edit-value-T1.PRE', 'force-on-S_REC', 'force-off-S_REC', 'unforce-S_REC', 'tag-add', 'tags-import-button', 'tag-def-edit-Pump', 'tag-def-delete-Pump']) {
      expect([id, q(id).disabled]).toEqual([id, true]);
    }
    expect(q('tag-toggle-Pump').title).toBe('needs the operator role');
    expect(q('force-on-S_REC').title).toBe('needs the engineer role');
    expect(q('tags-export')).not.toBeNull();
  });

  it('the tag table of an operator: writes, but no forces and no tag definitions', () => {
    const { q } = tagsView(user('operator'));
    for (const id of ['tag-toggle-Pump', 'tag-edit-value-Level', 'tag-edit-value-T1.PRE']) expect([id, q(id).disabled]).toEqual([id, false]);
    for (const id of ['force-on-S_REC', 'force-off-S_REC', 'tag-add', 'tags-import-button', 'tag-def-edit-Pump', 'tag-def-delete-Level']) {
      expect([id, q(id).disabled, q(id).title]).toEqual([id, true, 'needs the engineer role']);
    }
  });

  it('the tag table of an engineer: everything', () => {
    const { q } = tagsView(user('engineer'));
    for (const id of ['tag-toggle-Pump', 'force-on-S_REC', 'force-off-S_REC', 'tag-add', 'tags-import-button', 'tag-def-edit-Pump']) {
      expect([id, q(id).disabled]).toEqual([id, false]);
    }
    expect(q('unforce-S_REC').disabled).toBe(true); // not forced
  });

  it('the context menu of an operand: forces need an engineer, writes an operator', () => {
    recordFetch();
    setMe(user('operator'));
    const c = ctx();
    const io = tagMenuItems(c, 'S_REC');
    expect(io.map((i) => [i.testid, !!i.disabled, i.title])).toEqual([
      ['menu-force-on', true, 'needs the engineer role'],
      ['menu-force-off', true, 'needs the engineer role'],
      ['menu-unforce', true, 'needs the engineer role'],
    ]);
    expect(tagMenuItems(c, 'Pump').map((i) => [i.testid, !!i.disabled])).toEqual([['menu-toggle', false]]);
    setMe(user('viewer'));
    expect(tagMenuItems(c, 'Level').map((i) => [i.testid, !!i.disabled, i.title])).toEqual([['menu-set-value', true, 'needs the operator role']]);
    setMe(user('engineer'));
    expect(tagMenuItems(c, 'S_REC').map((i) => !!i.disabled)).toEqual([false, false, true]);
  });

  it('the program text is read-only below engineer, and is neither checked nor saved', async () => {
    const calls = recordFetch(() => jsonReply(200, { name: 'main.lad', language: 'ladder', plant: false, text: 'XIC(A)OTE(B);\n', diagnostics: [], rungs: [] }));
    setMe(user('operator'));
    const ed = new ProgramEditor(ctx(), 'main.lad', { loaded: () => undefined, textChanged: () => undefined, changed: () => undefined });
    expect(ed.textEl.readOnly).toBe(true);
    expect(ed.textEl.title).toBe('needs the engineer role');
    await ed.load();
    ed.setText('XIC(A)OTE(C);\n', false, false);
    expect(await ed.check()).toBe(false);
    expect(await ed.save()).toBe(false);
    expect(calls.map((c) => `${c.method} ${c.path}`)).toEqual(['GET /api/programs/main.lad']);
    setMe(user('engineer'));
    expect(new ProgramEditor(ctx(), 'main.lad', { loaded: () => undefined, textChanged: () => undefined, changed: () => undefined }).textEl.readOnly).toBe(false);
  });
});
