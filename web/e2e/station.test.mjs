// End-to-end tests of the operator station (issue 35, point 8) in Chromium, on
// examples/pid-level with an operator and an engineer:
// - the dark theme: toggled in the status bar, remembered across a reload, and
//   followed by the screen, the alarm banner, the faceplate and the tables;
// - the kiosk: the screens and the alarms only (no engineering tab, no top
//   bar, no designer), kept across a reload and entered with ?kiosk=1; an
//   operator cannot leave it (the server says who the session is), an
//   engineer signing in over it can;
// - the runtime view, the faceplate and the kiosk at 1024×768 (a tablet) and
//   390×844 (a phone, touch): nothing wider than the screen, controls a
//   finger can take.
// Screenshots: station-dark-1024x768.png, station-dark-faceplate-390x844.png,
// station-kiosk-390x844.png, station-kiosk-1024x768.png, station-kiosk-leave.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, startAlba } from './harness.mjs';

const olga = { name: 'olga', role: 'operator', password: 'pumps-and-valves-7731' };
const eric = { name: 'eric', role: 'engineer', password: 'ladder-and-logic-4412' };

let alba;
before(async () => {
  alba = await startAlba('pid-level', { users: [olga, eric] });
});
after(async () => {
  await alba?.stop();
});

async function login({ tid }, who) {
  await tid('login-form').waitFor();
  await tid('login-user').fill(who.name);
  await tid('login-password').fill(who.password);
  await tid('login-submit').click();
}

/** The page no wider than the window, and the controls a finger needs at least `min` px high. */
function fits(page, width, selectors, min = 40) {
  return page.evaluate(
    ([w, sels, m]) => {
      const out = [];
      if (document.documentElement.scrollWidth > w) out.push(`page ${document.documentElement.scrollWidth} px wide`);
      for (const sel of sels) {
        for (const el of document.querySelectorAll(sel)) {
          if (el.offsetParent === null && getComputedStyle(el).position !== 'fixed') continue;
          const r = el.getBoundingClientRect();
          if (r.width === 0) continue;
          if (r.height < m) out.push(`${sel} "${el.textContent.trim().slice(0, 20)}" ${Math.round(r.height)} px high`);
          if (r.right > w + 0.5 || r.left < -0.5) out.push(`${sel} off the screen`);
        }
      }
      return out;
    },
    [width, selectors, min],
  );
}

const rgb = (page, sel, prop) => page.evaluate(([s, p]) => getComputedStyle(document.querySelector(s))[p], [sel, prop]);
/** Relative luminance of a computed rgb() colour (0 black … 1 white). */
const luminance = (c) => {
  const [r, g, b] = c.match(/\d+(\.\d+)?/g).slice(0, 3).map((x) => {
    const v = Number(x) / 255;
    return v <= 0.03928 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4;
  });
  return 0.2126 * r + 0.7152 * g + 0.0722 * b;
};
const contrast = (a, b) => {
  const [x, y] = [luminance(a), luminance(b)].sort((p, q) => q - p);
  return (x + 0.05) / (y + 0.05);
};

test('the dark theme: toggled, remembered, followed by the screen, banner, faceplate and tables (1024×768, then a phone)', async () => {
  const b = await openBrowser({ viewport: { width: 1024, height: 768 }, hasTouch: true });
  const { page, tid } = b;
  try {
    await page.goto(`${alba.url}#/screens`);
    await login(b, olga);
    await tid('hmi-screen-loop').waitFor();
    const lightBg = await rgb(page, 'html', 'backgroundColor');
    assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), 'light');
    await tid('btn-theme').click();
    assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), 'dark');
    const darkBg = await rgb(page, 'html', 'backgroundColor');
    assert.ok(luminance(darkBg) < 0.05 && luminance(lightBg) > 0.8, `the page goes dark: ${lightBg} → ${darkBg}`);
    // the screen keeps an ISA-101 grey, dimmer; its black text stays readable
    const screenBg = await page.evaluate(() => getComputedStyle(document.querySelector('[data-testid="hmi-screen-loop"] .hmi-bg')).fill);
    assert.ok(contrast(screenBg, 'rgb(0, 0, 0)') >= 7, `black text on the screen's grey ${screenBg}: contrast ${contrast(screenBg, 'rgb(0, 0, 0)').toFixed(1)}`);
    assert.ok(luminance(screenBg) < 0.6, `dimmer than the light theme's screen: ${screenBg}`);
    // remembered across a reload
    await page.reload();
    await tid('hmi-screen-loop').waitFor();
    assert.equal(await page.evaluate(() => [document.documentElement.dataset.theme, localStorage.getItem('alba.theme')].join()), 'dark,dark');
    // text on the panels readable
    await tid('tab-alarms').click();
    await tid('alarms-view').waitFor();
    assert.ok(contrast(await rgb(page, 'main.content', 'color'), await rgb(page, 'main.content', 'backgroundColor')) >= 7, 'the alarm page reads');
    await tid('tab-screens').click();
    await tid('hmi-el-loop').click();
    await tid('faceplate').waitFor();
    const box = '[data-testid="faceplate"] .modal-box';
    assert.ok(contrast(await rgb(page, box, 'color'), await rgb(page, box, 'backgroundColor')) >= 7, 'the faceplate reads');
    assert.deepEqual([...(await fits(page, 1024, ['.hmi-view > .toolbar button'], 34)), ...(await fits(page, 1024, ['[data-testid="faceplate"] button']))], []);
    await b.shot('station-dark-faceplate-1024x768');
    await tid('faceplate-close').click();
    await tid('faceplate').waitFor({ state: 'detached' });
    await b.shot('station-dark-1024x768');
    // a phone: the faceplate fits and takes a finger
    await page.setViewportSize({ width: 390, height: 844 });
    await tid('hmi-el-loop').tap();
    await tid('faceplate').waitFor();
    assert.deepEqual([...(await fits(page, 390, ['.hmi-view > .toolbar :is(button, select)'], 34)), ...(await fits(page, 390, ['[data-testid="faceplate"] button']))], []);
    const fp = await page.locator(box).boundingBox();
    assert.ok(fp.x >= 0 && fp.x + fp.width <= 390.5, `the faceplate fits the phone: ${JSON.stringify(fp)}`);
    await b.shot('station-dark-faceplate-390x844');
    // back to light for the next browser (the profile is fresh anyway)
  } finally {
    await b.close();
  }
});

