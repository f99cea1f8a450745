//! Loading project folders.

use super::*;
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("alba-model-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn loads_a_project_and_reports_missing_programs() {
    let d = tmp("load");
    std::fs::write(
        d.join("alba.toml"),
        "name = \"t\"\nprograms = [\"main.lad\", \"gone.lad\", \"x.st\", \"../up.lad\", \"main.lad\"]\n",
    )
    .unwrap();
    std::fs::write(d.join("tags.csv"), "name,type\nA,BOOL\n").unwrap();
    std::fs::write(d.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
    let (p, diags) = load(&d);
    assert_eq!(p.programs.len(), 1);
    assert_eq!(p.tags.len(), 1);
    let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, [Code::ProgramFile; 4]);
    let short: Vec<_> = diags.iter().map(|x| x.short(&p.files)).collect();
    assert!(short[0].contains("alba.toml:2:25"), "{short:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn users_toml_is_checked_and_opcua_users_warned() {
    const HASH: &str = "$argon2id$v=19$m=8,t=1,p=1$YWxiYS10ZXN0LXNhbHQ$AAAAAAAAAAAAAAAAAAAAAA";
    let d = tmp("users");
    let toml = "name = \"t\"\nprograms = [\"main.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n";
    std::fs::write(d.join("alba.toml"), toml).unwrap();
    std::fs::write(d.join("tags.csv"), "name,type\nA,BOOL\n").unwrap();
    std::fs::write(d.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
    let short =
        |(p, diags): (Project, Vec<Diagnostic>)| -> Vec<String> { diags.iter().map(|x| x.short(&p.files)).collect() };
    // No users anywhere: a listener beyond loopback is refused.
    let e = short(load(&d));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].contains("alba.toml:4:10: error[E102]") && e[0].contains("needs users"),
        "{e:?}"
    );
    // A user in users.toml is enough; its errors are located.
    std::fs::write(
        d.join("users.toml"),
        format!("[users.op]\nrole = \"operator\"\npassword = \"{HASH}\"\n"),
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let f = d.join("users.toml");
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o644)).unwrap();
        let (p, diags) = load(&d);
        assert!(diags.is_empty(), "a users.toml open to others is a warning: {diags:?}");
        assert_eq!(p.warnings.len(), 1);
        assert!(p.warnings[0].render_warning(&p.files).contains("warning[E107]"));
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o600)).unwrap();
    }
    let (p, diags) = load(&d);
    assert!(diags.is_empty() && p.warnings.is_empty(), "{diags:?}");
    std::fs::write(d.join("users.toml"), "[users.op]\nrole = \"god\"\npassword = \"x\"\n").unwrap();
    let e = short(load(&d));
    assert_eq!(e.len(), 3, "{e:?}");
    assert!(e[0].contains("users.toml:2:8: error[E107]"), "{e:?}");
    // [opcua.users] still loads, with a warning that is not an error.
    std::fs::remove_file(d.join("users.toml")).unwrap();
    std::fs::write(d.join("alba.toml"), format!("{toml}[opcua.users]\nop = \"{HASH}\"\n")).unwrap();
    let (p, diags) = load(&d);
    assert!(diags.is_empty(), "{diags:?}");
    assert_eq!(p.warnings.len(), 1);
    let w = p.warnings[0].render_warning(&p.files);
    assert!(w.contains("warning[E109]") && w.contains("alba user"), "{w}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn missing_folder_is_one_clear_error_per_file() {
    let (p, diags) = load(Path::new("/nonexistent/alba"));
    assert!(p.config.is_none());
    assert_eq!(diags.len(), 2);
    assert!(diags[0].message.contains("cannot read /nonexistent/alba/alba.toml"));
}
