//! The scan path allocates nothing (issue 18, "no allocation on the scan
//! path"): for every golden project, after a few warm-up scans, 2 000 more
//! scans — fused interpreter, monitored interpreter (power flow recorded)
//! and native code — with forces applied and inputs written between scans,
//! make no heap allocation on the engine's thread. A counting allocator
//! (this test binary's global allocator) counts the allocations of the
//! thread under test only, so the harness's own threads do not interfere.
//! The count is exact; no time is measured.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::sync::Arc;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

fn note() {
    // `try_with`: the thread's locals may be gone while it exits.
    let _ = COUNTING.try_with(|c| {
        if c.get() {
            let _ = COUNT.try_with(|n| n.set(n.get() + 1));
        }
    });
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> u64 {
    COUNT.with(|n| n.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    COUNT.with(|n| n.get())
}

#[derive(Debug, Clone, Copy)]
enum Mode {
    Fused,
    Monitored,
    Native,
}

#[test]
fn scans_allocate_nothing_in_any_engine_mode() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .expect("tests/golden")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("alba.toml").exists())
        .collect();
    dirs.sort();
    assert!(dirs.len() > 50, "the golden projects ({})", dirs.len());
    let mut failures = Vec::new();
    for dir in &dirs {
        let c = alba_load::compile_dir(dir);
        let Some(program) = c.program else {
            panic!("{} does not compile", dir.display());
        };
        let program = Arc::new(program);
        // An input to write and one to force between scans, if the project has them.
        let inputs: Vec<alba_ir::Place> = program
            .layout
            .tags
            .iter()
            .filter_map(|t| match program.layout.resolve(&t.name) {
                Ok(alba_ir::Target::Value {
                    place,
                    access: alba_ir::Access::Input,
                }) => Some(place),
                _ => None,
            })
            .collect();
        for mode in [Mode::Fused, Mode::Monitored, Mode::Native] {
            let mut e = alba_engine::Engine::new(program.clone()).expect("verifies");
            match mode {
                Mode::Monitored => e.set_monitor(true),
                Mode::Native => e.compile_native().expect("native code"),
                Mode::Fused => {}
            }
            if let Some(p) = inputs.first() {
                e.force(*p, e.read(*p));
            }
            let mut t = 0;
            let mut run = |e: &mut alba_engine::Engine, scans: u64| {
                for k in 0..scans {
                    if let Some(p) = inputs.last() {
                        let v = e.read(*p);
                        e.write(*p, v);
                    }
                    e.step_plants(t);
                    // A major fault (a runaway loop in a golden case) ends the run, as it would.
                    if e.scan(t).is_err() {
                        return;
                    }
                    t += 10 + k % 3;
                }
            };
            // Warm-up: lazily sized buffers (fault records, power flow) settle.
            run(&mut e, 50);
            let n = allocations(|| run(&mut e, 2_000));
            if n != 0 {
                failures.push(format!("{} ({mode:?}): {n} allocations in 2 000 scans", dir.display()));
            }
        }
    }
    assert!(failures.is_empty(), "the scan path allocates:\n{}", failures.join("\n"));
}
