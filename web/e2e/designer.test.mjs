// The SCADA designer's editors (issue 35): a polygon drawn by its vertices and
// edited by dragging them, several elements edited together, an image
// uploaded into the project and seen after a reload.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s));

// a 40×30 red PNG
const PNG = Buffer.from('iVBORw0KGgoAAAANSUhEUgAAACgAAAAeCAIAAADRv8uKAAAALElEQVR4nO3NMQ0AAAgDsClBCf6DLGTA0aR/M10nIhaLxWKxWCwWi8Xiv/ECIbNPrNXtoNkAAAAASUVORK5CYII=', 'base64');

/** The page position of the screen point (x, y) of the designer's drawing. */
async function at(page, x, y) {
  return page.evaluate(([x, y]) => {
    const m = document.querySelector('[data-testid="hmi-design-svg"]').getScreenCTM();
    return { x: m.a * x + m.c * y + m.e, y: m.b * x + m.d * y + m.f };
  }, [x, y]);
}

const pointsOf = (page, id) => page.evaluate((id) => document.querySelector(`[data-testid="hmi-el-${id}"] [data-part="fill"]`).getAttribute('points'), id);

async function newScreen(page, tid, name) {
  await page.goto(alba.url);
  await tid('tab-screens').click();
  await tid('hmi-new').waitFor();
  page.removeAllListeners('dialog');
  page.once('dialog', (d) => d.accept(name));
  await tid('hmi-new').click();
  await tid('hmi-designer').waitFor();
  page.on('dialog', (d) => d.accept());
}

