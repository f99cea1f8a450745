//! A real PostgreSQL server for tests (Debian's `postgresql`, which test.sh installs):
//! a fresh cluster in a temporary directory, listening on a free loopback port, with a
//! password (SCRAM) for user `alba`. Under root it runs as the `postgres` user (the
//! server refuses to run as root).

use std::path::PathBuf;
use std::process::Command;

/// A PostgreSQL server of its own, stopped when dropped: a cluster in a temporary directory, a password
/// (SCRAM) for user `alba`, listening on 127.0.0.1 only.
pub struct PgServer {
    /// The cluster, the password file and the server's socket and log.
    pub dir: tempfile::TempDir,
    bin: PathBuf,
    /// The loopback port it listens on.
    pub port: u16,
    /// Under root the server runs as the `postgres` user (it refuses to run as root).
    run_as: Option<&'static str>,
}

/// The password of user `alba` (in [`PgServer::password_file`]).
pub const PASSWORD: &str = "s3cret-historian-pw";

fn pg_bin() -> Option<PathBuf> {
    let mut found: Vec<(u32, PathBuf)> = std::fs::read_dir("/usr/lib/postgresql")
        .ok()?
        .flatten()
        .filter_map(|e| {
            let version = e.file_name().to_str()?.parse::<u32>().ok()?;
            let bin = e.path().join("bin");
            bin.join("pg_ctl").exists().then_some((version, bin))
        })
        .collect();
    found.sort();
    found.pop().map(|(_, b)| b)
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

pub(crate) fn free_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").expect("bind a loopback port");
    l.local_addr().expect("local address").port()
}

impl PgServer {
    /// Starts a server (`initdb`, `pg_ctl start`), or `None` (test skipped) when PostgreSQL is not installed outside
    /// CI. Under `CI=true` a missing PostgreSQL fails the test.
    pub fn start() -> Option<PgServer> {
        let Some(bin) = pg_bin() else {
            let msg = "PostgreSQL is not installed (/usr/lib/postgresql/*/bin/pg_ctl): \
                       apt-get install -y postgresql (test.sh does)";
            if std::env::var("CI").is_ok_and(|v| v == "true") {
                panic!("{msg}");
            }
            eprintln!("skipped: {msg}");
            return None;
        };
        let dir = tempfile::tempdir().expect("temporary directory");
        let run_as = is_root().then_some("postgres");
        std::fs::write(dir.path().join("pw"), format!("{PASSWORD}\n")).expect("password file");
        if let Some(user) = run_as {
            let ok = Command::new("chown")
                .args(["-R", &format!("{user}:"), &dir.path().display().to_string()])
                .status()
                .expect("chown")
                .success();
            assert!(ok, "chown the cluster directory to {user}");
        }
        let server = PgServer {
            dir,
            bin,
            port: free_port(),
            run_as,
        };
        let data = server.data();
        let pw = server.dir.path().join("pw");
        server.run(
            "initdb",
            &[
                "-D",
                &data,
                "-U",
                "alba",
                "--auth=scram-sha-256",
                "--pwfile",
                &pw.display().to_string(),
                "-E",
                "UTF8",
                "--locale=C",
            ],
        );
        server.start_again();
        Some(server)
    }

    /// The cluster's data directory.
    pub fn data(&self) -> String {
        self.dir.path().join("data").display().to_string()
    }

