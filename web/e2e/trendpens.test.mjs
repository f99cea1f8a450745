// End-to-end test of a screen trend with three pens (issue 35, point 1), on a
// copy of examples/tank-plant with a screen of its own (hmi/pens.json): the
// server takes `props.pens`, the studio subscribes to the three tags and
// draws each as its line, in its colour, on one scale, with the legend.
// Screenshot: trend-three-pens.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { openBrowser, startAlba } from './harness.mjs';

const SCREEN = {
  schema: 1,
  width: 640,
  height: 360,
  elements: [
    {
      id: 'levels', type: 'trend', x: 20, y: 30, w: 600, h: 300,
      props: {
        label: 'Tank, container and level', window_s: 30,
        pens: [{ tag: 'Vol_L', color: '#1565c0' }, { tag: 'Cont_L', color: '#e8710a' }, { tag: 'Nivel_m' }],
      },
    },
  ],
};

let alba;
before(async () => {
  alba = await startAlba('tank-plant', { prepare: (dir) => writeFileSync(join(dir, 'hmi', 'pens.json'), JSON.stringify(SCREEN, null, 2)) });
});
after(async () => {
  await alba?.stop();
});

test('a trend with three pens: each tag its line and colour, one scale, a legend', async () => {
  const b = await openBrowser({ viewport: { width: 1024, height: 768 } });
  const { page, tid } = b;
  try {
    await page.goto(`${alba.url}#/screens`);
    await tid('hmi-screen').waitFor();
    await tid('hmi-screen').selectOption('pens');
    await tid('hmi-screen-pens').waitFor();
    const parts = ['line', 'line-2', 'line-3'];
    await page.waitForFunction(
      (ps) => ps.every((p) => (document.querySelector(`[data-testid="hmi-el-levels"] [data-part="${p}"]`)?.getAttribute('points') ?? '').split(' ').length >= 2),
      parts,
      { timeout: 15_000 },
    );
    const drawn = await page.evaluate((ps) => ps.map((p) => document.querySelector(`[data-testid="hmi-el-levels"] [data-part="${p}"]`).getAttribute('stroke')), parts);
    assert.deepEqual(drawn, ['#1565c0', '#e8710a', '#2e7d32']);
    const legend = await page.evaluate(() => [1, 2, 3].map((k) => document.querySelector(`[data-testid="hmi-el-levels"] [data-part="pen-${k}"]`)?.textContent));
    assert.deepEqual(legend, ['Vol_L', 'Cont_L', 'Nivel_m']);
    // one scale: the tank's litres (up to 60) and its level in metres (up to 1.5) share it
    const max = Number(await page.locator('[data-testid="hmi-el-levels"] [data-part="y-max"]').textContent());
    assert.ok(max >= 30, `the scale holds the litres: ${max}`);
    await page.waitForTimeout(1500);
    await b.shot('trend-three-pens');
  } finally {
    await b.close();
  }
});
