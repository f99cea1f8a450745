//! Alba's users (docs/security.md, "Users and roles"): one store for every
//! interface (HTTP and WebSocket, OPC UA), kept in the project's
//! `users.toml`, with a [`Role`] per user and the argon2id hash of each
//! password.
//!
//! - [`Users::load`] reads the store of a project folder (users.toml, plus
//!   the deprecated `[opcua.users]` of alba.toml); [`Users::verify`] checks
//!   a password (blocking: argon2 takes tens of milliseconds; an unknown
//!   user costs the same as a wrong password).
//! - [`Users::add`], [`Users::set_password`], [`Users::set_role`],
//!   [`Users::remove`] and [`Users::save`] edit it (`alba user`), with the
//!   password policy of [`check_password`].
//! - [`Backoff`] counts failed logins per key for the login routes.
//!
//! The file's reading and form checks live in `alba_settings::users` (so
//! `alba check` reports them with the project); hashing and verifying here.

mod backoff;
mod policy;

pub use alba_settings::users::{MAX_NAME_LEN, Role, USERS_FILE, User, check_user_name};
pub use backoff::Backoff;
pub use policy::{MAX_PASSWORD_BYTES, MIN_PASSWORD_CHARS, PasswordRefused, check_password};

use alba_diag::{FileId, Span};
use argon2::password_hash::{PasswordHash, PasswordHasher, PasswordVerifier, SaltString};
use std::path::Path;

