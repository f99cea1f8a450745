// OPC UA client connections in the studio (issue 20, docs/protocols.md "Browse" and
// "Health"): `alba run` on examples/tank serves OPC UA on loopback (security None,
// anonymous); `alba run` on examples/opcsm-tour is its client (an [[opcua_server]]
// "plant" binding the tour's Level to the tank's level sensor). In the net editor the
// Input element's tag picker browses the tank's address space — Objects, Alba, tank,
// Tags — and picks a variable: its node id and the binding line are shown. The status
// bar shows the connection's health, green, then red with the reason when the tank stops.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { appendFileSync } from 'node:fs';
import { join } from 'node:path';
import { createServer } from 'node:net';
import { openBrowser, startAlba } from './harness.mjs';

let remote, alba, b;

/** A free TCP port on loopback. */
const freePort = () =>
  new Promise((ok, fail) => {
    const srv = createServer();
    srv.once('error', fail);
    srv.listen(0, '127.0.0.1', () => {
      const { port } = srv.address();
      srv.close(() => ok(port));
    });
  });

before(async () => {
  const port = await freePort();
  remote = await startAlba('tank', { args: ['--opcua', `127.0.0.1:${port}`] });
  alba = await startAlba('opcsm-tour', {
    prepare: (dir) =>
      appendFileSync(
        join(dir, 'alba.toml'),
        `\n[[opcua_server]]\nname = "plant"\nendpoint = "opc.tcp://127.0.0.1:${port}/"\npublishing_interval_ms = 100\n` +
          `bind = [{ tag = "Level", node = "nsu=urn:alba:tank;s=S_ULT", dir = "in" }]\n`,
      ),
  });
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
  await remote?.stop();
});

test('browse the remote server from the Input element, pick a variable, see the connection health', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/tour.pnml`);
  await tid('net-tour.pnml').waitFor();
  // The connection is healthy: green in the status bar, the endpoint in the tooltip.
  const health = tid('status-remote-plant');
  await page.waitForFunction(() => document.querySelector('[data-testid="status-remote-plant"]')?.dataset.health === 'ok', null, { timeout: 20_000 });
  assert.match(await health.getAttribute('title'), /^plant: connected to opc\.tcp:\/\/127\.0\.0\.1:\d+\/$/);
  // The tank's level reaches the tour's Level through the subscription.
  const level = (await remote.json('/api/tags/S_ULT')).value;
  for (let k = 0; (await alba.json('/api/tags/Level')).value !== level; k++) {
    assert.ok(k < 200, 'Level never took the remote value');
    await new Promise((r) => setTimeout(r, 50));
  }

  // The Input element `read` reads Level: its tag picker browses the server.
  await tid('net-node-read').click();
  assert.equal(await tid('net-prop-prop-source').inputValue(), 'Level');
  await tid('net-browse-opcua-source').click();
  await tid('opcua-browse').waitFor();
  const tree = tid('opcua-tree');
  // Objects is opened at once: the server's own object and Alba's folder.
  await tree.locator('[data-testid="opcua-node-i=2253"]').waitFor();
  const open = async (suffix) => {
    const li = tree.locator(`li[data-node$="${suffix}"]`).first();
    await li.locator(':scope > .opcua-toggle').click();
    await li.locator(':scope > ul > li').first().waitFor();
  };
  await open(';s=Alba');
  await open(';s=Alba/tank');
  await open(';s=Alba/tank/Tags');
  const sensor = tree.locator('li[data-node$=";s=S_ULT"] > .opcua-label');
  assert.match(await sensor.textContent(), /S_ULT\s+Variable · Int16/);
  await sensor.click();
  assert.equal(await tid('opcua-picked-node').inputValue(), 'nsu=urn:alba:tank;s=S_ULT');
  assert.equal(await tid('opcua-tag').inputValue(), 'Level');
  assert.equal(await tid('opcua-binding').inputValue(), '{ tag = "Level", node = "nsu=urn:alba:tank;s=S_ULT", dir = "in" },');
  assert.match(await tid('opcua-how').textContent(), /\[\[opcua_server\]\] named "plant"/);
  await b.shot('opcua-browse');
  await tid('opcua-close').click();
  await tid('opcua-browse').waitFor({ state: 'detached' });
  // Picking changed nothing in the net: the element still reads Level.
  assert.equal(await tid('net-prop-prop-source').inputValue(), 'Level');

  // The tag form has the same dialog, for the tag edited.
  await tid('tab-tags').click();
  await tid('tag-def-edit-Level').click();
  await tid('tag-form-browse-opcua').click();
  await tid('opcua-tree').locator('[data-testid="opcua-node-i=2253"]').waitFor();
  assert.equal(await tid('opcua-tag').inputValue(), 'Level');
  await page.keyboard.press('Escape');
  await tid('opcua-browse').waitFor({ state: 'detached' });
  await tid('tag-form-cancel').click();
  await tid('tab-program-tour.pnml').click();
  await tid('net-node-read').click();

  // The tank stops: the connection turns red, the reason in its tooltip; browsing says why.
  await remote.kill();
  await page.waitForFunction(() => document.querySelector('[data-testid="status-remote-plant"]')?.dataset.health === 'down', null, { timeout: 20_000 });
  assert.match(await health.getAttribute('title'), /^plant: opc\.tcp:\/\/127\.0\.0\.1:\d+\/ is down: .+/);
  await tid('net-browse-opcua-source').click();
  await tid('opcua-error').waitFor();
  assert.match(await tid('opcua-error').textContent(), /OPC UA server plant \(opc\.tcp:\/\/127\.0\.0\.1:\d+\/\): /);
  assert.match(await tid('opcua-server-health').textContent(), /^plant is not connected: /);
  await b.shot('opcua-down');
  await page.keyboard.press('Escape');
  assert.deepEqual(b.errors, []);
});
