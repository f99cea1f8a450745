// A modal confirmation for actions that change the plant (Stop, Run, remove
// every force): says what will happen, defaults to Cancel, Escape cancels.
import { h } from '../dom';
import { tr } from '../i18n';

export const confirmText = { cancel: tr('Cancel') };

/** Asks; resolves true when the user confirms with `ok`. */
export function confirmAction(title: string, message: string, ok: string): Promise<boolean> {
  return new Promise((resolve) => {
    const okBtn = h('button', { class: 'danger', 'data-testid': 'confirm-ok' }, ok);
    const cancelBtn = h('button', { 'data-testid': 'confirm-cancel' }, confirmText.cancel);
    const box = h(
      'div',
      { class: 'modal', role: 'alertdialog', 'aria-modal': 'true', 'aria-labelledby': 'confirm-title', 'data-testid': 'confirm' },
      h('div', { class: 'modal-box' }, h('h2', { id: 'confirm-title' }, title), h('p', null, message), h('div', { class: 'modal-buttons' }, cancelBtn, okBtn)),
    );
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
    okBtn.onclick = () => done(true);
    cancelBtn.onclick = () => done(false);
    document.addEventListener('keydown', onKey, true);
    document.body.append(box);
    cancelBtn.focus();
  });
}
