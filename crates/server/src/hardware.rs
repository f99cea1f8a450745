//! The project's hardware as the API shows it (`/api/hardware`, docs/api.md
//! "Hardware"): the board and pin map of alba.toml, the machine's serial
//! ports, firmware builds with their sizes, byte-code downloads as jobs.
//!
//! This crate does not know Arduino: alba-app implements [`Hardware`] with
//! the command line's code (`alba export`, `alba download`) and sets it in
//! `AppState::hardware` before serving. Unset: `/api/hardware` answers 404.
//! Every method may block (a build runs avr-gcc, a download opens a serial
//! port): the handlers call them on blocking threads.

use crate::reply::{BoardIdentity, BuildSizes, Diagnostic, HardwareJob, HardwareView, Verified};
use alba_control::{Actor, Control, Refused};
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;

/// An attach or detach under way (the service acts through the control
/// layer, on the async runtime).
pub type Acting<'a> = Pin<Box<dyn Future<Output = Result<(), HardwareError>> + Send + 'a>>;

/// How a board is used as the running PLC's I/O (`POST /api/hardware/attach`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttachMode {
    /// The board runs the controller (remote-I/O) firmware (`alba firmware`):
    /// its pins are the program's inputs and outputs, the program runs here.
    Controller,
    /// The board runs the project's stand-alone sketch (`alba export
    /// arduino`) and is watched through its monitoring link: the ladder,
    /// tags and screens show the board's memory.
    Monitor,
}

impl AttachMode {
    pub fn parse(s: &str) -> Option<AttachMode> {
        match s {
            "controller" => Some(AttachMode::Controller),
            "monitor" => Some(AttachMode::Monitor),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            AttachMode::Controller => "controller",
            AttachMode::Monitor => "monitor",
        }
    }
}

/// A change of `[board]` (`PUT /api/hardware/board`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BoardChange {
    /// `uno`, `nano` or `mega`.
    pub board: String,
    /// A preset (`aurora`, `s7`, `openplc`).
    pub pinmap: String,
    /// Pins per direction (`di`, `do`, `ai`, `ao`) replacing the preset's;
    /// `None`: the preset's.
    pub di: Option<Vec<String>>,
    pub r#do: Option<Vec<String>>,
    pub ai: Option<Vec<String>>,
    pub ao: Option<Vec<String>>,
    /// `[board] port`; `None` leaves it out.
    pub port: Option<String>,
}

/// Why a hardware request failed.
#[derive(Debug, Clone)]
pub enum HardwareError {
    /// A bad board, kind, pin or port name (`400`).
    Malformed(String),
    /// No such job (`404`).
    NotFound(String),
    /// The project (or the changed `[board]`) does not check: nothing was
    /// built or saved (`422` with the diagnostics).
    DoesNotBuild(Vec<Diagnostic>),
    /// A job already runs on this port (`429`).
    Busy(String),
    /// The port cannot be opened: busy, vanished, permission denied (`502`).
    Port(String),
    /// The toolchain or the machine failed (`500`): the message says why.
    Failed(String),
    /// The control layer refused (a role too small, no audit row, the
    /// runtime): mapped as the API maps every refusal.
    Refused(Arc<Refused>),
    /// The board is attached, or none is (`409`): detach first, attach first.
    Conflict(String),
}

impl From<Refused> for HardwareError {
    fn from(r: Refused) -> HardwareError {
        HardwareError::Refused(Arc::new(r))
    }
}

impl std::fmt::Display for HardwareError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            HardwareError::Malformed(m)
            | HardwareError::NotFound(m)
            | HardwareError::Busy(m)
            | HardwareError::Port(m)
            | HardwareError::Failed(m)
            | HardwareError::Conflict(m) => f.write_str(m),
            HardwareError::DoesNotBuild(d) => match d.first() {
                Some(d) => write!(f, "{}: {}", d.code, d.message),
                None => f.write_str("the project does not build"),
            },
            HardwareError::Refused(r) => write!(f, "{r}"),
        }
    }
}

/// The hardware service of `alba run`.
pub trait Hardware: Send + Sync {
    /// The board, pin map (with its problems), ports and recent jobs.
    fn view(&self) -> Result<HardwareView, HardwareError>;
    /// Checks `[board]` as changed and saves it into alba.toml atomically;
    /// refused (nothing saved) when it does not check. Returns the target
    /// that was saved (`[board]` after the change) for the audit row.
    fn save_board(&self, change: &BoardChange) -> Result<HardwareView, HardwareError>;
    /// Puts `[board]` back as it was before the last save of this run (only
    /// `[board]`: the rest of alba.toml as it is now), checked and saved
    /// atomically; [`HardwareError::Conflict`] when there is nothing to undo.
    fn undo_board(&self) -> Result<HardwareView, HardwareError>;
    /// Builds the project's sketch or the byte-code interpreter for `board`.
    fn build(&self, board: &str, kind: &str) -> Result<BuildSizes, HardwareError>;
    /// Starts a job that builds the firmware `kind` (`sketch`,
    /// `interpreter`, `controller`) for `board` and uploads it to the board
    /// on `port` with avrdude (as `alba export arduino --upload` does).
    fn upload(&self, port: &str, board: &str, kind: &str) -> Result<String, HardwareError>;
    /// Starts downloading the project's byte code to the board on `port`.
    fn download(&self, port: &str) -> Result<String, HardwareError>;
    /// A job by id.
    fn job(&self, id: &str) -> Option<HardwareJob>;
    /// Asks a running job to stop (a download drops at the next record and
    /// the board runs its program on); the job as it stands, `None` if unknown.
    fn cancel(&self, id: &str) -> Option<HardwareJob>;
    /// Asks what is connected to `port`.
    fn identify(&self, port: &str) -> Result<BoardIdentity, HardwareError>;
    /// Reads the board's running program back and compares it with the project's byte code.
    fn verify(&self, port: &str) -> Result<Verified, HardwareError>;
    /// Uses the board on `port` as the running PLC's I/O (`mode`), without
    /// restarting it: through `control` for `actor` (the role, the audit
    /// row `attach`); [`Hardware::view`] says it is attached. Refused while
    /// a board is attached (detach first) or a job uses the port.
    fn attach<'a>(&'a self, control: &'a Control, actor: &'a Actor, port: &'a str, mode: AttachMode) -> Acting<'a>;
    /// Lets the attached board go and puts the project's own I/O back
    /// (audited `detach`: a safety action, as stop: the board's outputs go off).
    fn detach<'a>(&'a self, control: &'a Control, actor: &'a Actor) -> Acting<'a>;
}
