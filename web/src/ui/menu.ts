// A context menu at the mouse: a list of items, closed by a click elsewhere or Escape.
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

export function closeMenu(): void {
  open?.remove();
  open = null;
}

export function showMenu(x: number, y: number, title: string, items: MenuItem[]): HTMLElement {
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
