// SCADA screens at run time (issue 17): the demo's tank screen
// (examples/tank-plant/hmi/tank.json) follows the running plant: the tank's
// level rises while pump B1 turns, and the Fill request switch writes its tag.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { out, useStudio } from './harness.mjs';

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

test('the screen\'s trend: its time window filled from the history when the screen opens, scale and time labels', async () => {
  const { page, tid } = b;
  const part = (p) => page.locator(`[data-testid="hmi-el-level_trend"] [data-part="${p}"]`);
  // Away for a while (the historian records meanwhile), then back: the line starts in the past at once.
  await tid('tab-tags').click();
  await page.waitForTimeout(6000);
  await tid('tab-screens').click();
  await tid('hmi-screen-tank').waitFor();
  const line = async () => {
    const [x0, , x1] = (await part('line').getAttribute('data-box')).split(',').map(Number);
    const xs = ((await part('line').getAttribute('points')) || '').split(' ').filter(Boolean).map((p) => Number(p.split(',')[0]));
    return { x0, x1, xs };
  };
  // the history's reply (not live values, which only start now) draws the line back at least 6 s of the 120 s window
  const reachesBack = () => {
    const pen = document.querySelector('[data-testid="hmi-el-level_trend"] [data-part="line"]');
    const [x0, , x1] = (pen?.getAttribute('data-box') ?? '0,0,0,0').split(',').map(Number);
    const xs = (pen?.getAttribute('points') ?? '').split(' ').filter(Boolean).map((p) => Number(p.split(',')[0]));
    return xs.length > 0 && Math.min(...xs) < x1 - ((x1 - x0) * 6) / 120;
  };
  await page.waitForFunction(reachesBack, null, { timeout: 10_000 }).catch(() => undefined);
  const l = await line();
  const sixSeconds = ((l.x1 - l.x0) * 6) / 120;
  assert.ok(Math.min(...l.xs) < l.x1 - sixSeconds, `the line reaches back at least 6 s of the 120 s window: ${JSON.stringify({ ...l, xs: l.xs.slice(0, 4) })}`);
  assert.ok(Math.abs(Math.max(...l.xs) - l.x1) < 0.5, 'and runs up to now');
  assert.equal(await part('y-min').textContent(), '0');
  assert.equal(await part('y-max').textContent(), '60');
  const [from, to] = [await part('x-from').textContent(), await part('x-to').textContent()];
  assert.match(from, /^\d{1,2}:\d\d:\d\d\s[AP]M$/);
  assert.match(to, /^\d{1,2}:\d\d:\d\d\s[AP]M$/);
  const secs = (t) => { const [h, m, s2] = t.split(/[:\s]/).map(Number); return h * 3600 + m * 60 + s2; };
  assert.equal((secs(to) - secs(from) + 86400) % 86400 % 43200, 120, `${from} – ${to}: two minutes`);
  await page.locator('[data-testid="hmi-el-level_trend"]').screenshot({ path: `${out}/screen-trend.png` });
  assert.deepEqual(b.errors, []);
});

