//! Program memory: one array per storage class plus the marker bytes.

use crate::layout::{Counts, Layout, Place, TagSlot};
use alba_model::{DataType, Value};

#[derive(Debug, PartialEq)]
pub struct Memory {
    pub b: Vec<bool>,
    pub i: Vec<i32>,
    pub f: Vec<f32>,
    pub l: Vec<i64>,
    pub d: Vec<f64>,
    /// Marker memory, byte addressed, multi-byte values big-endian.
    pub m: Vec<u8>,
}

impl Clone for Memory {
    fn clone(&self) -> Memory {
        Memory {
            b: self.b.clone(),
            i: self.i.clone(),
            f: self.f.clone(),
            l: self.l.clone(),
            d: self.d.clone(),
            m: self.m.clone(),
        }
    }

    /// Copies into this memory's own buffers: no allocation when they are
    /// large enough (the runtime's recycled snapshots, issue 18).
    fn clone_from(&mut self, src: &Memory) {
        self.b.clone_from(&src.b);
        self.i.clone_from(&src.i);
        self.f.clone_from(&src.f);
        self.l.clone_from(&src.l);
        self.d.clone_from(&src.d);
        self.m.clone_from(&src.m);
    }
}

impl Memory {
    pub fn new(c: Counts, marker_bytes: u32) -> Memory {
        Memory {
            b: vec![false; c.b as usize],
            i: vec![0; c.i as usize],
            f: vec![0.0; c.f as usize],
            l: vec![0; c.l as usize],
            d: vec![0.0; c.d as usize],
            m: vec![0; marker_bytes as usize],
        }
    }

    /// Bytes used (for memory reports).
    pub fn size_bytes(&self) -> usize {
        self.b.len() + 4 * self.i.len() + 4 * self.f.len() + 8 * self.l.len() + 8 * self.d.len() + self.m.len()
    }

    fn m_bytes<const N: usize>(&self, at: u32) -> [u8; N] {
        let mut out = [0u8; N];
        let at = at as usize;
        if let Some(src) = self.m.get(at..at + N) {
            out.copy_from_slice(src);
        }
        out
    }

    fn set_m_bytes(&mut self, at: u32, bytes: &[u8]) {
        let at = at as usize;
        if let Some(dst) = self.m.get_mut(at..at + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
    }

    /// Reads a value. Places come from the layout this memory was made for.
    pub fn read(&self, p: Place) -> Value {
        match p {
            Place::Bool(b) => Value::Bool(self.b[b.0 as usize]),
            Place::Int(i, ty) => int_value(self.i[i.0 as usize] as i64, ty),
            Place::Real(f) => Value::Real(self.f[f.0 as usize]),
            Place::Lint(l) => Value::Lint(self.l[l.0 as usize]),
            Place::Lreal(d) => Value::Lreal(self.d[d.0 as usize]),
            Place::MBit { byte, bit } => Value::Bool(self.m_bytes::<1>(byte)[0] >> bit & 1 == 1),
            Place::MByte(at) => Value::Sint(self.m_bytes::<1>(at)[0] as i8),
            Place::MWord(at) => Value::Int(i16::from_be_bytes(self.m_bytes(at))),
            Place::MDword(at, ty) => int_value(i32::from_be_bytes(self.m_bytes(at)) as i64, ty),
            Place::MReal(at) => Value::Real(f32::from_be_bytes(self.m_bytes(at))),
        }
    }

    /// Writes a value, converting it to the place's type (callers check the
    /// range first; out-of-range integers wrap).
    pub fn write(&mut self, p: Place, v: Value) {
        match p {
            Place::Bool(b) => self.b[b.0 as usize] = v.as_bool(),
            Place::Int(i, _) => self.i[i.0 as usize] = v.as_i64() as i32,
            Place::Real(f) => self.f[f.0 as usize] = v.as_f64() as f32,
            Place::Lint(l) => self.l[l.0 as usize] = v.as_i64(),
            Place::Lreal(d) => self.d[d.0 as usize] = v.as_f64(),
            Place::MBit { byte, bit } => {
                let old = self.m_bytes::<1>(byte)[0];
                let new = if v.as_bool() { old | 1 << bit } else { old & !(1 << bit) };
                self.set_m_bytes(byte, &[new]);
            }
            Place::MByte(at) => self.set_m_bytes(at, &[v.as_i64() as u8]),
            Place::MWord(at) => self.set_m_bytes(at, &(v.as_i64() as i16).to_be_bytes()),
            Place::MDword(at, _) => self.set_m_bytes(at, &(v.as_i64() as i32).to_be_bytes()),
            Place::MReal(at) => self.set_m_bytes(at, &(v.as_f64() as f32).to_be_bytes()),
        }
    }

    /// Online edit: a memory for `new` that keeps the values of every tag
    /// that exists in `old` with the same name and type (timers and counters
    /// with their accumulators and status bits), plus the marker bytes and
    /// I/O images. Everything else comes from `new_init`.
    pub fn migrate(&self, old: &Layout, new: &Layout, new_init: &Memory) -> Memory {
        let mut out = new_init.clone();
        Migration::new(old, new).apply(self, &mut out);
        out
    }
}

/// A storage class of [`Memory`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    B,
    I,
    F,
    L,
    D,
    M,
}

