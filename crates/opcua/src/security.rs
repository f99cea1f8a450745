//! Who may connect to the OPC UA server, and how (docs/protocols.md,
//! "OPC UA security").
//!
//! - Bound to a loopback address: endpoint `None` with anonymous access,
//!   plus Basic256Sha256 (Sign, SignAndEncrypt) with user name and password.
//!   Client certificates are trusted on first use (only this machine can
//!   connect).
//! - Bound anywhere else: only Basic256Sha256 (Sign, SignAndEncrypt) with
//!   user name and password; no anonymous session on any endpoint. An
//!   unknown client certificate is refused and stored in `pki/rejected/`;
//!   moving it to `pki/trusted/` trusts it.
//!
//! Passwords are checked against the project's user store (`alba_auth::Users`:
//! users.toml, and the deprecated `[opcua.users]`). Viewers get no write
//! access; operators and up keep each node's own access level.

use alba_auth::{Role, Users};
use async_trait::async_trait;
use opcua::crypto::SecurityPolicy;
use opcua::nodes::AccessLevel;
use opcua::server::ServerEndpoint;
use opcua::server::authenticator::{
    AuthManager, Password, UserToken, user_pass_security_policy_id, user_pass_security_policy_uri,
};
use opcua::types::{Error, MessageSecurityMode, NodeId, StatusCode, UAString, UserTokenPolicy, UserTokenType};
use std::net::IpAddr;
use std::sync::Arc;

pub use alba_auth::{hash_password, verify_password};

/// Whether a server bound to `ip` may offer security None and anonymous
/// access (and trust client certificates on first use).
pub fn is_local(ip: IpAddr) -> bool {
    ip.is_loopback()
}

/// The endpoints of a server bound to `ip`: (id, endpoint).
pub fn endpoints(ip: IpAddr) -> Vec<(&'static str, ServerEndpoint)> {
    let mut out = Vec::new();
    if is_local(ip) {
        out.push((
            "none",
            ServerEndpoint::new_none("/", &[opcua::server::ANONYMOUS_USER_TOKEN_ID.to_string()]),
        ));
    }
    // (async-opcua marks Basic256Sha256 deprecated; it is the policy SPEC §9
    // names and every client supports.)
    let secure = |mode| ServerEndpoint::new("/", SecurityPolicy::Basic256Sha256, mode, &[]);
    out.push(("basic256sha256_sign", secure(MessageSecurityMode::Sign)));
    out.push((
        "basic256sha256_sign_encrypt",
        secure(MessageSecurityMode::SignAndEncrypt),
    ));
    out
}

/// The server's [`AuthManager`]: anonymous only on a loopback server's
/// `None` endpoint, user names and passwords (argon2) on the secure ones.
pub struct Auth {
    local: bool,
    users: Arc<Users>,
    /// One argon2 check at a time: a flood of logins costs one core at
    /// most, never both (the engine thread keeps its own).
    checking: tokio::sync::Semaphore,
}

impl Auth {
    pub fn new(ip: IpAddr, users: Arc<Users>) -> Auth {
        Auth {
            local: is_local(ip),
            users,
            checking: tokio::sync::Semaphore::new(1),
        }
    }

    /// Whether a session of `token` may write (what the node allows).
    fn may_write(&self, token: &UserToken) -> bool {
        if token.is_anonymous() {
            return self.users.is_empty();
        }
        self.users.role(&token.0).is_some_and(|r| r >= Role::Operator)
    }

    fn anonymous_allowed(&self, endpoint: &ServerEndpoint) -> bool {
        self.local && endpoint.security_policy() == SecurityPolicy::None
    }

    fn passwords_allowed(endpoint: &ServerEndpoint) -> bool {
        endpoint.security_policy() != SecurityPolicy::None
    }
}

fn rejected(msg: impl Into<String>) -> Error {
    Error::new(StatusCode::BadIdentityTokenRejected, msg.into())
}

