//! Who makes a request, and whether they may (docs/security.md, "Sessions
//! and roles").
//!
//! - [`Auth`] holds the project's users, the sessions of logged-in users
//!   and the failed-login accounting; `POST /api/login` (api/session.rs)
//!   opens a session, identified by a 256-bit random token sent back as
//!   the `alba_session` cookie and in the reply (for `Authorization:
//!   Bearer`). Sessions end after `[session] idle_minutes` without a
//!   request, `max_hours` after the login, or on logout. Only a hash of
//!   each token is kept.
//! - `crate::gate::session`, the one place where routes meet roles, runs before every
//!   route: it finds the role the route needs in `crate::ROUTE_ROLES`,
//!   answers 401 without a valid session (when users exist) and 403 for
//!   too small a role, and attaches a [`Who`] to the request.
//! - Handlers and the audit trail take a [`Who`] as an extractor:
//!   `async fn put(who: Who, …)` (or `Option<Who>` on public routes).
//!
//! With no users configured the API is open to loopback clients only,
//! each acting as `admin` with no user name; `alba run` (crates/app)
//! refuses a non-loopback listener then.

pub use alba_auth::Role;

use crate::error::ApiError;
use axum::extract::{FromRequestParts, OptionalFromRequestParts};
use axum::http::request::Parts;
use axum::http::{HeaderMap, Method, header};
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// The session cookie's name.
pub const COOKIE: &str = "alba_session";
/// Sessions kept at most (the least recently used go first).
pub const MAX_SESSIONS: usize = 1024;
/// Sessions of one user kept at most (their least recently used go first).
pub const MAX_SESSIONS_PER_USER: usize = 16;
/// Password verifications run at once (each argon2 verification takes
/// ~19 MiB and tens of milliseconds; further logins queue).
pub const VERIFY_AT_ONCE: usize = 2;

/// The identity of a request: the logged-in user (`None` when no users
/// are configured and the request acts with full rights on loopback), its
/// role, and the client's address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Who {
    pub user: Option<String>,
    pub role: Role,
    pub addr: SocketAddr,
}

impl<S: Send + Sync> FromRequestParts<S> for Who {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Who, ApiError> {
        parts
            .extensions
            .get::<Who>()
            .cloned()
            .ok_or_else(|| ApiError::Internal("the request has no identity (no session layer)".into()))
    }
}

/// On public routes (login, logout): the session's identity if there is one.
impl<S: Send + Sync> OptionalFromRequestParts<S> for Who {
    type Rejection = std::convert::Infallible;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Option<Who>, Self::Rejection> {
        Ok(parts.extensions.get::<Who>().cloned())
    }
}

/// What a route needs (the table `crate::ROUTE_ROLES`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Anybody: the studio's files, login, logout.
    Public,
    /// A session with at least this role.
    Role(Role),
}

/// The time, for session expiry and login back-off; tests pass a
/// [`ManualClock`].
pub trait Clock: Send + Sync {
    fn now(&self) -> Instant;
}

/// The monotonic clock of the system.
pub struct SystemClock;

impl Clock for SystemClock {
    fn now(&self) -> Instant {
        Instant::now()
    }
}

/// A clock that moves only when told to (tests).
pub struct ManualClock {
    start: Instant,
    ms: AtomicU64,
}

impl ManualClock {
    pub fn new() -> ManualClock {
        ManualClock {
            start: Instant::now(),
            ms: AtomicU64::new(0),
        }
    }

    pub fn advance(&self, d: Duration) {
        let ms = u64::try_from(d.as_millis()).unwrap_or(u64::MAX);
        self.ms.fetch_add(ms, Ordering::SeqCst);
    }
}

impl Default for ManualClock {
    fn default() -> ManualClock {
        ManualClock::new()
    }
}

impl Clock for ManualClock {
    fn now(&self) -> Instant {
        self.start + Duration::from_millis(self.ms.load(Ordering::SeqCst))
    }
}