/// What [`Memory::migrate`] copies from a memory of one layout into one of
/// another, worked out once from the two layouts (name look-ups, off the
/// engine's thread) and applied at the scan boundary as plain copies.
#[derive(Debug, Clone, Default)]
pub struct Migration {
    /// (class, from, to, count), in the order `migrate` defines.
    copies: Vec<(Class, u32, u32, u32)>,
}

impl Migration {
    pub fn new(old: &Layout, new: &Layout) -> Migration {
        let mut m = Migration::default();
        // Runs of slots that stay together (each class's slots are given in
        // tag order, so tags that keep their order keep their runs) become one
        // copy: an edit's swap then costs a few memcpys. Destinations never
        // overlap, so the order of the copies does not matter.
        let mut last: [Option<usize>; 6] = [None; 6];
        let mut copy = |c: Class, from: u32, to: u32, n: u32| {
            if n == 0 {
                return;
            }
            let k = c as usize;
            if let Some((_, lf, lt, ln)) = last[k].map(|i| &mut m.copies[i])
                && c != Class::M
                && lf.checked_add(*ln) == Some(from)
                && lt.checked_add(*ln) == Some(to)
            {
                *ln += n;
                return;
            }
            last[k] = Some(m.copies.len());
            m.copies.push((c, from, to, n));
        };
        // Every marker byte both memories have (clamped when applied).
        copy(Class::M, 0, 0, u32::MAX);
        let region = |c: Class, from: crate::layout::Region, to: crate::layout::Region| {
            (c, from.base, to.base, from.len.min(to.len))
        };
        for (c, f, t, n) in [
            region(Class::B, old.di, new.di),
            region(Class::B, old.dout, new.dout),
            region(Class::I, old.ai, new.ai),
            region(Class::I, old.ao, new.ao),
        ] {
            copy(c, f, t, n);
        }
        copy(Class::B, old.system.minor_fault.0, new.system.minor_fault.0, 1);
        for (n, s) in &new.timers {
            if let Some(o) = old.timers.get(n) {
                copy(Class::I, o.i.0, s.i.0, 4);
                copy(Class::B, o.b.0, s.b.0, 2);
            }
        }
        for (n, s) in &new.counters {
            if let Some(o) = old.counters.get(n) {
                copy(Class::I, o.i.0, s.i.0, 2);
                copy(Class::B, o.b.0, s.b.0, 5);
            }
        }
        copy(Class::I, old.system.fault_code.0, new.system.fault_code.0, 1);
        for (idx, tag) in new.tags.iter().enumerate() {
            let Some(oidx) = old.tags.position(&tag.name) else {
                continue;
            };
            let otag = old.tags.iter().nth(oidx);
            if otag.map(|t| t.ty) != Some(tag.ty) {
                continue;
            }
            match (old.slot(oidx), new.slot(idx)) {
                (TagSlot::Bool(a), TagSlot::Bool(b)) => copy(Class::B, a.0, b.0, 1),
                (TagSlot::Int(a), TagSlot::Int(b)) => copy(Class::I, a.0, b.0, 1),
                (TagSlot::Real(a), TagSlot::Real(b)) => copy(Class::F, a.0, b.0, 1),
                (TagSlot::Lint(a), TagSlot::Lint(b)) => copy(Class::L, a.0, b.0, 1),
                (TagSlot::Lreal(a), TagSlot::Lreal(b)) => copy(Class::D, a.0, b.0, 1),
                (TagSlot::Timer(a), TagSlot::Timer(b)) => {
                    copy(Class::I, a.i.0, b.i.0, 3);
                    copy(Class::B, a.b.0, b.b.0, 3);
                }
                (TagSlot::Counter(a), TagSlot::Counter(b)) => {
                    copy(Class::I, a.i.0, b.i.0, 2);
                    copy(Class::B, a.b.0, b.b.0, 5);
                }
                (TagSlot::Pid(a), TagSlot::Pid(b)) => {
                    use crate::op::{PID_B_SLOTS, PID_F_SLOTS, PID_I_SLOTS};
                    copy(Class::F, a.f.0, b.f.0, PID_F_SLOTS);
                    copy(Class::I, a.i.0, b.i.0, PID_I_SLOTS);
                    copy(Class::B, a.b.0, b.b.0, PID_B_SLOTS);
                }
                // Tags on addresses keep their value through the image/markers.
                _ => {}
            }
        }
        m
    }

