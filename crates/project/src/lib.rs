//! An Alba project: its settings file `alba.toml` ([`config`], one module
//! per table) and the loading of a project folder ([`Project::load`]: the
//! settings, `tags.csv` and the program files).
//!
//! The TOML reader lives here, apart from the data model (`alba-model`), so
//! the IR, the engine and the front ends do not depend on it. Password hashes
//! in `[opcua.users]` are checked for form with `password-hash` only; the
//! `argon2` verifier belongs to `alba-auth`. The user store, `users.toml`,
//! is read and written by [`users`].

pub mod config;
pub mod hmi;
mod project;
pub mod users;

pub use config::Config;
pub use project::{Language, ProgramSource, Project, read_text};