/// The users logins are checked against: `alba_auth::Users`, or a test's.
pub trait UserStore: Send + Sync {
    fn is_empty(&self) -> bool;
    /// The role of user `name`, if there is such a user.
    fn role(&self, name: &str) -> Option<Role>;
    /// The role of `name` when `password` is theirs; an unknown name must
    /// cost what a wrong password costs. Blocking.
    fn verify(&self, name: &str, password: &str) -> Option<Role>;
}

impl UserStore for alba_auth::Users {
    fn is_empty(&self) -> bool {
        alba_auth::Users::is_empty(self)
    }
    fn role(&self, name: &str) -> Option<Role> {
        alba_auth::Users::role(self, name)
    }
    fn verify(&self, name: &str, password: &str) -> Option<Role> {
        alba_auth::Users::verify(self, name, password)
    }
}

/// How long sessions last.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// A session with no request for this long ends.
    pub idle: Duration,
    /// A session ends this long after its login.
    pub max: Duration,
}

impl Limits {
    /// From alba.toml's `[session]`.
    pub fn from_config(s: &alba_settings::Session) -> Limits {
        Limits {
            idle: Duration::from_secs(u64::from(s.idle_minutes) * 60),
            max: Duration::from_secs(u64::from(s.max_hours) * 3600),
        }
    }
}

impl Default for Limits {
    fn default() -> Limits {
        Limits::from_config(&alba_settings::Session::default())
    }
}

#[derive(Debug, Clone)]
struct Session {
    user: String,
    created: Instant,
    last: Instant,
}

/// How often the store's files are looked at for a change.
const RELOAD_EVERY: Duration = Duration::from_secs(1);

/// A file's modification time and length; `None` when it is missing.
type Stamp = Option<(std::time::SystemTime, u64)>;

/// Re-reading the project's store when users.toml (or alba.toml, for the
/// deprecated `[opcua.users]`) changes.
struct Reload {
    dir: std::path::PathBuf,
    /// When the files were last looked at, and what they were then.
    seen: Mutex<(Option<Instant>, Vec<Stamp>)>,
}

impl Reload {
    fn stamps(&self) -> Vec<Stamp> {
        [alba_auth::USERS_FILE, "alba.toml"]
            .iter()
            .map(|f| {
                let m = std::fs::metadata(self.dir.join(f)).ok()?;
                Some((m.modified().ok()?, m.len()))
            })
            .collect()
    }
}

/// A successful login.
#[derive(Debug, Clone)]
pub struct LoggedIn {
    pub token: String,
    pub user: String,
    pub role: Role,
}

/// Users, sessions and failed-login accounting of one server.
pub struct Auth {
    users: std::sync::RwLock<Arc<dyn UserStore>>,
    reload: Option<Reload>,
    limits: Limits,
    clock: Arc<dyn Clock>,
    /// By the SHA-256 of the token.
    sessions: Mutex<HashMap<[u8; 32], Session>>,
    /// Failures per (user, address) pair and per address: what holds a login back.
    backoff: Mutex<alba_auth::Backoff>,
    /// Failures per user name, from any address: never a refusal (that would
    /// lock the user out for everyone while someone guesses), an alert.
    guessed: Mutex<alba_auth::Backoff>,
    /// When each current alert was raised (Unix ms), by user name.
    alerted: Mutex<HashMap<String, i64>>,
    verifying: tokio::sync::Semaphore,
}

/// Failed logins for one user name (within `alba_auth::FORGET_AFTER` of each
/// other) that raise the alert `login` in `GET /api/status` and a line on stderr.
pub const GUESSING_ALERT_AFTER: u32 = 10;

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

fn digest(token: &str) -> [u8; 32] {
    Sha256::digest(token.as_bytes()).into()
}

