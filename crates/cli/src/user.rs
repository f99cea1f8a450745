//! `alba user add|passwd|remove|list|role|migrate`: the project's user
//! store, users.toml (docs/security.md, "Users and roles"). Passwords come
//! from a prompt without echo on a terminal, or as one line of standard
//! input otherwise; never from an argument.

use crate::audit::{audited, json_string};
use alba_audit::Action;
use alba_auth::{Role, Users, UsersError};
use clap::Subcommand;
use std::io::{BufRead, IsTerminal};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Subcommand)]
pub enum UserCmd {
    /// Add a user; the password is prompted for (or read as one line from stdin).
    Add {
        /// The project folder (with alba.toml).
        project: PathBuf,
        /// The user name: 1 to 64 letters, digits and `_ . - @`.
        name: String,
        /// viewer, operator, engineer or admin (each includes the ones before).
        #[arg(long)]
        role: Role,
    },
    /// Set a user's password (prompted for, or one line from stdin).
    Passwd { project: PathBuf, name: String },
    /// Remove a user.
    Remove { project: PathBuf, name: String },
    /// List the users and their roles (never the hashes).
    List { project: PathBuf },
    /// Change a user's role.
    Role { project: PathBuf, name: String, role: Role },
    /// Copy the users of the deprecated `[opcua.users]` of alba.toml into users.toml.
    Migrate { project: PathBuf },
}

