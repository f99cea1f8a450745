// Browsing a remote OPC UA server (`[[opcua_server]]` of alba.toml) from the
// studio's tag pickers (docs/protocols.md "Browse"): a tree that asks the
// server for a node's children when it is opened (GET
// /api/opcua/{server}/browse), from the Objects folder down. A variable can be
// picked: the dialog shows its node id and a ready binding line for the
// server's `bind` list in alba.toml, to copy. Net elements and programs read
// and write tags; the binding is what connects a tag to the node, and it takes
// effect when `alba run` restarts (docs/nets.md, "Editor").
import { ApiError, api } from '../api';
import { h } from '../dom';
import { tr } from '../i18n';
import type { BrowseNode, Connection } from '../types';

export type Dir = 'in' | 'out';

/** The Objects folder: where browsing starts. */
export const OBJECTS = 'i=85';

const text = {
  title: tr('Browse OPC UA server'),
  server: tr('Server'),
  close: tr('Close'),
  copy: tr('Copy'),
  copied: tr('Copied to the clipboard.'),
  loading: tr('Loading…'),
  empty: tr('(no children)'),
  objects: tr('Objects'),
  pickHint: tr('Open folders and objects; click a variable to pick it.'),
  picked: tr('Node id'),
  tag: tr('Tag'),
  dir: tr('Direction'),
  dirIn: tr('in (the server feeds the tag)'),
  dirOut: tr('out (the tag is written to the server)'),
  line: tr('Binding line'),
  how: (server: string) =>
    tr('Add this line to the bind list of the [[opcua_server]] named "{server}" in alba.toml, and the tag to tags.csv if it is new; the binding takes effect when alba run restarts.', { server }),
  down: (name: string, error: string) => tr('{name} is not connected: {error}', { name, error }),
};

/** A TOML basic string. */
export function tomlString(s: string): string {
  return `"${s.replace(/\\/g, '\\\\').replace(/"/g, '\\"').replace(/[\u0000-\u001f]/g, (c) => `\\u${c.charCodeAt(0).toString(16).padStart(4, '0')}`)}"`;
}

/** A tag name made from a browse name (letters, digits and _; not starting with a digit). */
export function tagNameOf(browseName: string): string {
  const t = browseName.replace(/[^A-Za-z0-9_]+/g, '_').replace(/^_+|_+$/g, '');
  return t === '' ? 'Tag' : /^[0-9]/.test(t) ? `_${t}` : t;
}

/** The node id a binding should name: the namespace URI form when there is one. */
export function bindingNode(n: BrowseNode): string {
  return n.node_uri ?? n.node;
}

/** One entry of a `[[opcua_server]]` `bind` list. */
export function bindingLine(tag: string, node: string, dir: Dir): string {
  return `{ tag = ${tomlString(tag)}, node = ${tomlString(node)}, dir = "${dir}" },`;
}

export interface BrowseOptions {
  /** The OPC UA connections of the status (the first one is browsed first). */
  connections: Connection[];
  /** The tag the binding is for (empty: a name from the picked node). */
  tag: string;
  dir: Dir;
  notify(message: string, kind?: 'info' | 'error'): void;
}

