//! What the command-line tests of `host_demo` and `hrts_lab` share (`lab/tests/cli.rs` includes this file
//! by path): a fresh temporary folder, running a program, and the checks of a clean failure and of an
//! out-of-range option.

// Each test binary uses only part of the helpers.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// A fresh, empty temporary folder for the test `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrts-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Runs the program `exe` with `args` and waits for it.
pub fn run(exe: &str, args: &[&str]) -> Output {
    Command::new(exe)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{exe} runs: {e}"))
}

/// The run failed with exit code 1 and a one-line `error: ` message that holds `expect`, never a panic.
pub fn assert_clean_failure(output: &Output, stderr: &str, expect: &str) {
    assert!(
        !output.status.success(),
        "expected failure, stderr: {stderr}"
    );
    assert_eq!(output.status.code(), Some(1), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panicked: {stderr}");
    assert!(stderr.starts_with("error: "), "stderr: {stderr}");
    assert!(stderr.contains(expect), "expected '{expect}' in: {stderr}");
}

/// Each of `cases` (arguments, the flag, its range) is refused by `exe` with a message naming the flag
/// and its range, never a panic.
pub fn assert_out_of_range_refused(exe: &str, cases: &[(&[&str], &str, &str)]) {
    for &(args, flag, range) in cases {
        let output = run(exe, args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} accepted");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(
            stderr.contains(flag) && stderr.contains(range),
            "{args:?}: {stderr}"
        );
    }
}
