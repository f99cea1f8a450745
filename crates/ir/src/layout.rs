//! Where every tag lives: the typed-slot layout of program memory.
//!
//! Slots are allocated per storage class (bool, i32, f32, i64, f64) in a
//! fixed order: system slots, then the I/O images (digital in, digital out,
//! analog in, analog out), then the tags in tags.csv order, then the
//! temporaries and constants the compiler needs. The layout is a pure
//! function of the tag table and the I/O channels the programs use, so a
//! recompiled program finds its tags again (see [`crate::Memory::migrate`]).

use crate::op::{B, Ctr, D, F, I, L, PID_B_SLOTS, PID_F_SLOTS, PID_I_SLOTS, Pidt, Tmr};
use alba_model::address::{Address, MarkerWidth};
use alba_model::slc::SlcStruct;
use alba_model::{DataType, TagTable};

/// Number of slots of each class.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    pub b: u32,
    pub i: u32,
    pub f: u32,
    pub l: u32,
    pub d: u32,
}

/// Where one tag's value is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TagSlot {
    Bool(B),
    /// SINT, INT, DINT, TIME.
    Int(I),
    Real(F),
    Lint(L),
    Lreal(D),
    Timer(Tmr),
    Counter(Ctr),
    Pid(Pidt),
    /// A tag on a marker address lives in marker memory.
    Marker(Address),
}

/// A contiguous run of slots: the I/O images.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Region {
    pub base: u32,
    pub len: u32,
}

/// System slots (SPEC §2.3, §2.4, and the S7-200 special memory of §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct System {
    /// `S:FS` (S7 `SM0.1`): true during the first scan after a start.
    pub first_scan: B,
    /// `S:MINOR`: set when a minor fault happened since the start.
    pub minor_fault: B,
    /// `S:FAULTCODE`: code of the last minor fault (see the engine's `FaultCode`).
    pub fault_code: I,
    /// `SM0.0`: always on.
    pub always_on: B,
    /// `SM0.4`: 30 s off, 30 s on.
    pub clock_60s: B,
    /// `SM0.5`: 0.5 s off, 0.5 s on.
    pub clock_1s: B,
    /// `SM0.6`: off one scan, on the next.
    pub scan_toggle: B,
    /// `SMW22`: duration of the last scan in ms.
    pub scan_time: I,
    /// Scan statistics set by the real-time runtime, six DINTs from here:
    /// `S:SCANTIME`, `S:SCANMIN`, `S:SCANMAX`, `S:SCANAVG`, `S:JITTER` (µs)
    /// and `S:OVERRUNS` (see [`STAT_TAGS`]).
    pub stats: I,
    /// `S:IOOK`: the I/O driver's link is healthy (always on with the
    /// simulated I/O).
    pub io_ok: B,
    /// `S:IOERRORS`: I/O link errors (timeouts, bad frames, lost ports)
    /// since the runtime started.
    pub io_errors: I,
    /// `S:RETAINLOST`: retentive data was lost at start (a damaged retain
    /// file, values that could not be restored); set by the runtime.
    pub retain_lost: B,
    /// `S:STOREOK`: every store of the runtime works (retain saves, the
    /// historian, disk space); set by the runtime.
    pub store_ok: B,
}

/// The scan-statistics tags, in slot order from [`System::stats`].
pub const STAT_TAGS: [&str; 6] = [
    "S:SCANTIME",
    "S:SCANMIN",
    "S:SCANMAX",
    "S:SCANAVG",
    "S:JITTER",
    "S:OVERRUNS",
];

/// The system tags and what they are.
pub const SYSTEM_TAGS: &[(&str, &str)] = &[
    ("S:FS", "first scan after a start (also SM0.1)"),
    ("S:MINOR", "a minor fault happened since the start"),
    ("S:FAULTCODE", "code of the last minor fault"),
    ("SM0.0", "always on"),
    ("SM0.1", "first scan after a start (also S:FS)"),
    ("SM0.4", "clock: 30 s off, 30 s on"),
    ("SM0.5", "clock: 0.5 s off, 0.5 s on"),
    ("SM0.6", "off one scan, on the next"),
    ("SMW22", "duration of the last scan in ms"),
    ("S:SCANTIME", "duration of the last scan in µs (real time)"),
    ("S:SCANMIN", "shortest scan since the last run, µs"),
    ("S:SCANMAX", "longest scan since the last run, µs"),
    ("S:SCANAVG", "mean scan time since the last run, µs"),
    ("S:JITTER", "largest lateness of a scan start since the last run, µs"),
    ("S:OVERRUNS", "scan deadlines missed since the last run"),
    ("S:IOOK", "the I/O link is healthy (always on with simulated I/O)"),
    ("S:IOERRORS", "I/O link errors since the runtime started"),
    ("S:RETAINLOST", "retentive data was lost at start (see /api/status)"),
    (
        "S:STOREOK",
        "retain saves, the historian and disk space are all healthy",
    ),
];