/** Opens the dialog; resolves with the picked node (null when closed without one). */
export function openOpcuaBrowser(opts: BrowseOptions): Promise<BrowseNode | null> {
  const servers = opts.connections.filter((c) => c.protocol === 'opcua');
  let picked: BrowseNode | null = null;
  let server = servers[0]?.name ?? '';
  return new Promise((resolve) => {
    const tree = h('ul', { class: 'opcua-tree', role: 'tree', 'data-testid': 'opcua-tree' });
    const serverSel = h('select', { 'data-testid': 'opcua-server' },
      servers.map((c) => h('option', { value: c.name, selected: c.name === server }, `${c.ok ? '●' : '○'} ${c.name} — ${c.endpoint}`)));
    const health = h('p', { class: 'hint opcua-down', role: 'status', 'data-testid': 'opcua-server-health' });
    const nodeOut = h('input', { readonly: true, 'data-testid': 'opcua-picked-node', placeholder: text.pickHint });
    const typeOut = h('small', { 'data-testid': 'opcua-picked-type' });
    const tagIn = h('input', { value: opts.tag, 'data-testid': 'opcua-tag', spellcheck: 'false', autocomplete: 'off' });
    const dirSel = h('select', { 'data-testid': 'opcua-dir' },
      h('option', { value: 'in', selected: opts.dir === 'in' }, text.dirIn),
      h('option', { value: 'out', selected: opts.dir === 'out' }, text.dirOut));
    const lineOut = h('textarea', { readonly: true, rows: 2, 'data-testid': 'opcua-binding', spellcheck: 'false' });
    const howOut = h('p', { class: 'hint', 'data-testid': 'opcua-how' });
    const copyBtn = h('button', { 'data-testid': 'opcua-copy', disabled: true }, text.copy);
    const closeBtn = h('button', { 'data-testid': 'opcua-close' }, text.close);
    const pickedBox = h('div', { class: 'opcua-picked' },
      h('label', null, h('span', null, text.picked), nodeOut, typeOut),
      h('label', null, h('span', null, text.tag), tagIn),
      h('label', null, h('span', null, text.dir), dirSel),
      h('label', null, h('span', null, text.line), lineOut),
      howOut,
      h('div', { class: 'modal-buttons' }, copyBtn, closeBtn));
    const box = h('div', { class: 'modal', role: 'dialog', 'aria-modal': 'true', 'aria-labelledby': 'opcua-title', 'data-testid': 'opcua-browse' },
      h('div', { class: 'modal-box opcua-box' },
        h('h2', { id: 'opcua-title' }, text.title),
        h('label', null, h('span', null, text.server), serverSel),
        health,
        tree,
        pickedBox));

    const refreshLine = () => {
      if (!picked) {
        lineOut.value = '';
        howOut.textContent = '';
        copyBtn.disabled = true;
        return;
      }
      const tag = tagIn.value.trim() || tagNameOf(picked.browse_name);
      lineOut.value = bindingLine(tag, bindingNode(picked), dirSel.value as Dir);
      howOut.textContent = text.how(server);
      copyBtn.disabled = false;
    };
    tagIn.addEventListener('input', refreshLine);
    dirSel.addEventListener('change', refreshLine);

    const showHealth = () => {
      const c = servers.find((x) => x.name === server);
      health.textContent = c && !c.ok && c.last_error ? text.down(c.name, c.last_error) : '';
      health.hidden = health.textContent === '';
    };

    /** A tree item: a toggle for anything that may have children, a pick for a variable. */
    const item = (n: BrowseNode): HTMLLIElement => {
      const variable = n.class === 'Variable';
      const kids = h('ul', { role: 'group', hidden: true });
      const toggle = h('button', { class: 'small link opcua-toggle', 'aria-expanded': 'false', 'data-testid': `opcua-toggle-${n.node}`, title: n.node }, '▸');
      const label = h('button', { class: 'small link opcua-label', 'data-testid': `opcua-node-${n.node}`, 'data-class': n.class, title: n.node },
        n.display_name || n.browse_name, ' ', h('small', null, variable && n.data_type ? `${n.class} · ${n.data_type}` : n.class));
      // A variable is a leaf here (its properties are not bound).
      const li = h('li', { role: 'treeitem', 'data-node': n.node }, variable ? h('span', { class: 'opcua-leaf' }) : toggle, label, variable ? null : kids);
      let loaded = false;
      const open = async () => {
        const opening = kids.hidden;
        kids.hidden = !opening;
        toggle.textContent = opening ? '▾' : '▸';
        toggle.setAttribute('aria-expanded', String(opening));
        if (opening && !loaded) {
          loaded = await load(kids, n.node);
        }
      };
      toggle.onclick = () => void open();
      label.onclick = () => {
        if (!variable) {
          void open();
          return;
        }
        box.querySelectorAll('.opcua-label.picked').forEach((x) => x.classList.remove('picked'));
        label.classList.add('picked');
        picked = n;
        nodeOut.value = bindingNode(n);
        nodeOut.title = n.node_uri ? `${n.node_uri}\n${n.node}` : n.node;
        typeOut.textContent = n.data_type ? ` ${n.data_type}` : '';
        refreshLine();
      };
      return li;
    };

    /** Fills `into` with the children of `node`; false on an error (shown there, retried when opened again). */
    const load = async (into: HTMLElement, node: string): Promise<boolean> => {
      into.replaceChildren(h('li', { class: 'hint' }, text.loading));
      try {
        const r = await api.opcuaBrowse(server, node);
        // Folders and objects first, then variables, each by name (servers answer in any order).
        const rank = (n: BrowseNode) => (n.class === 'Variable' ? 1 : n.class === 'Object' ? 0 : 2);
        const sorted = [...r.children].sort((a, b) => rank(a) - rank(b) || (a.display_name || a.browse_name).localeCompare(b.display_name || b.browse_name));
        into.replaceChildren(...(sorted.length ? sorted.map(item) : [h('li', { class: 'hint' }, text.empty)]));
        return true;
      } catch (e) {
        const msg = e instanceof ApiError ? e.message : String(e);
        into.replaceChildren(h('li', { class: 'inline-error', role: 'alert', 'data-testid': 'opcua-error' }, msg));
        return false;
      }
    };

    const root = () => {
      picked = null;
      nodeOut.value = '';
      typeOut.textContent = '';
      refreshLine();
      showHealth();
      const top = item({ node: OBJECTS, node_uri: null, browse_name: 'Objects', display_name: text.objects, class: 'Object', data_type: null });
      tree.replaceChildren(top);
      (top.querySelector('.opcua-toggle') as HTMLButtonElement).click();
    };
    serverSel.onchange = () => {
      server = serverSel.value;
      root();
    };

    const done = () => {
      box.remove();
      document.removeEventListener('keydown', onKey, true);
      resolve(picked);
    };
    const onKey = (e: KeyboardEvent) => {
      if (e.key === 'Escape') {
        e.preventDefault();
        done();
      }
    };
    copyBtn.onclick = async () => {
      try {
        await navigator.clipboard.writeText(lineOut.value);
        opts.notify(text.copied);
      } catch {
        // No clipboard (plain HTTP beyond loopback): the text is selected for Ctrl+C.
        lineOut.select();
      }
    };
    closeBtn.onclick = done;
    document.addEventListener('keydown', onKey, true);
    document.body.append(box);
    root();
    serverSel.focus();
  });
}
