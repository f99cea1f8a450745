//! One `alba run` per project (issue 15): an OS advisory lock (`flock` on
//! Linux, `File::try_lock`) on the project directory itself, held for as
//! long as the run lasts. A second `alba run` on the same folder stops at
//! once, naming the first one's process id, instead of fighting it over
//! retain.json, the historian and online edits. The lock goes with the
//! process, `kill -9` included.
//!
//! The directory, not a file in it, is what is locked (issue 31): a file can
//! be deleted while held, after which a second run would lock a new one.
//! `.alba/lock` only tells the next one who holds the project (the pid); it
//! is opened without following a symbolic link (`O_NOFOLLOW`) and must be a
//! regular file, so a link planted there cannot make `alba run` truncate
//! another file.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Held while the project runs: the locked directory and the pid file.
pub(crate) struct ProjectLock {
    _dir: File,
    _pid: File,
}

/// Opens `.alba/lock` for the pid, refusing a link or anything but a regular file.
fn open_pid_file(path: &Path) -> Result<File, String> {
    let mut open = OpenOptions::new();
    open.read(true).write(true).create(true).truncate(false);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut open, rustix::fs::OFlags::NOFOLLOW.bits() as i32);
    let refused = || {
        format!(
            "{} is not a regular file (a symbolic link?): remove it, `alba run` makes its own",
            path.display()
        )
    };
    let f = open.open(path).map_err(|e| {
        if path.symlink_metadata().is_ok_and(|m| !m.is_file()) {
            refused()
        } else {
            format!("cannot open {}: {e}", path.display())
        }
    })?;
    match f.metadata() {
        Ok(m) if m.is_file() => Ok(f),
        Ok(_) => Err(refused()),
        Err(e) => Err(format!("cannot open {}: {e}", path.display())),
    }
}

pub(crate) fn acquire(dir: &Path) -> Result<ProjectLock, String> {
    let alba = dir.join(".alba");
    std::fs::create_dir_all(&alba).map_err(|e| format!("cannot create {}: {e}", alba.display()))?;
    let folder = File::open(dir).map_err(|e| format!("cannot open {}: {e}", dir.display()))?;
    let path = alba.join("lock");
    match folder.try_lock() {
        Ok(()) => {
            let mut f = open_pid_file(&path)?;
            // Who holds it, for the next one's message.
            let _ = f.set_len(0);
            let _ = f.seek(SeekFrom::Start(0));
            let _ = writeln!(f, "{}", std::process::id());
            let _ = f.sync_all();
            Ok(ProjectLock { _dir: folder, _pid: f })
        }
        Err(TryLockError::WouldBlock) => {
            let mut pid = String::new();
            if let Ok(mut f) = open_pid_file(&path) {
                let _ = f.read_to_string(&mut pid);
            }
            let pid = pid.trim();
            Err(format!(
                "another `alba run` ({}) is running the project in {}: stop it first (one runtime per project, or \
                 retentive data, history and edits would be overwritten by both)",
                if pid.is_empty() {
                    "pid unknown".to_string()
                } else {
                    format!("pid {pid}")
                },
                dir.display()
            ))
        }
        Err(TryLockError::Error(e)) => Err(format!("cannot lock {}: {e}", dir.display())),
    }
}