/// Why the user store refused an operation.
#[derive(Debug, thiserror::Error)]
pub enum UsersError {
    /// users.toml (or `[opcua.users]`) has errors: the rendered diagnostics,
    /// with places. A store that cannot be read is never taken as empty.
    #[error("{0}")]
    Invalid(String),
    #[error("`{name}` is not a valid user name: {why}")]
    BadName {
        name: String,
        why: alba_settings::users::UserNameError,
    },
    #[error("user `{0}` already exists (change the password with `alba user passwd`)")]
    Exists(String),
    #[error(transparent)]
    Password(#[from] PasswordRefused),
    #[error("cannot hash the password: {0}")]
    Hash(String),
    #[error("there is no user `{0}`")]
    NoSuchUser(String),
    #[error("{} keeps changing: try again", .0.display())]
    KeepsChanging(std::path::PathBuf),
    /// users.toml could not be written.
    #[error(transparent)]
    Save(#[from] alba_settings::users::SaveError),
}

/// The argon2id hash (PHC string) of `password` with argon2's default
/// parameters (19 MiB, 2 passes, 1 lane) and a random salt.
pub fn hash_password(password: &str) -> Result<String, UsersError> {
    let salt = SaltString::generate(&mut argon2::password_hash::rand_core::OsRng);
    argon2::Argon2::default()
        .hash_password(password.as_bytes(), &salt)
        .map(|h| h.to_string())
        .map_err(|e| UsersError::Hash(e.to_string()))
}

/// Whether `hash` (a PHC string) is the hash of `password`. Blocking.
pub fn verify_password(hash: &str, password: &str) -> bool {
    match PasswordHash::new(hash) {
        Ok(h) => argon2::Argon2::default()
            .verify_password(password.as_bytes(), &h)
            .is_ok(),
        Err(_) => false,
    }
}

/// The hash verified for an unknown user name, so that it costs what a
/// wrong password costs: made like every other (default parameters) from
/// a random password nobody kept.
pub const DUMMY_HASH: &str =
    "$argon2id$v=19$m=19456,t=2,p=1$NFKr9uyn2z03ebSDCIPxOw$pxOCx10hJOXjcRnbC2VAKpFAMhuqY3gXtTcsB80tyOo";

/// A project's user store.
#[derive(Debug, Clone, Default)]
pub struct Users {
    users: Vec<User>,
    warnings: Vec<String>,
}

impl Users {
    /// Reads the store of the project in `dir`: `users.toml` (none: an empty
    /// store) merged with the deprecated `[opcua.users]` of alba.toml. An
    /// invalid users.toml is an error (the rendered diagnostics, with
    /// places): a store that cannot be read is never taken as empty.
    pub fn load(dir: &Path) -> Result<Users, UsersError> {
        let l = alba_settings::users::load_users(dir);
        if !l.errors.is_empty() {
            return Err(UsersError::Invalid(alba_diag::render_all(&l.errors, &l.files)));
        }
        let warnings = l.warnings.iter().map(|w| w.render_warning(&l.files)).collect();
        Ok(Users {
            users: l.users,
            warnings,
        })
    }

    /// A store of these users (tests, tools).
    pub fn from_users(users: Vec<User>) -> Users {
        Users {
            users,
            warnings: Vec::new(),
        }
    }

    /// Rendered warnings of loading (the `[opcua.users]` deprecation).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    pub fn is_empty(&self) -> bool {
        self.users.is_empty()
    }

    pub fn len(&self) -> usize {
        self.users.len()
    }

    /// The users, in the store's order (users.toml's, then `[opcua.users]`).
    pub fn users(&self) -> &[User] {
        &self.users
    }

    /// Names and roles, sorted by name (never the hashes).
    pub fn list(&self) -> Vec<(String, Role)> {
        let mut out: Vec<_> = self.users.iter().map(|u| (u.name.clone(), u.role)).collect();
        out.sort();
        out
    }

    /// The role of user `name`, if there is such a user.
    pub fn role(&self, name: &str) -> Option<Role> {
        self.get(name).map(|u| u.role)
    }

    pub fn get(&self, name: &str) -> Option<&User> {
        self.users.iter().find(|u| u.name == name)
    }

    /// The role of `name` when `password` is theirs. Blocking (argon2, tens of
    /// milliseconds: call it from `spawn_blocking` in async code). An unknown
    /// name is checked against [`DUMMY_HASH`], so it costs the same as a
    /// wrong password.
    pub fn verify(&self, name: &str, password: &str) -> Option<Role> {
        match self.get(name) {
            Some(u) => verify_password(&u.hash, password).then_some(u.role),
            None => {
                let _ = verify_password(DUMMY_HASH, password);
                None
            }
        }
    }

    /// Adds user `name` (an error if there is one, if the name is not valid
    /// or the password fails the policy).
    pub fn add(&mut self, name: &str, role: Role, password: &str) -> Result<(), UsersError> {
        check_user_name(name).map_err(|why| UsersError::BadName {
            name: name.to_string(),
            why,
        })?;
        if self.get(name).is_some() {
            return Err(UsersError::Exists(name.to_string()));
        }
        check_password(name, password)?;
        let hash = hash_password(password)?;
        self.users.push(User {
            name: name.to_string(),
            role,
            hash,
            span: Span::new(FileId(0), 0..0),
            from_opcua: false,
        });
        Ok(())
    }

    fn get_mut(&mut self, name: &str) -> Result<&mut User, UsersError> {
        self.users
            .iter_mut()
            .find(|u| u.name == name)
            .ok_or_else(|| UsersError::NoSuchUser(name.to_string()))
    }

    /// Sets the password of user `name` (policy checked).
    pub fn set_password(&mut self, name: &str, password: &str) -> Result<(), UsersError> {
        self.get_mut(name)?;
        check_password(name, password)?;
        let hash = hash_password(password)?;
        self.get_mut(name)?.hash = hash;
        Ok(())
    }

    /// Sets the role of user `name`.
    pub fn set_role(&mut self, name: &str, role: Role) -> Result<(), UsersError> {
        self.get_mut(name)?.role = role;
        Ok(())
    }

    /// Removes user `name`.
    pub fn remove(&mut self, name: &str) -> Result<User, UsersError> {
        let i = self
            .users
            .iter()
            .position(|u| u.name == name)
            .ok_or_else(|| UsersError::NoSuchUser(name.to_string()))?;
        Ok(self.users.remove(i))
    }

    /// Whether some users come from the deprecated `[opcua.users]`.
    pub fn has_opcua_users(&self) -> bool {
        self.users.iter().any(|u| u.from_opcua)
    }

    /// Loads the store of `dir`, applies `change` and saves it, unless
    /// users.toml changed meanwhile (another `alba user`, an admin's edit):
    /// then it starts again from the new file, a few times, so that two
    /// concurrent edits do not lose one. `change`'s value is returned; its
    /// error may be the caller's own (any type a [`UsersError`] converts to).
    pub fn edit<T, E: From<UsersError>>(
        dir: &Path,
        mut change: impl FnMut(&mut Users) -> Result<T, E>,
    ) -> Result<T, E> {
        let path = dir.join(USERS_FILE);
        let read = || std::fs::read(&path).ok();
        for _ in 0..5 {
            let before = read();
            let mut users = Users::load(dir)?;
            let out = change(&mut users)?;
            if read() != before {
                continue;
            }
            users.save(dir)?;
            return Ok(out);
        }
        Err(UsersError::KeepsChanging(path).into())
    }

    /// Writes the store as `dir`/users.toml (atomically, mode 0600 on Unix).
    /// Users of `[opcua.users]` are written too: saving migrates them (alba.toml
    /// is left as it is; its entries are then shadowed by users.toml's).
    pub fn save(&self, dir: &Path) -> Result<(), UsersError> {
        alba_settings::users::save_users(dir, &self.users).map_err(UsersError::Save)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("alba-auth-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn dummy_hash_is_a_default_cost_argon2id_hash() {
        let h = PasswordHash::new(DUMMY_HASH).unwrap();
        let mine = hash_password("x").unwrap();
        let m = PasswordHash::new(&mine).unwrap();
        assert_eq!(h.algorithm, m.algorithm);
        assert_eq!(h.params, m.params, "same cost as a real hash");
        assert!(alba_settings::check_password_hash(DUMMY_HASH).is_ok());
        assert!(!verify_password(DUMMY_HASH, ""));
    }

    #[test]
    fn hashes_verify_and_differ() {
        let a = hash_password("correct horse").unwrap();
        let b = hash_password("correct horse").unwrap();
        assert_ne!(a, b, "salted");
        assert!(a.starts_with("$argon2id$"));
        assert!(verify_password(&a, "correct horse"));
        assert!(!verify_password(&a, "correct horse "));
        assert!(!verify_password("not a hash", "x"));
    }

    /// An unknown name costs what a wrong password costs (one argon2
    /// verification at the same parameters): medians of alternated runs.
    #[test]
    fn unknown_user_and_wrong_password_cost_the_same() {
        let u = Users::from_users(vec![User {
            name: "alice".into(),
            role: Role::Admin,
            hash: hash_password("correct horse battery").unwrap(),
            span: Span::new(FileId(0), 0..0),
            from_opcua: false,
        }]);
        let time = |name: &str| {
            let t = std::time::Instant::now();
            assert_eq!(u.verify(name, "wrong guess at it"), None);
            t.elapsed()
        };
        let (mut known, mut unknown) = (Vec::new(), Vec::new());
        for _ in 0..7 {
            known.push(time("alice"));
            unknown.push(time("mallory"));
        }
        known.sort();
        unknown.sort();
        let ratio = unknown[3].as_secs_f64() / known[3].as_secs_f64();
        assert!(
            (0.5..2.0).contains(&ratio),
            "unknown {:?} vs wrong {:?}",
            unknown[3],
            known[3]
        );
    }

    #[test]
    fn a_missing_file_is_an_empty_store_and_a_bad_one_an_error() {
        let d = tmp("empty");
        let u = Users::load(&d).unwrap();
        assert!(u.is_empty());
        assert_eq!(u.verify("anyone", "anything"), None);
        std::fs::write(d.join(USERS_FILE), "[users.a]\nrole = \"king\"\npassword = \"x\"\n").unwrap();
        let err = Users::load(&d).unwrap_err().to_string();
        assert!(err.contains("E107") && err.contains("users.toml:2:8"), "{err}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn edit_save_load_verify() {
        let d = tmp("edit");
        let mut u = Users::load(&d).unwrap();
        u.add("alice", Role::Engineer, "correct horse battery").unwrap();
        u.add("bob", Role::Viewer, "staple of the plant").unwrap();
        assert!(matches!(
            u.add("alice", Role::Admin, "another long one"),
            Err(UsersError::Exists(n)) if n == "alice"
        ));
        assert!(
            u.add("carol", Role::Admin, "password123")
                .unwrap_err()
                .to_string()
                .contains("common")
        );
        assert!(u.add("bad name", Role::Admin, "whatever it is 1").is_err());
        u.save(&d).unwrap();
        let text = std::fs::read_to_string(d.join(USERS_FILE)).unwrap();
        assert!(!text.contains("correct horse"), "no plain text");
        let mut u = Users::load(&d).unwrap();
        assert_eq!(
            u.list(),
            [("alice".to_string(), Role::Engineer), ("bob".to_string(), Role::Viewer)]
        );
        assert_eq!(u.verify("alice", "correct horse battery"), Some(Role::Engineer));
        assert_eq!(u.verify("alice", "staple of the plant"), None);
        assert_eq!(u.verify("nobody", "correct horse battery"), None);
        u.set_password("bob", "a new long password").unwrap();
        assert!(
            u.set_password("bob", "Password123")
                .unwrap_err()
                .to_string()
                .contains("common")
        );
        assert!(
            u.set_password("zed", "a new long password")
                .unwrap_err()
                .to_string()
                .contains("no user")
        );
        u.set_role("bob", Role::Operator).unwrap();
        u.remove("alice").unwrap();
        assert!(u.remove("alice").is_err());
        u.save(&d).unwrap();
        let u = Users::load(&d).unwrap();
        assert_eq!(u.list(), [("bob".to_string(), Role::Operator)]);
        assert_eq!(u.verify("bob", "a new long password"), Some(Role::Operator));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_edit_starts_again_when_the_file_changed_meanwhile() {
        let d = tmp("race");
        let mut runs = 0;
        Users::edit(&d, |u| {
            runs += 1;
            if runs == 1 {
                // Another process adds a user while this edit is under way.
                Users::edit(&d, |other| other.add("first", Role::Viewer, "a long secret one"))?;
            }
            u.add("second", Role::Admin, "another long secret")
        })
        .unwrap();
        assert_eq!(runs, 2);
        let names: Vec<_> = Users::load(&d).unwrap().list().into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, ["first", "second"], "neither edit lost");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn opcua_users_are_merged_with_a_warning() {
        let d = tmp("opcua");
        let h = hash_password("old opcua pw").unwrap();
        std::fs::write(
            d.join("alba.toml"),
            format!("name = \"t\"\nprograms = [\"main.lad\"]\n[opcua]\nread_only = [\"ro\"]\n[opcua.users]\nop = \"{h}\"\nro = \"{h}\"\n"),
        )
        .unwrap();
        let u = Users::load(&d).unwrap();
        assert_eq!(u.verify("op", "old opcua pw"), Some(Role::Operator));
        assert_eq!(u.verify("ro", "old opcua pw"), Some(Role::Viewer));
        assert_eq!(u.warnings().len(), 1);
        assert!(u.warnings()[0].contains("warning[E109]"), "{}", u.warnings()[0]);
        assert!(u.has_opcua_users());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
