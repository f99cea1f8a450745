//! Who may hold the studio's HTTP connections (issues 15 and 31,
//! docs/reliability.md): at most `[http] max_connections` open at once, and
//! at most a quarter of them ([`per_client`]) from one client address (an
//! IPv6 client: its /64 network), so that one address cannot take them all.
//!
//! A new connection that finds its address's share, or the whole cap, taken
//! closes the connection of that address (or of anyone) that has been idle
//! longest — one waiting for a request head, which includes an idle
//! keep-alive and half a request — instead of being refused: connections
//! that send nothing cannot lock the studio's own reconnects out. Only when
//! every connection is busy (a request being answered, a live WebSocket) is
//! the new one answered 503 (JSON, as every API error) and closed. Idle
//! connections also end by themselves after `[http] header_timeout_s`
//! (crate::serve).
//!
//! Each accepted connection also gets a fixed send buffer
//! ([`SEND_BUFFER`], where Linux would grow it to 4 MB): what a client that
//! stops reading can have queued is bounded, so a live client that stops
//! reading is dropped within seconds (its next send waits 5 s, see the
//! server's ws.rs), not after megabytes.

use std::collections::HashMap;
use std::net::IpAddr;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, ReadBuf};
use tokio::sync::Notify;

/// The send buffer of every connection: 64 KiB (the kernel doubles it for
/// its bookkeeping); at LAN round-trip times that is still tens of MB/s.
pub const SEND_BUFFER: usize = 64 * 1024;

/// Fixes `tcp`'s send buffer at [`SEND_BUFFER`].
pub fn bound_send_buffer(tcp: &tokio::net::TcpStream) {
    let _ = socket2::SockRef::from(tcp).set_send_buffer_size(SEND_BUFFER);
}

/// The connections one client address may hold: a quarter of the cap.
pub fn per_client(max: usize) -> usize {
    (max / 4).max(1)
}

/// What connections are counted by: an IPv4 address, or an IPv6 /64 network
/// (one host has a whole one).
fn client_of(ip: IpAddr) -> IpAddr {
    match ip.to_canonical() {
        IpAddr::V6(v6) => {
            let s = v6.segments();
            IpAddr::V6(std::net::Ipv6Addr::new(s[0], s[1], s[2], s[3], 0, 0, 0, 0))
        }
        v4 => v4,
    }
}

/// One open connection, as the cap sees it.
pub struct Slot {
    client: IpAddr,
    /// Requests being answered.
    busy: AtomicUsize,
    /// Switched to a WebSocket: busy for as long as it lives.
    upgraded: AtomicBool,
    /// The last bytes read or written, or the last answer (ms since `Conns::start`).
    last: AtomicU64,
    /// Told when the connection is closed to make room.
    pub evict: Notify,
}

impl Slot {
    fn idle(&self) -> bool {
        self.busy.load(Ordering::Relaxed) == 0 && !self.upgraded.load(Ordering::Relaxed)
    }

    /// A request starts; the guard ends it.
    pub fn request(self: &Arc<Self>, conns: &Arc<Conns>) -> Busy {
        self.busy.fetch_add(1, Ordering::Relaxed);
        Busy {
            slot: self.clone(),
            conns: conns.clone(),
        }
    }

    /// The connection is now a WebSocket.
    pub fn upgraded(&self) {
        self.upgraded.store(true, Ordering::Relaxed);
    }
}

/// A request being answered on a slot.
pub struct Busy {
    slot: Arc<Slot>,
    conns: Arc<Conns>,
}

impl Drop for Busy {
    fn drop(&mut self) {
        self.conns.touch(&self.slot);
        self.slot.busy.fetch_sub(1, Ordering::Relaxed);
    }
}

/// The open connections of one listener.
pub struct Conns {
    start: Instant,
    max: usize,
    per_client: usize,
    open: Mutex<HashMap<u64, Arc<Slot>>>,
    next: AtomicU64,
    /// Connections closed to make room (for tests and the curious).
    pub evicted: AtomicU64,
}

/// Why a connection was not admitted: every place is busy.
#[derive(Debug)]
pub struct Full;

impl Conns {
    pub fn new(max: usize) -> Arc<Conns> {
        Arc::new(Conns {
            start: Instant::now(),
            max: max.max(1),
            per_client: per_client(max),
            open: Mutex::new(HashMap::new()),
            next: AtomicU64::new(0),
            evicted: AtomicU64::new(0),
        })
    }

    fn now(&self) -> u64 {
        self.start.elapsed().as_millis() as u64
    }

    fn touch(&self, slot: &Slot) {
        slot.last.store(self.now(), Ordering::Relaxed);
    }

    /// A place for a connection from `ip`, made if need be by closing the
    /// longest-idle connection of the same client (at its share) or of
    /// anyone (at the cap).
    pub fn admit(self: &Arc<Self>, ip: IpAddr) -> Result<Counted, Full> {
        let client = client_of(ip);
        let mut open = self.open.lock().unwrap_or_else(PoisonError::into_inner);
        let oldest_idle = |of_client: bool| {
            open.iter()
                .filter(|(_, s)| (!of_client || s.client == client) && s.idle())
                .min_by_key(|(_, s)| s.last.load(Ordering::Relaxed))
                .map(|(id, _)| *id)
        };
        let mine = open.values().filter(|s| s.client == client).count();
        let victim = if mine >= self.per_client {
            Some(oldest_idle(true).ok_or(Full)?)
        } else if open.len() >= self.max {
            Some(oldest_idle(false).ok_or(Full)?)
        } else {
            None
        };
        if let Some(slot) = victim.and_then(|id| open.remove(&id)) {
            slot.evict.notify_one();
            self.evicted.fetch_add(1, Ordering::Relaxed);
        }
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let slot = Arc::new(Slot {
            client,
            busy: AtomicUsize::new(0),
            upgraded: AtomicBool::new(false),
            last: AtomicU64::new(self.now()),
            evict: Notify::new(),
        });
        open.insert(id, slot.clone());
        Ok(Counted {
            conns: self.clone(),
            id,
            slot,
        })
    }

