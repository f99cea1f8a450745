// End-to-end tests of the studio's shell and the ladder as a new user meets
// them (issue 30), on examples/tank-plant: the ladder keeps its scroll position
// and selection across a click, an edit, a save and live updates (rung 9); the
// keyboard path (a skip link, arrows in the ladder, Shift+F10 and the menu key
// for the force menu, the focus kept in the tag table); banners that never push
// the view down; Run/Stop/Compile/Save disabled while not live; and a page
// opened while the runtime is down that starts by itself when it is back.
// Screenshots: ladder-rung9-selected.png, ladder-keyboard-menu.png,
// banners-forces-alarm.png, not-live-disabled.png, runtime-down-countdown.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { elementId, openBrowser, repo, startAlba } from './harness.mjs';

let alba, b;
const id = {};

before(async () => {
  alba = await startAlba('tank-plant');
  b = await openBrowser();
  const program = await alba.json('/api/programs/main.lad');
  id.fill = elementId(program, 'XIC', ['FILL']);
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

const put = (path, body) => alba.api(path, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });
const del = (path) => alba.api(path, { method: 'DELETE', headers: { 'content-type': 'application/json' }, body: '{}' });

/** The ladder's scroll position, and whether the selection is wholly inside the visible part of the rungs. */
const scrollState = () =>
  b.page.evaluate(() => {
    const main = document.querySelector('.ladder-main');
    const sel = document.querySelector('.rungs g.el.selected, .rungs .rung.selected');
    const m = main.getBoundingClientRect();
    const r = sel?.getBoundingClientRect();
    return { top: main.scrollTop, selected: sel?.getAttribute('data-testid') ?? null, inView: !!r && r.top >= m.top && r.bottom <= m.bottom };
  });

test('the ladder keeps its place and the selection in view across a click, an edit, a save and live updates', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/main.lad`);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('rung-10').waitFor();
  await page.locator(`[data-testid="el-${id.fill}"][data-on]`).waitFor();
  // Rung 9 (FILL starts a discharge) at the top of the view: the ladder scrolled well down.
  await page.evaluate(() => document.querySelector('[data-testid="rung-8"]').scrollIntoView({ block: 'start' }));
  const start = await scrollState();
  assert.ok(start.top > 300, `scrolled down: ${start.top}`);
  await page.locator(`[data-testid="el-${id.fill}"]`).click();
  await page.locator(`[data-testid="el-${id.fill}"].selected`).waitFor();
  let now = await scrollState();
  assert.deepEqual(now, { top: start.top, selected: `el-${id.fill}`, inView: true }, 'a click keeps the place');
  // Live updates for two seconds (power flow, values): nothing moves.
  await page.waitForTimeout(2000);
  assert.deepEqual(await scrollState(), now, 'live updates keep the place');
  await b.shot('ladder-rung9-selected');
  // An operand edit: the rung is drawn again, the place and the selection stay.
  await tid('operand-0').fill('S_REC');
  await tid('operand-0').press('Enter');
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'true');
  await page.locator('[data-testid="rung-8"] g.el.selected text.operand', { hasText: 'S_REC' }).waitFor();
  now = await scrollState();
  assert.equal(now.top, start.top, 'an edit keeps the place');
  assert.equal(now.inView, true, 'the edited element stays in view');
  // Saved online: the running version comes back with new ids, in the same place.
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  await page.locator('[data-testid="rung-8"] g.el.selected text.operand', { hasText: 'S_REC' }).waitFor();
  now = await scrollState();
  assert.equal(now.top, start.top, 'a save keeps the place');
  assert.equal(now.inView, true, 'the selection stays in view after a save');
  // Back as it was.
  await tid('operand-0').fill('FILL');
  await tid('operand-0').press('Enter');
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  assert.equal((await scrollState()).top, start.top);
  assert.deepEqual(b.errors, []);
});

test('the keyboard: a skip link to the rungs, arrows select, Shift+F10 and the menu key open the force menu', async () => {
  const { page, tid } = b;
  id.fill = elementId(await alba.json('/api/programs/main.lad'), 'XIC', ['FILL']);
  // a new document (another query), so that the focus starts at its top
  await page.goto(`${alba.url}?keys#/program/main.lad`);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('rung-10').waitFor();
  const focused = () => page.evaluate(() => document.activeElement?.getAttribute('data-testid') ?? document.activeElement?.tagName);
  // The first Tab reaches the skip link; it leads past the top bar, the tabs and the toolbars.
  await page.keyboard.press('Tab');
  assert.equal(await focused(), 'skip-link');
  assert.equal(await tid('skip-link').isVisible(), true, 'shown while focused');
  await page.keyboard.press('Enter');
  assert.equal(await focused(), 'rungs');
  // Down to rung 9, right to its first element: XIC(FILL).
  for (let k = 0; k < 9; k++) await page.keyboard.press('ArrowDown');
  await page.locator('[data-testid="rung-8"].selected').waitFor();
  await page.keyboard.press('ArrowRight');
  await page.locator(`[data-testid="el-${id.fill}"].selected`).waitFor();
  assert.equal((await scrollState()).inView, true, 'the keyboard scrolls the selection into view');
  await page.keyboard.press('Shift+F10');
  await tid('context-menu').waitFor();
  assert.equal(await focused(), 'menu-force-on');
  await b.shot('ladder-keyboard-menu');
  await page.keyboard.press('Enter');
  await page.waitForFunction(async () => (await (await fetch('/api/forces')).json()).some((f) => f.name === 'FILL' && f.value === true));
  assert.equal(await focused(), 'rungs', 'the focus is back on the rungs');
  // The menu key, then the arrows to Unforce.
  await page.locator(`[data-testid="el-${id.fill}"] .forced-badge`).waitFor();
  await page.keyboard.press('ContextMenu');
  await tid('context-menu').waitFor();
  await page.keyboard.press('ArrowDown');
  await page.keyboard.press('ArrowDown');
  assert.equal(await focused(), 'menu-unforce');
  await page.keyboard.press('Enter');
  await page.waitForFunction(async () => (await (await fetch('/api/forces')).json()).length === 0);
  assert.equal(await focused(), 'rungs');
  // Escape clears the selection.
  await page.keyboard.press('Escape');
  await page.waitForFunction(() => !document.querySelector('.rungs .selected'));
  assert.deepEqual(b.errors, []);
});

