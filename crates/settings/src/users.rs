//! `users.toml`: the project's users, their roles and password hashes
//! (docs/file-formats.md, docs/security.md "Users and roles"). One store for
//! every interface (HTTP, WebSocket, OPC UA); the users of the deprecated
//! `[opcua.users]` of alba.toml are merged in by [`load_users`].
//!
//! ```toml
//! [users.alice]
//! role = "engineer"
//! password = "$argon2id$v=19$m=19456,t=2,p=1$...$..."
//! ```
//!
//! This module reads and writes the file and checks its form (names, roles,
//! hashes); verifying passwords is `alba-auth`'s.

use crate::{Settings as Config, check_password_hash};
use alba_diag::{Code, Diagnostic, FileId, Files, Span};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
use toml::Spanned;

/// The user file's name, beside alba.toml.
pub const USERS_FILE: &str = "users.toml";

/// The longest user name accepted.
pub const MAX_NAME_LEN: usize = 64;

/// What a user may do; each role includes the ones before it
/// (`Viewer < Operator < Engineer < Admin`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Reads everything, subscribes.
    Viewer,
    /// Writes non-input tags, acknowledges alarms.
    Operator,
    /// Forces I/O, edits online, saves programs and tags, runs/stops.
    Engineer,
    /// Manages users.
    Admin,
}

impl Role {
    pub const ALL: [Role; 4] = [Role::Viewer, Role::Operator, Role::Engineer, Role::Admin];

    pub fn as_str(self) -> &'static str {
        match self {
            Role::Viewer => "viewer",
            Role::Operator => "operator",
            Role::Engineer => "engineer",
            Role::Admin => "admin",
        }
    }

    /// Whether this role includes `needed`.
    pub fn allows(self, needed: Role) -> bool {
        self >= needed
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Role {
    type Err = String;

    fn from_str(s: &str) -> Result<Role, String> {
        Role::ALL
            .into_iter()
            .find(|r| r.as_str() == s)
            .ok_or_else(|| format!("`{s}` is not a role: use viewer, operator, engineer or admin"))
    }
}

/// One user of the store.
#[derive(Clone, PartialEq, Eq)]
pub struct User {
    pub name: String,
    pub role: Role,
    /// The password's argon2 hash as a PHC string (checked for form).
    pub hash: String,
    /// Where the user is defined (users.toml, or alba.toml's `[opcua.users]`).
    pub span: Span,
    /// Read from the deprecated `[opcua.users]` of alba.toml.
    pub from_opcua: bool,
}

impl fmt::Debug for User {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Never the hash, even in a debug print.
        f.debug_struct("User")
            .field("name", &self.name)
            .field("role", &self.role)
            .field("from_opcua", &self.from_opcua)
            .finish_non_exhaustive()
    }
}

/// Why a user name is refused, if it is: 1 to [`MAX_NAME_LEN`] characters,
/// letters, digits and `_ . - @`.
pub fn check_user_name(name: &str) -> Result<(), UserNameError> {
    if name.is_empty() {
        return Err(UserNameError::Empty);
    }
    if name.chars().count() > MAX_NAME_LEN {
        return Err(UserNameError::TooLong);
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_alphanumeric() || matches!(c, '_' | '.' | '-' | '@')))
    {
        return Err(UserNameError::Character(c));
    }
    Ok(())
}

/// Why a user name is refused ([`check_user_name`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UserNameError {
    #[error("a user name is not empty")]
    Empty,
    #[error("a user name has at most {MAX_NAME_LEN} characters")]
    TooLong,
    #[error("`{}` may not be in a user name (letters, digits and _ . - @ only)", .0.escape_default())]
    Character(char),
}

