//! The server's request handler, without sockets or a runtime: what a
//! decoded request reads from program memory and the map, and what it
//! writes. The Modbus TCP server (`alba-modbus`) and the synchronous path
//! the fuzz target runs (the `offline` module) both answer through [`plan`],
//! so they answer every request the same way.

use crate::map::{Map, Scratch, Write};
use crate::pdu::{self, Exception, Request};
use alba_ir::Memory;
use alba_project::config::ModbusArea;

/// What a request needs once it is checked: nothing more (a read, answered
/// onto `out`), or writes to apply, then an echo of the request's address
/// and count or value (FC 5, 6, 15, 16) or a read of holding registers (FC 23).
pub enum Plan {
    Done,
    Write { writes: Vec<Write>, then: Then },
}

/// What follows a write once it is applied.
pub enum Then {
    Echo([u8; 4]),
    ReadRegs { start: u16, count: u16 },
}

/// Reads answer from `mem` onto `out` (after the function code); writes
/// are checked and planned, not applied.
pub fn plan(req: Request<'_>, map: &Map, mem: &Memory, sc: &Scratch, out: &mut Vec<u8>) -> Result<Plan, Exception> {
    // What a write's reply repeats (unused by reads).
    let echo = Then::Echo(req.echo().unwrap_or_default());
    let (writes, then) = match req {
        Request::ReadCoils { start, count } => {
            return read(map, mem, sc, ModbusArea::Coil, start, count, out).map(|()| Plan::Done);
        }
        Request::ReadDiscreteInputs { start, count } => {
            return read(map, mem, sc, ModbusArea::DiscreteInput, start, count, out).map(|()| Plan::Done);
        }
        Request::ReadHoldingRegisters { start, count } => {
            return read(map, mem, sc, ModbusArea::HoldingRegister, start, count, out).map(|()| Plan::Done);
        }
        Request::ReadInputRegisters { start, count } => {
            return read(map, mem, sc, ModbusArea::InputRegister, start, count, out).map(|()| Plan::Done);
        }
        Request::WriteSingleCoil { addr, value } => {
            let mut w = Vec::with_capacity(1);
            map.plan_coils(addr, std::iter::once(value), &mut w)?;
            (w, echo)
        }
        Request::WriteSingleRegister { addr, value } => {
            let mut w = Vec::with_capacity(1);
            map.plan_regs(addr, &[value], &mut w)?;
            (w, echo)
        }
        Request::WriteMultipleCoils { start, count, bits } => {
            let mut w = Vec::with_capacity(usize::from(count));
            map.plan_coils(start, (0..usize::from(count)).map(|i| pdu::bit(&bits, i)), &mut w)?;
            (w, echo)
        }
        Request::WriteMultipleRegisters { start, values } => {
            let values: Vec<u16> = pdu::registers(&values).collect();
            let mut w = Vec::with_capacity(values.len());
            map.plan_regs(start, &values, &mut w)?;
            (w, echo)
        }
        Request::ReadWriteRegisters {
            read_start: start,
            read_count: count,
            write_start,
            values,
        } => {
            // Both halves are checked before anything is written.
            let mut probe = Vec::new();
            read(map, mem, sc, ModbusArea::HoldingRegister, start, count, &mut probe)?;
            let values: Vec<u16> = pdu::registers(&values).collect();
            let mut w = Vec::with_capacity(values.len());
            map.plan_regs(write_start, &values, &mut w)?;
            (w, Then::ReadRegs { start, count })
        }
    };
    Ok(Plan::Write { writes, then })
}

/// A read's reply data: the byte count, then the bits or registers.
pub fn read(
    map: &Map,
    mem: &Memory,
    sc: &Scratch,
    area: ModbusArea,
    start: u16,
    count: u16,
    out: &mut Vec<u8>,
) -> Result<(), Exception> {
    let at = |i: u16| u32::from(start) + u32::from(i);
    if area.is_bits() {
        pdu::put_bits(out, count, |i| map.bit(area, mem, sc, at(i)))
    } else {
        pdu::put_registers(out, count, |i| map.reg(area, mem, sc, at(i)))
    }
}
