//! The address map: Modbus addresses to places of program memory.
//!
//! OpenPLC v3's map (SPEC §9), so HMIs made for OpenPLC work unchanged:
//!
//! | area | addresses | Alba |
//! |---|---|---|
//! | coils | 0–8191 | `%QX` (digital outputs, `%QX0.0` = coil 0) |
//! | discrete inputs | 0–8191 | `%IX` (digital inputs) |
//! | input registers | 0–1023 | `%IW` (analog inputs) |
//! | holding registers | 0–1023 | `%QW` (analog outputs) |
//! | holding registers | 1024–2047 | `%MW0`–`%MW1023` (marker bytes 0–2047) |
//! | holding registers | 2048–4095 | `%MD0`–`%MD1023`, two registers each, high word first (marker bytes 0–4095) |
//! | holding registers | 4096–8191 | OpenPLC's `%ML` (Alba has no `%ML`: kept as Modbus-only storage) |
//!
//! Alba's marker memory is one byte-addressed area (SPEC §2.2), so the
//! `%MW` and `%MD` windows show the same bytes: register 1024 + n and
//! register 2048 + n are both marker bytes 2n and 2n+1.
//!
//! As in OpenPLC, an address inside these ranges that the project's image
//! does not reach reads 0 (inputs) or is Modbus-only storage (coils and
//! holding registers: what a client writes, clients read back; programs do
//! not see it). After these ranges come the explicit addresses of
//! `[modbus.tags]`; any other address is an illegal data address.

use crate::pdu::Exception;
use alba_diag::{Code, Diagnostic};
use alba_ir::{Access, Layout, Memory, Place, Region, Target};
use alba_model::{Address, DataType, Value};
use alba_project::config::{ModbusArea, ModbusTag};
use std::sync::atomic::{AtomicBool, AtomicU16, Ordering};

/// OpenPLC's ranges.
pub const BITS: u32 = 8192;
pub const INPUT_REGS: u32 = 1024;
pub const HOLDING_REGS: u32 = 8192;
const MW_BASE: u32 = 1024;
const MD_BASE: u32 = 2048;
const ML_BASE: u32 = 4096;

/// Coils and holding registers of OpenPLC's ranges that the image does not
/// reach: Modbus-only storage shared by every connection (lock-free).
pub struct Scratch {
    coils: Vec<AtomicBool>,
    regs: Vec<AtomicU16>,
}

impl Default for Scratch {
    fn default() -> Scratch {
        Scratch {
            coils: (0..BITS).map(|_| AtomicBool::new(false)).collect(),
            regs: (0..HOLDING_REGS).map(|_| AtomicU16::new(0)).collect(),
        }
    }
}

/// One place of a write, checked and ready to apply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Write {
    Engine(Place, Value),
    Coil(u16, bool),
    Reg(u16, u16),
}

impl Scratch {
    pub fn apply(&self, w: &Write) {
        match *w {
            Write::Coil(a, v) => self.coils[usize::from(a)].store(v, Ordering::Relaxed),
            Write::Reg(a, v) => self.regs[usize::from(a)].store(v, Ordering::Relaxed),
            Write::Engine(..) => {}
        }
    }
}

/// A tag on an explicit address.
#[derive(Debug, Clone)]
struct Entry {
    start: u32,
    width: u32,
    place: Place,
}

/// The map of one compiled program.
#[derive(Debug, Clone)]
pub struct Map {
    di: Region,
    dout: Region,
    ai: Region,
    ao: Region,
    /// Per analog output: its tag is a DINT (a register is written to it
    /// as 0..65535 rather than as a signed INT).
    ao_dint: Vec<bool>,
    marker_bytes: u32,
    /// Explicit entries per area (coil, di, ir, hr), sorted by start.
    explicit: [Vec<Entry>; 4],
}

fn area_index(a: ModbusArea) -> usize {
    match a {
        ModbusArea::Coil => 0,
        ModbusArea::DiscreteInput => 1,
        ModbusArea::InputRegister => 2,
        ModbusArea::HoldingRegister => 3,
    }
}

fn area_name(a: ModbusArea) -> &'static str {
    match a {
        ModbusArea::Coil => "coils",
        ModbusArea::DiscreteInput => "discrete inputs",
        ModbusArea::InputRegister => "input registers",
        ModbusArea::HoldingRegister => "holding registers",
    }
}

