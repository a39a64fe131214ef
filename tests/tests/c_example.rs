//! The C example an integrator starts from (examples/c/minimal.c) builds warning-free as C99 against the
//! generated header and the plugin's shared library, runs with the validation layer on (it counts the
//! layer's errors through a debug messenger and fails on any), and matches the exact shadow: it must print
//! `0 mismatches` with both lit and shadowed pixels compared. Without a Vulkan device the example fails,
//! and so does this test.

mod native;

use native::{compile_c, library_dir, run, workspace};
use std::process::Command;

/// The number printed just before `label` in `text` (e.g. 812 in "812 shadowed").
fn count_before(text: &str, label: &str) -> u64 {
    let end = text
        .find(label)
        .unwrap_or_else(|| panic!("no '{label}' in:\n{text}"));
    let before = &text[..end];
    let start = before
        .rfind(|c: char| !c.is_ascii_digit())
        .map_or(0, |i| i + 1);
    before[start..]
        .parse()
        .unwrap_or_else(|_| panic!("no count before '{label}' in:\n{text}"))
}

#[test]
fn minimal_c_example_matches_the_exact_shadow_without_validation_errors() {
    let root = workspace();
    let lib = library_dir();
    let dir = std::env::temp_dir().join(format!("hrts-c-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("minimal");
    let source = root.join("examples/c/minimal.c");
    compile_c(&exe, &root.join("hrts/include"), &[source], &lib);
    // `run` asserts the exit status: 0 only with no mismatch and no validation error.
    let out = run(Command::new(&exe)
        .current_dir(&dir)
        .env("HRTS_VALIDATION", "1"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("validation layer: on"), "{stdout}");
    assert!(stdout.contains("validation: 0 errors"), "{stdout}");
    assert!(stdout.contains(", 0 mismatches"), "{stdout}");
    assert!(count_before(&stdout, " lit,") > 0, "{stdout}");
    assert!(count_before(&stdout, " shadowed,") > 0, "{stdout}");
    let pgm = std::fs::read(dir.join("minimal.pgm")).expect("minimal.pgm written");
    assert!(pgm.starts_with(b"P5\n160 120\n255\n"), "not a 160x120 PGM");
    assert_eq!(pgm.len(), b"P5\n160 120\n255\n".len() + 160 * 120);
    std::fs::remove_dir_all(&dir).ok();
}
