//! Alba's alarms (docs/alarms.md): definitions from `alarms.csv`
//! ([`def`]), the ISA-18.2 state machine evaluated on published snapshots at
//! the engine's time ([`state`]), and the persistent log ([`log`]). No HTTP
//! here: the API (alba-server) and `alba run` (alba-app) use this crate.

pub mod def;
pub mod hub;
pub mod kpi;
pub mod log;
pub mod state;

pub use def::{AlarmDef, Cmp, Condition, parse};
pub use hub::{Hub, HubError, Request, Stats};
pub use log::{Log, LogError};
pub use state::{ActionError, Alarm, Alarms, Event, Persisted, State, format_value};

/// The file of a project that defines its alarms.
pub const FILE: &str = "alarms.csv";
