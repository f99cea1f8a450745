// Shelving an alarm (issue 30, item 14): one in-page dialog — for how many
// minutes (the time it ends shown as it is typed) and why — checked before it
// is sent with the server's rules (1 to 10 080 whole minutes, a reason), and
// the server's refusal shown in the dialog, which stays open. Escape or
// Cancel closes it; Enter shelves.
import { h } from '../dom';
import { tr, when } from '../i18n';
import type { Alarm } from '../types';
import { confirmText } from './confirm';

/** The longest shelving the server accepts: a week. */
export const MAX_SHELVE_MINUTES = 10_080;

/** What is wrong with `minutes` and `reason` as typed (and in which field), or null. */
export function shelveProblem(minutes: string, reason: string): { field: 'minutes' | 'reason'; message: string } | null {
  const m = minutes.trim();
  if (!/^\d+$/.test(m) || Number(m) < 1 || Number(m) > MAX_SHELVE_MINUTES)
    return { field: 'minutes', message: tr('Shelve for 1 to {max} whole minutes.', { max: MAX_SHELVE_MINUTES }) };
  if (!reason.trim()) return { field: 'reason', message: tr('Say why the alarm is shelved.') };
  return null;
}

/**
 * Opens the dialog for `a`; `shelve` sends it and answers an error message
 * (shown, the dialog stays) or null (done). Resolves true once shelved.
 */
export function shelveDialog(a: Alarm, shelve: (minutes: number, reason: string) => Promise<string | null>): Promise<boolean> {
  return new Promise((resolve) => {
    const minutes = h('input', { type: 'number', min: 1, max: MAX_SHELVE_MINUTES, step: 1, value: 60, required: true, 'data-testid': 'shelve-minutes' });
    const reason = h('input', { type: 'text', required: true, maxlength: 200, placeholder: tr('e.g. maintenance on the pump'), 'data-testid': 'shelve-reason' });
    const until = h('span', { class: 'hint', 'data-testid': 'shelve-until' });
    const error = h('p', { class: 'inline-error', role: 'alert', 'data-testid': 'shelve-error', hidden: true });
    const ok = h('button', { type: 'submit', class: 'primary', 'data-testid': 'shelve-ok' }, tr('Shelve'));
    // not a submit button: Enter in a field shelves, it does not cancel
    const cancel = h('button', { type: 'button', 'data-testid': 'shelve-cancel' }, confirmText.cancel);
    const form = h('form', { class: 'modal-box shelve-box', novalidate: true },
      h('h2', { id: 'shelve-title' }, tr('Shelve {id}', { id: a.id })),
      h('p', null, a.message),
      h('label', { class: 'field' }, h('span', null, tr('For (minutes)')), minutes, until),
      h('label', { class: 'field' }, h('span', null, tr('Reason')), reason),
      error,
      h('div', { class: 'modal-buttons' }, cancel, ok));
    const box = h('div', { class: 'modal', role: 'dialog', 'aria-modal': 'true', 'aria-labelledby': 'shelve-title', 'data-testid': 'shelve-dialog' }, form);
    const showUntil = () => {
      const m = Number(minutes.value);
      until.textContent = Number.isInteger(m) && m >= 1 && m <= MAX_SHELVE_MINUTES ? tr('until {time}', { time: when(Date.now() + m * 60_000) }) : '';
    };
    const say = (msg: string | null) => {
      error.hidden = msg === null;
      error.textContent = msg ?? '';
    };
    const done = (yes: boolean) => {
      box.remove();
      document.removeEventListener('keydown', onKey, true);
      resolve(yes);
    };
    const onKey = (e: KeyboardEvent) => {
      if (e.key === 'Escape') {
        e.preventDefault();
        done(false);
      }
    };
    minutes.addEventListener('input', () => {
      showUntil();
      say(null);
    });
    reason.addEventListener('input', () => say(null));
    cancel.onclick = () => done(false);
    form.onsubmit = async (e) => {
      e.preventDefault();
      const problem = shelveProblem(minutes.value, reason.value);
      say(problem?.message ?? null);
      if (problem) return (problem.field === 'reason' ? reason : minutes).focus();
      ok.disabled = true;
      const refused = await shelve(Number(minutes.value), reason.value.trim());
      ok.disabled = false;
      if (refused === null) done(true);
      else say(refused);
    };
    showUntil();
    document.addEventListener('keydown', onKey, true);
    document.body.append(box);
    reason.focus();
  });
}