test('draw a polygon by vertices, then drag, insert and remove vertices (undoable)', async () => {
  const { page, tid } = b;
  await newScreen(page, tid, 'shapes');
  await page.waitForTimeout(300); // the first fit
  await tid('hmi-draw-polygon').click();
  await tid('hmi-draw-overlay').waitFor();
  for (const [x, y] of [[100, 100], [300, 100], [300, 250]]) {
    const p = await at(page, x, y);
    await page.mouse.click(p.x, p.y);
  }
  const last = await at(page, 100, 250);
  await page.mouse.dblclick(last.x, last.y);
  await tid('hmi-el-polygon1').waitFor();
  await tid('hmi-draw-overlay').waitFor({ state: 'detached' });
  assert.equal(await pointsOf(page, 'polygon1'), '0,0 200,0 200,150 0,150', 'four vertices, the double-click\'s repeat dropped');
  assert.equal(await tid('hmi-prop-el-points').inputValue(), '0,0 200,0 200,150 0,150', 'the form shows them too');
  // the cursor's x/y in the status line
  const probe = await at(page, 420, 330);
  await page.mouse.move(probe.x, probe.y);
  assert.match(await tid('hmi-status').textContent(), /x 4[12]\d\s+y 3[23]\d/);
  // drag vertex 2 to (340, 300) on the grid: the box grows with it
  const v2 = await tid('hmi-vertex-2').boundingBox();
  await page.mouse.move(v2.x + v2.width / 2, v2.y + v2.height / 2);
  await page.mouse.down();
  const to = await at(page, 342, 298);
  await page.mouse.move(to.x, to.y, { steps: 5 });
  await b.shot('designer-polygon-vertex-drag');
  await page.mouse.up();
  assert.equal(await pointsOf(page, 'polygon1'), '0,0 200,0 240,200 0,150');
  // a double-click on edge 0 (the top) inserts a vertex there
  const mid = await at(page, 200, 100);
  await page.mouse.dblclick(mid.x, mid.y);
  await tid('hmi-vertex-4').waitFor();
  assert.equal(await pointsOf(page, 'polygon1'), '0,0 100,0 200,0 240,200 0,150');
  // the new vertex dragged up: the box grows upwards
  const v1 = await tid('hmi-vertex-1').boundingBox();
  await page.mouse.move(v1.x + v1.width / 2, v1.y + v1.height / 2);
  await page.mouse.down();
  const up = await at(page, 200, 60);
  await page.mouse.move(up.x, up.y, { steps: 5 });
  await page.mouse.up();
  assert.equal(await pointsOf(page, 'polygon1'), '0,40 100,0 200,40 240,240 0,190');
  await b.shot('designer-polygon-edited');
  // right-click removes a vertex; Delete removes the one last grabbed
  await tid('hmi-vertex-3').click({ button: 'right' });
  await tid('hmi-vertex-4').waitFor({ state: 'detached' });
  assert.equal(await pointsOf(page, 'polygon1'), '0,40 100,0 200,40 0,190');
  await tid('hmi-vertex-1').click();
  await page.keyboard.press('Delete');
  assert.equal(await pointsOf(page, 'polygon1'), '0,0 200,0 0,150', 'Delete took the vertex, not the polygon');
  // three are kept
  await tid('hmi-vertex-0').click({ button: 'right' });
  await tid('toasts').getByText('A polygon keeps at least 3 vertices.').waitFor();
  assert.equal(await tid('hmi-vertex-2').count(), 1);
  // each was one undo step
  await tid('hmi-undo').click();
  assert.equal(await pointsOf(page, 'polygon1'), '0,40 100,0 200,40 0,190');
  await tid('hmi-undo').click();
  await tid('hmi-undo').click();
  assert.equal(await pointsOf(page, 'polygon1'), '0,0 100,0 200,0 240,200 0,150', 'back before the vertex was moved up');
  await tid('hmi-redo').click();
  // a polyline drawn with Enter
  await tid('hmi-draw-line').click();
  for (const [x, y] of [[500, 100], [600, 150], [700, 100]]) {
    const p = await at(page, x, y);
    await page.mouse.click(p.x, p.y);
  }
  await page.keyboard.press('Enter');
  await tid('hmi-el-line1').waitFor();
  assert.equal(await pointsOf(page, 'line1'), '0,0 100,50 200,0');
  // saved: the server takes the vertices
  await tid('hmi-save').click();
  await tid('toasts').getByText('shapes saved').waitFor();
  const saved = await alba.json('/api/screens/shapes');
  const poly = saved.elements.find((e) => e.id === 'polygon1');
  assert.deepEqual(poly.props.points, [[0, 40], [100, 0], [200, 40], [240, 240], [0, 190]]);
  assert.deepEqual([poly.x, poly.y, poly.w, poly.h], [100, 60, 240, 240]);
  assert.deepEqual(b.errors, []);
});

test('several selected elements edited together where they agree', async () => {
  const { page, tid } = b;
  await tid('hmi-draw-polygon').waitFor();
  for (const x of [100, 250, 400]) {
    await tid('hmi-add-rectangle').click();
    await tid('hmi-prop-x').fill(String(x));
    await tid('hmi-prop-x').press('Enter');
    await tid('hmi-prop-y').fill('420');
    await tid('hmi-prop-y').press('Enter');
  }
  await tid('hmi-el-rectangle1').click();
  await tid('hmi-el-rectangle2').click({ modifiers: ['Shift'] });
  await tid('hmi-el-rectangle3').click({ modifiers: ['Shift'] });
  await tid('hmi-props').getByText('3 elements selected').waitFor();
  await tid('hmi-multi-color').fill('#2e7d32');
  await tid('hmi-multi-color').press('Enter');
  const fills = () => page.evaluate(() => ['rectangle1', 'rectangle2', 'rectangle3'].map((id) => document.querySelector(`[data-testid="hmi-el-${id}"] [data-part="fill"]`).getAttribute('fill')));
  assert.deepEqual(await fills(), ['#2e7d32', '#2e7d32', '#2e7d32']);
  assert.equal(await tid('hmi-multi-color').inputValue(), '#2e7d32', 'the value they now agree on');
  await b.shot('designer-multi-selection-form');
  // one undo step for the three
  await tid('hmi-undo').click();
  assert.ok((await fills()).every((f) => f !== '#2e7d32'));
  // with the polygon too: only what a polygon and a rectangle share
  await tid('hmi-el-polygon1').click({ modifiers: ['Shift'] });
  await tid('hmi-props').getByText('4 elements selected').waitFor();
  assert.equal(await tid('hmi-multi-points').count(), 0, 'no vertices for several');
  assert.equal(await tid('hmi-multi-color').count(), 1);
  assert.deepEqual(b.errors, []);
});

