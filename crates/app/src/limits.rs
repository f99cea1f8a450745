//! At most `[http] max_connections` open HTTP connections (issue 15,
//! docs/reliability.md): a listener that counts the connections it hands to
//! the server and answers the ones beyond the cap with a 503 (JSON, as every
//! API error) and closes them, instead of letting a flood of clients take
//! every file descriptor and the CPU the engine thread needs.
//!
//! Each accepted connection also gets a fixed send buffer
//! ([`SEND_BUFFER`], where Linux would grow it to 4 MB): what a client that
//! stops reading can have queued is bounded, so a live client that stops
//! reading is dropped within seconds (its next send waits 5 s, see the
//! server's ws.rs), not after megabytes.

use axum::serve::Listener;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, ReadBuf};
use tokio::sync::{OwnedSemaphorePermit, Semaphore};

/// The send buffer of every connection: 64 KiB (the kernel doubles it for
/// its bookkeeping); at LAN round-trip times that is still tens of MB/s.
pub const SEND_BUFFER: usize = 64 * 1024;

/// Fixes `tcp`'s send buffer at [`SEND_BUFFER`].
pub fn bound_send_buffer(tcp: &tokio::net::TcpStream) {
    let _ = socket2::SockRef::from(tcp).set_send_buffer_size(SEND_BUFFER);
}

/// `L` with a cap on the connections open at once.
pub struct Capped<L> {
    inner: L,
    permits: Arc<Semaphore>,
    max: u32,
}

impl<L> Capped<L> {
    pub fn new(inner: L, max: u32) -> Capped<L> {
        Capped {
            inner,
            permits: Arc::new(Semaphore::new(max as usize)),
            max,
        }
    }
}

impl<L: Listener> Listener for Capped<L> {
    type Io = Counted<L::Io>;
    type Addr = L::Addr;

    async fn accept(&mut self) -> (Self::Io, Self::Addr) {
        loop {
            let (io, addr) = self.inner.accept().await;
            match self.permits.clone().try_acquire_owned() {
                Ok(permit) => return (Counted { io, _permit: permit }, addr),
                Err(_) => {
                    tokio::spawn(refuse(io, self.max));
                }
            }
        }
    }

    fn local_addr(&self) -> std::io::Result<Self::Addr> {
        self.inner.local_addr()
    }
}

/// Answers a connection beyond the cap: its request head is read (so that
/// closing does not reset the answer away), then a 503 and the close.
async fn refuse<Io: AsyncRead + AsyncWrite + Unpin>(mut io: Io, max: u32) {
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

/// A connection holding one of the cap's places until it closes.
pub struct Counted<Io> {
    io: Io,
    _permit: OwnedSemaphorePermit,
}

impl<Io: AsyncRead + Unpin> AsyncRead for Counted<Io> {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().io).poll_read(cx, buf)
    }
}

impl<Io: AsyncWrite + Unpin> AsyncWrite for Counted<Io> {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<std::io::Result<usize>> {
        Pin::new(&mut self.get_mut().io).poll_write(cx, buf)
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
        Pin::new(&mut self.get_mut().io).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.io.is_write_vectored()
    }
}