pub fn run(cmd: UserCmd) -> ExitCode {
    match user(cmd) {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn user(cmd: UserCmd) -> Result<(), String> {
    match cmd {
        UserCmd::Add { project, name, role } => {
            // Checked before the password is asked for, and again on saving.
            let users = load(&project)?;
            alba_auth::check_user_name(&name).map_err(|why| format!("`{name}` is not a valid user name: {why}"))?;
            if users.get(&name).is_some() {
                return Err(format!(
                    "user `{name}` already exists (`alba user passwd` changes a password, `alba user role` a role)"
                ));
            }
            let pw = password(&name)?;
            let values = (None, Some(json_string(role.as_str())));
            audited(&project, Action::UserAdded, &name, values, "alba user add", || {
                Users::edit(&project, |users| users.add(&name, role, &pw)).map_err(|e: UsersError| e.to_string())
            })?;
            println!("added user `{name}` ({role})");
            Ok(())
        }
        UserCmd::Passwd { project, name } => {
            known(&load(&project)?, &name)?;
            let pw = password(&name)?;
            let values = (None, Some(json_string("password changed")));
            audited(&project, Action::UserChanged, &name, values, "alba user passwd", || {
                Users::edit(&project, |users| users.set_password(&name, &pw)).map_err(|e: UsersError| e.to_string())
            })?;
            println!("password of `{name}` changed");
            Ok(())
        }
        UserCmd::Remove { project, name } => {
            let before = load(&project)?.role(&name);
            let values = (before.map(|r| json_string(r.as_str())), None);
            audited(&project, Action::UserRemoved, &name, values, "alba user remove", || {
                Users::edit(&project, |users| -> Result<(), Refusal> {
                    known(users, &name)?;
                    if users.get(&name).is_some_and(|u| u.from_opcua) {
                        return Err(Refusal(format!(
                            "`{name}` is defined in [opcua.users] of alba.toml (deprecated): delete it there"
                        )));
                    }
                    Ok(users.remove(&name).map(drop)?)
                })
                .map_err(|Refusal(e)| e)
            })?;
            // A name also in [opcua.users] comes back from alba.toml.
            if load(&project)?.get(&name).is_some() {
                return Err(format!(
                    "`{name}` was removed from users.toml but is still in [opcua.users] of alba.toml: delete it there too"
                ));
            }
            println!("removed user `{name}`");
            Ok(())
        }
        UserCmd::List { project } => {
            let users = load(&project)?;
            for w in users.warnings() {
                eprint!("{w}");
            }
            if users.is_empty() {
                eprintln!("no users: `alba run` serves on loopback only, with full rights for every request");
            }
            for u in users.users() {
                let from = if u.from_opcua {
                    "  ([opcua.users] of alba.toml, deprecated)"
                } else {
                    ""
                };
                println!("{}\t{}{from}", u.name, u.role);
            }
            Ok(())
        }
        UserCmd::Role { project, name, role } => {
            let before = load(&project)?.role(&name);
            let values = (
                before.map(|r| json_string(r.as_str())),
                Some(json_string(role.as_str())),
            );
            audited(&project, Action::UserChanged, &name, values, "alba user role", || {
                Users::edit(&project, |users| -> Result<(), Refusal> {
                    known(users, &name)?;
                    Ok(users.set_role(&name, role)?)
                })
                .map_err(|Refusal(e)| e)
            })?;
            println!("`{name}` is now {role}");
            Ok(())
        }
        UserCmd::Migrate { project } => {
            let users = load(&project)?;
            if !users.has_opcua_users() {
                println!("nothing to migrate: alba.toml has no [opcua.users]");
                return Ok(());
            }
            let moved = Users::edit(&project, |users| -> Result<_, UsersError> {
                Ok(users
                    .users()
                    .iter()
                    .filter(|u| u.from_opcua)
                    .map(|u| u.name.clone())
                    .collect::<Vec<_>>())
            })
            .map_err(|e| e.to_string())?;
            println!(
                "copied {} into users.toml: {}\nnow delete [opcua.users] and read_only from the [opcua] table of alba.toml",
                if moved.len() == 1 { "1 user" } else { "the users" },
                moved.join(", ")
            );
            Ok(())
        }
    }
}

/// The user store of `project`, which must be a project folder. (Edits go
/// through `Users::edit`, which saves users of `[opcua.users]` too: they
/// are then in users.toml, which takes precedence.)
fn load(project: &Path) -> Result<Users, String> {
    if !project.join("alba.toml").is_file() {
        return Err(format!(
            "{} is not an Alba project (no alba.toml); `alba new <dir>` creates one",
            project.display()
        ));
    }
    Users::load(project).map_err(|diags| format!("the user store cannot be read:\n{diags}"))
}

fn known(users: &Users, name: &str) -> Result<(), String> {
    match users.get(name) {
        Some(_) => Ok(()),
        None => Err(format!("there is no user `{name}` (`alba user list` lists them)")),
    }
}

/// The new password of `name`: prompted twice without echo on a terminal,
/// else one line of standard input (its line end dropped).
fn password(name: &str) -> Result<String, String> {
    let pw = if std::io::stdin().is_terminal() {
        let first = rpassword::prompt_password(format!("New password for `{name}`: "))
            .map_err(|e| format!("cannot read the password: {e}"))?;
        alba_auth::check_password(name, &first).map_err(|e| e.to_string())?;
        let again = rpassword::prompt_password("Again: ").map_err(|e| format!("cannot read the password: {e}"))?;
        if again != first {
            return Err("the two passwords differ".into());
        }
        first
    } else {
        let mut line = String::new();
        std::io::stdin()
            .lock()
            .read_line(&mut line)
            .map_err(|e| format!("cannot read the password from standard input: {e}"))?;
        let pw = line.strip_suffix('\n').unwrap_or(&line);
        pw.strip_suffix('\r').unwrap_or(pw).to_string()
    };
    if pw.is_empty() {
        return Err("no password given (type it at the prompt, or give it as one line on standard input)".into());
    }
    alba_auth::check_password(name, &pw).map_err(|why| format!("weak password: {why}"))?;
    Ok(pw)
}

/// An error of `alba user` inside `Users::edit`: the store's or the
/// command's own (an unknown user, a user of `[opcua.users]`).
struct Refusal(String);

impl From<UsersError> for Refusal {
    fn from(e: UsersError) -> Refusal {
        Refusal(e.to_string())
    }
}

impl From<String> for Refusal {
    fn from(e: String) -> Refusal {
        Refusal(e)
    }
}
