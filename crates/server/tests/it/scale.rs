//! The API's cost in program size (issue 15): the program view of a 40 k-rung
//! program is linear, asserted by the work its location lookups do rather
//! than by a clock.

use alba_server::project;

/// A project of `rungs` rungs; the bytes of `main.lad`.
fn write_project(rungs: usize) -> (std::path::PathBuf, usize) {
    let dir = std::env::temp_dir().join(format!("alba-scale-{rungs}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(dir.join("alba.toml"), "name = \"big\"\nprograms = [\"main.lad\"]\n").expect("toml");
    let tags: String = (0..100).map(|i| format!("B{i},BOOL,,,,\n")).collect();
    std::fs::write(
        dir.join("tags.csv"),
        format!("name,type,address,initial,retain,description\n{tags}"),
    )
    .expect("tags");
    let lad: String = (0..rungs)
        .map(|r| {
            format!(
                "XIC(B{})[XIO(B{}),XIC(B{})]OTE(B{});\n",
                r % 100,
                (r + 1) % 100,
                (r + 7) % 100,
                (r + 3) % 100
            )
        })
        .collect();
    std::fs::write(dir.join("main.lad"), &lad).expect("lad");
    (dir, lad.len())
}

/// The bytes the view of `rungs` rungs examined to locate its elements.
fn view_cost(rungs: usize) -> (u64, usize) {
    let (dir, len) = write_project(rungs);
    let c = project::load(&dir);
    assert!(c.program.is_some(), "{:?}", c.diagnostics.first());
    let before = c.project.files.bytes_scanned();
    let view = project::program_json(&c.project, c.program.as_ref(), "main.lad", &c.diagnostics).expect("view");
    assert_eq!(view.rungs.map(|r| r.len()), Some(rungs));
    let cost = c.project.files.bytes_scanned() - before;
    let _ = std::fs::remove_dir_all(&dir);
    (cost, len)
}

#[test]
fn the_program_view_is_linear_in_program_size() {
    let (small, _) = view_cost(10_000);
    let (big, len) = view_cost(40_000);
    eprintln!("program view: {small} bytes examined for 10 000 rungs, {big} for 40 000 ({len} bytes of text)");
    // Four times the rungs, four times the work (a quadratic view did ~16×,
    // and examined the whole text before each element: ~10¹¹ bytes here).
    assert!(big <= 4 * small + 4 * 1024, "{small} → {big}");
    assert!(big <= 4 * len as u64, "{big} bytes examined for a {len}-byte program");
}