/// Registers a value of this type takes.
pub fn width(ty: DataType) -> u32 {
    match ty {
        DataType::Lint | DataType::Lreal => 4,
        DataType::Dint | DataType::Real | DataType::Time => 2,
        _ => 1,
    }
}

fn range_text(area: ModbusArea, start: u32, width: u32) -> String {
    if width == 1 {
        format!("{} {start}", area.key())
    } else {
        format!("{} {start} to {}", area.key(), start + width - 1)
    }
}

impl Map {
    /// The map of `layout` with the explicit addresses of `[modbus.tags]`.
    /// Entries that cannot be used are left out, each with a diagnostic
    /// (E106) on its place in alba.toml.
    pub fn build(layout: &Layout, tags: &[ModbusTag]) -> (Map, Vec<Diagnostic>) {
        let mut diags = Vec::new();
        let mut ao_dint = vec![false; layout.ao.len as usize];
        for t in layout.tags.iter() {
            if let Some(Address::AnalogOut(n)) = t.address
                && let Some(d) = ao_dint.get_mut(n as usize)
            {
                *d = t.ty == DataType::Dint;
            }
        }
        let mut explicit: [Vec<(Entry, &ModbusTag)>; 4] = Default::default();
        for t in tags {
            let bad = |msg: String| Diagnostic::new(Code::ModbusTag, msg, t.name_span, "in [modbus.tags]");
            let (place, access) = match layout.resolve(&t.name) {
                Ok(Target::Value { place, access }) => (place, access),
                Ok(Target::Timer(_) | Target::Counter(_)) => {
                    diags.push(bad(format!(
                        "`{}` is a structure: map its members (`{0}.PRE`, `{0}.ACC`, `{0}.DN`)",
                        t.name
                    )));
                    continue;
                }
                Ok(Target::Pid(_)) => {
                    diags.push(bad(format!(
                        "`{}` is a PID loop: map its members (`{0}.SP`, `{0}.PV`, `{0}.CV`, `{0}.MAN`)",
                        t.name
                    )));
                    continue;
                }
                Err(e) => {
                    diags.push(bad(e.to_string()));
                    continue;
                }
            };
            let ty = place.data_type();
            if (ty == DataType::Bool) != t.area.is_bits() {
                let want = if ty == DataType::Bool {
                    "a coil or a discrete input (`coil`, `di`)"
                } else {
                    "registers (`hr`, `ir`)"
                };
                diags.push(
                    Diagnostic::new(
                        Code::ModbusTag,
                        format!("`{}` is a {ty}: it goes on {want}", t.name),
                        t.span,
                        "here",
                    )
                    .with_note(t.name_span, "the tag"),
                );
                continue;
            }
            if t.area.is_writable() && access != Access::ReadWrite {
                let what = if access == Access::Input {
                    "an input"
                } else {
                    "read-only"
                };
                let to = if t.area.is_bits() {
                    "a discrete input (`di`)"
                } else {
                    "an input register (`ir`)"
                };
                diags.push(
                    Diagnostic::new(
                        Code::ModbusTag,
                        format!(
                            "`{}` is {what}: clients write {}, so put it on {to}",
                            t.name,
                            area_name(t.area)
                        ),
                        t.span,
                        "a writable area",
                    )
                    .with_note(t.name_span, "the tag"),
                );
                continue;
            }
            let w = if t.area.is_bits() { 1 } else { width(ty) };
            let start = u32::from(t.start);
            if start + w > 0x1_0000 {
                diags.push(Diagnostic::new(
                    Code::ModbusTag,
                    format!(
                        "`{}` needs {w} registers: {} runs past 65535",
                        t.name,
                        range_text(t.area, start, w)
                    ),
                    t.span,
                    "here",
                ));
                continue;
            }
            explicit[area_index(t.area)].push((Entry { start, width: w, place }, t));
        }
        let mut out: [Vec<Entry>; 4] = Default::default();
        for (i, list) in explicit.iter_mut().enumerate() {
            list.sort_by_key(|(e, _)| e.start);
            let mut kept: Vec<(Entry, &ModbusTag)> = Vec::new();
            for (e, t) in list.drain(..) {
                if let Some((p, pt)) = kept.last()
                    && e.start < p.start + p.width
                {
                    diags.push(
                        Diagnostic::new(
                            Code::ModbusTag,
                            format!(
                                "`{}` ({}) overlaps `{}` ({})",
                                t.name,
                                range_text(t.area, e.start, e.width),
                                pt.name,
                                range_text(pt.area, p.start, p.width)
                            ),
                            t.span,
                            "here",
                        )
                        .with_note(pt.span, "the other entry"),
                    );
                    continue;
                }
                kept.push((e, t));
            }
            out[i] = kept.into_iter().map(|(e, _)| e).collect();
        }
        diags.sort_by_key(|d| d.primary.as_ref().map(|l| l.span.start));
        (
            Map {
                di: layout.di,
                dout: layout.dout,
                ai: layout.ai,
                ao: layout.ao,
                ao_dint,
                marker_bytes: layout.marker_bytes,
                explicit: out,
            },
            diags,
        )
    }

