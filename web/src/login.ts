// The login page and the start of the studio.
//
// boot(): GET /api/me. 200 → the studio starts with that user (`"users": false`:
// no users configured, full rights, no login page). 401 → the login page; its
// POST /api/login sets the session cookie (HttpOnly: the page never sees it,
// and the bearer token of the reply is not kept), then the studio starts.
// Later, any 401 means the session ended (idle or absolute expiry, logout
// elsewhere): main.ts shows the login page again over the studio.
import { ApiError, api } from './api';
import { LOCAL, type Me, parseMe, setMe } from './auth';
import { h } from './dom';
import { tr } from './i18n';

/** The strings of the login page (one place; a Spanish catalogue comes later). */
export const loginText = {
  title: tr('Sign in to Alba'),
  user: tr('User'),
  password: tr('Password'),
  submit: tr('Sign in'),
  busy: tr('Signing in…'),
  missing: tr('Enter your user name and password'),
  wrong: tr('Wrong user name or password'),
  wait: (s: number) => tr('Too many failed attempts: wait {s} s before trying again', { s }),
  unreachable: (m: string) => tr('Cannot reach the server: {m}', { m }),
  badReply: tr('The server answered the login with something unexpected'),
  expired: (m: string) => tr('Your session has ended ({m}): sign in again', { m }),
  signedOut: tr('Signed out'),
  fatal: (m: string) => tr('Cannot start the studio: {m}', { m }),
  retryIn: (s: number) => tr('Trying again in {s} s…', { s }),
  retrying: tr('Trying again…'),
  retryNow: tr('Try now'),
};

/** The waits between attempts to reach a server that does not answer, in seconds (the last repeats). */
export const RETRY_DELAYS = [1, 2, 4, 8, 15, 30];

/** No answer at all, or a gateway's or an overloaded server's (502, 503, 504): worth trying again. */
export function unreachable(e: unknown): boolean {
  return e instanceof ApiError && (e.status === 0 || e.status === 502 || e.status === 503 || e.status === 504);
}

/**
 * `f()`, tried again while the server cannot be reached (a studio opened while
 * the runtime is down, or restarting): a line says why, counts down to the next
 * attempt (1 s, 2 s, 4 s … 30 s) and offers to try at once; it goes away when
 * the server answers. Any other failure is thrown.
 */
export async function untilReachable<T>(f: () => Promise<T>, root: HTMLElement = document.body): Promise<T> {
  let panel: HTMLElement | null = null;
  for (let attempt = 0; ; attempt++) {
    try {
      const r = await f();
      panel?.remove();
      return r;
    } catch (e) {
      if (!unreachable(e)) {
        panel?.remove();
        throw e;
      }
      const reason = h('span', { 'data-testid': 'unreachable-reason' }, loginText.fatal(e instanceof Error ? e.message : String(e)));
      const count = h('span', { class: 'countdown', 'data-testid': 'retry-countdown' });
      const now = h('button', { class: 'small', 'data-testid': 'retry-now' }, loginText.retryNow);
      const next = h('div', { class: 'unreachable', role: 'alert', 'data-testid': 'unreachable' }, reason, ' ', count, ' ', now);
      if (panel) panel.replaceWith(next);
      else root.append(next);
      panel = next;
      await new Promise<void>((go) => {
        let left = RETRY_DELAYS[Math.min(attempt, RETRY_DELAYS.length - 1)];
        const done = () => {
          clearInterval(timer);
          count.textContent = loginText.retrying;
          now.disabled = true;
          go();
        };
        const tick = () => {
          if (left <= 0) return done();
          count.textContent = loginText.retryIn(left);
          left--;
        };
        const timer = setInterval(tick, 1000);
        now.onclick = done;
        tick();
      });
    }
  }
}

export interface LoginOptions {
  /** Shown above the form (why the page is shown). */
  message?: string;
  /** The user logged in; the page has been removed. */
  onLoggedIn(me: Me): void;
  /** Where the page goes (document.body). */
  root?: HTMLElement;
}

