// The operator elements of a net's live view (issue 20, docs/nets.md "Live view") on a
// copy of examples/opcsm-tour: its Display shows Doubled, its Plot draws the last values
// of Level, its Label shows its caption, and its Button writes Start true while pressed
// and false when released — which sends the token past the `go` condition.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('opcsm-tour', (s) => ({ alba, b } = s));

const put = (name, value) =>
  alba.api(`/api/tags/${name}`, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });

/** Waits (up to 10 s) until the tag `name` has the value `v` on the server. */
async function tagIs(name, v) {
  for (let k = 0; k < 500; k++) {
    if ((await alba.json(`/api/tags/${name}`)).value === v) return;
    await new Promise((r) => setTimeout(r, 20));
  }
  assert.fail(`${name} never became ${v}`);
}

test('a net’s Display, Plot and Label show live values and its Button writes its tag', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/tour.pnml`);
  await tid('net-tour.pnml').waitFor();
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'live');
  const value = (id) => page.evaluate((id) => document.querySelector(`[data-testid="net-widget-${id}"] .net-widget-value`)?.textContent, id);
  const valueIs = (id, text) =>
    page.waitForFunction(([id, text]) => document.querySelector(`[data-testid="net-widget-${id}"] .net-widget-value`)?.textContent === text, [id, text]);

  // The Display follows its tag.
  assert.equal((await put('Doubled', 12.5)).status, 200);
  await valueIs('w_doubled', '12.5');
  // The Plot draws each new value of Level (and shows the last one).
  for (const v of [20, 80, 35]) {
    assert.equal((await put('Level', v)).status, 200);
    await valueIs('w_level', String(v));
  }
  const points = await page.evaluate(() => document.querySelector('[data-testid="net-widget-w_level"] .net-plot-line')?.getAttribute('points') ?? '');
  const ys = points.trim().split(/\s+/).map((p) => Number(p.split(',')[1]));
  assert.ok(ys.length >= 3, `the plot has the last values: ${points}`);
  // the last three points: 20, 80, 35 — 80 the highest (smallest y), 20 the lowest
  const [a, z, c] = ys.slice(-3);
  assert.ok(z < c && c < a, `the plot's shape follows 20, 80, 35: ${points}`);
  // The Label shows its caption and no value.
  assert.equal(await tid('net-widget-w_note').locator('.net-widget-caption').textContent(), 'The elements of OPCSM, one of each kind');
  assert.equal(await value('w_note'), '');
  await b.shot('net-widgets-live');

  // The Button: Start true while pressed, false when released; the token passes `go`.
  await tagIs('tour.go', 1);
  const box = await tid('net-widget-w_start').locator('.net-widget-box').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await tagIs('Start', true);
  await valueIs('w_start', '1');
  // The token passes `go`; the history lists it as a firing, or — when the WebSocket
  // coalesced that scan away on a loaded machine (docs/nets.md, "history") — as the
  // marking change of the transition that held it.
  await tagIs('tour.go', 0);
  await page.waitForFunction(() => /fired go|go −1/.test(document.querySelector('[data-testid="net-history"]')?.textContent ?? ''));
  await b.shot('net-widget-button-pressed');
  await page.mouse.up();
  await tagIs('Start', false);
  await valueIs('w_start', '0');
  // Pressing it wrote the tag: it neither selected nor moved the widget.
  assert.doesNotMatch(await tid('net-widget-w_start').getAttribute('class'), /selected/);
  assert.equal((await alba.json('/api/programs/tour.pnml')).text.includes('x="60" y="260">Start</widget>'), true);
  assert.deepEqual(b.errors, []);
});