/// The slots of an S7-200 timer or counter (see `S7Tmr`, `S7Ctr`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct S7Slots {
    pub i: I,
    pub b: B,
}

/// What the programs of a project name besides tags, gathered before the
/// layout is made: I/O and marker addresses, S7-200 timers and counters.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Uses {
    pub addresses: Vec<Address>,
    pub timers: std::collections::BTreeSet<u8>,
    pub counters: std::collections::BTreeSet<u8>,
    /// SLC 500 timer and counter elements (`T4:0`, `C5:1`).
    pub slc: std::collections::BTreeSet<SlcStruct>,
}

#[derive(Debug, Clone)]
pub struct Layout {
    pub tags: TagTable,
    /// Parallel to `tags`.
    pub slots: Vec<TagSlot>,
    pub system: System,
    pub di: Region,
    pub dout: Region,
    pub ai: Region,
    pub ao: Region,
    pub counts: Counts,
    pub marker_bytes: u32,
    /// S7-200 timers `T0..T255` and counters `C0..C255` in use.
    pub timers: std::collections::BTreeMap<u8, S7Slots>,
    pub counters: std::collections::BTreeMap<u8, S7Slots>,
    /// SLC 500 timers and counters in use (`T4:0`): TIMER and COUNTER
    /// slots, as a tag of that type has.
    pub slc: std::collections::BTreeMap<SlcStruct, S7Slots>,
    /// Names resolve for a plant model (see [`Access::Output`]) while its
    /// programs compile.
    pub plant: bool,
}

impl Layout {
    /// Lays out `tags`, with I/O images large enough for every address used
    /// by a tag or by a program, and the S7 timers and counters programs use.
    pub fn new(tags: &TagTable, uses: &Uses) -> Layout {
        let used = &uses.addresses;
        let mut di = 0u32;
        let mut dout = 0u32;
        let mut ai = 0u32;
        let mut ao = 0u32;
        let mut marker = 0u32;
        for a in tags.iter().filter_map(|t| t.address.as_ref()).chain(used) {
            match *a {
                Address::DigitalIn(n) => di = di.max(n + 1),
                Address::DigitalOut(n) => dout = dout.max(n + 1),
                Address::AnalogIn(n) => ai = ai.max(n + 1),
                Address::AnalogOut(n) => ao = ao.max(n + 1),
                Address::Marker { .. } => marker = marker.max(a.footprint().1.div_ceil(8)),
            }
        }
        // Digital images are whole bytes, so %IXb.0..7 always exist together.
        let di = di.next_multiple_of(8);
        let dout = dout.next_multiple_of(8);
        let mut c = Counts::default();
        let system = System {
            first_scan: B(take(&mut c.b, 1)),
            minor_fault: B(take(&mut c.b, 1)),
            fault_code: I(take(&mut c.i, 1)),
            always_on: B(take(&mut c.b, 1)),
            clock_60s: B(take(&mut c.b, 1)),
            clock_1s: B(take(&mut c.b, 1)),
            scan_toggle: B(take(&mut c.b, 1)),
            scan_time: I(take(&mut c.i, 1)),
            stats: I(take(&mut c.i, STAT_TAGS.len() as u32)),
            // Placed after everything else, below.
            io_ok: B(0),
            io_errors: I(0),
            retain_lost: B(0),
            store_ok: B(0),
        };
        let di = Region {
            base: take(&mut c.b, di),
            len: di,
        };
        let dout = Region {
            base: take(&mut c.b, dout),
            len: dout,
        };
        let ai = Region {
            base: take(&mut c.i, ai),
            len: ai,
        };
        let ao = Region {
            base: take(&mut c.i, ao),
            len: ao,
        };
        let mut slots = Vec::with_capacity(tags.len());
        for t in tags.iter() {
            let slot = match (t.address, t.ty) {
                (Some(Address::DigitalIn(n)), _) => TagSlot::Bool(B(di.base + n)),
                (Some(Address::DigitalOut(n)), _) => TagSlot::Bool(B(dout.base + n)),
                (Some(Address::AnalogIn(n)), _) => TagSlot::Int(I(ai.base + n)),
                (Some(Address::AnalogOut(n)), _) => TagSlot::Int(I(ao.base + n)),
                (Some(a @ Address::Marker { .. }), _) => TagSlot::Marker(a),
                (None, DataType::Bool) => TagSlot::Bool(B(take(&mut c.b, 1))),
                (None, DataType::Sint | DataType::Int | DataType::Dint | DataType::Time) => {
                    TagSlot::Int(I(take(&mut c.i, 1)))
                }
                (None, DataType::Real) => TagSlot::Real(F(take(&mut c.f, 1))),
                (None, DataType::Lint) => TagSlot::Lint(L(take(&mut c.l, 1))),
                (None, DataType::Lreal) => TagSlot::Lreal(D(take(&mut c.d, 1))),
                (None, DataType::Timer) => TagSlot::Timer(Tmr {
                    i: I(take(&mut c.i, 3)),
                    b: B(take(&mut c.b, 3)),
                }),
                (None, DataType::Counter) => TagSlot::Counter(Ctr {
                    i: I(take(&mut c.i, 2)),
                    b: B(take(&mut c.b, 5)),
                }),
                (None, DataType::Pid) => TagSlot::Pid(Pidt {
                    f: F(take(&mut c.f, PID_F_SLOTS)),
                    i: I(take(&mut c.i, PID_I_SLOTS)),
                    b: B(take(&mut c.b, PID_B_SLOTS)),
                }),
            };
            slots.push(slot);
        }
        // After the tags, so tag slots do not move when timers are added.
        let mut slots_of = |ints: u32, bools: u32| S7Slots {
            i: I(take(&mut c.i, ints)),
            b: B(take(&mut c.b, bools)),
        };
        let timers = uses.timers.iter().map(|&n| (n, slots_of(4, 2))).collect();
        let counters = uses.counters.iter().map(|&n| (n, slots_of(2, 5))).collect();
        let slc = uses
            .slc
            .iter()
            .map(|&st| (st, if st.counter { slots_of(2, 5) } else { slots_of(3, 3) }))
            .collect();
        // The I/O link status came later than the rest: last, so that no
        // other slot moved when it was added.
        let mut system = system;
        system.io_ok = B(take(&mut c.b, 1));
        system.io_errors = I(take(&mut c.i, 1));
        // And the store health after it, for the same reason.
        system.retain_lost = B(take(&mut c.b, 1));
        system.store_ok = B(take(&mut c.b, 1));
        Layout {
            tags: tags.clone(),
            slots,
            timers,
            counters,
            slc,
            plant: false,
            system,
            di,
            dout,
            ai,
            ao,
            counts: c,
            marker_bytes: marker,
        }
    }