    fn entry(&self, area: ModbusArea, addr: u32) -> Option<&Entry> {
        let list = &self.explicit[area_index(area)];
        let i = list.partition_point(|e| e.start <= addr);
        let e = list.get(i.checked_sub(1)?)?;
        (addr < e.start + e.width).then_some(e)
    }

    /// One coil or discrete input.
    pub fn bit(&self, area: ModbusArea, mem: &Memory, scratch: &Scratch, addr: u32) -> Result<bool, Exception> {
        if addr < BITS {
            let (r, from_scratch) = if area == ModbusArea::Coil {
                (self.dout, true)
            } else {
                (self.di, false)
            };
            return Ok(if addr < r.len {
                mem.b[(r.base + addr) as usize]
            } else {
                from_scratch && scratch.coils[addr as usize].load(Ordering::Relaxed)
            });
        }
        let e = self.entry(area, addr).ok_or(Exception::IllegalDataAddress)?;
        Ok(mem.read(e.place).as_bool())
    }

    fn marker_reg(&self, mem: &Memory, scratch: &Scratch, addr: u32, byte: u32) -> u16 {
        if byte >= self.marker_bytes {
            return scratch.regs[addr as usize].load(Ordering::Relaxed);
        }
        let hi = mem.m.get(byte as usize).copied().unwrap_or(0);
        let lo = mem.m.get(byte as usize + 1).copied().unwrap_or(0);
        u16::from_be_bytes([hi, lo])
    }

    /// One input or holding register.
    pub fn reg(&self, area: ModbusArea, mem: &Memory, scratch: &Scratch, addr: u32) -> Result<u16, Exception> {
        match area {
            ModbusArea::InputRegister if addr < INPUT_REGS => Ok(if addr < self.ai.len {
                mem.i[(self.ai.base + addr) as usize] as u16
            } else {
                0
            }),
            ModbusArea::HoldingRegister if addr < MW_BASE => Ok(if addr < self.ao.len {
                mem.i[(self.ao.base + addr) as usize] as u16
            } else {
                scratch.regs[addr as usize].load(Ordering::Relaxed)
            }),
            ModbusArea::HoldingRegister if addr < MD_BASE => {
                Ok(self.marker_reg(mem, scratch, addr, 2 * (addr - MW_BASE)))
            }
            ModbusArea::HoldingRegister if addr < ML_BASE => {
                Ok(self.marker_reg(mem, scratch, addr, 2 * (addr - MD_BASE)))
            }
            ModbusArea::HoldingRegister if addr < HOLDING_REGS => {
                Ok(scratch.regs[addr as usize].load(Ordering::Relaxed))
            }
            _ => {
                let e = self.entry(area, addr).ok_or(Exception::IllegalDataAddress)?;
                let words = to_registers(mem.read(e.place));
                Ok(words[(addr - e.start) as usize])
            }
        }
    }

    /// Checks a write of coils and says what to write; nothing is written
    /// if any address is illegal.
    pub fn plan_coils(
        &self,
        start: u16,
        values: impl Iterator<Item = bool>,
        out: &mut Vec<Write>,
    ) -> Result<(), Exception> {
        for (i, v) in values.enumerate() {
            let addr = u32::from(start) + i as u32;
            if addr < BITS {
                out.push(if addr < self.dout.len {
                    Write::Engine(Place::Bool(alba_ir::B(self.dout.base + addr)), Value::Bool(v))
                } else {
                    Write::Coil(addr as u16, v)
                });
            } else {
                let e = self
                    .entry(ModbusArea::Coil, addr)
                    .ok_or(Exception::IllegalDataAddress)?;
                out.push(Write::Engine(e.place, Value::Bool(v)));
            }
        }
        Ok(())
    }

