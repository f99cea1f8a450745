// The operator station (issue 35, point 8): a dark theme for control rooms and
// a kiosk mode.
//
// The theme is a choice of this browser (localStorage `alba.theme`), set on
// <html data-theme>; the style sheet's custom properties follow it, so every
// view — screens, banners, faceplates, trends, tables — changes at once.
//
// Kiosk: the runtime screens, the alarms and the faceplates only, full screen,
// no engineering tab (<html data-station="kiosk">; main.ts keeps the route on
// those views). Entered from the status bar or with `?kiosk=1`, and remembered
// in localStorage so that a reload (or a power cut) comes back in kiosk. To
// leave it the server must say the session is an engineer's (GET /api/me); if
// it is not, an engineer signs in over it (POST /api/login checks the password
// and gives the role) — the session becomes the engineer's. This is a lock on
// the studio's layout, not the security boundary: the server's role table
// still decides every write (docs/operator-station.md).
import { type Me, type Role, atLeast, parseMe } from '../auth';
import { api } from '../api';
import { h } from '../dom';
import { tr } from '../i18n';
import { showLogin } from '../login';

export type Theme = 'light' | 'dark';

const THEME_KEY = 'alba.theme';
const KIOSK_KEY = 'alba.kiosk';
/** The role that may leave the kiosk. */
export const KIOSK_EXIT_ROLE: Role = 'engineer';
/** The views a kiosk shows (route keys). */
export const KIOSK_VIEWS: readonly string[] = ['screens', 'alarms'];

export const stationText = {
  dark: tr('Dark'),
  light: tr('Light'),
  themeTitle: tr('Switch between the light and the dark (control room) theme'),
  kiosk: tr('Kiosk'),
  kioskTitle: tr('Only the screens and the alarms, full screen; an engineer leaves it'),
  leave: tr('Leave kiosk'),
  leaveTitle: tr('An engineer signs in to leave the kiosk'),
  signIn: tr('An engineer signs in to leave the kiosk.'),
  notEngineer: (who: string) => tr('{who} may not leave the kiosk: it needs the engineer role', { who }),
  cancel: tr('Cancel'),
};

function get(key: string): string | null {
  try {
    return localStorage.getItem(key);
  } catch {
    return null;
  }
}

function put(key: string, value: string | null): void {
  try {
    if (value === null) localStorage.removeItem(key);
    else localStorage.setItem(key, value);
  } catch {
    /* storage unavailable: the choice lasts until the page reloads */
  }
}

/** A stored theme, else the system's preference. */
export function storedTheme(stored: string | null, prefersDark: boolean): Theme {
  if (stored === 'dark' || stored === 'light') return stored;
  return prefersDark ? 'dark' : 'light';
}

export function theme(): Theme {
  return document.documentElement.dataset.theme === 'dark' ? 'dark' : 'light';
}

export function setTheme(t: Theme, remember = true): void {
  document.documentElement.dataset.theme = t;
  document.documentElement.style.colorScheme = t;
  if (remember) put(THEME_KEY, t);
}

/** At boot, before the login page: the remembered theme. */
export function applyStoredTheme(): void {
  const prefersDark = typeof matchMedia === 'function' && matchMedia('(prefers-color-scheme: dark)').matches;
  setTheme(storedTheme(get(THEME_KEY), prefersDark), false);
}

/**
 * Whether the studio starts in kiosk: `?kiosk=1` (remembered), `?kiosk=0`
 * asks nothing (leaving still needs an engineer), else what was remembered.
 */
export function kioskWanted(search: string, stored: string | null): boolean {
  const q = new URLSearchParams(search).get('kiosk');
  if (q === '1' || q === 'true') return true;
  return stored === '1';
}

export function inKiosk(): boolean {
  return document.documentElement.dataset.station === 'kiosk';
}

/** The route a kiosk allows: its own views, else the screens. */
export function kioskRoute(key: string): string {
  return KIOSK_VIEWS.includes(key) ? key : KIOSK_VIEWS[0];
}

/** May this session leave the kiosk? With no users (a local studio) anyone may. */
export function mayLeaveKiosk(who: Me): boolean {
  return !who.users || atLeast(who.role, KIOSK_EXIT_ROLE);
}

