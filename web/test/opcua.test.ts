// The OPC UA browse dialog of the tag pickers (docs/protocols.md "Browse"):
// lazy browsing from the Objects folder, picking a variable, the binding line.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { bindingLine, openOpcuaBrowser, tagNameOf, tomlString } from '../src/ui/opcuaBrowse';
import type { BrowseNode, Connection } from '../src/types';

const conn: Connection = { name: 'plant', protocol: 'opcua', endpoint: 'opc.tcp://127.0.0.1:4840/', ok: true, connected: true, connects: 1, errors: 0, last_error: null, queue: null };
const node = (browse_name: string, cls: string, node: string, over: Partial<BrowseNode> = {}): BrowseNode => ({
  node, node_uri: null, browse_name, display_name: browse_name, class: cls, data_type: null, ...over,
});
const flush = () => new Promise((r) => setTimeout(r, 0));

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.replaceChildren();
});

describe('binding lines', () => {
  it('quotes TOML strings and makes tag names from browse names', () => {
    expect(tomlString('a"b\\c')).toBe('"a\\"b\\\\c"');
    expect(bindingLine('Level', 'nsu=urn:plant;s=Tank.Level', 'in')).toBe('{ tag = "Level", node = "nsu=urn:plant;s=Tank.Level", dir = "in" },');
    expect([tagNameOf('Tank Level'), tagNameOf('2nd'), tagNameOf('---')]).toEqual(['Tank_Level', '_2nd', 'Tag']);
  });
});

describe('the browse dialog', () => {
  it('browses lazily from Objects, picks a variable and offers its binding line', async () => {
    const children: Record<string, BrowseNode[]> = {
      'i=85': [node('Aaa', 'Variable', 'ns=2;s=Aaa'), node('Tank', 'Object', 'ns=2;s=Tank', { node_uri: 'nsu=urn:plant;s=Tank' }), node('Server', 'Object', 'i=2253')],
      'ns=2;s=Tank': [node('Level', 'Variable', 'ns=2;s=Tank.Level', { node_uri: 'nsu=urn:plant;s=Tank.Level', data_type: 'Double' })],
    };
    const asked: string[] = [];
    vi.stubGlobal('fetch', vi.fn(async (url: string) => {
      const u = new URL(url, 'http://x');
      const n = u.searchParams.get('node') ?? 'i=85';
      asked.push(`${u.pathname} ${n}`);
      return new Response(JSON.stringify({ server: 'plant', node: n, children: children[n] ?? [] }), { status: 200 });
    }));
    const done = openOpcuaBrowser({ connections: [conn], tag: 'TankLevel', dir: 'out', notify: () => undefined });
    await flush();
    // The Objects folder is opened at once; nothing deeper is asked for yet.
    expect(asked).toEqual(['/api/opcua/plant/browse i=85']);
    const q = (id: string) => document.querySelector(`[data-testid="${id}"]`) as HTMLElement;
    expect(q('opcua-node-i=2253')).not.toBeNull();
    // Objects before variables, each by name, whatever the server's order.
    expect([...document.querySelectorAll('[data-testid="opcua-tree"] > li > ul > li')].map((li) => li.getAttribute('data-node'))).toEqual(['i=2253', 'ns=2;s=Tank', 'ns=2;s=Aaa']);
    q('opcua-toggle-ns=2;s=Tank').click();
    await flush();
    expect(asked[1]).toBe('/api/opcua/plant/browse ns=2;s=Tank');
    const level = q('opcua-node-ns=2;s=Tank.Level');
    expect(level.textContent).toContain('Double');
    level.click();
    expect((q('opcua-picked-node') as HTMLInputElement).value).toBe('nsu=urn:plant;s=Tank.Level');
    expect((q('opcua-binding') as HTMLTextAreaElement).value).toBe('{ tag = "TankLevel", node = "nsu=urn:plant;s=Tank.Level", dir = "out" },');
    (q('opcua-dir') as HTMLSelectElement).value = 'in';
    q('opcua-dir').dispatchEvent(new Event('change'));
    expect((q('opcua-binding') as HTMLTextAreaElement).value).toContain('dir = "in"');
    q('opcua-close').click();
    expect((await done)?.node).toBe('ns=2;s=Tank.Level');
    expect(q('opcua-browse')).toBeNull();
  });

  it("shows the server's refusal where the folder would open", async () => {
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify({ error: 'OPC UA server plant (opc.tcp://x/): cannot connect' }), { status: 502 })));
    const done = openOpcuaBrowser({ connections: [{ ...conn, ok: false, connected: false, last_error: 'connection lost' }], tag: '', dir: 'in', notify: () => undefined });
    await flush();
    const err = document.querySelector('[data-testid="opcua-error"]') as HTMLElement;
    expect(err.textContent).toContain('cannot connect');
    expect((document.querySelector('[data-testid="opcua-server-health"]') as HTMLElement).textContent).toBe('plant is not connected: connection lost');
    document.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape' }));
    expect(await done).toBeNull();
  });
});