test('rulers, a guide dragged out of one, and an element snapping to it', async () => {
  const { page, tid } = b;
  await page.keyboard.press('Escape');
  await tid('hmi-rulers').click();
  await tid('hmi-ruler-top').waitFor();
  await page.waitForTimeout(200);
  // a horizontal guide out of the top ruler, Alt held: off the grid, at y 503
  const r = await tid('hmi-ruler-top').boundingBox();
  const g = await at(page, 700, 503);
  await page.mouse.move(g.x, r.y + r.height / 2);
  await page.mouse.down();
  await page.keyboard.down('Alt');
  await page.mouse.move(g.x, g.y, { steps: 6 });
  await page.mouse.up();
  await page.keyboard.up('Alt');
  assert.equal(await tid('hmi-guide-h-0').getAttribute('data-at'), '503');
  // rectangle1 (y 420, 60 high) dragged down 20: the grid puts its bottom at 500, the guide pulls it to 503
  const c = await at(page, 130, 450);
  const d = await at(page, 131, 471);
  await page.mouse.move(c.x, c.y);
  await page.mouse.down();
  await page.mouse.move(d.x, d.y, { steps: 5 });
  await page.mouse.up();
  await tid('hmi-props').getByText('rectangle1 (rectangle)').waitFor();
  assert.equal(await tid('hmi-prop-y').inputValue(), '443');
  await b.shot('designer-rulers-guide');
  // dropped back on the ruler, the guide goes
  const gl = await at(page, 700, 503);
  const back = await at(page, 700, -10);
  await page.mouse.move(gl.x, gl.y);
  await page.mouse.down();
  await page.mouse.move(back.x, back.y, { steps: 4 });
  await page.mouse.up();
  assert.equal(await tid('hmi-guide-h-0').count(), 0);
  // zoomed in and scrolled, the rulers stay at the canvas's top and left edges
  await tid('hmi-canvas').focus();
  for (let k = 0; k < 3; k++) await page.keyboard.press('+');
  await tid('hmi-canvas').evaluate((c) => ((c.scrollTop = 300), (c.scrollLeft = 200)));
  await page.waitForTimeout(150);
  const edge = await tid('hmi-canvas').evaluate((c) => { const r = c.getBoundingClientRect(); return { x: r.left + c.clientLeft, y: r.top + c.clientTop, scrolled: [c.scrollLeft, c.scrollTop] }; });
  assert.deepEqual(edge.scrolled, [200, 300], 'the canvas scrolls when zoomed in');
  const top = await tid('hmi-ruler-top').boundingBox();
  const left = await tid('hmi-ruler-left').boundingBox();
  assert.ok(Math.abs(top.y - edge.y) < 1.5, `the top ruler at the canvas's top: ${top.y} vs ${edge.y}`);
  assert.ok(Math.abs(left.x - edge.x) < 1.5, `the left ruler at the canvas's left: ${left.x} vs ${edge.x}`);
  await b.shot('designer-rulers-scrolled');
  await page.keyboard.press('0');
  await tid('hmi-rulers').click();
  await tid('hmi-ruler-top').waitFor({ state: 'detached' });
  assert.deepEqual(b.errors, []);
});

