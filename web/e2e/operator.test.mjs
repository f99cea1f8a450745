// End-to-end tests of the operator's views — screens, alarms, tags, trends — at
// three sizes (issue 30, items 6 and 8), on examples/tank-plant: a desktop
// (1400×900), a small laptop (1024×700: nothing wraps into a second row) and a
// phone (390×844, touch: the page is no wider than the screen, every tab and
// the language menu can be reached, a long press opens the force menu). Full
// screen keeps the alarm banner and its sound button, with a way out.
// Screenshots: operator-<view>-<size>.png, ladder-long-press-390x844.png,
// fullscreen-alarm-banner.png, fullscreen-phone.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { elementId, openBrowser, startAlba } from './harness.mjs';

let alba;

before(async () => {
  alba = await startAlba('tank-plant');
});

after(async () => {
  await alba?.stop();
});

const put = (path, body) => alba.api(path, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });
const forces = async () => (await alba.json('/api/forces')).map((f) => `${f.name}=${f.value}`);

/** What does not fit: the page wider than the window, a bar in two rows, a toolbar that must scroll, a control off the screen. */
function misfits(page, width) {
  return page.evaluate((w) => {
    const out = [];
    const doc = document.documentElement;
    if (doc.scrollWidth > w) out.push(`page ${doc.scrollWidth} px wide`);
    const rows = { '.topbar': 46, '.banners': 33, '.statusbar': 26, 'main .toolbar': 46 };
    if (w > 600) rows['.tabs'] = 40;
    for (const [sel, max] of Object.entries(rows)) {
      for (const el of document.querySelectorAll(sel)) {
        if (el.closest('[hidden]') || el.offsetParent === null) continue;
        const h = el.getBoundingClientRect().height;
        if (h > max) out.push(`${sel} ${Math.round(h)} px high`);
        if (el.scrollHeight > el.clientHeight + 1) out.push(`${sel} squeezed (${el.scrollHeight} > ${el.clientHeight})`);
        // below a phone's width a toolbar may scroll sideways; above it everything shows
        if (w > 600 && sel === 'main .toolbar' && el.scrollWidth > el.clientWidth + 1) out.push(`${sel} cut (${el.scrollWidth} > ${el.clientWidth})`);
      }
    }
    for (const el of document.querySelectorAll('.tabs a, .topbar select.lang, .topbar button.run, .topbar button.stop')) {
      const r = el.getBoundingClientRect();
      if (r.right > w + 0.5 || r.left < 0) out.push(`${el.dataset.testid} off the screen (${Math.round(r.left)}…${Math.round(r.right)})`);
    }
    return out;
  }, width);
}

const SIZES = [
  { width: 1400, height: 900 },
  { width: 1024, height: 700 },
  { width: 390, height: 844, phone: true },
];

for (const size of SIZES) {
  const name = `${size.width}x${size.height}`;
  test(`the operator's views fit ${name}${size.phone ? ' (a phone, touch)' : ''}`, async () => {
    const b = await openBrowser({ viewport: { width: size.width, height: size.height }, hasTouch: !!size.phone });
    const { page, tid } = b;
    try {
      await page.goto(`${alba.url}#/screens`);
      await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
      for (const view of ['screens', 'alarms', 'tags', 'trends']) {
        await tid(`tab-${view}`).click(); // reachable: a tap on its tab
        await tid(`${view === 'screens' ? 'hmi' : view}-view`).waitFor();
        if (view === 'screens') {
          await tid('hmi-screen-tank').waitFor();
          const box = await tid('hmi-screen-tank').boundingBox();
          assert.ok(box.width > size.width * 0.8 && box.x >= 0 && box.x + box.width <= size.width + 0.5, `the screen fits: ${JSON.stringify(box)}`);
          if (size.phone) {
            // a finger works the Fill request switch (it toggles Llenar)
            const before = (await alba.json('/api/tags/Llenar')).value;
            await tid('hmi-el-fill').tap();
            await page.waitForFunction(async (v) => (await (await fetch('/api/tags/Llenar')).json()).value !== v, before);
          }
        }
        if (view === 'tags') {
          await page.waitForFunction(() => /^\d/.test(document.querySelector('[data-testid="tag-value-Nivel_L"]')?.textContent ?? ''));
          for (const id of ['tag-value-FILL', 'force-on-FILL', 'unforce-FILL']) {
            const r = await tid(id).boundingBox();
            assert.ok(r && r.x + r.width <= size.width, `${id} on the screen`);
          }
          if (!size.phone) {
            // one line a row: the description is cut short (whole in its tooltip), the buttons stay side by side
            const tall = await page.$$eval('[data-testid="tag-table"] tbody tr:not([hidden])', (rows) =>
              rows.filter((r) => r.getBoundingClientRect().height > 40).map((r) => `${r.dataset.testid} ${Math.round(r.getBoundingClientRect().height)} px`));
            assert.deepEqual(tall, [], 'tag rows one line high');
          }
        }
        if (view === 'trends' && !(await tid('trend-pen-Nivel_L').count())) {
          await tid('trend-pen-input').fill('Nivel_L');
          await tid('trend-pen-add').click();
          await page.waitForFunction(() => Number(document.querySelector('[data-testid="trend-plot"]')?.getAttribute('data-points')) > 0);
          const plot = await page.locator('[data-testid="trend-plot"] canvas').first().boundingBox();
          assert.ok(plot.x >= 0 && plot.x + plot.width <= size.width + 0.5, `the plot fits: ${JSON.stringify(plot)}`);
        }
        await page.waitForTimeout(300);
        assert.deepEqual(await misfits(page, size.width), [], `${view} at ${name}`);
        await b.shot(`operator-${view}-${name}`);
      }
      if (!size.phone) {
        // the ladder too: its toolbar in one row, whole
        await tid('tab-program-main.lad').click();
        await tid('rung-10').waitFor();
        assert.deepEqual(await misfits(page, size.width), [], `the ladder at ${name}`);
      } else {
        // A long press (a finger held still) opens the force menu: on a tag's row …
        const cdp = await page.context().newCDPSession(page);
        const longPress = async (locator) => {
          await locator.waitFor(); // a view just opened may not be laid out yet
          await locator.scrollIntoViewIfNeeded();
          const r = await locator.boundingBox();
          assert.ok(r, 'the long-pressed element has a box');
          const at = { x: r.x + Math.min(r.width / 2, 30), y: r.y + r.height / 2 };
          await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [at] });
          await page.waitForTimeout(800);
          await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
        };
        await tid('tab-tags').click();
        await longPress(page.locator('[data-testid="tag-row-FILL"] td.name'));
        await tid('context-menu').waitFor();
        await tid('menu-force-on').tap();
        await page.waitForFunction(() => document.querySelector('[data-testid="tag-forced-FILL"]'));
        assert.deepEqual(await forces(), ['FILL=true']);
        // … and on a contact in the ladder
        await tid('tab-program-main.lad').click();
        const program = await alba.json('/api/programs/main.lad');
        const contact = page.locator(`[data-testid="el-${elementId(program, 'XIC', ['FILL'])}"]`);
        await contact.scrollIntoViewIfNeeded();
        await longPress(contact);
        await tid('context-menu').waitFor();
        await b.shot(`ladder-long-press-${name}`);
        await tid('menu-unforce').tap();
        await page.waitForFunction(async () => (await (await fetch('/api/forces')).json()).length === 0);
        assert.equal(await tid('context-menu').count(), 0, 'the menu closed');
        assert.equal(await page.evaluate(() => document.documentElement.scrollWidth), size.width, 'the ladder too fits the width');
      }
      assert.deepEqual(b.errors, []);
    } finally {
      await b.close();
    }
  });
}

