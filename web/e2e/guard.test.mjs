// End-to-end test of the browser guard (docs/security.md, "guard: Browser attacks and
// transport"): a page of another origin, in the operator's browser, tries to stop the
// PLC and to read it through the WebSocket; a rebound DNS name tries to reach the studio.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { createServer } from 'node:http';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { startAlba } from './harness.mjs';

let alba, evil, context, profile;

before(async () => {
  alba = await startAlba('tank-plant');
  // The attacker's site: any page the operator happens to open.
  evil = createServer((_, res) => {
    res.writeHead(200, { 'content-type': 'text/html' });
    res.end('<!doctype html><title>cute cats</title><p>cats</p>');
  });
  await new Promise((ok) => evil.listen(0, '127.0.0.1', ok));
  profile = mkdtempSync(join(tmpdir(), 'alba-chromium-guard-'));
  context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
      // DNS rebinding, simulated: the attacker's name resolves to the PLC's address.
      '--host-resolver-rules=MAP evil.test 127.0.0.1',
    ],
  });
});

after(async () => {
  await context?.close();
  if (profile) rmSync(profile, { recursive: true, force: true });
  evil?.close();
  await alba?.stop();
});

test('a page of another origin cannot stop the PLC nor open the WebSocket', async () => {
  const page = context.pages()[0] ?? (await context.newPage());
  await page.goto(`http://localhost:${evil.address().port}/`);
  const studio = alba.url;
  const tried = await page.evaluate(async (studio) => {
    const out = {};
    // The attack: a "simple" request, sent without a preflight.
    try {
      await fetch(`${studio}api/stop`, { method: 'POST', mode: 'no-cors', headers: { 'Content-Type': 'text/plain' }, body: '{}' });
      out.simple = 'sent';
    } catch (e) {
      out.simple = `error: ${e.message}`;
    }
    // JSON needs a preflight, which the server never approves.
    try {
      await fetch(`${studio}api/stop`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' });
      out.json = 'answered';
    } catch {
      out.json = 'blocked';
    }
    out.ws = await new Promise((ok) => {
      const ws = new WebSocket(`${studio.replace(/^http/, 'ws')}api/ws`);
      ws.onopen = () => ok('open');
      ws.onerror = () => ok('refused');
    });
    return out;
  }, studio);
  assert.equal(tried.json, 'blocked');
  assert.equal(tried.ws, 'refused');
  // A form posted to the studio (a plain navigation, no script needed).
  const [res] = await Promise.all([
    page.waitForNavigation(),
    page.evaluate((studio) => {
      const f = document.createElement('form');
      f.method = 'POST';
      f.action = `${studio}api/stop`;
      f.enctype = 'text/plain';
      document.body.append(f);
      f.submit();
    }, studio),
  ]);
  assert.equal(res.status(), 403, 'the form post is refused');
  // The PLC kept running through all of it.
  const status = await alba.json('/api/status');
  assert.equal(status.state, 'running', JSON.stringify({ tried, status }));
});

test('a rebound DNS name does not reach the studio', async () => {
  const page = await context.newPage();
  const port = new URL(alba.url).port;
  const res = await page.goto(`http://evil.test:${port}/`);
  assert.equal(res.status(), 421);
  assert.match(await page.textContent('body'), /allowed_hosts/);
  // The studio itself, by its own address, still works.
  const own = await page.goto(alba.url);
  assert.equal(own.status(), 200);
  await page.close();
});
