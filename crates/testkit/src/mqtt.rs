//! A real MQTT broker for tests (Debian's `mosquitto`, which test.sh installs): its own
//! configuration in a temporary directory, listening on a free loopback port, anonymous,
//! without persistence. Stopped when dropped.

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

impl Drop for Broker {
    fn drop(&mut self) {
        self.stop();
    }
}
