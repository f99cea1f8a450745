//! Streamed CSV answers (`/api/history.csv`, `/api/audit.csv`): a blocking
//! task writes the export into a [`ChunkWriter`] (an `io::Write`), which sends
//! it on in pieces of [`CHUNK`] bytes, a few at most waiting in memory, and
//! [`body`] streams them to the client. A client that takes nothing for
//! [`SEND_TIMEOUT`] ends the export; an error sent after the first bytes cuts
//! the answer short (the client sees a broken transfer, not a short file).

use axum::body::{Body, Bytes};
use futures_util::StreamExt;
use std::io;
use std::time::Duration;
use tokio::sync::mpsc;

/// The size of the pieces an export is sent in.
pub const CHUNK: usize = 64 * 1024;
/// A client that takes no piece for this long is given up.
pub const SEND_TIMEOUT: Duration = Duration::from_secs(30);

/// One piece of an export, or the error that ends it.
pub type Piece<E> = Result<Bytes, E>;

/// A writer for a blocking task and the receiver of its pieces. Call it on
/// the runtime (it keeps a handle to it to send from the blocking thread).
pub fn channel<E>() -> (ChunkWriter<E>, mpsc::Receiver<Piece<E>>) {
    let (tx, rx) = mpsc::channel(4);
    let w = ChunkWriter {
        tx,
        rt: tokio::runtime::Handle::current(),
        buf: Vec::with_capacity(CHUNK),
    };
    (w, rx)
}

pub struct ChunkWriter<E> {
    tx: mpsc::Sender<Piece<E>>,
    rt: tokio::runtime::Handle,
    buf: Vec<u8>,
}

impl<E> ChunkWriter<E> {
    fn put(&self, piece: Piece<E>) -> io::Result<()> {
        match self
            .rt
            .block_on(tokio::time::timeout(SEND_TIMEOUT, self.tx.send(piece)))
        {
            Ok(Ok(())) => Ok(()),
            Ok(Err(_)) => Err(io::Error::new(io::ErrorKind::BrokenPipe, "the client left")),
            Err(_) => Err(io::Error::new(io::ErrorKind::TimedOut, "the client takes nothing")),
        }
    }

    fn send(&mut self) -> io::Result<()> {
        if self.buf.is_empty() {
            return Ok(());
        }
        let piece = std::mem::replace(&mut self.buf, Vec::with_capacity(CHUNK));
        self.put(Ok(Bytes::from(piece)))
    }

    /// Sends what is left: the export is complete.
    pub fn finish(mut self) -> io::Result<()> {
        self.send()
    }

    /// Ends the export with `e` (the client may be gone: then nobody hears it).
    pub fn fail(self, e: E) {
        let _ = self.put(Err(e));
    }
}

impl<E> io::Write for ChunkWriter<E> {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(b);
        if self.buf.len() >= CHUNK {
            self.send()?;
        }
        Ok(b.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// The answer's body: `first` (already taken from `rx`, e.g. to turn an
/// early error into an ordinary API error), then the rest of `rx`.
pub fn body<E>(first: Bytes, rx: mpsc::Receiver<Piece<E>>) -> Body
where
    E: std::error::Error + Send + Sync + 'static,
{
    let rest = futures_util::stream::unfold(rx, |mut rx| async move {
        let item = rx.recv().await?.map_err(io::Error::other);
        Some((item, rx))
    });
    Body::from_stream(futures_util::stream::once(async move { Ok::<_, io::Error>(first) }).chain(rest))
}