    /// Runs one of the server's tools (as the server's user), failing the test on error.
    pub fn run(&self, tool: &str, args: &[&str]) {
        let exe = self.bin.join(tool);
        let mut cmd = match self.run_as {
            Some(user) => {
                let mut c = Command::new("runuser");
                c.args(["-u", user, "--"]).arg(&exe);
                c
            }
            None => Command::new(&exe),
        };
        let out = cmd.args(args).output().unwrap_or_else(|e| panic!("{tool}: {e}"));
        assert!(
            out.status.success(),
            "{tool} {args:?} failed: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }

    /// Starts the stopped server again, on the same port.
    pub fn start_again(&self) {
        let opts = format!(
            "-p {} -k {} -c listen_addresses=127.0.0.1",
            self.port,
            self.dir.path().display()
        );
        let log = self.dir.path().join("log").display().to_string();
        self.run(
            "pg_ctl",
            &["-D", &self.data(), "-l", &log, "-w", "-t", "120", "-o", &opts, "start"],
        );
    }

    /// Stops the server (fast shutdown: clients are disconnected).
    pub fn stop(&self) {
        self.run("pg_ctl", &["-D", &self.data(), "-w", "-t", "120", "-m", "fast", "stop"]);
    }

    /// Turns TLS on with a server certificate for `localhost` and `127.0.0.1` signed by a
    /// CA of its own, refuses unencrypted connections from now on, and restarts. Returns
    /// the CA's certificate (PEM file) that clients must trust.
    pub fn enable_tls(&self) -> PathBuf {
        let ca_key = rcgen::KeyPair::generate().expect("CA key");
        let mut ca = rcgen::CertificateParams::new(Vec::<String>::new()).expect("CA params");
        ca.is_ca = rcgen::IsCa::Ca(rcgen::BasicConstraints::Unconstrained);
        ca.distinguished_name
            .push(rcgen::DnType::CommonName, "Alba test database CA");
        let ca_cert = ca.self_signed(&ca_key).expect("CA certificate");
        let key = rcgen::KeyPair::generate().expect("server key");
        let params =
            rcgen::CertificateParams::new(vec!["localhost".to_owned(), "127.0.0.1".to_owned()]).expect("server params");
        let cert = params.signed_by(&key, &ca_cert, &ca_key).expect("server certificate");
        let data = PathBuf::from(self.data());
        std::fs::write(data.join("server.crt"), cert.pem()).expect("server.crt");
        std::fs::write(data.join("server.key"), key.serialize_pem()).expect("server.key");
        let conf = data.join("postgresql.conf");
        let mut text = std::fs::read_to_string(&conf).expect("postgresql.conf");
        text.push_str("\nssl = on\nssl_cert_file = 'server.crt'\nssl_key_file = 'server.key'\n");
        std::fs::write(&conf, text).expect("postgresql.conf");
        let hba = data.join("pg_hba.conf");
        let text = std::fs::read_to_string(&hba).expect("pg_hba.conf");
        std::fs::write(&hba, format!("hostnossl all all 0.0.0.0/0 reject\n{text}")).expect("pg_hba.conf");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(data.join("server.key"), std::fs::Permissions::from_mode(0o600));
        }
        if let Some(user) = self.run_as {
            let ok = Command::new("chown")
                .arg(format!("{user}:"))
                .arg(data.join("server.crt"))
                .arg(data.join("server.key"))
                .status()
                .expect("chown")
                .success();
            assert!(ok, "chown the server's certificate to {user}");
        }
        self.stop();
        self.start_again();
        let ca_file = self.dir.path().join("ca.pem");
        std::fs::write(&ca_file, ca_cert.pem()).expect("ca.pem");
        ca_file
    }

    /// Connection settings without the password.
    pub fn url(&self) -> String {
        format!("host=127.0.0.1 port={} user=alba dbname=postgres", self.port)
    }

    /// A file holding [`PASSWORD`] (one line).
    pub fn password_file(&self) -> PathBuf {
        self.dir.path().join("pw")
    }
}

impl Drop for PgServer {
    fn drop(&mut self) {
        let exe = self.bin.join("pg_ctl");
        let data = self.data();
        let args = ["-D", data.as_str(), "-m", "immediate", "stop"];
        let _ = match self.run_as {
            Some(user) => Command::new("runuser")
                .args(["-u", user, "--"])
                .arg(&exe)
                .args(args)
                .output(),
            None => Command::new(&exe).args(args).output(),
        };
    }
}
