//! A real MQTT broker for tests (Debian's `mosquitto`, which test.sh installs): its own
//! configuration in a temporary directory, listening on a free loopback port, anonymous,
//! without persistence, TLS with client certificates when asked. Stopped when dropped.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A Mosquitto broker of its own.
pub struct Broker {
    /// The configuration file's directory.
    pub dir: tempfile::TempDir,
    /// The loopback port it listens on.
    pub port: u16,
    bin: PathBuf,
    child: Option<Child>,
}

fn mosquitto() -> Option<PathBuf> {
    ["/usr/sbin/mosquitto", "/usr/bin/mosquitto", "/usr/local/sbin/mosquitto"]
        .into_iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
}

impl Broker {
    /// Starts a broker, or `None` (test skipped) when Mosquitto is not installed outside
    /// CI. Under `CI=true` a missing Mosquitto fails the test.
    pub fn start() -> Option<Broker> {
        let Some(bin) = mosquitto() else {
            let msg = "Mosquitto is not installed: apt-get install -y mosquitto (test.sh does)";
            if std::env::var("CI").is_ok_and(|v| v == "true") {
                panic!("{msg}");
            }
            eprintln!("skipped: {msg}");
            return None;
        };
        let dir = tempfile::tempdir().expect("temporary directory");
        let port = crate::pg::free_port();
        let conf = dir.path().join("mosquitto.conf");
        std::fs::write(
            &conf,
            format!("listener {port} 127.0.0.1\nallow_anonymous true\npersistence false\n"),
        )
        .expect("mosquitto.conf");
        // Started as root, Mosquitto reads its files as the user `mosquitto`.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755));
            let _ = std::fs::set_permissions(&conf, std::fs::Permissions::from_mode(0o644));
        }
        let mut b = Broker {
            dir,
            port,
            bin,
            child: None,
        };
        b.start_again();
        Some(b)
    }

    /// `127.0.0.1:<port>`.
    pub fn addr(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }

    /// Starts the stopped broker again on the same port, and waits until it listens.
    pub fn start_again(&mut self) {
        let child = Command::new(&self.bin)
            .arg("-c")
            .arg(self.dir.path().join("mosquitto.conf"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("mosquitto starts");
        self.child = Some(child);
        let deadline = Instant::now() + Duration::from_secs(30);
        while std::net::TcpStream::connect(self.addr()).is_err() {
            assert!(Instant::now() < deadline, "mosquitto did not listen on {}", self.addr());
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Stops the broker (SIGKILL: its clients see the connection drop).
    pub fn stop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// The PEM files of a broker that speaks TLS only ([`Broker::enable_tls`]).
pub struct BrokerTls {
    /// The CA that signed the broker's certificate and the client's.
    pub ca: PathBuf,
    pub client_cert: PathBuf,
    pub client_key: PathBuf,
    /// A CA of its own that signed nothing the broker knows.
    pub other_ca: PathBuf,
}

impl Broker {
    /// Makes a CA, a certificate for `127.0.0.1` and one for a client, and restarts the
    /// broker on the same port speaking TLS only and asking every client for a
    /// certificate signed by that CA.
    pub fn enable_tls(&mut self) -> BrokerTls {
        let ca = |name: &str| {
            let key = rcgen::KeyPair::generate().expect("CA key");
            let mut params = rcgen::CertificateParams::new(Vec::<String>::new()).expect("CA params");
            params.is_ca = rcgen::IsCa::Ca(rcgen::BasicConstraints::Unconstrained);
            params.distinguished_name.push(rcgen::DnType::CommonName, name);
            let cert = params.self_signed(&key).expect("CA certificate");
            (cert, key)
        };
        let (ca_cert, ca_key) = ca("Alba test broker CA");
        let (other, _) = ca("Another CA");
        let signed = |names: &[&str]| {
            let key = rcgen::KeyPair::generate().expect("key");
            let params =
                rcgen::CertificateParams::new(names.iter().map(|n| n.to_string()).collect::<Vec<_>>()).expect("params");
            let cert = params.signed_by(&key, &ca_cert, &ca_key).expect("certificate");
            (cert.pem(), key.serialize_pem())
        };
        let (broker_pem, broker_key) = signed(&["127.0.0.1", "localhost"]);
        let (client_pem, client_key) = signed(&["alba-client"]);
        let d = self.dir.path().to_path_buf();
        let files = [
            ("ca.pem", ca_cert.pem()),
            ("other-ca.pem", other.pem()),
            ("broker.pem", broker_pem),
            ("broker.key", broker_key),
            ("client.pem", client_pem),
            ("client.key", client_key),
        ];
        for (name, text) in &files {
            std::fs::write(d.join(name), text).expect("PEM file");
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                let _ = std::fs::set_permissions(d.join(name), std::fs::Permissions::from_mode(0o644));
            }
        }
        let conf = d.join("mosquitto.conf");
        let mut text = std::fs::read_to_string(&conf).expect("mosquitto.conf");
        text.push_str(&format!(
            "cafile {0}/ca.pem\ncertfile {0}/broker.pem\nkeyfile {0}/broker.key\nrequire_certificate true\n",
            d.display()
        ));
        std::fs::write(&conf, text).expect("mosquitto.conf");
        self.stop();
        self.start_again();
        BrokerTls {
            ca: d.join("ca.pem"),
            client_cert: d.join("client.pem"),
            client_key: d.join("client.key"),
            other_ca: d.join("other-ca.pem"),
        }
    }
}

impl Drop for Broker {
    fn drop(&mut self) {
        self.stop();
    }
}
