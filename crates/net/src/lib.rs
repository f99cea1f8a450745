//! Alba nets.

pub mod analysis;
pub mod ptnet;

pub use ptnet::PtNet;
