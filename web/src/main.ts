// The studio: top bar, tabs (one per program, ladder or IL, Tags, Trends), status
// bar (with the user and a logout) and notifications. Routes with the URL hash
// (#/program/main.lad, #/tags, #/trends). Starts through login.ts's boot():
// the login page first when the project has users and there is no session.
import './style.css';
import { ApiError, api, onUnauthorized } from './api';
import { type Me, gate } from './auth';
import { type Ctx, TagCache } from './ctx';
import { clear, h } from './dom';
import { setDomain } from './domain';
import { IlView } from './il/view';
import { StView } from './st/view';
import { LadderView } from './ladder/view';
import { NetView } from './net/view';
import { SfcView } from './sfc/view';
import { LiveClient } from './live/client';
import { boot, loginText, setNextLoginMessage, showLogin, untilReachable } from './login';
import { ScreensView } from './hmi/view';
import { HardwareTab } from './hardware/view';
import { VerifyTab } from './verify/view';
import { TagsView } from './tags/view';
import { TrendsView } from './trends/view';
import type { ProgramRef } from './types';
import { freshness } from './live/freshness';
import { AlarmBanner } from './ui/alarms';
import { AlarmsView } from './ui/alarmsView';
import { RecipesView } from './ui/recipesView';
import { ForcesBanner, StaleBanner } from './ui/banners';
import { confirmAction } from './ui/confirm';
import { showCommands } from './ui/commands';
import { installLongPress } from './ui/longpress';
import { StatusBar } from './ui/statusbar';
import { Station, applyStoredTheme, inKiosk, kioskRoute } from './ui/station';
import { LANGUAGES, language, setLanguage, tr } from './i18n';

interface View {
  el: HTMLElement;
  show(): void;
  hide(): void;
}

/** A program tab (ladder, IL, net or SFC): the top bar's Compile/Save act on it. */
type Editor = LadderView | IlView | StView | NetView | SfcView;
const isEditor = (v: View | null | undefined): v is Editor => v instanceof LadderView || v instanceof IlView || v instanceof StView || v instanceof NetView || v instanceof SfcView;

/** The strings of the shell (one place; a Spanish catalogue comes later). */
const text = {
  signedInAgain: (user: string) => tr('Signed in again as {user}', { user }),
  logoutFailed: (m: string) => tr('Sign out failed: {m}', { m }),
  confirmStopTitle: tr('Stop the PLC?'),
  confirmStop: tr('Scanning stops after the current scan and every output goes off.'),
  confirmStopOk: tr('Stop'),
  confirmRunTitle: tr('Start the PLC?'),
  confirmRun: tr('The program starts from its first scan and drives the outputs.'),
  confirmRunOk: tr('Run'),
};

const toasts = h('div', { class: 'toasts', 'data-testid': 'toasts' });

function notify(message: string, kind: 'info' | 'error' = 'info', key?: string): void {
  const t = h('div', { class: `toast ${kind}`, role: kind === 'error' ? 'alert' : 'status', 'data-testid': `toast-${kind}`, 'data-key': key }, message);
  // the outcome of the same action again: the new toast takes the old one's place
  if (key) toasts.querySelectorAll(`[data-key="${CSS.escape(key)}"]`).forEach((old) => old.remove());
  toasts.append(t);
  setTimeout(() => t.remove(), kind === 'error' ? 8000 : 4000);
}

