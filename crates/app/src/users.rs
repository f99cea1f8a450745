//! The users of the HTTP API (docs/security.md, "Sessions and roles"):
//! the project's store, and no open door — without users, the studio and
//! its API are served on loopback only.

use alba_server::auth::{Auth, Limits};
use alba_settings::Settings;
use std::net::SocketAddr;
use std::path::Path;
use std::sync::Arc;

/// The API's users (as loaded from the project in `dir`) and session
/// limits, served at `addr`. Without users a non-loopback `addr` is refused: anyone who
/// could reach it would have full rights.
pub(crate) fn auth(
    dir: &Path,
    users: Arc<alba_auth::Users>,
    config: Option<&Settings>,
    addr: SocketAddr,
) -> Result<Auth, String> {
    if users.is_empty() && !addr.ip().is_loopback() {
        return Err(format!(
            "refusing to serve the studio on {addr}: this project has no users, so anyone who can reach that \
             address would have full control of the PLC. Add users first (`alba user add {} <name> --role admin`), \
             or serve on loopback (--http 127.0.0.1:{})",
            dir.display(),
            addr.port()
        ));
    }
    let limits = config.map_or_else(Limits::default, |c| Limits::from_config(&c.session));
    Ok(Auth::new(users, limits).reloading_from(dir))
}
