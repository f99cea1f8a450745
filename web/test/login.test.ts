import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { onUnauthorized } from '../src/api';
import { LOCAL, type Me, can, me, setMe } from '../src/auth';
import { boot, setNextLoginMessage, showLogin } from '../src/login';

const json = (status: number, j: unknown, headers: Record<string, string> = {}) =>
  new Response(JSON.stringify(j), { status, headers: { 'Content-Type': 'application/json', ...headers } });

/**
 * A server with one user, ann/right-horse-battery (operator): GET /api/me
 * answers 401 until a login succeeded (then the "cookie" is set); a login
 * with `tries` failed attempts left before the back-off.
 */
function server(opts: { users?: boolean; backoffAfter?: number } = {}) {
  let session = false;
  let failures = 0;
  const calls: { method: string; path: string; init: RequestInit }[] = [];
  vi.stubGlobal('fetch', async (path: string, init: RequestInit = {}) => {
    calls.push({ method: init.method ?? 'GET', path, init });
    if (path === '/api/me') {
      if (opts.users === false) return json(200, { user: null, role: 'admin', users: false });
      return session ? json(200, { user: 'ann', role: 'operator' }) : json(401, { error: 'not signed in' });
    }
    if (path === '/api/login') {
      if (failures >= (opts.backoffAfter ?? Infinity)) return json(429, { error: 'too many failed logins' }, { 'Retry-After': '3' });
      const b = JSON.parse(init.body as string);
      if (b.user === 'ann' && b.password === 'right-horse-battery') {
        session = true;
        return json(200, { token: 'tok-123', user: 'ann', role: 'operator' });
      }
      failures++;
      return json(401, { error: 'wrong user or password' });
    }
    return json(404, { error: 'no such endpoint' });
  });
  return calls;
}

const tid = (id: string) => document.querySelector(`[data-testid="${id}"]`) as HTMLElement | null;
const settle = () => new Promise((r) => setTimeout(r, 0));

async function submit(user: string, password: string) {
  (tid('login-user') as HTMLInputElement).value = user;
  (tid('login-password') as HTMLInputElement).value = password;
  (tid('login-form') as HTMLFormElement).requestSubmit();
  for (let k = 0; k < 5; k++) await settle();
}

beforeEach(() => {
  document.body.innerHTML = '';
  localStorage.clear();
  sessionStorage.clear();
  setMe({ user: null, role: 'viewer', users: true });
});

afterEach(() => {
  vi.unstubAllGlobals();
  vi.useRealTimers();
  onUnauthorized(null);
});