for (const size of [
  { width: 390, height: 844, phone: true },
  { width: 1024, height: 768 },
]) {
  const name = `${size.width}x${size.height}`;
  test(`the kiosk at ${name}: screens and alarms only, kept across a reload; an operator cannot leave it, an engineer can`, async () => {
    const b = await openBrowser({ viewport: { width: size.width, height: size.height }, hasTouch: true });
    const { page, tid } = b;
    try {
      await page.goto(`${alba.url}#/screens`);
      await login(b, olga);
      await tid('hmi-screen-loop').waitFor();
      await tid('btn-kiosk').click();
      assert.equal(await page.evaluate(() => document.documentElement.dataset.station), 'kiosk');
      // no engineering tab, no top bar (Run/Stop), no designer
      await tid('tab-program-main').waitFor({ state: 'hidden' }).catch(() => undefined);
      const shown = await page.evaluate(() => [...document.querySelectorAll('.tabs a')].filter((a) => a.offsetParent !== null).map((a) => a.dataset.key));
      assert.deepEqual(shown, ['screens', 'alarms']);
      for (const id of ['btn-run', 'hmi-edit', 'hmi-new', 'btn-kiosk']) assert.equal(await tid(id).isVisible(), false, `${id} hidden in kiosk`);
      // another view by its address: back to the screens
      await page.evaluate(() => (location.hash = '#/tags'));
      await page.waitForFunction(() => location.hash === '#/screens');
      await tid('hmi-screen-loop').waitFor();
      // the alarms are there; a tap on the tab
      await tid('tab-alarms').tap();
      await tid('alarms-view').waitFor();
      await tid('tab-screens').tap();
      await tid('hmi-screen-loop').waitFor();
      assert.deepEqual(await fits(page, size.width, ['.kiosk-leave', '.tabs a']), []);
      // (the tab redraws the screen when shown: the box once it has settled)
      let screen = null;
      for (let i = 0; i < 40 && !screen; i++) screen = (await tid('hmi-screen-loop').boundingBox().catch(() => null)) ?? (await page.waitForTimeout(50), null);
      assert.ok(screen.width > size.width * 0.8 && screen.x + screen.width <= size.width + 0.5, `the screen fits: ${JSON.stringify(screen)}`);
      // the operator works the faceplate in kiosk
      await tid('hmi-el-loop').tap();
      await tid('faceplate').waitFor();
      assert.deepEqual(await fits(page, size.width, ['[data-testid="faceplate"] button']), []);
      await tid('faceplate-close').tap();
      await tid('faceplate').waitFor({ state: 'detached' });
      await b.shot(`station-kiosk-${name}`);
      // a reload (a power cut) comes back in kiosk
      await page.reload();
      await tid('hmi-screen-loop').waitFor();
      assert.equal(await page.evaluate(() => document.documentElement.dataset.station), 'kiosk');
      // the operator may not leave: signing in as herself is refused, still in kiosk
      await tid('btn-kiosk-leave').tap();
      await tid('kiosk-login').waitFor();
      await tid('login-message').filter({ hasText: 'An engineer signs in to leave the kiosk.' }).waitFor();
      if (size.phone) await b.shot('station-kiosk-leave');
      await tid('kiosk-login-cancel').tap();
      await tid('kiosk-login').waitFor({ state: 'detached' });
      await tid('btn-kiosk-leave').tap();
      await login(b, olga);
      await tid('toast-error').filter({ hasText: 'olga may not leave the kiosk' }).waitFor();
      assert.equal(await page.evaluate(() => document.documentElement.dataset.station), 'kiosk');
      // an engineer signs in over it: the kiosk is left, the studio is theirs
      await tid('btn-kiosk-leave').tap();
      await login(b, eric);
      // (a phone's status bar leaves the user out: read, not seen)
      await page.waitForFunction(() => document.querySelector('[data-testid="status-user"]')?.textContent === 'eric (engineer)');
      await tid('btn-run').waitFor();
      assert.equal(await page.evaluate(() => [document.documentElement.dataset.station ?? '', localStorage.getItem('alba.kiosk')].join()), ',');
    } finally {
      await b.close();
    }
  });
}

test('?kiosk=1 starts in kiosk; an engineer\'s own session leaves it without signing in again', async () => {
  const b = await openBrowser({ viewport: { width: 1024, height: 768 } });
  const { page, tid } = b;
  try {
    await page.goto(`${alba.url}?kiosk=1#/program/main`);
    await login(b, eric);
    await tid('hmi-screen-loop').waitFor();
    assert.equal(await page.evaluate(() => location.hash), '#/screens');
    assert.equal(await tid('btn-run').isVisible(), false);
    await tid('btn-kiosk-leave').click();
    await page.waitForFunction(() => document.documentElement.dataset.station === undefined);
    assert.equal(await tid('kiosk-login').count(), 0, 'no sign-in: the server says the session is an engineer\'s');
    assert.equal(await page.evaluate(() => location.search), '', '?kiosk=1 dropped, so a reload does not bring it back');
    await tid('btn-run').waitFor();
  } finally {
    await b.close();
  }
});
