//! The Alba scan engine: runs IR programs over typed program memory with
//! the semantics of SPEC §3.2, records minor faults, publishes power flow
//! on demand, and simulates in virtual time.

pub mod analysis;
pub mod autotune;
pub mod clock;
pub mod engine;
mod error;
pub mod exec;
pub mod fault;
#[cfg(feature = "jit")]
pub mod jit;
mod mem;
pub mod pid;
pub mod plant;
pub mod sim;

pub use clock::{Clock, MonotonicClock, VirtualClock};
pub use engine::{Engine, MajorFault, Prepared, Retired};
pub use error::EngineError;
pub use exec::PowerFlow;
pub use fault::{Fault, FaultCode, Faults};