test('the tag table keeps the focus after a force, an unforce and a write', async () => {
  const { page, tid } = b;
  await tid('tab-tags').click();
  await tid('tag-row-S_REC').waitFor();
  const focused = () => page.evaluate(() => document.activeElement?.getAttribute('data-testid') ?? document.activeElement?.tagName);
  assert.equal(await tid('force-on-S_REC').getAttribute('title'), 'Force to 1 (on)');
  assert.equal(await tid('force-off-S_REC').getAttribute('title'), 'Force to 0 (off)');
  await tid('force-on-S_REC').focus();
  await page.keyboard.press('Enter');
  await tid('tag-forced-S_REC').waitFor();
  assert.equal(await focused(), 'force-on-S_REC');
  await page.keyboard.press('Tab'); // F0
  await page.keyboard.press('Tab'); // Unforce
  assert.equal(await focused(), 'unforce-S_REC');
  await page.keyboard.press('Enter');
  await tid('tag-forced-S_REC').waitFor({ state: 'detached' });
  assert.equal(await focused(), 'force-on-S_REC', 'Unforce is disabled now: the focus stays in the row');
  await tid('tag-edit-value-CT_STP.PRE').focus();
  await page.keyboard.press('Enter');
  assert.equal(await focused(), 'tag-input-CT_STP.PRE');
  await page.keyboard.type('2');
  await page.keyboard.press('Enter');
  await tid('tag-input-CT_STP.PRE').waitFor({ state: 'detached' });
  assert.equal(await focused(), 'tag-edit-value-CT_STP.PRE');
  assert.deepEqual(b.errors, []);
});

