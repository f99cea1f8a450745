// SCADA screens at run time (issue 17): the demo's tank screen
// (examples/tank-plant/hmi/tank.json) follows the running plant: the tank's
// level rises while pump B1 turns, and the Fill request switch writes its tag.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, startAlba } from './harness.mjs';

let alba, b;

before(async () => {
  alba = await startAlba('tank-plant');
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

test('the tank screen follows the plant and writes through its switch', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-screens').click();
  await tid('hmi-screen-tank').waitFor();
  const level = () => page.evaluate(() => Number(document.querySelector('[data-testid="hmi-el-tank"] [data-part="level"]').getAttribute('height')));
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="hmi-el-tank"] [data-part="level"]')?.getAttribute('height')) > 0);
  const first = await level();
  // B1 fills the tank: the level rises, the pump turns, the output box shows the litres.
  await page.waitForFunction((h) => Number(document.querySelector('[data-testid="hmi-el-tank"] [data-part="level"]').getAttribute('height')) > h, first);
  assert.equal(await page.locator('[data-testid="hmi-el-b1"] [data-part="rotor"]').getAttribute('class'), 'hmi-spin');
  assert.match(await page.locator('[data-testid="hmi-el-level"] [data-part="text"]').textContent(), /^\d+(\.\d+)?$/);
  // Only what the screen shows is subscribed, and the switch writes Llenar.
  const before = (await alba.json('/api/tags/Llenar')).value;
  await tid('hmi-el-fill').click();
  let now = before;
  for (let i = 0; i < 50 && now === before; i++) {
    await page.waitForTimeout(100);
    now = (await alba.json('/api/tags/Llenar')).value;
  }
  assert.equal(now, !before, 'the switch toggled Llenar');
  await b.shot('screen-tank');
  assert.deepEqual(b.errors, []);
});
