//! Integration tests of the engine: golden traces, properties, power flow.

mod autotune;
mod golden;
mod net_elements;
mod online_edit;
mod pid;
mod power_flow;
mod properties;
mod run_over;
mod seed_functions;
mod thesis;
mod util;
