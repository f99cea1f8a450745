//! `[opcua]`: the OPC UA server of `alba run` and its users.

use super::setting::listen;
use alba_diag::{Code, Diagnostic, FileId, Span};
use password_hash::PasswordHash;
use serde::Deserialize;
use toml::Spanned;

/// `[opcua]`: the OPC UA server (docs/protocols.md).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Opcua {
    /// Where to listen (`None`: only with `alba run --opcua`).
    pub listen: Option<std::net::SocketAddr>,
    /// Where `listen` is written.
    pub listen_span: Option<Span>,
    /// `[opcua.users]`: who may log in with a user name and password, each
    /// with the argon2 hash (PHC string) of the password; never the password.
    pub users: Vec<OpcuaUser>,
}

/// One entry of `[opcua.users]`: `operator = "$argon2id$v=19$..."`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpcuaUser {
    pub name: String,
    /// The password's argon2 hash as a PHC string (checked to parse).
    pub hash: String,
    pub span: Span,
    /// May write tags (what the HTTP API lets anyone write); `false` for
    /// the names listed in `[opcua] read_only`.
    pub write: bool,
}

/// Checks a `[opcua.users]` entry's value is an argon2 PHC hash; the error
/// says what is wrong (a plain-text password is called one).
///
/// Only the form is checked here, with the light `password-hash` crate (the
/// PHC string format); `argon2` itself, which verifies passwords, is a
/// dependency of the OPC UA server alone.
pub fn check_password_hash(text: &str) -> Result<(), HashError> {
    if !text.starts_with('$') {
        return Err(HashError::PlainText);
    }
    let hash = PasswordHash::new(text).map_err(|e| HashError::Invalid {
        text: text.to_string(),
        why: e.to_string(),
    })?;
    match hash.algorithm.as_str() {
        "argon2id" | "argon2i" | "argon2d" => {}
        other => return Err(HashError::Algorithm(other.to_string())),
    }
    if hash.hash.is_none() || hash.salt.is_none() {
        return Err(HashError::Incomplete(text.to_string()));
    }
    argon2_params(&hash).map_err(|e| HashError::Parameters {
        text: text.to_string(),
        why: e.to_string(),
    })?;
    Ok(())
}

/// Why a text is not an argon2 password hash ([`check_password_hash`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HashError {
    #[error("this is not a password hash: [opcua.users] holds argon2 hashes, never plain-text passwords")]
    PlainText,
    #[error("`{text}` is not a valid password hash ({why})")]
    Invalid { text: String, why: String },
    #[error("`{0}` hashes are not accepted: use argon2 (`$argon2id$...`)")]
    Algorithm(String),
    #[error("`{0}` has no salt or no hash output")]
    Incomplete(String),
    #[error("`{text}` has bad argon2 parameters ({why})")]
    Parameters { text: String, why: String },
}

