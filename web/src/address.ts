// I/O addresses in the notation the API lists them in (AuroraLD: DI:1/5,
// DO:2/0, AI:3/1, AO:4/0; markers M0.4, MB2, MW2, MD4), from any of the three
// notations of docs/file-formats.md (S7-200 I0.5, Q0.0, AIW2, AQW0, Ain1;
// IEC %IX0.5, %QX0.0, %IW1, %QW0, %MX0.4 …), so an operand finds the tag on
// its address. Anything else comes back unchanged.
export function apiAddress(operand: string): string {
  const s = operand.trim().toUpperCase();
  let m = /^%?([IQ])X?(\d+)\.([0-7])$/.exec(s);
  if (m) return `${m[1] === 'I' ? 'DI:1' : 'DO:2'}/${Number(m[2]) * 8 + Number(m[3])}`;
  m = /^A([IQ])W(\d+)$/.exec(s);
  if (m && Number(m[2]) % 2 === 0) return `${m[1] === 'I' ? 'AI:3' : 'AO:4'}/${Number(m[2]) / 2}`;
  m = /^AIN(\d+)$/.exec(s);
  if (m) return `AI:3/${Number(m[1])}`;
  m = /^%([IQ])W(\d+)$/.exec(s);
  if (m) return `${m[1] === 'I' ? 'AI:3' : 'AO:4'}/${Number(m[2])}`;
  m = /^%M([XBWD])(\d+)(?:\.([0-7]))?$/.exec(s);
  if (m) return m[1] === 'X' ? `M${m[2]}.${m[3] ?? 0}` : `M${m[1]}${m[2]}`;
  return s;
}
