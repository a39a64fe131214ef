//! Shared helpers of the tests that build native programs against the plugin's C ABI (c_host, install):
//! the workspace, the plugin's libraries built for the current test profile, the system compilers and
//! running commands that must succeed.

// Each test binary uses only part of the helpers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

pub fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The build this test executable belongs to: cargo's target folder, the profile to build the plugin with
/// and the folder of its outputs (target/<profile folder>).
pub struct Build {
    pub target: PathBuf,
    pub profile: String,
    pub dir: PathBuf,
}

pub fn current_build() -> Build {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf();
    let target = dir.parent().expect("target/<profile>").to_path_buf();
    let profile = match dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => "dev".to_owned(),
        Some(other) => other.to_owned(),
        None => panic!("unexpected target folder {}", dir.display()),
    };
    Build {
        target,
        profile,
        dir,
    }
}

/// The folder holding `libhrts.so` for this build profile (target/<profile>), building the plugin's
/// shared library there first (the `hrts-capi` package's, which `cargo test` does not build).
pub fn library_dir() -> PathBuf {
    let Build {
        target,
        profile,
        dir,
    } = current_build();
    run(&mut build_everything(&profile, &target));
    assert!(
        dir.join("libhrts.so").exists(),
        "libhrts.so not found in {} after building the hrts-capi package",
        dir.display()
    );
    dir
}

/// `cargo build --workspace --all-targets` for `profile` into `target`: what `cargo test --workspace` builds,
/// with the same features (a narrower selection such as `-p hrts-capi` resolves other features and
/// compiles the dependencies again), plus the C libraries `cargo test` leaves out.
pub fn build_everything(profile: &str, target: &Path) -> Command {
    let mut cargo = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cargo.args(["build", "--workspace", "--all-targets"]);
    if profile != "dev" {
        cargo.args(["--profile", profile]);
    }
    cargo
        .arg("--target-dir")
        .arg(target)
        .current_dir(workspace());
    cargo
}

/// Compiles the C `sources` as C99 (`-Wall -Wextra -Werror`) against the `hrts.h` in `include` and links
/// them with the plugin's shared library in `lib` into `exe`.
pub fn compile_c(exe: &Path, include: &Path, sources: &[PathBuf], lib: &Path) {
    run(Command::new(compiler("cc"))
        .args(["-std=c99", "-O1", "-Wall", "-Wextra", "-Werror"])
        .arg("-I")
        .arg(include)
        .args(sources)
        .arg("-o")
        .arg(exe)
        .arg("-L")
        .arg(lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lhrts", "-lvulkan", "-lm"]));
}

pub fn compiler(name: &str) -> String {
    std::env::var(name.to_uppercase()).unwrap_or_else(|_| name.to_owned())
}

pub fn run(cmd: &mut Command) -> std::process::Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}
