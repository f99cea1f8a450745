//! The password policy of `alba user add|passwd`: long enough, not a
//! common password, not the user name.

use std::collections::HashSet;
use std::sync::OnceLock;

/// The shortest password accepted, in characters.
pub const MIN_PASSWORD_CHARS: usize = 10;
/// The longest password accepted, in bytes (argon2 takes any length; this
/// bounds the work one request can ask for).
pub const MAX_PASSWORD_BYTES: usize = 1024;

/// The refused passwords, lowercase (data/common-passwords.txt).
fn common() -> &'static HashSet<String> {
    static LIST: OnceLock<HashSet<String>> = OnceLock::new();
    LIST.get_or_init(|| {
        include_str!("../data/common-passwords.txt")
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .map(str::to_lowercase)
            .collect()
    })
}

/// Why a password is refused ([`check_password`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PasswordRefused {
    #[error("the password is too short: {chars} characters, at least {MIN_PASSWORD_CHARS} are needed")]
    TooShort { chars: usize },
    #[error("the password is too long: at most {MAX_PASSWORD_BYTES} bytes")]
    TooLong,
    #[error("the password has a control character")]
    ControlCharacter,
    #[error("the password is one of the most common passwords: choose another")]
    Common,
    #[error("the password is the user name")]
    TheUserName,
    #[error("the password repeats one character")]
    OneCharacter,
}

/// Whether `password` may be the password of user `name`; the error says
/// why not.
pub fn check_password(name: &str, password: &str) -> Result<(), PasswordRefused> {
    let chars = password.chars().count();
    if chars < MIN_PASSWORD_CHARS {
        return Err(PasswordRefused::TooShort { chars });
    }
    if password.len() > MAX_PASSWORD_BYTES {
        return Err(PasswordRefused::TooLong);
    }
    if password.chars().any(char::is_control) {
        return Err(PasswordRefused::ControlCharacter);
    }
    let lower = password.to_lowercase();
    if common().contains(&lower) {
        return Err(PasswordRefused::Common);
    }
    // The name itself (any case); a longer password that contains it is
    // left to the length rule.
    if lower == name.to_lowercase() {
        return Err(PasswordRefused::TheUserName);
    }
    let mut it = password.chars();
    if let Some(first) = it.next()
        && it.all(|c| c == first)
    {
        return Err(PasswordRefused::OneCharacter);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_short_common_and_own_name() {
        assert!(check_password("alice", "correct horse battery").is_ok());
        let why = |n: &str, p: &str| check_password(n, p).unwrap_err().to_string();
        assert!(why("alice", "short1").contains("too short"));
        assert_eq!(
            check_password("alice", "short1"),
            Err(PasswordRefused::TooShort { chars: 6 })
        );
        assert!(why("alice", "123456789").contains("too short"));
        assert!(why("alice", "Password123").contains("most common"));
        assert!(why("alice", "QWERTYUIOP").contains("most common"));
        assert!(why("maintainer", "Maintainer").contains("user name"));
        assert!(why("bob", "zzzzzzzzzzzz").contains("repeats"));
        assert!(why("bobbybobby", "BobbyBobby").contains("user name"));
        assert!(
            check_password("operator", "operator on duty").is_ok(),
            "the name may be part of one"
        );
        assert!(why("bob", &"x1".repeat(600)).contains("too long"));
        assert!(why("bob", "tab\there-and-there").contains("control"));
        // Ten characters of any script count as ten.
        assert!(check_password("bob", "ĳĳĳĳĳĳĳĳĳé").is_ok());
    }

    #[test]
    fn the_list_is_loaded_and_needs_the_length_rule_less() {
        let list = common();
        assert!(list.len() >= 150, "{}", list.len());
        assert!(list.contains("password123") && list.contains("1q2w3e4r5t"));
        assert!(!list.iter().any(|p| p.starts_with('#')));
    }
}
