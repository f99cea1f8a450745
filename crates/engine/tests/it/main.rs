//! Integration tests of the engine: golden traces, properties, power flow.

mod autotune;
mod golden;
mod net_counter;
mod online_edit;
mod pid;
mod power_flow;
mod properties;
mod seed_functions;
mod thesis;
mod util;
