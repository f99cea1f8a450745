//! Program memory as slices for one scan, slot access without bounds
//! checks, and where faults go: what the interpreter (`exec`), the PID
//! instruction (`pid`) and the native code's fallback (`jit`) share. It
//! imports none of them.

use crate::fault::{FaultCode, Faults};

/// Program memory as slices for one scan. Every slot index used with it
/// comes from a program that passed `Program::verify` against memory of
/// exactly these sizes (checked at the start of `exec::run`).
pub(crate) struct Mem<'a> {
    pub(crate) b: &'a mut [bool],
    pub(crate) i: &'a mut [i32],
    pub(crate) f: &'a mut [f32],
    pub(crate) l: &'a mut [i64],
    pub(crate) d: &'a mut [f64],
    pub(crate) m: &'a mut [u8],
}

/// Reads a slot without a bounds check.
macro_rules! rd {
    ($s:expr, $x:expr) => {{
        let i = $x as usize;
        debug_assert!(i < $s.len());
        // SAFETY: `i` is a slot of a verified program and `run` checked that
        // the memory has the sizes it was verified against.
        #[allow(unsafe_code)]
        unsafe {
            *$s.get_unchecked(i)
        }
    }};
}
pub(crate) use rd;

/// Writes a slot without a bounds check.
macro_rules! wr {
    ($s:expr, $x:expr, $v:expr) => {{
        let i = $x as usize;
        let v = $v;
        debug_assert!(i < $s.len());
        // SAFETY: as for `rd!`.
        #[allow(unsafe_code)]
        unsafe {
            *$s.get_unchecked_mut(i) = v;
        }
    }};
}
pub(crate) use wr;

/// Where faults go, with the map back to canonical ops.
pub(crate) struct Sink<'a> {
    pub(crate) faults: &'a mut Faults,
    pub(crate) src: &'a [u32],
}

impl Sink<'_> {
    #[cold]
    #[inline(never)]
    pub(crate) fn fault(&mut self, code: FaultCode, pc: usize) {
        let canonical = self.src.get(pc).copied().unwrap_or(pc as u32);
        self.faults.record(code, canonical);
    }

    #[inline(always)]
    pub(crate) fn check(&mut self, code: Option<FaultCode>, pc: usize) {
        if let Some(c) = code {
            self.fault(c, pc);
        }
    }
}