test('the designer: build a screen by drag and drop, arrange, undo/redo, a located error on its element, save, reload, and run it', async () => {
  const { page, tid } = b;
  page.removeAllListeners('dialog');
  page.once('dialog', (d) => d.accept('plant2'));
  await tid('hmi-new').click();
  await tid('hmi-designer').waitFor();
  page.on('dialog', (d) => d.accept());
  const els = () => page.locator('[data-testid="hmi-design-svg"] g.hmi-el');
  const setField = async (testid, value) => {
    await tid(testid).fill(value);
    await tid(testid).press('Enter');
  };
  // A tank bound to the level: dragged from the palette, filled by Nivel_L (0 to 60 L).
  await tid('hmi-add-tank').dragTo(tid('hmi-canvas'), { targetPosition: { x: 150, y: 200 } });
  await tid('hmi-props').getByText('tank1 (tank)').waitFor();
  await tid('hmi-prop-anim-add').selectOption('fill');
  await setField('hmi-prop-anim-tag-0', 'Nivel_L');
  // the animation's own form: numbers, a choice (the JSON stays as the expert view)
  await setField('hmi-prop-anim-0-min', '0');
  await setField('hmi-prop-anim-0-max', '60');
  await tid('hmi-prop-anim-0-direction').selectOption('up');
  // a move shows where it ends while the element is selected; removed, its preview goes
  await tid('hmi-prop-anim-add').selectOption('move');
  await setField('hmi-prop-anim-1-dx', '200');
  await tid('hmi-preview-tank1').locator('[data-part="move-ghost"]').waitFor();
  assert.equal(await tid('hmi-preview-tank1').locator('[data-part="move-ghost"]').getAttribute('x'), '200');
  await b.shot('designer-animation-form-move-preview');
  await tid('hmi-prop-anim-remove-1').click();
  await tid('hmi-preview-tank1').waitFor({ state: 'detached' });
  // A pump that rotates while B1 runs; its tag first mistyped.
  await tid('hmi-add-pump').dragTo(tid('hmi-canvas'), { targetPosition: { x: 300, y: 120 } });
  await tid('hmi-props').getByText('pump1 (pump)').waitFor();
  await tid('hmi-prop-anim-add').selectOption('rotate');
  await setField('hmi-prop-anim-tag-0', 'Bomba9');
  assert.equal(await tid('hmi-prop-anim-tag-0').getAttribute('class'), 'invalid', 'the picker marks a name that is not a tag');
  // A button that starts filling: it sets Llenar.
  await tid('hmi-add-button').dragTo(tid('hmi-canvas'), { targetPosition: { x: 300, y: 260 } });
  await tid('hmi-props').getByText('button1 (button)').waitFor();
  await setField('hmi-prop-label', 'Start');
  await tid('hmi-prop-action-kind').selectOption('set');
  await setField('hmi-prop-action-tag', 'Llenar');
  assert.equal(await els().count(), 3);
  // Undo takes back the last actions one by one, redo puts them back.
  await tid('hmi-undo').click();
  await tid('hmi-undo').click();
  await tid('hmi-undo').click();
  assert.equal(await els().count(), 3, 'three undos take back the tag, the action and the label');
  assert.equal(await tid('hmi-el-button1').textContent(), 'button');
  await tid('hmi-undo').click();
  assert.equal(await els().count(), 2, 'the fourth, the button');
  await tid('hmi-redo').click();
  await tid('hmi-redo').click();
  await tid('hmi-redo').click();
  await tid('hmi-redo').click();
  await tid('hmi-el-button1').getByText('Start').waitFor();
  // A rubber band around the tank and the pump selects both; align their tops, group them.
  const box = await tid('hmi-canvas').boundingBox();
  await page.mouse.move(box.x + 15, box.y + 15);
  await page.mouse.down();
  await page.mouse.move(box.x + 420, box.y + 200, { steps: 5 });
  await page.mouse.up();
  await tid('hmi-props').getByText('2 elements selected').waitFor();
  await tid('hmi-align-top').click();
  await tid('hmi-group').click();
  await tid('hmi-zoom-in').click();
  // A button that goes to the tank screen.
  await tid('hmi-add-button').dragTo(tid('hmi-canvas'), { targetPosition: { x: 500, y: 260 } });
  await tid('hmi-props').getByText('button2 (button)').waitFor();
  await setField('hmi-prop-label', 'To tank');
  await tid('hmi-prop-action-kind').selectOption('navigate');
  await tid('hmi-prop-action-screen').selectOption('tank');
  // Save: refused, the unknown tag drawn on the pump and listed with its place.
  await tid('hmi-save').click();
  await tid('hmi-problem-0').waitFor();
  assert.match(await tid('hmi-problem-0').textContent(), /^\d+:\d+ `pump1`: animation `rotate`: unknown tag `Bomba9`/);
  await tid('hmi-error-pump1').waitFor();
  await b.shot('screen-designer');
  // Fixed from the problem (a click selects the element): its outline and its entry go at once, before Save.
  await tid('hmi-problem-0').click();
  await tid('hmi-prop-error').filter({ hasText: 'unknown tag `Bomba9`' }).waitFor();
  await setField('hmi-prop-anim-tag-0', 'Bomba1');
  await tid('hmi-error-pump1').waitFor({ state: 'detached' });
  await tid('hmi-problem-0').waitFor({ state: 'detached' });
  assert.equal(await tid('hmi-prop-error').isHidden(), true);
  assert.ok(!JSON.stringify(await alba.json('/api/screens')).includes('plant2'), 'checking saved nothing');
  // A second animation on the pump: green while B1 runs.
  await tid('hmi-prop-anim-add').selectOption('color');
  await setField('hmi-prop-anim-tag-1', 'Bomba1');
  await tid('hmi-prop-anim-1-on-swatch').fill('#43a047');
  await page.waitForFunction(() => document.querySelector('[data-testid="hmi-prop-anim-1-on"]')?.value === '#43a047');
  await tid('hmi-save').click();
  await tid('toast-info').filter({ hasText: 'plant2 saved' }).waitFor();
  // the success took the failed save's place
  assert.equal(await tid('toast-error').filter({ hasText: 'plant2 not saved' }).count(), 0);
  // The group saved as a symbol of the user's, then inserted from the palette: copies, grouped.
  page.removeAllListeners('dialog');
  page.once('dialog', (d) => d.accept('tank_and_pump'));
  await tid('hmi-el-tank1').click();
  await tid('hmi-save-symbol').click();
  await tid('hmi-symbol-tank_and_pump').click();
  await page.waitForFunction(() => document.querySelectorAll('[data-testid="hmi-design-svg"] g.hmi-el').length === 6);
  await tid('hmi-el-tank2').waitFor();
  await tid('hmi-props').getByText('2 elements selected').waitFor();
  assert.deepEqual((await alba.json('/api/symbols')), ['tank_and_pump']);
  await tid('hmi-undo').click();
  assert.equal(await els().count(), 4);
  page.on('dialog', (d) => d.accept());
  const saved = await alba.json('/api/screens/plant2');
  const byId = Object.fromEntries(saved.elements.map((e) => [e.id, e]));
  assert.deepEqual(byId.tank1.animations, [{ kind: 'fill', tag: 'Nivel_L', min: 0, max: 60, direction: 'up' }]);
  assert.deepEqual(byId.pump1.animations, [{ kind: 'rotate', tag: 'Bomba1', speed: 1 }, { kind: 'color', tag: 'Bomba1', on: '#43a047', off: '#9ea3a8' }]);
  assert.deepEqual(byId.button2.action, { kind: 'navigate', tag: null, value: null, min: null, max: null, screen: 'tank' });
  assert.equal(byId.button1.action.kind, 'set');
  assert.equal(byId.button1.action.tag, 'Llenar');
  assert.equal(byId.tank1.y, byId.pump1.y, 'aligned tops');
  assert.ok(byId.tank1.group && byId.tank1.group === byId.pump1.group, 'grouped');
  // Reload the studio, open the screen at run time: the button starts B1, the pump turns, the tank fills.
  await page.reload();
  await tid('tab-screens').click();
  await tid('hmi-screen').selectOption('plant2');
  await tid('hmi-screen-plant2').waitFor();
  const level = () => page.evaluate(() => Number(document.querySelector('[data-testid="hmi-el-tank1"] [data-part="level"]').getAttribute('height')));
  await tid('hmi-el-button1').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="hmi-el-pump1"] [data-part="rotor"]')?.classList.contains('hmi-spin'));
  // the rotor really turns (an SVG animation at its speed: its angle on screen changes)
  const angle = () => page.evaluate(() => {
    const m = document.querySelector('[data-testid="hmi-el-pump1"] [data-part="rotor"]').getCTM();
    return Math.atan2(m.b, m.a);
  });
  const a0 = await angle();
  await page.waitForFunction((a0) => {
    const m = document.querySelector('[data-testid="hmi-el-pump1"] [data-part="rotor"]').getCTM();
    return Math.abs(Math.atan2(m.b, m.a) - a0) > 0.05;
  }, a0);
  const first = await level();
  await page.waitForFunction((h) => Number(document.querySelector('[data-testid="hmi-el-tank1"] [data-part="level"]').getAttribute('height')) > h, first);
  await page.waitForFunction(() => document.querySelector('[data-testid="hmi-el-pump1"] [data-part="fill"]')?.getAttribute('fill') === '#43a047');
  await b.shot('screen-plant2');
  // The navigation button opens the tank screen.
  await tid('hmi-el-button2').click();
  await tid('hmi-screen-tank').waitFor();
  assert.equal(await tid('hmi-screen').inputValue(), 'tank');
  assert.deepEqual(b.errors, []);
});