#[async_trait]
impl AuthManager for Auth {
    async fn authenticate_anonymous_token(&self, endpoint: &ServerEndpoint) -> Result<(), Error> {
        if self.anonymous_allowed(endpoint) {
            Ok(())
        } else {
            Err(rejected(
                "anonymous access is refused: log in with a user name and password",
            ))
        }
    }

    async fn authenticate_username_identity_token(
        &self,
        endpoint: &ServerEndpoint,
        username: &str,
        password: &Password,
    ) -> Result<UserToken, Error> {
        if !Auth::passwords_allowed(endpoint) {
            return Err(rejected(
                "user names and passwords are accepted on Basic256Sha256 endpoints only",
            ));
        }
        let _turn = self
            .checking
            .acquire()
            .await
            .map_err(|_| rejected("the server is stopping"))?;
        let users = self.users.clone();
        let name = username.to_string();
        let pw = password.get().to_string();
        // argon2 takes tens of milliseconds of CPU: off the async workers. An
        // unknown name costs the same as a wrong password (`Users::verify`).
        let role = tokio::task::spawn_blocking(move || users.verify(&name, &pw))
            .await
            .unwrap_or(None);
        if role.is_some() {
            Ok(UserToken(username.to_string()))
        } else {
            eprintln!("OPC UA: login refused for user `{username}`");
            Err(rejected(format!("wrong user name or password for `{username}`")))
        }
    }

    /// A viewer's sessions see (and get) no write access; operators and up
    /// keep the node's own access level (inputs, status members and system
    /// tags are read-only for all, as in the HTTP API). Anonymous sessions
    /// (loopback only) keep it while the project has no users, as the HTTP
    /// API does; once it has users they are viewers.
    fn effective_user_access_level(&self, token: &UserToken, level: AccessLevel, _node: &NodeId) -> AccessLevel {
        if self.may_write(token) {
            level
        } else {
            level - AccessLevel::CURRENT_WRITE
        }
    }

    fn user_token_policies(&self, endpoint: &ServerEndpoint) -> Vec<UserTokenPolicy> {
        let mut out = Vec::new();
        if self.anonymous_allowed(endpoint) {
            out.push(UserTokenPolicy {
                policy_id: UAString::from("anonymous"),
                token_type: UserTokenType::Anonymous,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: UAString::null(),
            });
        }
        if Auth::passwords_allowed(endpoint) {
            out.push(UserTokenPolicy {
                policy_id: user_pass_security_policy_id(endpoint),
                token_type: UserTokenType::UserName,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: user_pass_security_policy_uri(endpoint),
            });
        }
        out
    }
}