/// users.toml could not be written ([`save_users`]).
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {source}", path.display())]
pub struct SaveError {
    pub path: std::path::PathBuf,
    pub source: std::io::Error,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    #[serde(default)]
    users: BTreeMap<Spanned<String>, Spanned<RawUser>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawUser {
    role: Spanned<String>,
    password: Spanned<String>,
}

/// Parses and checks the text of users.toml; every problem found is a
/// diagnostic (code E107), and the users that passed are returned.
pub fn parse_users(text: &str, file: FileId) -> (Vec<User>, Vec<Diagnostic>) {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let raw: RawFile = match toml::from_str(text) {
        Ok(r) => r,
        Err(e) => {
            let msg = e.message().trim().to_string();
            return (
                Vec::new(),
                vec![
                    Diagnostic::new(
                        Code::UsersFile,
                        format!("users.toml: {msg}"),
                        sp(e.span().unwrap_or(0..0)),
                        "here",
                    )
                    .with_help("each user is a table: [users.NAME] with role = \"operator\" and password = \"$argon2id$...\"; `alba user add` writes it"),
                ],
            );
        }
    };
    let mut diags = Vec::new();
    let mut users = Vec::new();
    let mut entries: Vec<_> = raw.users.into_iter().collect();
    entries.sort_by_key(|(name, _)| name.span().start);
    for (name, entry) in entries {
        let n = name.get_ref();
        if let Err(why) = check_user_name(n) {
            diags.push(Diagnostic::new(
                Code::UsersFile,
                format!("`{n}` is not a valid user name"),
                sp(name.span()),
                why.to_string(),
            ));
            continue;
        }
        let entry = entry.into_inner();
        let role = match entry.role.get_ref().parse::<Role>() {
            Ok(r) => Some(r),
            Err(msg) => {
                diags.push(Diagnostic::new(
                    Code::UsersFile,
                    msg,
                    sp(entry.role.span()),
                    format!("the role of `{n}`"),
                ));
                None
            }
        };
        let hash_ok = match check_password_hash(entry.password.get_ref()) {
            Ok(()) => true,
            Err(msg) => {
                diags.push(
                    Diagnostic::new(
                        Code::UsersFile,
                        msg.to_string().replace("[opcua.users]", "users.toml"),
                        sp(entry.password.span()),
                        format!("the password hash of `{n}`"),
                    )
                    .with_help(format!("set the password with `alba user passwd <project> {n}`")),
                );
                false
            }
        };
        if let (Some(role), true) = (role, hash_ok) {
            users.push(User {
                name: n.clone(),
                role,
                hash: entry.password.into_inner(),
                span: sp(name.span()),
                from_opcua: false,
            });
        }
    }
    (users, diags)
}

/// The users of the deprecated `[opcua.users]` table as store users:
/// `read_only` ones are viewers, the others operators.
pub fn opcua_users(config: &Config) -> Vec<User> {
    let Some(o) = &config.opcua else { return Vec::new() };
    o.users
        .iter()
        .map(|u| User {
            name: u.name.clone(),
            role: if u.write { Role::Operator } else { Role::Viewer },
            hash: u.hash.clone(),
            span: u.span,
            from_opcua: true,
        })
        .collect()
}

/// A warning when users.toml (at `path`) may be read or written by other
/// users of the machine (Unix: any mode bit beyond 0600).
pub fn permission_warning(path: &Path) -> Option<Diagnostic> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).ok()?.permissions().mode() & 0o777;
        if mode & 0o077 != 0 {
            return Some(
                Diagnostic::unplaced(
                    Code::UsersFile,
                    format!(
                        "{} can be read or written by other users (mode {mode:o}): its password hashes are for its owner only",
                        path.display()
                    ),
                )
                .with_help(format!("chmod 600 {}", path.display())),
            );
        }
    }
    #[cfg(not(unix))]
    let _ = path;
    None
}

/// The deprecation warning for `[opcua.users]` in alba.toml, when it has
/// users (`None` otherwise). A warning: the project still loads and runs.
pub fn opcua_users_warning(config: &Config) -> Option<Diagnostic> {
    let first = config.opcua.as_ref()?.users.first()?;
    Some(
        Diagnostic::new(
            Code::OpcuaUsersDeprecated,
            "[opcua.users] is deprecated: users now live in users.toml, for every interface",
            first.span,
            "still accepted: these users are operators (viewers when in read_only)",
        )
        .with_help(
            "move each user with `alba user add <project> <name> --role operator` (or `alba user migrate <project>`, \
             which copies the hashes), then delete [opcua.users] and read_only from alba.toml",
        ),
    )
}

/// The error for an OPC UA `listen` address beyond loopback in a project
/// without users: such an address serves no anonymous endpoint, so nobody
/// could log in.
pub fn opcua_listen_needs_users(config: &Config, has_users: bool) -> Option<Diagnostic> {
    let o = config.opcua.as_ref()?;
    let (a, span) = (o.listen?, o.listen_span?);
    if a.ip().is_loopback() || has_users {
        return None;
    }
    Some(
        Diagnostic::new(
            Code::ConfigField,
            format!("listen = \"{a}\" is not a loopback address, so it needs users"),
            span,
            "beyond loopback only Basic256Sha256 with a user name and password is served",
        )
        .with_help("add users with `alba user add <project> <name> --role operator`, or listen on 127.0.0.1"),
    )
}

/// A project's user store as read from its folder: users.toml (when
/// present) merged with the deprecated `[opcua.users]` of alba.toml.
#[derive(Debug, Default)]
pub struct LoadedUsers {
    pub files: Files,
    /// users.toml's users first, then those of `[opcua.users]` whose name
    /// users.toml does not already have.
    pub users: Vec<User>,
    /// Errors: the store should not be used when there are any.
    pub errors: Vec<Diagnostic>,
    /// Warnings (the `[opcua.users]` deprecation, a users.toml open to others).
    pub warnings: Vec<Diagnostic>,
    /// Whether users.toml exists.
    pub has_file: bool,
}

