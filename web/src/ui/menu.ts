// A context menu at the mouse (or at the selection, opened from the keyboard):
// a list of items, closed by a click elsewhere or Escape. The first item
// takes the focus, the arrows move it, and the focus goes back to where the
// menu was opened from when it closes.
import { h } from '../dom';
import { tr } from '../i18n';

export interface MenuItem {
  label: string;
  testid: string;
  action: () => void;
  disabled?: boolean;
  /** Tooltip (why the item is disabled). */
  title?: string;
}

let open: HTMLElement | null = null;
/** Where the focus goes back to when the menu closes. */
let opener: HTMLElement | null = null;

export function closeMenu(): void {
  const back = open?.contains(document.activeElement) ? opener : null;
  open?.remove();
  open = null;
  opener = null;
  if (back?.isConnected) back.focus({ preventScroll: true });
}

export function showMenu(x: number, y: number, title: string, items: MenuItem[], from: HTMLElement | null = null): HTMLElement {
  closeMenu();
  const menu = h(
    'div',
    { class: 'menu', role: 'menu', 'data-testid': 'context-menu', style: { left: `${x}px`, top: `${y}px` } },
    h('div', { class: 'menu-title' }, title),
    items.length === 0 ? h('div', { class: 'menu-empty' }, tr('No actions for this element')) : null,
    items.map((it) =>
      h(
        'button',
        {
          class: 'menu-item',
          role: 'menuitem',
          'data-testid': it.testid,
          disabled: it.disabled,
          title: it.title,
          onclick: () => {
            closeMenu();
            it.action();
          },
        },
        it.label,
      ),
    ),
  );
  document.body.append(menu);
  open = menu;
  opener = from;
  const buttons = [...menu.querySelectorAll<HTMLButtonElement>('button.menu-item:not(:disabled)')];
  buttons[0]?.focus({ preventScroll: true });
  menu.addEventListener('keydown', (e) => {
    const k = buttons.indexOf(document.activeElement as HTMLButtonElement);
    const step = e.key === 'ArrowDown' ? 1 : e.key === 'ArrowUp' ? -1 : 0;
    if (step && buttons.length) {
      e.preventDefault();
      buttons[(k + step + buttons.length) % buttons.length].focus();
    } else if (e.key === 'Tab') closeMenu();
  });
  const r = menu.getBoundingClientRect();
  if (r.right > window.innerWidth) menu.style.left = `${Math.max(0, window.innerWidth - r.width - 4)}px`;
  if (r.bottom > window.innerHeight) menu.style.top = `${Math.max(0, window.innerHeight - r.height - 4)}px`;
  return menu;
}

document.addEventListener('mousedown', (e) => {
  if (open && !open.contains(e.target as Node)) closeMenu();
});
document.addEventListener('keydown', (e) => {
  if (e.key === 'Escape') closeMenu();
});
