//! The studio's HTTP server loop (HTTP/1.1 on hyper, in place of
//! `axum::serve`, which sets no timeouts): every connection takes a place in
//! `crate::limits::Conns` before it is served, must send a request head
//! within `[http] header_timeout_s` of opening or of its last answer (idle
//! keep-alives and half-sent requests are closed: issue 31), and is closed
//! at once when a newer client needs its place while it is idle.
//!
//! No answer depends on the wall clock being sane: hyper formats its `Date`
//! header through httpdate, which panicked for a clock before 1970 (every
//! answer failed, issue 31); the workspace's copy of httpdate
//! (`vendor/httpdate`) clamps instead.

use crate::limits::{Conns, Held, refuse};
use axum::Router;
use axum::extract::ConnectInfo;
use axum::http::{Request, StatusCode};
use axum::serve::Listener;
use hyper::body::Incoming;
use hyper_util::rt::{TokioIo, TokioTimer};
use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;
use tower_service::Service;

/// How the server treats connections (`[http]`).
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    pub max_connections: u32,
    pub header_timeout: Duration,
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
                let Ok(res) = router.call(req).await;
                if res.status() == StatusCode::SWITCHING_PROTOCOLS {
                    slot.upgraded();
                }
                drop(busy);
                Ok::<_, Infallible>(res)
            }
        })
    };
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new()).header_read_timeout(limits.header_timeout);
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
    use std::time::{Duration, SystemTime, UNIX_EPOCH};

    /// Issue 31: hyper's `Date` header (httpdate) panicked for a clock
    /// before 1970, and so did every answer. The workspace's httpdate clamps.
    #[test]
    fn any_clock_gives_a_date_and_no_panic() {
        let day = Duration::from_secs(86_400);
        assert_eq!(
            httpdate::fmt_http_date(UNIX_EPOCH - day),
            "Thu, 01 Jan 1970 00:00:00 GMT"
        );
        assert_eq!(
            httpdate::fmt_http_date(UNIX_EPOCH + Duration::from_secs(300_000_000_000)),
            "Fri, 31 Dec 9999 23:59:59 GMT"
        );
        assert_eq!(
            httpdate::fmt_http_date(UNIX_EPOCH + day),
            "Fri, 02 Jan 1970 00:00:00 GMT"
        );
        let _ = httpdate::fmt_http_date(SystemTime::now());
    }
}
