// The tag table keeps the keyboard's place (issue 30, item 10): after a force,
// an unforce, a write or the definition form the focus stays on the control
// (or the next one of its row), never dropping to <body>.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { type Ctx, TagCache } from '../src/ctx';
import { LiveClient } from '../src/live/client';
import { TagsView } from '../src/tags/view';
import type { Force, TagInfo } from '../src/types';

const tag = (name: string, type: string, address: string | null, access = 'readwrite'): TagInfo =>
  ({ name, type, address, notations: [], description: '', retain: false, access, value: null, forced: null }) as TagInfo;
const TAGS = [tag('STOP', 'BOOL', 'DI:1/0', 'input'), tag('Level', 'REAL', null), tag('Pump', 'BOOL', 'DO:2/0')];

function server() {
  let forces: Force[] = [];
  const writes: string[] = [];
  vi.stubGlobal('fetch', async (path: string, init: RequestInit = {}) => {
    const json = (j: unknown) => new Response(JSON.stringify(j), { status: 200, headers: { 'Content-Type': 'application/json' } });
    const method = init.method ?? 'GET';
    const name = decodeURIComponent(path.split('/').pop()!);
    if (path === '/api/tags') return json(TAGS);
    if (path === '/api/forces') return json(forces);
    if (path.startsWith('/api/forces/') && method === 'PUT') {
      forces = [{ name, value: JSON.parse(init.body as string).value }];
      return json(forces[0]);
    }
    if (path.startsWith('/api/forces/') && method === 'DELETE') {
      forces = [];
      return new Response(null, { status: 204 });
    }
    if (path.startsWith('/api/tags/') && method === 'PUT') {
      writes.push(`${name}=${init.body}`);
      return json({ name, value: JSON.parse(init.body as string).value });
    }
    return json({});
  });
  return writes;
}

async function view() {
  const writes = server();
  const tags = new TagCache();
  await tags.refresh();
  const live = new LiveClient('ws://127.0.0.1:1/none');
  const ctx = { live, tags, notify: () => undefined } as unknown as Ctx;
  const v = new TagsView(ctx);
  document.body.append(v.el);
  v.show();
  return { v, writes };
}

const tid = (id: string) => document.querySelector<HTMLElement>(`[data-testid="${id}"]`)!;
const focused = () => (document.activeElement as HTMLElement | null)?.dataset.testid ?? document.activeElement?.tagName;
const settle = async () => {
  for (let k = 0; k < 10; k++) await new Promise((r) => setTimeout(r, 0));
};

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.replaceChildren();
});

describe('the tag table and the keyboard', () => {
  it('keeps the focus on a force button, and on the row when Unforce goes disabled', async () => {
    await view();
    await settle();
    expect(tid('force-on-STOP').title).toBe('Force to 1 (on)');
    expect(tid('force-off-STOP').title).toBe('Force to 0 (off)');
    tid('force-on-STOP').focus();
    tid('force-on-STOP').click();
    await settle();
    expect(tid('tag-forced-STOP')).not.toBeNull();
    expect(focused()).toBe('force-on-STOP');
    tid('unforce-STOP').focus();
    tid('unforce-STOP').click();
    await settle();
    expect(tid('tag-forced-STOP')).toBeNull();
    expect((tid('unforce-STOP') as HTMLButtonElement).disabled).toBe(true);
    expect(focused()).toBe('force-on-STOP');
  });

  it('gives the focus back to ✎ after a write, and to the button that opened the form', async () => {
    const { writes } = await view();
    await settle();
    tid('tag-edit-value-Level').click();
    expect(focused()).toBe('tag-input-Level');
    (tid('tag-input-Level') as HTMLInputElement).value = '42';
    tid('tag-input-Level').dispatchEvent(new KeyboardEvent('keydown', { key: 'Enter', bubbles: true }));
    await settle();
    expect(writes).toEqual(['Level={"value":42}']);
    expect(focused()).toBe('tag-edit-value-Level');
    tid('tag-edit-value-Level').click();
    tid('tag-input-Level').dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape', bubbles: true }));
    expect(focused()).toBe('tag-edit-value-Level');
    tid('tag-def-edit-Level').focus();
    tid('tag-def-edit-Level').click();
    await settle();
    expect(focused()).toBe('tag-form-name');
    tid('tag-form-cancel').click();
    expect(focused()).toBe('tag-def-edit-Level');
  });
});