    /// The slot of the tag at position `idx` of the tag table.
    pub fn slot(&self, idx: usize) -> TagSlot {
        self.slots[idx]
    }

    /// Marker place of a marker address with a given type.
    pub fn marker_place(addr: Address, ty: DataType) -> Option<Place> {
        let Address::Marker { byte, width } = addr else {
            return None;
        };
        Some(match width {
            MarkerWidth::Bit(bit) => Place::MBit { byte, bit },
            MarkerWidth::Byte => Place::MByte(byte),
            MarkerWidth::Word => Place::MWord(byte),
            MarkerWidth::DWord if ty == DataType::Real => Place::MReal(byte),
            MarkerWidth::DWord => Place::MDword(byte, ty),
        })
    }

    /// Is `p` in the digital or analog output image?
    pub fn is_output(&self, p: Place) -> bool {
        let within = |r: Region, x: u32| (r.base..r.base + r.len).contains(&x);
        match p {
            Place::Bool(b) => within(self.dout, b.0),
            Place::Int(i, _) => within(self.ao, i.0),
            _ => false,
        }
    }

    /// The place of an address, if it is inside the image.
    pub fn address_place(&self, addr: Address, ty: DataType) -> Option<Place> {
        let inside = |r: Region, n: u32| (n < r.len).then_some(r.base + n);
        Some(match addr {
            Address::DigitalIn(n) => Place::Bool(B(inside(self.di, n)?)),
            Address::DigitalOut(n) => Place::Bool(B(inside(self.dout, n)?)),
            Address::AnalogIn(n) => Place::Int(I(inside(self.ai, n)?), ty),
            Address::AnalogOut(n) => Place::Int(I(inside(self.ao, n)?), ty),
            Address::Marker { .. } => {
                if addr.footprint().1 > self.marker_bytes * 8 {
                    return None;
                }
                Layout::marker_place(addr, ty)?
            }
        })
    }
}

fn take(counter: &mut u32, n: u32) -> u32 {
    let at = *counter;
    *counter += n;
    at
}

/// Where a value lives: a typed slot or a place in marker memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Place {
    Bool(B),
    /// An integer slot holding a value of the given type (SINT, INT, DINT, TIME).
    Int(I, DataType),
    Real(F),
    Lint(L),
    Lreal(D),
    MBit {
        byte: u32,
        bit: u8,
    },
    /// SINT in marker memory.
    MByte(u32),
    /// INT in marker memory (big-endian).
    MWord(u32),
    /// DINT or TIME in marker memory (big-endian).
    MDword(u32, DataType),
    /// REAL in marker memory (big-endian IEEE bits).
    MReal(u32),
}

impl Place {
    pub fn data_type(&self) -> DataType {
        match *self {
            Place::Bool(_) | Place::MBit { .. } => DataType::Bool,
            Place::Int(_, t) | Place::MDword(_, t) => t,
            Place::Real(_) | Place::MReal(_) => DataType::Real,
            Place::Lint(_) => DataType::Lint,
            Place::Lreal(_) => DataType::Lreal,
            Place::MByte(_) => DataType::Sint,
            Place::MWord(_) => DataType::Int,
        }
    }
}