function setKiosk(on: boolean): void {
  if (on) document.documentElement.dataset.station = 'kiosk';
  else delete document.documentElement.dataset.station;
  put(KIOSK_KEY, on ? '1' : null);
}

/** Full screen where the browser allows it (a gesture is needed: the first tap in kiosk does it). */
function fullScreen(on: boolean): void {
  if (on && !document.fullscreenElement) void document.documentElement.requestFullscreen?.().catch(() => undefined);
  if (!on && document.fullscreenElement) void document.exitFullscreen?.().catch(() => undefined);
}

export interface StationOptions {
  /** Called when the kiosk is entered or left (main.ts re-routes). */
  onKiosk(on: boolean): void;
  notify(message: string, kind?: 'info' | 'error'): void;
}

/**
 * The station's controls for the status bar: the theme toggle, Kiosk, and
 * (shown only in kiosk) Leave kiosk. Starts in kiosk when asked.
 */
export class Station {
  readonly el: HTMLElement;
  private readonly themeBtn = h('button', { class: 'small link station-theme', 'data-testid': 'btn-theme', title: stationText.themeTitle });
  private readonly kioskBtn = h('button', { class: 'small link station-kiosk', 'data-testid': 'btn-kiosk', title: stationText.kioskTitle }, stationText.kiosk);
  private readonly leaveBtn = h('button', { class: 'kiosk-leave', 'data-testid': 'btn-kiosk-leave', title: stationText.leaveTitle }, stationText.leave);

  constructor(private readonly opts: StationOptions) {
    this.showTheme();
    this.themeBtn.onclick = () => {
      setTheme(theme() === 'dark' ? 'light' : 'dark');
      this.showTheme();
    };
    this.kioskBtn.onclick = () => this.enter(true);
    this.leaveBtn.onclick = () => void this.leave();
    this.el = h('span', { class: 'station' }, this.themeBtn, this.kioskBtn);
    document.body.append(this.leaveBtn);
    // a kiosk's first tap takes the whole display (browsers want a gesture for it)
    document.addEventListener('pointerdown', () => inKiosk() && fullScreen(true), { capture: true });
    if (kioskWanted(location.search, get(KIOSK_KEY))) this.enter(false);
  }

  private showTheme(): void {
    const dark = theme() === 'dark';
    this.themeBtn.textContent = dark ? `☀ ${stationText.light}` : `☾ ${stationText.dark}`;
    this.themeBtn.setAttribute('aria-pressed', String(dark));
  }

  private enter(gesture: boolean): void {
    setKiosk(true);
    if (gesture) fullScreen(true);
    this.opts.onKiosk(true);
  }

  private exit(): void {
    setKiosk(false);
    fullScreen(false);
    // `?kiosk=1` would bring it back on a reload
    if (new URLSearchParams(location.search).has('kiosk')) history.replaceState(null, '', location.pathname + location.hash);
    this.opts.onKiosk(false);
  }

  /** The server says who the session is; an engineer leaves, anyone else signs in as one. */
  async leave(): Promise<void> {
    let who: Me | null = null;
    try {
      who = parseMe(await api.me());
    } catch {
      who = null; // ended session or no answer: an engineer signs in
    }
    if (who && mayLeaveKiosk(who)) {
      this.exit();
      return;
    }
    const page = showLogin({
      message: stationText.signIn,
      onLoggedIn: (again) => {
        if (mayLeaveKiosk(again)) {
          this.exit();
          // the studio now belongs to the engineer: start afresh as them
          location.reload();
        } else {
          this.opts.notify(stationText.notEngineer(again.user ?? ''), 'error');
          // someone else's session now: the page follows it (still in kiosk)
          if (who && again.user !== who.user) location.reload();
        }
      },
    });
    page.dataset.testid = 'kiosk-login';
    const cancel = h('button', { type: 'button', 'data-testid': 'kiosk-login-cancel' }, stationText.cancel);
    cancel.onclick = () => page.remove();
    page.querySelector('form')?.append(cancel);
  }
}
