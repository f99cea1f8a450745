//! The studio's HTTP server loop (HTTP/1.1 on hyper, in place of
//! `axum::serve`, which sets no timeouts): every connection takes a place in
//! `crate::limits::Conns` before it is served, must send a request head
//! within `[http] header_timeout_s` of opening or of its last answer (idle
//! keep-alives and half-sent requests are closed: issue 31), and is closed
//! at once when a newer client needs its place while it is idle.
//!
//! No answer depends on the wall clock being sane: hyper's own `Date`
//! header panics for a clock before 1970 (every answer then failed, issue
//! 31), so it is off and [`date`] writes one only for a clock it can format.

use crate::limits::{Conns, Held, refuse};
use axum::Router;
use axum::extract::ConnectInfo;
use axum::http::{HeaderValue, Request, StatusCode, header};
use axum::serve::Listener;
use hyper::body::Incoming;
use hyper_util::rt::{TokioIo, TokioTimer};
use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::{Duration, SystemTime, UNIX_EPOCH};
use tower_service::Service;

/// How the server treats connections (`[http]`).
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    pub max_connections: u32,
    pub header_timeout: Duration,
}

/// The `Date` header for the wall-clock time `now`, if it is one HTTP can
/// say (1970 to 9999); `None` otherwise — an origin server without a
/// usable clock sends none (RFC 9110 §6.6.1).
pub fn date(now: SystemTime) -> Option<HeaderValue> {
    let secs = now.duration_since(UNIX_EPOCH).ok()?.as_secs();
    // httpdate refuses (panics) from year 10000 on.
    if secs >= 253_402_300_800 {
        return None;
    }
    HeaderValue::from_str(&httpdate::fmt_http_date(now)).ok()
}

/// Serves `router` on `listener` until `shutdown` completes, then lets the
/// connections finish their answers.
pub async fn serve<L>(
    mut listener: L,
    router: Router,
    limits: Limits,
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) where
    L: Listener<Addr = SocketAddr>,
{
    let conns = Conns::new(limits.max_connections as usize);
    let (stop, stopping) = tokio::sync::watch::channel(false);
    // Every connection's task holds a receiver; all gone: all finished.
    let (done_tx, done_rx) = tokio::sync::watch::channel(());
    let mut shutdown = std::pin::pin!(shutdown);
    loop {
        let (io, peer) = tokio::select! {
            conn = listener.accept() => conn,
            _ = &mut shutdown => break,
        };
        match conns.admit(peer.ip()) {
            Ok(place) => {
                let held = Held { io, place };
                let task = connection(held, peer, router.clone(), conns.clone(), limits, stopping.clone());
                let done = done_rx.clone();
                tokio::spawn(async move {
                    task.await;
                    drop(done);
                });
            }
            Err(_) => {
                tokio::spawn(refuse(io, limits.max_connections));
            }
        }
    }
    let _ = stop.send(true);
    drop(done_rx);
    drop(listener);
    done_tx.closed().await;
}

/// Serves one connection until it closes, is closed for room or times out.
async fn connection<Io>(
    held: Held<Io>,
    peer: SocketAddr,
    router: Router,
    conns: Arc<Conns>,
    limits: Limits,
    mut stopping: tokio::sync::watch::Receiver<bool>,
) where
    Io: tokio::io::AsyncRead + tokio::io::AsyncWrite + Unpin + Send + 'static,
{
    let slot = held.place.slot.clone();
    let answer = {
        let slot = slot.clone();
        hyper::service::service_fn(move |mut req: Request<Incoming>| {
            let mut router = router.clone();
            let busy = slot.request(&conns);
            let slot = slot.clone();
            req.extensions_mut().insert(ConnectInfo(peer));
            async move {
                let Ok(mut res) = router.call(req).await;
                if res.status() == StatusCode::SWITCHING_PROTOCOLS {
                    slot.upgraded();
                }
                drop(busy);
                if !res.headers().contains_key(header::DATE)
                    && let Some(d) = date(SystemTime::now())
                {
                    res.headers_mut().insert(header::DATE, d);
                }
                Ok::<_, Infallible>(res)
            }
        })
    };
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .auto_date_header(false);
    let conn = http.serve_connection(TokioIo::new(held), answer).with_upgrades();
    let mut conn = std::pin::pin!(conn);
    let mut graceful = false;
    loop {
        tokio::select! {
            _ = conn.as_mut() => return,
            // Its place was given to a newer client: dropping closes it.
            _ = slot.evict.notified() => return,
            changed = stopping.wait_for(|s| *s), if !graceful => {
                graceful = true;
                if changed.is_ok() {
                    conn.as_mut().graceful_shutdown();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 31: hyper formatted `Date` from the wall clock and panicked for
    /// a time before 1970, so every answer failed. Any clock value now gives
    /// a header or none, never a panic.
    #[test]
    fn any_clock_gives_a_date_header_or_none() {
        let day = Duration::from_secs(86_400);
        assert_eq!(date(UNIX_EPOCH - day), None);
        assert_eq!(date(UNIX_EPOCH - Duration::from_secs(1_000_000 * 86_400)), None);
        assert_eq!(
            date(UNIX_EPOCH + day).as_ref().and_then(|h| h.to_str().ok()),
            Some("Fri, 02 Jan 1970 00:00:00 GMT")
        );
        assert_eq!(date(UNIX_EPOCH + Duration::from_secs(253_402_300_800)), None);
        assert!(date(UNIX_EPOCH + Duration::from_secs(253_402_300_799)).is_some());
        assert!(date(SystemTime::now()).is_some());
    }
}