    /// Connections open now.
    #[cfg(test)]
    fn open(&self) -> usize {
        self.open.lock().unwrap_or_else(PoisonError::into_inner).len()
    }
}

/// A connection's place in [`Conns`], given back when it is dropped (with
/// the connection, or after its WebSocket closes).
pub struct Counted {
    conns: Arc<Conns>,
    id: u64,
    pub slot: Arc<Slot>,
}

impl Drop for Counted {
    fn drop(&mut self) {
        self.conns
            .open
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(&self.id);
    }
}

/// A connection holding its place, noting when bytes move.
pub struct Held<Io> {
    pub io: Io,
    pub place: Counted,
}

impl<Io> Held<Io> {
    fn moved(&self) {
        self.place.conns.touch(&self.place.slot);
    }
}

impl<Io: AsyncRead + Unpin> AsyncRead for Held<Io> {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<std::io::Result<()>> {
        let this = self.get_mut();
        let before = buf.filled().len();
        let r = Pin::new(&mut this.io).poll_read(cx, buf);
        if buf.filled().len() > before {
            this.moved();
        }
        r
    }
}

impl<Io: AsyncWrite + Unpin> AsyncWrite for Held<Io> {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<std::io::Result<usize>> {
        let this = self.get_mut();
        let r = Pin::new(&mut this.io).poll_write(cx, buf);
        if matches!(r, Poll::Ready(Ok(n)) if n > 0) {
            this.moved();
        }
        r
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().io).poll_flush(cx)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().io).poll_shutdown(cx)
    }

    fn poll_write_vectored(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[std::io::IoSlice<'_>],
    ) -> Poll<std::io::Result<usize>> {
        let this = self.get_mut();
        let r = Pin::new(&mut this.io).poll_write_vectored(cx, bufs);
        if matches!(r, Poll::Ready(Ok(n)) if n > 0) {
            this.moved();
        }
        r
    }

    fn is_write_vectored(&self) -> bool {
        self.io.is_write_vectored()
    }
}

/// Answers a connection that finds every place busy: its request head is
/// read (so that closing does not reset the answer away), then a 503 and
/// the close.
pub async fn refuse<Io: AsyncRead + AsyncWrite + Unpin>(mut io: Io, max: u32) {
    let body = format!(
        "{{\"error\":\"too many connections ({max} open): try again shortly, or raise [http] max_connections\"}}"
    );
    let reply = format!(
        "HTTP/1.1 503 Service Unavailable\r\ncontent-type: application/json\r\ncontent-length: {}\r\n\
         retry-after: 1\r\nconnection: close\r\n\r\n{body}",
        body.len()
    );
    let _ = tokio::time::timeout(Duration::from_secs(2), async {
        let mut head = Vec::with_capacity(1024);
        let mut buf = [0u8; 1024];
        while !head.windows(4).any(|w| w == b"\r\n\r\n") && head.len() < 16 * 1024 {
            let n = io.read(&mut buf).await?;
            if n == 0 {
                break;
            }
            head.extend_from_slice(&buf[..n]);
        }
        io.write_all(reply.as_bytes()).await?;
        io.shutdown().await
    })
    .await;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ip(s: &str) -> IpAddr {
        s.parse().expect("ip")
    }

    #[test]
    fn a_full_share_or_cap_makes_room_by_closing_the_longest_idle() {
        let conns = Conns::new(8);
        // One address: its share is 2; a third closes its oldest idle one.
        let a1 = conns.admit(ip("10.0.0.1")).expect("a1");
        let a2 = conns.admit(ip("10.0.0.1")).expect("a2");
        let _busy = a2.slot.request(&conns);
        let a3 = conns.admit(ip("10.0.0.1")).expect("room made");
        assert_eq!(conns.evicted.load(Ordering::Relaxed), 1);
        assert_eq!(conns.open(), 2, "a1 went, a2 (busy) and a3 stay");
        drop(a1);
        // Both of the address's places busy: refused.
        let _b3 = a3.slot.request(&conns);
        assert!(conns.admit(ip("10.0.0.1")).is_err());
        // Others still get in, up to the cap, then take the idle ones' places.
        let others: Vec<Counted> = (2..8)
            .map(|i| conns.admit(ip(&format!("10.0.0.{i}"))).expect("other"))
            .collect();
        assert_eq!(conns.open(), 8);
        let _late = conns.admit(ip("10.0.0.99")).expect("room made at the cap");
        assert_eq!(conns.open(), 8);
        assert_eq!(conns.evicted.load(Ordering::Relaxed), 2);
        // An IPv6 host counts as its /64.
        assert_eq!(client_of(ip("2001:db8::1")), client_of(ip("2001:db8::ffff:2")));
        drop(others);
    }
}