async function start(me: Me): Promise<void> {
  // The domain first: the language, and the role table that decides what the
  // controls below enable.
  try {
    setDomain(await untilReachable(api.domain));
  } catch (e) {
    document.body.append(h('p', { class: 'fatal' }, tr('Cannot load the studio: {m}', { m: e instanceof Error ? e.message : String(e) })));
    return;
  }
  installLongPress();
  const live = new LiveClient();
  const tags = new TagCache();
  const statusBar = new StatusBar();
  statusBar.user(me);
  const projectName = h('span', { class: 'project', 'data-testid': 'project-name' }, '…');
  const runBtn = h('button', { class: 'run', 'data-testid': 'btn-run', title: tr('Start scanning') }, '▶ ', h('span', { class: 'word' }, tr('Run')));
  const stopBtn = h('button', { class: 'stop', 'data-testid': 'btn-stop', title: tr('Stop scanning (outputs off)') }, '■ ', h('span', { class: 'word' }, tr('Stop')));
  const compileBtn = h('button', { 'data-testid': 'btn-compile', title: tr('Check the program being edited') }, tr('Compile'));
  const saveBtn = h('button', { class: 'primary', 'data-testid': 'btn-save', title: tr('Save the program and apply it online') }, tr('Save'));
  const nav = h('nav', { class: 'tabs', 'data-testid': 'tabs' });
  const alarms = new AlarmBanner(notify);
  const stale = new StaleBanner();
  const forces = new ForcesBanner(notify);
  const main = h('main', { class: 'content', id: 'content', tabindex: '-1' });
  // The first stop of Tab: past the top bar, the tabs and the view's toolbars, to
  // what the view is about (its `data-skip-target`: the rungs, the tag table), else to the view.
  const skip = h('a', { class: 'skip-link', href: '#content', 'data-testid': 'skip-link' }, tr('Skip to content'));
  skip.onclick = (e: Event) => {
    e.preventDefault(); // the hash is the route
    (main.querySelector<HTMLElement>('[data-skip-target]') ?? main).focus();
  };
  document.body.append(
    skip,
    h('header', { class: 'topbar' },
      h('span', { class: 'logo' }, 'Alba'), projectName,
      h('span', { class: 'seg' }, runBtn, stopBtn),
      h('span', { class: 'seg edit-commands' }, compileBtn, saveBtn),
      h('span', { class: 'spacer' }),
      h('select', { class: 'lang', 'data-testid': 'lang', title: tr('Language'), onchange: (e: Event) => setLanguage((e.target as HTMLSelectElement).value as 'en' | 'es') },
        LANGUAGES.map(([code, name]) => h('option', { value: code, selected: code === language() }, name)))),
    nav,
    // One line kept for the banners whether they show or not, so that none pushes the view down
    // (their lists open over the view); "all clear" while none shows.
    h('div', { class: 'banners', 'data-testid': 'banners' },
      h('div', { class: 'banners-clear', 'data-testid': 'banners-clear' }, tr('Live · no alarm to acknowledge · no force')),
      stale.el, forces.el, alarms.el),
    main,
    statusBar.el,
    toasts,
  );
  // The operator station (ui/station.ts): the dark theme and the kiosk, in the status bar.
  let go = () => {};
  const station = new Station({ notify, onKiosk: () => go() });
  statusBar.el.append(station.el);

  // What the role may not do is disabled, saying why (auth.ts decides).
  gate(runBtn, 'runstop');
  gate(stopBtn, 'runstop');
  gate(compileBtn, 'edit');
  gate(saveBtn, 'edit');
  // Run/Stop/Compile/Save: what the role, the runtime's state and the tab allow (ui/commands.ts)
  let runState = '';
  let notLive = false;
  let current: View | null = null;
  const showButtons = () =>
    showCommands({ run: runBtn, stop: stopBtn, compile: compileBtn, save: saveBtn }, { stale: notLive, state: runState, editor: isEditor(current) });
  const showRunState = (state: string) => {
    runState = state;
    showButtons();
  };

  // The session ended (a 401): the login page over the studio, which keeps its
  // state (an edited program) for the same user; another user starts afresh.
  let leaving = false;
  let relogin: HTMLElement | null = null;
  const sessionEnded = (message: string) => {
    if (relogin || !me.users || leaving) return;
    live.close();
    relogin = showLogin({
      message: loginText.expired(message),
      onLoggedIn: (again) => {
        relogin = null;
        if (again.user !== me.user || again.role !== me.role) {
          leaving = true;
          location.reload();
          return;
        }
        live.connect();
        void tags.refresh().catch(() => undefined);
        notify(text.signedInAgain(again.user ?? ''));
      },
    });
  };
  onUnauthorized(sessionEnded);
  statusBar.onLogout(async () => {
    try {
      await api.logout();
    } catch (e) {
      if (!(e instanceof ApiError && e.status === 401)) notify(text.logoutFailed(e instanceof Error ? e.message : String(e)), 'error');
      return;
    }
    setNextLoginMessage(loginText.signedOut);
    leaving = true;
    location.reload();
  });

  // Whether the screen is live: one place for every view (live/freshness.ts).
  let liveSince = Date.now();
  const checkFresh = () => {
    const f = freshness(live.state, live.status, live.lastMessageMs, Date.now());
    if (f === 'live') liveSince = Date.now();
    stale.update(f, f === 'stale' ? live.lastMessageMs || liveSince : liveSince, live.status);
    statusBar.stale(f === 'stale');
    if (notLive !== (f === 'stale')) {
      notLive = f === 'stale';
      showButtons();
    }
  };
  setInterval(checkFresh, 1000);

  let lost = false;
  live.onState((s) => {
    statusBar.conn(s);
    checkFresh();
    // after a reconnection the tag table may have changed
    if (s === 'reconnecting') {
      lost = true;
      // the WebSocket may have been refused for an ended session: a 401 here says so
      if (me.users) void api.me().catch(() => undefined);
    } else if (s === 'connected' && lost) {
      lost = false;
      void tags.refresh().catch(() => undefined);
    }
  });
  live.onBatch((b) => {
    if (b.status) {
      statusBar.status(b.status);
      showRunState(b.status.state);
      forces.update(b.status.forces ?? []);
      checkFresh();
    }
    if (b.alarms) void alarms.update(b.alarms);
    b.errors.forEach((e) => console.warn('server:', e));
  });
  live.connect();

  const runStop = async (f: () => Promise<unknown>) => {
    try {
      const s = (await f()) as import('./types').Status;
      statusBar.status(s);
      live.status = s;
      showRunState(s.state);
      checkFresh();
    } catch (e) {
      notify(e instanceof ApiError ? e.message : String(e), 'error');
    }
  };
  runBtn.onclick = async () => {
    if (await confirmAction(text.confirmRunTitle, text.confirmRun, text.confirmRunOk)) await runStop(api.run);
  };
  stopBtn.onclick = async () => {
    if (await confirmAction(text.confirmStopTitle, text.confirmStop, text.confirmStopOk)) await runStop(api.stop);
  };

  let status, programs: ProgramRef[];
  try {
    [status, programs] = await untilReachable(() => Promise.all([api.status(), api.programs(), tags.refresh()]));
  } catch (e) {
    main.append(h('p', { class: 'fatal' }, tr('Cannot load the project: {m}', { m: e instanceof Error ? e.message : String(e) })));
    return;
  }
  projectName.textContent = status.project;
  document.title = `${status.project} — Alba`;
  statusBar.status(status);
  live.status = status;
  showRunState(status.state);
  forces.update(status.forces ?? []);
  checkFresh();

  const ctx: Ctx = { live, tags, notify };
  const views = new Map<string, { label: string; make: () => View; view?: View; testid: string }>();
  for (const p of programs) {
    views.set(`program/${p.name}`, {
      label: p.plant ? tr('{name} (plant)', { name: p.name }) : p.name,
      testid: `tab-program-${p.name}`,
      make: () => {
        const v =
          p.language === 'il' ? new IlView(ctx, p.name)
          : p.language === 'st' ? new StView(ctx, p.name)
          : p.language === 'net' ? new NetView(ctx, p.name)
          : p.language === 'sfc' ? new SfcView(ctx, p.name)
          : new LadderView(ctx, p.name);
        v.load().catch((e) => notify(`${p.name}: ${e.message}`, 'error'));
        return v;
      },
    });
  }
  views.set('tags', { label: tr('Tags'), testid: 'tab-tags', make: () => new TagsView(ctx) });
  views.set('screens', { label: tr('Screens'), testid: 'tab-screens', make: () => new ScreensView(ctx) });
  views.set('alarms', { label: tr('Alarms'), testid: 'tab-alarms', make: () => new AlarmsView(ctx) });
  views.set('recipes', { label: tr('Recipes'), testid: 'tab-recipes', make: () => new RecipesView(ctx) });
  views.set('hardware', { label: tr('Hardware'), testid: 'tab-hardware', make: () => new HardwareTab(ctx) });
  views.set('verify', { label: tr('Verify & Test'), testid: 'tab-verify', make: () => new VerifyTab(ctx) });
  // made at once: its pens record in the background from the start
  const trends = new TrendsView(ctx);
  views.set('trends', { label: tr('Trends'), testid: 'tab-trends', make: () => trends, view: trends });

  go = () => {
    let key = decodeURIComponent(location.hash.replace(/^#\/?/, '')) || [...views.keys()][0];
    if (inKiosk() && kioskRoute(key) !== key) {
      // a kiosk shows the screens and the alarms only
      key = kioskRoute(key);
      history.replaceState(null, '', `#/${key}`);
    }
    const entry = views.get(key) ?? views.get([...views.keys()][0])!;
    current?.hide();
    entry.view ??= entry.make();
    current = entry.view;
    clear(main);
    main.append(current.el);
    current.show();
    nav.querySelectorAll('a').forEach((a) => a.classList.toggle('active', a.dataset.key === key));
    showButtons();
  };
  for (const [key, v] of views) {
    nav.append(h('a', { href: `#/${encodeURIComponent(key).replace(/%2F/g, '/')}`, 'data-key': key, 'data-testid': v.testid }, v.label));
  }
  window.addEventListener('hashchange', go);
  go();

  compileBtn.onclick = async () => {
    if (!isEditor(current)) return;
    const ok = await current.check();
    notify(ok ? tr('{program}: no problems', { program: current.program }) : tr('{program}: see the problems list', { program: current.program }), ok ? 'info' : 'error');
  };
  saveBtn.onclick = () => {
    if (isEditor(current)) void current.save();
  };
  // AuroraLD's shortcuts where a browser lets a page have them (docs: web/README.md):
  // Ctrl+S save, Ctrl+B compile (Ctrl+C stays copy), Ctrl+R run, Ctrl+Shift+R stop
  // (both ask first), Alt+1 the first program, Alt+2 Tags, Alt+3 Trends.
  window.addEventListener('keydown', (e) => {
    if (inKiosk()) return; // no engineering shortcut in a kiosk
    const ctrl = e.ctrlKey || e.metaKey;
    const key = e.key.toLowerCase();
    const act = (f: () => void) => {
      e.preventDefault();
      f();
    };
    // (a disabled Save still keeps the browser's "Save page as" away)
    if (ctrl && !e.altKey && key === 's') act(() => !saveBtn.disabled && saveBtn.click());
    else if (ctrl && !e.altKey && key === 'b') act(() => !compileBtn.disabled && compileBtn.click());
    else if (ctrl && !e.altKey && key === 'r' && !e.shiftKey && !runBtn.disabled) act(() => runBtn.click());
    else if (ctrl && !e.altKey && key === 'r' && e.shiftKey && !stopBtn.disabled) act(() => stopBtn.click());
    else if (ctrl && key === 'r') e.preventDefault(); // not a reload of a running studio by habit
    else if (e.altKey && !ctrl && ['1', '2', '3'].includes(e.key)) {
      const target = e.key === '1' ? [...views.keys()][0] : e.key === '2' ? 'tags' : 'trends';
      act(() => (location.hash = `#/${target}`));
    }
  });
  window.addEventListener('beforeunload', (e) => {
    if (leaving) return;
    if ([...views.values()].some((v) => isEditor(v.view) && v.view.dirty)) e.preventDefault();
  });
}

applyStoredTheme();
void boot(start);
