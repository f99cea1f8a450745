//! Every golden source and example, cut and mutated byte by byte (a fixed
//! pseudo-random sequence, so a failure repeats), goes through the checks
//! of the `st_check` fuzz target: no panic, spans inside the input, a clean
//! program verifies.

#[path = "common/check.rs"]
mod check;

use std::path::Path;

fn inputs() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for d in ["tests/parse", "tests/errors", "../../examples/st-motor"] {
        let mut paths: Vec<_> = std::fs::read_dir(root.join(d))
            .expect("folder")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "st"))
            .collect();
        paths.sort();
        out.extend(paths.iter().map(|p| std::fs::read_to_string(p).expect("read")));
    }
    assert!(out.len() >= 10, "inputs missing");
    out
}

#[test]
fn golden_sources_pass_the_fuzz_checks() {
    for src in inputs() {
        check::check_and_lower(&src).unwrap_or_else(|e| panic!("{e}\n{src}"));
    }
}

#[test]
fn mutated_sources_pass_the_fuzz_checks() {
    let pieces: [&str; 16] = [
        ";",
        ":=",
        "(",
        ")",
        "[",
        "]",
        "END_IF",
        "IF x THEN",
        "FOR i := 1 TO 3 DO",
        "a[",
        "T#",
        "16#",
        "'",
        "(*",
        "..",
        ".",
    ];
    let mut seed: u64 = 0x5eed;
    let mut next = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) as usize
    };
    let mut runs = 0;
    for src in inputs() {
        for _ in 0..60 {
            let mut s = src.clone();
            for _ in 0..(1 + next() % 4) {
                let mut at = next() % (s.len() + 1);
                while !s.is_char_boundary(at) {
                    at -= 1;
                }
                if next() % 2 == 0 {
                    let mut end = (at + 1 + next() % 8).min(s.len());
                    while !s.is_char_boundary(end) {
                        end -= 1;
                    }
                    s.replace_range(at..end, "");
                } else {
                    s.insert_str(at, pieces[next() % pieces.len()]);
                }
            }
            check::check_and_lower(&s).unwrap_or_else(|e| panic!("{e}\ninput: {s:?}"));
            runs += 1;
        }
    }
    assert!(runs >= 600);
}