/** Shows the login page (a full-window layer); returns it. */
export function showLogin(opts: LoginOptions): HTMLElement {
  const root = opts.root ?? document.body;
  const userIn = h('input', { name: 'user', autocomplete: 'username', required: true, 'data-testid': 'login-user' });
  const passIn = h('input', { name: 'password', type: 'password', autocomplete: 'current-password', required: true, 'data-testid': 'login-password' });
  const submit = h('button', { type: 'submit', class: 'primary', 'data-testid': 'login-submit' }, loginText.submit);
  const error = h('div', { class: 'login-error', role: 'alert', 'data-testid': 'login-error', hidden: true });
  let timer: ReturnType<typeof setInterval> | null = null;
  const showError = (text: string | null) => {
    error.hidden = text === null;
    error.textContent = text ?? '';
  };
  /** 429: the button stays disabled, counting down, until the wait is over. */
  const backOff = (seconds: number) => {
    let left = Math.max(1, Math.ceil(seconds));
    submit.disabled = true;
    showError(loginText.wait(left));
    if (timer) clearInterval(timer);
    timer = setInterval(() => {
      left -= 1;
      if (left > 0) {
        showError(loginText.wait(left));
        return;
      }
      if (timer) clearInterval(timer);
      timer = null;
      submit.disabled = false;
      showError(null);
    }, 1000);
  };
  const form = h(
    'form',
    { class: 'login-form', 'data-testid': 'login-form', novalidate: true },
    h('h1', null, loginText.title),
    opts.message ? h('p', { class: 'login-message', 'data-testid': 'login-message' }, opts.message) : null,
    h('label', null, h('span', null, loginText.user), userIn),
    h('label', null, h('span', null, loginText.password), passIn),
    error,
    submit,
  );
  const page = h('div', { class: 'login-page', 'data-testid': 'login-page' }, form);
  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    if (submit.disabled) return;
    const user = userIn.value.trim();
    const password = passIn.value;
    if (!user || !password) {
      showError(loginText.missing);
      return;
    }
    submit.disabled = true;
    submit.textContent = loginText.busy;
    let me: Me | null = null;
    try {
      me = parseMe(await api.login(user, password));
      if (!me) showError(loginText.badReply);
    } catch (err) {
      passIn.value = '';
      if (err instanceof ApiError && err.status === 429) {
        submit.textContent = loginText.submit;
        backOff(err.retryAfter ?? 1);
        return;
      }
      if (err instanceof ApiError && err.status === 401) showError(loginText.wrong);
      else if (err instanceof ApiError && err.status !== 0) showError(err.message);
      else showError(loginText.unreachable(err instanceof Error ? err.message : String(err)));
    }
    submit.textContent = loginText.submit;
    submit.disabled = false;
    if (!me) {
      passIn.focus();
      return;
    }
    if (timer) clearInterval(timer);
    page.remove();
    opts.onLoggedIn(me);
  });
  root.append(page);
  userIn.focus();
  return page;
}

/** A message for the next login page, across the reload after a logout. */
const NEXT_MESSAGE = 'alba.loginMessage';

export function setNextLoginMessage(message: string): void {
  try {
    sessionStorage.setItem(NEXT_MESSAGE, message);
  } catch {
    /* storage unavailable: no message */
  }
}

function takeNextLoginMessage(): string | undefined {
  try {
    const m = sessionStorage.getItem(NEXT_MESSAGE);
    sessionStorage.removeItem(NEXT_MESSAGE);
    return m ?? undefined;
  } catch {
    return undefined;
  }
}

/**
 * Finds out who is using the studio (GET /api/me), through the login page if
 * needed, then calls `start` with them (also set as auth.ts's current user).
 */
export async function boot(start: (me: Me) => void | Promise<void>, root: HTMLElement = document.body): Promise<void> {
  const go = (me: Me) => {
    setMe(me);
    return start(me);
  };
  let reply: unknown;
  try {
    reply = await untilReachable(api.me, root);
  } catch (e) {
    if (e instanceof ApiError && e.status === 401) {
      showLogin({ root, message: takeNextLoginMessage(), onLoggedIn: (me) => void go(me) });
      return;
    }
    // a server without users and without GET /api/me
    if (e instanceof ApiError && e.status === 404) return go(LOCAL);
    root.append(h('p', { class: 'fatal', 'data-testid': 'fatal' }, loginText.fatal(e instanceof Error ? e.message : String(e))));
    return;
  }
  takeNextLoginMessage();
  const me = parseMe(reply);
  if (!me) {
    root.append(h('p', { class: 'fatal', 'data-testid': 'fatal' }, loginText.fatal(`GET /api/me: ${JSON.stringify(reply)}`)));
    return;
  }
  return go(me);
}
