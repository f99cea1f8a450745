//! Arduino firmware for Alba projects (SPEC §7.3, §7.5): the control program
//! as a sketch ([`sketch`]), built with avr-gcc against the Arduino AVR core
//! and checked against the board's flash and RAM ([`toolchain`]), and run on
//! an emulated MCU in simavr with the same stimulus and trace as `alba sim`
//! ([`simavr`]).

pub mod bytecode;
pub mod ihex;
pub mod interp;
pub mod simavr;
pub mod sketch;
pub mod toolchain;

pub use sketch::{Sketch, Target, generate};
