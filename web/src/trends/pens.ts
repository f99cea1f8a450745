// Which tag a pen plots: one of this runtime's (live from the WebSocket,
// history from its historian) or, with a shared historian
// (`[history] backend = "postgres"`), one that another node recorded
// (history only, refreshed while the view is live).
import type { TrendPen } from '../types';

/** A pen's tag and node (none: this runtime's). */
export interface PenRef {
  tag: string;
  node?: string;
}

/** How often pens of other nodes are read again from the history while the view is live. */
export const REMOTE_REFRESH_MS = 2000;

/** A pen's name in the legend, test ids and the CSV export: `Tag`, or `Tag@node` for another node's. */
export function penId(p: PenRef): string {
  return p.node ? `${p.tag}@${p.node}` : p.tag;
}

/** The key of a pen's live buffer: tags are case-insensitive, node ids are not. */
export function penKey(p: PenRef): string {
  return p.node ? `${p.tag.toUpperCase()}@${p.node}` : p.tag.toUpperCase();
}

/**
 * The pen a user asked for: `Tag@node` names another node's tag, otherwise
 * `node` (the node picked beside the input) does; this runtime's own node id
 * (`own`) is no other node.
 */
export function parsePen(text: string, node: string, own: string): PenRef {
  const t = text.trim();
  const at = t.lastIndexOf('@');
  const [tag, n] = at > 0 ? [t.slice(0, at).trim(), t.slice(at + 1).trim()] : [t, node];
  return n && n !== own ? { tag, node: n } : { tag };
}

/** The pens of this runtime, whose values come live over the WebSocket. */
export function liveTags(pens: PenRef[]): string[] {
  return pens.filter((p) => !p.node).map((p) => p.tag);
}

/** The pens of other nodes, drawn from history only. */
export function remotePens<P extends PenRef>(pens: P[]): P[] {
  return pens.filter((p) => !!p.node);
}

/** A new pen: axis 1, automatic scale. */
export function newPen(ref: PenRef): TrendPen {
  return ref.node ? { tag: ref.tag, node: ref.node, axis: 1, min: null, max: null } : { tag: ref.tag, axis: 1, min: null, max: null };
}