    /// Checks a write of holding registers and says what to write. A tag on
    /// explicit registers is written whole or not at all (a write that
    /// covers only part of it is an illegal data address); a value its
    /// type cannot hold is an illegal data value.
    pub fn plan_regs(&self, start: u16, values: &[u16], out: &mut Vec<Write>) -> Result<(), Exception> {
        let mut i = 0usize;
        while i < values.len() {
            let addr = u32::from(start) + i as u32;
            let v = values[i];
            if addr < HOLDING_REGS {
                let marker = |byte: u32| {
                    if byte + 1 < self.marker_bytes {
                        Write::Engine(Place::MWord(byte), Value::Int(v as i16))
                    } else if byte < self.marker_bytes {
                        Write::Engine(Place::MByte(byte), Value::Sint((v >> 8) as i8))
                    } else {
                        Write::Reg(addr as u16, v)
                    }
                };
                out.push(match addr {
                    a if a < MW_BASE && a < self.ao.len => {
                        let dint = self.ao_dint.get(a as usize).copied().unwrap_or(false);
                        let (ty, value) = if dint {
                            (DataType::Dint, Value::Dint(i32::from(v)))
                        } else {
                            (DataType::Int, Value::Int(v as i16))
                        };
                        Write::Engine(Place::Int(alba_ir::I(self.ao.base + a), ty), value)
                    }
                    a if a < MW_BASE => Write::Reg(a as u16, v),
                    a if a < MD_BASE => marker(2 * (a - MW_BASE)),
                    a if a < ML_BASE => marker(2 * (a - MD_BASE)),
                    a => Write::Reg(a as u16, v),
                });
                i += 1;
                continue;
            }
            let e = self
                .entry(ModbusArea::HoldingRegister, addr)
                .ok_or(Exception::IllegalDataAddress)?;
            let w = e.width as usize;
            if addr != e.start || i + w > values.len() {
                return Err(Exception::IllegalDataAddress);
            }
            let value = from_registers(e.place.data_type(), &values[i..i + w]).ok_or(Exception::IllegalDataValue)?;
            out.push(Write::Engine(e.place, value));
            i += w;
        }
        Ok(())
    }
}

/// A value as registers, high word first.
pub fn to_registers(v: Value) -> [u16; 4] {
    let mut w = [0u16; 4];
    let mut put = |bytes: &[u8]| {
        for (k, p) in bytes.chunks_exact(2).enumerate() {
            w[k] = u16::from_be_bytes([p[0], p[1]]);
        }
    };
    match v {
        Value::Bool(b) => w[0] = u16::from(b),
        Value::Sint(x) => w[0] = x as i16 as u16,
        Value::Int(x) => w[0] = x as u16,
        Value::Dint(x) | Value::Time(x) => put(&x.to_be_bytes()),
        Value::Real(x) => put(&x.to_be_bytes()),
        Value::Lint(x) => put(&x.to_be_bytes()),
        Value::Lreal(x) => put(&x.to_be_bytes()),
    }
    w
}

/// A value of type `ty` from its registers (high word first); `None` when
/// it does not fit the type (a SINT outside -128..127, a non-finite real).
pub fn from_registers(ty: DataType, r: &[u16]) -> Option<Value> {
    let mut bytes = [0u8; 8];
    for (k, w) in r.iter().take(4).enumerate() {
        bytes[2 * k..2 * k + 2].copy_from_slice(&w.to_be_bytes());
    }
    let b4 = [bytes[0], bytes[1], bytes[2], bytes[3]];
    Some(match ty {
        DataType::Bool => Value::Bool(*r.first()? != 0),
        DataType::Sint => Value::Sint(i8::try_from(*r.first()? as i16).ok()?),
        DataType::Int => Value::Int(*r.first()? as i16),
        DataType::Dint => Value::Dint(i32::from_be_bytes(b4)),
        DataType::Time => Value::Time(i32::from_be_bytes(b4)),
        DataType::Real => Some(f32::from_be_bytes(b4))
            .filter(|f| f.is_finite())
            .map(Value::Real)?,
        DataType::Lint => Value::Lint(i64::from_be_bytes(bytes)),
        DataType::Lreal => Some(f64::from_be_bytes(bytes))
            .filter(|f| f.is_finite())
            .map(Value::Lreal)?,
        _ => return None,
    })
}
