//! How the engine thread publishes a [`Snapshot`] after every scan without
//! allocating and without taking a lock (issue 18, docs/performance.md).
//!
//! - **Recycled buffers.** The engine keeps a few `Arc<Snapshot>`s. To
//!   publish, it takes one that nobody else holds any more
//!   (`Arc::get_mut`: every reader has dropped it) and copies memory, power
//!   flow and statistics into it in place; the sizes do not change from one
//!   scan to the next, so nothing is allocated. [`POOL_START`] buffers are
//!   made at start; only when readers hold every one (readers keeping many
//!   old snapshots) is a new one made, up to [`POOL`]; past that one is let
//!   go to its readers and replaced.
//! - **The latest snapshot** is an `ArcSwap`: the engine stores into it
//!   (lock-free writer) and `Handle::snapshot` loads from it (lock-free
//!   reader), so a reader never delays the engine and always sees the last
//!   publication.
//! - **The courier thread** (`alba-publish`) forwards the latest snapshot to
//!   the `watch` channel that subscribers (WebSocket clients, the historian,
//!   alarms, MQTT…) wait on. The channel's lock and the wake-up of every
//!   subscriber's task (tokio's run queues and their mutexes) are therefore
//!   taken on the courier's thread, never on the engine's: the engine only
//!   unparks the courier (an atomic swap, plus one futex wake when it
//!   sleeps). A subscriber that is slow, or a courier that is late, sees a
//!   later snapshot; nothing queues.

use crate::Snapshot;
use arc_swap::ArcSwap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use tokio::sync::watch;

/// Snapshot buffers made at start: the latest, the one the subscribers'
/// channel holds, the one being written and a few held by readers.
pub(crate) const POOL_START: usize = 8;
/// At most this many are kept for reuse.
pub(crate) const POOL: usize = 16;

/// The latest publication, shared with the handles.
pub(crate) type Latest = Arc<ArcSwap<Snapshot>>;

/// The engine thread's side.
pub(crate) struct Publisher {
    latest: Latest,
    pool: Vec<Arc<Snapshot>>,
    /// The buffer let go next when every one is held (round robin).
    evict: usize,
    courier: Courier,
}

impl Publisher {
    /// Publishes `first` and starts the courier; returns the latest
    /// snapshot (for `Handle::snapshot`) and the subscribers' channel.
    pub(crate) fn start(first: Arc<Snapshot>) -> std::io::Result<(Publisher, Latest, watch::Receiver<Arc<Snapshot>>)> {
        let latest = Arc::new(ArcSwap::new(first.clone()));
        let (tx, rx) = watch::channel(first);
        let courier = Courier::start(latest.clone(), tx)?;
        let publisher = Publisher {
            latest: latest.clone(),
            pool: (0..POOL_START).map(|_| buffer(&latest.load())).collect(),
            evict: 0,
            courier,
        };
        Ok((publisher, latest, rx))
    }

    /// Fills a free buffer with `fill` (which overwrites every field) and
    /// publishes it.
    pub(crate) fn publish(&mut self, fill: impl FnOnce(&mut Snapshot)) {
        let i = match self.pool.iter_mut().position(|s| Arc::get_mut(s).is_some()) {
            Some(i) => i,
            None => {
                let fresh = buffer(&self.latest.load());
                if self.pool.len() < POOL {
                    self.pool.push(fresh);
                    self.pool.len() - 1
                } else {
                    self.evict = (self.evict + 1) % POOL;
                    self.pool[self.evict] = fresh;
                    self.evict
                }
            }
        };
        let Some(buffer) = Arc::get_mut(&mut self.pool[i]) else {
            unreachable!("buffer {i} is held by nobody else: free, or just made")
        };
        fill(buffer);
        self.latest.store(self.pool[i].clone());
        self.courier.wake();
    }
}

/// A new buffer like `s`, with as much room for the power flow.
fn buffer(s: &Snapshot) -> Arc<Snapshot> {
    let mut b = s.clone();
    b.power.reserve(s.power.capacity());
    Arc::new(b)
}

/// The thread that forwards the latest snapshot to the subscribers.
struct Courier {
    thread: Option<JoinHandle<()>>,
    stop: Arc<AtomicBool>,
}

impl Courier {
    fn start(latest: Latest, tx: watch::Sender<Arc<Snapshot>>) -> std::io::Result<Courier> {
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = stop.clone();
        let thread = std::thread::Builder::new().name("alba-publish".into()).spawn(move || {
            loop {
                // Read before the snapshot: a stop asked after the last
                // publication still forwards that publication.
                let stop = stopping.load(Ordering::Acquire);
                let s = latest.load_full();
                let sent = Arc::ptr_eq(&s, &tx.borrow());
                if !sent {
                    tx.send_replace(s);
                }
                if stop {
                    return;
                }
                // Woken by `wake`; a wake before the park is not lost.
                std::thread::park();
            }
        })?;
        Ok(Courier {
            thread: Some(thread),
            stop,
        })
    }

    fn wake(&self) {
        if let Some(t) = &self.thread {
            t.thread().unpark();
        }
    }
}

impl Drop for Courier {
    /// Forwards the last publication, then ends the thread (subscribers
    /// then see the channel closed).
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        self.wake();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
