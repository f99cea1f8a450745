// End-to-end tests of users, roles and the browser guards (issue 13) in
// Chromium, against `alba run` on a copy of examples/tank-plant with users
// added by `alba user add` (and a second copy without users for the
// cross-origin attack on the default, user-less set-up):
// - without a session the studio is the login page; a wrong password is said;
// - an operator writes a tag and finds the engineer-only actions disabled
//   (and the server refuses them anyway); signing out ends the session;
// - an engineer edits a rung online; the session ends under the studio and
//   signing in again keeps the edit;
// - failed logins in a row: the wait is shown, the button held;
// - a page served from another origin (another port of 127.0.0.1: the same
//   site, so the browser does send the session cookie) tries a `fetch` POST
//   /api/stop and a WebSocket to the studio: refused, the PLC keeps running.
// Screenshots (login.png, operator.png, engineer.png, cross-origin.png) in E2E_OUT.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { createServer } from 'node:http';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { elementId, openBrowser, startAlba } from './harness.mjs';

const USERS = [
  { name: 'olga', role: 'operator', password: 'pumps-and-valves-7731' },
  { name: 'eric', role: 'engineer', password: 'ladder-rungs-5520' },
];
const [olga, eric] = USERS;

let alba, open, b;

before(async () => {
  [alba, open] = await Promise.all([startAlba('tank-plant', { users: USERS }), startAlba('tank-plant')]);
  await alba.login(eric.name, eric.password);
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
  await open?.stop();
});

const json = (value) => ({ method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify(value) });

async function login(user, password) {
  const { tid } = b;
  await tid('login-form').waitFor();
  await tid('login-user').fill(user);
  await tid('login-password').fill(password);
  await tid('login-submit').click();
}

/** A control disabled by the role, with the reason as its tooltip. */
async function assertNeeds(locator, role, what) {
  await locator.waitFor();
  assert.equal(await locator.isDisabled(), true, `${what} is disabled`);
  const title = await locator.getAttribute('title');
  // (a palette button's tooltip is the instruction's doc, then the reason)
  assert.ok(title === `needs the ${role} role` || title?.endsWith(`(needs the ${role} role)`), `${what} says why: ${title}`);
}

test('without a session: the login page; the API answers 401; a wrong password is said', async () => {
  const { page, tid } = b;
  assert.equal((await fetch(new URL('/api/tags', alba.url))).status, 401);
  await page.goto(alba.url);
  await tid('login-form').waitFor();
  assert.equal(await tid('tabs').count(), 0, 'no studio behind the login page');
  await login(olga.name, 'not-her-password-1');
  await tid('login-error').filter({ hasText: 'Wrong user name or password' }).waitFor();
  assert.equal(await tid('login-password').inputValue(), '', 'the password field is emptied');
  await b.shot('login');
});

test('an operator writes a tag and finds the engineer-only actions disabled', async () => {
  const { page, tid } = b;
  await login(olga.name, olga.password);
  await tid('status-user').filter({ hasText: 'olga (operator)' }).waitFor();
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  const stored = await page.evaluate(() => JSON.stringify({ ...localStorage, ...sessionStorage }));
  assert.doesNotMatch(stored, /token|session|password/i, `nothing of the session in the page's storage: ${stored}`);

  // the top bar: run/stop and compile/save are the engineer's
  await tid('status-state').filter({ hasText: 'running' }).waitFor();
  await assertNeeds(tid('btn-stop'), 'engineer', 'Stop');
  await assertNeeds(tid('btn-run'), 'engineer', 'Run');
  await assertNeeds(tid('btn-save'), 'engineer', 'Save');
  await assertNeeds(tid('btn-compile'), 'engineer', 'Compile');

  // the tag table: a write goes through; forces and definitions are disabled
  await tid('tab-tags').click();
  await tid('tag-row-CT_STP.PRE').waitFor();
  await tid('tag-edit-value-CT_STP.PRE').click();
  await tid('tag-input-CT_STP.PRE').fill('4');
  await tid('tag-input-CT_STP.PRE').press('Enter');
  await tid('tag-value-CT_STP.PRE').filter({ hasText: /^4$/ }).waitFor();
  assert.equal((await alba.json('/api/tags/CT_STP.PRE')).value, 4, 'written by the operator');
  await assertNeeds(tid('force-on-S_REC'), 'engineer', 'Force on');
  await assertNeeds(tid('force-off-S_REC'), 'engineer', 'Force off');
  await assertNeeds(tid('tag-add'), 'engineer', 'New tag');
  await assertNeeds(tid('tags-import-button'), 'engineer', 'Import CSV');
  await assertNeeds(tid('tag-def-edit-Nivel_L'), 'engineer', 'Edit definition');
  await b.shot('operator');

  // the ladder: no palette, no edit tools, the text read-only, no force in the menu
  await tid('tab-program-main.lad').click();
  await tid('rung-0').waitFor();
  await assertNeeds(tid('palette-XIC'), 'engineer', 'The palette');
  await assertNeeds(tid('btn-rung-add'), 'engineer', 'Add rung');
  await assertNeeds(tid('btn-delete'), 'engineer', 'Delete');
  const program = await alba.json('/api/programs/main.lad');
  await page.locator(`[data-testid="el-${elementId(program, 'XIC', ['STOP'])}"]`).click({ button: 'right' });
  await assertNeeds(tid('menu-force-on'), 'engineer', 'Force ON in the menu');
  await page.keyboard.press('Escape');
  await tid('view-text').click();
  assert.equal(await tid('editor-text').getAttribute('readonly'), '', 'the program text is read-only');
  await tid('view-graphic').click();

  // and the server refuses the operator what the studio disables
  const refused = await page.evaluate(async () => {
    const send = async (method, path) =>
      (await fetch(path, { method, headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(method === 'PUT' ? { value: true } : {}) })).status;
    return { force: await send('PUT', '/api/forces/S_REC'), stop: await send('POST', '/api/stop') };
  });
  assert.deepEqual(refused, { force: 403, stop: 403 });
  assert.equal((await alba.json('/api/status')).state, 'running');

  // signing out ends the session
  await tid('btn-logout').click();
  await tid('login-message').filter({ hasText: 'Signed out' }).waitFor();
  assert.equal(await page.evaluate(async () => (await fetch('/api/me')).status), 401);
});