test('upload an image and see it after a reload; an oversize one is refused with the 413 message', async () => {
  const { page, tid } = b;
  await tid('hmi-upload-file').setInputFiles({ name: 'logo plant.png', mimeType: 'image/png', buffer: PNG });
  await tid('hmi-el-image1').waitFor();
  await tid('toasts').getByText('logo_plant.png uploaded').waitFor();
  const img = tid('hmi-el-image1').locator('[data-part="image"]');
  assert.equal(await img.getAttribute('href'), '/api/assets/logo_plant.png');
  assert.equal(await img.getAttribute('width'), '40', 'its own size');
  // scaled by percent in its form
  await tid('hmi-prop-el-scale').fill('200');
  await tid('hmi-prop-el-scale').press('Enter');
  assert.equal(await img.getAttribute('width'), '80');
  // the form offers the project's images: it shows the one it has
  assert.equal(await tid('hmi-asset-pick').inputValue(), 'assets/logo_plant.png');
  await tid('hmi-asset-thumb').waitFor();
  // a new image element takes an existing image from the picker (no upload)
  await tid('hmi-add-image').click();
  await tid('hmi-el-image2').waitFor();
  await tid('hmi-props').getByText('image2 (image)').waitFor();
  assert.deepEqual(await tid('hmi-asset-pick').locator('option').allTextContents(), ['(choose an image)', 'logo_plant.png']);
  await tid('hmi-asset-pick').selectOption('assets/logo_plant.png');
  assert.equal(await tid('hmi-el-image2').locator('[data-part="image"]').getAttribute('href'), '/api/assets/logo_plant.png');
  await b.shot('designer-image-picker');
  await tid('hmi-canvas').focus();
  await page.keyboard.press('Delete');
  await tid('hmi-el-image2').waitFor({ state: 'detached' });
  // too big: the server's 413, said in the toast; nothing added
  await tid('hmi-upload-file').setInputFiles({ name: 'big.png', mimeType: 'image/png', buffer: Buffer.concat([PNG, Buffer.alloc(3 * 1024 * 1024)]) });
  await tid('toasts').getByText(/big\.png not uploaded: .*too large/).waitFor();
  assert.equal(await tid('hmi-el-image2').count(), 0);
  await tid('hmi-save').click();
  await tid('toasts').getByText('shapes saved').waitFor();
  // after a reload, on the running screen: the image is there and loads
  await page.reload();
  await tid('tab-screens').click();
  await tid('hmi-screen').selectOption('shapes');
  await tid('hmi-screen-shapes').waitFor();
  const shown = page.locator('[data-testid="hmi-el-image1"] [data-part="image"]').first();
  await shown.waitFor();
  assert.equal(await shown.getAttribute('href'), '/api/assets/logo_plant.png');
  const got = await page.evaluate(async () => {
    const r = await fetch('/api/assets/logo_plant.png');
    const bmp = await createImageBitmap(await r.blob());
    return { status: r.status, type: r.headers.get('content-type'), w: bmp.width };
  });
  assert.deepEqual(got, { status: 200, type: 'image/png', w: 40 });
  await b.shot('designer-image-after-reload');
  assert.deepEqual(b.errors, []);
});