/// A fresh token: 256 random bits, hex.
fn new_token() -> Result<String, ApiError> {
    let mut bytes = [0u8; 32];
    getrandom::fill(&mut bytes).map_err(|e| ApiError::Internal(format!("no randomness for a session token: {e}")))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

impl Auth {
    pub fn new(users: Arc<dyn UserStore>, limits: Limits) -> Auth {
        Auth {
            users: std::sync::RwLock::new(users),
            reload: None,
            limits,
            clock: Arc::new(SystemClock),
            sessions: Mutex::new(HashMap::new()),
            backoff: Mutex::new(alba_auth::Backoff::new()),
            guessed: Mutex::new(alba_auth::Backoff::new()),
            alerted: Mutex::new(HashMap::new()),
            verifying: tokio::sync::Semaphore::new(VERIFY_AT_ONCE),
        }
    }

    /// No users: loopback clients act as admin.
    pub fn open() -> Auth {
        Auth::new(Arc::new(alba_auth::Users::default()), Limits::default())
    }

    /// Takes the time from `clock` (tests).
    pub fn with_clock(mut self, clock: Arc<dyn Clock>) -> Auth {
        self.clock = clock;
        self
    }

    /// Re-reads the store of the project in `dir` (`alba_auth::Users::load`)
    /// within a second of a change to its files (`alba user …` while the
    /// server runs): added users can log in, a removed user's sessions
    /// end, a changed role applies to open sessions. A store that does not
    /// load leaves the previous one in force.
    pub fn reloading_from(mut self, dir: &std::path::Path) -> Auth {
        let r = Reload {
            dir: dir.to_path_buf(),
            seen: Mutex::new((None, Vec::new())),
        };
        let stamps = r.stamps();
        lock(&r.seen).1 = stamps;
        self.reload = Some(r);
        self
    }

    /// The store, re-read first if its files changed (see [`Auth::reloading_from`]).
    fn users(&self) -> Arc<dyn UserStore> {
        if let Some(r) = &self.reload {
            let now = self.clock.now();
            let mut seen = lock(&r.seen);
            if seen.0.is_none_or(|t| now.saturating_duration_since(t) >= RELOAD_EVERY) {
                seen.0 = Some(now);
                let stamps = r.stamps();
                if stamps != seen.1 {
                    seen.1 = stamps;
                    if let Ok(u) = alba_auth::Users::load(&r.dir) {
                        *self.users.write().unwrap_or_else(PoisonError::into_inner) = Arc::new(u);
                    }
                }
            }
        }
        self.users.read().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// Whether the project has users (else loopback clients act as admin).
    pub fn has_users(&self) -> bool {
        !self.users().is_empty()
    }

    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// Checks `password` for `user` (after the back-off of that user from
    /// the client's address, and of the address) and opens a session. Every
    /// attempt that is not held back by the back-off runs the same
    /// verification, for known and unknown users alike. Failures for one
    /// user from other addresses never hold it back (someone guessing a
    /// name must not lock its owner out): they raise an alert instead
    /// ([`Auth::alerts`]).
    pub async fn login(&self, user: &str, password: &str, addr: SocketAddr) -> Result<LoggedIn, ApiError> {
        let client = client_key(addr.ip());
        let user_key = format!("user:{user}@{client}");
        let addr_key = format!("addr:{client}");
        // Queued logins see the failures of those before them.
        let _permit = self
            .verifying
            .acquire()
            .await
            .map_err(|_| ApiError::Internal("logins are closed".into()))?;
        {
            let now = self.clock.now();
            let b = lock(&self.backoff);
            let waits = [b.check(&user_key, now), b.check(&addr_key, now)];
            if let Some(wait) = waits.iter().filter_map(|w| w.err()).max() {
                return Err(ApiError::TooManyAttempts(wait));
            }
        }
        let users = self.users();
        let (u, p) = (user.to_string(), password.to_string());
        let role = tokio::task::spawn_blocking(move || users.verify(&u, &p))
            .await
            .map_err(|e| ApiError::Internal(format!("password check: {e}")))?;
        let now = self.clock.now();
        let Some(role) = role else {
            let mut b = lock(&self.backoff);
            b.failure(&user_key, now);
            b.failure(&addr_key, now);
            drop(b);
            let mut g = lock(&self.guessed);
            g.failure(user, now);
            if g.failures(user) == GUESSING_ALERT_AFTER {
                lock(&self.alerted).insert(user.to_string(), alba_control::now_ms());
                eprintln!(
                    "warning: {GUESSING_ALERT_AFTER} failed logins for user `{user}` within 15 minutes (the last from \
                     {client}): someone may be guessing its password"
                );
            }
            return Err(ApiError::Unauthorized("unknown user or wrong password".into()));
        };
        lock(&self.backoff).success(&user_key);
        let token = new_token()?;
        let mut sessions = lock(&self.sessions);
        sessions.retain(|_, s| self.session_alive(s, now));
        // One user's logins end that user's oldest sessions, not others'.
        let theirs = sessions.values().filter(|s| s.user == user).count();
        if theirs >= MAX_SESSIONS_PER_USER
            && let Some(oldest) = sessions
                .iter()
                .filter(|(_, s)| s.user == user)
                .min_by_key(|(_, s)| s.last)
                .map(|(k, _)| *k)
        {
            sessions.remove(&oldest);
        }
        if sessions.len() >= MAX_SESSIONS
            && let Some(oldest) = sessions.iter().min_by_key(|(_, s)| s.last).map(|(k, _)| *k)
        {
            sessions.remove(&oldest);
        }
        sessions.insert(
            digest(&token),
            Session {
                user: user.to_string(),
                created: now,
                last: now,
            },
        );
        Ok(LoggedIn {
            token,
            user: user.to_string(),
            role,
        })
    }

    /// The users someone may be guessing the password of: `(user, failed
    /// logins, since when in Unix ms)` for those with [`GUESSING_ALERT_AFTER`]
    /// or more, each within 15 minutes of the one before.
    pub fn alerts(&self) -> Vec<(String, u32, i64)> {
        let now = self.clock.now();
        let current = lock(&self.guessed).at_least(GUESSING_ALERT_AFTER, now);
        let mut alerted = lock(&self.alerted);
        alerted.retain(|u, _| current.iter().any(|(c, _)| c == u));
        let mut out: Vec<(String, u32, i64)> = current
            .into_iter()
            .map(|(u, n)| {
                let since = alerted.get(&u).copied().unwrap_or(0);
                (u, n, since)
            })
            .collect();
        out.sort();
        out
    }

    fn session_alive(&self, s: &Session, now: Instant) -> bool {
        now.saturating_duration_since(s.last) < self.limits.idle
            && now.saturating_duration_since(s.created) < self.limits.max
    }

    /// The user and role of the session `token`, if it is alive (its idle
    /// time restarts); an ended session is forgotten, and so is the
    /// session of a user no longer in the store. The role is the user's
    /// role now.
    pub fn session(&self, token: &str) -> Option<(String, Role)> {
        let users = self.users();
        let now = self.clock.now();
        let key = digest(token);
        let mut sessions = lock(&self.sessions);
        let s = sessions.get_mut(&key)?;
        let role = users.role(&s.user);
        let Some(role) = role.filter(|_| self.session_alive(s, now)) else {
            sessions.remove(&key);
            return None;
        };
        s.last = now;
        Some((s.user.clone(), role))
    }

    /// Ends the session `token` (nothing if there is none).
    pub fn logout(&self, token: &str) {
        lock(&self.sessions).remove(&digest(token));
    }

    /// Sessions kept (alive or not yet swept).
    pub fn sessions(&self) -> usize {
        lock(&self.sessions).len()
    }

    /// Whether the session of `key` is alive, without counting this as a
    /// request (its idle time goes on).
    pub fn alive(&self, key: &SessionKey) -> bool {
        let users = self.users();
        let now = self.clock.now();
        lock(&self.sessions)
            .get(&key.0)
            .is_some_and(|s| self.session_alive(s, now) && users.role(&s.user).is_some())
    }
}

/// Which session a request came with (an extension the layer adds beside
/// [`Who`]): the WebSocket closes when it ends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SessionKey([u8; 32]);

/// The `Set-Cookie` value carrying `token`; `secure` over HTTPS.
pub fn cookie(token: &str, secure: bool) -> String {
    let secure = if secure { "; Secure" } else { "" };
    format!("{COOKIE}={token}; HttpOnly; SameSite=Strict; Path=/{secure}")
}

/// The `Set-Cookie` value that deletes the cookie.
pub fn cleared_cookie(secure: bool) -> String {
    let secure = if secure { "; Secure" } else { "" };
    format!("{COOKIE}=; HttpOnly; SameSite=Strict; Path=/; Max-Age=0{secure}")
}

/// The client a failed login is counted against: its IPv4 address, or
/// the /64 network of an IPv6 address (one host usually holds a whole
/// /64, and could otherwise change address at every attempt).
fn client_key(ip: std::net::IpAddr) -> String {
    match ip.to_canonical() {
        std::net::IpAddr::V4(v4) => v4.to_string(),
        std::net::IpAddr::V6(v6) => {
            let s = v6.segments();
            format!("{:x}:{:x}:{:x}:{:x}::/64", s[0], s[1], s[2], s[3])
        }
    }
}

/// The session token a request carries: `Authorization: Bearer`, else the
/// `alba_session` cookie.
pub fn token(headers: &HeaderMap) -> Option<String> {
    // Another scheme (a reverse proxy's Basic) leaves the cookie in force.
    let bearer = headers
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().split_once(' '))
        .filter(|(scheme, _)| scheme.eq_ignore_ascii_case("bearer"));
    if let Some((_, t)) = bearer {
        return Some(t.trim().to_string());
    }
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|c| c.trim().split_once('='))
        .find(|(name, _)| *name == COOKIE)
        .map(|(_, v)| v.trim().to_string())
        .filter(|v| !v.is_empty())
}

