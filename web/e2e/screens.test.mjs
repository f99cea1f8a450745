// SCADA screens at run time (issue 17): the demo's tank screen
// (examples/tank-plant/hmi/tank.json) follows the running plant: the tank's
// level rises while pump B1 turns, and the Fill request switch writes its tag.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s));

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

test('the designer: drag, set properties, undo and redo, save with a located error, then the saved screen runs', async () => {
  const { page, tid } = b;
  await tid('hmi-edit').click();
  await tid('hmi-designer').waitFor();
  const count = () => page.locator('[data-testid="hmi-design-svg"] g.hmi-el').count();
  const n0 = await count();
  // Drag a pump from the palette onto the screen.
  await tid('hmi-add-pump').dragTo(tid('hmi-canvas'), { targetPosition: { x: 300, y: 150 } });
  await page.waitForFunction((n) => document.querySelectorAll('[data-testid="hmi-design-svg"] g.hmi-el').length === n + 1, n0);
  await tid('hmi-props').getByText('pump1 (pump)').waitFor();
  // Undo removes it, redo puts it back.
  await tid('hmi-undo').click();
  assert.equal(await count(), n0);
  await tid('hmi-redo').click();
  assert.equal(await count(), n0 + 1);
  // A rotate animation on a tag that does not exist: Save is refused with the place.
  await tid('hmi-prop-anim-kind').selectOption('rotate');
  await tid('hmi-prop-anim-tag').fill('Bomba9');
  await tid('hmi-prop-anim-tag').press('Enter');
  await tid('hmi-save').click();
  await tid('hmi-problem-0').waitFor();
  assert.match(await tid('hmi-problem-0').textContent(), /^\d+:\d+ `pump1`: animation `rotate`: unknown tag `Bomba9`/);
  await b.shot('screen-designer');
  // Fixed, saved, and the runtime view shows it turning with B2.
  await tid('hmi-prop-anim-tag').fill('Bomba2');
  await tid('hmi-prop-anim-tag').press('Enter');
  await tid('hmi-save').click();
  await tid('toast-info').filter({ hasText: 'tank saved' }).waitFor();
  const saved = await alba.json('/api/screens/tank');
  const pump = saved.elements.find((e) => e.id === 'pump1');
  assert.deepEqual(pump.animations, [{ kind: 'rotate', tag: 'Bomba2', speed: 1 }]);
  await tid('hmi-close').click();
  await tid('hmi-el-pump1').waitFor();
  await b.shot('screen-designer-saved');
  assert.deepEqual(b.errors, []);
});