/// The parameter checks of `argon2::Params::try_from(&PasswordHash)`
/// (argon2 0.5), with the same errors: the server's verifier accepts
/// exactly the hashes that pass.
fn argon2_params(hash: &PasswordHash) -> Result<(), password_hash::Error> {
    use password_hash::errors::InvalidValue;
    // argon2's defaults for parameters a hash leaves out.
    let (mut m, mut t, mut p) = (19 * 1024_u32, 2_u32, 1_u32);
    for (ident, value) in hash.params.iter() {
        match ident.as_str() {
            "m" => m = value.decimal()?,
            "t" => t = value.decimal()?,
            "p" => p = value.decimal()?,
            // At most 8 bytes of key id and 32 of associated data.
            "keyid" => drop(value.b64_decode(&mut [0; 8])?),
            "data" => drop(value.b64_decode(&mut [0; 32])?),
            _ => return Err(password_hash::Error::ParamNameInvalid),
        }
    }
    // Memory: at least 8 KiB, and 8 KiB per lane.
    if m < 8 || u64::from(m) < u64::from(p) * 8 || t < 1 || p < 1 {
        return Err(InvalidValue::TooShort.param_error());
    }
    if p > 0xFF_FFFF {
        return Err(InvalidValue::TooLong.param_error());
    }
    let len = hash.hash.map_or(0, |h| h.len());
    if len < 4 {
        return Err(password_hash::Error::OutputSize {
            provided: std::cmp::Ordering::Less,
            expected: 4,
        });
    }
    Ok(())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOpcua {
    listen: Option<Spanned<String>>,
    #[serde(default)]
    users: std::collections::BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    read_only: Vec<Spanned<String>>,
}

/// Validates `[opcua]`: user names and password hashes. (That a listen
/// address beyond loopback has users is checked by `alba_load::load`, which
/// knows users.toml too.)
pub(super) fn opcua(o: RawOpcua, file: FileId, diags: &mut Vec<Diagnostic>) -> Opcua {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let addr = o.listen.as_ref().and_then(|l| listen(l, file, diags));
    let mut users = Vec::new();
    let mut entries: Vec<_> = o.users.into_iter().collect();
    entries.sort_by_key(|(name, _)| name.span().start);
    for (name, hash) in entries {
        let n = name.get_ref();
        if n.is_empty() || n.chars().any(|c| c.is_whitespace() || c.is_control()) {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("`{n}` is not a user name"),
                sp(name.span()),
                "in [opcua.users]: a user name is not empty and has no spaces",
            ));
            continue;
        }
        match check_password_hash(hash.get_ref()) {
            Ok(()) => users.push(OpcuaUser {
                name: n.clone(),
                hash: hash.get_ref().clone(),
                span: sp(name.span()),
                write: true,
            }),
            Err(msg) => diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    msg.to_string(),
                    sp(hash.span()),
                    format!("the password hash of `{n}`"),
                )
                .with_help("make one with `alba hash-password` (it reads the password from stdin)"),
            ),
        }
    }
    for r in &o.read_only {
        match users.iter_mut().find(|u| u.name == *r.get_ref()) {
            Some(u) => u.write = false,
            None => diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("`{}` is not in [opcua.users]", r.get_ref()),
                sp(r.span()),
                "read_only lists user names of [opcua.users]",
            )),
        }
    }
    let listen_span = o.listen.as_ref().map(|l| sp(l.span()));
    Opcua {
        listen: addr,
        listen_span,
        users,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The form check reads the parameters as argon2 does, with the same
    /// verdict and error.
    #[test]
    fn parameter_checks_match_argon2() {
        let params = [
            "m=8,t=1,p=1",
            "m=7,t=1,p=1",
            "m=16,t=1,p=2",
            "m=16,t=1,p=3",
            "m=8,t=0,p=1",
            "m=8,t=1,p=0",
            "m=4294967295,t=1,p=16777215",
            "m=4294967295,t=1,p=16777216",
            "t=1",
            "p=4",
            "m=8,t=1,p=1,keyid=AAAAAAAAAAA",
            "m=8,t=1,p=1,keyid=AAAAAAAAAAAA",
            "m=8,t=1,p=1,data=AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA",
            "m=8,t=1,p=1,data=AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA",
            "m=8,t=1,p=1,x=1",
            "m=08,t=1,p=1",
            "m=8,t=1,p=99999999999",
        ];
        let mut checked = 0;
        for p in params {
            for out in ["AAAAAAAAAAAAAA", "AAAAAAAAAAAAAAAAAAAAAA"] {
                let text = format!("$argon2id$v=19${p}$YWxiYS10ZXN0LXNhbHQ${out}");
                let Ok(hash) = PasswordHash::new(&text) else { continue };
                let theirs = argon2::Params::try_from(&hash).map(|_| ());
                assert_eq!(argon2_params(&hash), theirs, "{text}");
                checked += 1;
            }
        }
        assert!(checked >= 30, "only {checked} hashes parsed");
    }
}
