// tags.csv (docs/file-formats.md §3): RFC 4180 fields, a header naming the
// columns in any order. The tag table edits definitions and writes the
// whole file back in the header's column order.
import { typeInfo } from '../domain';

export const COLUMNS = ['name', 'type', 'address', 'initial', 'retain', 'description'] as const;
export type Column = (typeof COLUMNS)[number];
export type TagDef = Record<Column, string>;

/** Splits CSV text into records of fields (quotes and doubled quotes, CRLF or LF, blank lines dropped). */
export function parseCsv(text: string): string[][] {
  const rows: string[][] = [];
  let row: string[] = [];
  let field = '';
  let quoted = false;
  let wasQuoted = false;
  const t = text.replace(/^\uFEFF/, '');
  const endField = () => {
    row.push(wasQuoted ? field : field.trim());
    field = '';
    wasQuoted = false;
  };
  const endRow = () => {
    endField();
    if (!(row.length === 1 && row[0] === '' )) rows.push(row);
    row = [];
  };
  for (let i = 0; i < t.length; i++) {
    const c = t[i];
    if (quoted) {
      if (c === '"') {
        if (t[i + 1] === '"') {
          field += '"';
          i++;
        } else quoted = false;
      } else field += c;
    } else if (c === '"' && field.trim() === '') {
      quoted = true;
      wasQuoted = true;
      field = '';
    } else if (wasQuoted && (c === ' ' || c === '\t')) {
      continue; // spaces after a closing quote
    } else if (c === ',') endField();
    else if (c === '\n') endRow();
    else if (c === '\r' && t[i + 1] === '\n') continue;
    else field += c;
  }
  if (field !== '' || row.length > 0 || wasQuoted) endRow();
  return rows;
}

/** One CSV field, quoted when it has to be. */
export function csvField(v: string): string {
  return /[",\r\n]/.test(v) || /^\s|\s$/.test(v) ? `"${v.replace(/"/g, '""')}"` : v;
}

export function toCsv(rows: string[][]): string {
  return rows.map((r) => r.map(csvField).join(',')).join('\n') + '\n';
}

export interface TagsFile {
  /** Columns in the file's order. */
  columns: Column[];
  defs: TagDef[];
}

export function parseTagsCsv(text: string): TagsFile {
  const rows = parseCsv(text);
  if (rows.length === 0) return { columns: [...COLUMNS], defs: [] };
  const columns = rows[0].map((c) => c.trim().toLowerCase()).filter((c): c is Column => (COLUMNS as readonly string[]).includes(c));
  const idx = rows[0].map((c) => c.trim().toLowerCase());
  const defs = rows.slice(1).map((r) => {
    const d = Object.fromEntries(COLUMNS.map((c) => [c, ''])) as TagDef;
    idx.forEach((c, k) => {
      if ((COLUMNS as readonly string[]).includes(c)) d[c as Column] = r[k] ?? '';
    });
    return d;
  });
  return { columns, defs };
}

/** The file text; columns that some definition needs are added to the header. */
export function tagsCsv(file: TagsFile): string {
  const columns = [...file.columns];
  for (const c of COLUMNS) if (!columns.includes(c) && file.defs.some((d) => d[c] !== '')) columns.push(c);
  for (const c of ['name', 'type'] as Column[]) if (!columns.includes(c)) columns.unshift(c);
  return toCsv([columns, ...file.defs.map((d) => columns.map((c) => d[c] ?? ''))]);
}

const RESERVED = new Set(['TRUE', 'FALSE', 'MOD', 'AND', 'OR', 'XOR', 'NOT', 'PI', 'E']);

/** Checks a definition before sending it; the server checks everything else (addresses, initial values). */
export function validateDef(d: TagDef, others: TagDef[]): string | null {
  const name = d.name.trim();
  if (!name) return 'A tag needs a name';
  if (!/^[A-Za-z_][A-Za-z0-9_]*$/.test(name)) return 'A name has letters, digits and _, and does not start with a digit';
  if (name.length > 64) return 'A name has at most 64 characters';
  if (RESERVED.has(name.toUpperCase())) return `${name} is a reserved word`;
  if (others.some((o) => o.name.trim().toUpperCase() === name.toUpperCase())) return `There is already a tag ${name}`;
  if (!typeInfo(d.type.trim())) return `Unknown type ${d.type}`;
  return null;
}

/** The 1-based line of each definition in the text tagsCsv writes (fields may hold line breaks). */
export function lineOfDefs(file: TagsFile): number[] {
  let line = 2;
  return file.defs.map((d) => {
    const at = line;
    line += 1 + Object.values(d).reduce((n, v) => n + (v.match(/\n/g)?.length ?? 0), 0);
    return at;
  });
}
