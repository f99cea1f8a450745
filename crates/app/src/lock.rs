//! One `alba run` per project (issue 15): `.alba/lock`, held with an OS
//! advisory lock (`File::try_lock`, `flock` on Linux) for as long as the run
//! lasts. A second `alba run` on the same folder stops at once, naming the
//! first one's process id, instead of fighting it over retain.json, the
//! historian and online edits. The lock goes with the process, `kill -9`
//! included; the file stays (its content is only informative).

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Held while the project runs.
pub(crate) struct ProjectLock(#[allow(dead_code)] File);

pub(crate) fn acquire(dir: &Path) -> Result<ProjectLock, String> {
    let alba = dir.join(".alba");
    std::fs::create_dir_all(&alba).map_err(|e| format!("cannot create {}: {e}", alba.display()))?;
    let path = alba.join("lock");
    let mut f = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    match f.try_lock() {
        Ok(()) => {
            // Who holds it, for the next one's message.
            let _ = f.set_len(0);
            let _ = f.seek(SeekFrom::Start(0));
            let _ = writeln!(f, "{}", std::process::id());
            let _ = f.sync_all();
            Ok(ProjectLock(f))
        }
        Err(TryLockError::WouldBlock) => {
            let mut pid = String::new();
            let _ = f.read_to_string(&mut pid);
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
        Err(TryLockError::Error(e)) => Err(format!("cannot lock {}: {e}", path.display())),
    }
}
