//! What the link threads of the drivers share: a poison-tolerant lock, a
//! stop flag whose sleeps end as soon as the runtime asks the thread to
//! stop, and the images the engine thread exchanges with a link thread.

use alba_engine::Engine;
use alba_ir::{B, I, Place};
use alba_model::{DataType, Value};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Locks `m`, taking the data of a poisoned lock (a panicked holder left
/// plain images, never half-written invariants).
pub(crate) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// The runtime's request that a link thread end.
#[derive(Default)]
pub(crate) struct Stop(AtomicBool);

impl Stop {
    pub(crate) fn request(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub(crate) fn stopping(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Sleeps `d` unless asked to stop meanwhile.
    pub(crate) fn sleep(&self, d: Duration) {
        let end = Instant::now() + d;
        while !self.stopping() {
            let now = Instant::now();
            if now >= end {
                break;
            }
            std::thread::sleep((end - now).min(Duration::from_millis(20)));
        }
    }
}

/// The outputs a link thread writes: digital levels and analog words.
#[derive(Default, Clone)]
pub(crate) struct Outputs {
    pub(crate) r#do: Vec<bool>,
    pub(crate) ao: Vec<u16>,
}

impl Outputs {
    pub(crate) fn new(r#do: usize, ao: usize) -> Outputs {
        Outputs {
            r#do: vec![false; r#do],
            ao: vec![0; ao],
        }
    }

    /// Sets the outputs from the front of `r#do` and `ao`.
    pub(crate) fn set(&mut self, r#do: &[bool], ao: &[u16]) {
        for (d, s) in self.r#do.iter_mut().zip(r#do) {
            *d = *s;
        }
        for (d, s) in self.ao.iter_mut().zip(ao) {
            *d = *s;
        }
    }

    /// Copies the engine's outputs (past the program's image: off and 0),
    /// each analog output through `word`.
    pub(crate) fn copy_from(&mut self, engine: &Engine, word: impl Fn(i32) -> u16) {
        let layout = &engine.program().layout;
        let mem = engine.memory();
        for (n, d) in self.r#do.iter_mut().enumerate() {
            *d = n < layout.dout.len as usize && mem.b.get(layout.dout.base as usize + n).copied().unwrap_or(false);
        }
        for (n, a) in self.ao.iter_mut().enumerate() {
            let v = if n < layout.ao.len as usize {
                mem.i.get(layout.ao.base as usize + n).copied().unwrap_or(0)
            } else {
                0
            };
            *a = word(v);
        }
    }
}

/// Writes digital inputs `(channel, level)` and analog inputs `(channel,
/// value)` into the engine's input image (channels past it are left out).
pub(crate) fn load_inputs(
    engine: &mut Engine,
    di: impl Iterator<Item = (usize, bool)>,
    ai: impl Iterator<Item = (usize, i16)>,
) {
    let (di_at, ai_at) = {
        let l = &engine.program().layout;
        (l.di, l.ai)
    };
    for (n, v) in di.filter(|(n, _)| *n < di_at.len as usize) {
        engine.write(Place::Bool(B(di_at.base + n as u32)), Value::Bool(v));
    }
    for (n, v) in ai.filter(|(n, _)| *n < ai_at.len as usize) {
        engine.write(Place::Int(I(ai_at.base + n as u32), DataType::Int), Value::Int(v));
    }
}
