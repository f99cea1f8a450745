// The studio in Spanish (issue 16, item 5): the language switch in the top bar
// reloads the studio in Spanish, remembered across visits; back to English.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s));

test('the studio speaks Spanish when asked, and remembers it', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  assert.equal(await tid('btn-run').textContent(), '▶ Run');
  assert.equal(await page.evaluate(() => document.documentElement.lang), 'en');
  await Promise.all([page.waitForEvent('load'), tid('lang').selectOption('es')]);
  await tid('status-conn').filter({ hasText: /^conectado$/ }).waitFor();
  assert.equal(await tid('btn-run').textContent(), '▶ Ejecutar');
  assert.equal(await page.evaluate(() => document.documentElement.lang), 'es', '<html lang> follows the language');
  assert.equal(await tid('btn-stop').textContent(), '■ Detener');
  assert.equal(await tid('tab-tags').textContent(), 'Etiquetas');
  assert.equal(await tid('tab-trends').textContent(), 'Tendencias');
  assert.equal(await tid('status-state').textContent(), 'en marcha');
  await tid('tab-program-main.lad').click();
  assert.equal(await tid('btn-rung-copy').textContent(), 'Copiar');
  await tid('rung-0').click({ position: { x: 20, y: 10 } });
  await page.getByText('Escalón 1', { exact: true }).waitFor();
  await b.shot('studio-es');
  // Remembered: a new visit is in Spanish too.
  await page.reload();
  await tid('status-conn').filter({ hasText: /^conectado$/ }).waitFor();
  assert.equal(await tid('tab-tags').textContent(), 'Etiquetas');
  await tid('tab-tags').click();
  await page.getByRole('columnheader', { name: 'Descripción' }).waitFor();
  await b.shot('tags-es');
  await Promise.all([page.waitForEvent('load'), tid('lang').selectOption('en')]);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  assert.equal(await tid('tab-tags').textContent(), 'Tags');
  assert.equal(await page.evaluate(() => document.documentElement.lang), 'en');
  assert.deepEqual(b.errors, []);
});
