//! The OPC UA server of `alba run`: on `--opcua`, else where `[opcua]
//! listen` says (security None only on loopback).

use crate::{Service, Started};

pub(crate) async fn start(s: &Service<'_>, addr: Option<std::net::SocketAddr>) -> Result<Started, String> {
    let cfg = s.config.and_then(|c| c.opcua.as_ref());
    let Some(addr) = addr.or(cfg.and_then(|o| o.listen)) else {
        return Ok(Started::Off);
    };
    let pki = s.dir.join(".alba").join("pki");
    let name = &s.state.name;
    let bound = alba_opcua::serve(
        s.state.control.clone(),
        name,
        addr,
        pki.clone(),
        s.users.clone(),
        s.state.closing(),
    )
    .await?;
    s.say(format_args!(
        "OPC UA server: opc.tcp://{bound}/ (tags under Objects/Alba/{name}/Tags)"
    ));
    if alba_opcua::security::is_local(bound.ip()) {
        s.say(format_args!(
            "  security: None (anonymous) and Basic256Sha256 with user names and passwords; client certificates trusted on first use"
        ));
    } else {
        s.say(format_args!(
            "  security: Basic256Sha256 with user names and passwords only; unknown client certificates go to {}/rejected/",
            pki.display()
        ));
    }
    Ok(Started::On)
}