    /// Copies the kept values of `from` (a memory of the old layout) into
    /// `into` (one of the new layout, its initial values).
    pub fn apply(&self, from: &Memory, into: &mut Memory) {
        for &(c, f, t, n) in &self.copies {
            match c {
                Class::B => copy_n(&from.b, f, &mut into.b, t, n),
                Class::I => copy_n(&from.i, f, &mut into.i, t, n),
                Class::F => copy_n(&from.f, f, &mut into.f, t, n),
                Class::L => copy_n(&from.l, f, &mut into.l, t, n),
                Class::D => copy_n(&from.d, f, &mut into.d, t, n),
                Class::M => {
                    let n = (n as usize).min(from.m.len()).min(into.m.len());
                    into.m[..n].copy_from_slice(&from.m[..n]);
                }
            }
        }
    }
}

fn copy_n<T: Copy>(src: &[T], from: u32, dst: &mut [T], to: u32, n: u32) {
    let (from, to, n) = (from as usize, to as usize, n as usize);
    dst[to..to + n].copy_from_slice(&src[from..from + n]);
}

fn int_value(v: i64, ty: DataType) -> Value {
    match ty {
        DataType::Sint => Value::Sint(v as i8),
        DataType::Int => Value::Int(v as i16),
        DataType::Time => Value::Time(v as i32),
        DataType::Lint => Value::Lint(v),
        _ => Value::Dint(v as i32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marker_words_are_big_endian_and_overlap() {
        let mut m = Memory::new(Counts::default(), 8);
        m.write(Place::MWord(2), Value::Int(0x1234));
        assert_eq!(m.m[2..4], [0x12, 0x34]);
        // MW3 overlaps MW2's low byte.
        assert_eq!(m.read(Place::MWord(3)), Value::Int(0x3400));
        m.write(Place::MBit { byte: 3, bit: 0 }, Value::Bool(true));
        assert_eq!(m.read(Place::MWord(2)), Value::Int(0x1235));
        m.write(Place::MReal(4), Value::Real(1.5));
        assert_eq!(m.read(Place::MReal(4)), Value::Real(1.5));
        assert_eq!(m.m[4..8], 1.5f32.to_be_bytes());
    }
}