test('an engineer edits a rung online', async () => {
  const { page, tid } = b;
  await login(eric.name, eric.password);
  await tid('status-user').filter({ hasText: 'eric (engineer)' }).waitFor();
  await tid('tab-program-main.lad').click();
  await tid('rung-0').waitFor();
  assert.equal(await tid('btn-save').isDisabled(), false);
  assert.equal(await tid('palette-XIC').isDisabled(), false);
  const scans = (await alba.json('/api/status')).scans;
  await tid('view-text').click();
  const editor = tid('editor-text');
  const text = await editor.inputValue();
  assert.ok(text.includes('GEQ(Nivel_L,60.0)OTU(Llenar);'));
  await editor.fill(text.replace('GEQ(Nivel_L,60.0)', 'GEQ(Nivel_L,55.0)'));
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  await tid('toast-info').first().waitFor();
  assert.ok(readFileSync(join(alba.dir, 'main.lad'), 'utf8').includes('GEQ(Nivel_L,55.0)OTU(Llenar);'), 'saved to the project file');
  const st = await alba.json('/api/status');
  assert.equal(st.state, 'running');
  assert.ok(st.scans > scans, 'still scanning after the online edit');
  await tid('view-graphic').click();
  await page.locator('[data-testid="rung-6"]', { hasText: '55.0' }).waitFor();

  // The session ends under the studio (a sign-out from another tab of this
  // browser): the next save is answered 401, the login page comes back over
  // the studio saying why, and the same user signing in finds the edit kept.
  await tid('view-text').click();
  const edited = (await editor.inputValue()).replace('GEQ(Nivel_L,55.0)', 'GEQ(Nivel_L,52.0)');
  await editor.fill(edited);
  assert.equal(await page.evaluate(async () => (await fetch('/api/logout', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' })).status), 204);
  // The save, or the background check of the edited text if it goes first on a
  // busy machine, is answered 401: either brings the login page back.
  await tid('btn-save').click({ timeout: 5000 }).catch(() => undefined);
  await tid('login-message').filter({ hasText: 'Your session has ended' }).waitFor();
  assert.ok(!readFileSync(join(alba.dir, 'main.lad'), 'utf8').includes('52.0'), 'not saved without a session');
  await login(eric.name, eric.password);
  await tid('login-page').waitFor({ state: 'detached' });
  assert.equal(await editor.inputValue(), edited, 'the edit is kept');
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  assert.ok(readFileSync(join(alba.dir, 'main.lad'), 'utf8').includes('GEQ(Nivel_L,52.0)OTU(Llenar);'), 'saved after signing in again');
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('view-graphic').click();
  // the engineer may force: the menu item is enabled
  const program = await alba.json('/api/programs/main.lad');
  await page.locator(`[data-testid="el-${elementId(program, 'XIC', ['STOP'])}"]`).click({ button: 'right' });
  assert.equal(await tid('menu-force-on').isDisabled(), false);
  await page.keyboard.press('Escape');
  await b.shot('engineer');
});

/** A page on another port of 127.0.0.1 that attacks `target` as soon as it loads. */
async function evilServer(target) {
  const ws = target.replace(/^http/, 'ws');
  const html = `<!doctype html><title>evil</title><script>
  (async () => {
    const out = {};
    // a "simple" request: no preflight, the cookie goes along (same site)
    try {
      await fetch(${JSON.stringify(target + 'api/stop')}, { method: 'POST', mode: 'no-cors', credentials: 'include', headers: { 'Content-Type': 'text/plain' }, body: '{}' });
      out.simple = 'sent';
    } catch (e) { out.simple = 'failed: ' + e.message; }
    // JSON, as the studio sends it: needs a CORS preflight
    try {
      const r = await fetch(${JSON.stringify(target + 'api/stop')}, { method: 'POST', credentials: 'include', headers: { 'Content-Type': 'application/json' }, body: '{}' });
      out.json = 'answered ' + r.status;
    } catch (e) { out.json = 'refused'; }
    out.ws = await new Promise((done) => {
      let got = 0;
      const s = new WebSocket(${JSON.stringify(ws + 'api/ws')});
      s.onopen = () => s.send(JSON.stringify({ subscribe: '*' }));
      s.onmessage = () => { if (++got === 3) done('open, ' + got + ' messages'); };
      s.onclose = (e) => done(got ? 'open, ' + got + ' messages' : 'refused (' + e.code + ')');
      setTimeout(() => done('no answer'), 10000);
    });
    window.__result = out;
  })();
  </script>`;
  const server = createServer((req, res) => {
    res.writeHead(200, { 'content-type': 'text/html' });
    res.end(html);
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
  return {
    url: `http://127.0.0.1:${server.address().port}/`,
    close: () => {
      server.closeAllConnections();
      return new Promise((ok) => server.close(ok));
    },
  };
}

for (const [label, which] of [
  ['with users, the engineer signed in', () => alba],
  ['without users (loopback, full rights)', () => open],
]) {
  test(`a page of another origin cannot stop the PLC nor open the WebSocket (${label})`, async () => {
    const target = which();
    const { page } = b;
    const evil = await evilServer(target.url);
    try {
      const before = await target.json('/api/status');
      assert.equal(before.state, 'running');
      await page.goto(evil.url);
      const result = await (await page.waitForFunction(() => window.__result, null, { timeout: 20_000 })).jsonValue();
      console.log(`cross-origin page (${label}): ${JSON.stringify(result)}`);
      await b.shot(`cross-origin${target === open ? '-no-users' : ''}`);
      assert.match(result.ws, /^refused/, 'the WebSocket is refused');
      assert.equal(result.json, 'refused', 'the JSON POST is refused (no CORS grant)');
      // the simple POST was sent (its answer is opaque to the page): the PLC still runs
      const st = await target.json('/api/status');
      assert.equal(st.state, 'running', 'the PLC still runs');
      assert.ok(st.scans > before.scans, 'and keeps scanning');
      // what the server answered that request: a refusal, for the foreign Origin
      const origin = evil.url.replace(/\/$/, '');
      const direct = await target.api('/api/stop', { method: 'POST', headers: { origin, 'content-type': 'text/plain' }, body: '{}' });
      assert.ok(direct.status >= 400 && direct.status < 500, `POST /api/stop from ${origin}: ${direct.status}`);
      assert.equal((await target.json('/api/status')).state, 'running');
    } finally {
      await evil.close();
    }
  });
}

test('failed logins in a row: the wait is shown and the button held until it is over', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('btn-logout').click(); // the engineer's session from the tests above
  await tid('login-form').waitFor();
  let said = '';
  for (let k = 0; k < 10 && !said.startsWith('Too many'); k++) {
    await tid('login-user').fill('mallory');
    await tid('login-password').fill(`guess-number-${k}`);
    await tid('login-submit').click(); // (waits while the button is held)
    await page.waitForFunction(() => document.querySelector('[data-testid="login-submit"]')?.textContent === 'Sign in');
    said = (await tid('login-error').textContent()) ?? '';
  }
  assert.match(said, /^Too many failed attempts: wait \d+ s before trying again$/);
  assert.equal(await tid('login-submit').isDisabled(), true, 'held during the wait');
  await b.shot('login-backoff');
  await page.waitForFunction(() => document.querySelector('[data-testid="login-submit"]')?.disabled === false, null, { timeout: 70_000 });
  await login(olga.name, olga.password);
  await tid('status-user').filter({ hasText: 'olga (operator)' }).waitFor();
});
