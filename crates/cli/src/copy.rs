//! `alba run --copy`: runs a copy of a project, so that what the studio saves
//! goes into the copy and the original (an example of the repository, whose
//! golden files the tests check) stays as it is — as `alba demo` does.

use std::path::{Path, PathBuf};

/// Where `--copy` without a folder puts the copy: `./alba-<project folder name>`.
pub fn default_dest(project: &Path) -> PathBuf {
    let name = std::fs::canonicalize(project)
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "project".into());
    PathBuf::from(format!("alba-{name}"))
}

/// Copies `project` into `dest` unless `dest` holds a project already (then
/// the earlier copy, with its edits, is run again). The copy is made in a
/// temporary folder beside `dest` and renamed into place, so an interrupted
/// copy leaves nothing half-made; the runtime's own `.alba/` state is not
/// copied. Returns whether a new copy was made.
pub fn prepare(project: &Path, dest: &Path) -> Result<bool, String> {
    if dest.join("alba.toml").exists() {
        return Ok(false);
    }
    if !project.join("alba.toml").is_file() {
        return Err(format!("{} is not an Alba project (no alba.toml)", project.display()));
    }
    if dest.exists() && std::fs::read_dir(dest).map_or(true, |mut d| d.next().is_some()) {
        return Err(format!(
            "{} exists and is neither empty nor an Alba project; give --copy another folder",
            dest.display()
        ));
    }
    let (src, to) = (
        std::fs::canonicalize(project).map_err(|e| format!("{}: {e}", project.display()))?,
        std::path::absolute(dest).map_err(|e| format!("{}: {e}", dest.display()))?,
    );
    if to.starts_with(&src) {
        return Err(format!("--copy {} is inside the project it copies", dest.display()));
    }
    let tmp = to.with_file_name(format!(
        ".{}.copying-{}",
        to.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&tmp);
    let done = copy_dir(&src, &tmp).and_then(|()| {
        if dest.exists() {
            std::fs::remove_dir(dest)?;
        }
        std::fs::rename(&tmp, dest)
    });
    if let Err(e) = done {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(format!(
            "cannot copy {} into {}: {e}",
            project.display(),
            dest.display()
        ));
    }
    Ok(true)
}

fn copy_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let kind = entry.file_type()?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if kind.is_dir() {
            if entry.file_name() != ".alba" {
                copy_dir(&src, &dst)?;
            }
        } else if kind.is_file() {
            std::fs::copy(&src, &dst)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_copy_is_made_once_without_the_runtime_state_and_kept_after() {
        let tmp = tempfile::tempdir().expect("tmp");
        let p = tmp.path().join("plant");
        std::fs::create_dir_all(p.join(".alba")).expect("mkdir");
        std::fs::create_dir_all(p.join("hmi")).expect("mkdir");
        for (f, t) in [
            ("alba.toml", "name = \"p\"\n"),
            ("hmi/a.json", "{}"),
            (".alba/retain.json", "{}"),
        ] {
            std::fs::write(p.join(f), t).expect("write");
        }
        let dest = tmp.path().join("copy");
        assert_eq!(prepare(&p, &dest), Ok(true));
        assert!(dest.join("hmi/a.json").is_file());
        assert!(
            !dest.join(".alba").exists(),
            "the runtime's state is the original's own"
        );
        // An edit in the copy is kept: the next run uses it as it is.
        std::fs::write(dest.join("alba.toml"), "name = \"edited\"\n").expect("edit");
        assert_eq!(prepare(&p, &dest), Ok(false));
        assert_eq!(
            std::fs::read_to_string(dest.join("alba.toml")).expect("read"),
            "name = \"edited\"\n"
        );
        // Refusals: a folder with other files, a copy inside the project, no project.
        let busy = tmp.path().join("busy");
        std::fs::create_dir_all(&busy).expect("mkdir");
        std::fs::write(busy.join("x"), "").expect("write");
        assert!(
            prepare(&p, &busy)
                .expect_err("busy")
                .contains("neither empty nor an Alba project")
        );
        assert!(
            prepare(&p, &p.join("inner"))
                .expect_err("inside")
                .contains("inside the project")
        );
        assert!(
            prepare(&tmp.path().join("none"), &tmp.path().join("c2"))
                .expect_err("none")
                .contains("no alba.toml")
        );
        assert_eq!(default_dest(&p), PathBuf::from("alba-plant"));
    }
}
