// The operator elements' properties as OPCSM defines them (issue 34, point 10; docs/nets.md
// "The operator elements' properties") on a copy of examples/opcsm-tour whose widgets are
// given some: the Display in hex with a unit and a larger font, the Plot between 0 and 100
// with a title and a unit, the Label in white on navy, centred and without a border; a
// double-click latches the Button's tag at true, and the next press releases it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('opcsm-tour', (s) => ({ alba, b } = s), {
  prepare: (dir) => {
    const f = join(dir, 'tour.pnml');
    const text = readFileSync(f, 'utf8')
      .replace('kind="display" tag="Doubled" x="200" y="260"', 'kind="display" tag="Doubled" x="200" y="260" format="hex" unit="kg" font_size="14"')
      .replace('kind="plot" tag="Level" x="340" y="260"', 'kind="plot" tag="Level" x="340" y="260" autoscale="false" min="0" max="100" title="Tank level" unit="%"')
      .replace('kind="label" x="60" y="330"', 'kind="label" x="60" y="330" color="#ffffff" background="navy" align="center" border="false" font_size="13"');
    writeFileSync(f, text);
  },
});

const put = (name, value) =>
  alba.api(`/api/tags/${name}`, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });

async function tagIs(name, v) {
  for (let k = 0; k < 500; k++) {
    if ((await alba.json(`/api/tags/${name}`)).value === v) return;
    await new Promise((r) => setTimeout(r, 20));
  }
  assert.fail(`${name} never became ${v}`);
}

test('a net’s widgets show their properties, and a double-click latches a Button', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/tour.pnml`);
  await tid('net-tour.pnml').waitFor();
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'live');
  const valueIs = (id, text) =>
    page.waitForFunction(([id, text]) => document.querySelector(`[data-testid="net-widget-${id}"] .net-widget-value`)?.textContent === text, [id, text]);
  assert.equal((await put('Doubled', 255)).status, 200);
  await valueIs('w_doubled', '16#FF kg');
  for (const v of [20, 80, 35]) {
    assert.equal((await put('Level', v)).status, 200);
    await valueIs('w_level', `${v} %`);
  }
  assert.equal(await tid('net-widget-w_level').locator('.net-widget-caption').textContent(), 'Tank level');
  assert.equal(await tid('net-widget-w_level').locator('.net-plot-scale').textContent(), '0…100 %');
  assert.equal(await tid('net-widget-w_note').locator('rect').getAttribute('style'), 'fill:navy');
  assert.match(await tid('net-widget-w_note').getAttribute('class'), /no-border/);
  await b.shot('net-widgets-styled');
  // A double-click latches Start at true: it stays true after the mouse is released.
  const box = await tid('net-widget-w_start').locator('.net-widget-box').boundingBox();
  await page.mouse.dblclick(box.x + box.width / 2, box.y + box.height / 2);
  await tagIs('Start', true);
  await page.waitForTimeout(300);
  assert.equal((await alba.json('/api/tags/Start')).value, true, 'latched');
  assert.match(await tid('net-widget-w_start').getAttribute('class'), /latched/);
  await b.shot('net-widget-button-latched');
  // The next press releases it.
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await tagIs('Start', false);
  assert.doesNotMatch(await tid('net-widget-w_start').getAttribute('class'), /latched/);
  assert.deepEqual(b.errors, []);
});
