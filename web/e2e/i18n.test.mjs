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
  // The palette's texts come from GET /api/domain, worded by the server in Spanish.
  assert.equal(await tid('palette-group-timer').textContent(), 'Temporizador');
  assert.match(await tid('palette-XIC').getAttribute('title'), /^XIC\(Bit\) — Examinar si cerrado: examinar si cerrado: deja pasar el peldaño cuando el bit es 1/);
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

// A diagnostic in Spanish at its place (issue 34 point 11): the studio sends
// its language as Accept-Language, the server words the check's diagnostics in
// it; the file is left as it was.
test('a ladder error is shown in Spanish at its place', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await Promise.all([page.waitForEvent('load'), tid('lang').selectOption('es')]);
  await tid('status-conn').filter({ hasText: /^conectado$/ }).waitFor();
  await tid('tab-program-main.lad').click();
  await tid('view-text').click();
  const editor = tid('editor-text');
  const saved = await editor.inputValue();
  assert.ok(saved.includes('OTE(L_RUN)'), 'the example drives L_RUN');
  await editor.fill(saved.replace('OTE(L_RUN)', 'OTE(L_RUM)'));
  await tid('btn-compile').click();
  const problem = tid('diagnostic-0');
  await tid('diagnostics').filter({ hasText: 'variable desconocida `L_RUM`' }).waitFor();
  const text = await problem.textContent();
  assert.match(text, /E301/);
  assert.match(text, /variable desconocida `L_RUM`/);
  assert.match(text, /¿quiso decir `L_RUN`\?/, 'the hint in Spanish too');
  assert.doesNotMatch(text, /unknown tag|did you mean/);
  // Its place: the line and column of L_RUM in the text.
  const line = saved.split('\n').findIndex((l) => l.includes('OTE(L_RUN)')) + 1;
  assert.match(await problem.locator('.where').textContent(), new RegExp(`^${line}:\\d+$`));
  await b.shot('i18n-diagnostic-es');
  // Back to the saved text: no problem left, in Spanish.
  await editor.fill(saved);
  await tid('btn-compile').click();
  await tid('diagnostics').filter({ hasText: 'Sin problemas' }).waitFor();
  assert.deepEqual(b.errors, []);
});
