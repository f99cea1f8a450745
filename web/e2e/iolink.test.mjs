// The runtime view when the I/O link drops (issue 17, item 5): tank-plant
// with its I/O on a Modbus TCP slave (`--io modbus`, a [[modbus_device]]);
// the slave here is a minimal one in this file (it answers reads with zeros
// and acknowledges writes). Stopping it makes S:IOOK false: the screen says
// so and greys its elements; starting it again clears both.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { appendFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { useStudio } from './harness.mjs';

/** A Modbus TCP slave answering every request of function 1 to 6, 15 and 16. */
function slave() {
  const sockets = new Set();
  const server = createServer((sock) => {
    sockets.add(sock);
    sock.on('close', () => sockets.delete(sock));
    sock.on('error', () => {});
    let buf = Buffer.alloc(0);
    sock.on('data', (d) => {
      buf = Buffer.concat([buf, d]);
      while (buf.length >= 8 && buf.length >= 6 + buf.readUInt16BE(4)) {
        const len = buf.readUInt16BE(4);
        const [head, pdu] = [buf.subarray(0, 7), buf.subarray(7, 6 + len)];
        buf = buf.subarray(6 + len);
        const fc = pdu[0];
        const qty = pdu.length >= 5 ? pdu.readUInt16BE(3) : 0;
        let reply;
        if (fc === 1 || fc === 2) reply = Buffer.concat([Buffer.from([fc, Math.ceil(qty / 8)]), Buffer.alloc(Math.ceil(qty / 8))]);
        else if (fc === 3 || fc === 4) reply = Buffer.concat([Buffer.from([fc, qty * 2]), Buffer.alloc(qty * 2)]);
        else reply = pdu.subarray(0, 5);
        const mbap = Buffer.from(head);
        mbap.writeUInt16BE(reply.length + 1, 4);
        sock.write(Buffer.concat([mbap, reply]));
      }
    });
  });
  return {
    listen: (port = 0) => new Promise((ok) => server.listen(port, '127.0.0.1', () => ok(server.address().port))),
    stop: () => new Promise((ok) => {
      server.close(() => ok());
      sockets.forEach((s) => s.destroy());
    }),
  };
}

const plc = slave();
const port = await plc.listen();
let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s), {
  args: ['--io', 'modbus'],
  prepare: (dir) =>
    appendFileSync(`${dir}/alba.toml`, `
[[modbus_device]]
name = "rack"
tcp = "127.0.0.1:${port}"
poll_ms = 50
timeout_ms = 200
retries = 0
map = [
  { remote = "di 0", count = 4, at = "DI:1/0" },
  { remote = "coil 0", count = 6, at = "DO:2/0" },
  { remote = "ir 0", count = 1, at = "AI:3/0" },
]
`),
});

test('a screen says when the I/O link is down, and greys its elements until it is back', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-screens').click();
  await tid('hmi-screen-tank').waitFor();
  for (let i = 0; i < 100 && (await alba.json('/api/tags/S:IOOK')).value !== true; i++) await page.waitForTimeout(50);
  assert.equal(await tid('hmi-io-down').isHidden(), true);
  await plc.stop();
  await tid('hmi-io-down').waitFor({ timeout: 15_000 });
  assert.match(await page.locator('[data-testid="hmi-screen-tank"]').getAttribute('class'), /io-down/);
  await b.shot('screen-io-down');
  await plc.listen(port);
  await tid('hmi-io-down').waitFor({ state: 'hidden', timeout: 15_000 });
  assert.doesNotMatch(await page.locator('[data-testid="hmi-screen-tank"]').getAttribute('class'), /io-down/);
  await plc.stop();
  assert.deepEqual(b.errors, []);
});