test('make a template and two instances; the instances follow the template and their own prefix', async () => {
  const { page, tid } = b;
  await newScreen(page, tid, 'faceplates');
  const answer = async (value, act) => {
    page.removeAllListeners('dialog');
    const done = new Promise((res) => page.once('dialog', (d) => d.accept(value).then(res)));
    await act();
    await done;
    page.on('dialog', (d) => d.accept());
  };
  const setField = async (testid, value) => {
    await tid(testid).fill(value);
    await tid(testid).press('Enter');
  };
  // the template: a pump turning with Bomba1 and a lamp showing it
  await tid('hmi-add-pump').click();
  await setField('hmi-prop-x', '100');
  await setField('hmi-prop-y', '100');
  await tid('hmi-prop-anim-add').selectOption('rotate');
  await setField('hmi-prop-anim-tag-0', 'Bomba1');
  await tid('hmi-add-led').click();
  await setField('hmi-prop-x', '180');
  await setField('hmi-prop-y', '110');
  await setField('hmi-prop-shows', 'Bomba1');
  await tid('hmi-el-pump1').click();
  await tid('hmi-el-led1').click({ modifiers: ['Shift'] });
  await answer('pumpface', () => tid('hmi-save-symbol').click());
  await tid('hmi-instance-pumpface').waitFor();
  // two instances: Bomba1 (moved left) and Bomba2
  await answer('Bomba1', () => tid('hmi-instance-pumpface').click());
  await tid('hmi-el-led2').waitFor();
  for (let i = 0; i < 20; i++) await page.keyboard.press('ArrowLeft');
  await answer('Bomba2', () => tid('hmi-instance-pumpface').click());
  await tid('hmi-el-led3').waitFor();
  await tid('hmi-instance-of').getByText('Instance of pumpface').waitFor();
  assert.equal(await tid('hmi-instance-prefix').inputValue(), 'Bomba2');
  // the template changes (a colour for both parts): both instances follow
  await tid('hmi-el-pump1').click();
  await tid('hmi-el-led1').click({ modifiers: ['Shift'] });
  await setField('hmi-multi-color', '#c62828');
  await answer('pumpface', () => tid('hmi-save-symbol').click());
  await tid('toasts').getByText('2 instances updated from their templates').waitFor();
  // the second's prefix changed: its tags follow
  await tid('hmi-el-pump3').click();
  await setField('hmi-instance-prefix', 'Llenar');
  await page.waitForFunction(() => document.querySelector('[data-testid="hmi-instance-prefix"]')?.value === 'Llenar');
  await b.shot('designer-template-instances');
  await tid('hmi-save').click();
  await tid('toasts').getByText('faceplates saved').waitFor();
  const saved = await alba.json('/api/screens/faceplates');
  const of = (prefix) => saved.elements.filter((e) => e.props?.prefix === prefix);
  const tags = (els) => els.flatMap((e) => [e.props.tag, ...(e.animations ?? []).map((a) => a.tag)].filter(Boolean));
  assert.deepEqual(tags(of('Bomba1')), ['Bomba1', 'Bomba1']);
  assert.deepEqual(tags(of('Llenar')), ['Llenar', 'Llenar']);
  assert.deepEqual([...of('Bomba1'), ...of('Llenar')].map((e) => e.props.color), ['#c62828', '#c62828', '#c62828', '#c62828']);
  assert.ok(of('Bomba1').every((e) => e.props.template === 'pumpface' && e.group) && of('Bomba1')[0].group !== of('Llenar')[0].group);
  assert.equal(of('Bomba1')[0].x, of('Llenar')[0].x - 200, 'the first instance was moved 200 left, and stays there through the rebuilds');
  // the template saved again from another screen (a blue pump alone): the saved faceplates follow
  await newScreen(page, tid, 'pumps2');
  await tid('hmi-add-pump').click();
  await tid('hmi-prop-anim-add').selectOption('rotate');
  await setField('hmi-prop-anim-tag-0', 'Bomba1');
  await setField('hmi-prop-el-color', '#1565c0');
  await tid('hmi-el-pump1').click();
  await answer('pumpface', () => tid('hmi-save-symbol').click());
  await tid('toasts').getByText('1 saved screens updated from pumpface').waitFor();
  const after = await alba.json('/api/screens/faceplates');
  const inst = (prefix) => after.elements.filter((e) => e.props?.prefix === prefix);
  assert.deepEqual(inst('Bomba1').map((e) => [e.type, e.props.color, e.animations[0]?.tag]), [['pump', '#1565c0', 'Bomba1']]);
  assert.deepEqual(inst('Llenar').map((e) => [e.type, e.props.color, e.animations[0]?.tag]), [['pump', '#1565c0', 'Llenar']]);
  assert.equal(inst('Bomba1')[0].x, of('Bomba1')[0].x, 'in its place');
  assert.deepEqual(b.errors, []);
});