test('full screen keeps the alarm banner and its sound button, and has a way out', async () => {
  const b = await openBrowser();
  const { page, tid } = b;
  try {
    await page.goto(`${alba.url}#/screens`);
    await tid('hmi-screen-tank').waitFor();
    await tid('hmi-fullscreen').click();
    await page.waitForFunction(() => document.body.classList.contains('kiosk'));
    for (const hidden of ['.topbar', '.tabs', '.statusbar', '.hmi-view > .toolbar']) {
      assert.equal(await page.locator(hidden).isVisible(), false, `${hidden} steps aside`);
    }
    // an alarm arrives while full screen: the emergency stop pressed
    assert.equal((await put('/api/forces/STOP', { value: true })).status, 200);
    await page.waitForFunction(() => document.querySelector('[data-testid=alarm-text]')?.textContent?.includes('estop'));
    assert.equal(await tid('alarm-banner').isVisible(), true, 'the banner shows over the screen');
    assert.equal(await tid('alarm-mute').isVisible(), true, 'with its sound button');
    assert.equal(await tid('hmi-exit-fullscreen').isVisible(), true);
    const screen = await tid('hmi-screen-tank').boundingBox();
    assert.ok(screen.height > 800, `the screen takes the display: ${JSON.stringify(screen)}`);
    await b.shot('fullscreen-alarm-banner');
    assert.match(await tid('alarm-mute').textContent(), /Sound on/);
    await tid('alarm-mute').click();
    assert.match(await tid('alarm-mute').textContent(), /Muted/);
    await tid('alarm-mute').click();
    await tid('alarm-toggle').click();
    await tid('alarm-ack-estop').click();
    // acknowledged, nothing else waits: the banner steps aside (the summary
    // arrives a moment after the click, so wait for it rather than close the list)
    await tid('alarm-banner').waitFor({ state: 'hidden' });
    await tid('hmi-exit-fullscreen').click();
    await page.waitForFunction(() => !document.body.classList.contains('kiosk') && !document.fullscreenElement);
    assert.equal(await tid('tabs').isVisible(), true);
    assert.equal(await tid('hmi-exit-fullscreen').count(), 0);
    // Escape leaves it too
    await tid('hmi-fullscreen').click();
    await page.waitForFunction(() => document.body.classList.contains('kiosk'));
    await page.keyboard.press('Escape');
    await page.waitForFunction(() => !document.body.classList.contains('kiosk'));
    await alba.api('/api/forces', { method: 'DELETE', headers: { 'content-type': 'application/json' }, body: '{}' });
    assert.deepEqual(b.errors, []);
  } finally {
    await b.close();
  }
  // on a phone, full screen as well
  const p = await openBrowser({ viewport: { width: 390, height: 844 }, hasTouch: true });
  try {
    await p.page.goto(`${alba.url}#/screens`);
    await p.tid('hmi-screen-tank').waitFor();
    await p.tid('hmi-fullscreen').tap();
    await p.page.waitForFunction(() => document.body.classList.contains('kiosk'));
    assert.equal(await p.tid('banners').isVisible(), true);
    await p.shot('fullscreen-phone');
    await p.tid('hmi-exit-fullscreen').tap();
    await p.page.waitForFunction(() => !document.body.classList.contains('kiosk'));
    assert.deepEqual(p.errors, []);
  } finally {
    await p.close();
  }
});