test('banners, their lists and the edit state never push the view down', async () => {
  const { page, tid } = b;
  await tid('tab-program-main.lad').click();
  await tid('rung-10').waitFor();
  const top = () => page.evaluate(() => Math.round(document.querySelector('.rungs').getBoundingClientRect().top));
  const base = await top();
  // a force: its banner, and its list opened
  assert.equal((await put('/api/forces/FILL', { value: false })).status, 200);
  await tid('forces-banner').waitFor();
  assert.equal(await top(), base, 'the forces banner');
  await tid('forces-toggle').click();
  await tid('forces-item-FILL').waitFor();
  assert.equal(await top(), base, 'the list of forces');
  await tid('forces-toggle').click();
  // an alarm (the emergency stop) beside it, and its list
  assert.equal((await put('/api/forces/STOP', { value: true })).status, 200);
  await page.waitForFunction(() => document.querySelector('[data-testid=alarm-text]')?.textContent?.includes('estop'));
  assert.equal(await top(), base, 'the alarm banner');
  await tid('alarm-toggle').click();
  await tid('alarm-row-estop').waitFor();
  assert.equal(await top(), base, 'the alarm list');
  await b.shot('banners-forces-alarm');
  await tid('alarm-toggle').click();
  assert.equal(await tid('banners').evaluate((e) => e.getBoundingClientRect().height), 32, 'one line for every banner');
  // the edit state grows with an edit and a problem: the toolbar stays one row
  await tid('view-text').click();
  const text = await tid('editor-text').inputValue();
  await tid('editor-text').fill(text.replace('OTE(L_RUN)', 'OTE(L_RUM)'));
  await tid('view-graphic').click();
  await tid('edit-state').filter({ hasText: /problem/ }).waitFor();
  assert.equal(await top(), base, 'the edit state');
  assert.match(await tid('edit-state').getAttribute('title'), /edited — not saved .* · 1 problem/);
  await tid('view-text').click();
  await tid('editor-text').fill(text);
  await tid('view-graphic').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  // the PLC stopped: the "stopped" banner
  await alba.api('/api/stop', { method: 'POST', headers: { 'content-type': 'application/json' }, body: '{}' });
  await page.waitForFunction(() => document.body.dataset.live === 'stopped');
  assert.equal(await top(), base, 'the stopped banner');
  await alba.api('/api/run', { method: 'POST', headers: { 'content-type': 'application/json' }, body: '{}' });
  await del('/api/forces');
  await page.waitForFunction(() => document.body.dataset.live === 'live');
  await tid('forces-banner').waitFor({ state: 'hidden' });
  assert.equal(await top(), base);
});

test('while not live Run, Stop, Compile and Save are disabled; a page opened while the runtime is down starts when it is back', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}?live#/program/main.lad`);
  await page.waitForFunction(() => document.body.dataset.live === 'live');
  for (const btn of ['btn-stop', 'btn-compile', 'btn-save']) assert.equal(await tid(btn).isEnabled(), true, btn);
  // (the trends view saves its pens half a second after it starts: not while the server is away)
  await page.waitForTimeout(1000);
  await alba.kill();
  await page.waitForFunction(() => document.body.dataset.live === 'stale', null, { timeout: 20_000 });
  for (const btn of ['btn-run', 'btn-stop', 'btn-compile', 'btn-save']) {
    assert.equal(await tid(btn).isDisabled(), true, btn);
    assert.equal(await tid(btn).getAttribute('title'), 'Not live: the runtime does not answer');
  }
  // a click (and Ctrl+S) does nothing, and says nothing
  await tid('btn-save').evaluate((e) => e.click());
  await page.keyboard.press('Control+S');
  await page.waitForTimeout(500);
  assert.deepEqual(await tid('toast-error').allTextContents(), [], 'no error toast');
  await b.shot('not-live-disabled');

  // A page opened now (from the browser's cache, as a console restoring its tabs: the
  // studio's files from web/dist, which the binary embeds; the API goes to the dead
  // server): the reason, a countdown, and it starts by itself when the server answers.
  // (A document served by the test has no address of its own, so Chromium's checks of
  // pages reaching a local network, which would refuse its WebSocket, are off.)
  const b2 = await openBrowser({ args: ['--disable-features=LocalNetworkAccessChecks'] });
  try {
    const dist = join(repo, 'web/dist');
    await b2.page.route(
      (url) => !url.pathname.startsWith('/api'),
      (route) => {
        const path = new URL(route.request().url()).pathname;
        const file = join(dist, path === '/' ? 'index.html' : path);
        const type = file.endsWith('.js') ? 'text/javascript' : file.endsWith('.css') ? 'text/css' : 'text/html';
        return route.fulfill({ body: readFileSync(file), contentType: type });
      },
    );
    await b2.page.goto(alba.url);
    await b2.tid('unreachable').waitFor();
    assert.match(await b2.tid('unreachable-reason').textContent(), /^Cannot start the studio: cannot reach the server/);
    await b2.page.waitForFunction(() => /in [2-9] s…$/.test(document.querySelector('[data-testid="retry-countdown"]')?.textContent ?? ''), null, { timeout: 10_000 });
    await b2.shot('runtime-down-countdown');
    await alba.restart();
    await b2.tid('status-conn').filter({ hasText: /^connected$/ }).waitFor({ timeout: 40_000 });
    assert.equal(await b2.tid('unreachable').count(), 0);
    assert.equal(await b2.tid('project-name').textContent(), 'tank-plant');
    assert.deepEqual(b2.errors, []);
  } finally {
    await b2.close();
  }
  // The first page is live again: Stop is enabled.
  await page.waitForFunction(() => document.body.dataset.live === 'live', null, { timeout: 20_000 });
  assert.equal(await tid('btn-stop').isEnabled(), true);
  assert.deepEqual(b.errors, []);
});
