// Two banners on every page: "not live" (what the screen shows is stale: the
// connection is down or silent, or the PLC is stopped or faulted, since when)
// and "N forces active" (with the list and Remove all).
import { api } from '../api';
import { can, gate } from '../auth';
import { clear, h } from '../dom';
import type { Freshness } from '../live/freshness';
import type { Force, Status } from '../types';
import { confirmAction } from './confirm';
import { clockTime as clock, tr } from '../i18n';

export const bannerText = {
  stale: (since: string) => tr('Not live: no data since {since}. The values shown are from then; reconnecting…', { since }),
  stopped: (since: string) => tr('The PLC is stopped (since {since}): values change only when written or single-stepped.', { since }),
  faulted: (since: string, fault: string) => tr('The PLC is faulted (since {since}): {fault}', { since, fault }),
  forces: (n: number) => (n === 1 ? tr('1 force active') : tr('{n} forces active', { n })),
  removeAll: tr('Remove all'),
  show: tr('List'),
  hide: tr('Hide'),
  confirmRemoveTitle: tr('Remove every force?'),
  confirmRemove: (n: number) => n === 1 ? tr('The forced input or output will follow the program and the plant again at once.') : tr('The {n} forced inputs and outputs will follow the program and the plant again at once.', { n }),
};


export class StaleBanner {
  readonly el = h('div', { class: 'stale-banner', role: 'status', 'data-testid': 'stale-banner', hidden: true });
  private shown: Freshness = 'live';
  private since = 0;

  /** Shows `f`; `sinceMs` is when the data stopped being live (kept while the state lasts). */
  update(f: Freshness, sinceMs: number, status: Status | null): void {
    if (f !== this.shown) {
      this.shown = f;
      this.since = sinceMs;
    }
    document.body.dataset.live = f;
    this.el.hidden = f === 'live';
    this.el.dataset.state = f;
    const since = clock(this.since);
    const t =
      f === 'stale' ? bannerText.stale(since) : f === 'stopped' ? bannerText.stopped(since) : f === 'faulted' ? bannerText.faulted(since, status?.fault ?? '') : '';
    if (this.el.textContent !== t) this.el.textContent = this.el.title = t;
  }
}

export class ForcesBanner {
  readonly el: HTMLElement;
  private readonly text = h('span', { class: 'forces-text', 'data-testid': 'forces-text' });
  private readonly list = h('ul', { class: 'forces-list', 'data-testid': 'forces-list', hidden: true });
  private readonly toggle = h('button', { class: 'small', 'data-testid': 'forces-toggle' }, bannerText.show);
  private readonly removeAll = h('button', { class: 'small danger', 'data-testid': 'forces-remove-all' }, bannerText.removeAll);
  private key = '';
  private count = 0;

  constructor(private readonly notify: (m: string, kind?: 'info' | 'error') => void) {
    this.el = h('div', { class: 'forces-banner', role: 'status', 'data-testid': 'forces-banner', hidden: true }, this.text, this.toggle, this.removeAll, this.list);
    gate(this.removeAll, 'force');
    this.toggle.onclick = () => {
      this.list.hidden = !this.list.hidden;
      this.toggle.textContent = this.list.hidden ? bannerText.show : bannerText.hide;
    };
    this.removeAll.onclick = async () => {
      if (!can('force') || !(await confirmAction(bannerText.confirmRemoveTitle, bannerText.confirmRemove(this.count), bannerText.removeAll))) return;
      try {
        await api.unforceAll();
      } catch (e) {
        this.notify(e instanceof Error ? e.message : String(e), 'error');
      }
    };
  }

  update(forces: Force[]): void {
    const key = JSON.stringify(forces);
    if (key === this.key) return;
    this.key = key;
    this.count = forces.length;
    this.el.hidden = forces.length === 0;
    this.text.textContent = bannerText.forces(forces.length);
    clear(this.list);
    for (const f of forces) this.list.append(h('li', { 'data-testid': `forces-item-${f.name}` }, `${f.name} = ${JSON.stringify(f.value)}`));
  }
}
