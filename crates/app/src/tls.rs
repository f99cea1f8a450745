//! HTTPS for the studio's listener (docs/security.md, "Browser attacks and
//! transport"): a non-loopback `--http` address serves HTTPS only, unless
//! plain HTTP is explicitly allowed (`--insecure-http`, `[http] insecure =
//! true`). The certificate is the user's (`[http] cert`/`key`, PEM) or a
//! self-signed one made on first run in `<project>/.alba/tls/` (the key
//! readable by its owner only), naming `localhost`, the loopback addresses,
//! the listening address and `[http] allowed_hosts`.

use alba_settings::Http;
use rustls::pki_types::pem::PemObject;
use rustls::pki_types::{CertificateDer, PrivateKeyDer};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;
use tokio::net::{TcpListener, TcpStream};
use tokio_rustls::TlsAcceptor;
use tokio_rustls::server::TlsStream;

/// Whether the studio's listener speaks HTTPS (`alba run --https`,
/// `--insecure-http`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tls {
    /// HTTPS on a non-loopback address (plain HTTP there only with `[http]
    /// insecure = true`), plain HTTP on loopback.
    #[default]
    Auto,
    /// HTTPS on any address, loopback included.
    Always,
    /// Plain HTTP on any address: explicitly insecure beyond loopback.
    Never,
}

/// Whether `addr` is served over HTTPS; `insecure` is `[http] insecure`.
pub fn https(tls: Tls, addr: SocketAddr, insecure: bool) -> bool {
    match tls {
        Tls::Always => true,
        Tls::Never => false,
        Tls::Auto => !addr.ip().is_loopback() && !insecure,
    }
}

/// The scheme the studio of `dir` is served with at `addr` (`[http]
/// insecure` read from its alba.toml), for the line `alba run` prints.
pub fn scheme(dir: &Path, tls: Tls, addr: SocketAddr) -> &'static str {
    let insecure = std::fs::read_to_string(dir.join("alba.toml"))
        .ok()
        .and_then(|text| {
            let mut files = alba_diag::Files::new();
            let file = files.add("alba.toml", &text);
            alba_settings::Settings::parse(&text, file).0
        })
        .is_some_and(|c| c.http.insecure);
    if https(tls, addr, insecure) { "https" } else { "http" }
}

/// Where the self-signed certificate and its key are kept.
pub fn self_signed_paths(dir: &Path) -> (PathBuf, PathBuf) {
    let tls = dir.join(".alba").join("tls");
    (tls.join("cert.pem"), tls.join("key.pem"))
}

/// The TLS configuration of the studio of `dir`: the user's certificate,
/// else the self-signed one (made now if missing).
pub fn acceptor(dir: &Path, http: &Http, addr: SocketAddr) -> Result<TlsAcceptor, String> {
    let (cert, key) = match (&http.cert, &http.key) {
        (Some(c), Some(k)) => (dir.join(c), dir.join(k)),
        _ => {
            let (cert, key) = self_signed_paths(dir);
            if !(cert.exists() && key.exists()) {
                make_self_signed(&cert, &key, addr, &http.allowed_hosts)?;
            }
            (cert, key)
        }
    };
    let chain = CertificateDer::pem_file_iter(&cert)
        .and_then(|certs| certs.collect::<Result<Vec<_>, _>>())
        .map_err(|e| format!("{}: cannot read the TLS certificate: {e}", cert.display()))?;
    if chain.is_empty() {
        return Err(format!("{}: no certificate in this PEM file", cert.display()));
    }
    let key_der = PrivateKeyDer::from_pem_file(&key)
        .map_err(|e| format!("{}: cannot read the TLS private key: {e}", key.display()))?;
    let config = rustls::ServerConfig::builder_with_provider(Arc::new(rustls::crypto::ring::default_provider()))
        .with_safe_default_protocol_versions()
        .map_err(|e| e.to_string())?
        .with_no_client_auth()
        .with_single_cert(chain, key_der)
        .map_err(|e| format!("{}: {e}", cert.display()))?;
    Ok(TlsAcceptor::from(Arc::new(config)))
}

/// Makes a self-signed certificate for `localhost`, the loopback
/// addresses, `addr` (unless unspecified) and `names`; the key file is
/// created readable by its owner only.
pub fn make_self_signed(cert: &Path, key: &Path, addr: SocketAddr, names: &[String]) -> Result<(), String> {
    let mut sans: Vec<String> = vec!["localhost".into(), "127.0.0.1".into(), "::1".into()];
    if !addr.ip().is_unspecified() && !addr.ip().is_loopback() {
        sans.push(addr.ip().to_string());
    }
    sans.extend(names.iter().cloned());
    let made = rcgen::generate_simple_self_signed(sans).map_err(|e| format!("cannot make a TLS certificate: {e}"))?;
    let dir = cert.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    write_private(key, made.key_pair.serialize_pem().as_bytes())?;
    alba_model::fsutil::write_atomic(cert, |w| w.write_all(made.cert.pem().as_bytes()))
        .map_err(|e| format!("{}: {e}", cert.display()))
}

/// Writes `bytes` to `path` atomically, the file readable by its owner only.
fn write_private(path: &Path, bytes: &[u8]) -> Result<(), String> {
    use std::io::Write;
    let err = |e: std::io::Error| format!("{}: {e}", path.display());
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    let mut open = std::fs::OpenOptions::new();
    open.write(true).create(true).truncate(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut open, 0o600);
    let written = (|| {
        let mut f = open.open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.map_err(err)
}

/// How long a client may take over its TLS handshake.
const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(10);

/// A TCP listener whose connections are TLS: handshakes run in their own
/// tasks (a slow client holds up no other) and finished ones are handed to
/// the server.
pub struct TlsListener {
    local: SocketAddr,
    ready: tokio::sync::mpsc::Receiver<(TlsStream<TcpStream>, SocketAddr)>,
    accepting: tokio::task::JoinHandle<()>,
}

impl TlsListener {
    pub fn new(tcp: TcpListener, acceptor: TlsAcceptor) -> std::io::Result<TlsListener> {
        let local = tcp.local_addr()?;
        let (tx, ready) = tokio::sync::mpsc::channel(64);
        let accepting = tokio::spawn(async move {
            loop {
                let Ok((stream, peer)) = tcp.accept().await else {
                    // Out of file descriptors and the like: try again shortly.
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                };
                crate::limits::bound_send_buffer(&stream);
                let (acceptor, tx) = (acceptor.clone(), tx.clone());
                tokio::spawn(async move {
                    if let Ok(Ok(tls)) = tokio::time::timeout(HANDSHAKE_TIMEOUT, acceptor.accept(stream)).await {
                        let _ = tx.send((tls, peer)).await;
                    }
                });
            }
        });
        Ok(TlsListener {
            local,
            ready,
            accepting,
        })
    }
}

impl Drop for TlsListener {
    fn drop(&mut self) {
        self.accepting.abort();
    }
}

impl axum::serve::Listener for TlsListener {
    type Io = TlsStream<TcpStream>;
    type Addr = SocketAddr;

    async fn accept(&mut self) -> (Self::Io, Self::Addr) {
        match self.ready.recv().await {
            Some(conn) => conn,
            // The accepting task ended (the listener is being dropped).
            None => std::future::pending().await,
        }
    }

    fn local_addr(&self) -> std::io::Result<SocketAddr> {
        Ok(self.local)
    }
}