/// Reads the user store of the project in `dir`: users.toml (a missing
/// file is an empty store) and alba.toml's `[opcua.users]` (a missing or
/// unreadable alba.toml adds nothing here: project loading reports it).
pub fn load_users(dir: &Path) -> LoadedUsers {
    let mut out = LoadedUsers::default();
    let path = dir.join(USERS_FILE);
    match std::fs::metadata(&path) {
        Ok(_) => {
            out.has_file = true;
            match alba_project::read_text(&path) {
                Ok(text) => {
                    let f = out.files.add(path.display().to_string(), text);
                    let (users, d) = parse_users(out.files.text(f), f);
                    out.users = users;
                    out.errors = d;
                    out.warnings.extend(permission_warning(&path));
                }
                Err(msg) => out.errors.push(Diagnostic::unplaced(Code::Io, msg.to_string())),
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => out.errors.push(Diagnostic::unplaced(
            Code::Io,
            format!("cannot read {}: {e}", path.display()),
        )),
    }
    if let Ok(text) = alba_project::read_text(&dir.join("alba.toml")) {
        let f = out.files.add(dir.join("alba.toml").display().to_string(), text);
        let (config, d) = Config::parse(out.files.text(f), f);
        if let Some(config) = config {
            // alba.toml's errors (a bad [opcua.users] entry included, which
            // is left out) are the project's to report: `alba check`.
            drop(d);
            out.warnings.extend(opcua_users_warning(&config));
            for u in opcua_users(&config) {
                if !out.users.iter().any(|x| x.name == u.name) {
                    out.users.push(u);
                }
            }
        }
    }
    out
}

/// The text of users.toml for `users` (those read from `[opcua.users]`
/// included: saving migrates them).
pub fn users_toml(users: &[User]) -> String {
    let mut out = String::from(
        "# Alba users (docs/security.md): managed with `alba user add|passwd|remove|list|role`.\n\
         # Passwords are argon2id hashes, never plain text. Keep this file private.\n",
    );
    let mut sorted: Vec<&User> = users.iter().collect();
    sorted.sort_by(|a, b| a.name.cmp(&b.name));
    for u in sorted {
        out.push_str(&format!(
            "\n[users.{}]\nrole = \"{}\"\npassword = {}\n",
            toml_key(&u.name),
            u.role,
            crate::toml_string(&u.hash)
        ));
    }
    out
}

/// `name` as a TOML key: bare when it can be, else quoted.
fn toml_key(name: &str) -> String {
    let bare = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        name.to_string()
    } else {
        crate::toml_string(name)
    }
}

/// Saves `users` as the users.toml of `dir`: atomically, readable and
/// writable by the owner only on Unix (0600).
pub fn save_users(dir: &Path, users: &[User]) -> Result<(), SaveError> {
    let path = dir.join(USERS_FILE);
    let text = users_toml(users);
    alba_model::fsutil::write_atomic_private(&path, |w| w.write_all(text.as_bytes()))
        .map_err(|source| SaveError { path, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HASH: &str = "$argon2id$v=19$m=8,t=1,p=1$YWxiYS10ZXN0LXNhbHQ$AAAAAAAAAAAAAAAAAAAAAA";

    #[test]
    fn roles_order_and_names() {
        assert!(Role::Viewer < Role::Operator && Role::Operator < Role::Engineer && Role::Engineer < Role::Admin);
        for r in Role::ALL {
            assert_eq!(r.to_string().parse::<Role>(), Ok(r));
        }
        assert!("Admin".parse::<Role>().is_err());
        assert!(Role::Engineer.allows(Role::Operator));
        assert!(!Role::Operator.allows(Role::Engineer));
    }

    #[test]
    fn parses_users_with_located_errors() {
        let text = format!(
            "[users.alice]\nrole = \"engineer\"\npassword = \"{HASH}\"\n\n\
             [users.bob]\nrole = \"boss\"\npassword = \"{HASH}\"\n\n\
             [users.carol]\nrole = \"viewer\"\npassword = \"hunter2\"\n\n\
             [users.\"d d\"]\nrole = \"viewer\"\npassword = \"{HASH}\"\n"
        );
        let mut files = Files::new();
        let f = files.add("users.toml", text);
        let (users, diags) = parse_users(files.text(f), f);
        assert_eq!(users.len(), 1);
        assert_eq!((users[0].name.as_str(), users[0].role), ("alice", Role::Engineer));
        let short: Vec<_> = diags.iter().map(|d| d.short(&files)).collect();
        assert_eq!(diags.len(), 3, "{short:?}");
        assert!(diags.iter().all(|d| d.code == Code::UsersFile));
        assert!(
            short[0].starts_with("users.toml:6:8:") && short[0].contains("`boss` is not a role"),
            "{short:?}"
        );
        assert!(
            short[1].starts_with("users.toml:11:12:") && short[1].contains("not a password hash"),
            "{short:?}"
        );
        assert!(short[2].starts_with("users.toml:13:8:"), "{short:?}");
    }

    #[test]
    fn unknown_keys_and_bad_toml_are_refused() {
        let mut files = Files::new();
        let f = files.add(
            "users.toml",
            format!("[users.a]\nrole = \"admin\"\npassword = \"{HASH}\"\nplain = \"x\"\n"),
        );
        let (users, diags) = parse_users(files.text(f), f);
        assert!(users.is_empty());
        assert_eq!(diags.len(), 1);
        assert!(diags[0].message.contains("unknown field"), "{}", diags[0].message);
        let g = files.add("users.toml", "[users.a\n");
        assert_eq!(parse_users(files.text(g), g).1.len(), 1);
    }

    #[test]
    fn user_names() {
        assert!(check_user_name("alice").is_ok());
        assert!(check_user_name("j.doe-2@plant_1").is_ok());
        assert!(check_user_name("").is_err());
        assert!(check_user_name("a b").is_err());
        assert!(check_user_name("a\"b").is_err());
        assert!(check_user_name(&"x".repeat(65)).is_err());
    }

    #[test]
    fn saves_read_back_owner_only() {
        let dir = std::env::temp_dir().join(format!("alba-users-save-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let u = |name: &str, role| User {
            name: name.into(),
            role,
            hash: HASH.into(),
            span: Span::new(FileId(0), 0..0),
            from_opcua: false,
        };
        save_users(&dir, &[u("zed", Role::Viewer), u("ann.o", Role::Admin)]).unwrap();
        let loaded = load_users(&dir);
        assert!(loaded.errors.is_empty(), "{:?}", loaded.errors);
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        assert!(loaded.has_file);
        let got: Vec<_> = loaded.users.iter().map(|u| (u.name.as_str(), u.role)).collect();
        assert_eq!(got, [("ann.o", Role::Admin), ("zed", Role::Viewer)]);
        let text = std::fs::read_to_string(dir.join(USERS_FILE)).unwrap();
        assert!(
            text.contains("[users.\"ann.o\"]\nrole = \"admin\"\n") && text.contains("[users.zed]\n"),
            "{text}"
        );
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(dir.join(USERS_FILE)).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o600);
            // Opened to others by hand: a warning that says how to fix it.
            let p = dir.join(USERS_FILE);
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o644)).unwrap();
            let w = load_users(&dir).warnings;
            assert_eq!(w.len(), 1);
            assert!(
                w[0].message.contains("mode 644")
                    && w[0].help.as_deref() == Some(&*format!("chmod 600 {}", p.display()))
            );
            save_users(&dir, &[u("zed", Role::Viewer)]).unwrap();
            assert!(load_users(&dir).warnings.is_empty(), "a save makes it private again");
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "temporary file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn opcua_users_merge_with_a_warning() {
        let dir = std::env::temp_dir().join(format!("alba-users-opcua-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("alba.toml"),
            format!(
                "name = \"t\"\nprograms = [\"main.lad\"]\n[opcua]\nread_only = [\"ro\"]\n[opcua.users]\nop = \"{HASH}\"\nro = \"{HASH}\"\nalice = \"{HASH}\"\n"
            ),
        )
        .unwrap();
        let none = load_users(&dir);
        assert!(!none.has_file && none.errors.is_empty());
        let got: Vec<_> = none
            .users
            .iter()
            .map(|u| (u.name.as_str(), u.role, u.from_opcua))
            .collect();
        assert_eq!(
            got,
            [
                ("op", Role::Operator, true),
                ("ro", Role::Viewer, true),
                ("alice", Role::Operator, true)
            ]
        );
        assert_eq!(none.warnings.len(), 1);
        assert_eq!(none.warnings[0].code, Code::OpcuaUsersDeprecated);
        assert!(none.warnings[0].help.as_deref().unwrap_or("").contains("alba user"));
        std::fs::write(
            dir.join(USERS_FILE),
            format!("[users.alice]\nrole = \"admin\"\npassword = \"{HASH}\"\n"),
        )
        .unwrap();
        let both = load_users(&dir);
        let got: Vec<_> = both.users.iter().map(|u| (u.name.as_str(), u.role)).collect();
        assert_eq!(
            got,
            [("alice", Role::Admin), ("op", Role::Operator), ("ro", Role::Viewer)]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
