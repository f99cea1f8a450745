//! An Alba project as the compiler sees it: `alba.toml`'s project tables
//! ([`config`], one module per table, with their serde forms and checks),
//! the loaded folder ([`Project`]: the tables, `tags.csv` and the program
//! files) and the screens ([`hmi`]).
//!
//! No TOML reader here (ADR 0014): `alba-load`, above the compiler, reads
//! alba.toml into a [`config::RawConfig`] and loads folders; the services'
//! tables and users.toml are `alba-settings`'. The raw forms keep where each
//! value was written with `serde_spanned` (the type `toml` re-exports).

pub mod config;
pub mod hmi;
mod project;

pub use config::Config;
pub use project::{Language, ProgramSource, Project, ReadError, read_text};
