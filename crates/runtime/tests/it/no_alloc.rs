//! The real runtime's engine thread allocates nothing per scan (issue 18):
//! not in the scan, not in publishing the snapshot, not in applying writes
//! between scans, not in saving retentive data. A counting global allocator
//! counts the allocations made on the engine thread only (an `Io` driver,
//! which the engine thread calls every scan, marks that thread), while
//! subscribers read every snapshot, one of them keeping the last few,
//! monitoring (power flow) is on, a force is held and writes arrive every few
//! scans. The count is exact; no time is measured.

use super::{LAD, TAGS, compile, opts, place, until};
use alba_model::Value;
use alba_runtime::{IoError, Runtime};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

struct Counting;

/// Counting is on (the test's window).
static ON: AtomicBool = AtomicBool::new(false);
static COUNT: AtomicU64 = AtomicU64::new(0);
/// The size of the last allocation counted (for the failure message).
static LAST_SIZE: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// This thread is the engine's.
    static ENGINE: Cell<bool> = const { Cell::new(false) };
}

fn note(layout: Layout) {
    // `try_with`: the thread's locals may be gone while it exits.
    if ON.load(Ordering::Relaxed) && ENGINE.try_with(Cell::get).unwrap_or(false) {
        COUNT.fetch_add(1, Ordering::Relaxed);
        LAST_SIZE.store(layout.size() as u64, Ordering::Relaxed);
    }
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(layout);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// The simulated I/O, marking the thread that calls it as the engine's.
struct Marking;

impl alba_runtime::Io for Marking {
    fn name(&self) -> &str {
        "sim"
    }
    fn read_inputs(&mut self, engine: &mut alba_engine::Engine) -> Result<(), IoError> {
        ENGINE.with(|e| e.set(true));
        engine.step_plants_now();
        Ok(())
    }
    fn write_outputs(&mut self, _: &alba_engine::Engine) -> Result<(), IoError> {
        Ok(())
    }
}

const SCANS: u64 = 2000;

#[tokio::test(flavor = "current_thread")]
async fn the_engine_thread_allocates_nothing_per_scan_while_read_monitored_and_written() {
    let dir = std::env::temp_dir().join(format!("alba-noalloc-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for native in [false, true] {
        let mut o = opts(1);
        o.native = native;
        // A save every 20 scans or so: handed to the saver thread.
        o.retain_file = Some(dir.join(format!("retain-{native}.json")));
        o.retain_interval_ms = 20;
        let program = compile(TAGS, LAD);
        let rt = Runtime::start(program.clone(), o, Box::new(Marking)).unwrap();
        let h = rt.handle();
        h.monitor(true);
        h.force("In".into(), place(&program, "In"), Value::Bool(true))
            .await
            .unwrap();
        // A subscriber that reads every snapshot and keeps the last four.
        let mut rx = h.subscribe();
        let reader = tokio::spawn(async move {
            let mut kept = VecDeque::new();
            let mut seen = 0u64;
            while rx.changed().await.is_ok() {
                let s = rx.borrow_and_update().clone();
                assert!(s.power().is_none() || s.energised(0).is_some());
                kept.push_back(s);
                if kept.len() > 4 {
                    kept.pop_front();
                }
                seen += 1;
            }
            seen
        });
        // Another reader on a thread of its own, polling the latest.
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let poller = {
            let (h, stop) = (h.clone(), stop.clone());
            std::thread::spawn(move || {
                let mut n = 0u64;
                while !stop.load(Ordering::Relaxed) {
                    n = n.max(h.snapshot().scans);
                    std::thread::yield_now();
                }
                n
            })
        };
        let warm = until(&rt, "warm-up scans with power flow", |s| {
            s.scans >= 200 && s.power().is_some()
        })
        .await
        .scans;
        COUNT.store(0, Ordering::Relaxed);
        ON.store(true, Ordering::Relaxed);
        let count = place(&program, "Count");
        let mut writes = 0;
        while h.snapshot().scans < warm + SCANS {
            h.write(count, Value::Dint(writes)).await.unwrap();
            writes += 1;
            tokio::time::sleep(std::time::Duration::from_millis(3)).await;
        }
        ON.store(false, Ordering::Relaxed);
        let last = h.snapshot();
        stop.store(true, Ordering::Relaxed);
        let polled = poller.join().unwrap();
        rt.shutdown();
        let seen = reader.await.unwrap();
        let n = COUNT.load(Ordering::Relaxed);
        assert_eq!(
            n,
            0,
            "native {native}: {n} allocations on the engine thread in {} scans and {writes} writes \
             (the last of {} bytes)",
            last.scans - warm,
            LAST_SIZE.load(Ordering::Relaxed)
        );
        // The window held what it should: scans, writes, readers fed, saves.
        assert!(last.scans >= warm + SCANS && writes > 100, "{writes} writes");
        assert!(last.power().is_some() && last.forces.len() == 1);
        assert!(seen > 100 && polled >= warm, "subscriber saw {seen}, poller {polled}");
        let saved = std::fs::read_to_string(dir.join(format!("retain-{native}.json"))).unwrap();
        assert!(saved.contains("\"Kept\""), "{saved}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
