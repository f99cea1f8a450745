//! The Modbus TCP server of `alba run` (OpenPLC v3 address map,
//! docs/protocols.md): on `--modbus`, else where `[modbus] listen` says;
//! beyond loopback only with `[modbus] allow` (docs/security.md, "Modbus").

use crate::{Service, Started};

pub(crate) async fn start(s: &Service<'_>, addr: Option<std::net::SocketAddr>) -> Result<Started, String> {
    let cfg = s.config.and_then(|c| c.modbus.as_ref());
    let Some(addr) = addr.or(cfg.and_then(|m| m.listen)) else {
        return Ok(Started::Off);
    };
    // Modbus has no authentication: refused before anything listens.
    alba_modbus::check_listen(addr, cfg.and_then(|m| m.allow.as_deref())).map_err(|e| e.to_string())?;
    let l = tokio::net::TcpListener::bind(addr)
        .await
        .map_err(|e| format!("cannot listen for Modbus TCP on {addr}: {e}"))?;
    let bound = l.local_addr().map_err(|e| e.to_string())?;
    let mut settings = cfg.map(alba_modbus::Settings::from).unwrap_or_default();
    settings.tags = s.modbus_tags.to_vec();
    let server = alba_modbus::Server::new(s.state.control.clone(), settings);
    // The server follows online edits itself: it rebuilds its map when the
    // runtime's program changes (seen in its snapshots).
    tokio::spawn(server.serve(l, s.state.closing()));
    s.say(format_args!(
        "Modbus TCP server: {bound} (OpenPLC v3 address map, docs/protocols.md)"
    ));
    let clients = match cfg.and_then(|m| m.allow.as_ref()) {
        Some(list) => list.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "),
        None => "loopback only".to_string(),
    };
    let writes = if cfg.is_some_and(|m| m.read_only) {
        "read-only"
    } else {
        "reads and writes"
    };
    s.say(format_args!("  clients: {clients}; {writes}"));
    Ok(Started::On)
}