describe('the start of the studio', () => {
  it('no users configured: no login page, full rights', async () => {
    server({ users: false });
    const started: Me[] = [];
    await boot((m) => void started.push(m));
    expect(started).toEqual([LOCAL]);
    expect(tid('login-form')).toBeNull();
    expect(can('runstop')).toBe(true);
  });

  it('a session already open: no login page, the user of the session', async () => {
    const calls: { method: string; path: string; init: RequestInit }[] = [];
    vi.stubGlobal('fetch', async (path: string, init: RequestInit = {}) => {
      calls.push({ method: init.method ?? 'GET', path, init });
      return json(200, { user: 'bob', role: 'engineer' });
    });
    const started: Me[] = [];
    await boot((m) => void started.push(m));
    expect(started).toEqual([{ user: 'bob', role: 'engineer', users: true }]);
    expect(me().user).toBe('bob');
    expect(tid('login-form')).toBeNull();
  });

  it('401: the login page; a wrong password is said, the right one starts the studio as that user', async () => {
    const calls = server();
    const started: Me[] = [];
    await boot((m) => void started.push(m));
    // as main.ts does once the studio runs: a 401 then means the session ended
    const ended: string[] = [];
    onUnauthorized((m) => ended.push(m));
    expect(tid('login-form')).not.toBeNull();
    expect(started).toEqual([]);

    await submit('ann', 'wrong-horse');
    expect(tid('login-error')?.hidden).toBe(false);
    expect(tid('login-error')?.textContent).toBe('Wrong user name or password');
    expect((tid('login-password') as HTMLInputElement).value).toBe('');
    expect(started).toEqual([]);
    expect(ended).toEqual([]); // a failed login is not an ended session

    await submit('', '');
    expect(tid('login-error')?.textContent).toBe('Enter your user name and password');

    await submit('ann', 'right-horse-battery');
    expect(tid('login-form')).toBeNull();
    expect(started).toEqual([{ user: 'ann', role: 'operator', users: true }]);
    expect(me()).toEqual({ user: 'ann', role: 'operator', users: true });
    expect(can('write')).toBe(true);
    expect(can('force')).toBe(false);

    const login = calls.filter((c) => c.path === '/api/login');
    expect(login.length).toBe(2);
    for (const c of login) {
      expect(c.method).toBe('POST');
      expect((c.init.headers as Record<string, string>)['Content-Type']).toBe('application/json');
      expect(c.init.credentials).toBe('same-origin');
    }
    expect(JSON.parse(login[1].init.body as string)).toEqual({ user: 'ann', password: 'right-horse-battery' });
    // the session is the server's cookie: the token of the reply is kept nowhere
    expect(JSON.stringify({ ...localStorage })).not.toContain('tok-123');
    expect(JSON.stringify({ ...sessionStorage })).not.toContain('tok-123');
    expect(document.cookie).not.toContain('tok-123');
  });

  it('429: the wait is shown and the button stays disabled until it is over', async () => {
    server({ backoffAfter: 1 });
    await boot(() => undefined);
    await submit('ann', 'bad-1');
    expect(tid('login-error')?.textContent).toBe('Wrong user name or password');
    vi.useFakeTimers();
    (tid('login-user') as HTMLInputElement).value = 'ann';
    (tid('login-password') as HTMLInputElement).value = 'bad-2';
    (tid('login-form') as HTMLFormElement).requestSubmit();
    await vi.advanceTimersByTimeAsync(0);
    const button = tid('login-submit') as HTMLButtonElement;
    expect(tid('login-error')?.textContent).toBe('Too many failed attempts: wait 3 s before trying again');
    expect(button.disabled).toBe(true);
    await vi.advanceTimersByTimeAsync(1000);
    expect(tid('login-error')?.textContent).toBe('Too many failed attempts: wait 2 s before trying again');
    expect(button.disabled).toBe(true);
    await vi.advanceTimersByTimeAsync(2000);
    expect(button.disabled).toBe(false);
    expect(tid('login-error')?.hidden).toBe(true);
  });

  it('the message of a logout is shown once on the next login page', async () => {
    server();
    setNextLoginMessage('Signed out');
    await boot(() => undefined);
    expect(tid('login-message')?.textContent).toBe('Signed out');
    document.body.innerHTML = '';
    await boot(() => undefined);
    expect(tid('login-message')).toBeNull();
  });

  it('a server that cannot be reached: said, tried again with a countdown, and the studio starts when it answers', async () => {
    let up = false;
    let tries = 0;
    vi.stubGlobal('fetch', async () => {
      tries++;
      if (!up) throw new TypeError('Failed to fetch');
      return json(200, { user: null, role: 'admin', users: false });
    });
    vi.useFakeTimers();
    const started: Me[] = [];
    const booted = boot((m) => void started.push(m));
    await vi.advanceTimersByTimeAsync(0);
    expect(started).toEqual([]);
    expect(tid('unreachable-reason')?.textContent).toBe('Cannot start the studio: cannot reach the server: Failed to fetch');
    expect(tid('retry-countdown')?.textContent).toBe('Trying again in 1 s…');
    await vi.advanceTimersByTimeAsync(1000);
    expect(tries).toBe(2);
    // the waits grow: 2 s, then 4 s
    expect(tid('retry-countdown')?.textContent).toBe('Trying again in 2 s…');
    await vi.advanceTimersByTimeAsync(1000);
    expect(tid('retry-countdown')?.textContent).toBe('Trying again in 1 s…');
    await vi.advanceTimersByTimeAsync(1000);
    expect([tries, tid('retry-countdown')?.textContent]).toEqual([3, 'Trying again in 4 s…']);
    // "Try now" does not wait; the server is back: the line goes, the studio starts
    up = true;
    tid('retry-now')!.click();
    await booted;
    expect(tries).toBe(4);
    expect(started).toEqual([LOCAL]);
    expect(tid('unreachable')).toBeNull();
    expect(tid('fatal')).toBeNull();
  });

  it('untilReachable: another failure than no answer is thrown at once', async () => {
    const { ApiError } = await import('../src/api');
    const { untilReachable } = await import('../src/login');
    let n = 0;
    await expect(untilReachable(async () => {
      n++;
      throw new ApiError(403, 'forbidden');
    })).rejects.toThrow('forbidden');
    expect(n).toBe(1);
    expect(tid('unreachable')).toBeNull();
  });

  it('showLogin over a running studio (session ended) says why and hands back the user', async () => {
    server();
    const again: Me[] = [];
    showLogin({ message: 'Your session has ended (session expired): sign in again', onLoggedIn: (m) => again.push(m) });
    expect(tid('login-message')?.textContent).toBe('Your session has ended (session expired): sign in again');
    await submit('ann', 'right-horse-battery');
    expect(again).toEqual([{ user: 'ann', role: 'operator', users: true }]);
    expect(tid('login-page')).toBeNull();
  });
});