/// The role a request needs: the entry of the route that serves it in
/// `table` (method `*` matches any), else viewer for a read (GET, HEAD)
/// and admin for anything else (a route nobody classified stays closed).
/// A request no route serves goes to the studio's files: public, unless
/// its path is under `/api` (then as an unclassified route).
pub fn needed(table: &[(&str, &str, Access)], method: &Method, route: Option<&str>, path: &str) -> Access {
    let method = if *method == Method::HEAD { &Method::GET } else { method };
    match route {
        Some(route) => {
            if let Some((_, _, access)) = table
                .iter()
                .find(|(m, r, _)| *r == route && (*m == "*" || *m == method.as_str()))
            {
                return *access;
            }
        }
        None if !path.starts_with("/api/") && path != "/api" => return Access::Public,
        None => {}
    }
    if *method == Method::GET {
        Access::Role(Role::Viewer)
    } else {
        Access::Role(Role::Admin)
    }
}

/// Who a request is (and its session): `Ok(None)` for an anonymous
/// request, an error for an ended or unknown session.
pub(crate) fn identify(
    auth: &Auth,
    headers: &HeaderMap,
    addr: SocketAddr,
) -> Result<Option<(Who, Option<SessionKey>)>, ApiError> {
    if !auth.has_users() {
        // (An IPv4 client of a dual-stack listener shows as ::ffff:a.b.c.d.)
        // A request a proxy forwarded is not local, wherever the proxy runs.
        let proxied = ["forwarded", "x-forwarded-for", "x-real-ip"]
            .iter()
            .any(|h| headers.contains_key(*h));
        let who = Who {
            user: None,
            role: Role::Admin,
            addr,
        };
        return Ok((addr.ip().to_canonical().is_loopback() && !proxied).then_some((who, None)));
    }
    let Some(token) = token(headers) else { return Ok(None) };
    match auth.session(&token) {
        Some((user, role)) => Ok(Some((
            Who {
                user: Some(user),
                role,
                addr,
            },
            Some(SessionKey(digest(&token))),
        ))),
        None => Err(ApiError::Unauthorized(
            "your session has ended (logged out or expired): log in again".into(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;

    /// One user `ann` (operator, password `right`), counting verifications.
    struct Counting {
        calls: AtomicUsize,
    }

    impl UserStore for Counting {
        fn is_empty(&self) -> bool {
            false
        }
        fn role(&self, name: &str) -> Option<Role> {
            (name == "ann").then_some(Role::Operator)
        }
        fn verify(&self, name: &str, password: &str) -> Option<Role> {
            self.calls.fetch_add(1, Ordering::SeqCst);
            (name == "ann" && password == "right").then_some(Role::Operator)
        }
    }

    fn auth() -> (Auth, Arc<Counting>, Arc<ManualClock>) {
        let users = Arc::new(Counting {
            calls: AtomicUsize::new(0),
        });
        let clock = Arc::new(ManualClock::new());
        let limits = Limits {
            idle: Duration::from_secs(30 * 60),
            max: Duration::from_secs(12 * 3600),
        };
        (Auth::new(users.clone(), limits).with_clock(clock.clone()), users, clock)
    }

    fn addr(last: u8) -> SocketAddr {
        SocketAddr::from(([10, 0, 0, last], 40000))
    }

    #[tokio::test]
    async fn unknown_user_and_wrong_password_take_the_same_path() {
        let (a, users, _) = auth();
        let unknown = a.login("nobody", "right", addr(1)).await.expect_err("unknown");
        assert_eq!(users.calls.load(Ordering::SeqCst), 1, "an unknown user is verified");
        let wrong = a.login("ann", "wrong", addr(2)).await.expect_err("wrong");
        assert_eq!(users.calls.load(Ordering::SeqCst), 2, "a wrong password is verified");
        assert_eq!(unknown.to_string(), wrong.to_string());
        assert_eq!(crate::error::status(&unknown), crate::error::status(&wrong));
        let ok = a.login("ann", "right", addr(3)).await.expect("login");
        assert_eq!(users.calls.load(Ordering::SeqCst), 3);
        assert_eq!((ok.user.as_str(), ok.role), ("ann", Role::Operator));
        assert_eq!(ok.token.len(), 64, "256 bits in hex");
    }

    #[tokio::test]
    async fn sessions_end_when_idle_at_their_age_and_on_logout() {
        let (a, _, clock) = auth();
        let t = a.login("ann", "right", addr(1)).await.expect("login").token;
        let u = a.login("ann", "right", addr(1)).await.expect("login").token;
        assert_ne!(t, u, "every login its own token");
        assert_eq!(a.session(&t), Some(("ann".into(), Role::Operator)));
        // Used every 29 minutes, it lives until its 12th hour.
        for _ in 0..24 {
            clock.advance(Duration::from_secs(29 * 60));
            assert!(a.session(&t).is_some());
        }
        clock.advance(Duration::from_secs(29 * 60));
        assert!(a.session(&t).is_none(), "past 12 h");
        assert!(a.session(&u).is_none(), "u was idle");
        // Idle: 30 minutes without a request.
        let v = a.login("ann", "right", addr(1)).await.expect("login").token;
        clock.advance(Duration::from_secs(30 * 60 - 1));
        assert!(a.session(&v).is_some());
        clock.advance(Duration::from_secs(30 * 60));
        assert!(a.session(&v).is_none(), "idle for 30 min");
        let w = a.login("ann", "right", addr(1)).await.expect("login").token;
        a.logout(&w);
        assert!(a.session(&w).is_none(), "logged out");
        assert!(a.session("not-a-token").is_none());
    }

    #[tokio::test]
    async fn failed_logins_back_off_per_user_and_per_address() {
        let (a, users, clock) = auth();
        let free = (0..)
            .find(|&n| alba_auth::Backoff::wait_after(n) > Duration::ZERO)
            .unwrap_or(0);
        for i in 0..free {
            let e = a.login("ann", "wrong", addr(1)).await.expect_err("wrong");
            assert!(matches!(e, ApiError::Unauthorized(_)), "attempt {i}: {e}");
        }
        let calls = users.calls.load(Ordering::SeqCst);
        // Held back, even with the right password, from this address...
        let e = a.login("ann", "right", addr(1)).await.expect_err("held back");
        assert!(matches!(e, ApiError::TooManyAttempts(d) if d > Duration::ZERO), "{e}");
        assert_eq!(
            users.calls.load(Ordering::SeqCst),
            calls,
            "no verification while held back"
        );
        // The address is held back for any user.
        let e = a.login("bob", "x", addr(1)).await.expect_err("held back");
        assert!(matches!(e, ApiError::TooManyAttempts(_)), "{e}");
        clock.advance(Duration::from_secs(120));
        a.login("ann", "right", addr(1)).await.expect("after the wait");
    }

    /// Issue 31: while someone guessed ann's password, ann herself got 429
    /// with the right one. The guesser is held back (per pair and per
    /// address), ann from her own address is not: an alert says instead.
    #[tokio::test]
    async fn guessing_a_user_from_other_addresses_never_locks_the_user_out() {
        let (a, users, _) = auth();
        // Guessers on many addresses, each within its free failures, then one
        // address that keeps at it until held back.
        for guesser in 10..20 {
            for _ in 0..2 {
                let e = a.login("ann", "guess", addr(guesser)).await.expect_err("wrong");
                assert!(matches!(e, ApiError::Unauthorized(_)), "{e}");
            }
        }
        let mut held = 0;
        for _ in 0..10 {
            if matches!(
                a.login("ann", "guess", addr(30)).await,
                Err(ApiError::TooManyAttempts(_))
            ) {
                held += 1;
            }
        }
        assert!(held > 0, "the persistent guesser is held back");
        let calls = users.calls.load(Ordering::SeqCst);
        // Ann, from her own address, with the right password: in.
        let ok = a.login("ann", "right", addr(1)).await.expect("not locked out");
        assert_eq!(ok.user, "ann");
        assert_eq!(users.calls.load(Ordering::SeqCst), calls + 1);
        // And the guessing is visible.
        let alerts = a.alerts();
        assert_eq!(alerts.len(), 1, "{alerts:?}");
        assert_eq!(alerts[0].0, "ann");
        assert!(alerts[0].1 >= GUESSING_ALERT_AFTER, "{alerts:?}");
    }

    #[test]
    fn failed_logins_count_per_ipv4_address_and_ipv6_network() {
        let ip = |s: &str| s.parse::<std::net::IpAddr>().expect("ip");
        assert_eq!(client_key(ip("10.0.0.7")), "10.0.0.7");
        assert_eq!(client_key(ip("::ffff:10.0.0.7")), "10.0.0.7");
        assert_eq!(client_key(ip("2001:db8:1:2:aaaa::1")), "2001:db8:1:2::/64");
        assert_eq!(
            client_key(ip("2001:db8:1:2:bbbb::9")),
            client_key(ip("2001:db8:1:2::1"))
        );
        assert_ne!(client_key(ip("2001:db8:1:3::1")), client_key(ip("2001:db8:1:2::1")));
    }

    #[tokio::test]
    async fn one_users_logins_end_only_their_own_oldest_sessions() {
        let (a, _, clock) = auth();
        struct Two;
        impl UserStore for Two {
            fn is_empty(&self) -> bool {
                false
            }
            fn role(&self, name: &str) -> Option<Role> {
                Some(if name == "ann" { Role::Viewer } else { Role::Admin })
            }
            fn verify(&self, name: &str, _: &str) -> Option<Role> {
                self.role(name)
            }
        }
        let a = Auth::new(Arc::new(Two), a.limits()).with_clock(clock.clone());
        let bob = a.login("bob", "x", addr(1)).await.expect("bob").token;
        let mut ann = Vec::new();
        for _ in 0..MAX_SESSIONS_PER_USER + 3 {
            clock.advance(Duration::from_secs(1));
            ann.push(a.login("ann", "x", addr(2)).await.expect("ann").token);
        }
        assert!(a.session(&bob).is_some(), "bob's session stays");
        assert_eq!(a.sessions(), MAX_SESSIONS_PER_USER + 1);
        assert!(ann[..3].iter().all(|t| a.session(t).is_none()), "ann's oldest went");
        assert!(ann[3..].iter().all(|t| a.session(t).is_some()));
    }

    #[test]
    fn the_route_decides_not_the_path() {
        let table = [
            ("POST", "/api/run", Access::Role(Role::Engineer)),
            ("POST", "/api/login", Access::Public),
        ];
        let n = |m: Method, route: Option<&str>, path: &str| needed(&table, &m, route, path);
        assert_eq!(
            n(Method::POST, Some("/api/run"), "/api/run"),
            Access::Role(Role::Engineer)
        );
        // Whatever the path looks like, the route that serves it decides.
        assert_eq!(
            n(Method::POST, Some("/api/run"), "/x/../api/run"),
            Access::Role(Role::Engineer)
        );
        assert_eq!(n(Method::POST, Some("/api/other"), "/other"), Access::Role(Role::Admin));
        assert_eq!(
            n(Method::HEAD, Some("/api/other"), "/other"),
            Access::Role(Role::Viewer)
        );
        assert_eq!(n(Method::POST, Some("/api/login"), "/api/login"), Access::Public);
        // No route: the studio's files are public; under /api, as unclassified.
        assert_eq!(n(Method::GET, None, "/index.html"), Access::Public);
        assert_eq!(n(Method::POST, None, "/api/x"), Access::Role(Role::Admin));
        assert_eq!(n(Method::GET, None, "/api"), Access::Role(Role::Viewer));
    }

    #[test]
    fn without_users_only_direct_loopback_clients_act() {
        let a = Auth::open();
        let local = SocketAddr::from(([127, 0, 0, 1], 5000));
        let h = HeaderMap::new();
        let who = identify(&a, &h, local).expect("ok").expect("local");
        assert_eq!((who.0.user, who.0.role), (None, Role::Admin));
        let mapped: SocketAddr = "[::ffff:127.0.0.1]:5000".parse().expect("addr");
        assert!(
            identify(&a, &h, mapped).expect("ok").is_some(),
            "IPv4 loopback on a dual-stack listener"
        );
        assert!(identify(&a, &h, addr(1)).expect("ok").is_none(), "not loopback");
        for proxy in ["forwarded", "x-forwarded-for", "x-real-ip"] {
            let mut h = HeaderMap::new();
            h.insert(proxy, "for=203.0.113.9".parse().expect("header"));
            assert!(
                identify(&a, &h, local).expect("ok").is_none(),
                "{proxy}: forwarded by a local proxy"
            );
        }
    }

    #[test]
    fn tokens_from_bearer_or_cookie() {
        let mut h = HeaderMap::new();
        assert_eq!(token(&h), None);
        h.insert(header::COOKIE, "a=b; alba_session=abc ; c=d".parse().expect("header"));
        assert_eq!(token(&h).as_deref(), Some("abc"));
        h.insert(header::AUTHORIZATION, "Bearer xyz".parse().expect("header"));
        assert_eq!(token(&h).as_deref(), Some("xyz"), "the header first");
        h.insert(header::AUTHORIZATION, "Basic eHl6".parse().expect("header"));
        assert_eq!(token(&h).as_deref(), Some("abc"), "not a bearer token: the cookie");
        h.remove(header::COOKIE);
        assert_eq!(token(&h), None);
    }
}