/// Makes the PKI folder's `private/` readable by its owner only (the
/// server's private key lives there): before the server creates the key,
/// and again after for a key made by an older version.
pub fn protect_private_key(pki_dir: &std::path::Path) -> Result<(), String> {
    let private = pki_dir.join("private");
    std::fs::create_dir_all(&private).map_err(|e| format!("cannot create {}: {e}", private.display()))?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let set = |p: &std::path::Path, mode: u32| {
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode))
                .map_err(|e| format!("cannot restrict {}: {e}", p.display()))
        };
        set(&private, 0o700)?;
        let key = private.join("private.pem");
        if key.exists() {
            set(&key, 0o600)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_verify_and_differ() {
        let a = hash_password("correct horse").unwrap();
        let b = hash_password("correct horse").unwrap();
        assert_ne!(a, b, "salted");
        assert!(a.starts_with("$argon2id$"));
        assert!(alba_settings::check_password_hash(&a).is_ok());
        assert!(verify_password(&a, "correct horse"));
        assert!(!verify_password(&a, "correct horse "));
        assert!(!verify_password("not a hash", "x"));
    }

    #[test]
    fn endpoints_by_bind_address() {
        let ids = |ip: &str| -> Vec<(&str, SecurityPolicy, String)> {
            endpoints(ip.parse().unwrap())
                .into_iter()
                .map(|(id, e)| (id, e.security_policy(), e.security_mode.clone()))
                .collect()
        };
        let local = ids("127.0.0.2");
        assert_eq!(local.len(), 3);
        assert_eq!(local[0].1, SecurityPolicy::None);
        let wide = ids("0.0.0.0");
        assert_eq!(wide.len(), 2);
        assert!(wide.iter().all(|e| e.1 == SecurityPolicy::Basic256Sha256));
        assert_eq!(
            wide.iter().map(|e| e.2.as_str()).collect::<Vec<_>>(),
            ["Sign", "SignAndEncrypt"]
        );
        assert_eq!(ids("::1").len(), 3);
        assert_eq!(ids("192.168.1.5").len(), 2);
    }

    #[test]
    fn anonymous_only_on_a_loopback_none_endpoint() {
        let rt = tokio::runtime::Builder::new_multi_thread().build().unwrap();
        let h = hash_password("pw").unwrap();
        let user = |name: &str, role| alba_auth::User {
            name: name.into(),
            role,
            hash: h.clone(),
            span: alba_diag::Span::new(alba_diag::FileId(0), 0..0),
            from_opcua: false,
        };
        let users = Arc::new(Users::from_users(vec![user("op", Role::Operator)]));
        for (ip, none_anonymous) in [("127.0.0.1", true), ("0.0.0.0", false), ("10.0.0.1", false)] {
            let ip: IpAddr = ip.parse().unwrap();
            let auth = Auth::new(ip, users.clone());
            for (_, e) in endpoints(ip) {
                let anon = rt.block_on(auth.authenticate_anonymous_token(&e)).is_ok();
                let none = e.security_policy() == SecurityPolicy::None;
                assert_eq!(anon, none && none_anonymous, "{ip} {}", e.security_policy);
                let pols = auth.user_token_policies(&e);
                assert_eq!(pols.iter().any(|p| p.token_type == UserTokenType::Anonymous), anon);
                assert_eq!(pols.iter().any(|p| p.token_type == UserTokenType::UserName), !none);
                let login = |u: &str, p: &str| {
                    rt.block_on(auth.authenticate_username_identity_token(&e, u, &Password::new(p.into())))
                };
                assert_eq!(login("op", "pw").is_ok(), !none, "{ip}");
                assert!(login("op", "wrong").is_err());
                assert!(login("nobody", "pw").is_err());
            }
            let rw = AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE;
            let n = NodeId::new(1, "Speed");
            assert_eq!(
                auth.effective_user_access_level(&UserToken("op".into()), rw, &n).bits(),
                rw.bits()
            );
            // Viewers write nothing; engineers and admins write as operators.
            let staff = Arc::new(Users::from_users(vec![
                user("op", Role::Viewer),
                user("eng", Role::Engineer),
                user("adm", Role::Admin),
            ]));
            let ro = Auth::new(ip, staff);
            let level = |a: &Auth, who: &str| a.effective_user_access_level(&UserToken(who.into()), rw, &n).bits();
            assert_eq!(level(&ro, "op"), AccessLevel::CURRENT_READ.bits());
            assert_eq!(level(&ro, "eng"), rw.bits());
            assert_eq!(level(&ro, "adm"), rw.bits());
            // A token of a user no longer in the store writes nothing.
            assert_eq!(level(&ro, "gone"), AccessLevel::CURRENT_READ.bits());
            // Anonymous (loopback None) writes only while there are no users.
            let anon = opcua::server::ANONYMOUS_USER_TOKEN_ID;
            assert_eq!(level(&ro, anon), AccessLevel::CURRENT_READ.bits());
            let open = Auth::new(ip, Arc::new(Users::default()));
            assert_eq!(level(&open, anon), rw.bits());
        }
    }

    #[cfg(unix)]
    #[test]
    fn the_private_key_is_the_owners_only() {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("alba-pki-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("private")).unwrap();
        std::fs::write(dir.join("private/private.pem"), "key").unwrap();
        protect_private_key(&dir).unwrap();
        let mode = |p: &str| std::fs::metadata(dir.join(p)).unwrap().permissions().mode() & 0o777;
        assert_eq!((mode("private"), mode("private/private.pem")), (0o700, 0o600));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
