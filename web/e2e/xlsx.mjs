// A small XLSX reader for the e2e tests (no dependency): the zip's central
// directory, its entries inflated with node:zlib, and the sheets' cells with
// shared strings resolved. Enough to check what a report holds; not a
// general-purpose reader (no ZIP64, no encryption).
import { inflateRawSync } from 'node:zlib';

/** The entries of a zip archive: name → bytes. */
export function unzip(buf) {
  // the end of central directory record: signature 0x06054b50, near the end
  let eocd = -1;
  for (let i = buf.length - 22; i >= Math.max(0, buf.length - 65_557); i--) {
    if (buf.readUInt32LE(i) === 0x06054b50) {
      eocd = i;
      break;
    }
  }
  if (eocd < 0) throw new Error('not a zip archive (no end of central directory)');
  const count = buf.readUInt16LE(eocd + 10);
  let at = buf.readUInt32LE(eocd + 16);
  const out = new Map();
  for (let n = 0; n < count; n++) {
    if (buf.readUInt32LE(at) !== 0x02014b50) throw new Error(`bad central directory entry ${n}`);
    const method = buf.readUInt16LE(at + 10);
    const size = buf.readUInt32LE(at + 20);
    const nameLen = buf.readUInt16LE(at + 28);
    const extraLen = buf.readUInt16LE(at + 30);
    const commentLen = buf.readUInt16LE(at + 32);
    const local = buf.readUInt32LE(at + 42);
    const name = buf.subarray(at + 46, at + 46 + nameLen).toString('utf8');
    at += 46 + nameLen + extraLen + commentLen;
    if (buf.readUInt32LE(local) !== 0x04034b50) throw new Error(`bad local header for ${name}`);
    const start = local + 30 + buf.readUInt16LE(local + 26) + buf.readUInt16LE(local + 28);
    const data = buf.subarray(start, start + size);
    if (method === 0) out.set(name, Buffer.from(data));
    else if (method === 8) out.set(name, inflateRawSync(data));
    else throw new Error(`${name}: compression method ${method}`);
  }
  return out;
}

const unescape = (s) =>
  s.replace(/&(lt|gt|amp|quot|apos|#(\d+)|#x([0-9a-f]+));/gi, (_, e, d, x) =>
    d ? String.fromCodePoint(Number(d)) : x ? String.fromCodePoint(parseInt(x, 16)) : { lt: '<', gt: '>', amp: '&', quot: '"', apos: "'" }[e]);
const attr = (tag, name) => tag.match(new RegExp(`\\b${name}="([^"]*)"`))?.[1];

/** A workbook's sheets in order: [{ name, cells: { A1: value } }] (numbers as numbers). */
export function readXlsx(buf) {
  const files = unzip(buf);
  const text = (p) => {
    const f = files.get(p);
    if (!f) throw new Error(`no ${p} in the workbook`);
    return f.toString('utf8');
  };
  const shared = files.has('xl/sharedStrings.xml')
    ? [...text('xl/sharedStrings.xml').matchAll(/<si>([\s\S]*?)<\/si>/g)].map((m) => unescape([...m[1].matchAll(/<t[^>]*>([\s\S]*?)<\/t>/g)].map((t) => t[1]).join('')))
    : [];
  const rels = new Map([...text('xl/_rels/workbook.xml.rels').matchAll(/<Relationship\b[^>]*>/g)].map((m) => [attr(m[0], 'Id'), attr(m[0], 'Target')]));
  return [...text('xl/workbook.xml').matchAll(/<sheet\b[^>]*>/g)].map((m) => {
    const name = unescape(attr(m[0], 'name'));
    const target = rels.get(attr(m[0], 'r:id'));
    const path = target.startsWith('/') ? target.slice(1) : `xl/${target}`;
    const cells = {};
    for (const c of text(path).matchAll(/<c\b([^>]*?)(?:\/>|>([\s\S]*?)<\/c>)/g)) {
      const ref = attr(c[1], 'r');
      const type = attr(c[1], 't');
      const inner = c[2] ?? '';
      const v = inner.match(/<v>([\s\S]*?)<\/v>/)?.[1];
      if (type === 's') cells[ref] = shared[Number(v)];
      else if (type === 'inlineStr') cells[ref] = unescape(inner.match(/<t[^>]*>([\s\S]*?)<\/t>/)?.[1] ?? '');
      else if (type === 'str' || type === 'b') cells[ref] = type === 'b' ? v === '1' : unescape(v ?? '');
      else if (v !== undefined) cells[ref] = Number(v);
    }
    return { name, cells };
  });
}
